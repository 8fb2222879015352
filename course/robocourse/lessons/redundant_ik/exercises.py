"""Exercises of assignment 06 (redundant 7-DOF arm IK): from one DH transform to a null-space step,
a resolved-rate tracking loop with a secondary task, and an open exercise, a whole IK solver for the
iiwa by any method.

Inputs are generated from the KUKA LBR iiwa 14 R820 and the Franka Panda of :mod:`robokit.arm`
(random configurations inside the joint limits), plus small hand-checkable chains and random DH
chains. The notebook's arm (DH table, limits, link lengths) and the tracking loop's settings come
from :func:`data`, which takes them from :func:`robokit.arm.iiwa14`, the arm the lesson runs.

References
----------
.. [1] L. Huang and R. Jiang, "A new method of inverse kinematics solution for industrial 7DOF robot"
   (question 4 of the course's assignment).
.. [2] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
.. [3] B. Siciliano, L. Sciavicco, L. Villani and G. Oriolo, *Robotics: Modelling, Planning and
   Control*, Springer, 2009 (Sec. 3.1.3, the geometric Jacobian; Sec. 3.7, inverse kinematics
   algorithms).
.. [4] A. Liégeois, "Automatic supervisory control of the configuration and behavior of multibody
   mechanisms", *IEEE Transactions on Systems, Man, and Cybernetics* 7(12), 868-871, 1977.
.. [5] C. W. Wampler, "Manipulator inverse kinematic solutions based on vector formulations and
   damped least-squares methods", *IEEE Transactions on Systems, Man, and Cybernetics* 16(1),
   93-101, 1986.
"""
from __future__ import annotations

import numpy as np

from typing import Any

from robokit.arm import (LIMIT_TOL, dh_fk, dh_jacobian, dh_transform, elbow_angle, feasible_arm_angles, geometric_jacobian,
                         ik_srs_readable, limit_distance_gradient, null_space_step, panda, shoulder_angles,
                         wrist_centre)
from robokit.arm.srs_geometry import arm_angle_terms
from robokit.geometry import as_se3, pose_error, rot_y, rot_z
from robokit.validation import as_array
from robocourse.exercises.compare import close
from robocourse.exercises.plain import numeric_array, summarize
from robocourse.exercises.spec import Case, Exercise
from robocourse.lessons.redundant_ik.tracking import (ARM, IIWA_DH, TRACK, TRACK_SHORTCUTS, judge_track, track_cases,
                                                     track_path)

ASSIGNMENT = "06_redundant_ik"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"06.extra_dof": 2, "06.self_motion": 2, "06.your_solver": 2}
#: Tolerance on the open exercise's answers: flange position [m] and orientation [rad].
IK_TOL = 1e-6

_PLANAR = [[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]]            # two-link planar arm, lengths 1 m and 0.5 m
#: The iiwa's S-R-S geometry: shoulder point [m] and the shoulder-elbow, elbow-wrist and wrist-flange
#: distances [m] (the DH table's d_1, d_3, d_5, d_7).
_SHOULDER = [0.0, 0.0, float(ARM.d[0])]
_D_SE, _D_EW, _D_WF = (float(ARM.d[i]) for i in (2, 4, 6))


def data() -> dict:
    """What the notebook works on: the iiwa of the lesson (:func:`robokit.arm.iiwa14`) as plain data,
    and the tracking loop's settings (:data:`TRACK`); the grading worker has no robokit.

    Examples
    --------
    >>> d = data()
    >>> d["dh"][0], d["d_wf"], d["track"]["steps"]
    ([0.36, 0.0, -1.5707963267948966], 0.126, 30)
    """
    return {"dh": IIWA_DH, "qmin": ARM.qmin.tolist(), "qmax": ARM.qmax.tolist(), "shoulder": _SHOULDER,
            "d_se": _D_SE, "d_ew": _D_EW, "d_wf": _D_WF, "track": dict(TRACK)}


def _iiwa_q(rng: np.random.Generator, n: int) -> np.ndarray:
    q = ARM.random_q(n, rng)
    # keep clear of the shoulder/wrist singularities (sin q2 = 0), where q1 and q3 are not unique
    q[:, 1] = np.sign(q[:, 1]) * np.clip(np.abs(q[:, 1]), 0.2, None)
    return q


