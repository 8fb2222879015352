"""Assignment 06 exercises: registration and check() catching wrong answers (references: test_exercises_references.py)."""
import numpy as np
import pytest

from robocourse.lessons.redundant_ik import exercises as redundant_ik, tracking
from robocourse.grading import check
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes

EXERCISES = exercises_for("06_redundant_ik")
SOLVE_IK = next(e for e in EXERCISES if e.id == "06.solve_ik")


def test_assignment_is_registered():
    assert redundant_ik.ASSIGNMENT == "06_redundant_ik"
    assert len(EXERCISES) >= 7
    assert set(redundant_ik.WRITTEN) == {"06.extra_dof", "06.self_motion", "06.your_solver"}
    assert {e.id for e in EXERCISES} >= {"06.dh_transform", "06.forward_kinematics", "06.geometric_jacobian",
                                         "06.wrist_centre", "06.elbow_angle", "06.shoulder_angles",
                                         "06.null_space_step", "06.track_path", "06.solve_ik"}


def test_total_points_unchanged():
    """Issue 37 rebalanced the points (a loop exercise added), not the assignment's total of 19."""
    assert sum(e.points for e in EXERCISES) + sum(redundant_ik.WRITTEN.values()) == 19


def test_data_is_the_lessons_iiwa():
    """The notebook's arm and the exercises' cases are robokit's iiwa14, the arm the lesson runs."""
    from robokit.arm import iiwa14

    arm, d = iiwa14(), redundant_ik.data()
    assert np.allclose(d["dh"], np.stack([arm.d, arm.a, arm.alpha], 1))
    assert np.allclose(d["qmin"], arm.qmin) and np.allclose(d["qmax"], arm.qmax)
    assert d["shoulder"] == [0.0, 0.0, arm.d[0]] and (d["d_se"], d["d_ew"], d["d_wf"]) == tuple(arm.d[[2, 4, 6]])
    assert d["track"] == redundant_ik.TRACK


def test_cases_depend_on_the_seed():
    ex = EXERCISES[1]  # (the first has a NaN case, and NaN != NaN)
    assert ex.make_cases(1) != ex.make_cases(2)
    assert ex.make_cases(1) == ex.make_cases(1)


def _wrong(reference):
    def fn(*args, **kwargs):
        out = np.asarray(reference(*args, **kwargs), dtype=float)
        return out + 1e-3  # a small but real mistake
    return fn


@pytest.mark.parametrize("exercise", EXERCISES, ids=lambda e: e.id)
def test_check_fails_a_wrong_implementation(exercise, capsys):
    with pytest.raises(AssertionError):
        check(exercise.id, _wrong(exercise.answer))
    assert_check_passes(exercise.id, exercise.answer, len(exercise.make_cases(2024)))


def test_check_fails_an_implementation_that_ignores_bad_input():
    def dh_no_validation(theta, d, a, alpha):
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
        return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                         [0, sa, ca, d], [0, 0, 0, 1.0]])
    with pytest.raises(AssertionError):
        check("06.dh_transform", dh_no_validation)


def test_elbow_sign_convention_is_checked():
    from robokit.arm import elbow_angle

    with pytest.raises(AssertionError):
        check("06.elbow_angle", lambda *a: -elbow_angle(*a))


def _solve_ik_cases(seed):
    return next(e for e in EXERCISES if e.id == "06.solve_ik").make_cases(seed)


@pytest.mark.parametrize("seed", [0, 1, 2024])
def test_open_ik_reference_is_the_truth(seed):
    """Every reachable case has a true posture inside the limits (by construction), and the
    reference returns a posture that reaches the target inside the limits (checked by FK here,
    not by the exercise's compare)."""
    from robokit.arm import LIMIT_TOL, iiwa14
    from robokit.geometry import pose_error

    arm = iiwa14()
    for case in _solve_ik_cases(seed):
        if case.raises:
            with pytest.raises(ValueError):
                redundant_ik.solve_ik(*case.args)
            continue
        T = np.array(case.args[0])
        q = redundant_ik.solve_ik(*case.args)
        assert np.abs(pose_error(T, arm.fk(q))).max() < 1e-9
        assert np.all((q >= arm.qmin - LIMIT_TOL) & (q <= arm.qmax + LIMIT_TOL))


