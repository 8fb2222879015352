"""Compiled (numba) single-target kernels of the analytic S-R-S IK: one call per target.

Unchecked kernels of :mod:`robokit.arm.ik_analytic`, imported on its first solve (see
:mod:`robokit.arm.jit`). One call does what the readable modules do step by step: check that the
target is an SE(3) matrix (a failure is reported by a code, and the caller lets
:func:`robokit.geometry.as_se3` raise the named error), Shimizu's coefficients, the exact feasible
arm-angle intervals of every branch, the arm angle nearest the start posture inside them (here:
sampling, bounds and Brent's minimisation), and the FK check of the answer. The tests compare every
step with its readable counterpart.

The arm-angle parameterisation (Shimizu et al. 2008, Sec. III-IV): for a target and an elbow sign,
every joint of the shoulder and wrist groups is a function of the arm angle ``psi`` through
coefficients ``A sin psi + B cos psi + C`` (:func:`coefficients`; readable:
:func:`robokit.arm.srs_geometry.coefficient_terms`); the joint limits cut the circle of ``psi`` at
split points, between which each branch is feasible or not (:func:`feasible_intervals`; readable:
:mod:`robokit.arm.arm_angle_intervals`).

Array layouts: ``G[e, g, k, 3 i + j]`` is coefficient ``k`` (0: ``A`` of ``sin psi``, 1: ``B`` of
``cos psi``, 2: ``C``) of entry ``(i, j)`` of the rotation of group ``g`` (0: shoulder
``Rz(q1) Ry(q2) Rz(q3)``, 1: wrist ``Rz(q5) Ry(q6) Rz(q7)``) for elbow sign ``e`` (0: ``q4 >= 0``).
Interval lists are ``(k, 2)`` arrays with a count.

References
----------
.. [1] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
.. [2] R. P. Brent, *Algorithms for Minimization without Derivatives*, Prentice-Hall, 1973, Ch. 5.
"""
from __future__ import annotations

import math

import numpy as np

from .chain_kernels import se3_defect, frames, matmul4, pose_error
from .jit import njit

__all__ = []


#: Most split points of one group's arm-angle circle (3 joints x 3 equations x 2 roots, and -pi).
MAX_SPLITS = 20
_PI = math.pi
#: Feasible arcs whose ends are closer than this [rad] merge (the same split point from two equations).
MERGE = 1e-12
#: ``(numerator entry, denominator entry, denominator sign)`` of the two tangent-type joints of a ZYZ
#: group in its rotation ``M`` (row-major entries): ``a = atan2(M12, M02)``, ``c = atan2(M21, -M20)``.
TANGENT = ((5, 2, 1.0), (7, 6, -1.0))


