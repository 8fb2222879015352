"""Result objects returned by every IK solver in :mod:`robokit.arm`."""
from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["IKResult", "IKBatchResult"]


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


def _verify(chain, T_target: np.ndarray, q: np.ndarray, tol_pos: float, tol_rot: float):
    """Unchecked: FK-verify joint vectors ``q`` (N, n) against targets (N, 4, 4).

    Returns ``(success, reasons, residual, pos_err, rot_err)``; success needs both tolerances met
    and every joint within limits, so no solver can report a false success.
    """
    from .se3 import _pose_error

    err = _pose_error(T_target, chain._flange(chain._frames(q)))
    err *= err
    pos2, rot2 = err[:, :3].sum(1), err[:, 3:].sum(1)
    pos, rot, residual = np.sqrt(pos2), np.sqrt(rot2), np.sqrt(pos2 + rot2)
    inside = ((q >= chain.qmin) & (q <= chain.qmax)).all(1)
    ok = (pos < tol_pos) & (rot < tol_rot)
    success = ok & inside
    reasons = ["converged"] * len(q)
    for i in np.flatnonzero(~success):
        if ok[i]:
            j = int(np.argmax(np.maximum(chain.qmin - q[i], q[i] - chain.qmax)))
            reasons[i] = f"pose reached but joint {j + 1} is outside its limits"
        else:
            reasons[i] = f"pose error above tolerance (position {pos[i]:.2e} m, orientation {rot[i]:.2e} rad)"
    return success, reasons, residual, pos, rot
