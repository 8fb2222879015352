"""The one weighted rigid fit of corresponding points (Procrustes without scale), in 2-D and 3-D.

:func:`fit_rigid` is the kernel that :func:`fit_se2` (a planar pose ``[x, y, theta]``) and
:func:`fit_se3` (a 4x4 ``T``) wrap: the rotation ``R`` and translation ``t`` minimising
``sum_i w_i |R s_i + t - t_i|^2``.

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
from .planar import wrap_angle

__all__ = ["DegenerateFitError", "RigidFit", "FIT_TOL", "fit_rigid", "fit_se2", "fit_se3"]

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


def _rotation_2d(cov: np.ndarray, gap: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eqs. (39)-(40) in closed form for d = 2 (the same rotation and degeneracy as the SVD, faster).

    Write ``Sigma = [[p + r, u - q], [u + q, p - r]]``. Its singular values are
    ``rho +- sqrt(r^2 + u^2)`` with ``rho = sqrt(p^2 + q^2)``, and the rotation ``U S V^T`` is the
    one by ``atan2(q, p)``: it maximises ``trace(R^T Sigma) = 2 (p cos + q sin)``. It is unique
    unless ``rho = 0``; with ``det Sigma < 0`` the SVD rule's ``sigma_1 - sigma_2`` is ``2 rho``, and
    with ``det Sigma >= 0`` the largest singular value is at most ``2 rho``, so the rule reads
    ``sigma_1 <= gap or 2 rho <= gap``.
    """
    p = 0.5 * (cov[..., 0, 0] + cov[..., 1, 1])
    q = 0.5 * (cov[..., 1, 0] - cov[..., 0, 1])
    r = 0.5 * (cov[..., 0, 0] - cov[..., 1, 1])
    u = 0.5 * (cov[..., 1, 0] + cov[..., 0, 1])
    rho = np.hypot(p, q)
    theta = np.arctan2(q, p)                                                       # Eq. (40) in 2-D
    c, s = np.cos(theta), np.sin(theta)
    R = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
    degenerate = (gap <= 0) | (rho + np.hypot(r, u) <= gap) | (2 * rho <= gap)
    return R, degenerate


