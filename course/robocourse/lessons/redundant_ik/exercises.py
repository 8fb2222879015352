"""Exercises of assignment 06 (redundant 7-DOF arm IK): from one DH transform to a null-space step,
and an open exercise, a whole IK solver for the iiwa by any method.

Inputs are generated from the KUKA LBR iiwa 14 R820 and the Franka Panda of :mod:`robokit.arm`
(random configurations inside the joint limits), plus small hand-checkable chains.

References
----------
.. [1] L. Huang and R. Jiang, "A new method of inverse kinematics solution for industrial 7DOF robot"
   (question 4 of the course's assignment).
.. [2] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
"""
from __future__ import annotations

import numpy as np

from typing import Any

from robokit.arm import (LIMIT_TOL, dh_fk, dh_jacobian, dh_transform, elbow_angle, feasible_arm_angles, geometric_jacobian,
                   iiwa14, ik_srs_readable, limit_distance_gradient, null_space_step, panda, shoulder_angles,
                   wrist_centre)
from robokit.geometry import as_se3, pose_error
from robocourse.exercises.compare import close
from robocourse.exercises.plain import numeric_array, summarize
from robocourse.exercises.spec import Case, Exercise

ASSIGNMENT = "06_redundant_ik"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"06.extra_dof": 2, "06.self_motion": 2, "06.your_solver": 2}
#: Tolerance on the open exercise's answers: flange position [m] and orientation [rad].
IK_TOL = 1e-6

_IIWA = iiwa14()
_IIWA_DH = np.stack([_IIWA.d, _IIWA.a, _IIWA.alpha], 1).tolist()
_PLANAR = [[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]]            # two-link planar arm, lengths 1 m and 0.5 m
_SHOULDER = [0.0, 0.0, 0.36]
_D_SE, _D_EW, _D_WF = 0.42, 0.40, 0.126


