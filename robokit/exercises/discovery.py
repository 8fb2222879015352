"""Find the assignments: every module in :mod:`robokit.exercises` that declares one.

A module ``robokit/exercises/<slug>.py`` sets ``ASSIGNMENT = "NN_slug"`` (the notebook name in
``solutions/`` and ``assignments/``), ``EXERCISES = [Exercise(...), ...]``, ``WRITTEN =
{"NN.name": points}`` (manually graded questions) and, if its notebook imports robokit functions
besides ``check``, ``HELPERS = ("robokit.pkg.name", ...)``: while grading, student code can import
only those (the grading worker holds no other robokit code). Modules are found automatically, so a
new lesson adds its file and touches nothing else. They are read once, on first use, and checked once: an
:class:`Assignment` refuses duplicate ids and ids of another lesson.
"""
from __future__ import annotations

import dataclasses
import functools
import importlib
import pkgutil
import re
from pathlib import Path
from types import MappingProxyType
from typing import Mapping

from .spec import EXERCISE_ID, Exercise

__all__ = ["Assignment", "catalog", "get_assignment", "assignments", "exercises_for", "get_exercise",
           "UnknownAssignmentError", "UnknownExerciseError"]

_SLUG = re.compile(r"^\d\d_[a-z][a-z0-9_]*$")
_HELPER = re.compile(r"^robokit(\.[A-Za-z_][A-Za-z0-9_]*){2,}$")


class UnknownAssignmentError(ValueError):
    """No exercise module declares this assignment."""


class UnknownExerciseError(ValueError):
    """No assignment declares this exercise id."""


@dataclasses.dataclass(frozen=True)
class Assignment:
    """One assignment: its slug, its auto-graded exercises and its written questions.

    Parameters
    ----------
    slug : str
        ``"NN_slug"``, e.g. ``"05_gps_sonar_truck"``.
    exercises : tuple of Exercise
        The check-cell exercises, in notebook order; ids unique and starting with ``NN``.
    written : mapping of str to float
        Manually graded questions: id ``"NN.name"`` -> positive points (read-only).
    helpers : tuple of str
        The robokit functions the notebook imports besides ``check``, as the notebook names them
        (``"robokit.outdoor.loop_metrics"`` for ``from robokit.outdoor import loop_metrics``). The
        grading worker provides exactly these; they must not live in a module that holds one of the
        assignment's references (``robokit.grading.kit`` refuses such a helper).

    Raises
    ------
    ValueError
        For a malformed slug, an exercise that is not an :class:`~.spec.Exercise`, duplicate ids
        (exercises and written questions share one id space), an id of another lesson, a
        written question with a malformed id or non-positive points, or a helper that is not a
        dotted ``robokit.`` name of a function in a subpackage.

    Examples
    --------
    >>> from robokit.exercises.spec import Case, Exercise
    >>> ex = Exercise(id="00.double", function="double", signature="double(x)", points=1,
    ...               cases=lambda rng: [Case((1.0,))], reference=lambda x: 2 * x)
    >>> a = Assignment("00_demo", (ex,), {"00.why": 1})
    >>> [e.id for e in a.exercises], dict(a.written)
    (['00.double'], {'00.why': 1})
    >>> Assignment("01_demo", (ex,), {})
    Traceback (most recent call last):
    ...
    ValueError: 01_demo: ids must start with the lesson number 01, got ['00.double']
    """

    slug: str
    exercises: tuple[Exercise, ...]
    written: Mapping[str, float] = dataclasses.field(default_factory=dict)
    helpers: tuple[str, ...] = ()

    def __post_init__(self):
        if not isinstance(self.slug, str) or not _SLUG.match(self.slug):
            raise ValueError(f"slug: expected 'NN_name' (e.g. '05_gps_sonar_truck'), got {self.slug!r}")
        exercises, written = tuple(self.exercises), dict(self.written)
        if not all(isinstance(e, Exercise) for e in exercises):
            raise ValueError(f"{self.slug}: EXERCISES must hold Exercise objects")
        malformed = [q for q in written if not isinstance(q, str) or not EXERCISE_ID.match(q)]
        if malformed:
            raise ValueError(f"{self.slug}: WRITTEN ids must look like 'NN.name', got {malformed}")
        ids = [e.id for e in exercises] + list(written)
        duplicated = sorted({i for i in ids if ids.count(i) > 1})
        if duplicated:
            raise ValueError(f"{self.slug}: ids must be unique, got {duplicated} more than once")
        foreign = [i for i in ids if i[:2] != self.slug[:2]]
        if foreign:
            raise ValueError(f"{self.slug}: ids must start with the lesson number {self.slug[:2]}, got {foreign}")
        bad_points = {q: p for q, p in written.items() if type(p) not in (int, float) or not p > 0}
        if bad_points:
            raise ValueError(f"{self.slug}: WRITTEN points must be positive numbers, got {bad_points}")
        if isinstance(self.helpers, str):
            raise ValueError(f"{self.slug}: HELPERS must be a tuple of names, got the string {self.helpers!r}")
        helpers = tuple(self.helpers)
        bad_helpers = [h for h in helpers if not isinstance(h, str) or not _HELPER.match(h)]
        if bad_helpers:
            raise ValueError(f"{self.slug}: HELPERS must be dotted names like 'robokit.outdoor.loop_metrics', "
                             f"got {bad_helpers}")
        object.__setattr__(self, "exercises", exercises)
        object.__setattr__(self, "written", MappingProxyType(written))
        object.__setattr__(self, "helpers", helpers)


