"""The geometric Jacobian of a serial chain and Yoshikawa's manipulability.

References
----------
.. [1] B. Siciliano, L. Sciavicco, L. Villani and G. Oriolo, *Robotics: Modelling, Planning and
   Control*, Springer, 2009.
.. [2] T. Yoshikawa, "Manipulability of robotic mechanisms", *The International Journal of Robotics
   Research* 4(2), 3-9, 1985.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, require_finite_result
from .chain import Chain, chain_from_table

__all__ = ["geometric_jacobian", "jacobian_from_frames", "dh_jacobian", "manipulability"]


def jacobian_from_frames(chain: Chain, frames: Any, *, validate: bool = True) -> np.ndarray:
    """The geometric Jacobian from link frames already computed (e.g. for FK in the same step).

    Parameters
    ----------
    chain : Chain
    frames : array_like, shape (..., n + 1, 4, 4)
        Frames 0..n of :meth:`Chain.frames`.
    validate : bool, default True
        Check ``chain`` and the shape of ``frames``; ``False`` skips it (solvers' inner loops).

    Returns
    -------
    numpy.ndarray, shape (..., 6, n)
        As :func:`geometric_jacobian`.

    Raises
    ------
    TypeError
        If ``chain`` is not a :class:`Chain`.
    ValueError
        If ``frames`` has the wrong shape or is not finite.

    Notes
    -----
    Siciliano et al. (2009), Eq. (3.30): column ``i`` is ``[z_i x (p_e - p_i); z_i]``.

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> J = jacobian_from_frames(arm, arm.frames(np.zeros(7)))
    >>> print(np.round(J[:, 1], 3) + 0.0)    # joint 2 tilts the straight arm forward
    [0.946 0.    0.    0.    1.    0.   ]
    """
    if validate:
        if not isinstance(chain, Chain):
            raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
        frames = chain.as_frames(frames)
    jf = chain.joint_frames(frames, validate=False)
    z = jf[..., :3, 2]                       # (..., n, 3) joint axes
    p = jf[..., :3, 3]                       # (..., n, 3) points on the axes
    p_e = chain.flange_transform(frames, validate=False)[..., None, :3, 3]
    r = p_e - p
    J = np.empty(z.shape[:-2] + (6, z.shape[-2]))
    J[..., 0, :] = z[..., 1] * r[..., 2] - z[..., 2] * r[..., 1]   # z x (p_e - p), Eq. (3.30)
    J[..., 1, :] = z[..., 2] * r[..., 0] - z[..., 0] * r[..., 2]
    J[..., 2, :] = z[..., 0] * r[..., 1] - z[..., 1] * r[..., 0]
    J[..., 3:, :] = np.swapaxes(z, -1, -2)
    return J


def geometric_jacobian(chain: Chain, q: Any) -> np.ndarray:
    """The geometric Jacobian mapping joint rates to the flange twist ``[v; omega]``.

    Parameters
    ----------
    chain : Chain
    q : array_like, shape (n,) or (N, n)
        Joint angles [rad].

    Returns
    -------
    numpy.ndarray, shape (6, n) or (N, 6, n)
        Rows 0-2: linear velocity of the flange origin [m/s per rad/s]; rows 3-5: angular velocity
        [rad/s per rad/s]; both in the base (world) frame. Column ``i`` is ``[z_i x (p_e - p_i); z_i]``.

    Raises
    ------
    TypeError
        If ``chain`` is not a :class:`Chain`.
    ValueError
        On a wrong-length or non-finite joint vector.

    Notes
    -----
    Siciliano et al. (2009), Eq. (3.30) for revolute joints.

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> J = geometric_jacobian(iiwa14(), np.radians([20, 40, -30, -70, 30, 60, 0]))
    >>> J.shape, int(np.linalg.matrix_rank(J))
    ((6, 7), 6)
    """
    if not isinstance(chain, Chain):
        raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
    return jacobian_from_frames(chain, chain.frames(q), validate=False)


def dh_jacobian(dh: Any, q: Any, *, modified: bool = False) -> np.ndarray:
    """Geometric Jacobian (6, n) of a chain given as a plain DH table of rows ``[d, a, alpha]``.

    Raises
    ------
    ValueError
        On a malformed table or a joint vector of the wrong length.

    Notes
    -----
    Siciliano et al. (2009), Eq. (3.30); see :func:`geometric_jacobian`.

    Examples
    --------
    >>> print(np.round(dh_jacobian([[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]], [0.0, 0.0]), 3) + 0.0)
    [[0.  0. ]
     [1.5 0.5]
     [0.  0. ]
     [0.  0. ]
     [0.  0. ]
     [1.  1. ]]
    """
    chain = chain_from_table(dh, modified=modified)
    return geometric_jacobian(chain, chain.as_q(q))


def manipulability(J: Any) -> float | np.ndarray:
    """Yoshikawa's manipulability ``w = sqrt(det(J J^T))``.

    Parameters
    ----------
    J : array_like, shape (m, n) or (N, m, n)
        Jacobian(s) with ``m <= n``.

    Returns
    -------
    float or numpy.ndarray, shape (N,)
        Zero exactly at singular configurations; the volume of the velocity ellipsoid otherwise.

    Raises
    ------
    ValueError
        If ``J`` is not 2-D/3-D, has more rows than columns or is not finite.

    Notes
    -----
    Yoshikawa (1985), Eq. (7).

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> print(round(manipulability(geometric_jacobian(arm, np.zeros(7))), 12))   # stretched: singular
    0.0
    >>> print(round(manipulability(geometric_jacobian(arm, np.radians([20, 40, -30, -70, 30, 60, 0]))), 4))
    0.122
    """
    J = as_array(J, "J")
    if J.ndim not in (2, 3) or not 1 <= J.shape[-2] <= J.shape[-1]:
        raise ValueError(f"J: expected a Jacobian of shape (m, n) or (N, m, n) with 1 <= m <= n, got shape {J.shape}")
    det = np.linalg.det(J @ np.swapaxes(J, -1, -2))
    require_finite_result("J", det)
    w = np.sqrt(np.clip(det, 0.0, None))
    return float(w) if w.ndim == 0 else w
