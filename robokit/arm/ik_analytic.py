"""Analytic inverse kinematics of S-R-S 7-DOF arms (e.g. the KUKA LBR iiwa) with the arm angle.

The method is the separation of position and posture of Huang & Jiang ("A new method of inverse
kinematics solution for industrial 7DOF robot", Proc. 32nd Chinese Control Conference, 2013):

1. the wrist centre ``W = p - d_wf z_7`` depends only on the target pose;
2. joints 1-4 place the wrist centre: a position problem of a 4-DOF arm, redundant by one. The
   elbow angle ``q4`` follows from the triangle shoulder-elbow-wrist (law of cosines); the
   remaining freedom is the rotation of that triangle about the shoulder-wrist line, the *arm
   angle* ``psi`` of Shimizu et al. (IEEE T-RO 24(5), 2008, Sec. III);
3. joints 5-7 produce the orientation in closed form (a ZYZ Euler decomposition);
4. an iteration over the redundancy parameter ``psi`` finds values that keep every joint inside
   its limits and picks the solution closest to a seed configuration.

Every function here is vectorised over many targets at once.
"""
from __future__ import annotations

import functools
from typing import Any

import numpy as np

from ..validation import as_array, check_int, check_positive
from .chain import Chain
from .result import IKBatchResult, IKResult, _verify
from .se3 import as_se3, _skew
from .srs import _flip, _reference_rotation, _rot_y, _rot_z, _zyz

__all__ = ["SRSArm", "arm_angle", "ik_srs_branches", "ik_srs", "ik_srs_batch"]

_ALPHA = np.array([-1, 1, 1, -1, -1, 1, 0]) * np.pi / 2
#: Branch order of the 8 solutions for one arm angle: (elbow, shoulder, wrist) sign flags.
BRANCHES = [(e, s, w) for e in (0, 1) for s in (0, 1) for w in (0, 1)]
#: Matrix entries read by the ZYZ decomposition: (0,2) (1,2) (2,2) (2,1) (2,0) (1,0) (1,1).
_GROUPS = np.array([[0, 1, 2], [4, 5, 6]])
_ROWS = np.array([0, 1, 2, 2, 2, 1, 1])
_COLS = np.array([2, 2, 2, 1, 0, 0, 1])


