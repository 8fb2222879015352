"""Exact feasible arm-angle intervals of an S-R-S arm (Shimizu et al. 2008, Sec. IV), readable form.

For a fixed target, every joint of an S-R-S arm is a function of the arm angle ``psi``. With the
shoulder (or wrist) rotation ``M(psi) = A sin psi + B cos psi + C`` (:mod:`robokit.arm.srs_geometry`)
and the ZYZ joints of each spherical group:

* **tangent type** (``q1, q3, q5, q7``): ``theta = atan2(an sin psi + bn cos psi + cn, ad sin psi +
  bd cos psi + cd)``, e.g. ``q1 = atan2(M12, M02)``. It meets the value ``lim`` where
  ``(an cos lim - ad sin lim) sin psi + (bn cos lim - bd sin lim) cos psi + (cn cos lim - cd sin lim)
  = 0``: at most two arm angles per value, in closed form. Where numerator and denominator vanish
  together (Shimizu's singular case) the joint is undefined and jumps by ``pi``; such a point solves
  that equation for every ``lim``, so it is a split point too. ``lim = pi`` adds the points where
  the angle wraps.
* **cosine type** (``q2, q6``): ``theta = +-acos(a sin psi + b cos psi + c)``: it meets ``lim`` where
  ``a sin psi + b cos psi + c = cos lim`` (the same equation for both signs).

Between consecutive split points no joint crosses a limit or jumps, so one test at the middle of
each arc decides it for all of the arc; the feasible set of a branch is the union of its feasible
arcs (the intersection over its joints). :func:`feasible_arm_angles` computes these intervals and
:func:`ik_srs_readable` picks the best arm angle inside them, both step by step with the
library's checked functions; :func:`robokit.arm.ik_srs` does the same in one compiled call (the
tests compare them).

References
----------
.. [1] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
.. [2] R. P. Brent, *Algorithms for Minimization without Derivatives*, Prentice-Hall, 1973, Ch. 5.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from ..geometry import as_se3
from ..validation import as_int
from .chain import Chain
from .ik_analytic import BRANCHES, SRSArm

__all__ = ["feasible_arm_angles", "ik_srs_readable", "split_points"]

#: ``(numerator entry, denominator entry, denominator sign)`` of the tangent-type joints of a ZYZ
#: group in its rotation ``M`` (row-major entries): ``a = atan2(M12, M02)``, ``c = atan2(M21, -M20)``.
_TANGENT = {0: (5, 2, 1.0), 2: (7, 6, -1.0)}


def _roots(alpha: float, beta: float, gamma: float) -> list[float]:
    """Arm angles in ``[-pi, pi)`` with ``alpha sin psi + beta cos psi + gamma = 0`` (closed form)."""
    R = np.hypot(alpha, beta)
    if R < 1e-14 or abs(gamma) > R:
        return []
    phi = np.arctan2(beta, alpha)               # alpha sin + beta cos = R sin(psi + phi)
    a = np.arcsin(-gamma / R)
    return [float((r + np.pi) % (2 * np.pi) - np.pi) for r in (a - phi, np.pi - a - phi)]


def _stationary(coeffs, e: int) -> np.ndarray:
    """Arm angles where a joint of elbow sign ``e`` is stationary, and the middle of each pair of a
    tangent-type joint (q1, q3, q5, q7; where a joint near Shimizu's singular case turns fastest).

    ``d/dpsi atan2(n, d)`` has the numerator ``(cn bd - bn cd) sin psi + (an cd - cn ad) cos psi +
    (an bd - bn ad)`` (Shimizu et al. 2008, Sec. IV-B), the same for both branches."""
    A, B, C = coeffs[0][0].reshape(3, 4, 9)
    out = []
    for g in range(2):
        eg = 2 * e + g
        for num, den, sd in _TANGENT.values():
            an, bn, cn = A[eg, num], B[eg, num], C[eg, num]
            ad, bd, cd = sd * A[eg, den], sd * B[eg, den], sd * C[eg, den]
            r = _roots(cn * bd - bn * cd, an * cd - cn * ad, an * bd - bn * ad)
            if len(r) == 2:
                d = (r[1] - r[0] + np.pi) % (2 * np.pi) - np.pi
                r.append((r[0] + 0.5 * d + np.pi) % (2 * np.pi) - np.pi)
            out += r
        if np.hypot(A[eg, 8], B[eg, 8]) > 1e-14:       # cosine type: stationary at atan2(a, b) and opposite
            r0 = float(np.arctan2(A[eg, 8], B[eg, 8]))
            out += [r0, r0 - np.pi if r0 >= 0 else r0 + np.pi]
    return np.sort(out)


def split_points(chain: Chain, T: Any) -> np.ndarray:
    """Arm angles where a joint of an S-R-S arm may meet one of its limits, jump or wrap.

    Parameters
    ----------
    chain : Chain
        An S-R-S chain (see :class:`~robokit.arm.SRSArm`).
    T : array_like, shape (4, 4)
        Target flange transform.

    Returns
    -------
    numpy.ndarray, shape (k,)
        Sorted arm angles in ``[-pi, pi)`` (``-pi`` always included), for every joint, both elbow
        signs and both branches of each spherical group; empty when the target is out of reach.

    Raises
    ------
    ValueError
        If ``T`` is not an SE(3) matrix or the chain is not S-R-S.

    Notes
    -----
    Shimizu et al. (2008), Sec. IV: tangent-type joints (Eqs. (23)-(24)) and cosine-type joints
    (Eq. (25)) meet a limit where a sinusoid in ``psi`` vanishes.

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> psi = split_points(arm, arm.fk(np.radians([35, 50, -40, -75, 60, 45, 20])))
    >>> bool(psi[0] == -np.pi), bool(np.all(np.diff(psi) >= 0))
    (True, True)
    """
    arm = SRSArm(chain)
    G, q4, c4 = arm.coefficients(arm.to_link7(as_se3(T, "T")))
    if abs(c4[0]) > 1.0 + 1e-12:
        return np.zeros(0)
    A, B, C = G[0].reshape(3, 4, 9)             # per (elbow, group): the 9 entries of M
    lo, hi = chain.qmin, chain.qmax
    out = [-np.pi]
    for eg in range(4):
        g = eg % 2
        for joint, (num, den, sd) in _TANGENT.items():
            for lim in (lo[4 * g + joint], hi[4 * g + joint], np.pi):
                cl, sl = np.cos(lim), np.sin(lim)
                out += _roots(A[eg, num] * cl - sd * A[eg, den] * sl, B[eg, num] * cl - sd * B[eg, den] * sl,
                              C[eg, num] * cl - sd * C[eg, den] * sl)
        for lim in (lo[4 * g + 1], hi[4 * g + 1]):                     # cosine type: M22 = cos lim
            out += _roots(A[eg, 8], B[eg, 8], C[eg, 8] - np.cos(lim))
    return np.sort(out)


def feasible_arm_angles(chain: Chain, T: Any) -> list[np.ndarray]:
    """The exact sets of arm angles at which each of the 8 IK branches stays within the joint limits.

    Parameters
    ----------
    chain : Chain
        An S-R-S chain (see :class:`~robokit.arm.SRSArm`), e.g. :func:`~robokit.arm.iiwa14`.
    T : array_like, shape (4, 4)
        Target flange transform.

    Returns
    -------
    list of 8 numpy.ndarray, shape (k, 2)
        For branch ``b`` (``robokit.arm.ik_analytic.BRANCHES[b]`` = elbow, shoulder, wrist mirror
        flags, as :func:`~robokit.arm.ik_srs_branches` orders them), sorted disjoint intervals
        ``[psi_lo, psi_hi]`` in ``[-pi, pi]`` [rad]; an interval through ``+-pi`` appears as two
        pieces, ``[a, pi]`` and ``[-pi, b]``. All empty when the target is out of reach. Joints
        within :data:`~robokit.arm.LIMIT_TOL` of a limit count as inside.

    Raises
    ------
    ValueError
        If ``T`` is not an SE(3) matrix or the chain is not S-R-S.

    Notes
    -----
    Shimizu et al. (2008), Sec. IV: the interval boundaries of every joint in closed form
    (:func:`split_points`), the feasible set of a branch as the intersection over its joints.

    Examples
    --------
    The arm angle of a configuration lies in the feasible set of its own branch:

    >>> from robokit.arm import arm_angle, iiwa14
    >>> arm = iiwa14()
    >>> q = np.radians([35, 50, -40, -75, 60, 45, 20])           # q2, q4, q6 signs: branch 4
    >>> intervals = feasible_arm_angles(arm, arm.fk(q))
    >>> psi = arm_angle(arm, q)
    >>> bool(np.any((intervals[4][:, 0] <= psi) & (psi <= intervals[4][:, 1])))
    True
    """
    arm = SRSArm(chain)
    T = as_se3(T, "T")
    splits = split_points(chain, T)
    if not splits.size:
        return [np.zeros((0, 2)) for _ in BRANCHES]
    ends = np.append(splits, np.pi)
    keep = np.diff(ends) > 1e-15
    lo, hi = ends[:-1][keep], ends[1:][keep]
    coeffs = arm.coefficients(arm.to_link7(T))
    q = arm.joints(coeffs, (0.5 * (lo + hi))[None])[0]              # (arcs, 8 branches, 7 joints)
    ok = chain.within_limits(q.reshape(-1, 7)).reshape(q.shape[:2])
    out = []
    for b in range(len(BRANCHES)):
        pieces = []
        for a, c in zip(lo[ok[:, b]], hi[ok[:, b]]):
            if pieces and pieces[-1][1] >= a - 1e-12:    # adjacent feasible arcs merge (srs_kernels.MERGE)
                pieces[-1][1] = c
            else:
                pieces.append([a, c])
        out.append(np.array(pieces).reshape(-1, 2))
    return out


def ik_srs_readable(chain: Chain, T: Any, q0: Any = None, *, n_psi: int = 32) -> tuple[np.ndarray, float, float]:
    """The feasible arm angle and branch nearest a start posture, step by step (the readable form of
    :func:`~robokit.arm.ik_srs`'s search).

    Parameters
    ----------
    chain : Chain
        An S-R-S chain.
    T : array_like, shape (4, 4)
        Target flange transform.
    q0 : array_like, shape (7,), optional
        Start posture; the middle of the joint ranges by default.
    n_psi : int, default 32
        Each feasible interval is sampled at its ends, at the arm angles ``-pi + 2 pi k / n_psi``
        at the stationary points of the joints and at ``q0``'s arm angle inside it;
        every local minimum of
        the samples is refined by bounded minimisation between its neighbours (see
        :func:`~robokit.arm.ik_srs_batch`).

    Returns
    -------
    q : numpy.ndarray, shape (7,)
        The joints (``q0`` if no arm angle is feasible or the target is out of reach).
    psi : float
        Their arm angle (NaN if none).
    cost : float
        ``sum((q - q0)^2)`` (inf if none).

    Raises
    ------
    ValueError
        On a non-SE(3) target, a bad ``q0`` or ``n_psi`` or a non-S-R-S chain.

    Notes
    -----
    Optimal means: the smallest squared joint distance to ``q0`` over every branch and every
    feasible arm angle (:func:`feasible_arm_angles`), found by Brent's bounded minimisation
    (Brent 1973, Ch. 5; ``scipy.optimize.minimize_scalar``) inside each feasible interval.

    Examples
    --------
    >>> from robokit.arm import iiwa14
    >>> arm = iiwa14()
    >>> q = np.radians([35, 50, -40, -75, 60, 45, 20])
    >>> q_best, psi, cost = ik_srs_readable(arm, arm.fk(q), q0=q)
    >>> bool(np.abs(q_best - q).max() < 1e-6)
    True
    """
    arm = SRSArm(chain)
    T = as_se3(T, "T")
    q0 = arm.mid if q0 is None else chain.as_q(q0, "q0")
    h = 2 * np.pi / as_int(n_psi, "n_psi", minimum=4)
    coeffs = arm.coefficients(arm.to_link7(T))

    def joints(b, psi):
        return np.clip(arm.joints(coeffs, np.atleast_1d(psi)[None])[0, :, b], chain.qmin, chain.qmax)

    def cost(b, psi):
        return ((joints(b, psi) - q0) ** 2).sum(-1)

    grid = -np.pi + h * np.arange(n_psi)
    psi0 = arm.arm_angle(q0)                                # the start posture's own arm angle is a sample too
    stationary = [np.append(_stationary(coeffs, e), psi0) for e in range(2)]
    candidates = []                                         # (sampled distance, branch, left, centre, right)
    for b, intervals in enumerate(feasible_arm_angles(chain, T)):
        for a, c in intervals:
            extra = np.concatenate([grid, stationary[b // 4]])
            ps = np.concatenate([[a], np.unique(extra[(extra > a) & (extra < c)]), [c] if c > a else []])
            fs = cost(b, ps)
            for i in range(len(ps)):
                if (i > 0 and fs[i] > fs[i - 1]) or (i < len(ps) - 1 and fs[i] > fs[i + 1]):
                    continue                                # not a local minimum of the samples
                candidates.append((fs[i], b, ps[max(i - 1, 0)], ps[i], ps[min(i + 1, len(ps) - 1)]))
    if not candidates:
        return q0.copy(), float("nan"), float("inf")
    candidates.sort(key=lambda x: x[0])                     # stable: ties keep branch order
    best = (candidates[0][0], candidates[0][1], candidates[0][3])
    for f0, b, left, x0, right in candidates:               # every local minimum, lowest first
        if right - left <= 1e-12:
            continue
        if x0 in (left, right):                             # an interval end: does the distance fall inwards?
            if cost(b, x0 + (1e-7 if x0 == left else -1e-7))[0] >= f0:
                continue
        r = minimize_scalar(lambda x: cost(b, x)[0], bounds=(left, right), method="bounded", options={"xatol": 1e-10})
        if r.fun < best[0]:
            best = (float(r.fun), b, float(r.x))
    f, b, psi = best
    if not np.isfinite(f):
        return q0.copy(), float("nan"), float("inf")
    return joints(b, psi)[0], psi, float(f)
