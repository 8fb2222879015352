"""``check(exercise_id, fn)``: immediate feedback on public cases inside the student's notebook.

The official grade comes from :mod:`robocourse.grading.grader` on hidden cases; while it grades, the
worker replaces ``check`` by a function that only prints that it is skipped.
"""
from __future__ import annotations

import types
from typing import Any, Callable

from robocourse.exercises.spec import PUBLIC_SEED
from robocourse.lessons import get_exercise
from robocourse.grading.judge import call_student, expected_output, judge

__all__ = ["check", "library_use", "PUBLIC_SEED", "CheckFailed", "NotImplementedYet"]



def library_use(fn: Callable[..., Any]) -> list[str]:
    """What of robokit a function's own code reaches: names it imports, and globals or closure
    values that are robokit objects (its nested functions included, not the functions it calls).

    The grading worker has no robokit, so such a function scores zero there; :func:`check` says so
    at once instead of passing the public cases.

    Examples
    --------
    >>> from robokit.geometry import wrap_angle as wrap
    >>> library_use(lambda angle: wrap(angle)), library_use(lambda angle: angle % 6.28)
    (['wrap (robokit.geometry.planar)'], [])
    """
    code = getattr(fn, "__code__", None)
    if not isinstance(code, types.CodeType):
        return []
    names, stack = set(), [code]
    while stack:
        c = stack.pop()
        names |= set(c.co_names)
        stack.extend(k for k in c.co_consts if isinstance(k, types.CodeType))
    values = {n: fn.__globals__[n] for n in names if n in getattr(fn, "__globals__", {})}
    for name, cell in zip(code.co_freevars, getattr(fn, "__closure__", None) or ()):
        try:
            values[name] = cell.cell_contents
        except ValueError:                      # an empty cell
            pass
    found = sorted(f"import of {n}" for n in names if n.split(".")[0] == "robokit")
    for name, value in sorted(values.items()):
        home = value.__name__ if isinstance(value, types.ModuleType) else getattr(value, "__module__", None)
        if isinstance(home, str) and home.split(".")[0] == "robokit":
            found.append(f"{name} ({home})")
    return found


class _MessageOnly:
    """Mixin: IPython shows only ``Name: message`` for these errors, not a traceback through robocourse.

    IPython asks an exception for ``_render_traceback_()`` before formatting a traceback; the cell
    still ends in an error (red, and a failed grade cell for nbgrader), but the student reads only
    what concerns their code.
    """

    def _render_traceback_(self) -> list[str]:
        return [f"{type(self).__name__}: {self}"]


class CheckFailed(_MessageOnly, AssertionError):
    """Some public cases of :func:`check` failed (an ``AssertionError``); the message lists them."""


class NotImplementedYet(_MessageOnly, NotImplementedError):
    """The function given to :func:`check` is still the assignment's stub (a ``NotImplementedError``)."""


def check(exercise_id: str, fn: Callable[..., Any], *, verbose: bool = True) -> None:
    """Run the public cases of an exercise on ``fn`` and print a short report.

    This is feedback only: it runs in your own notebook on public cases, and your grade comes
    from the instructor's grader on fresh hidden cases.

    Parameters
    ----------
    exercise_id : str
        E.g. ``"00.wrap_angle"``.
    fn : callable
        Your implementation.
    verbose : bool, default True
        Print one line per case (otherwise only the summary and failures).

    Returns
    -------
    None
        On success it prints the report and returns nothing, so the cell shows no ``Out[...]``.

    Raises
    ------
    NotImplementedYet
        (a ``NotImplementedError``) If ``fn`` is still the stub: the report says "not implemented
        yet". It raises, rather than returning quietly, so that nbgrader's in-kernel autograde
        scores an untouched stub zero; robocourse's harness lets the rest of an assignment notebook
        run on.
    CheckFailed
        (an ``AssertionError``) If any case fails, so the cell shows red. Its message lists the
        failed cases; in a notebook only that message is shown, not a traceback through robocourse.
        Also if ``fn`` uses robokit (:func:`library_use`): the grader has none, so it would score
        zero there.
    TypeError
        If ``fn`` is not callable.
    robocourse.lessons.UnknownExerciseError
        If no assignment declares ``exercise_id``.

    Notes
    -----
    Grading design (DESIGN.md, "Grading"); not from a paper.

    Examples
    --------
    A right answer prints ``check 00.wrap_angle: 6/6 public cases passed (...)`` and returns
    nothing. A wrong answer fails the cell, and the message says which cases and why:

    >>> check("00.wrap_angle", lambda angle: angle, verbose=False)
    Traceback (most recent call last):
    ...
    robocourse.grading.check.CheckFailed: 00.wrap_angle: 4 of 6 public cases failed:
    ...
    """
    exercise = get_exercise(exercise_id)
    if not callable(fn):
        raise TypeError(f"fn: expected your function {exercise.function}, got {type(fn).__name__}")
    uses = library_use(fn)
    if uses:
        raise CheckFailed(f"{exercise.id}: {exercise.function} uses robokit ({', '.join(uses)}); the grader has no "
                          "robokit, so it would score zero there: write it with numpy")
    cases = exercise.make_cases(PUBLIC_SEED)
    passes, failures = [], []
    for i, case in enumerate(cases, 1):
        result = call_student(fn, case)
        if result.error is not None and result.error.type == "NotImplementedError":
            print(f"{exercise.id}: not implemented yet — replace `raise NotImplementedError` in "
                  f"{exercise.function} with your code, then run this cell again.")
            raise NotImplementedYet(f"{exercise.id} is not implemented yet")
        outcome = judge(exercise, case, expected_output(exercise, case), result)
        text = f"case {i}" + (f" ({case.label})" if case.label else "")
        if outcome.passed:
            passes.append(f"  pass  {text}")
        else:
            where = f" [{result.error.line}]" if result.error and result.error.line else ""
            failures.append(f"  FAIL  {text}: {outcome.message}{where}\n"
                            f"        input: {case.call_text(exercise.function)}")
    print(f"check {exercise.id}: {len(passes)}/{len(cases)} public cases passed "
          "(feedback only; your grade comes from hidden cases)")
    if verbose and passes:          # the failed cases are in the error's message, shown once
        print("\n".join(passes))
    if failures:
        raise CheckFailed(f"{exercise.id}: {len(failures)} of {len(cases)} public cases failed:\n"
                          + "\n".join(failures))