def _iiwa_q(rng: np.random.Generator, n: int) -> np.ndarray:
    q = _IIWA.random_q(n, rng)
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
    >>> bool(np.abs(solve_ik(_IIWA.fk(q), q) - q).max() < 1e-6)
    True
    """
    T = as_se3(T, "T")
    q0 = _IIWA.as_q(q_start, "q_start")
    q, _, cost = ik_srs_readable(_IIWA, T, q0)
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
    err = pose_error(_IIWA.fk(np.asarray(expected, dtype=float)), _IIWA.fk(q))
    pos, rot = float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:]))
    outside = np.flatnonzero((q < _IIWA.qmin - LIMIT_TOL) | (q > _IIWA.qmax + LIMIT_TOL))
    if outside.size:
        j = int(outside[0])
        over = max(_IIWA.qmin[j] - q[j], q[j] - _IIWA.qmax[j])
        return (f"joint {j + 1} is at {np.degrees(q[j]):.2f} deg, {np.degrees(over):.3g} deg beyond its limits "
                f"[{np.degrees(_IIWA.qmin[j]):.0f}, {np.degrees(_IIWA.qmax[j]):.0f}] deg ({outside.size} joint(s) "
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
        Case((_IIWA_DH, [0.0] * 7), label="iiwa at zero: 1.306 m straight up"),
        *[Case((_IIWA_DH, qi.tolist()), label="iiwa, random configuration") for qi in q],
        Case((_IIWA_DH, [0.0] * 6), raises="ValueError", label="6 angles for 7 joints"),
    ]


def _jacobian_cases(rng: np.random.Generator) -> list[Case]:
    q = _iiwa_q(rng, 2)
    return [
        Case((_PLANAR, [0.3, 0.4]), label="planar arm"),
        *[Case((_IIWA_DH, qi.tolist()), label="iiwa, random configuration") for qi in q],
        Case((_IIWA_DH, [0.1] * 8), raises="ValueError", label="8 angles for 7 joints"),
    ]


def _wrist_cases(rng: np.random.Generator) -> list[Case]:
    T = _IIWA.fk(_iiwa_q(rng, 3))
    bad = T[0].copy()
    bad[:3, :3] *= 1.5
    return [
        *[Case((Ti.tolist(), _D_WF), label="iiwa target pose") for Ti in T],
        Case((np.eye(4).tolist(), 0.2), label="identity pose"),
        Case((bad.tolist(), _D_WF), raises="ValueError", label="rotation block scaled: not SE(3)"),
    ]


def _elbow_cases(rng: np.random.Generator) -> list[Case]:
    frames = _IIWA.link_frames(_iiwa_q(rng, 3))
    W = frames[:, 5, :3, 3]
    return [
        *[Case((_SHOULDER, w.tolist(), _D_SE, _D_EW), label="iiwa wrist centre") for w in W],
        Case((_SHOULDER, [0.0, 0.0, 0.36 + 0.82], _D_SE, _D_EW), label="arm stretched: q4 = 0"),
        Case((_SHOULDER, [0.0, 0.0, 1.5], _D_SE, _D_EW), raises="ValueError", label="wrist out of reach"),
    ]


def _shoulder_cases(rng: np.random.Generator) -> list[Case]:
    q = _iiwa_q(rng, 4)
    W = _IIWA.link_frames(q)[:, 5, :3, 3]
    psi = rng.uniform(-np.pi, np.pi, size=4)
    return [
        *[Case((_SHOULDER, w.tolist(), float(qi[3]), float(p), _D_SE, _D_EW), label="iiwa, random arm angle")
          for w, qi, p in zip(W, q, psi)],
        Case((_SHOULDER, W[0].tolist(), float(q[0, 3]), float("nan"), _D_SE, _D_EW), raises="ValueError",
             label="NaN arm angle"),
    ]


def _null_space_cases(rng: np.random.Generator) -> list[Case]:
    arm = panda()
    q = arm.random_q(3, rng)
    J = geometric_jacobian(arm, q)
    g = limit_distance_gradient(arm, q)
    e = rng.normal(0, 0.01, size=(3, 6))
    return [
        Case((J[0], [0.0] * 6, g[0].tolist(), 0.0, 1.0), label="zero pose error: pure self-motion"),
        Case((J[1], e[1].tolist(), [0.0] * 7, 0.05, 1.0), label="zero gradient: plain DLS"),
        Case((J[2], e[2].tolist(), g[2].tolist(), 0.01, 0.5), label="both terms"),
        Case((J[0][:5], e[0].tolist(), g[0].tolist(), 0.01, 0.5), raises="ValueError",
             label="Jacobian with 5 rows"),
    ]


def _arcs(T: np.ndarray) -> np.ndarray:
    """The exact feasible arm-angle arcs of all eight branches of target ``T``, stacked (k, 2) [rad]."""
    return np.concatenate([iv.reshape(-1, 2) for iv in feasible_arm_angles(_IIWA, T)])


def _psi_zero_infeasible(rng: np.random.Generator) -> np.ndarray:
    """A configuration whose pose no branch reaches inside the limits at arm angle 0 (drawn until found)."""
    for _ in range(1000):
        q = _IIWA.random_q(rng=rng)
        arcs = _arcs(_IIWA.fk(q))
        if not ((arcs[:, 0] <= 0.0) & (arcs[:, 1] >= 0.0)).any():
            return q
    raise RuntimeError("no configuration with an infeasible arm angle 0 in 1000 draws")  # pragma: no cover


def _no_feasible_arm_angle(rng: np.random.Generator) -> np.ndarray:
    """Joints (some outside the limits) whose pose has a reachable wrist centre but no feasible arm angle."""
    for _ in range(1000):
        q = rng.uniform(-np.pi, np.pi, 7)
        if not len(_arcs(_IIWA.fk(q))):
            return q
    raise RuntimeError("no target without a feasible arm angle in 1000 draws")  # pragma: no cover


def _narrow(rng: np.random.Generator) -> np.ndarray:
    """Joints whose pose has feasible arcs totalling 1.5-5 deg over the eight branches, none of them
    containing a multiple of 10 deg, one containing a whole degree: between a feasible target and
    one with no feasible arm angle, bisected on the straight line of joint values between them."""
    for _ in range(200):
        q_in, q_out = _IIWA.random_q(rng=rng), _no_feasible_arm_angle(rng)
        lo, hi = 0.0, 1.0
        for _ in range(40):
            t = 0.5 * (lo + hi)
            q = (1 - t) * q_in + t * q_out
            arcs = np.degrees(_arcs(_IIWA.fk(q)))
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
    q = _IIWA.random_q(3, rng)
    starts = _IIWA.random_q(3, rng)
    hard = [_psi_zero_infeasible(rng) for _ in range(4)]
    near = np.clip(hard[0] + rng.normal(0.0, 0.05, 7), _IIWA.qmin, _IIWA.qmax)
    narrow = [_narrow(rng) for _ in range(2)]
    blocked = _no_feasible_arm_angle(rng)
    far = np.eye(4)
    far[:3, 3] = [1.2, 0.3, 0.5]
    return [
        *[Case((_IIWA.fk(qi).tolist(), si.tolist()), label="a random reachable target, random start")
          for qi, si in zip(q, starts)],
        Case((_IIWA.fk(hard[0]).tolist(), near.tolist()), label="arm angle 0 breaks a limit on every branch; start nearby"),
        *[Case((_IIWA.fk(h).tolist(), _IIWA.random_q(rng=rng).tolist()),
               label="arm angle 0 breaks a limit on every branch; random start") for h in hard[1:]],
        *[Case((_IIWA.fk(n).tolist(), _IIWA.random_q(rng=rng).tolist()),
               label="feasible arm angles total under 5 deg, none at a multiple of 10 deg") for n in narrow],
        Case((_IIWA.fk(blocked).tolist(), [0.0] * 7), raises="ValueError",
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
        compare=close(rtol=0, atol=1e-9),
        kind="transcription",
        description="6 x n geometric Jacobian [v; omega] in the base frame; ValueError on a length mismatch.",
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
        compare=close(rtol=0, atol=1e-7),
        kind="transcription",
        description="(q1, q2 >= 0, q3) of the iiwa for arm angle psi; ValueError on NaN.",
    ),
    Exercise(
        id="06.null_space_step",
        function="null_space_step",
        signature=("null_space_step(J: numpy.ndarray, e: list[float], gradient: list[float], damping: float, "
                   "gain: float) -> numpy.ndarray"),
        points=2,
        cases=_null_space_cases,
        answer=null_space_step,
        compare=close(rtol=1e-6, atol=1e-9),
        kind="transcription",
        description="DLS step plus the gradient projected into the null space; ValueError on a bad Jacobian shape.",
    ),
    Exercise(
        id="06.solve_ik",
        function="solve_ik",
        signature="solve_ik(T: list[list[float]], q_start: list[float]) -> numpy.ndarray",
        points=3,
        cases=_solve_ik_cases,
        answer=solve_ik,
        compare=_reaches_target,
        kind="open",
        description=("Open: iiwa joints inside the limits reaching T to 1e-6 m and rad, any method; "
                     "ValueError when no posture inside the limits reaches it (out of reach, or no arm angle)."),
    ),
]
