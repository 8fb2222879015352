"""Mapping: the Kalman-filtered landmark database of Se, Lowe & Little (Sec. 3).

:mod:`.landmarks` holds the backward transformation with first-order covariance
(:func:`transform_covariance`) and the database (:class:`LandmarkMap`). The papers' pose
``[p, q, theta]`` acting on points (``pqt_robot_to_world``, ``pqt_transform_xz`` ...) is in
:mod:`robokit.geometry`. Never imports ``viz`` or ``sim``.
"""
from .landmarks import LandmarkMap, kalman_fuse, transform_covariance

__all__ = ["transform_covariance", "LandmarkMap", "kalman_fuse"]
