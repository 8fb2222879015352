"""Exercise definitions, one module per assignment (found automatically by robokit.grading).

Each module sets ``ASSIGNMENT = "NN_slug"`` and ``EXERCISES = [Exercise(...), ...]``; see
``getting_started.py`` for the pattern.
"""