@njit
def coefficients(T7, d_bs, d_se, d_ew, d_wf, G, q4):
    """Shimizu's ``A, B, C`` of link-7 transform ``T7`` into ``G`` (2, 2, 3, 9) and ``q4`` (2,); returns
    ``cos q4`` (``|.| > 1``: out of reach). The compiled form of ``coefficient_terms``."""
    sw0 = T7[0, 3] - d_wf * T7[0, 2]
    sw1 = T7[1, 3] - d_wf * T7[1, 2]
    sw2 = T7[2, 3] - d_wf * T7[2, 2] - d_bs
    L2 = sw0 * sw0 + sw1 * sw1 + sw2 * sw2
    L = math.sqrt(L2 if L2 > 0 else 1.0)
    c4 = (L2 - (d_se * d_se + d_ew * d_ew)) / (2.0 * d_se * d_ew)
    cc = min(1.0, max(-1.0, c4))
    s4 = math.sqrt(1.0 - cc * cc)
    a4 = math.acos(cc)
    u = np.array([sw0 / L, sw1 / L, sw2 / L])
    h = math.hypot(sw0, sw1)
    m1 = np.array([-sw1 / h, sw0 / h, 0.0]) if h != 0 else np.array([-sw1, 1.0, 0.0])
    c1, s1 = m1[1], -m1[0]
    cphi, sphi = sw2 / L, h / L
    cb, sb = (d_se + d_ew * cc) / L, d_ew * s4 / L
    cols = np.empty((3, 3))                      # columns of M_ref
    X = np.empty((3, 3, 3))                      # A, B, C: column j in X[k, j]
    for e in range(2):
        sign = 1.0 - 2.0 * e
        c2, s2 = cphi * cb - sign * sphi * sb, sphi * cb + sign * cphi * sb
        cols[0, 0], cols[0, 1], cols[0, 2] = c1 * c2, s1 * c2, -s2
        cols[1, 0], cols[1, 1], cols[1, 2] = m1[0], m1[1], m1[2]
        cols[2, 0], cols[2, 1], cols[2, 2] = c1 * s2, s1 * s2, c2
        for j in range(3):
            m = cols[j]
            X[0, j, 0] = u[1] * m[2] - u[2] * m[1]
            X[0, j, 1] = u[2] * m[0] - u[0] * m[2]
            X[0, j, 2] = u[0] * m[1] - u[1] * m[0]
            k = u[0] * m[0] + u[1] * m[1] + u[2] * m[2]
            for i in range(3):
                X[2, j, i] = u[i] * k
                X[1, j, i] = m[i] - X[2, j, i]
        ce, se = cc, sign * s4
        for k in range(3):
            for i in range(3):
                for j in range(3):
                    G[e, 0, k, 3 * i + j] = X[k, j, i]
            P = np.empty((3, 3))                 # X^T R
            for i in range(3):
                for j in range(3):
                    P[i, j] = X[k, i, 0] * T7[0, j] + X[k, i, 1] * T7[1, j] + X[k, i, 2] * T7[2, j]
            for j in range(3):
                G[e, 1, k, j] = ce * P[0, j] + se * P[2, j]
                G[e, 1, k, 3 + j] = P[1, j]
                G[e, 1, k, 6 + j] = ce * P[2, j] - se * P[0, j]
    q4[0], q4[1] = a4, -a4
    return c4


@njit
def group_angles(G, e, g, psi, out):
    """ZYZ angles ``(a, b >= 0, c)`` of group ``g``, elbow ``e`` at arm angle ``psi`` into ``out`` (3,)
    (as :func:`robokit.geometry.zyz_angles`; the mirror branch is ``(a -+ pi, -b, c -+ pi)``)."""
    group_angles_sc(G, e, g, math.sin(psi), math.cos(psi), out)


@njit
def group_angles_sc(G, e, g, s, c, out):
    """:func:`group_angles` from ``s, c = sin psi, cos psi`` (both groups share them)."""
    A, B, C = G[e, g, 0], G[e, g, 1], G[e, g, 2]     # entry ij of the rotation: A[ij] s + B[ij] c + C[ij]
    m02, m12, m22 = A[2] * s + B[2] * c + C[2], A[5] * s + B[5] * c + C[5], A[8] * s + B[8] * c + C[8]
    sb = math.hypot(m02, m12)
    out[1] = math.atan2(sb, m22)
    if sb < 1e-12:
        out[0] = 0.0
        out[2] = math.atan2(A[3] * s + B[3] * c + C[3], A[4] * s + B[4] * c + C[4])
    else:
        out[0] = math.atan2(m12, m02)
        out[2] = math.atan2(A[7] * s + B[7] * c + C[7], -(A[6] * s + B[6] * c + C[6]))


@njit
def branch_angles(ang, mirror, out):
    """Angles (3,) of one branch from the base angles ``ang``: as they are, or mirrored."""
    if mirror:
        out[0] = ang[0] - _PI if ang[0] > 0 else ang[0] + _PI
        out[1] = -ang[1]
        out[2] = ang[2] - _PI if ang[2] > 0 else ang[2] + _PI
    else:
        out[0], out[1], out[2] = ang[0], ang[1], ang[2]


@njit
def sort_prefix(a, n):
    """Sort ``a[:n]`` in place (insertion sort: a few dozen numbers, and it compiles in a fraction of
    the time of ``ndarray.sort``)."""
    for i in range(1, n):
        x = a[i]
        j = i - 1
        while j >= 0 and a[j] > x:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = x


