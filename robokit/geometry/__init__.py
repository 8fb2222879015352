"""Planar and spatial geometry: angle wrapping and rigid-body poses.

Conventions: SI units; right-handed world frame with z up; planar poses are ``[x, y, theta]`` with
``theta`` the heading measured counter-clockwise from the x axis; spatial poses are 4x4 homogeneous
transforms ``T_a_b`` (frame ``b`` expressed in frame ``a``); cameras use the OpenCV optical frame
(x right, y down, z forward). The seeds' planar ``[p, q, theta]`` (sideways X, forward Z, heading)
converts with :func:`se2_to_pqt` / :func:`pqt_to_se2`. Rotations are computed by
``scipy.spatial.transform``.

Submodules: :mod:`~robokit.geometry.planar` (SE(2)), :mod:`~robokit.geometry.spatial` (SE(3)),
:mod:`~robokit.geometry.seeds` (the seeds' ``[p, q, theta]`` and camera frame).
"""
from .planar import matrix_to_se2, se2_between, se2_compose, se2_inverse, se2_to_matrix, wrap_angle
from .seeds import R_BODY_OPTICAL, optical_to_seed, pqt_to_se2, se2_to_pqt
from .spatial import (euler_matrix, rotation_matrix, rotation_vector, se2_to_se3, se3_compose, se3_from_rt,
                      se3_inverse, se3_to_se2, transform_points)

__all__ = [
    "wrap_angle", "se2_compose", "se2_inverse", "se2_between", "se2_to_matrix", "matrix_to_se2",
    "rotation_matrix", "rotation_vector", "euler_matrix", "se3_from_rt", "se3_inverse", "se3_compose",
    "transform_points", "se2_to_se3", "se3_to_se2", "R_BODY_OPTICAL", "se2_to_pqt", "pqt_to_se2",
    "optical_to_seed",
]

