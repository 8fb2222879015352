"""Lesson 05, GPS waypoints and sonar obstacle avoidance on a skid-steer truck (Hamid et al. 2009).

experiment  the paper's courses driven again and again: seeded missions, cached
exercises   assignment 05
"""