@njit
def roots(alpha, beta, gamma, out, n):
    """Append the roots in ``[-pi, pi)`` of ``alpha sin psi + beta cos psi + gamma = 0`` to ``out``."""
    R = math.hypot(alpha, beta)
    if R < 1e-14 or abs(gamma) > R:
        return n
    phi = math.atan2(beta, alpha)              # alpha sin + beta cos = R sin(psi + phi)
    a = math.asin(-gamma / R)
    for r in (a - phi, _PI - a - phi):
        out[n] = (r + _PI) % (2.0 * _PI) - _PI
        n += 1
    return n


@njit
def group_splits(G, e, g, lo, hi, out):
    """Sorted arm angles (with ``-pi``) where a joint of group ``g`` may meet a limit or wrap; returns
    their number. Tangent type (``a``, ``c``): ``theta = lim`` where ``num cos lim - den sin lim = 0``
    (for both branches; ``lim = pi`` adds the wrap); cosine type (``b``): ``m22 = cos lim``."""
    n = 0
    out[n] = -_PI
    n += 1
    for t in range(2):
        num, den, sd = TANGENT[t]
        joint = 2 * t                                 # a (t = 0) and c (t = 1) of the group
        for lim in (lo[joint], hi[joint], _PI):
            cl, sl = math.cos(lim), math.sin(lim)
            n = roots(G[e, g, 0, num] * cl - sd * G[e, g, 0, den] * sl, G[e, g, 1, num] * cl - sd * G[e, g, 1, den] * sl,
                       G[e, g, 2, num] * cl - sd * G[e, g, 2, den] * sl, out, n)
    for lim in (lo[1], hi[1]):
        n = roots(G[e, g, 0, 8], G[e, g, 1, 8], G[e, g, 2, 8] - math.cos(lim), out, n)
    sort_prefix(out, n)
    return n


@njit
def _inside(x, lo, hi, tol):
    return x[0] >= lo[0] - tol and x[0] <= hi[0] + tol and x[1] >= lo[1] - tol and x[1] <= hi[1] + tol \
        and x[2] >= lo[2] - tol and x[2] <= hi[2] + tol


@njit
def group_intervals(G, e, g, lo, hi, tol, splits, ivl, counts):
    """Feasible arm-angle intervals of group ``g`` (elbow ``e``) for both branches: ``ivl[s]`` (k, 2)
    with ``counts[s]`` intervals (``s = 1``: mirror). Each arc between split points is tested at its
    middle; adjacent feasible arcs (closer than :data:`MERGE`) are merged (the circle is cut at ``-pi``)."""
    n = group_splits(G, e, g, lo, hi, splits)
    ang, x = np.empty(3), np.empty(3)
    counts[0], counts[1] = 0, 0
    for k in range(n):
        a = splits[k]
        b = splits[k + 1] if k + 1 < n else _PI
        if b - a < 1e-15:
            continue
        group_angles(G, e, g, 0.5 * (a + b), ang)
        for s in range(2):
            branch_angles(ang, s == 1, x)
            if _inside(x, lo, hi, tol):
                c = counts[s]
                if c > 0 and ivl[s, c - 1, 1] >= a - MERGE:
                    ivl[s, c - 1, 1] = b
                else:
                    ivl[s, c, 0], ivl[s, c, 1] = a, b
                    counts[s] = c + 1


@njit
def intersect(A, na, B, nb, out):
    """Intersection of two sorted lists of disjoint intervals; returns the count written to ``out``."""
    i = j = n = 0
    while i < na and j < nb:
        a, b = max(A[i, 0], B[j, 0]), min(A[i, 1], B[j, 1])
        if a <= b:
            out[n, 0], out[n, 1] = a, b
            n += 1
        if A[i, 1] < B[j, 1]:
            i += 1
        else:
            j += 1
    return n


