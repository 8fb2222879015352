"""Rigid-body helpers for arm kinematics: SE(3) validation, elementary rotations, pose errors.

Conventions: a pose is a 4x4 homogeneous matrix ``[[R, p], [0, 0, 0, 1]]`` with ``R`` in SO(3)
and ``p`` in metres; batches are stacked along leading axes, shape ``(..., 4, 4)``.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array

__all__ = ["as_se3", "pose_error"]

#: Tolerance on ``R^T R = I`` and ``det R = 1`` when checking a user-supplied pose.
SE3_TOL = 1e-6
_LAST_ROW = np.array([0.0, 0.0, 0.0, 1.0])
_EYE3 = np.eye(3)


def as_se3(value: Any, name: str, *, batch: bool = False, tol: float = SE3_TOL) -> np.ndarray:
    """Return ``value`` as a float SE(3) matrix (or a stack of them), checked.

    Parameters
    ----------
    value : array_like, shape (4, 4) or (N, 4, 4)
        Homogeneous transform(s).
    name : str
        Argument name used in error messages.
    batch : bool, default False
        Accept (and require) a stack of shape ``(N, 4, 4)``; a single ``(4, 4)`` is promoted.
    tol : float
        Tolerance on orthonormality, determinant and the last row.

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
    SE(3) as defined in Lynch & Park, *Modern Robotics* (2017), Sec. 3.3.1.
    """
    one = not batch or np.ndim(value) == 2
    T = as_array(value, name, shape=(4, 4) if one else (None, 4, 4))
    if batch and one:
        T = T[None]
    R = T[..., :3, :3]
    last_dev = np.abs(T[..., 3, :] - _LAST_ROW).max(axis=-1)
    if np.any(last_dev > tol):
        i = int(np.argmax(np.atleast_1d(last_dev)))
        raise ValueError(f"{name}: expected an SE(3) matrix with last row [0, 0, 0, 1], got "
                         f"{np.asarray(T[..., 3, :]).reshape(-1, 4)[i].tolist()}" + (f" at index {i}" if batch else ""))
    ortho = np.abs(np.swapaxes(R, -1, -2) @ R - _EYE3).max(axis=(-2, -1))
    det = np.linalg.det(R)
    bad = (ortho > tol) | (np.abs(det - 1.0) > tol)
    if np.any(bad):
        i = int(np.argmax(np.atleast_1d(bad)))
        raise ValueError(f"{name}: expected a rotation block with R^T R = I and det R = 1 (tolerance {tol:g}), "
                         f"got max |R^T R - I| = {np.atleast_1d(ortho)[i]:.3g} and det = {np.atleast_1d(det)[i]:.6g}"
                         + (f" at index {i}" if batch else ""))
    return T


def _skew(v: np.ndarray) -> np.ndarray:
    """Return the _skew-symmetric matrix ``[v]x`` of vectors ``v`` with shape ``(..., 3)``.

    Notes
    -----
    Lynch & Park (2017), Eq. (3.30). Internal helper: no validation.
    """
    v = np.asarray(v, dtype=float)
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


def _axis_angle_rotation(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues' formula: rotation by ``angle`` about unit ``axis`` (both broadcastable).

    ``axis`` has shape ``(..., 3)`` and must already be a unit vector; ``angle`` has shape ``(...)``.

    Notes
    -----
    Lynch & Park (2017), Eq. (3.51). Internal helper: no validation.
    """
    K = _skew(axis)
    s = np.sin(angle)[..., None, None]
    c = np.cos(angle)[..., None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def _rotation_log(R: np.ndarray) -> np.ndarray:
    """Return the rotation vector ``omega * theta`` of rotation matrices ``R`` (shape ``(..., 3, 3)``).

    The result has norm in ``[0, pi]``. Accurate near 0 (first-order series) and near ``pi``
    (axis from the symmetric part), which matters for pose errors of 1e-6 rad.

    Notes
    -----
    Matrix logarithm of SO(3), Lynch & Park (2017), Sec. 3.2.3.3, Algorithm in Eqs. (3.53)-(3.61).
    Internal helper: no validation.
    """
    R = np.asarray(R, dtype=float)
    vee = np.empty(R.shape[:-2] + (3,))
    np.subtract(R[..., 2, 1], R[..., 1, 2], out=vee[..., 0])
    np.subtract(R[..., 0, 2], R[..., 2, 0], out=vee[..., 1])
    np.subtract(R[..., 1, 0], R[..., 0, 1], out=vee[..., 2])
    vee *= 0.5
    cos = 0.5 * (R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2] - 1.0)
    sin = np.sqrt(np.einsum("...i,...i->...", vee, vee))
    theta = np.arctan2(sin, cos)
    # theta / sin(theta) -> 1 as theta -> 0 (and 0 / tiny = 0 at R = I); the near-pi case is
    # handled below
    out = vee * (theta / (sin + 1e-300))[..., None]
    near_pi = cos < -0.99
    if near_pi.any():
        # axis from R + I = 2 w w^T (largest column), sign from the antisymmetric part
        Rp = R[near_pi]
        B = 0.5 * (Rp + np.eye(3))
        k = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        col = np.take_along_axis(B, k[:, None, None], axis=-1)[..., 0]
        w = col / np.linalg.norm(col, axis=-1, keepdims=True)
        vp = vee[near_pi]
        sign = np.where(np.sum(w * vp, axis=-1) < 0, -1.0, 1.0)
        out[near_pi] = w * (sign * theta[near_pi])[..., None]
    return out


def pose_error(T_target: Any, T: Any) -> np.ndarray:
    """Return the 6-vector pose error ``[p_t - p, log(R_t R^T)]`` in the base frame.

    Parameters
    ----------
    T_target, T : array_like, shape (4, 4) or (N, 4, 4)
        Desired and current poses (a single pose broadcasts against a stack).

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
    Siciliano et al., *Robotics: Modelling, Planning and Control* (2009), Sec. 3.7.3.
    """
    Ta = as_se3(T_target, "T_target", batch=np.ndim(T_target) == 3)
    Tb = as_se3(T, "T", batch=np.ndim(T) == 3)
    if Ta.ndim == 3 and Tb.ndim == 3 and len(Ta) != len(Tb):
        raise ValueError(f"T_target, T: expected stacks of equal length, got {len(Ta)} and {len(Tb)}")
    return _pose_error(Ta, Tb)


def _pose_error(T_target: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Unchecked kernel of :func:`pose_error` (broadcast stacks of 4x4 poses)."""
    dw = _rotation_log(T_target[..., :3, :3] @ np.swapaxes(T[..., :3, :3], -1, -2))
    out = np.empty(dw.shape[:-1] + (6,))
    np.subtract(T_target[..., :3, 3], T[..., :3, 3], out=out[..., :3])
    out[..., 3:] = dw
    return out