def solve_ik(T: Any, q_start: Any) -> np.ndarray:
    """Joints of the KUKA LBR iiwa 14 that reach ``T`` inside the joint limits (the open exercise's answer).

    The arm-angle search of :func:`robokit.arm.ik_srs_readable` (Shimizu et al. 2008): over the
    eight branches and their exact feasible arm angles, the posture nearest ``q_start``. Any
    posture that reaches the target inside the limits is a right answer; the compare checks that,
    not the posture.

    Parameters
    ----------
    T : array_like, shape (4, 4)
        Target flange transform in the iiwa's base frame (metres).
    q_start : array_like, shape (7,)
        The arm's current joints [rad].

    Returns
    -------
    numpy.ndarray, shape (7,)

    Raises
    ------
    ValueError
        If ``T`` is not a rigid transform, ``q_start`` is not 7 finite angles, or no posture inside
        the limits reaches ``T`` (out of reach, or no feasible arm angle).

    Examples
    --------
    >>> q = np.radians([35, 50, -40, -75, 60, 45, 20])
    >>> bool(np.abs(solve_ik(ARM.fk(q), q) - q).max() < 1e-6)
    True
    """
    T = as_se3(T, "T")
    q0 = ARM.as_q(q_start, "q_start")
    q, _, cost = ik_srs_readable(ARM, T, q0)
    if not np.isfinite(cost):
        raise ValueError("T: no posture of the iiwa reaches this target inside its joint limits "
                         "(the wrist centre is out of reach, or no arm angle keeps every joint inside)")
    return q


def _reaches_target(expected: Any, got: Any) -> str | None:
    """Accept any 7 joint angles inside the iiwa's limits whose flange pose is the answer's (the target)."""
    q = numeric_array(got)                  # the one rule for what counts as numbers
    if q is None or q.dtype.kind == "b":
        return f"expected 7 joint angles, got {summarize(got)}"
    q = q.astype(float)
    if q.shape != (7,) or not np.all(np.isfinite(q)):
        return f"expected 7 finite joint angles (shape (7,)), got {summarize(got)}"
    err = pose_error(ARM.fk(np.asarray(expected, dtype=float)), ARM.fk(q))
    pos, rot = float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:]))
    outside = np.flatnonzero((q < ARM.qmin - LIMIT_TOL) | (q > ARM.qmax + LIMIT_TOL))
    if outside.size:
        j = int(outside[0])
        over = max(ARM.qmin[j] - q[j], q[j] - ARM.qmax[j])
        return (f"joint {j + 1} is at {np.degrees(q[j]):.2f} deg, {np.degrees(over):.3g} deg beyond its limits "
                f"[{np.degrees(ARM.qmin[j]):.0f}, {np.degrees(ARM.qmax[j]):.0f}] deg ({outside.size} joint(s) "
                f"outside; the flange is {pos * 1e3:.3g} mm and {rot:.3g} rad from the target)")
    if pos > IK_TOL or rot > IK_TOL:
        return (f"your joints put the flange {pos * 1e3:.3g} mm and {rot:.3g} rad from the target "
                f"(tolerance {IK_TOL:g} m and {IK_TOL:g} rad)")
    return None


def _dh_cases(rng: np.random.Generator) -> list[Case]:
    p = rng.uniform([-np.pi, -0.5, -0.5, -np.pi], [np.pi, 0.5, 0.5, np.pi], size=(3, 4))
    return [
        Case((0.0, 0.0, 0.0, 0.0), label="all zero: identity"),
        Case((np.pi / 2, 0.36, 0.0, -np.pi / 2), label="iiwa joint 1 at 90 deg"),
        *[Case(tuple(float(v) for v in row), label="random parameters") for row in p],
        Case((float("nan"), 0.1, 0.0, 0.0), raises="ValueError", label="NaN theta"),
    ]


def _fk_cases(rng: np.random.Generator) -> list[Case]:
    q = _iiwa_q(rng, 2)
    return [
        Case((_PLANAR, [0.0, 0.0]), label="planar arm stretched out"),
        Case((_PLANAR, [np.pi / 2, -np.pi / 2]), label="planar arm, elbow bent"),
        Case((IIWA_DH, [0.0] * 7), label="iiwa at zero: 1.306 m straight up"),
        *[Case((IIWA_DH, qi.tolist()), label="iiwa, random configuration") for qi in q],
        Case((IIWA_DH, [0.0] * 6), raises="ValueError", label="6 angles for 7 joints"),
    ]