@njit
def feasible_intervals(G, q4, lo, hi, tol, out, counts):
    """Feasible arm-angle intervals of all 8 branches (``BRANCHES`` order: elbow, shoulder, wrist
    mirror flags) into ``out`` (8, MAX_SPLITS, 2) and ``counts`` (8,)."""
    splits = np.empty(MAX_SPLITS)
    ivl = np.empty((2, 2, MAX_SPLITS, 2))        # group, branch, interval
    cnt = np.zeros((2, 2), np.int64)
    glo, ghi = np.empty((2, 3)), np.empty((2, 3))
    for g in range(2):
        for j in range(3):
            glo[g, j], ghi[g, j] = lo[4 * g + j], hi[4 * g + j]
    for e in range(2):
        ok4 = q4[e] >= lo[3] - tol and q4[e] <= hi[3] + tol
        for g in range(2):
            group_intervals(G, e, g, glo[g], ghi[g], tol, splits, ivl[g], cnt[g])
        for s in range(2):
            for w in range(2):
                b = 4 * e + 2 * s + w
                counts[b] = intersect(ivl[0, s], cnt[0, s], ivl[1, w], cnt[1, w], out[b]) if ok4 else 0


_SQRT_EPS = math.sqrt(2.220446049250313e-16)
_GOLDEN = 0.5 * (3.0 - math.sqrt(5.0))


@njit
def branch_q(G, q4, b, psi, lo, hi, work, q):
    """Joints (7,) of branch ``b`` at arm angle ``psi``, clipped onto the limits (within the tolerance)."""
    e, s, w = b // 4, (b // 2) % 2, b % 2
    sp, cp = math.sin(psi), math.cos(psi)
    for g in range(2):
        group_angles_sc(G, e, g, sp, cp, work)
        branch_angles(work, (s if g == 0 else w) == 1, q[4 * g:4 * g + 3])
    q[3] = q4[e]
    for j in range(7):
        q[j] = min(hi[j], max(lo[j], q[j]))


@njit
def cost(G, q4, b, psi, lo, hi, q0, work, q):
    """Squared joint distance to ``q0`` of branch ``b`` at ``psi`` (joints left in ``q``)."""
    branch_q(G, q4, b, psi, lo, hi, work, q)
    f = 0.0
    for j in range(7):
        f += (q[j] - q0[j]) ** 2
    return f


@njit
def minimise(G, q4, b, a, c, lo, hi, q0, xatol, work, q):
    """Brent's bounded minimisation (golden section with parabolic steps) of :func:`cost` on
    ``[a, c]``; returns ``(psi, cost, evaluations)``. Brent (1973), Ch. 5, procedure *localmin*."""
    fulc = nfc = xf = a + _GOLDEN * (c - a)
    rat = e = 0.0
    fx = cost(G, q4, b, xf, lo, hi, q0, work, q)
    ffulc = fnfc = fx
    evals = 1
    xm = 0.5 * (a + c)
    tol1 = _SQRT_EPS * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while abs(xf - xm) > tol2 - 0.5 * (c - a) and evals < 200:
        golden = True
        if abs(e) > tol1:                      # try a parabola through the three best points
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            p2 = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * p2 - (xf - nfc) * r
            p2 = 2.0 * (p2 - r)
            if p2 > 0.0:
                p = -p
            p2 = abs(p2)
            r, e = e, rat
            if abs(p) < abs(0.5 * p2 * r) and p > p2 * (a - xf) and p < p2 * (c - xf):
                rat = p / p2
                x = xf + rat
                if x - a < tol2 or c - x < tol2:
                    rat = tol1 if xm >= xf else -tol1
            else:
                golden = True
        if golden:                             # golden-section step into the larger part
            e = (a - xf) if xf >= xm else (c - xf)
            rat = _GOLDEN * e
        x = xf + (1.0 if rat >= 0 else -1.0) * max(abs(rat), tol1)
        fu = cost(G, q4, b, x, lo, hi, q0, work, q)
        evals += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                c = xf
            fulc, ffulc, nfc, fnfc, xf, fx = nfc, fnfc, xf, fx, x, fu
        else:
            if x < xf:
                a = x
            else:
                c = x
            if fu <= fnfc or nfc == xf:
                fulc, ffulc, nfc, fnfc = nfc, fnfc, x, fu
            elif fu <= ffulc or fulc == xf or fulc == nfc:
                fulc, ffulc = x, fu
        xm = 0.5 * (a + c)
        tol1 = _SQRT_EPS * abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
    return xf, fx, evals


