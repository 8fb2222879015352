"""The seeds' planar robot pose ``[p, q, theta]`` acting on 3-D points (Se et al.; Lin et al. Sec. 4).

Robot (camera) frame: X sideways to the right, Y up, Z forward. World frame: the same axes at the
initial pose. The pose ``[p, q, theta]`` is the robot's sideways (X) and forward (Z) position in the
world and its heading; ``theta`` turns the (X, Z) plane counter-clockwise when drawn with X to the
right and Z up the page (a bird's-eye view like Se et al. Fig. 2), so ``theta > 0`` turns left.
On the (X, Z) plane this is exactly the SE(2) pose ``[x, y, theta] = [p, q, theta]`` of
:func:`robokit.geometry.se2_compose`; height Y is unchanged.
"""
from __future__ import annotations

import numpy as np

from ..validation import as_array

__all__ = ["as_pose", "rotation_y", "robot_to_world", "world_to_robot", "transform_covariance"]


def as_pose(pose, name: str = "pose") -> np.ndarray:
    """Validate a pose ``[p, q, theta]`` (metres, metres, radians) and return it as a float array.

    Raises
    ------
    ValueError
        If it does not have shape (3,) or is not finite.

    Notes
    -----
    Lin et al. Sec. 4: "p and q are the sideways and forward translation in X and Z directions".
    """
    return as_array(pose, name, shape=(3,))


def rotation_y(theta: float) -> np.ndarray:
    """3 x 3 rotation of robot-frame points into the world for heading ``theta``.

    Notes
    -----
    ``[X_w, Z_w] = R(theta) [X, Z]`` with the planar rotation ``R``; Y is kept (Se et al. Sec. 3.3,
    the yaw stage ``P_yaw`` of the backward transformation).
    """
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def robot_to_world(points, pose) -> np.ndarray:
    """Map robot-frame points (N, 3) to the world frame: ``R(theta) r + (p, 0, q)``.

    Notes
    -----
    Se et al. Sec. 3.3, ``r_new = P(r_obs) + V`` restricted to the 3-DoF pose; Lin et al. Sec. 5
    (the equation relating landmark and feature positions).
    """
    pts = as_array(points, "points", shape=(None, 3))
    p = as_pose(pose)
    return pts @ rotation_y(p[2]).T + np.array([p[0], 0.0, p[1]])


def world_to_robot(points, pose) -> np.ndarray:
    """Map world points (N, 3) into the robot frame at ``pose`` (inverse of :func:`robot_to_world`).

    Notes
    -----
    Se et al. Sec. 3.2: database landmarks are predicted in the new frame from the odometry pose.
    """
    pts = as_array(points, "points", shape=(None, 3))
    p = as_pose(pose)
    return (pts - np.array([p[0], 0.0, p[1]])) @ rotation_y(p[2])


def transform_covariance(points, covariances, pose, pose_covariance) -> tuple[np.ndarray, np.ndarray]:
    """Backward transformation of observations into the world frame with first-order covariance.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Observed positions in the robot frame.
    covariances : array_like, shape (N, 3, 3)
        Their covariances (e.g. from :func:`robokit.vision.stereo.disparity_to_point`).
    pose : array_like, shape (3,)
        Robot pose ``[p, q, theta]``.
    pose_covariance : array_like, shape (3, 3)
        Covariance of the pose estimate.

    Returns
    -------
    points_world : numpy.ndarray, shape (N, 3)
    covariances_world : numpy.ndarray, shape (N, 3, 3)
        ``R Sigma_obs R^T + J Sigma_pose J^T`` with ``J = d r_new / d(p, q, theta)``.

    Notes
    -----
    Se et al. Sec. 3.3-3.4: the pose uncertainty is propagated to the landmark by first-order
    analysis; with a 3-DoF pose the 12 x 12 form of the paper reduces to these two terms.
    """
    pts = as_array(points, "points", shape=(None, 3))
    cov = as_array(covariances, "covariances", shape=(pts.shape[0], 3, 3))
    p = as_pose(pose)
    pcov = as_array(pose_covariance, "pose_covariance", shape=(3, 3))
    rot = rotation_y(p[2])
    world = pts @ rot.T + np.array([p[0], 0.0, p[1]])
    c, s = np.cos(p[2]), np.sin(p[2])
    jac = np.zeros((pts.shape[0], 3, 3))
    jac[:, 0, 0] = 1.0
    jac[:, 2, 1] = 1.0
    jac[:, 0, 2] = -s * pts[:, 0] - c * pts[:, 2]
    jac[:, 2, 2] = c * pts[:, 0] - s * pts[:, 2]
    out = rot @ cov @ rot.T + jac @ pcov @ np.swapaxes(jac, 1, 2)
    return world, out
