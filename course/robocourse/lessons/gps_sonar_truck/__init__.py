"""Lesson 05, GPS waypoints and sonar obstacle avoidance on a skid-steer truck (Hamid et al. 2009).

experiment  the paper's courses driven again and again: seeded missions, cached
plant       the loop exercise's given truck, GPS, compass and sonars in plain numpy (the notebook's cell)
loop        the loop exercise: seeded courses, the reference controller, the replay that judges the outcome
exercises   assignment 05
"""
