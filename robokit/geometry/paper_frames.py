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
That action is written once, :func:`pqt_transform_xz` (vectorised over poses and points, with its
Jacobian on request); :func:`pqt_robot_to_world` and :func:`pqt_world_to_robot` apply it to 3-D
points.

The course identifies the papers' ground plane (X, Z) with robokit's (x, y), so bird's-eye plots in
both conventions are the same picture: ``p = x``, ``q = y``, ``theta = theta_robokit - pi/2``
(:func:`se2_to_pqt`), and a point's height is measured from the floor instead of the camera
(:func:`paper_world_to_robokit`).

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

from ..validation import as_array, as_points, as_positive
from .planar import as_planar, wrap_angle
from .rotations import rot_y

__all__ = ["R_BODY_OPTICAL", "as_pqt", "se2_to_pqt", "pqt_to_se2", "pqt_to_se3", "pqt_rotate_xz",
           "pqt_transform_xz", "pqt_robot_to_world", "pqt_world_to_robot",
           "paper_world_to_robokit", "optical_to_y_up"]

#: Rotation from a robot body frame (x forward, y left, z up) to the OpenCV optical frame of a
#: forward-looking camera (x right, y down, z forward): columns are the optical axes in body axes.
R_BODY_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
#: Axes of the papers' world frame (X east, Y up, Z north) that give robokit's x, y, z.
_PAPER_TO_ROBOKIT = [0, 2, 1]


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


def _stack(value: Any, name: str, k: int) -> np.ndarray:
    """Validate an array of ``k``-vectors, shape (..., k), finite."""
    a = as_array(value, name)
    if a.ndim == 0 or a.shape[-1] != k:
        raise ValueError(f"{name}: expected shape (..., {k}), got shape {a.shape}")
    return a


def _broadcast(pqt: np.ndarray, points: np.ndarray, name: str) -> None:
    try:
        np.broadcast_shapes(pqt.shape[:-1], points.shape[:-1])
    except ValueError:
        raise ValueError(f"pqt, {name}: expected leading shapes that broadcast, got {pqt.shape} and "
                         f"{points.shape}") from None


def pqt_rotate_xz(theta: Any, xz: Any, *, validate: bool = True) -> np.ndarray:
    """Turn ground-plane points ``(X, Z)`` by the papers' heading ``theta``: ``R(theta) (X, Z)``.

    Parameters
    ----------
    theta : float or array_like, shape (...)
        Headings (radians); broadcast against the leading axes of ``xz``.
    xz : array_like, shape (..., 2)
        Ground-plane points ``(X, Z)`` (sideways, forward).
    validate : bool, default True
        Validate the inputs; ``False`` skips it (RANSAC's and the Hough vote's inner loops).

    Returns
    -------
    numpy.ndarray, shape (broadcast, 2)
        ``(cos(theta) X - sin(theta) Z, sin(theta) X + cos(theta) Z)``: ``rot_y(-theta)`` on the
        (X, Z) plane (the frame is left-handed, see the module docstring).

    Raises
    ------
    ValueError
        If ``xz`` does not end in an axis of 2, the shapes do not broadcast or a value is not finite.

    Notes
    -----
    Lin et al., Sec. 5, the rotation in ``(X_i, Z_i) = R(theta) (X'_i, Z'_i) + (p, q)``.

    Examples
    --------
    For a robot that has turned left by 90 degrees, straight ahead (Z = 1) is the world's -X:

    >>> print(np.round(pqt_rotate_xz(np.pi / 2, [0.0, 1.0]), 6) + 0.0)
    [-1.  0.]
    >>> pqt_rotate_xz(np.zeros((5, 1)), np.ones((40, 2))).shape          # 5 headings x 40 points
    (5, 40, 2)
    """
    if validate:
        th = as_array(theta, "theta")
        xz = _stack(xz, "xz", 2)
        try:
            np.broadcast_shapes(th.shape, xz.shape[:-1])
        except ValueError:
            raise ValueError(f"theta, xz: expected shapes that broadcast, got {th.shape} and {xz.shape}") from None
    else:
        th = np.asarray(theta, dtype=float)
    c, s = np.cos(th), np.sin(th)
    x, z = xz[..., 0], xz[..., 1]
    cx = c * x
    out = np.empty((2,) + cx.shape)                             # X then Z: each a contiguous block
    np.subtract(cx, s * z, out=out[0, ...])
    np.add(s * x, c * z, out=out[1, ...])
    return out.transpose(*range(1, out.ndim), 0)


