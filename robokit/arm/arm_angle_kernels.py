"""Compiled (numba) kernels of the arm-angle parameterisation: joint angles and feasible intervals.

Shimizu et al. (2008), Sec. III-IV: for a target and an elbow sign, every joint of the shoulder and
wrist groups is a function of the arm angle ``psi`` through coefficients ``A sin psi + B cos psi +
C`` (:func:`coefficients`; readable: :func:`robokit.arm.srs_geometry.coefficient_terms`); the joint
limits cut the circle of ``psi`` at split points, between which each branch is feasible or not
(:func:`feasible_intervals`; readable: :mod:`robokit.arm.arm_angle_intervals`). The search for
the best arm angle inside these intervals is in :mod:`robokit.arm.srs_kernels`.

Array layouts: ``G[e, g, k, 3 i + j]`` is coefficient ``k`` (0: ``A`` of ``sin psi``, 1: ``B`` of
``cos psi``, 2: ``C``) of entry ``(i, j)`` of the rotation of group ``g`` (0: shoulder
``Rz(q1) Ry(q2) Rz(q3)``, 1: wrist ``Rz(q5) Ry(q6) Rz(q7)``) for elbow sign ``e`` (0: ``q4 >= 0``).
Interval lists are ``(k, 2)`` arrays with a count.

References
----------
.. [1] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
"""
from __future__ import annotations

import math

import numpy as np

from .jit import njit

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
