"""Judging: the expected answer of a case, a call of the student's function, and the verdict.

The same three steps serve ``check()`` (in the student's notebook, public cases) and the grader
(trusted parent; the call itself happens in the sandboxed worker), so feedback and grades agree.
"""
from __future__ import annotations

import copy
import dataclasses
import traceback
from typing import Any, Callable

from robocourse.exercises.plain import MAX_ANSWER_VALUES, count_values, summarize, to_plain
from robocourse.exercises.spec import Case, Exercise
from robocourse.grading.protocol import CallResult

__all__ = ["Outcome", "judge", "expected_output", "call_student"]


@dataclasses.dataclass
class Outcome:
    """The verdict on one case: ``passed`` and a one-line ``message``."""

    case: Case
    passed: bool
    message: str


def expected_output(exercise: Exercise, case: Case) -> Any:
    """Return the expected answer for ``case`` as plain data (``None`` for raising cases): the
    case's own ``expected`` where its generator knew the truth, else what the exercise's ``answer``
    computes."""
    if case.raises:
        return None
    if case.expected is not None:
        return case.expected
    return to_plain(exercise.answer(*case.args, **case.kwargs))


def judge(exercise: Exercise, case: Case, expected: Any, result: CallResult) -> Outcome:
    """Judge what the student's function gave on ``case`` (``result``) against ``expected``.

    A bad-input case passes when the function raised ``case.raises`` (or a subclass); any other
    case when ``exercise.compare`` accepts the value. A value of more than
    :data:`~robocourse.exercises.plain.MAX_ANSWER_VALUES` numbers fails without being compared; a
    value that cannot even be compared (e.g. an integer too large for a float) fails its case; it
    never raises. Grading design (DESIGN.md, "Grading").
    """
    try:
        return _judge(exercise, case, expected, result)
    except Exception as exc:  # the value came from student code; whatever it does to a comparison fails the case
        label = f" ({case.label})" if case.label else ""
        return Outcome(case, False, f"your result could not be compared with the expected one{label} "
                                    f"({type(exc).__name__})")


def _judge(exercise: Exercise, case: Case, expected: Any, result: CallResult) -> Outcome:
    label = f" ({case.label})" if case.label else ""
    err = result.error
    if err is not None:
        if case.raises and case.raises in (err.classes or (err.type,)):
            return Outcome(case, True, f"raised {err.type} as expected{label}")
        if err.type == "NotImplementedError":
            return Outcome(case, False, "not implemented yet")
        want = f"expected {case.raises}" if case.raises else "expected a result"
        return Outcome(case, False, f"{want}{label}, but it raised {err.type}: {err.message}")
    if case.raises:
        return Outcome(case, False, f"expected {case.raises} for bad input{label}, got {summarize(result.value)}")
    if count_values(result.value) > MAX_ANSWER_VALUES:     # judged by its size, before any comparison
        return Outcome(case, False, f"your result holds more than {MAX_ANSWER_VALUES:,} values{label}")
    msg = exercise.compare(expected, result.value)
    return Outcome(case, msg is None, msg or f"ok{label}")


def call_student(fn: Callable[..., Any], case: Case) -> CallResult:
    """Call ``fn`` on copies of a case's inputs in this process; the result as plain data.

    An exception from ``fn`` is data here (with the student's line for the feedback); a
    ``KeyboardInterrupt`` still stops the notebook.
    """
    try:
        value = fn(*copy.deepcopy(case.args), **copy.deepcopy(case.kwargs))
    except Exception as exc:  # the student's exception is data here
        return CallResult.raised(exc, line=_student_line(exc))
    return CallResult.returned(value)


def _student_line(exc: BaseException) -> str:
    """Return ``"line N: source"`` of the innermost frame outside robocourse's grading code."""
    for frame in reversed(traceback.extract_tb(exc.__traceback__)):
        if "/robocourse/grading/" not in frame.filename.replace("\\", "/"):
            return f"line {frame.lineno}: {frame.line}" if frame.line else f"line {frame.lineno}"
    return ""