def pqt_transform_xz(pqt: Any, xz: Any, *, inverse: bool = False, jacobian: bool = False, validate: bool = True):
    """The papers' pose ``[p, q, theta]`` acting on ground-plane points: robot ``(X', Z')`` to world.

    Parameters
    ----------
    pqt : array_like, shape (..., 3)
        Poses; many poses (e.g. RANSAC hypotheses, shape (K, 1, 3)) broadcast against many points.
    xz : array_like, shape (..., 2)
        Ground-plane points ``(X, Z)``: in the robot frame, or in the world with ``inverse``.
    inverse : bool, default False
        Map world points into the robot frame instead: ``R(theta)^T ((X, Z) - (p, q))``.
    jacobian : bool, default False
        Also return the derivative with respect to ``[p, q, theta]`` (not with ``inverse``).
    validate : bool, default True
        Validate the inputs; ``False`` skips it (solvers' inner loops).

    Returns
    -------
    moved : numpy.ndarray, shape (broadcast, 2)
        ``R(theta) (X', Z') + (p, q)`` (see :func:`pqt_rotate_xz`).
    J : numpy.ndarray, shape (broadcast, 2, 3)
        With ``jacobian``: ``[[1, 0, -Z_r], [0, 1, X_r]]`` where ``(X_r, Z_r) = R(theta) (X', Z')``
        (turning moves a point at right angles to its rotated position).

    Raises
    ------
    ValueError
        If the last axes are not 3 and 2, the leading shapes do not broadcast, a value is not
        finite, or both ``inverse`` and ``jacobian`` are asked for.

    Notes
    -----
    Lin et al., Sec. 5: ``(X_i, Z_i) = R(theta) (X'_i, Z'_i) + (p, q)``, the ground-plane part of
    Se et al. (2002), Sec. 3.3, ``r_new = P(r_obs) + V``. The Jacobian is the first-order term of
    Se et al. (2002), Sec. 3.4 (pose uncertainty propagated to a landmark) and of the
    least-squares refinement of Lin et al., Sec. 6.

    Examples
    --------
    Two hypotheses, the second turned left by 90 degrees, applied to three points at once:

    >>> hypotheses = np.array([[1.0, 2.0, 0.0], [1.0, 2.0, np.pi / 2]])
    >>> points = [[0.0, 1.0], [1.0, 0.0], [0.0, 0.0]]                     # (X', Z') ahead, right, here
    >>> print(np.round(pqt_transform_xz(hypotheses[:, None], points), 6) + 0.0)
    [[[1. 3.]
      [2. 2.]
      [1. 2.]]
    <BLANKLINE>
     [[0. 2.]
      [1. 3.]
      [1. 2.]]]

    Turning moves a point 2 m straight ahead sideways by 2 m per radian (to the left, -X):

    >>> print(pqt_transform_xz([0.0, 0.0, 0.0], [0.0, 2.0], jacobian=True)[1].tolist())
    [[1.0, 0.0, -2.0], [0.0, 1.0, 0.0]]
    """
    if validate:
        pqt, xz = _stack(pqt, "pqt", 3), _stack(xz, "xz", 2)
        _broadcast(pqt, xz, "xz")
        if inverse and jacobian:
            raise ValueError("inverse, jacobian: expected at most one of them, got both")
    if inverse:
        return pqt_rotate_xz(-pqt[..., 2], xz - pqt[..., :2], validate=False)
    out = pqt_rotate_xz(pqt[..., 2], xz, validate=False)
    if jacobian:
        J = np.zeros(out.shape[:-1] + (2, 3))
        J[..., 0, 0] = J[..., 1, 1] = 1.0
        J[..., 0, 2] = -out[..., 1]                             # d X / d theta = -Z_r
        J[..., 1, 2] = out[..., 0]                              # d Z / d theta = X_r
    out[..., 0] += pqt[..., 0]                                  # in place: X and Z are contiguous blocks
    out[..., 1] += pqt[..., 1]
    return (out, J) if jacobian else out


