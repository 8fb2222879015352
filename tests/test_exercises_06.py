"""Assignment 06 exercises: registration and check() catching wrong answers (references: test_exercises_references.py)."""
import numpy as np
import pytest

from robokit.exercises import redundant_ik
from robokit.grading import check, exercises_for
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
        check(exercise.id, _wrong(exercise.reference))
    assert_check_passes(exercise.id, exercise.reference, len(exercise.make_cases(2024)))


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


def test_open_ik_tempting_shortcut_fails_some_cases():
    """Taking arm angle 0 (the reference plane) and the first branch inside the limits, without
    searching the arm angle, fails the cases where no branch is inside at psi = 0."""
    from robokit.arm import ik_srs_branches, iiwa14

    arm = iiwa14()

    def psi_zero(T, q_start):
        inside = ik_srs_branches(arm, T, 0.0)
        if len(inside):
            return inside[0]
        every = ik_srs_branches(arm, T, 0.0, within_limits=False)
        if not len(every):
            raise ValueError("T: out of reach")
        return every[0]

    with pytest.raises(AssertionError, match="arm angle 0 breaks a limit"):
        check("06.solve_ik", psi_zero)
