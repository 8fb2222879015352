"""Trivial answers: what a function that does not solve an exercise can still get right.

Some cases expect a degenerate value on purpose (``None`` when nothing qualifies, an empty array,
a margin of ``0.0``, every particle resampled from the one that holds all the weight), an exercise
whose answer takes a few values repeats them across cases, and hidden cases may repeat public ones
whose answers ``check()`` shows. A function that returns a constant, looks up the public answers,
returns an argument unchanged or takes an exercise's known shortcut passes such cases without
solving anything. So the grader works out, for each valid case, which trivial answers pass it
(:func:`trivial_passes`), and counts an exercise's cases only when the passes show work
(:func:`explained`):

* a passed case that no trivial answer passes but its own answer (a *non-degenerate* case); or,
  in a draw of cases where every valid case has another trivial answer (answers from a few
  values, like a direction or an index),
* passes that no single trivial answer gives all of (e.g. two different directions).

The trivial answers, the same set for every case of one draw (the grader computes them; the student
never sees them):

* the constants ``None``, ``True``, ``False``, ``0``, ``0.0``, ``""``, ``[]`` and ``{}``, and zeros
  shaped like the expected answer;
* each valid case's answer, as a constant (``"case 3's answer, always"``);
* each public case's answer, as a constant, and the public answers looked up by their inputs;
* each value inside the assignment's data (what the kit hands the notebook: a number, a list, any
  nested list or dict in it), as a constant (:func:`data_values`);
* each positional argument, returned unchanged;
* the exercise's ``shortcuts``: named functions of the case's inputs.
"""
from __future__ import annotations

import json
from typing import Any, Sequence

import numpy as np

from robocourse.exercises.plain import numeric_array, to_plain
from robocourse.exercises.spec import Case, Exercise

__all__ = ["CONSTANTS", "LOOKUP", "trivial_passes", "explained", "own_answer", "data_values"]

#: The constants every case is tried against.
CONSTANTS: tuple = (None, True, False, 0, 0.0, "", [], {})
#: The name of the trivial answer that looks up the public cases' answers by their inputs.
LOOKUP = "the public answers, looked up by their inputs"


def own_answer(i: int) -> str:
    """The name of case ``i``'s (0-based) own answer as a constant trivial answer."""
    return f"case {i + 1}'s answer, always"


def _inputs_key(case: Case) -> str:
    """A case's inputs as text, to find hidden cases that repeat a public one."""
    return json.dumps([list(case.args), case.kwargs], sort_keys=True, default=lambda a: np.asarray(a).tolist())


def data_values(data: Any) -> list:
    """Every value inside an assignment's data: the data itself, each dict value and list item, nested.

    Examples
    --------
    >>> data_values({"top_k": 5, "legs": ["FL", "FR"]})
    [{'top_k': 5, 'legs': ['FL', 'FR']}, ['FL', 'FR'], 'FR', 'FL', 5]
    """
    out, stack = [], [data]
    while stack:
        v = stack.pop()
        out.append(v)
        stack.extend(v.values() if isinstance(v, dict) else v if isinstance(v, list) else ())
    return out


def _candidates(exercise: Exercise, cases: Sequence[Case], expected: Sequence[Any],
                public: dict[str, Any], i: int, data: Sequence[Any]) -> list[tuple[str, Any]]:
    """``(name, answer)`` of every trivial answer on case ``i`` (see the module docstring)."""
    case, own = cases[i], expected[i]
    out = [(f"the constant {c!r}", c) for c in CONSTANTS]
    arr = numeric_array(own)
    if arr is not None and arr.size:
        out.append(("zeros shaped like the answer", np.zeros(arr.shape)))
    out += [(own_answer(j), expected[j]) for j in range(len(cases)) if not cases[j].raises]
    out += [(f"public case {k + 1}'s answer, always", answer) for k, answer in enumerate(public.values())]
    if _inputs_key(case) in public:
        out.append((LOOKUP, public[_inputs_key(case)]))
    out += [(f"argument {k + 1}, returned unchanged", to_plain(arg)) for k, arg in enumerate(case.args)]
    out += [(f"a value of the assignment's data ({value!r:.40})", value) for value in data]
    for name, shortcut in exercise.shortcuts.items():
        try:
            out.append((name, to_plain(shortcut(*case.args, **case.kwargs))))
        except Exception:  # a shortcut that does not apply to this case's inputs gives nothing
            continue
    return out


def trivial_passes(exercise: Exercise, cases: Sequence[Case], expected: Sequence[Any],
                   public: Sequence[tuple[Case, Any]] = (), data: Sequence[Any] = ()) -> list[frozenset[str]]:
    """For each case, the names of the trivial answers that pass it (empty for bad-input cases).

    Parameters
    ----------
    exercise : Exercise
    cases : sequence of Case
    expected : sequence
        The cases' expected answers as plain data (``None`` for bad-input cases).
    public : sequence of (Case, answer)
        The exercise's valid public cases and their answers (``check()`` shows them).
    data : sequence
        The values of the assignment's data (:func:`data_values`), each tried as a constant.

    Notes
    -----
    Computed by the trusted grader with the exercise's own comparison; a trivial answer the
    comparison cannot take passes nothing. Grading design (DESIGN.md, "Grading").

    Examples
    --------
    >>> from robocourse.exercises.spec import Case, Exercise
    >>> ex = Exercise(id="00.sign", function="sign", signature="sign(x) -> int", points=1,
    ...               cases=lambda rng: [], answer=lambda x: int(np.sign(x)))
    >>> cases = [Case((2.0,)), Case((0.0,)), Case((-3.0,)), Case((5.0,))]
    >>> [sorted(s) for s in trivial_passes(ex, cases, [1, 0, -1, 1])][::3]
    [["case 1's answer, always", "case 4's answer, always"], ["case 1's answer, always", "case 4's answer, always"]]
    """
    known = {_inputs_key(c): a for c, a in public}
    out = []
    for i, case in enumerate(cases):
        if case.raises:
            out.append(frozenset())
            continue
        names = set()
        for name, answer in _candidates(exercise, cases, expected, known, i, data):
            try:
                if exercise.compare(expected[i], answer) is None:
                    names.add(name)
            except Exception:  # an answer the comparison cannot take passes nothing
                continue
        out.append(frozenset(names))
    return out


def explained(passed: Sequence[int], valid: Sequence[int], trivial: Sequence[frozenset[str]]) -> str | None:
    """Why the passes ``passed`` (indices of valid cases) show no work, or ``None`` if they do.

    ``valid`` holds every valid case's index and ``trivial`` the names :func:`trivial_passes`
    gave. Returns ``"nothing passed"``, the name of one trivial answer, or ``"trivial answers only"``.

    Examples
    --------
    >>> t = [frozenset({"the constant None", "case 1's answer, always"}), frozenset({"case 2's answer, always"}),
    ...      frozenset({"the constant None", "case 3's answer, always"})]
    >>> explained([0, 2], [0, 1, 2], t), explained([0, 1], [0, 1, 2], t), explained([], [0, 1, 2], t)
    ('trivial answers only', None, 'nothing passed')
    >>> explained([0, 2], [0, 2], t)        # no non-degenerate case in this draw: one trivial answer
    'the constant None'
    """
    if not passed:
        return "nothing passed"

    def degenerate(i: int) -> bool:
        return bool(trivial[i] - {own_answer(i)})

    if any(not degenerate(i) for i in passed):
        return None
    if any(not degenerate(i) for i in valid):
        return "trivial answers only"
    common = frozenset.intersection(*(trivial[i] for i in passed))
    return min(common) if common else None