class SRSArm:
    """The S-R-S geometry of a chain with the iiwa's DH pattern.

    Parameters
    ----------
    chain : Chain
        Standard DH, all ``a = 0``, ``d2 = d4 = d6 = 0``, zero offsets and twists
        ``(-pi/2, pi/2, pi/2, -pi/2, -pi/2, pi/2, 0)`` (the KUKA LBR iiwa 7/14 family).

    Raises
    ------
    TypeError
        If ``chain`` is not a :class:`Chain`.
    ValueError
        If the chain is not of that S-R-S form.

    Notes
    -----
    With these twists ``R_0^3 Rx(-pi/2) = Rz(q1) Ry(q2) Rz(q3)``, ``R_3^4 = Rz(q4) Rx(-pi/2)`` and
    ``R_4^7 = Rz(q5) Ry(q6) Rz(q7)``: shoulder and wrist are ZYZ spherical joints (Shimizu et al.
    2008, Sec. II).
    """

    def __init__(self, chain: Chain):
        if not isinstance(chain, Chain):
            raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
        ok = (chain.n == 7 and chain.convention == "standard" and np.allclose(chain.a, 0)
              and np.allclose(chain.d[[1, 3, 5]], 0) and np.allclose(chain.alpha, _ALPHA)
              and np.allclose(chain.offset, 0) and np.all(chain.d[[0, 2, 4, 6]] > 0))
        if not ok:
            raise ValueError(f"chain: expected an S-R-S arm in the iiwa's DH form (a = 0, d2 = d4 = d6 = 0, "
                             f"twists (-90, 90, 90, -90, -90, 90, 0) deg), got {chain!r}")
        self.chain = chain
        self.d_bs, self.d_se, self.d_ew, self.d_wf = (float(x) for x in chain.d[[0, 2, 4, 6]])
        self._tool_inv = np.linalg.inv(chain.tool)
        self._base_inv = np.linalg.inv(chain.base)

    # --- the decomposition, step by step ---------------------------------------------------------
    def to_link7(self, T: np.ndarray) -> np.ndarray:
        """Unchecked: target flange poses (N, 4, 4) -> link-7 poses in frame 0."""
        return self._base_inv @ T @ self._tool_inv

    def wrist_centre(self, T7: np.ndarray) -> np.ndarray:
        """Unchecked: wrist centre ``p - d_wf z_7`` of link-7 poses (Huang & Jiang's step 1)."""
        return T7[..., :3, 3] - self.d_wf * T7[..., :3, 2]

    def elbow_cosine(self, sw_len: np.ndarray) -> np.ndarray:
        """Unchecked: ``cos q4`` from the shoulder-wrist distance (law of cosines)."""
        return (sw_len**2 - self.d_se**2 - self.d_ew**2) / (2 * self.d_se * self.d_ew)

    def reference_shoulder(self, sw: np.ndarray, q4: np.ndarray) -> np.ndarray:
        """Unchecked: ``Rz(q1) Ry(q2)`` of the reference arm plane (``q3 = 0``) reaching ``sw``."""
        return _reference_rotation(sw, q4, self.d_se, self.d_ew)

    def coefficients(self, T7: np.ndarray):
        """Unchecked: Shimizu's ``A, B, C`` coefficients for shoulder and wrist, per elbow sign.

        Returns ``(A, B, C, q4, cos_q4)``. ``A, B, C`` have shape (N, 2, 2, 7): elbow sign (+, -),
        group (shoulder ``M = Rz(q1) Ry(q2) Rz(q3)``, wrist ``Rz(q5) Ry(q6) Rz(q7)``) and the seven
        matrix entries that the ZYZ decomposition reads; each entry is
        ``A sin psi + B cos psi + C``. Shimizu et al. (2008), Eqs. (13)-(17) and (20)-(22), in this
        chain's frames: ``M(psi) = R_psi M_ref`` and ``R_4^7 = Ry(q4) M^T R_0^7``.
        """
        sw = self.wrist_centre(T7) - np.array([0.0, 0.0, self.d_bs])
        L = np.linalg.norm(sw, axis=-1)
        c4 = self.elbow_cosine(L)
        a4 = np.arccos(np.clip(c4, -1.0, 1.0))
        q4 = np.stack([a4, -a4], -1)                              # (N, 2)
        R_ref = self.reference_shoulder(sw[:, None, :], q4)       # (N, 2, 3, 3)
        u = sw / np.where(L > 0, L, 1.0)[:, None]
        K = _skew(u)[:, None]
        As = K @ R_ref                                            # R_psi = I + sin K + (1 - cos) K^2
        Bs = -(K @ As)
        Cs = R_ref - Bs
        Rt_Ry4 = _rot_y(q4)
        Rt = T7[:, None, :3, :3]
        mats = [np.stack([X, Rt_Ry4 @ np.swapaxes(X, -1, -2) @ Rt], 2) for X in (As, Bs, Cs)]
        A, B, C = (X[..., _ROWS, _COLS] for X in mats)
        return A, B, C, q4, c4

    def angles(self, coeffs, psi: np.ndarray):
        """Unchecked: shoulder and wrist angles of every branch for arm angles ``psi`` (N, K).

        Returns three arrays (first, second and third ZYZ angle), each of shape (N, 2, 2, 2, K):
        elbow sign, group (shoulder q1-q3 / wrist q5-q7), branch (``b >= 0`` or its mirror
        ``(a + pi, -b, c + pi)``), arm angle.
        """
        A, B, C = coeffs[:3]
        s, c = np.sin(psi)[:, None, None, None, :], np.cos(psi)[:, None, None, None, :]
        E = A[..., None] * s + B[..., None] * c + C[..., None]   # (N, 2, 2, 7, K)
        a, b, cc = _zyz(*(E[..., r, :] for r in range(7)))        # (N, 2, 2, K)
        return (np.stack([a, _flip(a)], 3), np.stack([b, -b], 3), np.stack([cc, _flip(cc)], 3))

    def joints(self, coeffs, psi: np.ndarray) -> np.ndarray:
        """Unchecked: all 8 branches for arm angles ``psi`` (N, K) -> q of shape (N, K, 8, 7).

        Branch ``b`` of the 8 is ``BRANCHES[b] = (elbow, shoulder, wrist)`` mirror flags.
        """
        ang = self.angles(coeffs, psi)
        q4 = coeffs[3]
        out = np.empty(psi.shape + (8, 7))
        for k, (e, sh, wr) in enumerate(BRANCHES):
            for j in range(3):
                out[:, :, k, j] = ang[j][:, e, 0, sh]
                out[:, :, k, 4 + j] = ang[j][:, e, 1, wr]
            out[:, :, k, 3] = q4[:, e, None]
        return out

    def arm_angle(self, q: np.ndarray) -> np.ndarray:
        """Unchecked: arm angle ``psi`` of configurations ``q`` (N, 7) -> (N,).

        ``psi`` is the angle, about the shoulder-wrist axis, of ``M R_ref^T`` with
        ``M = Rz(q1) Ry(q2) Rz(q3)`` (Shimizu et al. 2008, Eq. (9)).
        """
        M = _rot_z(q[:, 0]) @ _rot_y(q[:, 1]) @ _rot_z(q[:, 2])
        v = np.stack([-self.d_ew * np.sin(q[:, 3]), np.zeros(len(q)), self.d_se + self.d_ew * np.cos(q[:, 3])], -1)
        sw = (M @ v[..., None])[..., 0]
        R = M @ np.swapaxes(self.reference_shoulder(sw, q[:, 3]), -1, -2)
        u = sw / np.linalg.norm(sw, axis=-1, keepdims=True)
        vee = 0.5 * np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], -1)
        return np.arctan2(np.sum(vee * u, -1), 0.5 * (np.trace(R, axis1=1, axis2=2) - 1.0))


