"""Rotations (SO(3)): skew matrices, exponential and logarithm, elementary and Euler rotations.

Every function works on one rotation or on a stack: rotation vectors have shape ``(..., 3)`` and
rotation matrices ``(..., 3, 3)``; angles of the elementary rotations may be arrays of any shape.
Rotations are right-handed (a positive angle turns counter-clockwise when the axis points at the
viewer). Functions that solvers call in loops take ``validate=False`` to skip validation.

References
----------
.. [1] K. M. Lynch and F. C. Park, *Modern Robotics: Mechanics, Planning, and Control*, Cambridge
   University Press, 2017.
.. [2] J. J. Craig, *Introduction to Robotics: Mechanics and Control*, 3rd ed., Pearson, 2005.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ..validation import array_ndim, as_array

__all__ = ["ROTATION_TOL", "as_rotation", "require_rotation_block", "skew", "so3_exp", "so3_log", "rot_x", "rot_y", "rot_z",
           "euler_matrix", "zyz_angles", "quat_to_matrix"]

#: Default tolerance on ``|R^T R - I|`` and ``|det R - 1|`` when a rotation is checked.
ROTATION_TOL = 1e-6
_EYE3 = np.eye(3)
_EYE = {2: np.eye(2), 3: _EYE3}


def as_rotation(value: Any, name: str, *, dim: int = 3, batch: bool = False, tol: float = ROTATION_TOL) -> np.ndarray:
    """Return ``value`` as a float rotation matrix (or a stack of them), checked.

    Parameters
    ----------
    value : array_like, shape (dim, dim) or (N, dim, dim)
    name : str
        Argument name used in error messages.
    dim : int, default 3
        2 for planar rotations (SO(2)), 3 for spatial ones (SO(3)).
    batch : bool, default False
        Accept (and require) a stack of shape ``(N, dim, dim)``; a single matrix is promoted.
    tol : float, default :data:`ROTATION_TOL`
        Tolerance on ``max |R^T R - I|`` and ``|det R - 1|``.

    Returns
    -------
    numpy.ndarray, shape (dim, dim) or (N, dim, dim)

    Raises
    ------
    ValueError
        If the shape is wrong, a value is NaN or infinite, or a matrix is not a proper rotation.

    Notes
    -----
    SO(n) = {R : R^T R = I, det R = 1} (Lynch & Park 2017, Definition 3.1).

    Examples
    --------
    >>> as_rotation(rot_z(0.3), "R").shape
    (3, 3)
    >>> as_rotation(2 * np.eye(3), "R")
    Traceback (most recent call last):
    ...
    ValueError: R: expected a rotation matrix with R^T R = I and det R = 1 (tolerance 1e-06), got max |R^T R - I| = 3 and det = 8
    """
    one = not batch or array_ndim(value, name) == 2
    R = as_array(value, name, shape=(dim, dim) if one else (None, dim, dim))
    if batch and one:
        R = R[None]
    require_rotation_block(R, name, tol, indexed=batch)
    return R


def require_rotation_block(R: np.ndarray, name: str, tol: float = ROTATION_TOL, *, indexed: bool = False) -> None:
    """Raise if any matrix of a float stack ``R`` (..., n, n) is not a rotation within ``tol``.

    The kernel of :func:`as_rotation` for callers that have already checked the shape and finiteness
    (e.g. the rotation block of an SE(3) matrix). ``indexed`` adds the index of the first bad matrix
    to the message.

    Raises
    ------
    ValueError
        Naming ``name``, the tolerance and the measured deviation.

    Notes
    -----
    Lynch & Park (2017), Definition 3.1.

    Examples
    --------
    A stack whose second matrix is scaled by 1.01 (a shear or scale, not a rotation):

    >>> require_rotation_block(np.stack([np.eye(3), 1.01 * np.eye(3)]), "R", indexed=True)
    Traceback (most recent call last):
    ...
    ValueError: R: expected a rotation matrix with R^T R = I and det R = 1 (tolerance 1e-06), got max |R^T R - I| = 0.0201 and det = 1.0303 at index 1
    """
    eye = _EYE[R.shape[-1]] if R.shape[-1] in _EYE else np.eye(R.shape[-1])
    ortho = np.abs(np.swapaxes(R, -1, -2) @ R - eye).max(axis=(-2, -1))
    det = np.linalg.det(R)
    bad = (ortho > tol) | (np.abs(det - 1.0) > tol)
    if np.any(bad):
        i = int(np.argmax(np.atleast_1d(bad)))
        raise ValueError(f"{name}: expected a rotation matrix with R^T R = I and det R = 1 (tolerance {tol:g}), "
                         f"got max |R^T R - I| = {np.atleast_1d(ortho)[i]:.3g} and det = {np.atleast_1d(det)[i]:.6g}"
                         + (f" at index {i}" if indexed else ""))


def skew(v: Any) -> np.ndarray:
    """Return the skew-symmetric matrix ``[v]`` with ``[v] x = v x x`` (cross product).

    Parameters
    ----------
    v : array_like, shape (..., 3)

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)

    Raises
    ------
    ValueError
        If the last axis does not have length 3 or a value is not finite.

    Notes
    -----
    Lynch & Park (2017), Eq. (3.30).

    Examples
    --------
    >>> skew([1.0, 2.0, 3.0]).tolist()
    [[0.0, -3.0, 2.0], [3.0, 0.0, -1.0], [-2.0, 1.0, 0.0]]
    """
    return _skew(_vectors(v, "v"))


def _skew(v: np.ndarray) -> np.ndarray:
    """Unchecked :func:`skew`."""
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


def _vectors(v: Any, name: str) -> np.ndarray:
    v = as_array(v, name)
    if v.ndim == 0 or v.shape[-1] != 3:
        raise ValueError(f"{name}: expected 3-vectors, shape (..., 3), got shape {v.shape}")
    return v


def _rotations(R: Any, tol: float) -> np.ndarray:
    R = as_array(R, "R")
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise ValueError(f"R: expected rotation matrices, shape (..., 3, 3), got shape {R.shape}")
    require_rotation_block(R, "R", tol, indexed=R.ndim > 2)
    return R


def so3_exp(rotvec: Any, *, validate: bool = True) -> np.ndarray:
    """Rotation matrices of rotation vectors (axis times angle, radians): Rodrigues' formula.

    Parameters
    ----------
    rotvec : array_like, shape (..., 3)
    validate : bool, default True
        Validate the input; ``False`` skips it.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        ``I + (sin t / t) [v] + ((1 - cos t) / t^2) [v]^2`` with ``t = |v|``; exact at ``t = 0``
        (series coefficients below 1e-6 rad).

    Raises
    ------
    ValueError
        If the last axis does not have length 3 or a value is not finite.

    Notes
    -----
    Lynch & Park (2017), Eq. (3.51), written for the unnormalised vector ``v = w t``;
    ``1 - cos t = 2 sin^2(t / 2)`` avoids the cancellation at small angles.

    Examples
    --------
    >>> R = so3_exp([0.0, 0.0, np.pi / 2])
    >>> print(np.round(R @ [1.0, 0.0, 0.0], 6))
    [0. 1. 0.]
    >>> so3_exp(np.zeros((5, 3))).shape
    (5, 3, 3)
    """
    v = _vectors(rotvec, "rotvec") if validate else np.asarray(rotvec, dtype=float)
    t2 = np.einsum("...i,...i->...", v, v)
    t = np.sqrt(t2)
    small = t < 1e-6
    ts = np.where(small, 1.0, t)
    a = np.where(small, 1.0 - t2 / 6.0, np.sin(ts) / ts)                       # sin t / t
    b = np.where(small, 0.5 - t2 / 24.0, 2.0 * np.sin(0.5 * ts) ** 2 / ts**2)  # (1 - cos t) / t^2
    K = _skew(v)
    return _EYE3 + a[..., None, None] * K + b[..., None, None] * (K @ K)


def so3_log(R: Any, *, validate: bool = True, tol: float = ROTATION_TOL) -> np.ndarray:
    """Rotation vectors (axis times angle in [0, pi]) of rotation matrices: the SO(3) logarithm.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
    validate : bool, default True
        Check that every matrix is a rotation (within ``tol``); ``False`` skips it.
    tol : float, default :data:`ROTATION_TOL`

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Accurate near 0 (``theta / sin theta -> 1``) and near pi, where the axis comes from the
        symmetric part ``(R + R^T) / 2 - cos(theta) I = (1 - cos theta) w w^T`` and its sign from
        the antisymmetric part; this matters for pose errors of 1e-6 rad.

    Raises
    ------
    ValueError
        If the shape is wrong or a matrix is not a rotation.

    Notes
    -----
    Matrix logarithm of SO(3), Lynch & Park (2017), Sec. 3.2.3.3 (Algorithm, Eqs. (3.53)-(3.61)).

    Examples
    --------
    >>> print(np.round(so3_log(so3_exp([0.3, -0.2, 1.1])), 6))
    [ 0.3 -0.2  1.1]
    >>> print(np.round(np.linalg.norm(so3_log(rot_x(np.pi))), 6))
    3.141593
    """
    R = _rotations(R, tol) if validate else np.asarray(R, dtype=float)
    vee = np.empty(R.shape[:-2] + (3,))
    np.subtract(R[..., 2, 1], R[..., 1, 2], out=vee[..., 0])
    np.subtract(R[..., 0, 2], R[..., 2, 0], out=vee[..., 1])
    np.subtract(R[..., 1, 0], R[..., 0, 1], out=vee[..., 2])
    vee *= 0.5                                                  # sin(theta) w, Eq. (3.53)
    cos = 0.5 * (R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2] - 1.0)   # tr R = 1 + 2 cos theta
    sin = np.sqrt(np.einsum("...i,...i->...", vee, vee))
    theta = np.arctan2(sin, cos)
    # theta / sin(theta) -> 1 as theta -> 0 (and 0 / tiny = 0 at R = I)
    out = vee * (theta / (sin + 1e-300))[..., None]
    near_pi = cos < -0.99
    if near_pi.any():
        # sin(theta) is small: take the axis from the symmetric part instead,
        # (R + R^T) / 2 - cos(theta) I = (1 - cos(theta)) w w^T (Eq. (3.51)); its largest column
        # is parallel to w, and the antisymmetric part sin(theta) w gives the sign
        Rp, c = R[near_pi], cos[near_pi]
        B = 0.5 * (Rp + np.swapaxes(Rp, -1, -2)) - c[:, None, None] * _EYE3
        k = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        col = np.take_along_axis(B, k[:, None, None], axis=-1)[..., 0]
        w = col / np.linalg.norm(col, axis=-1, keepdims=True)
        sign = np.where(np.sum(w * vee[near_pi], axis=-1) < 0, -1.0, 1.0)
        out[near_pi] = w * (sign * theta[near_pi])[..., None]
    return out


def _elementary(angle: Any, i: int, j: int) -> np.ndarray:
    """Rotation about the axis ``k`` completing ``(i, j, k)`` cyclically: ``R[i, j] = -sin``."""
    a = as_array(angle, "angle")
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(a.shape + (3, 3))
    R[..., i, i], R[..., i, j], R[..., j, i], R[..., j, j] = c, -s, s, c
    R[..., 3 - i - j, 3 - i - j] = 1.0
    return R


def rot_x(angle: Any) -> np.ndarray:
    """Rotations about x by ``angle`` (radians, any shape) -> ``(..., 3, 3)``.

    Raises
    ------
    ValueError
        If an angle is NaN or infinite.

    Notes
    -----
    ``[[1, 0, 0], [0, c, -s], [0, s, c]]``, ``Rot(x, angle)`` of Lynch & Park (2017), Sec. 3.2.1.

    Examples
    --------
    >>> print(np.round(rot_x(np.pi / 2) @ [0.0, 1.0, 0.0], 6))
    [0. 0. 1.]
    """
    return _elementary(angle, 1, 2)


def rot_y(angle: Any) -> np.ndarray:
    """Rotations about y by ``angle`` (radians, any shape) -> ``(..., 3, 3)``.

    Raises
    ------
    ValueError
        If an angle is NaN or infinite.

    Notes
    -----
    ``[[c, 0, s], [0, 1, 0], [-s, 0, c]]``, ``Rot(y, angle)`` of Lynch & Park (2017), Sec. 3.2.1.

    Examples
    --------
    >>> print(np.round(rot_y(np.pi / 2) @ [0.0, 0.0, 1.0], 6))
    [1. 0. 0.]
    """
    return _elementary(angle, 2, 0)


def rot_z(angle: Any) -> np.ndarray:
    """Rotations about z by ``angle`` (radians, any shape) -> ``(..., 3, 3)``.

    Raises
    ------
    ValueError
        If an angle is NaN or infinite.

    Notes
    -----
    ``[[c, -s, 0], [s, c, 0], [0, 0, 1]]``, ``Rot(z, angle)`` of Lynch & Park (2017), Sec. 3.2.1.

    Examples
    --------
    >>> print(np.round(rot_z(np.pi / 2) @ [1.0, 0.0, 0.0], 6))
    [0. 1. 0.]
    >>> rot_z(np.zeros(4)).shape
    (4, 3, 3)
    """
    return _elementary(angle, 0, 1)


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
    Fixed-angle conventions, Craig (2005), Sec. 2.8, evaluated by ``scipy.spatial.transform``.

    Examples
    --------
    >>> print(np.round(euler_matrix([0.0, 0.0, np.pi / 2]) @ [1.0, 0.0, 0.0], 6))
    [0. 1. 0.]
    """
    a = as_array(angles, "angles", shape=(3,))
    if not isinstance(seq, str) or len(seq) != 3 or not (set(seq) <= set("xyz") or set(seq) <= set("XYZ")):
        raise ValueError(f"seq: expected three axes like 'xyz' or 'ZYX', got {seq!r}")
    return Rotation.from_euler(seq, a).as_matrix()


