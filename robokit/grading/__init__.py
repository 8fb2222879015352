"""Grading: in-notebook ``check()``, assignment generation and the sandboxed grader.

The exercise vocabulary and the assignments live one layer down, in :mod:`robokit.exercises`;
they are re-exported here because notebooks and instructors know them as ``robokit.grading``.
"""
from ..exercises import Case, Exercise, assignments, close, exact, exercises_for, get_exercise, unordered_rows
from .check import PUBLIC_SEED, check

__all__ = ["check", "PUBLIC_SEED", "Case", "Exercise", "close", "exact", "unordered_rows",
           "assignments", "exercises_for", "get_exercise"]