def _random_chain(rng: np.random.Generator, n: int) -> list:
    """A standard-DH table of ``n`` revolute joints with offsets and twists of every kind (no structure
    a student could rely on: no zero ``a``, no right-angle twists)."""
    return np.round(np.column_stack([rng.uniform(-0.4, 0.4, n), rng.uniform(-0.4, 0.4, n),
                                     rng.uniform(-np.pi, np.pi, n)]), 4).tolist()


def _jacobian_cases(rng: np.random.Generator) -> list[Case]:
    q = _iiwa_q(rng, 2)
    n = rng.integers(3, 7, size=2)
    return [
        Case((_PLANAR, rng.uniform(-np.pi, np.pi, 2).round(4).tolist()), label="planar arm"),
        *[Case((IIWA_DH, qi.tolist()), label="iiwa, random configuration") for qi in q],
        *[Case((_random_chain(rng, int(k)), rng.uniform(-np.pi, np.pi, int(k)).round(4).tolist()),
               label=f"a random {k}-joint chain (offsets a and d, twists of any angle)") for k in n],
        Case((IIWA_DH, [0.1] * 8), raises="ValueError", label="8 angles for 7 joints"),
    ]


#: Tolerance on a Jacobian entry: far above rounding of the exact columns (1e-15), far below what a
#: central difference of the pose can reach (about 1e-10 at its best step).
JACOBIAN_TOL = 1e-11


def finite_difference_jacobian(dh: Any, q: Any, h: float = 1e-6) -> np.ndarray:
    """The 6 x n Jacobian by central differences of the flange pose: ``(p(q + h e_i) - p(q - h e_i)) / 2h``
    and the rotation vector of ``R(q + h e_i) R(q - h e_i)^T`` over ``2h`` (a check, and a shortcut).

    Examples
    --------
    >>> J = finite_difference_jacobian([[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]], [0.3, 0.4])
    >>> bool(np.abs(J - dh_jacobian([[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]], [0.3, 0.4])).max() < 1e-8)
    True
    """
    q = as_array(q, "q", shape=(None,))
    J = np.zeros((6, len(q)))
    for i in range(len(q)):
        dq = np.zeros(len(q))
        dq[i] = h
        J[:, i] = pose_error(dh_fk(dh, q + dq), dh_fk(dh, q - dq)) / (2 * h)
    return J


def _jacobian_columns(expected: Any, got: Any) -> str | None:
    """Name the wrong columns of a geometric Jacobian (joints), and in each the part, linear or angular."""
    J = np.asarray(expected, dtype=float)
    g = numeric_array(got)
    if g is None or g.dtype.kind == "b" or g.shape != J.shape:
        return f"expected a {J.shape[0]} x {J.shape[1]} array (6 rows, one column per joint), got {summarize(got)}"
    g = g.astype(float)
    if not np.all(np.isfinite(g)):
        return "your Jacobian holds NaN or inf"
    bad = np.abs(g - J) > JACOBIAN_TOL
    if not bad.any():
        return None
    cols = np.flatnonzero(bad.any(axis=0))
    i = int(cols[0])
    parts = [name for name, rows in (("linear part (rows 1-3, the flange's velocity)", slice(0, 3)),
                                     ("angular part (rows 4-6, the flange's angular velocity)", slice(3, 6)))
             if bad[rows, i].any()]
    message = (f"{len(cols)} of {J.shape[1]} columns are wrong; the first, column {i + 1} (joint {i + 1}): the "
               f"{' and the '.join(parts)} {'is' if len(parts) == 1 else 'are'} wrong: yours "
               f"{np.round(g[:, i], 6).tolist()}, the exact column (what a central difference of the flange pose "
               f"approaches) is "
               f"{np.round(J[:, i], 6).tolist()}")
    hints = []
    for part, rows in (("linear", slice(0, 3)), ("angular", slice(3, 6))):
        if bad[rows, i].any() and np.allclose(g[rows, i], -J[rows, i], atol=1e-9):
            hints.append(f"your {part} part is the exact opposite: check the sign (the order of a cross product, "
                         f"or of a difference)")
    for k, shift in ((i + 1, "the next joint's"), (i - 1, "the previous joint's")):
        if 0 <= k < J.shape[1] and np.allclose(g[3:, i], J[3:, k], atol=1e-9) and not np.allclose(J[3:, i], J[3:, k], atol=1e-9):
            hints.append(f"your angular part is {shift} axis: which frame's z axis does joint {i + 1} turn about?")
    if not bad[:3].any() and bad[3:].any() and np.allclose(np.linalg.norm(g[3:, i]), 1.0, atol=1e-9):
        hints.append("your angular part is a unit vector, but not this joint's axis in the base frame")
    if bad[:3].any() and not bad[3:].any():
        hints.append("the axis is right: check the point the axis passes through, and the point whose velocity "
                     "you take (the flange's origin)")
    return message + ("; " + "; ".join(hints) if hints else "")