def test_open_ik_compare_accepts_another_valid_posture_and_names_a_limit():
    """Any posture that reaches the target inside the limits passes, not only the reference's;
    one outside a limit fails with the joint named."""
    from robokit.arm import arm_angle, iiwa14, ik_srs_branches

    arm = iiwa14()
    q = np.radians([35, 50, -40, -75, 60, 45, 20])
    other = ik_srs_branches(arm, arm.fk(q), arm_angle(arm, q) + 0.5)[0]          # a different posture, same pose
    assert np.abs(other - q).max() > 0.1
    assert SOLVE_IK.compare(q.tolist(), other.tolist()) is None
    outside = q.copy()
    outside[2] = np.radians(175)
    assert "joint 3" in SOLVE_IK.compare(q.tolist(), outside.tolist())


def _psi_zero_shortcut(T, q_start):
    """Arm angle 0 (the reference plane), the first branch inside the limits, else the first branch."""
    from robokit.arm import ik_srs_branches, iiwa14

    arm = iiwa14()
    inside = ik_srs_branches(arm, np.asarray(T), 0.0)
    if len(inside):
        return inside[0]
    every = ik_srs_branches(arm, np.asarray(T), 0.0, within_limits=False)
    if not len(every):
        raise ValueError("T: out of reach")
    return every[0]


def _grid_shortcut(T, q_start, step_deg=30):
    """Arm angles every ``step_deg`` degrees; the first branch inside the limits at the first that has one."""
    from robokit.arm import ik_srs_branches, iiwa14

    arm = iiwa14()
    for psi in np.radians(np.arange(-180, 180, step_deg)):
        inside = ik_srs_branches(arm, np.asarray(T), psi)
        if len(inside):
            return inside[0]
    raise ValueError("T: no arm angle on the grid keeps the joints inside")


def _failed_labels(fn, seed):
    failed = set()
    for case in _solve_ik_cases(seed):
        try:
            out = fn(*case.args)
        except ValueError:
            if not case.raises:
                failed.add(case.label)
            continue
        if case.raises or SOLVE_IK.compare(redundant_ik.solve_ik(*case.args), out) is not None:
            failed.add(case.label)
    return failed


@pytest.mark.parametrize("seed", [0, 1, pytest.param(2024, marks=pytest.mark.slow)])
def test_open_ik_tempting_shortcuts_fail_some_cases(seed):
    """Arm angle 0 fails where no branch is inside at psi = 0 and where no arm angle is; a 30-degree
    (or 10-degree) grid of arm angles misses the narrow feasible arcs; the reference passes all."""
    assert "arm angle 0 breaks a limit on every branch; random start" in _failed_labels(_psi_zero_shortcut, seed)
    narrow = "feasible arm angles total under 5 deg, none at a multiple of 10 deg"
    assert _failed_labels(_grid_shortcut, seed) == {narrow}
    assert narrow in _failed_labels(lambda T, q: _grid_shortcut(T, q, step_deg=10), seed)
    assert _failed_labels(redundant_ik.solve_ik, seed) == set()


def test_open_ik_cases_are_what_their_labels_say():
    """The narrow case's arcs total under 5 deg and miss every multiple of 10 deg; the blocked case's
    wrist centre is in reach yet no branch has a feasible arm angle."""
    from robokit.arm import feasible_arm_angles, iiwa14, wrist_centre

    arm = iiwa14()
    for seed in (0, 1):
        for case in _solve_ik_cases(seed):
            arcs = np.degrees(np.concatenate([iv.reshape(-1, 2) for iv in feasible_arm_angles(arm, np.array(case.args[0]))]))
            if case.label.startswith("feasible arm angles total"):
                assert 0 < np.diff(arcs, axis=1).sum() < 5
                assert not (np.floor(arcs[:, 1] / 10) * 10 >= arcs[:, 0]).any()
            if case.label.startswith("wrist centre in reach"):
                L = np.linalg.norm(wrist_centre(np.array(case.args[0]), 0.126) - [0, 0, 0.36])
                assert 0.02 <= L <= 0.82 and len(arcs) == 0


