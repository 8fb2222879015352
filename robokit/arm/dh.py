"""Denavit-Hartenberg link transforms, standard and modified (Craig) conventions.

Both functions broadcast over their arguments, so one call builds every link transform of a chain,
or of a whole batch of configurations, at once.

References
----------
.. [1] J. Denavit and R. S. Hartenberg, "A kinematic notation for lower-pair mechanisms based on
   matrices", *Journal of Applied Mechanics* 22(2), 215-221, 1955.
.. [2] M. W. Spong, S. Hutchinson and M. Vidyasagar, *Robot Modeling and Control*, Wiley, 2006.
.. [3] J. J. Craig, *Introduction to Robotics: Mechanics and Control*, 3rd ed., Pearson, 2005.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array

__all__ = ["dh_transform", "mdh_transform"]


def _params(theta: Any, d: Any, a: Any, alpha: Any):
    arrs = [as_array(v, n) for v, n in ((theta, "theta"), (d, "d"), (a, "a"), (alpha, "alpha"))]
    try:
        return np.broadcast_arrays(*arrs)
    except ValueError:
        shapes = ", ".join(f"{n}{x.shape}" for n, x in zip(("theta", "d", "a", "alpha"), arrs))
        raise ValueError(f"theta, d, a, alpha: expected broadcastable shapes, got {shapes}") from None


def dh_transform(theta: Any, d: Any, a: Any, alpha: Any) -> np.ndarray:
    """Standard DH link transform ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``.

    Parameters
    ----------
    theta : float or array_like
        Joint angle about ``z_{i-1}`` [rad].
    d : float or array_like
        Offset along ``z_{i-1}`` [m].
    a : float or array_like
        Link length along ``x_i`` [m].
    alpha : float or array_like
        Link twist about ``x_i`` [rad].

    Returns
    -------
    numpy.ndarray, shape (..., 4, 4)
        The transform of frame ``i`` in frame ``i-1``; leading axes are the broadcast shape of the inputs.

    Raises
    ------
    ValueError
        If a parameter is NaN/infinite or the shapes do not broadcast.

    Notes
    -----
    Denavit & Hartenberg (1955); matrix as in Spong et al. (2006), Eq. (3.10).

    Examples
    --------
    >>> print(np.round(dh_transform(np.pi / 2, 0.36, 0.0, -np.pi / 2), 3) + 0.0)   # + 0.0: no "-0."
    [[ 0.    0.   -1.    0.  ]
     [ 1.    0.    0.    0.  ]
     [ 0.   -1.    0.    0.36]
     [ 0.    0.    0.    1.  ]]
    """
    args = _params(theta, d, a, alpha)
    return _link_matrices(*args, modified=False)


def _link_matrices(th: np.ndarray, d: np.ndarray, a: np.ndarray, al: np.ndarray, *, modified: bool) -> np.ndarray:
    """Unchecked kernel of :func:`dh_transform` / :func:`mdh_transform` (broadcast float arrays)."""
    ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(al), np.sin(al)
    shape = np.broadcast_shapes(np.shape(th), np.shape(d), np.shape(a), np.shape(al))
    T = np.zeros(shape + (4, 4))
    T[..., 3, 3] = 1.0
    if modified:
        T[..., 0, 0], T[..., 0, 1], T[..., 0, 3] = ct, -st, a
        T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = st * ca, ct * ca, -sa, -sa * d
        T[..., 2, 0], T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = st * sa, ct * sa, ca, ca * d
        return T
    T[..., 0, 0], T[..., 0, 1], T[..., 0, 2], T[..., 0, 3] = ct, -st * ca, st * sa, a * ct
    T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = st, ct * ca, -ct * sa, a * st
    T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = sa, ca, d
    return T


def mdh_transform(theta: Any, d: Any, a: Any, alpha: Any) -> np.ndarray:
    """Modified (Craig) DH link transform ``Rx(alpha) Tx(a) Rz(theta) Tz(d)``.

    Parameters
    ----------
    theta : float or array_like
        Joint angle about ``z_i`` [rad].
    d : float or array_like
        Offset along ``z_i`` [m].
    a : float or array_like
        Link length ``a_{i-1}`` along ``x_{i-1}`` [m].
    alpha : float or array_like
        Link twist ``alpha_{i-1}`` about ``x_{i-1}`` [rad].

    Returns
    -------
    numpy.ndarray, shape (..., 4, 4)
        The transform of frame ``i`` in frame ``i-1``.

    Raises
    ------
    ValueError
        If a parameter is NaN/infinite or the shapes do not broadcast.

    Notes
    -----
    Craig (2005), Eq. (3.6). Franka Emika publishes the Panda's kinematics in this convention.

    Examples
    --------
    >>> mdh_transform(0.0, 0.333, 0.0, 0.0)[:3, 3].tolist()
    [0.0, 0.0, 0.333]
    """
    args = _params(theta, d, a, alpha)
    return _link_matrices(*args, modified=True)
