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

from typing import Any

import numpy as np

from ..validation import as_array, check_int, check_positive
from .chain import Chain
from .result import IKBatchResult, IKResult, verify
from .se3 import as_se3, axis_angle_rotation, skew

__all__ = ["SRSArm", "arm_angle", "ik_srs_branches", "ik_srs", "ik_srs_batch"]

_ALPHA = np.array([-1, 1, 1, -1, -1, 1, 0]) * np.pi / 2
#: Branch order of the 8 solutions for one arm angle: (elbow, shoulder, wrist) sign flags.
BRANCHES = [(e, s, w) for e in (0, 1) for s in (0, 1) for w in (0, 1)]


def _wrap(x):
    return np.mod(x + np.pi, 2 * np.pi) - np.pi


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _zyz(m02, m12, m22, m21, m20, m10, m11):
    """ZYZ Euler angles (a, b >= 0, c) of ``Rz(a) Ry(b) Rz(c)`` from its entries.

    At ``sin b = 0`` only ``a + c`` (or ``a - c``) is defined; then ``a = 0``.
    """
    sb = np.hypot(m02, m12)
    b = np.arctan2(sb, m22)
    sing = sb < 1e-12
    a = np.where(sing, 0.0, np.arctan2(m12, m02))
    c = np.where(sing, np.arctan2(m10, m11), np.arctan2(m21, -m20))
    return a, b, c


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
        v_x, v_z = -self.d_ew * np.sin(q4), self.d_se + self.d_ew * np.cos(q4)
        q1 = np.arctan2(sw[..., 1], sw[..., 0])
        q2 = np.arctan2(np.hypot(sw[..., 0], sw[..., 1]), sw[..., 2]) - np.arctan2(v_x, v_z)
        return _rz(q1) @ _ry(q2)

    def coefficients(self, T7: np.ndarray):
        """Unchecked: Shimizu's ``A, B, C`` matrices for shoulder and wrist, per elbow sign.

        Returns ``(As, Bs, Cs, Aw, Bw, Cw, q4, reach_cos)`` where ``M(psi) = As sin psi +
        Bs cos psi + Cs`` is ``Rz(q1) Ry(q2) Rz(q3)`` and ``Aw sin psi + Bw cos psi + Cw`` is
        ``Rz(q5) Ry(q6) Rz(q7)``; arrays have shape (N, 2, 3, 3) for the elbow signs (+, -).
        Shimizu et al. (2008), Eqs. (13)-(17) and (20)-(22), in this chain's frames.
        """
        sw = self.wrist_centre(T7) - np.array([0.0, 0.0, self.d_bs])
        L = np.linalg.norm(sw, axis=-1)
        c4 = self.elbow_cosine(L)
        a4 = np.arccos(np.clip(c4, -1.0, 1.0))
        q4 = np.stack([a4, -a4], -1)                              # (N, 2)
        R_ref = self.reference_shoulder(sw[:, None, :], q4)       # (N, 2, 3, 3)
        u = sw / np.where(L > 0, L, 1.0)[:, None]
        K = skew(u)[:, None]
        As = K @ R_ref
        Bs = -(K @ As)
        Cs = R_ref - Bs
        Rt = T7[:, None, :3, :3]
        Ry4 = _ry(q4)
        Aw, Bw, Cw = (Ry4 @ np.swapaxes(X, -1, -2) @ Rt for X in (As, Bs, Cs))
        return As, Bs, Cs, Aw, Bw, Cw, q4, c4

    def joints(self, coeffs, psi: np.ndarray) -> np.ndarray:
        """Unchecked: all 8 branches for arm angles ``psi`` (N, K) -> q of shape (N, K, 8, 7)."""
        As, Bs, Cs, Aw, Bw, Cw, q4, _ = coeffs
        s, c = np.sin(psi)[:, None, :], np.cos(psi)[:, None, :]   # (N, 1, K)

        def entry(A, B, C, r, k):
            return A[..., r, k, None] * s + B[..., r, k, None] * c + C[..., r, k, None]

        idx = ((0, 2), (1, 2), (2, 2), (2, 1), (2, 0), (1, 0), (1, 1))
        q1, q2, q3 = _zyz(*(entry(As, Bs, Cs, r, k) for r, k in idx))   # (N, 2, K)
        q5, q6, q7 = _zyz(*(entry(Aw, Bw, Cw, r, k) for r, k in idx))
        shoulder = [np.stack([q1, q2, q3], -1), np.stack([_wrap(q1 + np.pi), -q2, _wrap(q3 + np.pi)], -1)]
        wrist = [np.stack([q5, q6, q7], -1), np.stack([_wrap(q5 + np.pi), -q6, _wrap(q7 + np.pi)], -1)]
        q4k = np.broadcast_to(q4[:, :, None, None], q1.shape + (1,))
        out = np.empty(psi.shape + (8, 7))
        for b, (e, sh, wr) in enumerate(BRANCHES):
            out[:, :, b, :] = np.concatenate([shoulder[sh][:, e], q4k[:, e], wrist[wr][:, e]], -1)
        return out

    def arm_angle(self, q: np.ndarray) -> np.ndarray:
        """Unchecked: arm angle ``psi`` of configurations ``q`` (N, 7) -> (N,).

        ``psi`` is the angle, about the shoulder-wrist axis, of ``M R_ref^T`` with
        ``M = Rz(q1) Ry(q2) Rz(q3)`` (Shimizu et al. 2008, Eq. (9)).
        """
        M = _rz(q[:, 0]) @ _ry(q[:, 1]) @ _rz(q[:, 2])
        v = np.stack([-self.d_ew * np.sin(q[:, 3]), np.zeros(len(q)), self.d_se + self.d_ew * np.cos(q[:, 3])], -1)
        sw = (M @ v[..., None])[..., 0]
        R = M @ np.swapaxes(self.reference_shoulder(sw, q[:, 3]), -1, -2)
        u = sw / np.linalg.norm(sw, axis=-1, keepdims=True)
        vee = 0.5 * np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], -1)
        return np.arctan2(np.sum(vee * u, -1), 0.5 * (np.trace(R, axis1=1, axis2=2) - 1.0))


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
    arm = SRSArm(chain)
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
    arm = SRSArm(chain)
    T7 = arm.to_link7(as_se3(T, "T")[None])
    p = _check_psi(psi)
    coeffs = arm.coefficients(T7)
    if abs(coeffs[7][0]) > 1.0 + 1e-12:
        return np.zeros((0, 7))
    q = arm.joints(coeffs, np.array([[p]]))[0, 0]
    if within_limits:
        q = q[np.all((q >= chain.qmin) & (q <= chain.qmax), axis=1)]
    return q


