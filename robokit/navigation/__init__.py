"""Closed-loop navigation: a localizer, an estimator and a path follower in one loop.

visual_path  lesson 02's autonomous navigation along a recorded visual path: noisy visual fixes and
             odometry fused by the pose EKF, the path-following law on the estimate, the truth moved
             by the unicycle model; perturbed starts as in the paper's Fig. 13
"""
from .visual_path import FollowResult, follow_path, perturbed_starts

__all__ = ["FollowResult", "follow_path", "perturbed_starts"]
