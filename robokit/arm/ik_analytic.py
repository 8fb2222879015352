"""Analytic inverse kinematics of S-R-S 7-DOF arms (e.g. the KUKA LBR iiwa) with the arm angle.

The method is Shimizu et al.'s (2008); its first steps are the separation of position and posture
that Huang & Jiang (2013) also start from (our reading of their own route, a Newton iteration on
joints 1-4, is :func:`robokit.arm.ik_position_posture`):

1. the wrist centre ``W = p - d_wf z_7`` depends only on the target transform;
2. joints 1-4 place the wrist centre: a position problem of a 4-DOF arm, redundant by one. The
   elbow angle ``q4`` follows from the triangle shoulder-elbow-wrist (law of cosines); the
   remaining freedom is the rotation of that triangle about the shoulder-wrist line, the *arm
   angle* ``psi`` of Shimizu et al. (2008), Sec. III;
3. joints 5-7 produce the orientation in closed form (a ZYZ Euler decomposition);
4. the exact feasible arm-angle intervals of Shimizu et al. (2008), Sec. IV
   (:mod:`robokit.arm.arm_angle_intervals`) bound a one-dimensional minimisation over ``psi``
   that picks the valid solution closest to a preferred configuration ``q0``.

The solvers run as one compiled call per target (:mod:`robokit.arm.srs_kernels`, numba, compiled
on the first solve and cached on disk); :func:`robokit.arm.arm_angle_intervals.ik_srs_readable`
is the same search step by step.

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
import math
from typing import Any

import numpy as np

from ..geometry import as_se3, zyz_angles
from ..validation import array_ndim, as_array, as_int, as_positive
from .chain import LIMIT_TOL, Chain
from .result import IKBatchResult, IKResult, verify
from .srs_geometry import ARRAY, SCALAR, arm_angle_terms, coefficient_terms, mirror_angle

_KERNELS = None

__all__ = ["SRSArm", "arm_angle", "ik_srs_branches", "ik_srs", "ik_srs_batch", "BRANCHES"]

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
        # what the compiled kernels take (robokit.arm.srs_kernels), as plain writable float arrays
        self.kernel_args = (self._base_inv.copy(), self._tool_inv.copy(), self._plain,
                            np.array([self.d_bs, self.d_se, self.d_ew, self.d_wf]), chain.qmin.copy(), chain.qmax.copy())
        self.chain_args = tuple(np.array(x, dtype=float) for x in (*chain.link_terms, chain.offset, chain.base,
                                                                     chain.tool))
        self.mid = 0.5 * (chain.qmin + chain.qmax)

    # --- the decomposition, step by step ---------------------------------------------------------
    def to_link7(self, T: np.ndarray) -> np.ndarray:
        """Unchecked: target flange transforms (N, 4, 4) -> link-7 transforms in frame 0."""
        return T if self._plain else self._base_inv @ T @ self._tool_inv

    def out_of_reach(self, L: float, *, known: bool = False) -> str | None:
        """Unchecked: why a shoulder-wrist distance ``L`` [m] is out of reach, or ``None`` if it is not
        (``known=True``: a kernel already found it out of reach; say so whatever ``L`` rounds to)."""
        if not known and abs(self.d_se - self.d_ew) <= L <= self.d_se + self.d_ew:
            return None
        return (f"out of reach: shoulder-wrist distance {L:.4f} m outside "
                f"[{abs(self.d_se - self.d_ew):.4f}, {self.d_se + self.d_ew:.4f}] m")

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
        abc = zyz_angles((basis @ G).reshape(N, K, 2, 2, 3, 3), validate=False)   # of A sin psi + B cos psi + C
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


def _srs(chain: Chain) -> SRSArm:
    """The (validated) S-R-S geometry of a chain, built once per chain object."""
    if not isinstance(chain, Chain):
        raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
    return _srs_cached(chain)


@functools.lru_cache(maxsize=16)
def _srs_cached(chain: Chain) -> SRSArm:
    return SRSArm(chain)


def _as_psi(psi: Any) -> float:
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
    return arm.arm_angle(chain.as_q(q, batch=array_ndim(q, "q") == 2))


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
    p = _as_psi(psi)
    coeffs = arm.coefficients(T7)
    if abs(coeffs[2][0]) > 1.0 + 1e-12:
        return np.zeros((0, 7))
    q = arm.joints(coeffs, np.array([[p]]))[0, 0]
    if within_limits:
        q = np.clip(q[chain.within_limits(q)], chain.qmin, chain.qmax)
    return q


def _kernels():
    """The compiled kernels, imported (and numba loaded) on the first solve, never by ``import robokit``."""
    global _KERNELS
    if _KERNELS is None:
        from . import srs_kernels
        _KERNELS = srs_kernels
    return _KERNELS


#: Compiled entry points not yet called in this process: their first call may compile (and says so).
_FIRST = {"solve", "solve_batch"}


def _first_call(name: str):
    """The one-line compile notice before kernel ``name``'s first call (:func:`robokit.arm.jit.compile_notice`)."""
    _FIRST.discard(name)
    from .jit import compile_notice
    return compile_notice(f"srs_{name}", "the analytic IK solver" if name == "solve" else "the batched analytic IK solver")