#: Step [rad] of the one-sided test at an interval end: is the distance falling into the interval?
END_STEP = 1e-7


@njit
def group_stationary(G, e, g, out):
    """Arm angles where a joint of group ``g`` (elbow ``e``) is stationary, and the middle of each pair
    of a tangent-type joint (where a near-singular joint turns fastest); returns their number (<= 8).
    Between these points every joint of the group is monotonic in ``psi``.

    For ``theta = atan2(n, d)`` with ``n = an sin + bn cos + cn`` (and ``d`` alike), ``dtheta/dpsi``
    has the numerator ``(cn bd - bn cd) sin psi + (an cd - cn ad) cos psi + (an bd - bn ad)``
    (Shimizu et al. 2008, Sec. IV-B); the same for both branches."""
    n = 0
    for t in range(2):
        num, den, sd = TANGENT[t]
        an, bn, cn = G[e, g, 0, num], G[e, g, 1, num], G[e, g, 2, num]
        ad, bd, cd = sd * G[e, g, 0, den], sd * G[e, g, 1, den], sd * G[e, g, 2, den]
        m = roots(cn * bd - bn * cd, an * cd - cn * ad, an * bd - bn * ad, out, n)
        if m == n + 2:
            d = (out[n + 1] - out[n] + _PI) % (2.0 * _PI) - _PI
            out[m] = (out[n] + 0.5 * d + _PI) % (2.0 * _PI) - _PI
            m += 1
        n = m
    a, b = G[e, g, 0, 8], G[e, g, 1, 8]            # cosine type: a sin + b cos + c is stationary at atan2(a, b) (+ pi)
    if math.hypot(a, b) > 1e-14:
        r = math.atan2(a, b)
        out[n] = r
        out[n + 1] = r - _PI if r >= 0 else r + _PI
        n += 2
    return n


@njit
def _combine(base, e, s, w, q4e, lo, hi, q0, work, q):
    """Squared distance to ``q0`` of branch ``(e, s, w)`` from the base angles ``base[e]`` (2, 3)."""
    branch_angles(base[e, 0], s == 1, work)
    q[0], q[1], q[2] = work[0], work[1], work[2]
    branch_angles(base[e, 1], w == 1, work)
    q[4], q[5], q[6] = work[0], work[1], work[2]
    q[3] = q4e
    f = 0.0
    for j in range(7):
        q[j] = min(hi[j], max(lo[j], q[j]))
        f += (q[j] - q0[j]) ** 2
    return f


@njit
def _fill(G, e, psi, out):
    """Base angles (2, 3) of both groups of elbow ``e`` at ``psi``."""
    sp, cp = math.sin(psi), math.cos(psi)
    for g in range(2):                           # a loop: a constant argument would compile a second copy
        group_angles_sc(G, e, g, sp, cp, out[g])


#: Most distinct interval ends of one elbow: the split points of its two groups and ``pi``.
_MAX_ENDS = 2 * MAX_SPLITS + 1


@njit
def _end_cost(G, e, s, w, psi, q4e, lo, hi, q0, epsi, ebase, ne, work, q):
    """:func:`cost` of branch ``(e, s, w)`` at interval end ``psi``, from the angles of both groups at
    ``psi`` computed once per elbow (an end is a split point of one group, so other branches share it)."""
    k = 0
    while k < ne[e] and epsi[e, k] != psi:
        k += 1
    if k == ne[e]:
        epsi[e, k] = psi
        _fill(G, e, psi, ebase[k, e])
        ne[e] = k + 1
    return _combine(ebase[k], e, s, w, q4e, lo, hi, q0, work, q)


