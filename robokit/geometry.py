"""Planar and spatial geometry: angle wrapping and rigid-body poses.

Conventions: SI units; right-handed world frame with z up; planar poses are ``[x, y, theta]`` with
``theta`` the heading measured counter-clockwise from the x axis; spatial poses are 4x4 homogeneous
transforms ``T_a_b`` (frame ``b`` expressed in frame ``a``); cameras use the OpenCV optical frame
(x right, y down, z forward). The seeds' planar ``[p, q, theta]`` (sideways X, forward Z, heading)
converts with :func:`se2_to_pqt` / :func:`pqt_to_se2`. Rotations are computed by
``scipy.spatial.transform``.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from scipy.spatial.transform import Rotation

from .validation import as_array, as_points, check_finite_scalar

__all__ = [
    "wrap_angle", "se2_compose", "se2_inverse", "se2_between", "se2_to_matrix", "matrix_to_se2",
    "rotation_matrix", "rotation_vector", "euler_matrix", "se3_from_rt", "se3_inverse", "se3_compose",
    "transform_points", "se2_to_se3", "se3_to_se2", "R_BODY_OPTICAL", "se2_to_pqt", "pqt_to_se2",
    "optical_to_seed",
]


def wrap_angle(angle: Any) -> Any:
    """Wrap angles to the interval [-pi, pi).

    Parameters
    ----------
    angle : float or array_like
        Angles in radians (finite).

    Returns
    -------
    float or numpy.ndarray
        Same shape as the input; a float for scalar input.

    Raises
    ------
    ValueError
        If any angle is NaN or infinite.

    Notes
    -----
    Standard identity ``(a + pi) mod 2 pi - pi`` (e.g. Thrun, Burgard & Fox, *Probabilistic
    Robotics*, 2005, Sec. 5.4); used by every heading computation in the course.
    """
    a = as_array(angle, "angle")
    out = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return float(out) if out.ndim == 0 else out


def se2_compose(a: Any, b: Any) -> np.ndarray:
    """Compose planar poses: the pose ``b`` expressed in frame ``a``, mapped to the world.

    Parameters
    ----------
    a, b : array_like, shape (3,)
        Poses ``[x, y, theta]``.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``a ⊕ b = [x_a + cos(t_a) x_b - sin(t_a) y_b, y_a + sin(t_a) x_b + cos(t_a) y_b,
        wrap(t_a + t_b)]``.

    Raises
    ------
    ValueError
        If a pose does not have shape (3,) or is not finite.

    Notes
    -----
    The compounding operator of Smith, Self & Cheeseman, "Estimating uncertain spatial
    relationships in robotics" (1990), Eq. (3); it is also Eq. (1)'s composition in Duckett's
    relaxation used by lesson 02.
    """
    pa = as_array(a, "a", shape=(3,))
    pb = as_array(b, "b", shape=(3,))
    c, s = np.cos(pa[2]), np.sin(pa[2])
    return np.array([pa[0] + c * pb[0] - s * pb[1], pa[1] + s * pb[0] + c * pb[1],
                     wrap_angle(pa[2] + pb[2])])


# --- planar poses (SE(2)) ------------------------------------------------------------------------

def se2_inverse(a: Any) -> np.ndarray:
    """Invert a planar pose: the world origin expressed in the frame ``a``.

    Parameters
    ----------
    a : array_like, shape (3,)
        Pose ``[x, y, theta]``.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``⊖a = [-x cos t - y sin t, x sin t - y cos t, -t]`` so that ``se2_compose(a, ⊖a) = 0``.

    Raises
    ------
    ValueError
        If the pose does not have shape (3,) or is not finite.

    Notes
    -----
    The inverse relationship of Smith, Self & Cheeseman (1990), Eq. (4).
    """
    p = as_array(a, "a", shape=(3,))
    c, s = np.cos(p[2]), np.sin(p[2])
    return np.array([-c * p[0] - s * p[1], s * p[0] - c * p[1], wrap_angle(-p[2])])


def se2_between(a: Any, b: Any) -> np.ndarray:
    """Return the pose of ``b`` relative to ``a``: ``⊖a ⊕ b`` (e.g. an odometry increment).

    Parameters
    ----------
    a, b : array_like, shape (3,)
        Poses ``[x, y, theta]`` in the same frame.

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    ValueError
        If a pose does not have shape (3,) or is not finite.

    Notes
    -----
    Smith, Self & Cheeseman (1990), Eqs. (3)-(4) combined; Lu & Milios (1997) call it the relative
    pose constraint of a pose graph.
    """
    return se2_compose(se2_inverse(a), b)


def se2_to_matrix(pose: Any) -> np.ndarray:
    """Return the 3x3 homogeneous matrix of a planar pose ``[x, y, theta]``.

    Parameters
    ----------
    pose : array_like, shape (3,)

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        ``[[cos t, -sin t, x], [sin t, cos t, y], [0, 0, 1]]``.

    Raises
    ------
    ValueError
        If the pose does not have shape (3,) or is not finite.

    Notes
    -----
    Lynch & Park, *Modern Robotics* (2017), Sec. 3.3.1 (SE(2) as a matrix group).
    """
    p = as_array(pose, "pose", shape=(3,))
    c, s = np.cos(p[2]), np.sin(p[2])
    return np.array([[c, -s, p[0]], [s, c, p[1]], [0.0, 0.0, 1.0]])


def matrix_to_se2(matrix: Any) -> np.ndarray:
    """Return ``[x, y, theta]`` from a 3x3 homogeneous planar transform (inverse of :func:`se2_to_matrix`).

    Parameters
    ----------
    matrix : array_like, shape (3, 3)
        A rigid planar transform (rotation block orthonormal within 1e-6).

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    ValueError
        If the shape is wrong or the rotation block is not a rotation.

    Notes
    -----
    Lynch & Park, *Modern Robotics* (2017), Sec. 3.3.1.
    """
    T = as_array(matrix, "matrix", shape=(3, 3))
    _check_rotation(T[:2, :2], "matrix")
    return np.array([T[0, 2], T[1, 2], float(np.arctan2(T[1, 0], T[0, 0]))])


# --- spatial poses (SE(3)) -----------------------------------------------------------------------

def _check_rotation(R: np.ndarray, name: str) -> None:
    n = R.shape[0]
    if not np.allclose(R @ R.T, np.eye(n), atol=1e-6) or np.linalg.det(R) <= 0:
        raise ValueError(f"{name}: expected a proper rotation (orthonormal, det +1), got {R.tolist()}")


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


# --- the seeds' planar convention [p, q, theta] --------------------------------------------------

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