@functools.lru_cache(maxsize=1)
def catalog() -> Mapping[str, Assignment]:
    """Return ``{"NN_slug": Assignment}`` for every exercise module, sorted by slug.

    The modules are imported on the first call only (not when :mod:`robokit.exercises` is), so
    the grading worker can disable reference functions before any exercise module binds them.
    Raises ``ValueError`` for a malformed declaration (see :class:`Assignment`) or a slug declared twice.

    Examples
    --------
    >>> [e.id for e in catalog()["00_getting_started"].exercises]
    ['00.wrap_angle', '00.se2_compose']
    """
    found: dict[str, Assignment] = {}
    for info in pkgutil.iter_modules([str(Path(__file__).parent)]):
        module = importlib.import_module(f"{__package__}.{info.name}")
        slug = getattr(module, "ASSIGNMENT", None)
        if slug is None:
            continue
        if slug in found:
            raise ValueError(f"{module.__name__}: assignment {slug!r} is declared twice")
        found[slug] = Assignment(slug, tuple(module.EXERCISES), getattr(module, "WRITTEN", {}),
                                 getattr(module, "HELPERS", ()))
    return MappingProxyType(dict(sorted(found.items())))


def get_assignment(slug: str) -> Assignment:
    """Return the assignment ``"NN_slug"`` (e.g. ``"05_gps_sonar_truck"``).

    Raises
    ------
    UnknownAssignmentError
        With the list of known assignments.
    """
    known = catalog()
    if slug not in known:
        raise UnknownAssignmentError(f"assignment: unknown assignment {slug!r}; known: {sorted(known)}")
    return known[slug]


def assignments() -> dict[str, tuple[Exercise, ...]]:
    """Return ``{"NN_slug": (Exercise, ...)}`` for every assignment, sorted by slug."""
    return {slug: a.exercises for slug, a in catalog().items()}


def exercises_for(assignment: str) -> tuple[Exercise, ...]:
    """Return the exercises of an assignment (``"05_gps_sonar_truck"``).

    Raises
    ------
    UnknownAssignmentError
        With the list of known assignments.
    """
    return get_assignment(assignment).exercises


def get_exercise(exercise_id: str) -> Exercise:
    """Return the exercise with id ``"NN.name"``.

    Raises
    ------
    UnknownExerciseError
        If no assignment declares it (``TypeError`` if ``exercise_id`` is not a string).
    """
    if not isinstance(exercise_id, str):
        raise TypeError(f"exercise_id: expected a string like '00.wrap_angle', got {type(exercise_id).__name__}")
    for a in catalog().values():
        for ex in a.exercises:
            if ex.id == exercise_id:
                return ex
    raise UnknownExerciseError(f"exercise_id: no exercise {exercise_id!r} (ids look like '00.wrap_angle')")
