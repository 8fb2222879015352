"""Lesson 05, GPS waypoints and sonar obstacle avoidance on a skid-steer truck (Hamid et al. 2009).

exercises   assignment 05
"""
