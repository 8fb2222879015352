"""Grading: exercises, in-notebook ``check()``, assignment generation and the sandboxed grader."""
from .check import PUBLIC_SEED, check
from .compare import close, exact, unordered_rows
from .exercise import Case, Exercise
from .registry import assignments, exercises_for, get_exercise

__all__ = ["check", "PUBLIC_SEED", "Case", "Exercise", "close", "exact", "unordered_rows",
           "assignments", "exercises_for", "get_exercise"]
