"""Assignment 06 exercises: registration and check() catching wrong answers (references: test_exercises_references.py)."""
import numpy as np
import pytest

from robocourse.lessons.redundant_ik import exercises as redundant_ik
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
                                         "06.null_space_step", "06.solve_ik"}


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


@pytest.mark.parametrize("seed", [0, 1, 2024])
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
