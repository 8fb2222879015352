"""The one weighted rigid fit of corresponding points (Procrustes without scale), in 2-D and 3-D.

:func:`fit_rigid` is the kernel that :func:`robokit.geometry.fit_se2` (a planar pose
``[x, y, theta]``) and :func:`robokit.geometry.fit_se3` (a 4x4 ``T``) wrap: the rotation ``R`` and
translation ``t`` minimising ``sum_i w_i |R s_i + t - t_i|^2``. It sits below ``planar`` and
``spatial`` inside :mod:`robokit.geometry` (it imports only :mod:`robokit.validation`), so both
can use it.

The method: Arun, Huang & Blostein (1987) remove the translation by centring both sets on their
centroids and take the rotation from the SVD of the 3x3 correlation matrix; their solution can be
a reflection (``det = -1``) when the data are noisy or planar. Umeyama (1991) gives the corrected
closed form, for any dimension, that always returns a proper rotation: Eqs. (34)-(43), used here
without the scale ``c`` (``c = 1``) and with weights (each mean and Eq. (38)'s average weighted by
``w_i / sum w``).

References
----------
.. [1] K. S. Arun, T. S. Huang and S. D. Blostein, "Least-squares fitting of two 3-D point sets",
   IEEE Trans. Pattern Analysis and Machine Intelligence 9(5), 698-700, 1987.
.. [2] S. Umeyama, "Least-squares estimation of transformation parameters between two point
   patterns", IEEE Trans. Pattern Analysis and Machine Intelligence 13(4), 376-380, 1991.
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..validation import as_array

__all__ = ["DegenerateFitError", "RigidFit", "FIT_TOL", "fit_rigid"]

#: Relative tolerance below which a singular value of the correlation matrix counts as zero.
FIT_TOL = 1e-9


class DegenerateFitError(ValueError):
    """The points do not fix a rigid motion: fewer than ``d`` of them (2 in the plane, 3 in space),
    all coincident, or (in 3-D) all on one line, so that a rotation about it is free."""


class RigidFit(NamedTuple):
    """A rigid fit ``target ~ R @ source + t`` per problem of a batch."""

    #: (..., d, d) proper rotations.
    R: np.ndarray
    #: (..., d) translations.
    t: np.ndarray
    #: (...,) True where the points do not fix the rotation (then ``R`` is one of many minimisers).
    degenerate: np.ndarray


def fit_rigid(source: Any, target: Any, weights: Any = None, *, check: bool = True) -> RigidFit:
    """Weighted least-squares rotation and translation taking ``source`` onto ``target``.

    Parameters
    ----------
    source, target : array_like, shape (..., N, d)
        Corresponding points, ``d`` = 2 or 3; leading axes are a batch of independent problems.
    weights : array_like, shape (..., N), optional
        Non-negative weight per correspondence (default: all 1); a zero weight drops a point (a
        MoCap marker that was not seen).
    check : bool, default True
        Validate the inputs and raise :class:`DegenerateFitError` for a degenerate problem;
        ``False`` is the fast path (float arrays of matching shapes, positive weight sums): the
        result's ``degenerate`` flags say which problems have no unique rotation.

    Returns
    -------
    RigidFit
        ``R`` (..., d, d), ``t`` (..., d) minimising ``sum_i w_i |R s_i + t - t_i|^2`` with
        ``det R = +1``, and the ``degenerate`` flags (..., ).

    Raises
    ------
    DegenerateFitError
        (With ``check``; a ``ValueError``) for fewer than ``d`` points, or points that do not fix
        the rotation: the correlation matrix of Eq. (38) has rank below ``d - 1`` (all points
        coincide; in 3-D all lie on a line), or a reflection fits better and its two smallest
        singular values are equal (then no rotation is unique). "Below" and "equal" are relative to
        ``FIT_TOL`` times ``sqrt(sigma_s^2 sigma_t^2)`` (Eqs. (36)-(37)).
    ValueError
        For shapes that do not agree, NaN/inf, or negative weights or a zero weight sum.

    Notes
    -----
    Umeyama (1991), without scale: weighted means (Eqs. (34)-(35)), variances (Eqs. (36)-(37)),
    the correlation matrix ``Sigma = sum w (t_i - mu_t)(s_i - mu_s)^T / sum w`` (Eq. (38)) and its
    SVD ``U D V^T``; ``S = diag(1, ..., 1, det(U) det(V))`` (Eqs. (39) and (43): the sign of
    ``det Sigma`` when it is not zero, that of ``det(U) det(V)`` when ``rank Sigma = d - 1``),
    ``R = U S V^T`` (Eq. (40)) and ``t = mu_t - R mu_s`` (Eq. (41) with ``c = 1``). Without ``S``
    it is the SVD algorithm of Arun et al. (1987), whose answer can be a reflection. The centred
    points are scaled to unit size first, so huge coordinates do not overflow.

    Examples
    --------
    >>> src = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]])
    >>> R = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])    # 90 deg about z
    >>> fit = fit_rigid(src, src @ R.T + [1.0, 2.0, 3.0])
    >>> print(np.round(fit.R, 6) + 0.0, np.round(fit.t, 6), fit.degenerate)
    [[ 0. -1.  0.]
     [ 1.  0.  0.]
     [ 0.  0.  1.]] [1. 2. 3.] False
    >>> fit_rigid(src[:, :1] * [1.0, 1.0, 1.0], src)          # points on one line
    Traceback (most recent call last):
    ...
    robokit.geometry.procrustes.DegenerateFitError: source, target: expected points that fix the rotation (not all coincident; in 3-D not all on one line), got a degenerate set (problem 0)
    """
    if check:
        s = as_array(source, "source")
        if s.ndim < 2 or s.shape[-1] not in (2, 3):
            raise ValueError(f"source: expected shape (..., N, 2) or (..., N, 3), got shape {s.shape}")
        d = s.shape[-1]
        if s.shape[-2] < d:
            raise DegenerateFitError(f"source: expected at least {d} points for a rigid fit in {d}-D, "
                                     f"got {s.shape[-2]}")
        t = as_array(target, "target", shape=s.shape)
        w = np.ones(s.shape[:-1]) if weights is None else as_array(weights, "weights", shape=s.shape[:-1])
        if np.any(w < 0) or np.any(w.sum(-1) <= 0):
            raise ValueError("weights: expected non-negative weights with a positive sum per problem")
    else:
        s, t = source, target
        d = s.shape[-1]
        w = np.ones(s.shape[:-1]) if weights is None else weights
    total = w.sum(-1)
    mu_s = np.einsum("...n,...ni->...i", w, s) / total[..., None]                 # Eq. (34)
    mu_t = np.einsum("...n,...ni->...i", w, t) / total[..., None]                 # Eq. (35)
    a, b = s - mu_s[..., None, :], t - mu_t[..., None, :]
    ka = np.abs(a).max(axis=(-2, -1), keepdims=True)
    kb = np.abs(b).max(axis=(-2, -1), keepdims=True)
    a, b = a / np.where(ka > 0, ka, 1.0), b / np.where(kb > 0, kb, 1.0)         # unit size: no overflow
    var_s = np.einsum("...n,...ni,...ni->...", w, a, a) / total                   # Eq. (36)
    var_t = np.einsum("...n,...ni,...ni->...", w, b, b) / total                   # Eq. (37)
    cov = np.einsum("...n,...ni,...nj->...ij", w, b, a) / total[..., None, None]  # Eq. (38)
    U, sv, Vt = np.linalg.svd(cov)
    sign = np.where(np.linalg.det(U) * np.linalg.det(Vt) < 0, -1.0, 1.0)         # Eqs. (39), (43)
    S = np.ones(sv.shape)
    S[..., -1] = sign
    R = (U * S[..., None, :]) @ Vt                                                 # Eq. (40)
    trans = mu_t - np.einsum("...ij,...j->...i", R, mu_s)                         # Eq. (41), c = 1
    gap = FIT_TOL * np.sqrt(var_s * var_t)
    degenerate = ((gap <= 0) | (sv[..., d - 2] <= gap)
                  | ((sign < 0) & (sv[..., d - 2] - sv[..., d - 1] <= gap)))
    if check and np.any(degenerate):
        i = int(np.argmax(degenerate.reshape(-1)))
        names = "source, target" if weights is None else "source, target, weights"
        raise DegenerateFitError(f"{names}: expected points that fix the rotation (not all coincident; "
                                 f"in 3-D not all on one line), got a degenerate set (problem {i})")
    return RigidFit(R, trans, degenerate)
