"""Spatial poses (SE(3)): rotations (via ``scipy.spatial.transform``), homogeneous transforms
``T_a_b`` (frame ``b`` expressed in frame ``a``), and the planar <-> spatial embedding.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ..validation import as_array, as_points, check_finite_scalar
from .planar import _check_rotation, se2_to_matrix

__all__ = ["rotation_matrix", "rotation_vector", "euler_matrix", "se3_from_rt", "se3_inverse",
           "se3_compose", "transform_points", "se2_to_se3", "se3_to_se2"]


def rotation_matrix(rotvec: Any) -> np.ndarray:
    """Return the 3x3 rotation matrix of a rotation vector (axis times angle, radians).

    Parameters
    ----------
    rotvec : array_like, shape (3,)

    Returns
    -------
    numpy.ndarray, shape (3, 3)

    Raises
    ------
    ValueError
        If ``rotvec`` does not have shape (3,) or is not finite.

    Notes
    -----
    Rodrigues' formula (Lynch & Park, *Modern Robotics*, 2017, Eq. (3.51)), evaluated by
    ``scipy.spatial.transform.Rotation``.
    """
    return Rotation.from_rotvec(as_array(rotvec, "rotvec", shape=(3,))).as_matrix()


def rotation_vector(matrix: Any) -> np.ndarray:
    """Return the rotation vector (axis times angle in [0, pi]) of a 3x3 rotation matrix.

    Parameters
    ----------
    matrix : array_like, shape (3, 3)

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    ValueError
        If ``matrix`` is not a proper rotation.

    Notes
    -----
    Matrix logarithm of SO(3) (Lynch & Park, *Modern Robotics*, 2017, Sec. 3.2.3.3), via scipy.
    """
    R = as_array(matrix, "matrix", shape=(3, 3))
    _check_rotation(R, "matrix")
    return Rotation.from_matrix(R).as_rotvec()


def euler_matrix(angles: Any, seq: str = "xyz") -> np.ndarray:
    """Return the rotation matrix of Euler angles, e.g. roll, pitch, yaw with ``seq="xyz"``.

    Parameters
    ----------
    angles : array_like, shape (3,)
        Angles in radians, applied in the order of ``seq``.
    seq : str, default "xyz"
        scipy's axis sequence: lower case for extrinsic (fixed-axis), upper case for intrinsic.

    Returns
    -------
    numpy.ndarray, shape (3, 3)

    Raises
    ------
    ValueError
        If the angles are not three finite numbers or ``seq`` is not a valid sequence.

    Notes
    -----
    Se, Lowe & Little (2001), Sec. 3.5 compose roll, pitch and yaw rotations in this way; see also
    Craig, *Introduction to Robotics* (2005), Sec. 2.8 (fixed-angle conventions).
    """
    a = as_array(angles, "angles", shape=(3,))
    if not isinstance(seq, str) or len(seq) != 3 or not (set(seq) <= set("xyz") or set(seq) <= set("XYZ")):
        raise ValueError(f"seq: expected three axes like 'xyz' or 'ZYX', got {seq!r}")
    return Rotation.from_euler(seq, a).as_matrix()


def se3_from_rt(rotation: Any, translation: Any) -> np.ndarray:
    """Build a 4x4 homogeneous transform from a rotation matrix and a translation.

    Parameters
    ----------
    rotation : array_like, shape (3, 3)
        Proper rotation matrix.
    translation : array_like, shape (3,)
        Translation in metres.

    Returns
    -------
    numpy.ndarray, shape (4, 4)

    Raises
    ------
    ValueError
        If the shapes are wrong, values are not finite or ``rotation`` is not a rotation.

    Notes
    -----
    Lynch & Park, *Modern Robotics* (2017), Eq. (3.62).
    """
    R = as_array(rotation, "rotation", shape=(3, 3))
    _check_rotation(R, "rotation")
    t = as_array(translation, "translation", shape=(3,))
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def _se3(T: Any, name: str) -> np.ndarray:
    M = as_array(T, name, shape=(4, 4))
    if not np.allclose(M[3], [0, 0, 0, 1]):
        raise ValueError(f"{name}: expected last row [0, 0, 0, 1], got {M[3].tolist()}")
    _check_rotation(M[:3, :3], name)
    return M


def se3_inverse(transform: Any) -> np.ndarray:
    """Invert a 4x4 rigid transform using ``R^T`` (exact, unlike a general matrix inverse).

    Parameters
    ----------
    transform : array_like, shape (4, 4)

    Returns
    -------
    numpy.ndarray, shape (4, 4)
        ``[[R^T, -R^T t], [0, 1]]``.

    Raises
    ------
    ValueError
        If ``transform`` is not a rigid homogeneous transform.

    Notes
    -----
    Lynch & Park, *Modern Robotics* (2017), Proposition 3.15.
    """
    T = _se3(transform, "transform")
    out = np.eye(4)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return out


def se3_compose(*transforms: Any) -> np.ndarray:
    """Compose rigid transforms left to right: ``se3_compose(A, B, C) = A @ B @ C``.

    Parameters
    ----------
    *transforms : array_like, shape (4, 4)
        At least one transform, e.g. ``T_world_robot, T_robot_camera``.

    Returns
    -------
    numpy.ndarray, shape (4, 4)

    Raises
    ------
    ValueError
        If no transform is given or one is not rigid.

    Notes
    -----
    Lynch & Park, *Modern Robotics* (2017), Sec. 3.3.1 (composition of frames).
    """
    if not transforms:
        raise ValueError("transforms: expected at least one 4x4 transform, got none")
    out = np.eye(4)
    for i, T in enumerate(transforms):
        out = out @ _se3(T, f"transforms[{i}]")
    return out


def transform_points(transform: Any, points: Any) -> np.ndarray:
    """Apply a 4x4 rigid transform to points: ``R p + t`` for each row of ``points``.

    Parameters
    ----------
    transform : array_like, shape (4, 4)
    points : array_like, shape (N, 3) or (3,)

    Returns
    -------
    numpy.ndarray, shape (N, 3)

    Raises
    ------
    ValueError
        If ``transform`` is not rigid or ``points`` is not (N, 3) and finite.

    Notes
    -----
    Lynch & Park, *Modern Robotics* (2017), Eq. (3.63).
    """
    T = _se3(transform, "transform")
    P = as_points(points, "points", 3)
    return P @ T[:3, :3].T + T[:3, 3]


def se2_to_se3(pose: Any, z: float = 0.0) -> np.ndarray:
    """Lift a planar pose ``[x, y, theta]`` (z up) to a 4x4 transform at height ``z``.

    Parameters
    ----------
    pose : array_like, shape (3,)
    z : float, default 0
        Height of the frame's origin in metres.

    Returns
    -------
    numpy.ndarray, shape (4, 4)
        Rotation by ``theta`` about the vertical axis, translation ``(x, y, z)``.

    Raises
    ------
    ValueError
        If the pose is not finite or has the wrong shape.

    Notes
    -----
    Lynch & Park, *Modern Robotics* (2017), Sec. 3.3.1; planar motion is rotation about z.
    """
    p = as_array(pose, "pose", shape=(3,))
    T = np.eye(4)
    T[:2, :2] = se2_to_matrix(p)[:2, :2]
    T[:3, 3] = [p[0], p[1], check_finite_scalar(z, "z")]
    return T


def se3_to_se2(transform: Any) -> np.ndarray:
    """Project a 4x4 transform to the plane: ``[x, y, yaw]`` (yaw of the frame's x axis about z).

    Parameters
    ----------
    transform : array_like, shape (4, 4)

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    ValueError
        If ``transform`` is not rigid.

    Notes
    -----
    Inverse of :func:`se2_to_se3` for transforms that rotate about z only.
    """
    T = _se3(transform, "transform")
    return np.array([T[0, 3], T[1, 3], float(np.arctan2(T[1, 0], T[0, 0]))])