def test_open_ik_feedback_says_how_far_a_joint_is_over():
    q = np.radians([35, 50, -40, -75, 60, 45, 20])
    outside = q.copy()
    outside[2] = np.radians(175)
    message = SOLVE_IK.compare(q.tolist(), outside.tolist())
    assert "joint 3" in message and "5 deg beyond" in message


def _exercise(eid):
    return next(e for e in EXERCISES if e.id == eid)


def _valid(eid, seed=2024):
    from robocourse.grading.judge import expected_output

    ex = _exercise(eid)
    return [(c, expected_output(ex, c)) for c in ex.make_cases(seed) if not c.raises]


# --- 06.geometric_jacobian: a derivation; the feedback names the column and the part ---------------------
def test_jacobian_feedback_names_the_column_and_the_part():
    ex = _exercise("06.geometric_jacobian")
    for case, expected in _valid("06.geometric_jacobian"):
        J = np.array(expected)
        if J.shape[1] < 3:
            continue
        linear = J.copy()
        linear[:3, 2] *= -1                                   # the cross product the wrong way round
        msg = ex.compare(expected, linear)
        assert "column 3 (joint 3)" in msg and "linear part" in msg and "angular part" not in msg, msg
        assert "opposite" in msg or np.allclose(J[:3, 2], 0)
        shifted = J.copy()
        shifted[3:] = np.roll(J[3:], -1, axis=1)              # each joint about the next frame's z axis
        msg = ex.compare(expected, shifted)
        assert "angular part" in msg and "linear part" not in msg and "next joint's axis" in msg, msg
        assert ex.compare(expected, J) is None


def _jacobian_about_the_wrong_frame(dh, q):
    """A wrong Jacobian: joint i turns about the z axis of frame i (not i - 1)."""
    from robokit.arm import dh_jacobian

    J = np.array(dh_jacobian(dh, q))
    J[3:] = np.roll(J[3:], -1, axis=1)
    return J


def test_check_fails_a_jacobian_with_the_wrong_axes():
    with pytest.raises(AssertionError):
        check("06.geometric_jacobian", _jacobian_about_the_wrong_frame)


def test_finite_differences_do_not_pass_the_jacobian():
    """A central-difference Jacobian is close (1e-8) but not exact: the check asks for the derived columns."""
    ex = _exercise("06.geometric_jacobian")
    fd = ex.shortcuts["central differences of the flange pose"]
    for seed in (0, 1):
        for case, expected in _valid("06.geometric_jacobian", seed):
            got = fd(*case.args)
            assert np.abs(got - np.array(expected)).max() < 1e-7
            assert ex.compare(expected, got) is not None


# --- 06.shoulder_angles: the feedback says wrist, arm angle or branch ----------------------------------
def test_shoulder_feedback_says_what_is_wrong():
    from robokit.arm import shoulder_angles

    ex = _exercise("06.shoulder_angles")
    for case, expected in _valid("06.shoulder_angles"):
        S, W, q4, psi, d_se, d_ew = case.args
        q = np.array(expected["q"])
        assert ex.compare(expected, q) is None
        assert ex.compare(expected, q + [2 * np.pi, 0, -2 * np.pi]) is None          # the same angles
        assert "branch" in ex.compare(expected, q + [np.pi, -2 * q[1], np.pi])
        assert "wrist centre" in ex.compare(expected, q + [0, 0.05, 0])
        if abs(np.sin(psi)) > 0.05:
            assert "-psi" in ex.compare(expected, shoulder_angles(S, W, q4, -psi, d_se, d_ew))
            assert "arm angle" in ex.compare(expected, shoulder_angles(S, W, q4, 0.0, d_se, d_ew))


