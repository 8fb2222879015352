"""Planar and spatial geometry: the one spatial layer of robokit.

Conventions: SI units; a right-handed world frame with z up; planar poses ``[x, y, theta]`` with
``theta`` counter-clockwise from the x axis; rigid transforms are 4x4 matrices ``T_a_b`` (frame
``b`` in frame ``a``); cameras use the OpenCV optical frame (x right, y down, z forward). The source
papers' planar pose ``[p, q, theta]`` (sideways X, forward Z, heading; a left-handed frame) converts
with :func:`se2_to_pqt` / :func:`pqt_to_se2`. Functions take one element or a stack along leading
axes where their docstrings say so.

planar        SE(2): composition, inverse, relative pose, matrices, angle wrapping, line intersection
rotations     SO(3): skew, exponential and logarithm, elementary rotations, Euler and ZYZ angles,
              quaternions
spatial       SE(3): the checked transform, composition, inverse, action on points, the pose error
procrustes    the one weighted rigid fit of point sets (Umeyama), behind fit_se2 and fit_se3
paper_frames  the papers' [p, q, theta] acting on points, their world and camera frames
"""
from .planar import matrix_to_se2, se2_between, se2_compose, se2_inverse, se2_to_matrix, wrap_angle
from .rotations import euler_matrix, quat_to_matrix, rot_x, rot_y, rot_z, skew, so3_exp, so3_log, zyz_angles
from .spatial import (as_se3, pose_error, se2_to_se3, se3_compose, se3_from_rt, se3_inverse, se3_to_se2,
                      transform_points)
from .procrustes import DegenerateFitError, fit_rigid, fit_se2, fit_se3
from .paper_frames import (paper_world_to_robokit, pqt_robot_to_world, pqt_to_se2, pqt_to_se3, pqt_world_to_robot,
                           se2_to_pqt)

__all__ = ["matrix_to_se2", "se2_between", "se2_compose", "se2_inverse", "se2_to_matrix", "wrap_angle",
           "euler_matrix", "quat_to_matrix", "rot_x", "rot_y", "rot_z", "skew", "so3_exp", "so3_log", "zyz_angles",
           "as_se3", "pose_error", "se2_to_se3", "se3_compose", "se3_from_rt", "se3_inverse", "se3_to_se2",
           "transform_points", "DegenerateFitError", "fit_rigid", "fit_se2", "fit_se3", "paper_world_to_robokit",
           "pqt_robot_to_world", "pqt_to_se2", "pqt_to_se3", "pqt_world_to_robot", "se2_to_pqt"]