def fit_rigid(source: Any, target: Any, weights: Any = None, *, validate: bool = True) -> RigidFit:
    """Weighted least-squares rotation and translation taking ``source`` onto ``target``.

    Parameters
    ----------
    source, target : array_like, shape (..., N, d)
        Corresponding points, ``d`` = 2 or 3; leading axes are a batch of independent problems.
    weights : array_like, shape (..., N), optional
        Non-negative weight per correspondence (default: all 1); a zero weight drops a point (a
        MoCap marker that was not seen).
    validate : bool, default True
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
        (With ``validate``; a ``ValueError``) for fewer than ``d`` points, or points that do not fix
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
    if validate:
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
    gap = FIT_TOL * np.sqrt(var_s * var_t)
    if d == 2:
        R, degenerate = _rotation_2d(cov, gap)
    else:
        U, sv, Vt = np.linalg.svd(cov)
        sign = np.where(np.linalg.det(U) * np.linalg.det(Vt) < 0, -1.0, 1.0)     # Eqs. (39), (43)
        S = np.ones(sv.shape)
        S[..., -1] = sign
        R = (U * S[..., None, :]) @ Vt                                             # Eq. (40)
        degenerate = ((gap <= 0) | (sv[..., d - 2] <= gap)
                      | ((sign < 0) & (sv[..., d - 2] - sv[..., d - 1] <= gap)))
    trans = mu_t - np.einsum("...ij,...j->...i", R, mu_s)                         # Eq. (41), c = 1
    if validate and np.any(degenerate):
        i = int(np.argmax(degenerate.reshape(-1)))
        names = "source, target" if weights is None else "source, target, weights"
        raise DegenerateFitError(f"{names}: expected points that fix the rotation (not all coincident; "
                                 f"in 3-D not all on one line), got a degenerate set (problem {i})")
    return RigidFit(R, trans, degenerate)


def fit_se2(source: Any, target: Any, weights: Any = None, *, validate: bool = True) -> np.ndarray:
    """Least-squares planar pose taking ``source`` points onto ``target`` points (2-D Procrustes).

    Parameters
    ----------
    source, target : array_like, shape (..., N, 2)
        Corresponding points, N >= 2; leading axes are a batch of independent problems.
    weights : array_like, shape (..., N), optional
        Non-negative weight per correspondence (default: all 1).
    validate : bool, default True
        Validate the inputs and refuse a degenerate set; ``False`` (float arrays of matching shapes
        only) is the fast path that RANSAC loops take: a degenerate set then gives ``theta = 0``.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        ``[x, y, theta]`` minimising ``sum_i w_i ||R(theta) s_i + (x, y) - t_i||^2``, i.e. the pose of
        the source frame in the target frame.

    Raises
    ------
    DegenerateFitError
        (A ``ValueError``, with ``validate``) for fewer than two points, or points that all coincide,
        which leave the heading undetermined.
    ValueError
        For shapes that do not agree, NaN/inf, or negative or all-zero weights.

    Notes
    -----
    The closed-form minimiser of Umeyama (1991), Eqs. (34)-(41) without scale, computed by the one
    rigid-fit kernel :func:`~robokit.geometry.procrustes.fit_rigid` (shared with
    :func:`~robokit.geometry.fit_se3`); the heading is ``atan2(R[1, 0], R[0, 0])``. In the plane it
    equals ``theta = atan2(sum w (s' x t'), sum w (s' . t'))`` for the centred points ``s', t'``.
    With two points it is the two-point pose of Lin et al. (Sec. 5): the heading from the
    direction between them and the translation from their midpoints.

    Examples
    --------
    >>> from robokit.geometry import se2_compose
    >>> src = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0]])
    >>> tgt = se2_compose([1.0, 2.0, 0.5], np.column_stack([src, np.zeros(3)]))[:, :2]
    >>> print(np.round(fit_se2(src, tgt), 6))
    [1.  2.  0.5]
    """
    if validate:
        s = as_array(source, "source")
        if s.ndim < 2 or s.shape[-1] != 2:
            raise ValueError(f"source: expected shape (..., N, 2) with N >= 2, got shape {s.shape}")
        source = s
    R, t, _ = fit_rigid(source, target, weights, validate=validate)
    return np.stack([t[..., 0], t[..., 1], wrap_angle(np.arctan2(R[..., 1, 0], R[..., 0, 0]))], axis=-1)


def fit_se3(source: Any, target: Any, weights: Any = None) -> np.ndarray:
    """Least-squares rigid transform taking ``source`` points onto ``target`` points (3-D Procrustes).

    Parameters
    ----------
    source, target : array_like, shape (..., N, 3)
        Corresponding points, N >= 3 and not all on one line; leading axes are a batch of
        independent problems (one per MoCap frame, say).
    weights : array_like, shape (..., N), optional
        Non-negative weight per correspondence (default: all 1); zero drops a point.

    Returns
    -------
    numpy.ndarray, shape (..., 4, 4)
        ``T`` with ``target ~ T @ source`` (homogeneous points): it minimises
        ``sum_i w_i |R s_i + t - t_i|^2`` with ``det R = +1``. With ``source`` the markers in the
        body frame and ``target`` where the cameras saw them, ``T`` is ``T_world_body``.

    Raises
    ------
    DegenerateFitError
        (A ``ValueError``) for fewer than three points, or points that coincide or
        lie on one line (a rotation about that line is then free).
    ValueError
        For shapes that do not agree, NaN/inf, or negative or all-zero weights.

    Notes
    -----
    Arun et al. (1987): centring on the centroids separates the translation from the rotation,
    which comes from the SVD of the correlation matrix; Umeyama (1991), Eqs. (34)-(41) and (43)
    without scale, adds the sign matrix ``S`` that makes the answer a rotation, never a reflection.
    The kernel is :func:`~robokit.geometry.procrustes.fit_rigid`, the one that
    :func:`~robokit.geometry.fit_se2` uses too.

    Examples
    --------
    >>> from robokit.geometry import rot_z, se3_from_rt, transform_points
    >>> markers = np.array([[0.10, 0.03, 0.0115], [0.10, -0.04, 0.0115], [-0.11, 0.035, 0.0115],
    ...                     [-0.05, -0.02, 0.04]])
    >>> T_world_body = se3_from_rt(rot_z(0.3), [1.0, 0.5, 0.13])
    >>> seen = transform_points(T_world_body, markers)
    >>> print(np.round(fit_se3(markers, seen), 6) + 0.0)
    [[ 0.955336 -0.29552   0.        1.      ]
     [ 0.29552   0.955336  0.        0.5     ]
     [ 0.        0.        1.        0.13    ]
     [ 0.        0.        0.        1.      ]]
    """
    s = as_array(source, "source")
    if s.ndim < 2 or s.shape[-1] != 3:
        raise ValueError(f"source: expected shape (..., N, 3) with N >= 3, got shape {s.shape}")
    R, t, _ = fit_rigid(s, target, weights)
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3], T[..., :3, 3], T[..., 3, 3] = R, t, 1.0
    return T
