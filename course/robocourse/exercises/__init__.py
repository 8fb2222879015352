"""The vocabulary exercises are written in.

:class:`~.spec.Case` and :class:`~.spec.Exercise` (:mod:`.spec`), the comparisons
:func:`~.compare.close`, :func:`~.compare.exact` and :func:`~.compare.unordered_rows`
(:mod:`.compare`) and the plain-data conversion they rely on (:mod:`.plain`). Each lesson's
``exercises`` module (:mod:`robocourse.lessons`) writes its assignment in it; running and judging
exercises is :mod:`robocourse.grading`'s job.
"""
from robocourse.exercises.compare import close, exact, unordered_rows
from robocourse.exercises.spec import Case, Exercise

__all__ = ["Case", "Exercise", "close", "exact", "unordered_rows"]