_CHUNK = 256
_LOCAL = np.linspace(-1.0, 1.0, 9)
#: Up to this many targets, one dense pass replaces the coarse pass + local refinement.
_SMALL = 16


def _best_on_grid(arm: SRSArm, coeffs, psi: np.ndarray, seeds: np.ndarray):
    """Unchecked: over arm angles ``psi`` (m, K) and all 8 branches, the feasible solution nearest
    ``seeds`` (m, 7). Returns ``(cost, q, psi)``; cost is ``inf`` where nothing is feasible.

    The squared distance to the seed separates into shoulder, elbow and wrist terms, so the best
    shoulder and wrist branch are chosen independently for each elbow sign and arm angle.
    """
    chain = arm.chain
    m = len(psi)
    ang = arm.angles(coeffs, psi)                                   # 3 x (m, 2e, 2g, 2b, K)
    mid = 0.5 * (chain.qmin + chain.qmax)
    half = 0.5 * (chain.qmax - chain.qmin)
    ok = None
    cost = 0.0
    for j in range(3):
        g = _GROUPS[:, j]
        x = ang[j]
        ok_j = np.abs(x - mid[g][:, None, None]) <= half[g][:, None, None]
        ok = ok_j if ok is None else ok & ok_j
        cost = cost + (x - seeds[:, g][:, None, :, None, None]) ** 2
    cost = np.where(ok, cost, np.inf)                                # (m, 2e, 2g, 2b, K)
    br = (cost[:, :, :, 1] < cost[:, :, :, 0]).astype(np.intp)       # (m, 2e, 2g, K)
    cmin = np.minimum(cost[:, :, :, 0], cost[:, :, :, 1])
    q4 = coeffs[3]
    c4 = np.where(np.abs(q4 - mid[3]) <= half[3], (q4 - seeds[:, 3:4]) ** 2, np.inf)
    total = cmin[:, :, 0] + cmin[:, :, 1] + c4[:, :, None]           # (m, 2e, K)
    flat = total.reshape(m, -1).argmin(1)
    e, k = np.divmod(flat, psi.shape[1])
    i = np.arange(m)
    q = np.empty((m, 7))
    for j in range(3):
        q[:, j] = ang[j][i, e, 0, br[i, e, 0, k], k]
        q[:, 4 + j] = ang[j][i, e, 1, br[i, e, 1, k], k]
    q[:, 3] = q4[i, e]
    return total[i, e, k], q, psi[i, k]


def _srs(chain: Chain) -> SRSArm:
    """The (validated) S-R-S geometry of a chain, built once per chain object."""
    if not isinstance(chain, Chain):
        raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
    return _srs_cached(chain)


@functools.lru_cache(maxsize=16)
def _srs_cached(chain: Chain) -> SRSArm:
    return SRSArm(chain)


def _check_psi(psi: Any) -> float:
    return float(as_array(psi, "psi", shape=()))


