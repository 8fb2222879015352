"""One step of numerical inverse kinematics: damped least squares and redundancy resolution.

The public, checked steps :func:`dls_step` and :func:`null_space_step` (the exercises of lesson 06)
and the three step rules of the search in :mod:`robokit.arm.ik_numeric`, one class per method:

* :class:`DampedLeastSquares` (``"dls"``): ``dq = J^T (J J^T + lambda^2 I)^-1 e``;
* :class:`GradientProjection` (``"gradient_projection"``): DLS plus the gradient of a joint-range
  criterion projected into the Jacobian's null space (Liégeois 1977; Dubey, Euler & Babcock 1988);
* :class:`WeightedLeastNorm` (``"wln"``): ``dq = W^-1 J^T (J W^-1 J^T + lambda^2 I)^-1 e`` with
  Chan & Dubey's (1995) joint-limit weights.

All three damp with ``lambda^2 = lambda_0^2 + |e|^2 / 2`` (Sugihara 2011). A rule is called on
stacks of attempts, ``rule(J, e, err2, q, rows) -> dq``, and remembers per attempt what it needs
(only WLN does: the previous step's ``|dH/dq|``); ``rule.restart(row)`` forgets it.

References
----------
.. [1] C. W. Wampler, "Manipulator inverse kinematic solutions based on vector formulations and
   damped least-squares methods", *IEEE Transactions on Systems, Man, and Cybernetics* 16(1),
   93-101, 1986.
.. [2] Y. Nakamura and H. Hanafusa, "Inverse kinematic solutions with singularity robustness for
   robot manipulator control", *Journal of Dynamic Systems, Measurement, and Control* 108(3),
   163-171, 1986.
.. [3] A. Liégeois, "Automatic supervisory control of the configuration and behavior of multibody
   mechanisms", *IEEE Transactions on Systems, Man, and Cybernetics* 7(12), 868-871, 1977.
.. [4] R. V. Dubey, J. A. Euler and S. M. Babcock, "An efficient gradient projection optimization
   scheme for a seven-degree-of-freedom redundant robot with spherical wrist", *Proc. IEEE
   International Conference on Robotics and Automation (ICRA)*, 28-36, 1988.
.. [5] T. F. Chan and R. V. Dubey, "A weighted least-norm solution based scheme for avoiding joint
   limits for redundant joint manipulators", *IEEE Transactions on Robotics and Automation* 11(2),
   286-292, 1995.
.. [6] T. Sugihara, "Solvability-unconcerned inverse kinematics by the Levenberg-Marquardt method",
   *IEEE Transactions on Robotics* 27(5), 984-991, 2011.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, require_finite_result, as_positive
from .chain import Chain
from .limits import limit_distance_gradient, wln_weights

__all__ = ["METHODS", "NULL_SPACE_FADE", "PROJECTION_EPS", "dls_step", "null_space_step", "DampedLeastSquares",
           "GradientProjection", "WeightedLeastNorm", "STEP_RULES"]

_EYE6 = np.eye(6)
#: Regularisation of the null-space projector: ``J^T (J J^T + eps I)^-1 J`` has eigenvalues
#: ``s^2 / (s^2 + eps)`` in [0, 1], so the projector stays bounded at singularities while leaking
#: almost nothing of the secondary motion into the hand elsewhere.
PROJECTION_EPS = 1e-9
#: Pose-error norm [m, rad] below which the null-space gain fades linearly to zero (the projected
#: motion is exact only to first order).
NULL_SPACE_FADE = 1e-2


# --- one step, checked (the exercises' functions) and unchecked (the solver's kernels) ------------
def _jacobian_and_error(J: Any, e: Any):
    J = as_array(J, "J")
    if J.ndim not in (2, 3) or J.shape[-2] != 6:
        raise ValueError(f"J: expected a Jacobian of shape (6, n) or (N, 6, n), got shape {J.shape}")
    e = as_array(e, "e")
    if e.shape != J.shape[:-2] + (6,):
        raise ValueError(f"e: expected shape {J.shape[:-2] + (6,)} to match J of shape {J.shape}, got shape {e.shape}")
    return J, e


def dls_step(J: Any, e: Any, damping: float = 1e-2, weights: Any = None) -> np.ndarray:
    """One damped-least-squares (optionally weighted) joint update.

    Parameters
    ----------
    J : array_like, shape (6, n) or (N, 6, n)
        Geometric Jacobian(s).
    e : array_like, shape (6,) or (N, 6)
        Pose error ``[dp; dtheta]`` (see :func:`robokit.geometry.pose_error`).
    damping : float, default 1e-2
        Damping factor ``lambda`` (>= 0).
    weights : array_like, shape (n,) or (N, n), optional
        Positive joint weights ``W = diag(w)`` (weighted least norm); identity by default.

    Returns
    -------
    numpy.ndarray, shape (n,) or (N, n)
        ``dq = W^-1 J^T (J W^-1 J^T + lambda^2 I)^-1 e``.

    Raises
    ------
    ValueError
        On wrong shapes, NaN, a negative damping or non-positive weights.

    Notes
    -----
    Wampler (1986), Eq. (11); Nakamura & Hanafusa (1986). The weighted form is Chan & Dubey (1995),
    Eq. (7), damped.

    Examples
    --------
    >>> J = np.hstack([np.eye(6), np.zeros((6, 1))])
    >>> print(np.round(dls_step(J, [0.1, 0, 0, 0, 0, 0], damping=0.0), 6))
    [0.1 0.  0.  0.  0.  0.  0. ]
    """
    J, e = _jacobian_and_error(J, e)
    lam = as_positive(damping, "damping", allow_zero=True)
    winv = None
    if weights is not None:
        w = as_array(weights, "weights", shape=J.shape[:-2] + (J.shape[-1],))
        if np.any(w <= 0):
            raise ValueError("weights: expected positive joint weights")
        winv = 1.0 / w
    return _dls(J, e, np.full(J.shape[:-2], lam**2), winv)


def _dls(J, e, lam2, winv=None):
    """Unchecked kernel: ``W^-1 J^T (J W^-1 J^T + lam2 I)^-1 e`` for stacked inputs."""
    JW = J if winv is None else J * winv[..., None, :]
    A = JW @ np.swapaxes(J, -1, -2) + lam2[..., None, None] * _EYE6      # J W^-1 J^T + lambda^2 I
    y = np.linalg.solve(A, e[..., None])
    return (np.swapaxes(JW, -1, -2) @ y)[..., 0]                        # Wampler Eq. (11), Chan & Dubey Eq. (7)


def null_space_step(J: Any, e: Any, gradient: Any, damping: float = 1e-2, gain: float = 1.0) -> np.ndarray:
    """DLS step plus a secondary-task gradient projected into the Jacobian's null space.

    Parameters
    ----------
    J : array_like, shape (6, n) or (N, 6, n)
    e : array_like, shape (6,) or (N, 6)
        Pose error.
    gradient : array_like, shape (n,) or (N, n)
        Gradient of the criterion to *increase* (e.g. :func:`~robokit.arm.limit_distance_gradient`).
    damping : float, default 1e-2
    gain : float, default 1.0
        Step along the projected gradient (>= 0).

    Returns
    -------
    numpy.ndarray, shape (n,) or (N, n)
        ``dq = J# e + gain (I - J# J) gradient`` with the damped pseudo-inverse
        ``J# = J^T (J J^T + lambda^2 I)^-1``.

    Raises
    ------
    ValueError
        On wrong shapes, NaN or negative damping/gain.

    Notes
    -----
    Liégeois (1977), Eq. (9); Dubey, Euler & Babcock (1988), Sec. 2 (gradient projection).

    Examples
    --------
    With no pose error the step is pure self-motion: the hand does not move (to first order).

    >>> from robokit.arm import geometric_jacobian, limit_distance_gradient, panda
    >>> arm = panda()
    >>> q = arm.random_q(rng=0)
    >>> J = geometric_jacobian(arm, q)
    >>> dq = null_space_step(J, np.zeros(6), limit_distance_gradient(arm, q), damping=0.0)
    >>> bool(np.abs(J @ dq).max() < 1e-6), bool(np.linalg.norm(dq) > 1e-3)
    (True, True)
    """
    J, e = _jacobian_and_error(J, e)
    g = as_array(gradient, "gradient")
    if g.shape != J.shape[:-2] + (J.shape[-1],):
        raise ValueError(f"gradient: expected shape {J.shape[:-2] + (J.shape[-1],)} to match J of shape {J.shape}, "
                         f"got shape {g.shape}")
    lam = as_positive(damping, "damping", allow_zero=True)
    k = as_positive(gain, "gain", allow_zero=True)
    dq = _gp(J, e, g, np.full(J.shape[:-2], np.square(lam)), k)
    require_finite_result("J, e, gradient, damping, gain", dq)
    return dq


def _gp(J, e, g, lam2, k):
    """Unchecked kernel of :func:`null_space_step`."""
    Jt = np.swapaxes(J, -1, -2)
    JJt = J @ Jt
    primary = (Jt @ np.linalg.solve(JJt + lam2[..., None, None] * _EYE6, e[..., None]))[..., 0]   # J# e
    Jg = (J @ g[..., None])
    leak = (Jt @ np.linalg.solve(JJt + PROJECTION_EPS * _EYE6, Jg))[..., 0]                           # J# J g
    return primary + k[..., None] * (g - leak) if np.ndim(k) else primary + k * (g - leak)   # Liégeois Eq. (9)


# --- the three step rules of the search ----------------------------------------------------------
class DampedLeastSquares:
    """The step rule ``"dls"``: DLS with Sugihara's damping ``lambda^2 = lambda_0^2 + |e|^2 / 2``.

    Parameters
    ----------
    chain : Chain
    attempts : int
        Number of attempts (rows) the search runs side by side.
    damping : float
        Base damping ``lambda_0`` (>= 0).
    gain : float
        Gain of the null-space motion (>= 0; :class:`GradientProjection` only).

    Raises
    ------
    TypeError
        If ``chain`` is not a :class:`~robokit.arm.Chain`.
    ValueError
        On a negative damping or gain or a non-positive number of attempts.

    Notes
    -----
    Calling the rule is an unchecked kernel: ``rule(J, e, err2, q, rows)`` takes the Jacobians
    (m, 6, n), errors (m, 6), squared error norms (m,) and joints (m, n) of the attempts ``rows``
    (indices or a slice) and returns their steps (m, n). Wampler (1986), Eq. (11); Sugihara (2011),
    Eq. (13).

    Examples
    --------
    >>> from robokit.arm import geometric_jacobian, panda
    >>> arm = panda()
    >>> q = arm.random_q(1, rng=0)
    >>> rule = DampedLeastSquares(arm, attempts=1, damping=1e-3, gain=0.0)
    >>> e = np.array([[0.01, 0.0, 0.0, 0.0, 0.0, 0.0]])
    >>> J = geometric_jacobian(arm, q)
    >>> dq = rule(J, e, (e * e).sum(1), q, slice(None))
    >>> print(np.round(J[0] @ dq[0], 3) + 0.0)       # the hand moves by about e
    [0.01 0.   0.   0.   0.   0.  ]
    """

    def __init__(self, chain: Chain, attempts: int, damping: float, gain: float):
        if not isinstance(chain, Chain):
            raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
        if not (isinstance(attempts, (int, np.integer)) and attempts >= 1):
            raise ValueError(f"attempts: expected a positive integer, got {attempts!r}")
        damping = as_positive(damping, "damping", allow_zero=True)
        self.chain, self.lam2_0, self.gain = chain, damping**2, as_positive(gain, "gain", allow_zero=True)

    def restart(self, rows) -> None:
        """Forget what the step rule remembers about the attempts ``rows`` (none here)."""

    def damping(self, err2: np.ndarray) -> np.ndarray:
        return self.lam2_0 + 0.5 * err2                                 # Sugihara Eq. (13)

    def __call__(self, J, e, err2, q, rows) -> np.ndarray:
        """Joint steps of the attempts ``rows`` at ``q`` with Jacobians ``J``, errors ``e``, ``|e|^2``."""
        return _dls(J, e, self.damping(err2))                           # Wampler Eq. (11)


class GradientProjection(DampedLeastSquares):
    """The step rule ``"gradient_projection"``: DLS plus the joint-range gradient in the null space.

    Parameters, errors and calling convention as :class:`DampedLeastSquares`. The null-space motion
    is exact only to first order, so its gain fades out below :data:`NULL_SPACE_FADE`.

    Notes
    -----
    Liégeois (1977), Eqs. (9) and (14); Dubey, Euler & Babcock (1988), Sec. 2.

    Examples
    --------
    The step is the DLS step plus a motion that leaves the hand where DLS puts it (to first order)
    and moves the joints towards the middle of their ranges:

    >>> from robokit.arm import geometric_jacobian, limit_distance_gradient, panda
    >>> arm = panda()
    >>> q = arm.random_q(1, rng=0)
    >>> J, e = geometric_jacobian(arm, q), np.array([[0.05, 0.0, 0.0, 0.0, 0.0, 0.0]])
    >>> args = (J, e, (e * e).sum(1), q, slice(None))
    >>> extra = (GradientProjection(arm, attempts=1, damping=1e-3, gain=0.5)(*args)
    ...          - DampedLeastSquares(arm, attempts=1, damping=1e-3, gain=0.5)(*args))
    >>> print(np.round(J[0] @ extra[0], 6) + 0.0)                  # no hand motion
    [0. 0. 0. 0. 0. 0.]
    >>> bool(limit_distance_gradient(arm, q[0]) @ extra[0] > 0)    # away from the limits
    True
    """

    def __call__(self, J, e, err2, q, rows) -> np.ndarray:
        fade = np.minimum(1.0, np.sqrt(err2) / NULL_SPACE_FADE)
        g = limit_distance_gradient(self.chain, q, validate=False)         # Liégeois Eq. (14)
        return _gp(J, e, g, self.damping(err2), self.gain * fade)


class WeightedLeastNorm(DampedLeastSquares):
    """The step rule ``"wln"``: damped weighted least norm with Chan & Dubey's joint-limit weights.

    Parameters, errors and calling convention as :class:`DampedLeastSquares`. A weight grows only
    while its joint moves towards a limit, which needs the previous step's ``|dH/dq|`` (kept per
    attempt); an attempt's first step (and the first after a restart) has all weights 1.

    Notes
    -----
    Chan & Dubey (1995), Eq. (7) (damped) with the weights of Eq. (13).

    Examples
    --------
    Joint 4 of the Panda starts 0.3 rad below its upper limit; the first step is plain DLS, but once
    the joint has moved towards its limit its weight grows and it moves far less than under DLS:

    >>> from robokit.arm import geometric_jacobian, panda
    >>> arm = panda()
    >>> wln = WeightedLeastNorm(arm, attempts=1, damping=1e-3, gain=0.0)
    >>> dls = DampedLeastSquares(arm, attempts=1, damping=1e-3, gain=0.0)
    >>> def steps(q):
    ...     J, e = geometric_jacobian(arm, q), np.array([[0.0, 0.0, 0.05, 0.0, 0.0, 0.0]])
    ...     return wln(J, e, (e * e).sum(1), q, slice(None)), dls(J, e, (e * e).sum(1), q, slice(None))
    >>> q = 0.5 * (arm.qmin + arm.qmax)[None]
    >>> q[0, 3] = arm.qmax[3] - 0.3
    >>> first_wln, first_dls = steps(q)
    >>> bool(np.allclose(first_wln, first_dls))                     # all weights 1
    True
    >>> q[0, 3] += 0.1                                              # joint 4 nears its limit
    >>> second_wln, second_dls = steps(q)
    >>> print(round(second_wln[0, 3], 3), round(second_dls[0, 3], 3))
    -0.065 -0.554
    >>> wln.restart(0)                                              # a restart forgets the history
    >>> bool(np.allclose(steps(q)[0], second_dls))
    True
    """

    def __init__(self, chain: Chain, attempts: int, damping: float, gain: float):
        super().__init__(chain, attempts, damping, gain)
        self.previous = np.full((attempts, chain.n), np.nan)

    def restart(self, rows) -> None:
        self.previous[rows] = np.nan

    def __call__(self, J, e, err2, q, rows) -> np.ndarray:
        w, grad = wln_weights(self.chain, q, self.previous[rows], validate=False)   # Eq. (13)
        self.previous[rows] = grad
        return _dls(J, e, self.damping(err2), 1.0 / w)                           # Eq. (7), damped


#: The step rule of each method name.
STEP_RULES = {"dls": DampedLeastSquares, "gradient_projection": GradientProjection, "wln": WeightedLeastNorm}
#: The method names of :func:`~robokit.arm.ik_numeric_batch`.
METHODS = tuple(STEP_RULES)

