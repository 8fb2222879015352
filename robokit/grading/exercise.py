"""Exercises: what a student implements, the cases it is tried on and how answers are judged.

An :class:`Exercise` names the function a student writes, generates plain-data input cases from a
random generator (public seed for ``check()``, the instructor's secret seed for grading), computes
the expected answers with a robokit reference implementation and judges answers with a
:mod:`~robokit.grading.compare` comparison. Cases may expect an exception (bad input).
"""
from __future__ import annotations

import dataclasses
import re
from typing import Any, Callable, Sequence

import numpy as np

from .compare import Comparison, close
from .plain import NotPlainData, summarize, to_plain

__all__ = ["Case", "Exercise", "Outcome", "judge", "expected_output", "call_student"]

_ID = re.compile(r"^\d\d\.[a-z][a-z0-9_]*$")


@dataclasses.dataclass(frozen=True)
class Case:
    """One input case: positional ``args`` and keyword ``kwargs`` (plain data only).

    ``raises`` names the exception class the function must raise (e.g. ``"ValueError"``), for
    bad-input cases; a subclass is accepted. ``label`` says what the case tests, for feedback.
    """

    args: tuple = ()
    kwargs: dict = dataclasses.field(default_factory=dict)
    raises: str | None = None
    label: str = ""

    def __post_init__(self):
        object.__setattr__(self, "args", tuple(to_plain(list(self.args))))
        object.__setattr__(self, "kwargs", to_plain(dict(self.kwargs)))


@dataclasses.dataclass(frozen=True)
class Exercise:
    """A graded exercise.

    Parameters
    ----------
    id : str
        ``"NN.name"``, e.g. ``"05.nmea_checksum"``; ``NN`` is the lesson number.
    function : str
        Name of the function the student defines in the notebook.
    signature : str
        The signature shown to students, e.g. ``"nmea_checksum(sentence: str) -> str"``.
    points : float
        Points for passing every case (partial credit is proportional to cases passed).
    cases : callable
        ``cases(rng) -> list[Case]``; must be deterministic for a given generator.
    reference : callable
        The robokit implementation computing the expected output of a (non-raising) case.
    compare : callable
        ``compare(expected, got) -> None | message``; defaults to :func:`~robokit.grading.compare.close`.
    references : tuple of str
        Dotted names of robokit functions the student must not call (they are disabled while
        grading); defaults to the reference itself.
    """

    id: str
    function: str
    signature: str
    points: float
    cases: Callable[[np.random.Generator], Sequence[Case]]
    reference: Callable[..., Any]
    compare: Comparison = dataclasses.field(default_factory=close)
    references: tuple[str, ...] = ()
    description: str = ""

    def __post_init__(self):
        if not _ID.match(self.id):
            raise ValueError(f"id: expected 'NN.name' (e.g. '05.nmea_checksum'), got {self.id!r}")
        if not self.function.isidentifier():
            raise ValueError(f"function: expected a Python identifier, got {self.function!r}")
        if not self.points > 0:
            raise ValueError(f"points: expected a positive number, got {self.points!r}")
        if not self.references:
            ref = f"{self.reference.__module__}.{self.reference.__qualname__}"
            object.__setattr__(self, "references", (ref,))

    @property
    def lesson(self) -> str:
        """The two-digit lesson number, e.g. ``"05"``."""
        return self.id[:2]

    def make_cases(self, seed: int | str) -> list[Case]:
        """Return the cases for a seed (an integer or the instructor's secret string)."""
        rng = np.random.default_rng(_seed_int(seed, self.id))
        cases = list(self.cases(rng))
        if not cases or not all(isinstance(c, Case) for c in cases):
            raise TypeError(f"{self.id}: cases(rng) must return a non-empty list of Case")
        return cases


def _seed_int(seed: int | str, salt: str) -> int:
    import hashlib

    return int.from_bytes(hashlib.sha256(f"{seed}\x00{salt}".encode()).digest()[:8], "little")


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