def ik_srs(chain: Chain, T: Any, q_seed: Any = None, *, n_psi: int = 36, tol: float = 1e-6) -> IKResult:
    """Analytic IK of an S-R-S arm: the valid solution closest to ``q_seed``.

    See :func:`ik_srs_batch` (this is its one-target form).
    """
    seeds = None if q_seed is None else chain.check_q(q_seed, "q_seed")[None]
    return ik_srs_batch(chain, as_se3(T, "T")[None], seeds, n_psi=n_psi, tol=tol)[0]


def ik_srs_batch(chain: Chain, T: Any, q_seed: Any = None, *, n_psi: int = 36, tol: float = 1e-6,
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
    n_psi : int, default 36
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
    refine ``psi`` by two parabolic steps on the distance to the seed, accepting only feasible
    improvements; (3) targets with no feasible branch are retried on a finer grid. Shimizu et al.
    compute the feasible arm-angle intervals exactly (Sec. IV); the sampled search here is simpler
    and is what the lesson's experiment measures.
    """
    arm = SRSArm(chain)
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
    coeffs = arm.coefficients(T7)
    reach = np.abs(coeffs[7]) <= 1.0 + 1e-12
    psi0 = arm.arm_angle(seeds)
    q_best = seeds.copy()
    found = np.zeros(N, bool)
    evals = np.zeros(N, int)

    def search(rows, n):
        sub = tuple(c[rows] for c in coeffs)
        psi = psi0[rows, None] + np.arange(n) * (2 * np.pi / n)
        q = arm.joints(sub, psi)                                               # (m, n, 8, 7)
        ok = np.all((q >= chain.qmin) & (q <= chain.qmax), axis=-1)
        cost = np.where(ok, np.sum((q - seeds[rows, None, None]) ** 2, -1), np.inf)
        flat = cost.reshape(len(rows), -1).argmin(1)
        k, b = np.divmod(flat, 8)
        has = np.isfinite(cost.reshape(len(rows), -1)[np.arange(len(rows)), flat])
        best_q = q[np.arange(len(rows)), k, b]
        best_c = cost[np.arange(len(rows)), k, b]
        h = 2 * np.pi / n
        psi_k = psi[np.arange(len(rows)), k]
        # two parabolic refinements of the distance to the seed along psi (same branch)
        for step in (h, h / 4):
            trial = psi_k[:, None] + np.array([-step, step])
            qt = arm.joints(sub, trial)[np.arange(len(rows)), :, b]             # (m, 2, 7)
            okt = np.all((qt >= chain.qmin) & (qt <= chain.qmax), -1)
            ct = np.where(okt, np.sum((qt - seeds[rows, None]) ** 2, -1), np.inf)
            f0, f1, f2 = ct[:, 0], best_c, ct[:, 1]
            den = f0 - 2 * f1 + f2
            with np.errstate(invalid="ignore", divide="ignore"):
                x = np.where(np.isfinite(den) & (den > 0), 0.5 * (f0 - f2) / den, 0.0)
            x = np.clip(x, -1.0, 1.0)
            # also allow the better of the two probes when the parabola is not usable
            cand_psi = np.stack([psi_k + x * step, trial[:, 0], trial[:, 1]], -1)
            qc = arm.joints(sub, cand_psi[:, :1])[np.arange(len(rows)), 0, b]
            okc = np.all((qc >= chain.qmin) & (qc <= chain.qmax), -1)
            cc = np.where(okc, np.sum((qc - seeds[rows]) ** 2, -1), np.inf)
            all_c = np.stack([cc, ct[:, 0], ct[:, 1]], -1)
            all_q = np.stack([qc, qt[:, 0], qt[:, 1]], 1)
            j = all_c.argmin(1)
            better = all_c[np.arange(len(rows)), j] < best_c
            best_c = np.where(better, all_c[np.arange(len(rows)), j], best_c)
            best_q = np.where(better[:, None], all_q[np.arange(len(rows)), j], best_q)
            psi_k = np.where(better, cand_psi[np.arange(len(rows)), j], psi_k)
        return has, best_q, n * 8 + 6

    rows = np.flatnonzero(reach)
    if rows.size:
        has, qb, ne = search(rows, n_psi)
        q_best[rows[has]] = qb[has]
        found[rows[has]] = True
        evals[rows] += ne
        retry = rows[~has]
        if retry.size:
            has, qb, ne = search(retry, n_fine)
            q_best[retry[has]] = qb[has]
            found[retry[has]] = True
            evals[retry] += ne

    success, reasons, residual, pos, rot = verify(chain, Tt, q_best, tol, tol)
    for i in np.flatnonzero(~reach):
        L = np.linalg.norm(arm.wrist_centre(T7[i]) - [0, 0, arm.d_bs])
        reasons[i] = (f"out of reach: shoulder-wrist distance {L:.4f} m outside "
                      f"[{abs(arm.d_se - arm.d_ew):.4f}, {arm.d_se + arm.d_ew:.4f}] m")
    for i in np.flatnonzero(reach & ~found):
        reasons[i] = f"no arm angle keeps all joints within limits ({n_psi} + {n_fine} arm angles tried)"
    success &= found
    return IKBatchResult(q=q_best, success=success, reason=reasons, residual=residual, iterations=evals,
                         position_error=pos, orientation_error=rot, restarts=np.zeros(N, int))