def _wrist_cases(rng: np.random.Generator) -> list[Case]:
    T = ARM.fk(_iiwa_q(rng, 3))
    bad = T[0].copy()
    bad[:3, :3] *= 1.5
    return [
        *[Case((Ti.tolist(), _D_WF), label="iiwa target pose") for Ti in T],
        Case((np.eye(4).tolist(), 0.2), label="identity pose"),
        Case((bad.tolist(), _D_WF), raises="ValueError", label="rotation block scaled: not SE(3)"),
    ]


def _elbow_cases(rng: np.random.Generator) -> list[Case]:
    frames = ARM.link_frames(_iiwa_q(rng, 3))
    W = frames[:, 5, :3, 3]
    return [
        *[Case((_SHOULDER, w.tolist(), _D_SE, _D_EW), label="iiwa wrist centre") for w in W],
        Case((_SHOULDER, [0.0, 0.0, 0.36 + 0.82], _D_SE, _D_EW), label="arm stretched: q4 = 0"),
        Case((_SHOULDER, [0.0, 0.0, 1.5], _D_SE, _D_EW), raises="ValueError", label="wrist out of reach"),
    ]


def _shoulder_case(S: list, W: Any, q4: float, psi: float, label: str) -> Case:
    """A case of :func:`shoulder_angles` that carries, beside the answer, the geometry its feedback needs."""
    args = (S, np.asarray(W).tolist(), float(q4), float(psi), _D_SE, _D_EW)
    q = shoulder_angles(*args)
    return Case(args, label=label, expected={"q": q.tolist(), "shoulder": S, "wrist": args[1], "q4": args[2],
                                             "psi": args[3], "d_se": _D_SE, "d_ew": _D_EW})


def _shoulder_cases(rng: np.random.Generator) -> list[Case]:
    q = _iiwa_q(rng, 4)
    W = ARM.link_frames(q)[:, 5, :3, 3]
    psi = rng.uniform(-np.pi, np.pi, size=4)
    return [
        _shoulder_case(_SHOULDER, W[0], q[0, 3], 0.0, "iiwa, the reference plane (psi = 0)"),
        *[_shoulder_case(_SHOULDER, w, qi[3], p, "iiwa, random arm angle") for w, qi, p in zip(W[1:], q[1:], psi)],
        Case((_SHOULDER, W[0].tolist(), float(q[0, 3]), float("nan"), _D_SE, _D_EW), raises="ValueError",
             label="NaN arm angle"),
    ]


#: Ways to pass the reference-plane case without the arm angle: ignore psi, or turn the wrong way.
SHOULDER_SHORTCUTS = {"the arm angle ignored (psi = 0)": lambda S, W, q4, psi, d_se, d_ew: shoulder_angles(S, W, q4, 0.0, d_se, d_ew),
                      "the arm angle with the wrong sign": lambda S, W, q4, psi, d_se, d_ew: shoulder_angles(S, W, q4, -psi, d_se, d_ew)}


