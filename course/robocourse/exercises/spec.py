"""Exercises: what a student implements and the cases it is tried on.

An :class:`Exercise` names the function a student writes, generates plain-data input cases
(:class:`Case`) from a random generator (the public seed for ``check()``, the instructor's secret
seed for grading), holds the function that computes the expected answers (a robokit function, as
a rule) and the :mod:`~robocourse.exercises.compare` comparison that accepts or rejects an answer. Running
the cases and judging the answers is :mod:`robocourse.grading`'s business.
"""
from __future__ import annotations

import dataclasses
import hashlib
import re
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from robocourse.exercises.compare import Comparison, close
from robokit.validation import as_int, as_text
from robocourse.exercises.plain import numeric_array, summarize, to_plain

__all__ = ["Case", "Exercise", "EXERCISE_ID", "KINDS", "PUBLIC_SEED"]

#: Seed of the public cases that ``check()`` runs in the student's notebook; grading uses the
#: instructor's secret seed.
PUBLIC_SEED = 2024
#: An exercise or written-question id: the two-digit lesson number, a dot and a snake_case name.
EXERCISE_ID = re.compile(r"^\d\d\.[a-z][a-z0-9_]*$")
#: What an exercise asks of the student (issue 37), by name:
#:
#: * ``"warm-up"``: a transcription worth at most one point;
#: * ``"transcription"``: the task (or the lesson) states the formula or the procedure and the student
#:   codes it;
#: * ``"derivation"``: the student works out a formula or procedure the task does not state, from a
#:   definition or a model (IK from FK, a Jacobian, a signed distance);
#: * ``"open"``: any method passes; graded on the outcome;
#: * ``"loop"``: assembles a loop the lesson is about, graded on the outcome over hidden seeded runs.
KINDS = ("warm-up", "transcription", "derivation", "open", "loop")
#: The most a warm-up is worth.
WARM_UP_POINTS = 1