def _compiled(record) -> None:
    from .jit import compiled
    compiled(record)


#: Tolerance of the SE(3) check on targets (:data:`robokit.geometry.rotations.ROTATION_TOL`).
_SE3_TOL = 1e-6
#: Arm-angle tolerance of the bounded minimisation [rad].
_XATOL = 1e-10


def _options(n_psi: Any, tol: Any):
    if type(n_psi) is int and type(tol) is float and n_psi == 32 and tol == 1e-6:   # the defaults
        return 32, 1e-6
    return as_int(n_psi, "n_psi", minimum=4), as_positive(tol, "tol")


def _reason(arm: SRSArm, status: int, ok: bool, pos: float, rot: float, c4: float) -> str:
    """Why a solve failed (or ``"converged"``)."""
    if status == 2:
        L = math.sqrt(max(0.0, c4 * 2 * arm.d_se * arm.d_ew + arm.d_se**2 + arm.d_ew**2))
        return arm.out_of_reach(L, known=True)
    if status == 3:
        return "no arm angle keeps all joints within limits (the exact feasible arm-angle set is empty)"
    if not ok:
        return f"pose error above tolerance (position {pos:.2e} m, orientation {rot:.2e} rad)"
    return "converged"


def ik_srs(chain: Chain, T: Any, q0: Any = None, *, tol: float = 1e-6, n_psi: int = 32) -> IKResult:
    """Analytic IK of an S-R-S arm for one target: the valid solution closest to ``q0``.

    Parameters and result as :func:`ik_srs_batch`, for one transform ``T`` (4, 4) and one preferred
    configuration ``q0`` (7,). One compiled call does the whole solve, the check of ``T`` included
    (a target that fails it is handed to :func:`robokit.geometry.as_se3`, which names the error).

    Raises
    ------
    ValueError
        On a non-SE(3) target, a ``q0`` of the wrong shape or a chain that is not S-R-S.

    Notes
    -----
    The arm angle and the exact feasible intervals of Shimizu et al. (2008), Secs. III-IV, after
    the separation of position and posture (as in Huang & Jiang 2013).

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> T = arm.fk(np.radians([35, 50, -40, -75, 60, 45, 20]))
    >>> r = ik_srs(arm, T, np.radians([0, 30, 0, -60, 0, 60, 0]))
    >>> r.success, r.reason, r.position_error < 1e-9
    (True, 'converged', True)
    """
    arm = _srs(chain)
    if not (type(T) is np.ndarray and T.dtype == np.float64 and T.shape == (4, 4)):
        if array_ndim(T, "T") != 2:
            raise ValueError(f"T: expected one transform of shape (4, 4), got shape {np.shape(T)}")
        T = as_se3(T, "T")
    if not T.flags.c_contiguous:
        T = np.ascontiguousarray(T)
    if q0 is None:
        near = arm.mid
    elif type(q0) is np.ndarray and q0.dtype == np.float64 and q0.shape == (7,) and q0.flags.c_contiguous:
        near = q0
    else:
        if array_ndim(q0, "q0") != 1:
            raise ValueError(f"q0: expected one joint vector of shape (7,), got shape {np.shape(q0)}")
        near = chain.as_q(q0, "q0")
    n_psi, tol = _options(n_psi, tol)
    K = _kernels()
    q, info = np.empty(7), np.zeros(5)
    args = (arm.kernel_args + (LIMIT_TOL,), (_XATOL,) + arm.chain_args)
    psi0 = arm.arm_angle(near) if math.isfinite(near.sum()) else 0.0
    record = _first_call("solve") if "solve" in _FIRST else None
    status = K.solve(T, near, psi0, *args[0], _SE3_TOL, n_psi, *args[1], q, info)
    if record is not None:
        _compiled(record)
    if status == 1:
        T = as_se3(T, "T")                      # raises the named error (or passes within rounding)
        status = K.solve(T, near, psi0, *args[0], -1.0, n_psi, *args[1], q, info)
    if status == 4:
        chain.as_q(q0, "q0")                 # raises: NaN or infinity in q0
    if status == 0:
        pos, rot = float(info[0]), float(info[1])
        e = math.hypot(pos, rot)
    else:
        v = verify(chain, T[None], q[None], tol, validate=False)
        pos, rot, e = float(v.position_error[0]), float(v.orientation_error[0]), float(v.residual[0])
    ok = status == 0 and pos < tol and rot < tol
    return IKResult(q=q, success=ok, reason=_reason(arm, status, ok, pos, rot, float(info[3])), residual=e,
                    iterations=int(info[2]), position_error=pos, orientation_error=rot)