def _shoulder_geometry(expected: Any, got: Any) -> str | None:
    """Judge shoulder joints by what they do: put the wrist centre at W, at the arm angle asked, on the
    branch q2 >= 0; say which of the three fails first."""
    want = np.asarray(expected["q"], dtype=float)
    g = numeric_array(got)
    if g is None or g.dtype.kind == "b" or g.shape != (3,):
        return f"expected 3 shoulder angles (q1, q2, q3), got {summarize(got)}"
    g = g.astype(float)
    if not np.all(np.isfinite(g)):
        return "your shoulder angles hold NaN or inf"
    d = np.angle(np.exp(1j * (g - want)))                       # compared on the circle
    if np.abs(d).max() <= 1e-7:
        return None
    S, W = np.asarray(expected["shoulder"], float), np.asarray(expected["wrist"], float)
    q4, psi, d_se, d_ew = expected["q4"], expected["psi"], expected["d_se"], expected["d_ew"]
    v = np.array([-d_ew * np.sin(q4), 0.0, d_se + d_ew * np.cos(q4)])
    wrist = S + rot_z(g[0]) @ rot_y(g[1]) @ rot_z(g[2]) @ v
    miss = float(np.linalg.norm(wrist - W))
    yours = f"yours (q1, q2, q3) = {np.degrees(g).round(3).tolist()} deg, expected {np.degrees(want).round(3).tolist()} deg"
    if miss > 1e-6:
        return (f"{yours}: your joints put the wrist centre {miss * 1e3:.3g} mm from W; the reference posture "
                f"(where does q3 = 0 put the arm, and which q1, q2 send the wrist to W?) or the reading of the "
                f"angles back from the rotation is wrong")
    got_psi = float(arm_angle_terms(*g, q4, d_se, d_ew))
    off = float(np.angle(np.exp(1j * (got_psi - psi))))
    if abs(off) > 1e-6:
        flipped = abs(float(np.angle(np.exp(1j * (got_psi + psi))))) < 1e-6
        return (f"{yours}: the wrist centre is right, but your posture's arm angle is {np.degrees(got_psi):.3f} deg "
                f"where the case asks for psi = {np.degrees(psi):.3f} deg"
                + ("; it is -psi: you turn the arm plane the wrong way about the line from S to W" if flipped
                   else "; check the reference plane (psi = 0) and the rotation about the line from S to W"))
    return (f"{yours}: the wrist centre and the arm angle are right, but not the branch: the task asks for "
            f"q2 >= 0 (the same arm as (q1 + 180, -q2, q3 + 180) deg)")


def null_space_step_exact(J: Any, e: Any, gradient: Any, damping: float, gain: float) -> np.ndarray:
    """The damped least-squares step plus ``gain`` times the gradient's orthogonal projection onto the
    Jacobian's null space (the answer of ``06.null_space_step``).

    ``J# e`` minimises ``|J dq - e|^2 + damping^2 |dq|^2``, so ``J# = J^T (J J^T + damping^2 I)^-1``
    (Wampler 1986); the projection of ``g`` onto the null space of a full-rank ``J`` is
    ``g - J^T (J J^T)^-1 J g`` (Liégeois 1977, Eq. 9, with the exact pseudo-inverse). Unlike
    :func:`robokit.arm.null_space_step`, whose projector is regularised for singular Jacobians, the
    projection here is exact; the cases keep ``J`` far from singular.

    Parameters
    ----------
    J : array_like, shape (6, n)
    e : array_like, shape (6,)
    gradient : array_like, shape (n,)
    damping, gain : float
        ``lambda >= 0`` and ``k >= 0``.

    Returns
    -------
    numpy.ndarray, shape (n,)

    Raises
    ------
    ValueError
        On shapes that do not match, NaN, or a negative damping or gain.

    Examples
    --------
    >>> J = np.hstack([np.eye(6), np.zeros((6, 1))])
    >>> print(null_space_step_exact(J, [0.1, 0, 0, 0, 0, 0], [1, 1, 1, 1, 1, 1, 1], 0.0, 0.5))
    [0.1 0.  0.  0.  0.  0.  0.5]
    """
    null_space_step(J, e, gradient, damping, gain)         # robokit's (regularised) step validates the inputs
    J, e, g = (np.asarray(x, dtype=float) for x in (J, e, gradient))
    JJt = J @ J.T
    primary = J.T @ np.linalg.solve(JJt + damping ** 2 * np.eye(6), e)
    projected = g - J.T @ np.linalg.solve(JJt, J @ g)
    return primary + gain * projected


def _null_space_case(J, e, g, damping, gain, label) -> Case:
    args = (np.asarray(J).round(10).tolist(), np.asarray(e).round(10).tolist(), np.asarray(g).round(10).tolist(),
            damping, gain)
    dq = null_space_step_exact(*args)
    return Case(args, label=label, expected={"dq": dq.tolist(), "J": args[0], "e": args[1], "gradient": args[2],
                                             "damping": damping, "gain": gain})


