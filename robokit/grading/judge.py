"""Judging: the expected answer of a case, a call of the student's function, and the verdict.

The same three steps serve ``check()`` (in the student's notebook, public cases) and the grader
(trusted parent; the call itself happens in the sandboxed worker), so feedback and grades agree.
"""
from __future__ import annotations

import dataclasses
from typing import Any, Callable

from ..exercises.plain import NotPlainData, summarize, to_plain
from ..exercises.spec import Case, Exercise

__all__ = ["Outcome", "judge", "expected_output", "call_student"]


@dataclasses.dataclass
class Outcome:
    """The verdict on one case: ``passed`` and a one-line ``message``."""

    case: Case
    passed: bool
    message: str


def expected_output(exercise: Exercise, case: Case) -> Any:
    """Return the reference answer for ``case`` as plain data (``None`` for raising cases)."""
    if case.raises:
        return None
    return to_plain(exercise.reference(*case.args, **case.kwargs))


def judge(exercise: Exercise, case: Case, expected: Any, result: dict) -> Outcome:
    """Judge one student result against the expected answer.

    ``result`` is what running the student's function produced, as plain data:
    ``{"value": ...}`` on return, or ``{"error": {"type": name, "mro": [names], "message": str}}``.
    """
    label = f" ({case.label})" if case.label else ""
    if "error" in result:
        err = result["error"]
        mro = err.get("mro") or [err.get("type")]
        if case.raises and case.raises in mro:
            return Outcome(case, True, f"raised {err.get('type')} as expected{label}")
        if err.get("type") == "NotImplementedError":
            return Outcome(case, False, "not implemented yet")
        want = f"expected {case.raises}" if case.raises else "expected a result"
        return Outcome(case, False, f"{want}{label}, but it raised {err.get('type')}: {err.get('message', '')}")
    if case.raises:
        return Outcome(case, False, f"expected {case.raises} for bad input{label}, got {summarize(result.get('value'))}")
    msg = exercise.compare(expected, result.get("value"))
    return Outcome(case, msg is None, msg or f"ok{label}")


def call_student(fn: Callable[..., Any], case: Case) -> dict:
    """Call ``fn`` on a case in this process and return its result as plain data (see :func:`judge`)."""
    import copy

    try:
        value = fn(*copy.deepcopy(case.args), **copy.deepcopy(case.kwargs))
    except Exception as exc:  # the student's exception is data here
        return {"error": {"type": type(exc).__name__, "mro": [c.__name__ for c in type(exc).__mro__],
                          "message": str(exc)[:500], "line": _student_line(exc)}}
    try:
        return {"value": to_plain(value)}
    except NotPlainData as exc:
        return {"error": {"type": "NotPlainData", "mro": ["NotPlainData"], "message": str(exc)}}


def _student_line(exc: BaseException) -> str:
    """Return "line N: source" of the innermost frame outside robokit's grading code."""
    import traceback

    for frame in reversed(traceback.extract_tb(exc.__traceback__)):
        if "/robokit/grading/" not in frame.filename.replace("\\", "/"):
            return f"line {frame.lineno}: {frame.line}" if frame.line else f"line {frame.lineno}"
    return ""
