"""Find exercises: every module in :mod:`robokit.exercises` declares one assignment.

A module ``robokit/exercises/<slug>.py`` sets ``ASSIGNMENT = "NN_slug"`` (the notebook name in
``solutions/`` and ``assignments/``) and ``EXERCISES = [Exercise(...), ...]``. Modules are found
automatically, so a new lesson adds its file and touches nothing else.
"""
from __future__ import annotations

import functools
import importlib
import pkgutil

from .exercise import Exercise

__all__ = ["assignments", "exercises_for", "get_exercise", "UnknownAssignmentError", "UnknownExerciseError"]


class UnknownAssignmentError(ValueError):
    """No exercise module declares this assignment."""


class UnknownExerciseError(ValueError):
    """No assignment declares this exercise id."""


@functools.lru_cache(maxsize=1)
def assignments() -> dict[str, tuple[Exercise, ...]]:
    """Return ``{"NN_slug": (Exercise, ...)}`` for every exercise module, sorted by slug."""
    import robokit.exercises as pkg

    found: dict[str, tuple[Exercise, ...]] = {}
    for info in pkgutil.iter_modules(pkg.__path__):
        module = importlib.import_module(f"{pkg.__name__}.{info.name}")
        slug = getattr(module, "ASSIGNMENT", None)
        if slug is None:
            continue
        exercises = tuple(module.EXERCISES)
        ids = [e.id for e in exercises]
        if len(set(ids)) != len(ids) or any(e.lesson != slug[:2] for e in exercises):
            raise RuntimeError(f"{module.__name__}: exercise ids must be unique and start with {slug[:2]}.")
        found[slug] = exercises
    return dict(sorted(found.items()))


def exercises_for(assignment: str) -> tuple[Exercise, ...]:
    """Return the exercises of an assignment (``"05_gps_sonar_truck"``).

    Raises
    ------
    UnknownAssignmentError
        With the list of known assignments.
    """
    known = assignments()
    if assignment not in known:
        raise UnknownAssignmentError(f"assignment: unknown assignment {assignment!r}; known: {sorted(known)}")
    return known[assignment]


def get_exercise(exercise_id: str) -> Exercise:
    """Return the exercise with id ``"NN.name"``.

    Raises
    ------
    UnknownExerciseError
        If no assignment declares it.
    """
    if not isinstance(exercise_id, str):
        raise TypeError(f"exercise_id: expected a string like '00.wrap_angle', got {type(exercise_id).__name__}")
    for exercises in assignments().values():
        for ex in exercises:
            if ex.id == exercise_id:
                return ex
    raise UnknownExerciseError(f"exercise_id: no exercise {exercise_id!r} (ids look like '00.wrap_angle')")
