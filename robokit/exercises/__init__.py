"""Exercise definitions, one module per assignment, and the vocabulary they are written in.

Each assignment module (see ``getting_started.py`` for the pattern) sets ``ASSIGNMENT = "NN_slug"``,
``EXERCISES = [Exercise(...), ...]``, ``WRITTEN = {"NN.name": points}`` and, when its notebook
imports robokit functions besides ``check``, ``HELPERS``; :mod:`.discovery` finds and checks them.
The vocabulary: :class:`~.spec.Case` and :class:`~.spec.Exercise` (:mod:`.spec`), the comparisons
:func:`~.compare.close`, :func:`~.compare.exact` and :func:`~.compare.unordered_rows`
(:mod:`.compare`) and the plain-data conversion they rely on (:mod:`.plain`). Running and judging
exercises is :mod:`robokit.grading`'s job, one layer up.
"""
from .discovery import (Assignment, UnknownAssignmentError, UnknownExerciseError, assignments, catalog,
                      exercises_for, get_assignment, get_exercise)
from .compare import close, exact, unordered_rows
from .spec import Case, Exercise

__all__ = ["Case", "Exercise", "Assignment", "close", "exact", "unordered_rows", "catalog", "get_assignment",
           "assignments", "exercises_for", "get_exercise", "UnknownAssignmentError", "UnknownExerciseError"]