def _null_space_cases(rng: np.random.Generator) -> list[Case]:
    arm = panda()
    q = np.zeros((0, 7))
    while len(q) < 3:           # postures well away from a singularity (about 3 in 8 are)
        more = arm.random_q(8, rng)
        sigma = np.linalg.svd(geometric_jacobian(arm, more), compute_uv=False)[:, -1]
        q = np.vstack([q, more[sigma > 0.05]])
    q = q[:3]
    J, g = geometric_jacobian(arm, q), limit_distance_gradient(arm, q)
    e = rng.normal(0, 0.01, size=(3, 6))
    return [
        _null_space_case(J[0], [0.0] * 6, g[0], 0.0, 1.0, "zero pose error: pure self-motion"),
        _null_space_case(J[1], e[1], [0.0] * 7, 0.05, 1.0, "zero gradient: plain DLS"),
        _null_space_case(J[2], e[2], g[2], 0.1, 0.5, "both terms"),
        _null_space_case(J[0], e[0], g[0], 0.05, 0.3, "both terms, another damping and gain"),
        Case((J[0][:5].tolist(), e[0].tolist(), g[0].tolist(), 0.01, 0.5), raises="ValueError",
             label="Jacobian with 5 rows"),
    ]


def _plain_dls(J, e, gradient, damping, gain):
    """Shortcut: the damped least-squares step alone, no secondary task."""
    J = np.asarray(J, float)
    return J.T @ np.linalg.solve(J @ J.T + damping ** 2 * np.eye(6), np.asarray(e, float))


def _unprojected(J, e, gradient, damping, gain):
    """Shortcut: the DLS step plus the raw gradient (it moves the hand too)."""
    return _plain_dls(J, e, gradient, damping, gain) + gain * np.asarray(gradient, float)


#: Ways to pass some null-space cases without both terms.
NULL_SPACE_SHORTCUTS = {"the DLS step alone (no null-space term)": _plain_dls,
                        "the DLS step plus the gradient, not projected": _unprojected}


def _null_space_terms(expected: Any, got: Any) -> str | None:
    """Judge a null-space step and say which term is wrong: the part that moves the hand (J dq) or the
    part the hand does not see (the projected gradient)."""
    want = np.asarray(expected["dq"], dtype=float)
    g = numeric_array(got)
    if g is None or g.dtype.kind == "b" or g.shape != want.shape:
        return f"expected a joint step of shape {want.shape}, got {summarize(got)}"
    g = g.astype(float)
    if not np.all(np.isfinite(g)):
        return "your step holds NaN or inf"
    tol = 1e-9 + 1e-6 * np.abs(want)
    if np.all(np.abs(g - want) <= tol):
        return None
    J, e = np.asarray(expected["J"], float), np.asarray(expected["e"], float)
    grad, lam, k = np.asarray(expected["gradient"], float), expected["damping"], expected["gain"]
    worst = int(np.argmax(np.abs(g - want) - tol))
    head = (f"joint {worst + 1} of your step is {g[worst]:.6g}, expected {want[worst]:.6g} "
            f"({int(np.sum(np.abs(g - want) > tol))} of {want.size} joints differ)")
    hand, hand_want = J @ g, J @ want
    primary = _plain_dls(J, e, grad, lam, k)
    if np.allclose(hand, hand_want, rtol=1e-6, atol=1e-9):
        extra = g - primary
        why = ("it is missing" if np.allclose(extra, 0, atol=1e-9) else
               "check its sign and the gain" if np.allclose(J @ extra, 0, atol=1e-8) else "check the projection")
        return (f"{head}: the hand part J dq is right (to 1e-6); the difference is motion the hand does not see, "
                f"so the null-space term is wrong: {why}")
    if np.allclose(g, primary + k * grad, rtol=1e-6, atol=1e-9) and np.abs(grad).max() > 0:
        return (f"{head}: you added the gradient as it is; part of it moves the hand (J dq differs by "
                f"{np.linalg.norm(k * J @ grad):.3g}): keep only the part in the null space of J")
    undamped = J.T @ np.linalg.solve(J @ J.T, e)
    if lam > 0 and np.allclose(J @ g, J @ undamped, rtol=1e-6, atol=1e-9):
        return f"{head}: your hand part is the undamped least-squares step; the damping {lam:g} is missing"
    return (f"{head}: the hand part is wrong (J dq is {np.round(hand, 6).tolist()}, expected "
            f"{np.round(hand_want, 6).tolist()}): the damped least-squares term minimises |J dq - e|^2 + "
            f"damping^2 |dq|^2")




def _arcs(T: np.ndarray) -> np.ndarray:
    """The exact feasible arm-angle arcs of all eight branches of target ``T``, stacked (k, 2) [rad]."""
    return np.concatenate([iv.reshape(-1, 2) for iv in feasible_arm_angles(ARM, T)])


