"""The vocabulary exercises are written in; each lesson's ``exercises`` module writes its assignment in it.

spec     Case (one input case) and Exercise (a function to write, its cases, answer and comparison)
compare  the comparisons that accept or reject an answer: close, exact, unordered_rows
plain    the plain data that crosses from student code to the grader
trivial  the trivial answers (constants, arguments, shortcuts) a case can be passed by
"""
from robocourse.exercises.compare import close, exact, unordered_rows
from robocourse.exercises.spec import Case, Exercise

__all__ = ["Case", "Exercise", "close", "exact", "unordered_rows"]