def zyz_angles(R: Any, *, validate: bool = True, tol: float = ROTATION_TOL) -> np.ndarray:
    """ZYZ Euler angles ``(a, b, c)`` of rotations ``R = rot_z(a) @ rot_y(b) @ rot_z(c)``.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
    validate : bool, default True
        Check that every matrix is a rotation (within ``tol``); ``False`` skips it (the analytic IK
        calls it on thousands of arm angles per target).
    tol : float, default :data:`ROTATION_TOL`

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        ``a, c`` in [-pi, pi] and ``b`` in [0, pi]; the other solution is
        ``(a + pi, -b, c + pi)``. Where ``sin b < 1e-12`` (``b = 0`` or ``pi``, gimbal lock) only
        ``a + c`` (``b = 0``) or ``c - a`` (``b = pi``) is defined: then ``a = 0`` and ``c`` carries
        the whole rotation about z (scipy's ``as_euler("ZYZ")`` sets ``c = 0`` instead, with a
        warning).

    Raises
    ------
    ValueError
        If the shape is wrong or a matrix is not a rotation.

    Notes
    -----
    Z-Y-Z Euler angles, Craig (2005), Sec. 2.8: ``b = atan2(sqrt(r13^2 + r23^2), r33)``,
    ``a = atan2(r23, r13)``, ``c = atan2(r32, -r31)`` (1-based entries).

    Examples
    --------
    >>> print(np.round(zyz_angles(rot_z(0.3) @ rot_y(0.5) @ rot_z(-0.2)), 6))
    [ 0.3  0.5 -0.2]
    >>> print(np.round(zyz_angles(rot_z(0.3) @ rot_z(0.4)), 6))       # b = 0: a + c only
    [0.  0.  0.7]
    """
    R = _rotations(R, tol) if validate else np.asarray(R, dtype=float)
    m02, m12 = R[..., 0, 2], R[..., 1, 2]
    sb = np.hypot(m02, m12)
    out = np.empty((3,) + sb.shape)                  # a, b, c: each a contiguous block
    np.arctan2(m12, m02, out=out[0, ...])
    np.arctan2(sb, R[..., 2, 2], out=out[1, ...])
    np.arctan2(R[..., 2, 1], -R[..., 2, 0], out=out[2, ...])
    sing = sb < 1e-12
    if sing.any():
        out[0] = np.where(sing, 0.0, out[0])
        out[2] = np.where(sing, np.arctan2(R[..., 1, 0], R[..., 1, 1]), out[2])
    return out.transpose(*range(1, out.ndim), 0)