@njit
def best_arm_angle(G, q4, lo, hi, tol, q0, psi0, n_psi, xatol, q):
    """The feasible arm angle and branch nearest ``q0``: ``(branch, psi, cost, evaluations)``, the joints
    in ``q``; branch -1 when no arm angle is feasible.

    Each feasible interval of each branch is sampled at its two ends, at the arm angles
    ``-pi + 2 pi k / n_psi``, at the stationary points of its joints (:func:`group_stationary`) and
    at ``psi0`` (the arm angle of ``q0``) inside it. Every local minimum of the samples, lowest
    first, is refined by :func:`minimise` between its neighbours (an interval end only if the
    distance falls into the interval from it), unless a lower bound says the bracket cannot beat
    the best so far: no joint has a stationary point between samples, so each joint's range over
    the bracket is spanned by its three samples, which bounds the distance from below.
    """
    ivl = np.empty((8, MAX_SPLITS, 2))
    counts = np.zeros(8, np.int64)
    feasible_intervals(G, q4, lo, hi, tol, ivl, counts)
    h = 2.0 * _PI / n_psi
    base = np.empty((n_psi, 2, 2, 3))            # arm angle, elbow, group, ZYZ angles; filled when first used
    have = np.zeros((n_psi, 2), np.bool_)
    st = np.empty((2, 17))                       # per elbow: stationary points of both groups and psi0, sorted
    nst = np.zeros(2, np.int64)
    for e in range(2):
        nst[e] = 0
        for g in range(2):
            nst[e] += group_stationary(G, e, g, st[e, nst[e]:])
        st[e, nst[e]] = psi0
        nst[e] += 1
        sort_prefix(st[e], nst[e])
    sbase = np.empty((17, 2, 2, 3))              # the same at the stationary points (shared by 4 branches)
    shave = np.zeros((17, 2), np.bool_)
    epsi = np.empty((2, _MAX_ENDS))              # and at the interval ends met so far (split points of
    ebase = np.empty((_MAX_ENDS, 2, 2, 3))       # either group, shared by the branches of an elbow)
    ne = np.zeros(2, np.int64)
    ps, fs, qs = np.empty(n_psi + 20), np.empty(n_psi + 20), np.empty((n_psi + 20, 7))
    ncand = 0
    cand = np.empty((8 * (n_psi + 2 * MAX_SPLITS + 17), 6))   # value, branch, left, centre, right, bound
    work, qt = np.empty(3), np.empty(7)
    evals = 0                                    # each fill of both groups' angles and each cost counts one
    for b in range(8):
        e, s, w = b // 4, (b // 2) % 2, b % 2
        for k in range(counts[b]):
            a, c = ivl[b, k, 0], ivl[b, k, 1]
            n = 0
            ps[n], fs[n] = a, _end_cost(G, e, s, w, a, q4[e], lo, hi, q0, epsi, ebase, ne, work, qs[n])
            n += 1
            j = int(math.floor((a + _PI) / h)) + 1
            t = 0
            while True:                                # grid and stationary points inside, in order
                xg = -_PI + h * j if j < n_psi else np.inf
                while t < nst[e] and st[e, t] <= a:
                    t += 1
                xs = st[e, t] if t < nst[e] else np.inf
                if min(xg, xs) >= c:
                    break
                if xg <= xs:
                    if not have[j, e]:
                        _fill(G, e, -_PI + h * j, base[j, e])
                        have[j, e] = True
                        evals += 1
                    ps[n], fs[n] = xg, _combine(base[j], e, s, w, q4[e], lo, hi, q0, work, qs[n])
                    j += 1
                    if xs == xg:
                        t += 1
                else:
                    if not shave[t, e]:
                        _fill(G, e, xs, sbase[t, e])
                        shave[t, e] = True
                        evals += 1
                    ps[n], fs[n] = xs, _combine(sbase[t], e, s, w, q4[e], lo, hi, q0, work, qs[n])
                    t += 1
                n += 1
            if c > a:
                ps[n], fs[n] = c, _end_cost(G, e, s, w, c, q4[e], lo, hi, q0, epsi, ebase, ne, work, qs[n])
                n += 1
            for i in range(n):
                if (i > 0 and fs[i] > fs[i - 1]) or (i < n - 1 and fs[i] > fs[i + 1]):
                    continue
                left, right = max(i - 1, 0), min(i + 1, n - 1)
                cand[ncand, 0], cand[ncand, 1], cand[ncand, 3] = fs[i], b, ps[i]
                cand[ncand, 2], cand[ncand, 4] = ps[left], ps[right]
                bound = 0.0                      # every joint is monotonic between samples: its range
                for jj in range(7):              # over the bracket is spanned by the three samples
                    x_lo = min(qs[left, jj], qs[i, jj], qs[right, jj])
                    x_hi = max(qs[left, jj], qs[i, jj], qs[right, jj])
                    d = x_lo - q0[jj] if q0[jj] < x_lo else (q0[jj] - x_hi if q0[jj] > x_hi else 0.0)
                    bound += d * d
                cand[ncand, 5] = bound
                ncand += 1
    evals += ne[0] + ne[1]
    if ncand == 0:
        return -1, 0.0, np.inf, evals
    order = np.empty(ncand, np.int64)           # candidates by value, ties in sampling order (a stable
    for i in range(ncand):                       # insertion sort, as np.argsort(kind="mergesort"))
        x, j = cand[i, 0], i - 1
        while j >= 0 and cand[order[j], 0] > x:
            order[j + 1] = order[j]
            j -= 1
        order[j + 1] = i
    best, best_b, best_psi = cand[order[0], 0], int(cand[order[0], 1]), cand[order[0], 3]
    for r in range(ncand):
        f0, b, left, x0, right = cand[order[r], 0], int(cand[order[r], 1]), cand[order[r], 2], cand[order[r], 3], \
            cand[order[r], 4]
        if right - left <= 1e-12 or cand[order[r], 5] >= best:   # cannot beat the best: skip
            continue
        if x0 == left or x0 == right:            # an interval end: refine only if the distance falls inwards
            inward = x0 + END_STEP if x0 == left else x0 - END_STEP
            evals += 1
            if cost(G, q4, b, inward, lo, hi, q0, work, qt) >= f0:
                continue
        x, fx, ev = minimise(G, q4, b, left, right, lo, hi, q0, xatol, work, qt)
        evals += ev
        if fx < best:
            best, best_b, best_psi = fx, b, x
    branch_q(G, q4, best_b, best_psi, lo, hi, work, q)
    return best_b, best_psi, best, evals