def arm_angle(chain: Chain, q: Any) -> float | np.ndarray:
    """The arm angle ``psi`` [rad] of S-R-S configurations.

    Parameters
    ----------
    chain : Chain
        An S-R-S chain (see :class:`SRSArm`).
    q : array_like, shape (7,) or (N, 7)

    Returns
    -------
    float or numpy.ndarray, shape (N,)
        The rotation of the shoulder-elbow-wrist plane about the shoulder-wrist axis, measured from
        the reference plane in which ``q3 = 0``; in ``(-pi, pi]``.

    Raises
    ------
    ValueError
        On a non-S-R-S chain or a bad joint vector.

    Notes
    -----
    Shimizu et al., "Analytical inverse kinematic computation for 7-DOF redundant manipulators
    with joint limits ...", IEEE T-RO 24(5), 2008, Sec. III-A, Eq. (9).
    """
    arm = _srs(chain)
    qq = chain.check_q(q, batch=True)
    out = arm.arm_angle(qq)
    return float(out[0]) if np.ndim(q) == 1 else out


def ik_srs_branches(chain: Chain, T: Any, psi: float, *, within_limits: bool = True) -> np.ndarray:
    """Every closed-form IK solution of an S-R-S arm for one arm angle.

    Parameters
    ----------
    chain : Chain
        An S-R-S chain (see :class:`SRSArm`).
    T : array_like, shape (4, 4)
        Target flange pose (SE(3), metres).
    psi : float
        Arm angle [rad].
    within_limits : bool, default True
        Keep only branches inside the joint limits.

    Returns
    -------
    numpy.ndarray, shape (k, 7)
        Up to 8 solutions (elbow +-, shoulder +-, wrist +-), in the order elbow-major; ``k = 0``
        when the wrist centre is out of reach or no branch respects the limits.

    Raises
    ------
    ValueError
        If ``T`` is not an SE(3) matrix, ``psi`` is not a finite number or the chain is not S-R-S.

    Notes
    -----
    Shimizu et al. (2008), Sec. III-B, Eqs. (13)-(22); Huang & Jiang (2013) separation of position
    and posture.
    """
    arm = _srs(chain)
    T7 = arm.to_link7(as_se3(T, "T")[None])
    p = _check_psi(psi)
    coeffs = arm.coefficients(T7)
    if abs(coeffs[4][0]) > 1.0 + 1e-12:
        return np.zeros((0, 7))
    q = arm.joints(coeffs, np.array([[p]]))[0, 0]
    if within_limits:
        q = q[np.all((q >= chain.qmin) & (q <= chain.qmax), axis=1)]
    return q


def ik_srs(chain: Chain, T: Any, q_seed: Any = None, *, n_psi: int = 12, tol: float = 1e-6) -> IKResult:
    """Analytic IK of an S-R-S arm: the valid solution closest to ``q_seed``.

    See :func:`ik_srs_batch` (this is its one-target form).
    """
    if np.ndim(T) != 2:
        raise ValueError(f"T: expected one pose of shape (4, 4), got shape {np.shape(T)}")
    if q_seed is not None and np.ndim(q_seed) != 1:
        raise ValueError(f"q_seed: expected one joint vector of shape (7,), got shape {np.shape(q_seed)}")
    return ik_srs_batch(chain, T, q_seed, n_psi=n_psi, tol=tol)[0]


