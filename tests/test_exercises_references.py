"""Every registered exercise: its answer passes its own cases, bad input included, for any seed.

One test for all assignments (discovered from robocourse/lessons/), so a new lesson's exercises are
covered without copying this test.
"""
import pytest

from robocourse.lessons import assignments
from robocourse.grading.judge import call_student, expected_output, judge

ALL = [ex for exercises in assignments().values() for ex in exercises]


def test_every_assignment_has_exercises():
    assert len(assignments()) >= 4 and all(assignments().values())


#: The draws every answer is judged on: ``make test`` takes the public draw and one secret-like seed,
#: ``make check`` all five.
SEEDS = ["public", pytest.param(7, marks=pytest.mark.slow), pytest.param(2024, marks=pytest.mark.slow),
         pytest.param(12345, marks=pytest.mark.slow), "instructor-secret"]


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("exercise", ALL, ids=lambda e: e.id)
def test_the_answer_passes_its_own_cases(exercise, seed):
    cases = exercise.make_cases(seed)
    assert any(c.raises for c in cases), f"{exercise.id}: every exercise needs a bad-input case"
    for case in cases:
        outcome = judge(exercise, case, expected_output(exercise, case), call_student(exercise.answer, case))
        assert outcome.passed, f"{exercise.id} {case.label}: {outcome.message}"
