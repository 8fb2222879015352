"""The steps of the S-R-S decomposition, one function each (used by the lesson and its exercises).

For an arm whose first three axes meet at a shoulder point ``S``, whose last three meet at a wrist
centre ``W``, with a revolute elbow between (the KUKA LBR iiwa):

1. :func:`wrist_centre` - ``W`` from the target transform;
2. :func:`elbow_angle` - the elbow joint from the triangle ``S``-elbow-``W`` (law of cosines);
3. :func:`shoulder_angles` - the shoulder joints for a chosen arm angle ``psi``.

Angles follow the iiwa's DH frames (:func:`robokit.arm.iiwa14`): ``Rz(q1) Ry(q2) Rz(q3)`` is the
shoulder rotation, and ``q4 > 0`` bends the forearm towards the upper arm's ``-x`` axis.

References
----------
.. [1] L. Huang and R. Jiang, "A new method of inverse kinematics solution for industrial 7DOF
   robot", *Proc. 32nd Chinese Control Conference*, 2013.
.. [2] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..geometry import as_se3, rot_y, rot_z, so3_exp, zyz_angles
from ..validation import as_array, require_finite_result, as_finite_scalar, as_positive

__all__ = ["wrist_centre", "elbow_angle", "shoulder_angles"]


def _reference_rotation(sw: np.ndarray, q4: np.ndarray, d_se: float, d_ew: float) -> np.ndarray:
    """Unchecked: ``Rz(q1) Ry(q2)`` of the reference arm plane (``q3 = 0``) that reaches ``sw``.

    ``q1`` turns the vertical plane through the shoulder-wrist vector ``sw`` and ``q2`` tilts the
    upper arm in it so that ``Rz(q1) Ry(q2) v = sw`` with ``v = (-d_ew sin q4, 0, d_se + d_ew cos q4)``
    (Shimizu et al. 2008, Sec. III-A, reference plane).
    """
    v_x, v_z = -d_ew * np.sin(q4), d_se + d_ew * np.cos(q4)
    q1 = np.arctan2(sw[..., 1], sw[..., 0])
    q2 = np.arctan2(np.hypot(sw[..., 0], sw[..., 1]), sw[..., 2]) - np.arctan2(v_x, v_z)
    return rot_z(q1) @ rot_y(q2)


def wrist_centre(T: Any, d_wf: float) -> np.ndarray:
    """The wrist centre ``W = p - d_wf z`` of a target flange transform.

    Parameters
    ----------
    T : array_like, shape (4, 4)
        Target flange transform (SE(3)) in the base frame.
    d_wf : float
        Distance from the wrist centre to the flange along the flange's z axis [m] (0.126 m on the
        iiwa 14).

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    ValueError
        If ``T`` is not an SE(3) matrix or ``d_wf`` is negative or not finite.

    Notes
    -----
    Separation of position and posture: Huang & Jiang (2013), as quoted in the course's assignment; Shimizu et al. (2008), Eq. (3).

    Examples
    --------
    >>> T = np.eye(4)
    >>> T[:3, 3] = [0.5, 0.0, 0.8]
    >>> print(np.round(wrist_centre(T, 0.126), 3))
    [0.5   0.    0.674]
    """
    T = as_se3(T, "T")
    d = as_positive(d_wf, "d_wf", allow_zero=True)
    return T[:3, 3] - d * T[:3, 2]


def elbow_angle(shoulder: Any, wrist: Any, d_se: float, d_ew: float) -> float:
    """The elbow joint ``q4 >= 0`` that puts the wrist centre at distance ``|W - S|`` from the shoulder.

    Parameters
    ----------
    shoulder, wrist : array_like, shape (3,)
        Shoulder point ``S`` and wrist centre ``W`` [m].
    d_se, d_ew : float
        Upper-arm (shoulder-elbow) and forearm (elbow-wrist) lengths [m], positive.

    Returns
    -------
    float
        ``acos((|W - S|^2 - d_se^2 - d_ew^2) / (2 d_se d_ew))`` in ``[0, pi]``; ``-q4`` is the
        other elbow branch.

    Raises
    ------
    ValueError
        If the distance is outside ``[|d_se - d_ew|, d_se + d_ew]`` (out of reach), or an input is
        malformed.

    Notes
    -----
    Law of cosines in the shoulder-elbow-wrist triangle, Shimizu et al. (2008), Eq. (4).

    Examples
    --------
    >>> print(round(np.degrees(elbow_angle([0, 0, 0.36], [0.0, 0.0, 1.18], 0.42, 0.40)), 6))   # stretched
    0.0
    >>> print(round(np.degrees(elbow_angle([0, 0, 0.36], [0.5, 0.0, 0.36], 0.42, 0.40)), 2))
    104.9
    """
    S = as_array(shoulder, "shoulder", shape=(3,))
    W = as_array(wrist, "wrist", shape=(3,))
    l1, l2 = as_positive(d_se, "d_se"), as_positive(d_ew, "d_ew")
    L = float(np.linalg.norm(W - S))
    try:
        c = (L**2 - l1**2 - l2**2) / (2 * l1 * l2)
    except OverflowError:
        c = math.inf
    if not abs(c) <= 1.0 + 1e-12:
        raise ValueError(f"shoulder, wrist: out of reach, |W - S| = {L:.6g} m is outside [{abs(l1 - l2):.6g}, "
                         f"{l1 + l2:.6g}] m for d_se = {l1:.6g} m and d_ew = {l2:.6g} m")
    return float(np.arccos(np.clip(c, -1.0, 1.0)))


def shoulder_angles(shoulder: Any, wrist: Any, q4: float, psi: float, d_se: float, d_ew: float) -> np.ndarray:
    """Shoulder joints ``(q1, q2 >= 0, q3)`` that place the wrist centre, for one arm angle.

    Parameters
    ----------
    shoulder, wrist : array_like, shape (3,)
        Shoulder point and wrist centre [m].
    q4 : float
        Elbow joint [rad] consistent with ``|W - S|`` (see :func:`elbow_angle`).
    psi : float
        Arm angle [rad]: rotation of the arm plane about the shoulder-wrist axis, from the
        reference plane in which ``q3 = 0``.
    d_se, d_ew : float
        Upper-arm and forearm lengths [m].

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``(q1, q2, q3)`` with ``q2 >= 0``; the mirror branch is ``(q1 + pi, -q2, q3 + pi)``.

    Raises
    ------
    ValueError
        On malformed or non-finite input or a zero shoulder-wrist distance.

    Notes
    -----
    Shimizu et al. (2008), Eqs. (9)-(15): ``R_0^3(psi) = R_psi R_0^3(0)`` with ``R_psi`` the
    rotation by ``psi`` about the unit shoulder-wrist vector (Rodrigues' formula); then the ZYZ
    decomposition of ``Rz(q1) Ry(q2) Rz(q3)``.

    Examples
    --------
    The shoulder of the iiwa at a configuration, recovered from its wrist centre and arm angle:

    >>> from robokit.arm import arm_angle, iiwa14
    >>> arm, q = iiwa14(), np.radians([35, 50, -40, -75, 60, 45, 20])
    >>> W = arm.link_frames(q)[5, :3, 3]
    >>> print(np.round(np.degrees(shoulder_angles([0, 0, 0.36], W, q[3], arm_angle(arm, q), 0.42, 0.40)), 4))
    [ 35.  50. -40.]
    """
    S = as_array(shoulder, "shoulder", shape=(3,))
    W = as_array(wrist, "wrist", shape=(3,))
    q4 = as_finite_scalar(q4, "q4")
    psi = as_finite_scalar(psi, "psi")
    l1, l2 = as_positive(d_se, "d_se"), as_positive(d_ew, "d_ew")
    sw = W - S
    L = float(np.linalg.norm(sw))
    if L < 1e-12:
        raise ValueError("wrist: expected a wrist centre away from the shoulder, got |W - S| = 0")
    R_psi = so3_exp(psi * sw / L, validate=False)                 # rotation by psi about S-W (Rodrigues)
    M = R_psi @ _reference_rotation(sw, np.asarray(q4), l1, l2)   # R_0^3(psi) = R_psi R_0^3(0), Eqs. (9)-(15)
    require_finite_result("shoulder, wrist, q4, psi, d_se, d_ew", M)
    return zyz_angles(M, validate=False)
