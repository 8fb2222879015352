"""Result objects returned by every IK solver in :mod:`robokit.arm`, and the FK verification that
decides their success.

References
----------
.. [1] B. Siciliano, L. Sciavicco, L. Villani and G. Oriolo, *Robotics: Modelling, Planning and
   Control*, Springer, 2009.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..geometry import as_se3, pose_error
from ..validation import as_positive
from .chain import LIMIT_TOL, Chain

__all__ = ["IKResult", "IKBatchResult", "verify"]


@dataclasses.dataclass
class IKResult:
    """The outcome of one inverse-kinematics solve.

    Attributes
    ----------
    q : numpy.ndarray, shape (n,)
        Best joint vector found [rad] (the last iterate when the solve failed).
    success : bool
        True only if the pose error is below tolerance AND every joint is inside its limits.
    reason : str
        ``"converged"`` on success; otherwise why not (out of reach, joint limits, no convergence).
    residual : float
        Norm of the final 6-vector pose error ``[dp (m); dtheta (rad)]``.
    iterations : int
        Iterations used (summed over restarts and parallel attempts; closed-form branch evaluations
        for the analytic solver).
    position_error : float
        Final flange position error [m].
    orientation_error : float
        Final orientation error [rad] (angle of ``R_target R^T``).
    restarts : int
        Random restarts used (numerical solvers).
    """

    q: np.ndarray
    success: bool
    reason: str
    residual: float
    iterations: int
    position_error: float = float("nan")
    orientation_error: float = float("nan")
    restarts: int = 0

    def __bool__(self) -> bool:  # ``if result:`` reads naturally
        return bool(self.success)


@dataclasses.dataclass
class IKBatchResult:
    """Results of a batch of solves, as arrays (row ``i`` is target ``i``).

    Attributes have the meaning of :class:`IKResult`'s, stacked: ``q`` (N, n), ``success`` (N,),
    ``reason`` (list of N str), ``residual``, ``position_error``, ``orientation_error`` (N,),
    ``iterations`` and ``restarts`` (N,) int.
    """

    q: np.ndarray
    success: np.ndarray
    reason: list
    residual: np.ndarray
    iterations: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    restarts: np.ndarray

    def __len__(self) -> int:
        return len(self.success)

    @property
    def success_rate(self) -> float:
        """Fraction of targets solved."""
        return float(np.mean(self.success)) if len(self) else float("nan")

    def __getitem__(self, i: int) -> IKResult:
        return IKResult(q=self.q[i].copy(), success=bool(self.success[i]), reason=self.reason[i],
                        residual=float(self.residual[i]), iterations=int(self.iterations[i]),
                        position_error=float(self.position_error[i]),
                        orientation_error=float(self.orientation_error[i]), restarts=int(self.restarts[i]))


def verify(chain, T_target: Any, q: Any, tol: float = 1e-6, *, validate: bool = True) -> IKBatchResult:
    """FK-verify joint vectors against their targets: success needs the pose AND the joint limits.

    Parameters
    ----------
    chain : Chain
    T_target : array_like, shape (N, 4, 4)
        Targets.
    q : array_like, shape (N, n)
        Candidate solutions.
    tol : float, default 1e-6
        Tolerance on the position error [m] and on the orientation error [rad].
    validate : bool, default True
        Validate the arguments; ``False`` skips it (the solvers, on their own checked arrays).

    Returns
    -------
    IKBatchResult
        ``success``, ``reason``, the errors and ``residual``; ``iterations`` and ``restarts`` are
        zero for the caller to fill in. No solver can report a false success this way.

    Raises
    ------
    TypeError
        If ``chain`` is not a :class:`~robokit.arm.Chain`.
    ValueError
        On non-SE(3) targets, joint vectors of the wrong shape or a non-positive tolerance.

    Notes
    -----
    The pose error is :func:`robokit.geometry.pose_error` (Siciliano et al. 2009, Sec. 3.7.3).

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> q = arm.random_q(2, rng=0)
    >>> r = verify(arm, arm.fk(q), q + [[0.0] * 7, [0.1] + [0.0] * 6])
    >>> r.success.tolist(), r.reason[0]
    ([True, False], 'converged')
    """
    if validate:
        if not isinstance(chain, Chain):
            raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
        T_target = as_se3(T_target, "T_target", batch=True)
        q = chain.as_q(q, batch=True)
        if len(q) != len(T_target):
            raise ValueError(f"q: expected {len(T_target)} joint vectors (one per target), got {len(q)}")
        tol = as_positive(tol, "tol")
    err = pose_error(T_target, chain.flange_transform(chain.frames(q, validate=False), validate=False), validate=False)
    err *= err
    pos2, rot2 = err[:, :3].sum(1), err[:, 3:].sum(1)
    pos, rot, residual = np.sqrt(pos2), np.sqrt(rot2), np.sqrt(pos2 + rot2)
    inside = ((q >= chain.qmin - LIMIT_TOL) & (q <= chain.qmax + LIMIT_TOL)).all(1)
    ok = (pos < tol) & (rot < tol)
    success = ok & inside
    reasons = ["converged"] * len(q)
    for i in np.flatnonzero(~success):
        if ok[i]:
            j = int(np.argmax(np.maximum(chain.qmin - q[i], q[i] - chain.qmax)))
            reasons[i] = f"pose reached but joint {j + 1} is outside its limits"
        else:
            reasons[i] = f"pose error above tolerance (position {pos[i]:.2e} m, orientation {rot[i]:.2e} rad)"
    N = len(q)
    return IKBatchResult(q=q, success=success, reason=reasons, residual=residual, iterations=np.zeros(N, int),
                         position_error=pos, orientation_error=rot, restarts=np.zeros(N, int))