def _psi_zero_infeasible(rng: np.random.Generator) -> np.ndarray:
    """A configuration whose pose no branch reaches inside the limits at arm angle 0 (drawn until found)."""
    for _ in range(1000):
        q = ARM.random_q(rng=rng)
        arcs = _arcs(ARM.fk(q))
        if not ((arcs[:, 0] <= 0.0) & (arcs[:, 1] >= 0.0)).any():
            return q
    raise RuntimeError("no configuration with an infeasible arm angle 0 in 1000 draws")  # pragma: no cover


def _no_feasible_arm_angle(rng: np.random.Generator) -> np.ndarray:
    """Joints (some outside the limits) whose pose has a reachable wrist centre but no feasible arm angle."""
    for _ in range(1000):
        q = rng.uniform(-np.pi, np.pi, 7)
        if not len(_arcs(ARM.fk(q))):
            return q
    raise RuntimeError("no target without a feasible arm angle in 1000 draws")  # pragma: no cover


def _narrow(rng: np.random.Generator) -> np.ndarray:
    """Joints whose pose has feasible arcs totalling 1.5-5 deg over the eight branches, none of them
    containing a multiple of 10 deg, one containing a whole degree: between a feasible target and
    one with no feasible arm angle, bisected on the straight line of joint values between them."""
    for _ in range(200):
        q_in, q_out = ARM.random_q(rng=rng), _no_feasible_arm_angle(rng)
        lo, hi = 0.0, 1.0
        for _ in range(40):
            t = 0.5 * (lo + hi)
            q = (1 - t) * q_in + t * q_out
            arcs = np.degrees(_arcs(ARM.fk(q)))
            total = float(np.diff(arcs, axis=1).sum())
            if 1.5 < total < 5.0:
                whole = np.floor(arcs[:, 1]) >= arcs[:, 0]
                tens = np.floor(arcs[:, 1] / 10) * 10 >= arcs[:, 0]
                if whole.any() and not tens.any():
                    return q
                break
            lo, hi = (t, hi) if total >= 5.0 else (lo, t)
    raise RuntimeError("no narrow target in 200 attempts")  # pragma: no cover


def _solve_ik_cases(rng: np.random.Generator) -> list[Case]:
    q = ARM.random_q(3, rng)
    starts = ARM.random_q(3, rng)
    hard = [_psi_zero_infeasible(rng) for _ in range(4)]
    near = np.clip(hard[0] + rng.normal(0.0, 0.05, 7), ARM.qmin, ARM.qmax)
    narrow = [_narrow(rng) for _ in range(2)]
    blocked = _no_feasible_arm_angle(rng)
    far = np.eye(4)
    far[:3, 3] = [1.2, 0.3, 0.5]
    return [
        *[Case((ARM.fk(qi).tolist(), si.tolist()), label="a random reachable target, random start")
          for qi, si in zip(q, starts)],
        Case((ARM.fk(hard[0]).tolist(), near.tolist()), label="arm angle 0 breaks a limit on every branch; start nearby"),
        *[Case((ARM.fk(h).tolist(), ARM.random_q(rng=rng).tolist()),
               label="arm angle 0 breaks a limit on every branch; random start") for h in hard[1:]],
        *[Case((ARM.fk(n).tolist(), ARM.random_q(rng=rng).tolist()),
               label="feasible arm angles total under 5 deg, none at a multiple of 10 deg") for n in narrow],
        Case((ARM.fk(blocked).tolist(), [0.0] * 7), raises="ValueError",
             label="wrist centre in reach, but no arm angle keeps every joint inside its limits"),
        Case((far.tolist(), [0.0] * 7), raises="ValueError", label="target 1.3 m away: out of reach"),
    ]


