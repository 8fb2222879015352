"""Spatial poses (SE(3)): the checked 4x4 homogeneous transform ``T_a_b`` (frame ``b`` expressed in
frame ``a``), its inverse, composition and action on points, the planar <-> spatial embedding and
the pose error that inverse kinematics drives to zero.

Functions take one transform ``(4, 4)`` or, where the docstring says so, a stack ``(N, 4, 4)``.
:func:`as_se3` is the one SE(3) validator of robokit; functions that solvers call in loops take
``validate=False`` to skip it.

References
----------
.. [1] K. M. Lynch and F. C. Park, *Modern Robotics: Mechanics, Planning, and Control*, Cambridge
   University Press, 2017.
.. [2] B. Siciliano, L. Sciavicco, L. Villani and G. Oriolo, *Robotics: Modelling, Planning and
   Control*, Springer, 2009.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import array_ndim, as_array, as_points, as_finite_scalar
from .planar import as_planar
from .rotations import ROTATION_TOL, as_rotation, require_rotation_block, rot_z, so3_log

__all__ = ["as_se3", "se3_from_rt", "se3_inverse", "se3_compose", "transform_points", "se2_to_se3",
           "se3_to_se2", "pose_error"]

_LAST_ROW = np.array([0.0, 0.0, 0.0, 1.0])


def as_se3(value: Any, name: str, *, batch: bool = False, tol: float = ROTATION_TOL) -> np.ndarray:
    """Return ``value`` as a float SE(3) matrix (or a stack of them), checked.

    Parameters
    ----------
    value : array_like, shape (4, 4) or (N, 4, 4)
        Homogeneous transform(s).
    name : str
        Argument name used in error messages.
    batch : bool, default False
        Accept (and require) a stack of shape ``(N, 4, 4)``; a single ``(4, 4)`` is promoted.
    tol : float, default 1e-6
        Tolerance on the last row, on ``R^T R = I`` and on ``det R = 1``.

    Returns
    -------
    numpy.ndarray, shape (4, 4) or (N, 4, 4)

    Raises
    ------
    ValueError
        If the shape is wrong, a value is NaN/infinite, the last row is not ``[0, 0, 0, 1]`` or the
        rotation block is not a proper rotation (``R^T R != I`` or ``det R != 1``).

    Notes
    -----
    SE(3) as defined in Lynch & Park (2017), Definition 3.13.

    Examples
    --------
    >>> as_se3(np.eye(4), "T").shape
    (4, 4)
    >>> as_se3(np.eye(4), "T", batch=True).shape
    (1, 4, 4)
    >>> as_se3(np.diag([1.0, 1.0, -1.0, 1.0]), "T")
    Traceback (most recent call last):
    ...
    ValueError: T[:3, :3]: expected a rotation matrix with R^T R = I and det R = 1 (tolerance 1e-06), got max |R^T R - I| = 0 and det = -1
    """
    one = not batch or array_ndim(value, name) == 2
    T = as_array(value, name, shape=(4, 4) if one else (None, 4, 4))
    if batch and one:
        T = T[None]
    last_dev = np.abs(T[..., 3, :] - _LAST_ROW).max(axis=-1)
    if np.any(last_dev > tol):
        i = int(np.argmax(np.atleast_1d(last_dev)))
        raise ValueError(f"{name}: expected an SE(3) matrix with last row [0, 0, 0, 1], got "
                         f"{np.asarray(T[..., 3, :]).reshape(-1, 4)[i].tolist()}" + (f" at index {i}" if batch else ""))
    require_rotation_block(T[..., :3, :3], f"{name}[:3, :3]", tol, indexed=batch)
    return T


def se3_from_rt(rotation: Any, translation: Any, *, validate: bool = True) -> np.ndarray:
    """Build homogeneous transforms from rotation matrices and translations.

    Parameters
    ----------
    rotation : array_like, shape (3, 3) or (N, 3, 3)
        Proper rotation matrices.
    translation : array_like, shape (3,) or (N, 3)
        Translations in metres.
    validate : bool, default True
        Check the shapes, the values and that ``rotation`` is a rotation; ``False`` is the fast path
        for arrays a caller has made as rotations (e.g. by :func:`~robokit.geometry.fit_rigid`).

    Returns
    -------
    numpy.ndarray, shape (4, 4) or (N, 4, 4)

    Raises
    ------
    ValueError
        If the shapes disagree, values are not finite or ``rotation`` is not a rotation.

    Notes
    -----
    Lynch & Park (2017), Eq. (3.62).

    Examples
    --------
    >>> se3_from_rt(np.eye(3), [1.0, 2.0, 3.0])[:3, 3].tolist()
    [1.0, 2.0, 3.0]
    """
    if validate:
        R = as_rotation(rotation, "rotation", batch=array_ndim(rotation, "rotation") == 3)
        t = as_array(translation, "translation", shape=R.shape[:-2] + (3,))
    else:
        R, t = rotation, translation
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3], T[..., :3, 3], T[..., 3, 3] = R, t, 1.0
    return T


def se3_inverse(transform: Any) -> np.ndarray:
    """Invert rigid transforms using ``R^T`` (exact, unlike a general matrix inverse).

    Parameters
    ----------
    transform : array_like, shape (4, 4) or (N, 4, 4)

    Returns
    -------
    numpy.ndarray, shape (4, 4) or (N, 4, 4)
        ``[[R^T, -R^T t], [0, 1]]``.

    Raises
    ------
    ValueError
        If ``transform`` is not a rigid homogeneous transform.

    Notes
    -----
    Lynch & Park (2017), Proposition 3.15.

    Examples
    --------
    >>> T = se3_from_rt(rot_z(0.5), [1.0, 0.0, 0.0])
    >>> print(np.round(se3_inverse(T) @ T, 12).tolist() == np.eye(4).tolist())
    True
    """
    T = as_se3(transform, "transform", batch=array_ndim(transform, "transform") == 3)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    out = np.zeros(T.shape)
    out[..., :3, :3] = Rt
    if T.ndim == 2:
        out[:3, 3] = -Rt @ T[:3, 3]
    else:
        out[..., :3, 3] = -(Rt @ T[..., :3, 3, None])[..., 0]
    out[..., 3, 3] = 1.0
    return out


def se3_compose(*transforms: Any) -> np.ndarray:
    """Compose rigid transforms left to right: ``se3_compose(A, B, C) = A @ B @ C``.

    Parameters
    ----------
    *transforms : array_like, shape (4, 4) or (N, 4, 4)
        At least one transform, e.g. ``T_world_robot, T_robot_camera``; stacks broadcast against
        single transforms.

    Returns
    -------
    numpy.ndarray, shape (4, 4) or (N, 4, 4)

    Raises
    ------
    ValueError
        If no transform is given or one is not rigid.

    Notes
    -----
    Lynch & Park (2017), Sec. 3.3.1 (composition of frames).

    Examples
    --------
    >>> A = se3_from_rt(np.eye(3), [1.0, 0.0, 0.0])
    >>> se3_compose(A, A)[:3, 3].tolist()
    [2.0, 0.0, 0.0]
    """
    if not transforms:
        raise ValueError("transforms: expected at least one 4x4 transform, got none")
    out = np.eye(4)
    for i, T in enumerate(transforms):
        out = out @ as_se3(T, f"transforms[{i}]", batch=array_ndim(T, f"transforms[{i}]") == 3)
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
    Lynch & Park (2017), Eq. (3.63).

    Examples
    --------
    >>> T = se3_from_rt(rot_z(np.pi / 2), [1.0, 0.0, 0.0])
    >>> print(np.round(transform_points(T, [1.0, 0.0, 0.0]), 6))
    [[1. 1. 0.]]
    """
    T = as_se3(transform, "transform")
    return as_points(points, "points", 3) @ T[:3, :3].T + T[:3, 3]