def ik_srs_batch(chain: Chain, T: Any, q0: Any = None, *, tol: float = 1e-6, n_psi: int = 32) -> IKBatchResult:
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
    tol : float, default 1e-6
        Tolerance on the FK-verified position error [m] and orientation error [rad].
    n_psi : int, default 32
        Bracketing resolution of the minimisation: each feasible arm-angle interval is sampled at
        its ends and at most ``2 pi / n_psi`` apart before the bounded minimisation.

    Returns
    -------
    IKBatchResult
        ``success[i]`` is true only when the FK of ``q[i]`` is within ``tol`` of the target and
        every joint is within its limits; ``reason[i]`` says why not otherwise. ``iterations[i]``
        counts the branch evaluations.

    Raises
    ------
    ValueError
        On non-SE(3) targets, a wrong-shaped ``q0`` or a chain that is not S-R-S.

    Notes
    -----
    *Optimal* here means: over the 8 branches and every arm angle ``psi`` at which all joints are
    within their limits (:data:`~robokit.arm.LIMIT_TOL`), the solution with the smallest squared
    joint distance ``sum((q - q0)^2)`` to the preferred configuration. The feasible arm angles are
    the exact intervals of Shimizu et al. (2008), Sec. IV (interval boundaries in closed form for
    the tangent-type joints q1, q3, q5, q7 and the cosine-type joints q2, q6;
    :func:`~robokit.arm.arm_angle_intervals.feasible_arm_angles`). Inside each interval the
    distance is sampled at the interval's ends, at the arm angles ``-pi + 2 pi k / n_psi``, at
    the stationary points of the joints (and the middle of each pair of a tangent-type joint, where
    a joint near Shimizu's singular case turns fastest) and at the arm angle of ``q0`` inside it. Every
    local minimum of the samples is refined between its neighbouring samples by Brent's bounded
    minimisation (Brent 1973, Ch. 5), to its tolerance of about ``1.5e-8 |psi|`` rad (an interval
    end only if the distance falls into the interval; skipped when the joints' ranges between the
    samples, where each joint is monotonic, prove it cannot beat the best so far). So the answer is the global optimum (a
    boundary optimum exactly, in closed form; an interior one to that tolerance) unless two local
    minima of the distance lie between the same two samples. A joint within the tolerance of a
    limit is put exactly on it. Each target
    is one compiled call (:mod:`robokit.arm.srs_kernels`); the answers equal :func:`ik_srs`'s.

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
    Tt = np.ascontiguousarray(as_se3(T, "T", batch=True))
    N = Tt.shape[0]
    n_psi, tol = _options(n_psi, tol)
    if q0 is None:
        near = np.broadcast_to(arm.mid, (N, 7)).copy()
    else:
        near = chain.as_q(q0, "q0", batch=True)
        if near.shape[0] == 1 and N > 1:
            near = np.broadcast_to(near, (N, 7))
        elif near.shape[0] != N:
            raise ValueError(f"q0: expected one joint vector or {N} (one per target), got {near.shape[0]}")
        near = np.ascontiguousarray(near, dtype=float)
    q, status, info = np.empty((N, 7)), np.empty(N, np.int64), np.zeros((N, 5))
    K = _kernels()
    record = _first_call("solve_batch") if "solve_batch" in _FIRST else None
    K.solve_batch(Tt, near, np.ascontiguousarray(arm.arm_angle(near)), *arm.kernel_args, LIMIT_TOL, n_psi, _XATOL, *arm.chain_args,
                  q, status, info)
    if record is not None:
        _compiled(record)
    out = verify(chain, Tt, q, tol, validate=False)
    found = status == 0
    out.success &= found
    for i in np.flatnonzero(~out.success):
        out.reason[i] = _reason(arm, int(status[i]), False, out.position_error[i], out.orientation_error[i],
                                float(info[i, 3]))
    out.iterations = info[:, 2].astype(int)
    return out