def ik_srs_batch(chain: Chain, T: Any, q_seed: Any = None, *, n_psi: int = 12, tol: float = 1e-6,
                 n_fine: int = 720) -> IKBatchResult:
    """Analytic IK of an S-R-S arm for many targets, with joint limits and a preferred solution.

    Parameters
    ----------
    chain : Chain
        An S-R-S chain (see :class:`SRSArm`), e.g. :func:`~robokit.arm.iiwa14`.
    T : array_like, shape (N, 4, 4) or (4, 4)
        Target flange poses.
    q_seed : array_like, shape (N, 7) or (7,), optional
        Preferred configurations; the middle of the joint ranges by default.
    n_psi : int, default 12
        Arm angles tried in the first pass (evenly spaced, starting at each seed's own arm angle).
    tol : float, default 1e-6
        Tolerance on the FK-verified position error [m] and orientation error [rad].
    n_fine : int, default 720
        Arm angles tried for targets whose first pass found no branch inside the limits.

    Returns
    -------
    IKBatchResult
        ``success[i]`` is true only when the FK of ``q[i]`` is within ``tol`` of the target and
        every joint is within its limits; ``reason[i]`` says why not otherwise.

    Raises
    ------
    ValueError
        On non-SE(3) targets, a wrong-shaped seed or a chain that is not S-R-S.

    Notes
    -----
    The iteration over the redundancy parameter (Huang & Jiang 2013, "algebraic iteration") runs
    over the arm angle of Shimizu et al. (2008): (1) evaluate the 8 closed-form branches at
    ``n_psi`` arm angles; keep those inside the limits and take the one nearest the seed; (2)
    refine ``psi`` on a local grid of 9 arm angles spanning one grid step either side, accepting
    only feasible improvements; (3) targets with no feasible branch are retried on a finer grid.
    For 16 targets or fewer, steps (1)-(2) are one pass over ``4 n_psi`` arm angles (the same
    spacing as the local grid), which is cheaper when numpy's call overhead dominates. Shimizu et al.
    compute the feasible arm-angle intervals exactly (Sec. IV); the sampled search here is simpler
    and is what the lesson's experiment measures.
    """
    arm = _srs(chain)
    Tt = as_se3(T, "T", batch=True)
    N = Tt.shape[0]
    n_psi = check_int(n_psi, "n_psi", minimum=4)
    n_fine = check_int(n_fine, "n_fine", minimum=n_psi)
    tol = check_positive(tol, "tol")
    if q_seed is None:
        seeds = np.broadcast_to(0.5 * (chain.qmin + chain.qmax), (N, 7)).copy()
    else:
        seeds = chain.check_q(q_seed, "q_seed", batch=True)
        if seeds.shape[0] == 1 and N > 1:
            seeds = np.broadcast_to(seeds, (N, 7)).copy()
        elif seeds.shape[0] != N:
            raise ValueError(f"q_seed: expected one seed or {N} seeds (one per target), got {seeds.shape[0]}")

    T7 = arm.to_link7(Tt)
    psi0 = arm.arm_angle(seeds)
    q_best = seeds.copy()
    found = np.zeros(N, bool)
    reach = np.zeros(N, bool)
    evals = np.zeros(N, int)
    for start in range(0, N, _CHUNK):
        rows = np.arange(start, min(N, start + _CHUNK))
        coeffs = arm.coefficients(T7[rows])
        r_ok = np.abs(coeffs[4]) <= 1.0 + 1e-12
        reach[rows] = r_ok
        rows, coeffs = rows[r_ok], tuple(c[r_ok] for c in coeffs)
        for n in (n_psi, n_fine):
            if not rows.size:
                break
            if len(rows) <= _SMALL:
                # few targets: numpy's per-call overhead dominates, so one pass over a grid as fine
                # as the local one below costs less than two passes
                m = 4 * n
                psi_grid = psi0[rows, None] + np.arange(m) * (2 * np.pi / m)
                cost, q, _ = _best_on_grid(arm, coeffs, psi_grid, seeds[rows])
                evals[rows] += 8 * m
            else:
                psi_grid = psi0[rows, None] + np.arange(n) * (2 * np.pi / n)
                cost, q, psi = _best_on_grid(arm, coeffs, psi_grid, seeds[rows])
                # the iteration on the redundancy parameter: a finer local grid around the best psi
                c2, q2, _ = _best_on_grid(arm, coeffs, psi[:, None] + (2 * np.pi / n) * _LOCAL, seeds[rows])
                better = c2 < cost
                cost, q = np.where(better, c2, cost), np.where(better[:, None], q2, q)
                evals[rows] += 8 * (n + len(_LOCAL))
            has = np.isfinite(cost)
            q_best[rows[has]] = q[has]
            found[rows[has]] = True
            rows, coeffs = rows[~has], tuple(c[~has] for c in coeffs)

    success, reasons, residual, pos, rot = _verify(chain, Tt, q_best, tol, tol)
    for i in np.flatnonzero(~reach):
        L = float(np.linalg.norm(arm.wrist_centre(T7[i]) - [0, 0, arm.d_bs]))
        reasons[i] = (f"out of reach: shoulder-wrist distance {L:.4f} m outside "
                      f"[{abs(arm.d_se - arm.d_ew):.4f}, {arm.d_se + arm.d_ew:.4f}] m")
    for i in np.flatnonzero(reach & ~found):
        reasons[i] = f"no arm angle keeps all joints within limits ({n_psi} + {n_fine} arm angles tried)"
    success &= found
    return IKBatchResult(q=q_best, success=success, reason=reasons, residual=residual, iterations=evals,
                         position_error=pos, orientation_error=rot, restarts=np.zeros(N, int))
