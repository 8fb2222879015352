"""The numerical IK of :mod:`robokit.arm.ik_numeric` for one target, written as a plain loop.

One attempt from ``q0``, no restarts, no parallel attempts, one step rule per call, and only the
library's public, checked functions. It is the readable statement of what
:func:`~robokit.arm.ik_numeric_batch` computes (the tests compare the two iterate by iterate); it
is far slower, since every numpy call works on one small array.

References
----------
.. [1] C. W. Wampler, "Manipulator inverse kinematic solutions based on vector formulations and
   damped least-squares methods", *IEEE Transactions on Systems, Man, and Cybernetics* 16(1),
   93-101, 1986.
.. [2] A. Liégeois, "Automatic supervisory control of the configuration and behavior of multibody
   mechanisms", *IEEE Transactions on Systems, Man, and Cybernetics* 7(12), 868-871, 1977.
.. [3] T. F. Chan and R. V. Dubey, "A weighted least-norm solution based scheme for avoiding joint
   limits for redundant joint manipulators", *IEEE Transactions on Robotics and Automation* 11(2),
   286-292, 1995.
.. [4] T. Sugihara, "Solvability-unconcerned inverse kinematics by the Levenberg-Marquardt method",
   *IEEE Transactions on Robotics* 27(5), 984-991, 2011.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..geometry import as_se3, pose_error
from ..validation import as_choice, as_int, as_positive
from .chain import Chain
from .ik_steps import METHODS, NULL_SPACE_FADE, dls_step, null_space_step
from .jacobian import geometric_jacobian
from .limits import limit_distance_gradient, wln_weights
from .result import IKResult, verify

__all__ = ["ik_numeric_readable"]


def ik_numeric_readable(chain: Chain, T: Any, q0: Any, *, method: str = "wln", tol: float = 1e-6,
                         max_iter: int = 60, damping: float = 1e-3, gain: float = 0.5, clamp: bool = True,
                         max_step: float = 0.5, patience: int = 15) -> tuple[IKResult, np.ndarray]:
    """One attempt of damped least squares, gradient projection or weighted least norm IK.

    Parameters
    ----------
    chain : Chain
    T : array_like, shape (4, 4)
        Target flange transform.
    q0 : array_like, shape (n,)
        Start configuration.
    method, tol, max_iter, damping, gain, clamp, max_step, patience
        As :func:`~robokit.arm.ik_numeric_batch`.

    Returns
    -------
    result : IKResult
        FK-verified (:func:`~robokit.arm.result.verify`).
    iterates : numpy.ndarray, shape (steps + 1, n)
        ``q0`` and every iterate.

    Raises
    ------
    ValueError
        On a non-SE(3) target, a bad ``q0``, an unknown method or bad numbers.

    Notes
    -----
    Damping ``lambda^2 = lambda_0^2 + |e|^2 / 2`` (Sugihara 2011, Eq. (13)); steps by Wampler
    (1986), Eq. (11), Liégeois (1977), Eq. (9) and Chan & Dubey (1995), Eqs. (7) and (13).

    Examples
    --------
    >>> from robokit.arm import panda
    >>> arm = panda()
    >>> q_target = arm.random_q(rng=3)
    >>> q0 = np.clip(q_target + 0.2, arm.qmin, arm.qmax)          # a start near the answer
    >>> result, iterates = ik_numeric_readable(arm, arm.fk(q_target), q0, method="dls")
    >>> result.success, result.iterations, iterates.shape
    (True, 4, (5, 7))
    """
    T = as_se3(T, "T")
    q = chain.as_q(q0, "q0")
    method = as_choice(method, "method", METHODS)
    tol, max_step = as_positive(tol, "tol"), as_positive(max_step, "max_step")
    damping = as_positive(damping, "damping", allow_zero=True)
    gain = as_positive(gain, "gain", allow_zero=True)
    max_iter, patience = as_int(max_iter, "max_iter", minimum=1), as_int(patience, "patience", minimum=1)
    iterates, best, stall, previous = [q], np.inf, 0, None
    for k in range(max_iter + 1):
        e = pose_error(T, chain.fk(q))
        pos2, rot2 = e[:3] @ e[:3], e[3:] @ e[3:]
        if max(pos2, rot2) < tol**2:                   # converged (success only within the limits)
            break
        err2 = pos2 + rot2
        if np.sqrt(err2) < 0.5 * best:                 # progress: the error halved
            best, stall = np.sqrt(err2), 0
        else:
            stall += 1
        if k == max_iter or stall >= patience:
            break
        J = geometric_jacobian(chain, q)
        lam = np.sqrt(damping**2 + 0.5 * err2)         # Sugihara Eq. (13)
        if method == "dls":
            dq = dls_step(J, e, lam)                   # Wampler Eq. (11)
        elif method == "gradient_projection":          # Liégeois Eq. (9), faded out near the target
            fade = min(1.0, np.sqrt(err2) / NULL_SPACE_FADE)
            dq = null_space_step(J, e, limit_distance_gradient(chain, q), lam, gain * fade)
        else:                                          # Chan & Dubey Eq. (7); weights 1 at the first step
            if previous is None:
                weights, previous = np.ones(chain.n), wln_weights(chain, q)[1]
            else:
                weights, previous = wln_weights(chain, q, previous)    # Eq. (13)
            dq = dls_step(J, e, lam, weights)
        if np.linalg.norm(dq) > max_step:              # scale the step down, keep its direction
            dq = dq * (max_step / np.linalg.norm(dq))
        q = np.clip(q + dq, chain.qmin, chain.qmax) if clamp else q + dq
        iterates.append(q)
    result = verify(chain, T[None], q[None], tol)[0]
    result.iterations = len(iterates) - 1
    return result, np.array(iterates)