def se2_to_se3(pose: Any, z: float = 0.0) -> np.ndarray:
    """Lift planar poses ``[x, y, theta]`` (z up) to 4x4 transforms at height ``z``.

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3)
    z : float, default 0
        Height of the frame's origin in metres.

    Returns
    -------
    numpy.ndarray, shape (4, 4) or (N, 4, 4)
        Rotation by ``theta`` about the vertical axis, translation ``(x, y, z)``.

    Raises
    ------
    ValueError
        If the pose is not finite or has the wrong shape.

    Notes
    -----
    Lynch & Park (2017), Sec. 3.3.1; planar motion is rotation about z.

    Examples
    --------
    >>> T = se2_to_se3([1.0, 2.0, np.pi / 2], z=0.5)
    >>> print(np.round(T, 3))
    [[ 0.  -1.   0.   1. ]
     [ 1.   0.   0.   2. ]
     [ 0.   0.   1.   0.5]
     [ 0.   0.   0.   1. ]]
    """
    p = as_planar(pose, "pose")
    T = np.zeros(p.shape[:-1] + (4, 4))
    T[..., :3, :3] = rot_z(p[..., 2])
    T[..., 0, 3], T[..., 1, 3], T[..., 2, 3], T[..., 3, 3] = p[..., 0], p[..., 1], as_finite_scalar(z, "z"), 1.0
    return T