@njit
def solve(T, q0, psi0, base_inv, tool_inv, plain, dims, lo, hi, tol, se3_tol, n_psi, xatol, K, U, V, offset, base,
          tool, q, info):
    """One analytic S-R-S solve from start posture ``q0`` with arm angle ``psi0``. Returns a status: 0 solved (FK-checked errors in ``info``), 1 ``T`` is
    not SE(3) within ``se3_tol``, 2 out of reach, 3 no feasible arm angle, 4 ``q0`` not finite.
    ``info = (position error, orientation error, evaluations, cos q4, psi)``; ``q`` gets the answer
    (``q0`` unless solved)."""
    for j in range(7):
        if not math.isfinite(q0[j]):
            return 4
        q[j] = q0[j]
    if se3_tol > 0 and se3_defect(T, se3_tol):
        return 1
    T7 = T if plain else matmul4(matmul4(base_inv, T, np.empty((4, 4))), tool_inv, np.empty((4, 4)))
    G, q4 = np.empty((2, 2, 3, 9)), np.empty(2)
    c4 = coefficients(T7, dims[0], dims[1], dims[2], dims[3], G, q4)
    info[3] = c4
    if not abs(c4) <= 1.0 + 1e-12:
        return 2
    b, psi, f, evals = best_arm_angle(G, q4, lo, hi, tol, q0, psi0, n_psi, xatol, q)
    info[2], info[4] = evals, psi
    if b < 0:
        return 3
    F, e = np.empty((8, 4, 4)), np.empty(6)
    pos2, rot2 = pose_error(T, frames(q, K, U, V, offset, base, tool, F), e)
    info[0], info[1] = math.sqrt(pos2), math.sqrt(rot2)
    return 0


@njit
def solve_batch(T, q0, psi0, base_inv, tool_inv, plain, dims, lo, hi, tol, n_psi, xatol, K, U, V, offset, base,
                tool, q, status, info):
    """:func:`solve` for every target ``T[i]`` (already checked) with start posture ``q0[i]``."""
    for i in range(T.shape[0]):
        status[i] = solve(T[i], q0[i], psi0[i], base_inv, tool_inv, plain, dims, lo, hi, tol, -1.0, n_psi, xatol, K, U, V,
                          offset, base, tool, q[i], info[i])
