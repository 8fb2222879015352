"""Planar and spatial geometry: the one spatial layer of robokit.

Conventions: SI units; right-handed world frame with z up; planar poses are ``[x, y, theta]`` with
``theta`` the heading measured counter-clockwise from the x axis; rigid transforms are 4x4
homogeneous matrices ``T_a_b`` (frame ``b`` expressed in frame ``a``); cameras use the OpenCV
optical frame (x right, y down, z forward). The source papers' planar pose ``[p, q, theta]``
(sideways X, forward Z, heading; a left-handed frame) converts with :func:`se2_to_pqt` /
:func:`pqt_to_se2` and acts on points with the ``pqt_*`` functions; the papers' world points become
robokit's with :func:`paper_world_to_robokit`. Functions accept one element or a stack along leading
axes where their docstrings say so; those that solvers call in loops take ``validate=False``.

Submodules: :mod:`~robokit.geometry.planar` (SE(2)), :mod:`~robokit.geometry.rotations` (SO(3)),
:mod:`~robokit.geometry.spatial` (SE(3)), :mod:`~robokit.geometry.procrustes` (the one weighted
rigid fit of point sets, behind ``fit_se2`` and ``fit_se3``), :mod:`~robokit.geometry.paper_frames`
(the papers' ``[p, q, theta]`` and camera frame).
"""
from .paper_frames import (R_BODY_OPTICAL, as_pqt, optical_to_y_up, paper_world_to_robokit,
                           pqt_robot_to_world, pqt_rotate_xz, pqt_to_se2, pqt_to_se3, pqt_transform_xz,
                           pqt_world_to_robot, se2_to_pqt)
from .planar import (as_planar, intersect_lines, matrix_to_se2, se2_between, se2_compose, se2_inverse, se2_to_matrix,
                     wrap_angle)
from .procrustes import FIT_TOL, DegenerateFitError, RigidFit, fit_rigid, fit_se2, fit_se3
from .rotations import (ROTATION_TOL, as_rotation, require_rotation_block, euler_matrix, quat_to_matrix, rot_x, rot_y,
                        rot_z, skew, so3_exp, so3_log, zyz_angles)
from .spatial import (as_se3, pose_error, se2_to_se3, se3_compose, se3_from_rt, se3_inverse, se3_to_se2,
                      transform_points)

__all__ = [
    "as_planar", "wrap_angle", "se2_compose", "se2_inverse", "se2_between", "se2_to_matrix", "matrix_to_se2",
    "fit_se2", "intersect_lines",
    "ROTATION_TOL", "as_rotation", "require_rotation_block", "skew", "so3_exp", "so3_log", "rot_x", "rot_y",
    "rot_z", "euler_matrix", "zyz_angles", "quat_to_matrix",
    "as_se3", "se3_from_rt", "se3_inverse", "se3_compose", "transform_points", "se2_to_se3", "se3_to_se2",
    "pose_error", "fit_se3",
    "FIT_TOL", "DegenerateFitError", "RigidFit", "fit_rigid",
    "R_BODY_OPTICAL", "as_pqt", "se2_to_pqt", "pqt_to_se2", "pqt_to_se3", "pqt_rotate_xz", "pqt_transform_xz",
    "pqt_robot_to_world", "pqt_world_to_robot", "paper_world_to_robokit", "optical_to_y_up",
]