def se3_to_se2(transform: Any) -> np.ndarray:
    """Project 4x4 transforms to the plane: ``[x, y, yaw]`` (yaw of the frame's x axis about z).

    Parameters
    ----------
    transform : array_like, shape (4, 4) or (N, 4, 4)

    Returns
    -------
    numpy.ndarray, shape (3,) or (N, 3)

    Raises
    ------
    ValueError
        If ``transform`` is not rigid.

    Notes
    -----
    Inverse of :func:`se2_to_se3` for transforms that rotate about z only (Lynch & Park 2017,
    Sec. 3.3.1).

    Examples
    --------
    >>> print(np.round(se3_to_se2(se2_to_se3([1.0, 2.0, 0.3])), 6))
    [1.  2.  0.3]
    """
    T = as_se3(transform, "transform", batch=array_ndim(transform, "transform") == 3)
    return np.stack([T[..., 0, 3], T[..., 1, 3], np.arctan2(T[..., 1, 0], T[..., 0, 0])], axis=-1)


def pose_error(T_target: Any, T: Any, *, validate: bool = True) -> np.ndarray:
    """Return the 6-vector pose error ``[p_t - p, log(R_t R^T)]`` in the base frame.

    Parameters
    ----------
    T_target, T : array_like, shape (4, 4) or (N, 4, 4)
        Desired and current transforms (a single one broadcasts against a stack).
    validate : bool, default True
        Validate both; ``False`` skips it (solvers' inner loops, on float arrays).

    Returns
    -------
    numpy.ndarray, shape (..., 6)
        Position error in metres, then the rotation vector (radians) that turns the current
        orientation into the desired one, both expressed in the base frame, so that it matches the
        geometric Jacobian's ``[v; omega]`` ordering.

    Raises
    ------
    ValueError
        If either argument is not an SE(3) matrix (or stack of them) or the stacks differ in length.

    Notes
    -----
    The orientation error as the rotation vector of ``R_d R^T`` is one of the choices compared by
    Siciliano et al. (2009), Sec. 3.7.3; the logarithm is :func:`~robokit.geometry.so3_log`.

    Examples
    --------
    >>> T = se3_from_rt(rot_z(0.3), [0.1, 0.0, 0.0])
    >>> print(np.round(pose_error(T, np.eye(4)), 6))
    [0.1 0.  0.  0.  0.  0.3]
    """
    if validate:
        T_target = as_se3(T_target, "T_target", batch=array_ndim(T_target, "T_target") == 3)
        T = as_se3(T, "T", batch=array_ndim(T, "T") == 3)
        if T_target.ndim == 3 and T.ndim == 3 and len(T_target) != len(T):
            raise ValueError(f"T_target, T: expected stacks of equal length, got {len(T_target)} and {len(T)}")
    dw = so3_log(T_target[..., :3, :3] @ np.swapaxes(T[..., :3, :3], -1, -2), validate=False)
    out = np.empty(dw.shape[:-1] + (6,))
    np.subtract(T_target[..., :3, 3], T[..., :3, 3], out=out[..., :3])
    out[..., 3:] = dw
    return out
