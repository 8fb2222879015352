"""Joint-limit performance criteria used by the redundancy-resolution schemes of lesson 06."""
from __future__ import annotations

from typing import Any

import numpy as np

from .chain import Chain

__all__ = ["limit_distance_gradient", "wln_weights"]


def _limits(chain: Chain, q: Any, name: str = "q") -> np.ndarray:
    if not isinstance(chain, Chain):
        raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
    return chain.check_q(q, name, batch=np.ndim(q) == 2)


def limit_distance_gradient(chain: Chain, q: Any) -> np.ndarray:
    """Gradient of the joint-range criterion ``H(q) = -1/2 sum(((q_i - mid_i) / half_i)^2)``.

    Ascending this gradient moves every joint towards the middle of its range; projected into the
    Jacobian's null space it does so without moving the hand.

    Parameters
    ----------
    chain : Chain
    q : array_like, shape (n,) or (N, n)

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
    The criterion of Liégeois, "Automatic supervisory control of the configuration and behavior of
    multibody mechanisms", IEEE T-SMC 7(12), 1977, Eq. (14) (normalised by the half range here),
    as used for joint-limit avoidance by gradient projection in Dubey, Euler & Babcock, "An
    efficient gradient projection optimization scheme for a seven-degree-of-freedom redundant robot
    with spherical wrist", ICRA 1988.
    """
    q = _limits(chain, q)
    return _limit_gradient(chain, q)


def _limit_gradient(chain: Chain, q: np.ndarray) -> np.ndarray:
    """Unchecked kernel of :func:`limit_distance_gradient`."""
    mid = 0.5 * (chain.qmin + chain.qmax)
    half = np.maximum(0.5 * (chain.qmax - chain.qmin), 1e-9)
    return -(q - mid) / half**2


def wln_weights(chain: Chain, q: Any, previous: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """Diagonal weights of Chan & Dubey's weighted least-norm (WLN) solution.

    Parameters
    ----------
    chain : Chain
    q : array_like, shape (n,) or (N, n)
        Joint angles, strictly inside the limits for finite weights.
    previous : array_like, optional
        ``|dH/dq|`` of the previous step (same shape as ``q``); without it every joint counts as
        moving towards its limit.

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
    Chan & Dubey, "A weighted least-norm solution based scheme for avoiding joint limits for
    redundant joint manipulators", IEEE T-RA 11(2), 1995, Eqs. (9)-(11) (the criterion ``H``) and
    Eq. (13) (the weights).
    """
    q = _limits(chain, q)
    prev = None if previous is None else _as_previous(previous, q.shape)
    return _wln(chain, q, prev)


def _as_previous(previous: Any, shape) -> np.ndarray:
    from ..validation import as_array

    return as_array(previous, "previous", shape=shape)


def _wln(chain: Chain, q: np.ndarray, previous: np.ndarray | None):
    """Unchecked kernel of :func:`wln_weights`."""
    lo, hi = chain.qmin, chain.qmax
    span = hi - lo
    eps = 1e-9 * np.maximum(span, 1e-9)
    qc = np.minimum(np.maximum(q, lo + eps), hi - eps)
    grad = np.abs(span**2 * (2 * qc - hi - lo) / (4 * (hi - qc) ** 2 * (qc - lo) ** 2))
    if previous is None:
        return 1.0 + grad, grad
    return np.where(grad >= previous, 1.0 + grad, 1.0), grad
