"""The lessons: one folder each, holding its experiments and its assignment; this package finds them.

A lesson folder ``robocourse/lessons/<name>/`` holds the experiments its lecture notebook runs
(with their fast mode and cache keys) and an ``exercises`` module that sets ``ASSIGNMENT =
"NN_slug"`` (the notebook name in ``solutions/`` and ``assignments/``), ``EXERCISES =
[Exercise(...), ...]``, ``WRITTEN = {"NN.name": points}`` (manually graded questions) and, if its
notebook works on data, a function ``data()`` returning them as plain data
(:mod:`robocourse.grading.data`). Lessons are found automatically, so a new lesson adds its folder
and touches nothing else. They are read once, on first use, and checked once: an
:class:`Assignment` refuses duplicate ids and ids of another lesson.

getting_started        lesson 00: the warm-up assignment
visual_slam            lesson 01: stereo visual SLAM with PLOT and SIFT features
omni_localization      lesson 02: omnidirectional hierarchical localization and path following
corridor_localization  lesson 03: coarse-to-fine localization in a long corridor
littledog              lesson 04: the LittleDog quadruped as a system
gps_sonar_truck        lesson 05: GPS waypoints and sonar avoidance on a skid-steer truck
redundant_ik           lesson 06: inverse kinematics of a redundant 7-DOF arm
"""
from __future__ import annotations

import dataclasses
import functools
import importlib
import pkgutil
import re
from pathlib import Path
from types import MappingProxyType
from typing import Callable, Mapping

from robocourse.exercises.spec import EXERCISE_ID, Exercise

__all__ = ["Assignment", "catalog", "get_assignment", "assignments", "exercises_for", "get_exercise",
           "UnknownAssignmentError", "UnknownExerciseError"]

_SLUG = re.compile(r"^\d\d_[a-z][a-z0-9_]*$")


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
    data : callable, optional
        ``data() -> dict``: the plain data the notebook works on (``robocourse assign`` writes them
        to the assignment's data file; :func:`robocourse.grading.data.assignment_data` reads them).

    Raises
    ------
    ValueError
        For a malformed slug, an exercise that is not an :class:`robocourse.exercises.spec.Exercise`, duplicate ids
        (exercises and written questions share one id space), an id of another lesson, a
        written question with a malformed id or non-positive points, or ``data`` that is not callable.

    Examples
    --------
    >>> from robocourse.exercises.spec import Case, Exercise
    >>> ex = Exercise(id="00.double", function="double", signature="double(x)", points=1,
    ...               cases=lambda rng: [Case((1.0,))], answer=lambda x: 2 * x)
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
    data: Callable[[], dict] | None = None

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
        if self.data is not None and not callable(self.data):
            raise ValueError(f"{self.slug}: data must be a function (the lesson's data()), got {type(self.data).__name__}")
        object.__setattr__(self, "exercises", exercises)
        object.__setattr__(self, "written", MappingProxyType(written))


@functools.lru_cache(maxsize=1)
def catalog() -> Mapping[str, Assignment]:
    """Return ``{"NN_slug": Assignment}`` for every exercise module, sorted by slug.

    The lessons' ``exercises`` modules are imported on the first call only.
    Raises ``ValueError`` for a malformed declaration (see :class:`Assignment`) or a slug declared twice.

    Examples
    --------
    >>> [e.id for e in catalog()["00_getting_started"].exercises]
    ['00.wrap_angle', '00.se2_compose']
    """
    found: dict[str, Assignment] = {}
    for info in pkgutil.iter_modules([str(Path(__file__).parent)]):
        if not info.ispkg or not (Path(__file__).parent / info.name / "exercises.py").is_file():
            continue
        module = importlib.import_module(f"{__name__}.{info.name}.exercises")
        slug = getattr(module, "ASSIGNMENT", None)
        if slug is None:
            continue
        if slug in found:
            raise ValueError(f"{module.__name__}: assignment {slug!r} is declared twice")
        found[slug] = Assignment(slug, tuple(module.EXERCISES), getattr(module, "WRITTEN", {}),
                                 getattr(module, "data", None))
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