@dataclasses.dataclass(frozen=True)
class Case:
    """One input case: positional ``args`` and keyword ``kwargs`` (plain data only).

    ``raises`` names the exception class the function must raise (e.g. ``"ValueError"``), for
    bad-input cases; a subclass is accepted. ``label`` says what the case tests, for feedback.
    ``expected`` is the case's right answer when its generator knows a truth that no function of the
    inputs can compute (a simulator's: lesson 04's touchdowns are MuJoCo's contacts); the grader and
    ``check()`` then compare with it instead of calling the exercise's ``answer``. Like the label,
    it never reaches the grading worker, which gets only ``args`` and ``kwargs``. The inputs and
    ``expected`` are converted to plain data; anything else raises
    :class:`~robocourse.exercises.plain.NotPlainData`.

    Examples
    --------
    >>> Case(((1, 2),), label="a tuple").args
    ([1, 2],)
    >>> Case(([0.0, 9.0, 9.0],), expected=(1,)).expected
    [1]
    """

    args: tuple = ()
    kwargs: dict = dataclasses.field(default_factory=dict)
    raises: str | None = None
    label: str = ""
    expected: Any = None

    def __post_init__(self):
        object.__setattr__(self, "args", tuple(to_plain(list(self.args))))
        object.__setattr__(self, "kwargs", to_plain(dict(self.kwargs)))
        if self.expected is not None:
            if self.raises:
                raise ValueError("expected: a case that must raise has no expected answer")
            object.__setattr__(self, "expected", to_plain(self.expected))

    def call_text(self, function: str, limit: int = 400) -> str:
        """The call this case makes, for feedback: ``function(arg, ..., key=value)``.

        Each argument is shortened by :func:`~robocourse.exercises.plain.summarize` (large arrays
        show their shape and ends) and the whole text is at most ``limit`` characters, so a failing
        case can always show the student the inputs that broke it.

        Examples
        --------
        >>> Case(("$GPRMC,A*00", 2), {"strict": True}).call_text("parse")
        "parse('$GPRMC,A*00', 2, strict=True)"

        Raises
        ------
        TypeError, ValueError
            If ``function`` is not a non-empty string or ``limit`` is not an integer >= 16.
        """
        function = as_text(function, "function", empty=False)
        limit = as_int(limit, "limit", minimum=16)
        def show(value: Any) -> str:          # a list of numbers reads as the array it stands for
            arr = numeric_array(value) if isinstance(value, list) else None
            return summarize(value if arr is None or arr.size < 2 else arr, 160)

        parts = [show(a) for a in self.args]
        parts += [f"{k}={show(v)}" for k, v in self.kwargs.items()]
        text = f"{function}({', '.join(parts)})"
        return text if len(text) <= limit else text[: limit - 4] + "...)"


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
    answer : callable
        Computes the expected output of a (non-raising) case; called by the trusted grader only.
        For a case that carries its ``expected`` answer (a simulator's truth), it is the reference
        solution, tested on the cases like any answer but not called to grade them.
    compare : callable
        ``compare(expected, got) -> None | message``; defaults to :func:`~robocourse.exercises.compare.close`.
    description : str
        One sentence for the instructor's overview.
    kind : str, default "transcription"
        What the exercise asks, one of :data:`KINDS`; a warm-up is worth at most one point. The
        default is the weakest claim, so an exercise nobody classified counts as a transcription.
    shortcuts : dict of str to callable
        Known ways to pass some cases without solving the exercise, by name (e.g. ``"the heaviest
        particle, repeated"``): functions of a case's inputs. With the constants and the other
        trivial answers of :mod:`~robocourse.exercises.trivial` they decide which passes count.

    Raises
    ------
    ValueError
        For a malformed ``id``, a ``function`` that is not an identifier, non-positive ``points``,
        ``shortcuts`` that are not named functions, a ``kind`` not in :data:`KINDS` or a warm-up worth
        more than one point.

    Examples
    --------
    >>> ex = Exercise(id="00.double", function="double", signature="double(x: float) -> float",
    ...               points=1, cases=lambda rng: [Case((float(rng.integers(10)),))],
    ...               answer=lambda x: 2 * x)
    >>> ex.lesson, len(ex.make_cases(2024)), ex.kind
    ('00', 1, 'transcription')
    """

    id: str
    function: str
    signature: str
    points: float
    cases: Callable[[np.random.Generator], Sequence[Case]]
    answer: Callable[..., Any]
    compare: Comparison = dataclasses.field(default_factory=close)
    description: str = ""
    kind: str = "transcription"
    shortcuts: Mapping[str, Callable[..., Any]] = dataclasses.field(default_factory=dict, hash=False, compare=False)

    def __post_init__(self):
        if not isinstance(self.id, str) or not EXERCISE_ID.match(self.id):
            raise ValueError(f"id: expected 'NN.name' (e.g. '05.nmea_checksum'), got {self.id!r}")
        if not self.function.isidentifier():
            raise ValueError(f"function: expected a Python identifier, got {self.function!r}")
        if not self.points > 0:
            raise ValueError(f"points: expected a positive number, got {self.points!r}")
        if not all(isinstance(k, str) and callable(f) for k, f in dict(self.shortcuts).items()):
            raise ValueError("shortcuts: expected a dict of names to functions")
        if self.kind not in KINDS:
            raise ValueError(f"kind: expected one of {list(KINDS)}, got {self.kind!r}")
        if self.kind == "warm-up" and self.points > WARM_UP_POINTS:
            raise ValueError(f"kind: a warm-up is worth at most {WARM_UP_POINTS} point, got {self.points!r} points; "
                             "call it a transcription (or make it ask more)")
        object.__setattr__(self, "shortcuts", dict(self.shortcuts))

    @property
    def lesson(self) -> str:
        """The two-digit lesson number, e.g. ``"05"``."""
        return self.id[:2]

    def make_cases(self, seed: int | str) -> list[Case]:
        """Return the cases for a seed (an integer or the instructor's secret string).

        The generator is seeded from a hash of ``seed`` and the exercise id, so every exercise
        gets its own stream and the same seed always gives the same cases.

        Raises
        ------
        TypeError
            If ``cases(rng)`` does not return a non-empty list of :class:`Case`.
        """
        digest = hashlib.sha256(f"{seed}\x00{self.id}".encode()).digest()
        rng = np.random.default_rng(int.from_bytes(digest[:8], "little"))
        cases = list(self.cases(rng))
        if not cases or not all(isinstance(c, Case) for c in cases):
            raise TypeError(f"{self.id}: cases(rng) must return a non-empty list of Case")
        return cases