# --- 06.null_space_step: the feedback says which term --------------------------------------------------
def test_null_space_feedback_names_the_term():
    ex = _exercise("06.null_space_step")
    unprojected = ex.shortcuts["the DLS step plus the gradient, not projected"]
    plain = ex.shortcuts["the DLS step alone (no null-space term)"]
    for case, expected in _valid("06.null_space_step"):
        J, e, g, lam, k = case.args
        if not np.any(g) or k == 0:
            continue
        assert "as it is" in ex.compare(expected, unprojected(*case.args))
        assert "null-space term" in ex.compare(expected, plain(*case.args))
        dq = np.array(expected["dq"])
        null = dq - plain(*case.args)
        assert "null-space term" in ex.compare(expected, dq - 2 * null)               # the gradient's sign flipped
        if lam > 0:
            undamped = np.array(J).T @ np.linalg.solve(np.array(J) @ np.array(J).T, e) + null
            assert "damping" in ex.compare(expected, undamped)


# --- 06.track_path: the loop, graded on its outcome ---------------------------------------------------
def _loop_with(**changes):
    """The reference loop with one thing changed (a student's mistake)."""
    def loop(dh, qmin, qmax, q_start, targets, settings):
        return tracking.track_path(dh, qmin, qmax, q_start, targets, {**settings, **changes})
    return loop


def test_loop_feedback_shows_the_run():
    ex = _exercise("06.track_path")
    case, expected = _valid("06.track_path")[0]
    steps = expected["settings"]["steps"]
    assert ex.compare(expected, ex.answer(*case.args)) is None
    msg = ex.compare(expected, _loop_with(steps=5)(*case.args))                       # stops early
    assert "shape" in msg
    short = np.array(_loop_with(damping=3.0)(*case.args))                              # far too damped to arrive
    msg = ex.compare(expected, short)
    assert "target 1 of" in msg and "not reached" in msg and "iterations 1:" in msg and f"{steps}:" in msg, msg
    msg = ex.compare(expected, _loop_with(max_step=10.0, gain=20.0)(*case.args))      # no step limit to speak of
    assert msg and "more than max_step" in msg, msg
    msg = ex.compare(expected, ex.shortcuts["plain DLS (no secondary task)"](*case.args))
    assert "secondary task" in msg and "plain DLS ends at" in msg, msg
    run = np.array(ex.answer(*case.args))
    tighter = {**expected, "qmax": list(expected["qmax"])}
    tighter["qmax"][2] = float(run[:, 2].max()) - 1e-3             # joint 3's range ends just inside the run
    msg = ex.compare(tighter, run)
    assert "puts joint 3" in msg and "beyond its limits" in msg, msg


def test_check_fails_a_loop_that_turns_the_wrong_way():
    """A loop that aims at the transposed rotation of every target (the orientation error taken the wrong
    way round) misses the poses, and check() says so."""
    def wrong(dh, qmin, qmax, q_start, targets, settings):
        flipped = []
        for T in targets:
            T = np.array(T)
            T[:3, :3] = T[:3, :3].T                     # any wrong orientation target misses the pose
            flipped.append(T)
        return tracking.track_path(dh, qmin, qmax, q_start, flipped, settings)

    with pytest.raises(AssertionError):
        check("06.track_path", wrong)


@pytest.mark.parametrize("seed", [0, 1])
def test_loop_shortcuts_fail_every_case(seed):
    ex = _exercise("06.track_path")
    for case, expected in _valid("06.track_path", seed):
        assert ex.compare(expected, ex.answer(*case.args)) is None
        for name, shortcut in ex.shortcuts.items():
            assert ex.compare(expected, shortcut(*case.args)) is not None, name


def test_loop_cases_are_what_their_labels_say():
    """Starts far from mid-range, inside the limits; plain DLS ends well above the reference in joint-range cost."""
    for seed in (0, 1):
        for case, expected in _valid("06.track_path", seed):
            q0, qmin, qmax = (np.array(expected[k]) for k in ("q_start", "qmin", "qmax"))
            assert np.all((q0 > qmin) & (q0 < qmax))
            assert expected["cost_start"] >= 1.2
            assert expected["cost_dls"] - expected["cost_reference"] >= tracking.TRACK_MARGIN
            assert len(expected["targets"]) == tracking.TRACK_WAYPOINTS
