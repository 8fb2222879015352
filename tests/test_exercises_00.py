"""Assignment 00: the compounding exercise is a derivation whose feedback names the wrong part."""
from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

from robocourse.grading import check
from robocourse.grading.check import CheckFailed
from robocourse.lessons import exercises_for
from robokit.geometry import se2_compose, wrap_angle
from tests.conftest import assert_check_passes

EXERCISES = {ex.id: ex for ex in exercises_for("00_getting_started")}


def _report(fn) -> str:
    """What check() prints and the failures it raises, as one text."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(CheckFailed) as failed:
        check("00.se2_compose", fn)
    return out.getvalue() + str(failed.value)


def _shape(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape != (3,) or b.shape != (3,):
        raise ValueError("a, b")
    return a, b


def _unrotated(a, b):        # adds b's offset in the world's axes
    a, b = _shape(a, b)
    return np.array([a[0] + b[0], a[1] + b[1], wrap_angle(a[2] + b[2])])


def _rotated_backwards(a, b):   # rotates b's offset by -theta_a
    a, b = _shape(a, b)
    c, s = np.cos(a[2]), np.sin(a[2])
    return np.array([a[0] + c * b[0] + s * b[1], a[1] - s * b[0] + c * b[1], wrap_angle(a[2] + b[2])])


def _unwrapped(a, b):        # forgets to wrap the heading
    a, b = _shape(a, b)
    return np.array([*se2_compose(a, b)[:2], a[2] + b[2]])


def test_the_reference_passes_and_the_kind_is_a_derivation():
    exercise = EXERCISES["00.se2_compose"]
    assert exercise.kind == "derivation" and exercise.points == 2
    assert_check_passes("00.se2_compose", se2_compose, len(exercise.make_cases(2024)))


@pytest.mark.parametrize("wrong, hint", [
    (_unrotated, "the position is wrong"),
    (_rotated_backwards, "the position is wrong"),
    (_unwrapped, "the heading is right up to a whole turn"),
])
def test_feedback_names_the_wrong_part(wrong, hint):
    report = _report(wrong)
    assert "public cases passed" in report and hint in report, report
    if wrong is not _unwrapped:
        assert "the heading is" not in report, report


@pytest.mark.parametrize("bad", ["", "abc", None, [1.0, 2.0], ["a", "b", "c"], [True, False, True], {"x": 1},
                                 [0.0, 0.0, float("nan")], [10 ** 400, 0, 0]])
def test_an_answer_that_is_not_a_pose_gets_a_message_not_an_error(bad):
    exercise = EXERCISES["00.se2_compose"]
    expected = se2_compose([1.0, 2.0, 0.3], [0.5, -0.2, 0.1]).tolist()
    message = exercise.compare(expected, bad)
    assert isinstance(message, str) and message
