"""Lesson 06, inverse kinematics of a redundant 7-DOF arm (Huang & Jiang; Shimizu et al. 2008).

exercises   assignment 06
tracking    assignment 06's loop exercise: the reference, its cases and its judge
"""