def pqt_robot_to_world(points: Any, pqt: Any, *, validate: bool = True) -> np.ndarray:
    """Map points from the papers' robot frame (X right, Y up, Z forward) to their world frame.

    For the papers' pose ``[p, q, theta]`` only: a robokit pose ``[x, y, theta]`` must first go
    through :func:`se2_to_pqt`.

    Parameters
    ----------
    points : array_like, shape (..., 3)
        ``(X, Y, Z)``: right, up, forward from the robot (camera).
    pqt : array_like, shape (..., 3)
        Robot pose(s) ``[p, q, theta]``, broadcast against the points' leading axes.
    validate : bool, default True
        Validate the inputs; ``False`` skips it.

    Returns
    -------
    numpy.ndarray, shape (broadcast, 3)
        ``rot_y(-theta) r + (p, 0, q)``: (X, Z) by :func:`pqt_transform_xz`, height Y unchanged.

    Raises
    ------
    ValueError
        If ``points`` or ``pqt`` does not end in an axis of 3, the shapes do not broadcast or a
        value is not finite.

    Notes
    -----
    Se et al. (2002), Sec. 3.3, ``r_new = P(r_obs) + V`` restricted to the 3-DoF pose; Lin et
    al., Sec. 5 (the equation relating landmark and feature positions).

    Examples
    --------
    A point 1 m ahead of a robot at (p, q) = (2, 1) that faces the world's -X (turned left by
    90 degrees) lies at X = 1 m:

    >>> print(np.round(pqt_robot_to_world([[0.0, 0.5, 1.0]], [2.0, 1.0, np.pi / 2]), 6))
    [[1.  0.5 1. ]]
    """
    return _points(points, pqt, validate, inverse=False)


def pqt_world_to_robot(points: Any, pqt: Any) -> np.ndarray:
    """Map points from the papers' world frame into their robot frame at ``pqt`` (inverse of
    :func:`pqt_robot_to_world`).

    Parameters
    ----------
    points : array_like, shape (..., 3)
    pqt : array_like, shape (..., 3)
        The papers' pose(s) ``[p, q, theta]`` (not robokit's ``[x, y, theta]``).

    Returns
    -------
    numpy.ndarray, shape (broadcast, 3)
        ``rot_y(-theta)^T (w - (p, 0, q))``.

    Raises
    ------
    ValueError
        As :func:`pqt_robot_to_world`.

    Notes
    -----
    Se et al. (2002), Sec. 3.2: database landmarks are predicted in the new frame from the
    odometry pose.

    Examples
    --------
    >>> print(np.round(pqt_world_to_robot([[1.0, 0.5, 1.0]], [2.0, 1.0, np.pi / 2]), 6))
    [[0.  0.5 1. ]]
    """
    return _points(points, pqt, True, inverse=True)


def _points(points, pqt, validate, inverse):
    if validate:
        points, pqt = _stack(points, "points", 3), _stack(pqt, "pqt", 3)
        _broadcast(pqt, points, "points")
    xz = pqt_transform_xz(pqt, points[..., ::2], inverse=inverse, validate=False)
    out = np.empty(xz.shape[:-1] + (3,))
    out[..., ::2] = xz
    out[..., 1] = points[..., 1]
    return out


def paper_world_to_robokit(points: Any, covariances: Any = None, camera_height: float = 0.8):
    """Points (and covariances) from the papers' world frame to robokit's world frame.

    The course's one identification of the two frames, for every lesson that maps in the papers'
    frame and plots or simulates in robokit's: ``x = X`` (east, ``p``), ``y = Z`` (north, ``q``),
    ``z = Y + camera_height`` (up, from the floor instead of the camera).

    Parameters
    ----------
    points : array_like, shape (N, 3)
        ``(X, Y, Z)``: X east, Y up relative to the camera, Z north.
    covariances : array_like, shape (N, 3, 3), optional
    camera_height : float, default 0.8
        Height of the camera above the floor (metres); 0.8 is the simulator's default mount.

    Returns
    -------
    points : numpy.ndarray, shape (N, 3)
        ``(x, y, z) = (X, Z, Y + camera_height)``.
    covariances : numpy.ndarray, shape (N, 3, 3) or None
        Permuted the same way.

    Raises
    ------
    ValueError
        For malformed or non-finite points or covariances, or a non-positive camera height.

    Notes
    -----
    The convention of :func:`se2_to_pqt` (``p = x``, ``q = y``); the papers' frame is left-handed,
    so the permutation has determinant -1. Se et al. (2002), Sec. 3.1, measure Y from the camera.

    Examples
    --------
    A landmark 0.2 m above the camera, at X = 3 m east and Z = 5 m north:

    >>> points, _ = paper_world_to_robokit([[3.0, 0.2, 5.0]])
    >>> print(np.round(points, 3))
    [[3. 5. 1.]]
    """
    pts = as_array(points, "points", shape=(None, 3))
    out = pts[:, _PAPER_TO_ROBOKIT] + [0.0, 0.0, as_positive(camera_height, "camera_height")]
    if covariances is None:
        return out, None
    cov = as_array(covariances, "covariances", shape=(pts.shape[0], 3, 3))
    return out, cov[:, _PAPER_TO_ROBOKIT][:, :, _PAPER_TO_ROBOKIT]


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
