"""Analytic inverse kinematics of S-R-S 7-DOF arms (e.g. the KUKA LBR iiwa) with the arm angle.

The method is the separation of position and posture of Huang & Jiang (2013):

1. the wrist centre ``W = p - d_wf z_7`` depends only on the target transform;
2. joints 1-4 place the wrist centre: a position problem of a 4-DOF arm, redundant by one. The
   elbow angle ``q4`` follows from the triangle shoulder-elbow-wrist (law of cosines); the
   remaining freedom is the rotation of that triangle about the shoulder-wrist line, the *arm
   angle* ``psi`` of Shimizu et al. (2008), Sec. III;
3. joints 5-7 produce the orientation in closed form (a ZYZ Euler decomposition);
4. an iteration over the redundancy parameter ``psi`` finds values that keep every joint inside
   its limits and picks the solution closest to a preferred configuration ``q0``.

Every function here is vectorised over many targets at once.

References
----------
.. [1] L. Huang and R. Jiang, "A new method of inverse kinematics solution for industrial 7DOF
   robot", *Proc. 32nd Chinese Control Conference*, 2013.
.. [2] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
"""
from __future__ import annotations

import functools
from typing import Any

import numpy as np

from ..geometry import as_se3, zyz_angles
from ..validation import array_ndim, as_array, check_int, check_positive
from .chain import LIMIT_TOL, Chain
from .result import IKBatchResult, IKResult, verify
from .srs_geometry import ARRAY, SCALAR, arm_angle_terms, coefficient_terms, mirror_angle

__all__ = ["SRSArm", "arm_angle", "ik_srs_branches", "ik_srs", "ik_srs_batch"]