def quat_to_matrix(quat: Any, *, validate: bool = True) -> np.ndarray:
    """Rotation matrices of quaternions ``[w, x, y, z]`` (scalar first, MuJoCo's order).

    Parameters
    ----------
    quat : array_like, shape (..., 4)
        Quaternions; each is normalised first (scaled by its largest entry, then by its norm, so
        huge and tiny ones do not overflow), so one a little off unit length (rounding in a
        simulator's integration) still gives a proper rotation. ``q`` and ``-q`` give the same
        matrix.
    validate : bool, default True
        Validate the input (shape, finite values, not zero); ``False`` skips it.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)

    Raises
    ------
    ValueError
        If the last axis does not have length 4, a value is not finite, or a quaternion is zero.

    Notes
    -----
    The rotation of the unit quaternion ``(w, x, y, z)`` (Lynch & Park 2017, Appendix B.3)::

        [[1 - 2(y^2 + z^2), 2(xy - wz),       2(xz + wy)],
         [2(xy + wz),       1 - 2(x^2 + z^2), 2(yz - wx)],
         [2(xz - wy),       2(yz + wx),       1 - 2(x^2 + y^2)]]

    ``[cos(t/2), sin(t/2) u]`` is the rotation by ``t`` about the unit axis ``u``.

    Examples
    --------
    >>> c = np.cos(np.pi / 4)
    >>> print(np.round(quat_to_matrix([c, 0.0, 0.0, c]) @ [1.0, 0.0, 0.0], 6))   # 90 deg about z
    [0. 1. 0.]
    >>> quat_to_matrix(np.tile([1.0, 0.0, 0.0, 0.0], (5, 1))).shape
    (5, 3, 3)
    """
    q = as_array(quat, "quat") if validate else np.asarray(quat, dtype=float)
    if validate and (q.ndim == 0 or q.shape[-1] != 4):
        raise ValueError(f"quat: expected quaternions [w, x, y, z], shape (..., 4), got shape {q.shape}")
    big = np.max(np.abs(q), axis=-1, keepdims=True)
    if validate and np.any(big == 0):
        raise ValueError("quat: expected non-zero quaternions (a zero one is no rotation), got [0, 0, 0, 0]")
    q = q / big
    w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    if q.ndim == 1:      # one quaternion (a simulator's every step): the same products on floats, no stacks
        w, x, y, z = float(w), float(x), float(y), float(z)
        return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
                     np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
                     np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)],
                    -2)  # Lynch & Park 2017, App. B.3
