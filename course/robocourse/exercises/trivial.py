"""Trivial answers: what a function that does not solve an exercise can still get right.

Some cases expect a degenerate value on purpose (``None`` when nothing qualifies, an empty array,
a margin of ``0.0``, every particle resampled from the one that holds all the weight), and an
exercise whose answer takes a few values repeats them across cases. A function that returns a
constant, or one of its arguments unchanged, or an exercise's known shortcut, passes such cases
without solving anything. The grader therefore asks, for each valid case, which trivial answers
pass it (:func:`trivial_passes`), and counts an exercise's cases only when the function has passed
valid cases that no single trivial answer passes all of (:func:`explained_by_one`).

The trivial answers of a case (the grader computes them; the student never sees them):

* the constants ``None``, ``True``, ``False``, ``0``, ``0.0``, ``""``, ``[]`` and ``{}``;
* zeros shaped like the expected answer (a numeric array or list);
* the answer of every other case of the same exercise, as a constant (answers that repeat);
* the case's own answer as a constant, when it is a string, a boolean or an integer (a value a
  student can guess from the exercise's statement);
* the answer of every public case (those ``check()`` shows the student), as a constant: many
  hidden cases are the public ones again, so their answers can be copied;
* each positional argument, returned unchanged;
* the exercise's ``shortcuts``: named functions of the case's inputs (e.g. the heaviest particle,
  repeated).
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from robocourse.exercises.plain import numeric_array, to_plain
from robocourse.exercises.spec import Case, Exercise

__all__ = ["CONSTANTS", "trivial_passes", "explained_by_one"]

#: The constants every case is tried against.
CONSTANTS: tuple = (None, True, False, 0, 0.0, "", [], {})


def _guessable(value: Any) -> bool:
    """A discrete answer a student could return without computing it: a string, bool or integer."""
    return type(value) in (str, bool, int)


def _candidates(exercise: Exercise, cases: Sequence[Case], expected: Sequence[Any], public: Sequence[Any],
                i: int) -> list[tuple[str, Any]]:
    """``(name, answer)`` of every trivial answer for case ``i`` (see the module docstring)."""
    case, own = cases[i], expected[i]
    out = [(f"the constant {c!r}", c) for c in CONSTANTS]
    out += [(f"public case {k + 1}'s answer, always", answer) for k, answer in enumerate(public)]
    arr = numeric_array(own)
    if arr is not None and arr.size:
        out.append(("zeros shaped like the answer", np.zeros(arr.shape)))
    for j, other in enumerate(expected):
        if cases[j].raises:
            continue
        if j != i:
            out.append((f"the constant {_short(other)}" if _guessable(other) else f"case {j + 1}'s answer, always",
                        other))
        elif _guessable(own):
            out.append((f"the constant {_short(own)}", own))
    out += [(f"argument {k + 1}, returned unchanged", arg) for k, arg in enumerate(case.args)]
    for name, shortcut in exercise.shortcuts.items():
        try:
            out.append((name, to_plain(shortcut(*case.args, **case.kwargs))))
        except Exception:  # a shortcut that does not apply to this case's inputs gives nothing
            continue
    return out


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def trivial_passes(exercise: Exercise, cases: Sequence[Case], expected: Sequence[Any],
                   public: Sequence[Any] = ()) -> list[frozenset[str]]:
    """For each case, the names of the trivial answers that pass it (empty for bad-input cases).

    ``expected`` holds the cases' expected answers as plain data (``None`` for bad-input cases);
    ``public`` the answers of the exercise's public cases (valid ones), which the student sees.
    Computed by the trusted grader with the exercise's own comparison.

    Examples
    --------
    >>> from robocourse.exercises.spec import Case, Exercise
    >>> ex = Exercise(id="00.sign", function="sign", signature="sign(x) -> int", points=1,
    ...               cases=lambda rng: [], answer=lambda x: int(np.sign(x)))
    >>> cases = [Case((2.0,)), Case((0.0,)), Case((-3.0,))]
    >>> [sorted(s)[:2] for s in trivial_passes(ex, cases, [1, 0, -1])]
    [['the constant 1'], ['argument 1, returned unchanged', 'the constant 0'], ['the constant -1']]
    """
    out = []
    for i, case in enumerate(cases):
        if case.raises:
            out.append(frozenset())
            continue
        names = set()
        for name, answer in _candidates(exercise, cases, expected, public, i):
            try:
                if exercise.compare(expected[i], answer) is None:
                    names.add(name)
            except Exception:  # an answer the comparison cannot take passes nothing
                continue
        out.append(frozenset(names))
    return out


def explained_by_one(passed: Sequence[int], trivial: Sequence[frozenset[str]]) -> str | None:
    """The name of one trivial answer that passes every case in ``passed`` (indices of the valid
    cases a function passed), or ``None`` if none does; an empty ``passed`` is explained by
    ``"nothing"``.

    Examples
    --------
    >>> t = [frozenset({"the constant None"}), frozenset({"the constant None", "the constant 0"}), frozenset()]
    >>> explained_by_one([0, 1], t), explained_by_one([1, 2], t), explained_by_one([], t)
    ('the constant None', None, 'nothing')
    """
    if not passed:
        return "nothing"
    common = frozenset.intersection(*(trivial[i] for i in passed))
    return min(common) if common else None