_ALPHA = np.array([-1, 1, 1, -1, -1, 1, 0]) * np.pi / 2
#: Branch order of the 8 solutions for one arm angle: (elbow, shoulder, wrist) sign flags.
BRANCHES = [(e, s, w) for e in (0, 1) for s in (0, 1) for w in (0, 1)]


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
        self._plain = np.array_equal(chain.tool, np.eye(4)) and np.array_equal(chain.base, np.eye(4))
        # limits of the spherical joints as (branch, joint-in-group, 1, 1, group): the layout of
        # the angle arrays in _best_on_grid
        grp = np.array([[0, 4], [1, 5], [2, 6]])
        self._lo = chain.qmin[grp][None, :, None, None, None, :] - LIMIT_TOL
        self._hi = chain.qmax[grp][None, :, None, None, None, :] + LIMIT_TOL
        self._grp = grp
        self.mid = 0.5 * (chain.qmin + chain.qmax)

    # --- the decomposition, step by step ---------------------------------------------------------
    def to_link7(self, T: np.ndarray) -> np.ndarray:
        """Unchecked: target flange transforms (N, 4, 4) -> link-7 transforms in frame 0."""
        return T if self._plain else self._base_inv @ T @ self._tool_inv

    def wrist_centre(self, T7: np.ndarray) -> np.ndarray:
        """Unchecked: wrist centre ``p - d_wf z_7`` of link-7 transforms (Huang & Jiang's step 1)."""
        return T7[..., :3, 3] - self.d_wf * T7[..., :3, 2]

    def coefficients(self, T7: np.ndarray):
        """Unchecked: Shimizu's ``A, B, C`` coefficients for shoulder and wrist, per elbow sign.

        ``T7`` is one link-7 transform (4, 4) or a stack (N, 4, 4). Returns ``(G, q4, cos_q4)``: ``G``
        of shape (N, 3, 36) (coefficient, then elbow sign, group and rotation entry flattened, see
        :func:`robokit.arm.srs_geometry.coefficient_terms`), ``q4`` (N, 2) and ``cos_q4`` (N,).
        One transform is computed on Python floats, which is several times faster than numpy at N = 1.
        """
        if T7.ndim == 2:
            r = T7.tolist()
            sw = (r[0][3] - self.d_wf * r[0][2], r[1][3] - self.d_wf * r[1][2],
                  r[2][3] - self.d_wf * r[2][2] - self.d_bs)
            terms, q4, c4 = coefficient_terms(r, sw, self.d_se, self.d_ew, SCALAR)
            return np.array(terms).reshape(1, 3, 36), np.array([q4]), np.array([c4])
        W = self.wrist_centre(T7)
        sw = (W[:, 0], W[:, 1], W[:, 2] - self.d_bs)
        R = [[T7[:, i, j] for j in range(3)] for i in range(3)]
        terms, q4, c4 = coefficient_terms(R, sw, self.d_se, self.d_ew, ARRAY)
        return np.stack(terms, -1).reshape(-1, 3, 36), np.stack(q4, -1), c4

    def angles(self, G: np.ndarray, psi: np.ndarray):
        """Unchecked: ZYZ angles ``(a, b >= 0, c)`` of shoulder and wrist for arm angles ``psi`` (N, K).

        Each of the three arrays has shape (N, K, 2, 2): arm angle, elbow sign, group (shoulder
        q1-q3 / wrist q5-q7). The mirror branch of each group is ``(a + pi, -b, c + pi)``.
        """
        N, K = psi.shape
        basis = np.empty((N, K, 3))
        basis[..., 0], basis[..., 1], basis[..., 2] = np.sin(psi), np.cos(psi), 1.0
        abc = zyz_angles((basis @ G).reshape(N, K, 2, 2, 3, 3), check=False)   # of A sin psi + B cos psi + C
        return abc[..., 0], abc[..., 1], abc[..., 2]

    def joints(self, coeffs, psi: np.ndarray) -> np.ndarray:
        """Unchecked: all 8 branches for arm angles ``psi`` (N, K) -> q of shape (N, K, 8, 7).

        Branch ``b`` of the 8 is ``BRANCHES[b] = (elbow, shoulder, wrist)`` mirror flags.
        """
        a, b, c = self.angles(coeffs[0], psi)
        ang = ((a, b, c), (mirror_angle(a), -b, mirror_angle(c)))           # branch b >= 0, then its mirror
        q4 = coeffs[1]
        out = np.empty(psi.shape + (8, 7))
        for k, (e, sh, wr) in enumerate(BRANCHES):
            for j in range(3):
                out[:, :, k, j] = ang[sh][j][:, :, e, 0]
                out[:, :, k, 4 + j] = ang[wr][j][:, :, e, 1]
            out[:, :, k, 3] = q4[:, e, None]
        return out

    def arm_angle(self, q: np.ndarray):
        """Unchecked: arm angle ``psi`` of one configuration (7,) -> float, or of many (N, 7) -> (N,).

        Shimizu et al. (2008), Eq. (9); see :func:`robokit.arm.srs_geometry.arm_angle_terms`.
        """
        if q.ndim == 1:
            return arm_angle_terms(*q[:4].tolist(), self.d_se, self.d_ew, SCALAR)
        return arm_angle_terms(*q[:, :4].T, self.d_se, self.d_ew, ARRAY)


_CHUNK = 256
_LOCAL = np.linspace(-1.0, 1.0, 9)
#: Up to this many targets, one dense pass replaces the coarse pass + local refinement.
_SMALL = 16


