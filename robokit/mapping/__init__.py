"""Mapping: the seeds' planar pose acting on 3-D points, and the Kalman-filtered landmark database.

Modules: :mod:`.frames` (pose ``[p, q, theta]``, backward transformation with covariance) and
:mod:`.landmarks` (Se, Lowe & Little Sec. 3). Never imports ``viz`` or ``sim``.
"""
from .frames import as_pose, robot_to_world, rotation_y, transform_covariance, world_to_robot
from .landmarks import LandmarkMap, kalman_fuse

__all__ = ["as_pose", "robot_to_world", "rotation_y", "transform_covariance", "world_to_robot", "LandmarkMap",
           "kalman_fuse"]
