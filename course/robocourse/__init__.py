"""robocourse: the course built on the robokit library: lesson experiments, exercises, grading, the site.

What a notebook imports from here: :data:`FAST` (``ROBOKIT_FAST=1`` shrinks the lessons'
experiments), :func:`check` (feedback on an exercise's public cases), :func:`assignment_data`
(the data an assignment works on) and :func:`check_environment` (lesson 00's installation check). Subpackages, bottom layer first (``tests/test_layers.py``
enforces the order):

config     fast mode (ROBOKIT_FAST)
source     the code a module runs, found by reading imports: experiments' cache keys, the grading kit
environment  every package the course imports, with the lessons that need it (lesson 00's check)
site       notebook execution and hygiene, the course build and its two Sphinx sites, browser checks
exercises  the vocabulary exercises are written in: Case, Exercise, comparisons, plain data
lessons    one folder per lesson: its experiments (with their fast mode and cache keys) and its
           assignment's exercises; the package itself finds the assignments
grading    check(), the assignment generator, the sandboxed grader and its worker, reports, Gradescope
cli        the ``robocourse`` command
"""
from robocourse.config import FAST

__version__ = "0.1.0"

__all__ = ["FAST", "check", "assignment_data", "check_environment", "environment_table", "__version__"]


def __getattr__(name: str):
    """``check``, ``assignment_data`` and the environment check load their code on first use only."""
    if name == "check":
        from .grading.check import check
        return check
    if name == "assignment_data":
        from .grading.data import assignment_data
        return assignment_data
    if name in ("check_environment", "environment_table"):
        from . import environment
        return getattr(environment, name)
    raise AttributeError(f"module 'robocourse' has no attribute {name!r}")