def _best_on_grid(arm: SRSArm, coeffs, psi: np.ndarray, q0: np.ndarray):
    """Unchecked: over arm angles ``psi`` (m, K) and all 8 branches, the feasible solution nearest
    ``q0`` (m, 7). Returns ``(cost, q, psi)``; cost is ``inf`` where nothing is feasible.

    The squared distance to ``q0`` separates into shoulder, elbow and wrist terms, so the best
    shoulder and wrist branch are chosen independently for each elbow sign and arm angle.
    """
    chain = arm.chain
    G, q4 = coeffs[0], coeffs[1]
    m, K = psi.shape
    a, b, c = arm.angles(G, psi)                                     # (m, K, 2e, 2g)
    X = np.empty((2, 3, m, K, 2, 2))                                  # branch, joint in group, ...
    X[0, 0], X[0, 1], X[0, 2] = a, b, c
    X[1, 0], X[1, 1], X[1, 2] = mirror_angle(a), -b, mirror_angle(c)
    ok = ((X >= arm._lo) & (X <= arm._hi)).all(1)                    # (2b, m, K, 2e, 2g)
    D = X - q0[:, arm._grp].transpose(1, 0, 2)[None, :, :, None, None, :]
    cost = np.where(ok, np.einsum("bjmkeg,bjmkeg->bmkeg", D, D), np.inf)
    br = cost[1] < cost[0]                                           # (m, K, 2e, 2g)
    cmin = np.minimum(cost[0], cost[1])
    c4 = (q4 - q0[:, 3:4]) ** 2
    c4[(q4 < chain.qmin[3] - LIMIT_TOL) | (q4 > chain.qmax[3] + LIMIT_TOL)] = np.inf
    total = cmin.sum(-1) + c4[:, None, :]                            # (m, K, 2e)
    flat = total.reshape(m, -1).argmin(1)
    k, e = np.divmod(flat, 2)
    i = np.arange(m)
    q = np.empty((m, 7))
    q[:, :3] = X[br[i, k, e, 0].astype(np.intp), :, i, k, e, 0]
    q[:, 4:] = X[br[i, k, e, 1].astype(np.intp), :, i, k, e, 1]
    q[:, 3] = q4[i, e]
    np.clip(q, chain.qmin, chain.qmax, out=q)   # a joint within LIMIT_TOL of a limit lands on it
    return total[i, k, e], q, psi[i, k]


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
    Shimizu et al. (2008), Sec. III-A, Eq. (9).

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> print(round(float(np.degrees(arm_angle(iiwa14(), np.radians([35, 50, -40, -75, 60, 45, 20])))), 3))
    -29.971
    """
    arm = _srs(chain)
    return arm.arm_angle(chain.check_q(q, batch=array_ndim(q, "q") == 2))


def ik_srs_branches(chain: Chain, T: Any, psi: float, *, within_limits: bool = True) -> np.ndarray:
    """Every closed-form IK solution of an S-R-S arm for one arm angle.

    Parameters
    ----------
    chain : Chain
        An S-R-S chain (see :class:`SRSArm`).
    T : array_like, shape (4, 4)
        Target flange transform (SE(3), metres).
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

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> q = np.radians([35, 50, -40, -75, 60, 45, 20])
    >>> branches = ik_srs_branches(arm, arm.fk(q), arm_angle(arm, q), within_limits=False)
    >>> len(branches), bool(np.abs(branches - q).max(axis=1).min() < 1e-9)
    (8, True)
    """
    arm = _srs(chain)
    T7 = arm.to_link7(as_se3(T, "T"))
    p = _check_psi(psi)
    coeffs = arm.coefficients(T7)
    if abs(coeffs[2][0]) > 1.0 + 1e-12:
        return np.zeros((0, 7))
    q = arm.joints(coeffs, np.array([[p]]))[0, 0]
    if within_limits:
        q = np.clip(q[chain.within_limits(q)], chain.qmin, chain.qmax)
    return q


def _options(n_psi: Any, n_fine: Any, tol: Any):
    n_psi = check_int(n_psi, "n_psi", minimum=4)
    return n_psi, check_int(n_fine, "n_fine", minimum=n_psi), check_positive(tol, "tol")


def _search(arm: SRSArm, coeffs, psi0: np.ndarray, q0: np.ndarray, n: int, dense: bool):
    """Unchecked: one pass of the arm-angle iteration with ``n`` coarse arm angles per target.

    ``dense``: a single grid of ``4 n`` arm angles (few targets, where numpy's per-call overhead
    dominates); otherwise ``n`` angles, then a local grid of 9 spanning one step either side of
    the best. Returns ``(cost, q, branch evaluations per target)``.
    """
    if dense:
        m = 4 * n
        cost, q, _ = _best_on_grid(arm, coeffs, psi0[:, None] + np.arange(m) * (2 * np.pi / m), q0)
        return cost, q, 8 * m
    cost, q, psi = _best_on_grid(arm, coeffs, psi0[:, None] + np.arange(n) * (2 * np.pi / n), q0)
    c2, q2, _ = _best_on_grid(arm, coeffs, psi[:, None] + (2 * np.pi / n) * _LOCAL, q0)
    better = c2 < cost
    return np.where(better, c2, cost), np.where(better[:, None], q2, q), 8 * (n + len(_LOCAL))


def _finish(arm: SRSArm, T: np.ndarray, c4: np.ndarray, q: np.ndarray, found: np.ndarray, evals,
            n_psi: int, n_fine: int, tol: float) -> IKBatchResult:
    """Unchecked: FK-verify ``q`` (N, 7) against targets ``T`` (N, 4, 4) and say why not."""
    out = verify(arm.chain, T, q, tol, check=False)
    reasons = out.reason
    reach = np.abs(c4) <= 1.0 + 1e-12
    for i in np.flatnonzero(~reach):
        L = np.sqrt(max(0.0, c4[i] * 2 * arm.d_se * arm.d_ew + arm.d_se**2 + arm.d_ew**2))
        reasons[i] = (f"out of reach: shoulder-wrist distance {L:.4f} m outside "
                      f"[{abs(arm.d_se - arm.d_ew):.4f}, {arm.d_se + arm.d_ew:.4f}] m")
    for i in np.flatnonzero(reach & ~found):
        reasons[i] = f"no arm angle keeps all joints within limits ({n_psi} + {n_fine} arm angles tried)"
    out.success &= found
    out.iterations = np.broadcast_to(evals, (len(q),)).astype(int)
    return out


def ik_srs(chain: Chain, T: Any, q0: Any = None, *, n_psi: int = 12, tol: float = 1e-6,
           n_fine: int = 720) -> IKResult:
    """Analytic IK of an S-R-S arm for one target: the valid solution closest to ``q0``.

    Parameters and result as :func:`ik_srs_batch`, for one transform ``T`` (4, 4) and one preferred
    configuration ``q0`` (7,). The per-target geometry runs on Python floats and the arm-angle
    search is one dense pass over ``4 n_psi`` arm angles (then ``4 n_fine`` if nothing is
    feasible), the form of :func:`ik_srs_batch` for few targets.

    Raises
    ------
    ValueError
        On a non-SE(3) target, a ``q0`` of the wrong shape or a chain that is not S-R-S.

    Notes
    -----
    Huang & Jiang (2013) with the arm angle of Shimizu et al. (2008), Sec. III.

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> T = arm.fk(np.radians([35, 50, -40, -75, 60, 45, 20]))
    >>> r = ik_srs(arm, T, np.radians([0, 30, 0, -60, 0, 60, 0]))
    >>> r.success, r.reason, r.position_error < 1e-9
    (True, 'converged', True)
    """
    if array_ndim(T, "T") != 2:
        raise ValueError(f"T: expected one transform of shape (4, 4), got shape {np.shape(T)}")
    if q0 is not None and array_ndim(q0, "q0") != 1:
        raise ValueError(f"q0: expected one joint vector of shape (7,), got shape {np.shape(q0)}")
    arm = _srs(chain)
    Tt = as_se3(T, "T")
    n_psi, n_fine, tol = _options(n_psi, n_fine, tol)
    near = arm.mid if q0 is None else chain.check_q(q0, "q0")
    coeffs = arm.coefficients(arm.to_link7(Tt))
    near, psi0 = near[None], np.array([arm.arm_angle(near)])
    q, found, evals = near, np.zeros(1, bool), 0
    if abs(coeffs[2][0]) <= 1.0 + 1e-12:
        for n in (n_psi, n_fine):
            cost, q_n, ev = _search(arm, coeffs, psi0, near, n, dense=True)
            evals += ev
            if cost[0] < np.inf:
                q, found[0] = q_n, True
                break
    return _finish(arm, Tt[None], coeffs[2], q, found, evals, n_psi, n_fine, tol)[0]


def ik_srs_batch(chain: Chain, T: Any, q0: Any = None, *, n_psi: int = 12, tol: float = 1e-6,
                 n_fine: int = 720) -> IKBatchResult:
    """Analytic IK of an S-R-S arm for many targets, with joint limits and a preferred solution.

    Parameters
    ----------
    chain : Chain
        An S-R-S chain (see :class:`SRSArm`), e.g. :func:`~robokit.arm.iiwa14`.
    T : array_like, shape (N, 4, 4) or (4, 4)
        Target flange transforms.
    q0 : array_like, shape (N, 7) or (7,), optional
        Preferred configurations (the solution nearest each is kept); the middle of the joint
        ranges by default.
    n_psi : int, default 12
        Arm angles tried in the first pass (evenly spaced, starting at each ``q0``'s own arm angle).
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
        On non-SE(3) targets, a wrong-shaped ``q0`` or a chain that is not S-R-S.

    Notes
    -----
    The iteration over the redundancy parameter (Huang & Jiang 2013, "algebraic iteration") runs
    over the arm angle of Shimizu et al. (2008): (1) evaluate the 8 closed-form branches at
    ``n_psi`` arm angles; keep those inside the limits and take the one nearest ``q0``; (2)
    refine ``psi`` on a local grid of 9 arm angles spanning one grid step either side, accepting
    only feasible improvements; (3) targets with no feasible branch are retried on a finer grid.
    For 16 targets or fewer, steps (1)-(2) are one pass over ``4 n_psi`` arm angles (the same
    spacing as the local grid), which is cheaper when numpy's call overhead dominates. Shimizu et al.
    compute the feasible arm-angle intervals exactly (Sec. IV); the sampled search here is simpler
    and is what the lesson's experiment measures.

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> T = arm.fk(arm.random_q(50, rng=1))
    >>> res = ik_srs_batch(arm, T, arm.random_q(50, rng=2))
    >>> res.success_rate, bool(res.position_error.max() < 1e-9)
    (1.0, True)
    """
    arm = _srs(chain)
    Tt = as_se3(T, "T", batch=True)
    N = Tt.shape[0]
    n_psi, n_fine, tol = _options(n_psi, n_fine, tol)
    if q0 is None:
        near = np.broadcast_to(arm.mid, (N, 7)).copy()
    else:
        near = chain.check_q(q0, "q0", batch=True)
        if near.shape[0] == 1 and N > 1:
            near = np.broadcast_to(near, (N, 7)).copy()
        elif near.shape[0] != N:
            raise ValueError(f"q0: expected one joint vector or {N} (one per target), got {near.shape[0]}")

    G, q4, c4 = arm.coefficients(arm.to_link7(Tt))
    psi0 = arm.arm_angle(near)
    q_best = near.copy()
    found = np.zeros(N, bool)
    evals = np.zeros(N, int)
    reachable = np.flatnonzero(np.abs(c4) <= 1.0 + 1e-12)
    for start in range(0, len(reachable), _CHUNK):
        rows = reachable[start:start + _CHUNK]
        for n in (n_psi, n_fine):
            if not rows.size:
                break
            cost, q, ev = _search(arm, (G[rows], q4[rows]), psi0[rows], near[rows], n, len(rows) <= _SMALL)
            evals[rows] += ev
            has = cost < np.inf
            q_best[rows[has]] = q[has]
            found[rows[has]] = True
            rows = rows[~has]
    return _finish(arm, Tt, c4, q_best, found, evals, n_psi, n_fine, tol)
