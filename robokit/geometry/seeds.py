"""The seeds' conventions: the planar pose ``[p, q, theta]`` (sideways X, forward Z, heading)
and the camera frame X right, Y up, Z forward (Se, Lowe & Little 2002; Lin et al.).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, as_points
from .planar import wrap_angle

__all__ = ["R_BODY_OPTICAL", "se2_to_pqt", "pqt_to_se2", "optical_to_seed"]

#: Rotation from a robot body frame (x forward, y left, z up) to the OpenCV optical frame of a
#: forward-looking camera (x right, y down, z forward): columns are the optical axes in body axes.
R_BODY_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def se2_to_pqt(pose: Any) -> np.ndarray:
    """Convert a robokit planar pose ``[x, y, theta]`` to the seeds' ``[p, q, theta]``.

    robokit's world is right-handed with z up; a robot at heading 0 faces +x. The seeds (Se, Lowe &
    Little 2002, Sec. 5; Lin et al., PLOT paper, Sec. 4) use X sideways (right), Y up and Z forward,
    with a robot at heading 0 facing +Z and ``theta > 0`` turning left. The course identifies the
    seeds' ground plane (X, Z) with robokit's (x, y), so bird's-eye plots in both conventions are
    the same picture: ``p = x``, ``q = y``, ``theta = wrap(theta_robokit - pi/2)``. (This is the
    one convention of the course; ``robokit.mapping.frames`` works in it.)

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3)

    Returns
    -------
    numpy.ndarray
        Same shape: ``[p, q, theta]``.

    Raises
    ------
    ValueError
        If the input is not finite or does not have 3 columns.

    Notes
    -----
    Frame definition of Se, Lowe & Little, "Global localization using distinctive visual
    features" (IROS 2002), Sec. 5 (Hough space ``(X, Z, theta)``).
    """
    P = as_array(pose, "pose")
    if P.shape[-1:] != (3,) or P.ndim > 2:
        raise ValueError(f"pose: expected shape (3,) or (N, 3), got shape {P.shape}")
    return np.stack([P[..., 0], P[..., 1], wrap_angle(P[..., 2] - np.pi / 2)], axis=-1)


def pqt_to_se2(pqt: Any) -> np.ndarray:
    """Convert the seeds' ``[p, q, theta]`` to robokit's ``[x, y, theta]`` (inverse of :func:`se2_to_pqt`).

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
    """
    P = as_array(pqt, "pqt")
    if P.shape[-1:] != (3,) or P.ndim > 2:
        raise ValueError(f"pqt: expected shape (3,) or (N, 3), got shape {P.shape}")
    return np.stack([P[..., 0], P[..., 1], wrap_angle(P[..., 2] + np.pi / 2)], axis=-1)


def optical_to_seed(points: Any) -> np.ndarray:
    """Convert camera points from the OpenCV optical frame (x right, y down, z forward) to the
    seeds' camera frame (X right, Y up, Z forward): ``(X, Y, Z) = (x, -y, z)``.

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
    Se, Lowe & Little (2002), Sec. 3.1: ``X = (c - c0) I / d``, ``Y = (r0 - r) I / d``,
    ``Z = f I / d`` (row index grows downwards, Y upwards).
    """
    P = as_points(points, "points", 3).copy()
    P[:, 1] *= -1
    return P
