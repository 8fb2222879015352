"""Assignment 06 exercises: registration and check() catching wrong answers (references: test_exercises_references.py)."""
import numpy as np
import pytest

from robokit.exercises import redundant_ik
from robokit.grading import check, exercises_for
from tests.conftest import assert_check_passes

EXERCISES = exercises_for("06_redundant_ik")


def test_assignment_is_registered():
    assert redundant_ik.ASSIGNMENT == "06_redundant_ik"
    assert len(EXERCISES) >= 7
    assert set(redundant_ik.WRITTEN) == {"06.extra_dof"}
    assert {e.id for e in EXERCISES} >= {"06.dh_transform", "06.forward_kinematics", "06.geometric_jacobian",
                                         "06.wrist_centre", "06.elbow_angle", "06.shoulder_angles",
                                         "06.null_space_step"}


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
