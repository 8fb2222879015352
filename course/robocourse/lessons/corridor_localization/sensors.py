"""Lesson 03's sensors: the corridor robot's laser scanner and its forward-looking camera.

Ge et al. (2023), Sec. 4: the robot carries an RPLIDAR A2 (360 degrees, effective radius 8-10 m)
above a monocular camera (1280 x 960 pixels at 30 frames per second); every recording, map and run
of the lesson (:mod:`robocourse.lessons.corridor_localization.experiment`, ``corridor_trials``,
``corridor_kidnapping``) uses these two.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 2023, doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import numpy as np

from robokit.config import fast_mode
from robokit.sim import Lidar, PinholeCamera, camera_mount

__all__ = ["corridor_lidar", "corridor_camera"]


def corridor_lidar() -> Lidar:
    """The RPLIDAR-A2-like scanner of the lesson: 360 beams, 8 m range, 1 cm noise, 0.45 m high.

    Returns
    -------
    Lidar

    Notes
    -----
    Ge et al. (2023), Sec. 4: an RPLIDAR A2 (360 degrees, effective radius 8-10 m), mounted above the
    camera so the camera does not block its beams.

    Examples
    --------
    >>> corridor_lidar().r_max, corridor_lidar().beams
    (8.0, 360)
    """
    return Lidar(noise=0.01, height=0.45)


def corridor_camera(fast: bool | None = None) -> PinholeCamera:
    """The forward-looking camera of the lesson: 65 degrees wide, 0.35 m high, below the LiDAR.

    Parameters
    ----------
    fast : bool, optional
        320 x 240 pixels instead of 640 x 480 (default: :func:`robokit.config.fast_mode`).

    Returns
    -------
    PinholeCamera

    Notes
    -----
    Ge et al. (2023), Sec. 4: a monocular camera with 1280 x 960 pixels at 30 frames per second,
    mounted lower than the LiDAR. We render at half (or a quarter of) that size to keep the lesson
    fast; ORB's 500 features fit either.

    Examples
    --------
    >>> corridor_camera(fast=True).width, corridor_camera(fast=False).width
    (320, 640)
    """
    fast = fast_mode() if fast is None else bool(fast)
    w, h = (320, 240) if fast else (640, 480)
    return PinholeCamera.from_fov(np.deg2rad(65.0), w, h, mount=camera_mount(0.35))
