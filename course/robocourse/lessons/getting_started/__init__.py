"""Lesson 00, getting started.

exercises  the warm-up assignment: wrap an angle, compose two planar poses
"""
