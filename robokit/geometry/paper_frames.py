"""The source papers' frames: the planar pose ``[p, q, theta]`` and the camera frame X right, Y up,
Z forward of Se, Lowe & Little and Lin et al., and their conversion to robokit's frames.

robokit's world is right-handed with z up; a planar robot pose ``[x, y, theta]`` faces +x at
``theta = 0``. The papers' robot (camera) frame has X to the right, Y up and Z forward. **That frame
is left-handed** (X x Y = -Z): seen from above with X to the right and Z up the page (Se et al.'s
bird's-eye view), a positive heading turns the robot to the left, counter-clockwise. So the rotation
that takes robot-frame points to the world is the right-handed elementary rotation about Y by
*minus* the heading, ``rot_y(-theta)``: ``X_w = cos(theta) X - sin(theta) Z``,
``Z_w = sin(theta) X + cos(theta) Z``, which on the (X, Z) plane is exactly the SE(2) rotation of
:func:`robokit.geometry.se2_compose`. The pose ``[p, q, theta]`` is the robot's sideways (X) and
forward (Z) position in the world (the first pose's frame) and its heading; height Y is unchanged.

The course identifies the papers' ground plane (X, Z) with robokit's (x, y), so bird's-eye plots in
both conventions are the same picture: ``p = x``, ``q = y``, ``theta = theta_robokit - pi/2``
(:func:`se2_to_pqt`).

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [2] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, as_points
from .planar import as_planar, wrap_angle
from .rotations import rot_y

__all__ = ["R_BODY_OPTICAL", "as_pqt", "se2_to_pqt", "pqt_to_se2", "pqt_to_se3", "robot_to_world",
           "world_to_robot", "optical_to_y_up"]

#: Rotation from a robot body frame (x forward, y left, z up) to the OpenCV optical frame of a
#: forward-looking camera (x right, y down, z forward): columns are the optical axes in body axes.
R_BODY_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def as_pqt(pqt: Any, name: str = "pqt") -> np.ndarray:
    """Validate one pose ``[p, q, theta]`` (metres, metres, radians) and return it as a float array.

    Raises
    ------
    ValueError
        If it does not have shape (3,) or is not finite.

    Notes
    -----
    Lin et al., Sec. 4: "p and q are the sideways and forward translation in X and Z directions".

    Examples
    --------
    >>> as_pqt([1, 2, 0]).tolist()
    [1.0, 2.0, 0.0]
    """
    return as_array(pqt, name, shape=(3,))


def se2_to_pqt(pose: Any) -> np.ndarray:
    """Convert robokit planar poses ``[x, y, theta]`` to the papers' ``[p, q, theta]``.

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3)

    Returns
    -------
    numpy.ndarray
        Same shape: ``[p, q, theta] = [x, y, wrap(theta - pi/2)]``.

    Raises
    ------
    ValueError
        If the input is not finite or does not have 3 columns.

    Notes
    -----
    Frame definition of Se, Lowe & Little (2002), Sec. 5 (Hough space ``(X, Z, theta)``); a
    robot facing robokit's +y faces the papers' +Z (heading 0).

    Examples
    --------
    >>> print(np.round(se2_to_pqt([3.0, 2.0, np.pi / 2]), 6))
    [3. 2. 0.]
    """
    P = as_planar(pose, "pose")
    return np.stack([P[..., 0], P[..., 1], wrap_angle(P[..., 2] - np.pi / 2)], axis=-1)


def pqt_to_se2(pqt: Any) -> np.ndarray:
    """Convert the papers' ``[p, q, theta]`` to robokit's ``[x, y, theta]`` (inverse of :func:`se2_to_pqt`).

    Parameters
    ----------
    pqt : array_like, shape (3,) or (N, 3)

    Returns
    -------
    numpy.ndarray
        ``[x, y, theta] = [p, q, wrap(theta + pi/2)]``.

    Raises
    ------
    ValueError
        If the input is not finite or does not have 3 columns.

    Notes
    -----
    Se, Lowe & Little (2002), Sec. 5.

    Examples
    --------
    >>> print(np.round(pqt_to_se2([3.0, 2.0, 0.0]), 6))
    [3.       2.       1.570796]
    """
    P = as_planar(pqt, "pqt")
    return np.stack([P[..., 0], P[..., 1], wrap_angle(P[..., 2] + np.pi / 2)], axis=-1)


def pqt_to_se3(pqt: Any) -> np.ndarray:
    """The papers' pose ``[p, q, theta]`` as a 4x4 transform ``T_world_robot`` in their frames.

    Parameters
    ----------
    pqt : array_like, shape (3,)

    Returns
    -------
    numpy.ndarray, shape (4, 4)
        Rotation ``rot_y(-theta)`` (the frame is left-handed, see the module docstring) and
        translation ``(p, 0, q)``.

    Raises
    ------
    ValueError
        If ``pqt`` does not have shape (3,) or is not finite.

    Notes
    -----
    Se et al. (2002), Sec. 3.3: the yaw stage of the backward transformation for a robot that
    moves on the ground plane.

    Examples
    --------
    >>> print(np.round(pqt_to_se3([1.0, 2.0, np.pi / 2]), 6))
    [[ 0.  0. -1.  1.]
     [ 0.  1.  0.  0.]
     [ 1.  0.  0.  2.]
     [ 0.  0.  0.  1.]]
    """
    p = as_pqt(pqt)
    T = np.eye(4)
    T[:3, :3] = rot_y(-p[2])
    T[0, 3], T[2, 3] = p[0], p[1]
    return T


def robot_to_world(points: Any, pqt: Any) -> np.ndarray:
    """Map robot-frame points (N, 3) to the world frame for the robot at ``pqt``.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        ``(X, Y, Z)``: right, up, forward from the robot (camera).
    pqt : array_like, shape (3,)
        Robot pose ``[p, q, theta]``.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``rot_y(-theta) r + (p, 0, q)``.

    Raises
    ------
    ValueError
        If ``points`` is not (N, 3) or an input is not finite.

    Notes
    -----
    Se et al. (2002), Sec. 3.3, ``r_new = P(r_obs) + V`` restricted to the 3-DoF pose; Lin et
    al., Sec. 5 (the equation relating landmark and feature positions).

    Examples
    --------
    A point 1 m ahead of a robot at (p, q) = (2, 1) that faces the world's -X (turned left by
    90 degrees) lies at X = 1 m:

    >>> print(np.round(robot_to_world([[0.0, 0.5, 1.0]], [2.0, 1.0, np.pi / 2]), 6))
    [[1.  0.5 1. ]]
    """
    pts = as_array(points, "points", shape=(None, 3))
    T = pqt_to_se3(pqt)
    return pts @ T[:3, :3].T + T[:3, 3]                        # Se et al. Sec. 3.3


def world_to_robot(points: Any, pqt: Any) -> np.ndarray:
    """Map world points (N, 3) into the robot frame at ``pqt`` (inverse of :func:`robot_to_world`).

    Parameters
    ----------
    points : array_like, shape (N, 3)
    pqt : array_like, shape (3,)

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``rot_y(-theta)^T (w - (p, 0, q))``.

    Raises
    ------
    ValueError
        If ``points`` is not (N, 3) or an input is not finite.

    Notes
    -----
    Se et al. (2002), Sec. 3.2: database landmarks are predicted in the new frame from the
    odometry pose.

    Examples
    --------
    >>> print(np.round(world_to_robot([[1.0, 0.5, 1.0]], [2.0, 1.0, np.pi / 2]), 6))
    [[0.  0.5 1. ]]
    """
    pts = as_array(points, "points", shape=(None, 3))
    T = pqt_to_se3(pqt)
    return (pts - T[:3, 3]) @ T[:3, :3]


def optical_to_y_up(points: Any) -> np.ndarray:
    """Convert camera points from the OpenCV optical frame (x right, y down, z forward) to the
    papers' camera frame (X right, Y up, Z forward): ``(X, Y, Z) = (x, -y, z)``.

    Parameters
    ----------
    points : array_like, shape (N, 3) or (3,)

    Returns
    -------
    numpy.ndarray, shape (N, 3)

    Raises
    ------
    ValueError
        If ``points`` is not (N, 3) and finite.

    Notes
    -----
    Se et al. (2002), Sec. 3.1: ``X = (c - c0) I / d``, ``Y = (r0 - r) I / d``,
    ``Z = f I / d`` (row index grows downwards, Y upwards).

    Examples
    --------
    >>> optical_to_y_up([[1.0, 2.0, 3.0]]).tolist()
    [[1.0, -2.0, 3.0]]
    """
    P = as_points(points, "points", 3).copy()
    P[:, 1] *= -1
    return P
