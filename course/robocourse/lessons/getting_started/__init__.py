"""Lesson 00, getting started: the warm-up assignment's exercises (``exercises``)."""