EXERCISES = [
    Exercise(
        id="06.dh_transform",
        function="dh_transform",
        signature="dh_transform(theta: float, d: float, a: float, alpha: float) -> numpy.ndarray",
        points=1,
        cases=_dh_cases,
        answer=dh_transform,
        compare=close(rtol=0, atol=1e-9),
        kind="warm-up",
        description="Standard DH link transform Rz(theta) Tz(d) Tx(a) Rx(alpha), 4x4; ValueError on NaN.",
    ),
    Exercise(
        id="06.forward_kinematics",
        function="forward_kinematics",
        signature="forward_kinematics(dh: list[list[float]], q: list[float]) -> numpy.ndarray",
        points=1,
        cases=_fk_cases,
        answer=dh_fk,
        compare=close(rtol=0, atol=1e-9),
        kind="warm-up",
        description=("Flange pose (4x4) of a standard-DH chain with rows [d, a, alpha]; "
                     "ValueError on a length mismatch."),
    ),
    Exercise(
        id="06.geometric_jacobian",
        function="geometric_jacobian",
        signature="geometric_jacobian(dh: list[list[float]], q: list[float]) -> numpy.ndarray",
        points=2,
        cases=_jacobian_cases,
        answer=dh_jacobian,
        compare=_jacobian_columns,
        kind="derivation",
        shortcuts={"central differences of the flange pose": finite_difference_jacobian},
        description=("6 x n geometric Jacobian [v; omega] in the base frame, derived from the chain (the task "
                     "gives no formula), to 1e-11 per entry; the feedback names the wrong column and part; "
                     "ValueError on a length mismatch."),
    ),
    Exercise(
        id="06.wrist_centre",
        function="wrist_centre",
        signature="wrist_centre(T: list[list[float]], d_wf: float) -> numpy.ndarray",
        points=1,
        cases=_wrist_cases,
        answer=wrist_centre,
        compare=close(rtol=0, atol=1e-9),
        kind="warm-up",
        description="W = p - d_wf * z of the target pose; ValueError if T is not SE(3).",
    ),
    Exercise(
        id="06.elbow_angle",
        function="elbow_angle",
        signature="elbow_angle(shoulder: list[float], wrist: list[float], d_se: float, d_ew: float) -> float",
        points=1,
        cases=_elbow_cases,
        answer=elbow_angle,
        compare=close(rtol=0, atol=1e-7),
        kind="warm-up",
        description="Elbow joint q4 >= 0 by the law of cosines; ValueError when the wrist is out of reach.",
    ),
    Exercise(
        id="06.shoulder_angles",
        function="shoulder_angles",
        signature=("shoulder_angles(shoulder: list[float], wrist: list[float], q4: float, psi: float, "
                   "d_se: float, d_ew: float) -> numpy.ndarray"),
        points=2,
        cases=_shoulder_cases,
        answer=shoulder_angles,
        compare=_shoulder_geometry,
        kind="derivation",
        shortcuts=SHOULDER_SHORTCUTS,
        description=("(q1, q2 >= 0, q3) of the iiwa for arm angle psi, derived from the shoulder's geometry and "
                     "the definition of psi; the feedback says whether the wrist, the arm angle or the branch "
                     "is wrong; ValueError on NaN."),
    ),
    Exercise(
        id="06.null_space_step",
        function="null_space_step",
        signature=("null_space_step(J: numpy.ndarray, e: list[float], gradient: list[float], damping: float, "
                   "gain: float) -> numpy.ndarray"),
        points=1,
        cases=_null_space_cases,
        answer=null_space_step_exact,
        compare=_null_space_terms,
        kind="derivation",
        shortcuts=NULL_SPACE_SHORTCUTS,
        description=("The minimiser of |J dq - e|^2 + damping^2 |dq|^2 plus gain times the gradient's projection "
                     "onto the null space of J, both derived from their definitions; the feedback says which "
                     "term is wrong; ValueError on a bad Jacobian shape."),
    ),
    Exercise(
        id="06.track_path",
        function="track_path",
        signature=("track_path(dh: list[list[float]], qmin: list[float], qmax: list[float], q_start: list[float], "
                   "targets: list of 4x4, settings: dict) -> (K * steps, 7) array"),
        points=2,
        cases=track_cases,
        answer=track_path,
        compare=judge_track,
        kind="loop",
        shortcuts=TRACK_SHORTCUTS,
        description=("Loop: resolved-rate tracking of a short arc of iiwa flange poses with DLS and the "
                     "joint-range gradient in the null space; graded on the run: steps <= max_step, inside the "
                     "limits, every waypoint within tol by the end of its iterations, the final joint-range cost "
                     "at least halfway from plain DLS's to the reference's; ValueError for a start outside the "
                     "limits or shapes that do not match."),
    ),
    Exercise(
        id="06.solve_ik",
        function="solve_ik",
        signature="solve_ik(T: list[list[float]], q_start: list[float]) -> numpy.ndarray",
        points=2,
        cases=_solve_ik_cases,
        answer=solve_ik,
        compare=_reaches_target,
        kind="open",
        description=("Open: iiwa joints inside the limits reaching T to 1e-6 m and rad, any method; "
                     "ValueError when no posture inside the limits reaches it (out of reach, or no arm angle)."),
    ),
]
