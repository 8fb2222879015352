"""Joint-limit performance criteria used by the redundancy-resolution schemes of lesson 06.

References
----------
.. [1] A. Liégeois, "Automatic supervisory control of the configuration and behavior of multibody
   mechanisms", *IEEE Transactions on Systems, Man, and Cybernetics* 7(12), 868-871, 1977.
.. [2] R. V. Dubey, J. A. Euler and S. M. Babcock, "An efficient gradient projection optimization
   scheme for a seven-degree-of-freedom redundant robot with spherical wrist", *Proc. IEEE
   International Conference on Robotics and Automation (ICRA)*, 28-36, 1988.
.. [3] T. F. Chan and R. V. Dubey, "A weighted least-norm solution based scheme for avoiding joint
   limits for redundant joint manipulators", *IEEE Transactions on Robotics and Automation* 11(2),
   286-292, 1995.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import array_ndim, as_array
from .chain import Chain

__all__ = ["limit_distance_gradient", "wln_weights"]


def _limits(chain: Chain, q: Any, name: str = "q") -> np.ndarray:
    if not isinstance(chain, Chain):
        raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
    return chain.as_q(q, name, batch=array_ndim(q, name) == 2)


def limit_distance_gradient(chain: Chain, q: Any, *, validate: bool = True) -> np.ndarray:
    """Gradient of the joint-range criterion ``H(q) = -1/2 sum(((q_i - mid_i) / half_i)^2)``.

    Ascending this gradient moves every joint towards the middle of its range; projected into the
    Jacobian's null space it does so without moving the hand.

    Parameters
    ----------
    chain : Chain
    q : array_like, shape (n,) or (N, n)
    validate : bool, default True
        Validate ``chain`` and ``q``; ``False`` skips it (solvers' inner loops).

    Returns
    -------
    numpy.ndarray
        ``-(q - mid) / half^2``, same shape as ``q``.

    Raises
    ------
    ValueError
        On a bad joint vector.

    Notes
    -----
    The criterion of Liégeois (1977), Eq. (14) (normalised by the half range here), as used for
    joint-limit avoidance by gradient projection in Dubey, Euler & Babcock (1988).

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> print(np.round(limit_distance_gradient(arm, 0.5 * arm.qmax), 3))
    [-0.169 -0.239 -0.169 -0.239 -0.169 -0.239 -0.164]
    """
    if validate:
        q = _limits(chain, q)
    mid = 0.5 * (chain.qmin + chain.qmax)
    half = np.maximum(0.5 * (chain.qmax - chain.qmin), 1e-9)
    return -(q - mid) / half**2                                 # dH/dq, Liégeois Eq. (14)


def wln_weights(chain: Chain, q: Any, previous: Any = None, *, validate: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Diagonal weights of Chan & Dubey's weighted least-norm (WLN) solution.

    Parameters
    ----------
    chain : Chain
    q : array_like, shape (n,) or (N, n)
        Joint angles, strictly inside the limits for finite weights.
    previous : array_like, optional
        ``|dH/dq|`` of the previous step (same shape as ``q``); without it every joint counts as
        moving towards its limit. (With ``validate=False`` a NaN entry gives that joint weight 1,
        which the numerical solver uses for the first step of an attempt.)
    validate : bool, default True
        Validate the arguments; ``False`` skips it (solvers' inner loops).

    Returns
    -------
    weights : numpy.ndarray
        ``w_i = 1 + |dH/dq_i|`` for joints moving towards a limit (``|dH/dq_i|`` growing),
        ``w_i = 1`` otherwise.
    grad_abs : numpy.ndarray
        ``|dH/dq_i|`` at ``q``, to pass as ``previous`` next time.

    Raises
    ------
    ValueError
        On a bad joint vector.

    Notes
    -----
    Chan & Dubey (1995), Eqs. (9)-(11) (the criterion ``H``) and Eq. (13) (the weights).

    Examples
    --------
    >>> from robokit.arm import panda
    >>> arm = panda()
    >>> w, g = wln_weights(arm, 0.5 * (arm.qmin + arm.qmax))
    >>> print(np.round(w, 3))
    [1. 1. 1. 1. 1. 1. 1.]
    """
    if validate:
        q = _limits(chain, q)
        if previous is not None:
            previous = as_array(previous, "previous", shape=q.shape)
    lo, hi = chain.qmin, chain.qmax
    span = hi - lo
    eps = 1e-9 * np.maximum(span, 1e-9)
    qc = np.minimum(np.maximum(q, lo + eps), hi - eps)
    grad = np.abs(span**2 * (2 * qc - hi - lo) / (4 * (hi - qc) ** 2 * (qc - lo) ** 2))   # |dH/dq|, Eq. (11)
    if previous is None:
        return 1.0 + grad, grad
    return np.where(grad >= previous, 1.0 + grad, 1.0), grad                          # Eq. (13)
