r"""Kinematics and statics of one LittleDog leg: FK, closed-form IK (both knees), Jacobian, J^T f.

A leg is a hip roll about the body's x axis, then a hip pitch and a knee about the rolled y axis
(:mod:`robokit.legged.littledog`). In the body frame the foot centre is

.. math::

    p = h + R_x(q_1)\left(\begin{bmatrix}0\\ s d\\ 0\end{bmatrix}
        + R_y(q_2)\left(\begin{bmatrix}0\\0\\-L_1\end{bmatrix}
        + R_y(q_3)\begin{bmatrix}0\\0\\-L_2\end{bmatrix}\right)\right)

with ``h`` the hip position, ``s`` = +1 for a left leg and -1 for a right one, ``d`` the leg's hip-pitch
offset (:data:`~robokit.legged.littledog.HIP_OFFSETS`), ``L1``, ``L2`` the upper and lower leg
(Siciliano & Khatib 2016, Ch. 2, Eq. (2.40) composes the same elementary rotations). The inverse is closed-form: the roll is the angle that puts the
foot in the leg's sagittal plane (a point at distance ``d`` from the roll axis gives two tangents;
the one with the foot below the hip is taken), and the pitch and knee solve a planar two-link arm
by the law of cosines, whose two roots are the two knee branches: ``branch = -1`` bends the knee
backwards (foot ahead of the knee, LittleDog's front legs), ``branch = +1`` forwards (the hind
legs) - :data:`KNEE_BRANCH`.

Statics: joint torques ``tau`` and a force ``f`` at the foot balance when ``tau = J^T f``
(Siciliano & Khatib 2016, Ch. 2, Eq. (2.98), the principle of virtual work), with ``J`` the foot's
Jacobian (:func:`foot_jacobian`; :func:`torques_from_foot_force`). The ground's push on a standing foot follows
from the torques as ``f = J^{-T} (tau_g - tau)``, where ``tau_g`` is what gravity asks of the leg's
own links (:func:`foot_force_from_torques`): the lesson compares it with MuJoCo's contact forces.

References
----------
.. [1] B. Siciliano and O. Khatib (eds.), *Springer Handbook of Robotics*, 2nd ed., Springer, 2016,
   Ch. 2 "Kinematics" (K. Waldron and J. Schmiedeler).
.. [2] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Sec. 4.
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..geometry import as_se3
from ..validation import as_array, as_int, as_rng, describe, require_angles, require_finite_result
from .littledog import HIP_OFFSETS, HIP_POSITIONS, JOINT_LIMITS, LEGS, LOWER_LEG, UPPER_LEG

__all__ = ["KNEE_BRANCH", "UnreachableFootError", "leg_index", "foot_position", "leg_points", "foot_jacobian",
           "leg_ik", "leg_ik_batch", "LegIK", "within_limits", "reachable_workspace", "body_ik", "body_fk",
           "torques_from_foot_force", "foot_force_from_torques"]


KNEE_BRANCH = (-1, -1, +1, +1)
"""LittleDog's knee branch per leg (FL, FR, HL, HR): front knees bend backwards, hind forwards."""

_REACH_TOL = 1e-9


class UnreachableFootError(ValueError):
    """A foot target lies outside the leg's reach (too far, too close, or too near the roll axis)."""


def leg_index(leg: Any) -> int:
    """Index 0-3 of a leg given by name (``"FL"``, ``"FR"``, ``"HL"``, ``"HR"``) or index.

    Examples
    --------
    >>> leg_index("HL"), leg_index(1)
    (2, 1)
    """
    if isinstance(leg, str):
        if leg not in LEGS:
            raise ValueError(f"leg: expected one of {LEGS} or 0-3, got {leg!r}")
        return LEGS.index(leg)
    return as_int(leg, "leg", minimum=0, maximum=3)


def _side(i: int) -> float:
    return 1.0 if LEGS[i].endswith("L") else -1.0


def _angles(q: Any, name: str = "q_leg") -> np.ndarray:
    q = as_array(q, name)
    if q.ndim == 0 or q.shape[-1] != 3:
        raise ValueError(f"{name}: expected shape (..., 3) (hip roll, hip pitch, knee), got {describe(q)}")
    require_angles(q, name, "joint angles")
    return q


def _chain(q: np.ndarray, i: int):
    """Unchecked: hip, knee and foot positions in the body frame, each (..., 3)."""
    c1, s1 = np.cos(q[..., 0]), np.sin(q[..., 0])
    a2, a23 = q[..., 1], q[..., 1] + q[..., 2]
    # sagittal-plane coordinates after the roll (x forward, z down the leg)
    kx, kz = -UPPER_LEG * np.sin(a2), -UPPER_LEG * np.cos(a2)
    fx, fz = kx - LOWER_LEG * np.sin(a23), kz - LOWER_LEG * np.cos(a23)
    y = _side(i) * HIP_OFFSETS[i]
    hip = np.broadcast_to(HIP_POSITIONS[i], q.shape).copy()

    def rolled(x, z):  # R_x(q1) [x, y, z] + hip
        return np.stack([x, c1 * y - s1 * z, s1 * y + c1 * z], axis=-1) + hip
    return hip, rolled(kx, kz), rolled(fx, fz)


def foot_position(q_leg: Any, leg: Any) -> np.ndarray:
    """Foot centre in the body frame, from the leg's three joint angles (forward kinematics).

    Parameters
    ----------
    q_leg : array_like, shape (..., 3)
        Hip roll, hip pitch, knee (rad).
    leg : str or int
        ``"FL"``, ``"FR"``, ``"HL"``, ``"HR"`` or 0-3.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Metres, body frame (module docstring's formula).

    Examples
    --------
    >>> foot_position([0, 0, 0], "FL").round(5).tolist()   # leg straight down: 0.177 m below the hip
    [0.101, 0.05985, -0.1771]
    """
    return _chain(_angles(q_leg), leg_index(leg))[2]


def leg_points(q_leg: Any, leg: Any) -> np.ndarray:
    """Hip, hip-pitch axis, knee and foot of one leg in the body frame (for drawing).

    Returns
    -------
    numpy.ndarray, shape (..., 4, 3)

    Examples
    --------
    >>> leg_points([0, 0, 0], "HR")[..., 2].round(4)     # z of hip, pitch axis, knee, foot
    array([ 0.    ,  0.    , -0.0751, -0.1771])
    """
    q = _angles(q_leg)
    i = leg_index(leg)
    hip, knee, foot = _chain(q, i)
    c1, s1 = np.cos(q[..., 0]), np.sin(q[..., 0])
    y = _side(i) * HIP_OFFSETS[i]
    pitch = hip + np.stack([np.zeros_like(c1), c1 * y, s1 * y], axis=-1)
    return np.stack([hip, pitch, knee, foot], axis=-2)


def foot_jacobian(q_leg: Any, leg: Any) -> np.ndarray:
    """The 3x3 Jacobian ``d p_foot / d q_leg`` in the body frame (analytic).

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Column ``j`` is the foot velocity (m/s, body frame) per rad/s of joint ``j``: for the roll
        ``e_x x (p - h)``; for pitch and knee the rolled ``y`` axis crossed with the lever from the
        joint to the foot (Siciliano & Khatib 2016, Ch. 2, Eq. (2.72), revolute columns).

    Examples
    --------
    >>> foot_jacobian([0, 0, 0], "FL").round(4).tolist()
    [[0.0, -0.1771, -0.102], [0.1771, 0.0, 0.0], [0.0236, 0.0, 0.0]]
    """
    q = _angles(q_leg)
    i = leg_index(leg)
    hip, knee, foot = _chain(q, i)
    c1, s1 = np.cos(q[..., 0]), np.sin(q[..., 0])
    zero = np.zeros_like(c1)
    ex = np.broadcast_to([1.0, 0.0, 0.0], foot.shape)
    ey = np.stack([zero, c1, s1], axis=-1)               # the rolled y axis
    pitch = leg_points(q, i)[..., 1, :]
    cols = [np.cross(ex, foot - hip), np.cross(ey, foot - pitch), np.cross(ey, foot - knee)]  # Eq. (2.72)
    return np.stack(cols, axis=-1)


class LegIK(NamedTuple):
    """Result of :func:`leg_ik_batch`: joint angles ``q`` (N, 3) and ``ok`` (N,) reachable flags."""

    q: np.ndarray
    ok: np.ndarray


_SIDES = np.array([_side(k) for k in range(4)])


def _solve(p: np.ndarray, i: Any, branch: np.ndarray):
    """Unchecked closed-form IK: angles (N, 3), reach flags (N,); ``i`` one leg, or one leg per target."""
    v = p - HIP_POSITIONS[i]                                   # (3,) for one leg, (N, 3) for one per target
    d = _SIDES[i] * HIP_OFFSETS[i]
    r2 = v[:, 1] ** 2 + v[:, 2] ** 2
    ok = r2 >= HIP_OFFSETS[i] ** 2 * (1 - _REACH_TOL)
    r = np.sqrt(np.maximum(r2, HIP_OFFSETS[i] ** 2))
    # roll: the foot, turned back by q1, sits at y = d in the leg's plane; take the root with z < 0
    phi = np.arctan2(v[:, 2], v[:, 1])
    q1 = phi + np.arccos(np.clip(d / r, -1.0, 1.0))
    q1 = np.where(-np.sin(q1) * v[:, 1] + np.cos(q1) * v[:, 2] > 0,
                  phi - np.arccos(np.clip(d / r, -1.0, 1.0)), q1)
    q1 = (q1 + np.pi) % (2 * np.pi) - np.pi
    z = -np.sin(q1) * v[:, 1] + np.cos(q1) * v[:, 2]      # foot in the rolled frame (x, z)
    x = v[:, 0]
    D2 = x ** 2 + z ** 2
    c3 = (D2 - UPPER_LEG ** 2 - LOWER_LEG ** 2) / (2 * UPPER_LEG * LOWER_LEG)   # law of cosines
    ok &= np.abs(c3) <= 1 + _REACH_TOL
    q3 = branch * np.arccos(np.clip(c3, -1.0, 1.0))
    q2 = np.arctan2(-x, -z) - np.arctan2(LOWER_LEG * np.sin(q3), UPPER_LEG + LOWER_LEG * np.cos(q3))
    q2 = (q2 + np.pi) % (2 * np.pi) - np.pi
    q = np.stack([q1, q2, q3], axis=1)
    return np.where(ok[:, None], q, 0.0), ok


def _branch(branch: Any, i: int, n: int) -> np.ndarray:
    if branch is None:
        return np.full(n, float(KNEE_BRANCH[i]))
    b = as_array(branch, "branch")
    if b.ndim > 1 or not np.all(np.isin(b, (-1.0, 1.0))):
        raise ValueError(f"branch: expected -1 (knee back), +1 (knee forward) or None, got {describe(branch)}")
    if b.ndim == 1 and b.size != n:
        raise ValueError(f"branch: expected one value, or one per target ({n}), got {b.size}")
    return np.broadcast_to(b, (n,)).astype(float)


def leg_ik_batch(p_foot: Any, leg: Any, branch: Any = None) -> LegIK:
    """Closed-form inverse kinematics of one leg for many foot targets at once.

    Parameters
    ----------
    p_foot : array_like, shape (N, 3) or (3,)
        Foot-centre targets in the body frame (m).
    leg : str or int
        Which leg.
    branch : {-1, +1}, array of them, or None
        Knee branch: -1 bends the knee backwards, +1 forwards; ``None`` takes LittleDog's own
        (:data:`KNEE_BRANCH`).

    Returns
    -------
    LegIK
        ``q`` (N, 3) joint angles in (-pi, pi] and ``ok`` (N,): False where the target is out of
        reach (farther than ``L1 + L2`` or nearer than ``|L1 - L2|`` from the pitch axis, or nearer
        the roll axis than the hip offset); those rows hold zeros. A target on the boundary (within
        1e-9 relative) is reached with the leg straight. Joint limits are not applied: see
        :func:`within_limits`.

    Examples
    --------
    >>> q, ok = leg_ik_batch([[0.12, 0.07, -0.11], [0.5, 0.0, 0.0]], "FL")
    >>> ok.tolist(), foot_position(q[0], "FL").round(6).tolist()
    ([True, False], [0.12, 0.07, -0.11])
    """
    p = as_array(p_foot, "p_foot")
    if p.ndim == 1:
        p = p[None]
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"p_foot: expected shape (N, 3) or (3,), got {describe(p_foot)}")
    i = leg_index(leg)
    q, ok = _solve(p, i, _branch(branch, i, len(p)))
    return LegIK(q, ok)


def leg_ik(p_foot: Any, leg: Any, branch: Any = None) -> np.ndarray:
    """Closed-form inverse kinematics of one leg for one foot target.

    Parameters
    ----------
    p_foot : array_like, shape (3,)
        Foot-centre target in the body frame (m).
    leg : str or int
    branch : {-1, +1} or None
        As in :func:`leg_ik_batch`.

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    UnreachableFootError
        If the target is out of the leg's reach (the message says by how much).

    Examples
    --------
    >>> p = foot_position([0.1, 0.6, -1.2], "FR")
    >>> leg_ik(p, "FR").round(6).tolist(), leg_ik(p, "FR", branch=+1).round(3).tolist()
    ([0.1, 0.6, -1.2], [0.1, -0.807, 1.2])
    """
    p = as_array(p_foot, "p_foot", shape=(3,))
    i = leg_index(leg)
    q, ok = _solve(p[None], i, _branch(branch, i, 1))
    if not ok[0]:
        v = p - HIP_POSITIONS[i]
        raise UnreachableFootError(
            f"p_foot: {p.round(4).tolist()} is out of reach of leg {LEGS[i]} "
            f"({np.linalg.norm(v):.4f} m from the hip; the leg spans {abs(UPPER_LEG - LOWER_LEG):.4f}-"
            f"{UPPER_LEG + LOWER_LEG:.4f} m from its pitch axis, which is {HIP_OFFSETS[i]} m out from the hip)")
    return q[0]


def within_limits(q: Any, leg: Any = None) -> np.ndarray:
    """Whether joint angles respect LittleDog's limits (:data:`~robokit.legged.littledog.JOINT_LIMITS`).

    Parameters
    ----------
    q : array_like, shape (..., 3) with ``leg`` or (..., 12) without
    leg : str or int, optional

    Returns
    -------
    numpy.ndarray of bool, shape (...)

    Examples
    --------
    >>> bool(within_limits([0.0, 0.5, -1.5], "FL")), bool(within_limits([0.0, 0.5, -1.5], "HL"))
    (True, False)
    """
    q = as_array(q, "q")
    if leg is None:
        if q.ndim == 0 or q.shape[-1] != 12:
            raise ValueError(f"q: expected shape (..., 12) without leg, got {describe(q)}")
        lim = JOINT_LIMITS
    else:
        q = _angles(q, "q")
        i = leg_index(leg)
        lim = JOINT_LIMITS[3 * i:3 * i + 3]
    return np.all((q >= lim[:, 0] - 1e-12) & (q <= lim[:, 1] + 1e-12), axis=-1)


def reachable_workspace(leg: Any, n: int = 20000, *, rng: Any = 0, branch: Any = None) -> np.ndarray:
    """Foot positions reachable within the joint limits, sampled uniformly in joint space.

    Parameters
    ----------
    leg : str or int
    n : int, default 20000
        Number of samples.
    rng : numpy.random.Generator or int, default 0
    branch : {-1, +1} or None
        Keep only samples whose knee is on this branch (``None``: LittleDog's own).

    Returns
    -------
    numpy.ndarray, shape (M, 3)
        Body-frame foot positions (M <= n), for drawing the workspace as a point cloud.

    Examples
    --------
    >>> pts = reachable_workspace("FL", 2000)
    >>> bool(np.all(np.linalg.norm(pts - [0.101, 0.03625, 0], axis=1) <= 0.1771 + 0.0236))
    True
    """
    i = leg_index(leg)
    n = as_int(n, "n", minimum=1, maximum=10_000_000)
    g = as_rng(rng)
    b = KNEE_BRANCH[i] if branch is None else int(_branch(branch, i, 1)[0])
    lim = JOINT_LIMITS[3 * i:3 * i + 3]
    q = g.uniform(lim[:, 0], lim[:, 1], size=(n, 3))
    q = q[np.sign(q[:, 2]) == b]
    return _chain(q, i)[2]


def body_fk(q: Any) -> np.ndarray:
    """The four feet in the body frame from a full 12-joint vector.

    Parameters
    ----------
    q : array_like, shape (..., 12)
        Joint angles, leg-major (:data:`~robokit.legged.littledog.JOINT_NAMES`).

    Returns
    -------
    numpy.ndarray, shape (..., 4, 3)

    Examples
    --------
    >>> body_fk(np.zeros(12))[:, 2].round(4).tolist()
    [-0.1771, -0.1771, -0.1771, -0.1771]
    """
    q = as_array(q, "q")
    if q.ndim == 0 or q.shape[-1] != 12:
        raise ValueError(f"q: expected shape (..., 12), got {describe(q)}")
    require_angles(q, "q", "joint angles")
    legs = q.reshape(q.shape[:-1] + (4, 3))
    return np.stack([_chain(legs[..., i, :], i)[2] for i in range(4)], axis=-2)


def body_ik(feet: Any, T_world_body: Any = None, *, validate: bool = True) -> LegIK:
    """Joint angles that put the four feet at given points: the host's set-points for a body pose.

    Parameters
    ----------
    feet : array_like, shape (N, 4, 3) or (4, 3)
        Foot centres, in the world frame if ``T_world_body`` is given, else in the body frame (m).
    T_world_body : array_like, shape (N, 4, 4) or (4, 4), optional
        Where the body is (or is planned to be).
    validate : bool, default True
        Validate inputs; ``False`` is the fast path for the host loop.

    Returns
    -------
    LegIK
        ``q`` (N, 12) leg-major on LittleDog's knee branches and ``ok`` (N,): False if any foot of
        that row is out of reach (that leg's angles are zeros).

    Examples
    --------
    >>> from robokit.legged.littledog import STANCE_FEET
    >>> q, ok = body_ik(STANCE_FEET)
    >>> bool(ok[0]), np.allclose(body_fk(q[0]), STANCE_FEET)
    (True, True)
    """
    if validate:
        f = as_array(feet, "feet")
        single = f.ndim == 2
        f = f[None] if single else f
        if f.ndim != 3 or f.shape[1:] != (4, 3):
            raise ValueError(f"feet: expected shape (N, 4, 3) or (4, 3), got {describe(feet)}")
        if T_world_body is not None:
            T = as_se3(T_world_body, "T_world_body", batch=True)
            T = T[None] if T.ndim == 2 else T
            if len(T) != len(f):
                raise ValueError(f"T_world_body: expected {len(f)} poses (one per row of feet), got {len(T)}")
    else:
        f = np.asarray(feet, float)
        f = f[None] if f.ndim == 2 else f
        T = None if T_world_body is None else np.asarray(T_world_body, float)
        if T is not None and T.ndim == 2:
            T = T[None]
    if T_world_body is not None:
        R, t = T[:, :3, :3], T[:, :3, 3]
        f = np.einsum("nji,nkj->nki", R, f - t[:, None, :])    # R^T (p - t)
    legs = np.tile(np.arange(4), len(f))                      # all four legs in one batch
    q, ok = _solve(f.reshape(-1, 3), legs, np.asarray(KNEE_BRANCH, float)[legs])
    return LegIK(q.reshape(len(f), 12), ok.reshape(len(f), 4).all(axis=1))


def _vectors(value: Any, name: str, batch: tuple, against: str = "q_leg's") -> np.ndarray:
    """``value`` as 3-vectors (..., 3) whose leading axes broadcast with ``batch`` (the joint angles')."""
    v = as_array(value, name)
    if v.shape[-1:] != (3,):
        raise ValueError(f"{name}: expected shape (..., 3), got {describe(value)}")
    try:
        np.broadcast_shapes(v.shape[:-1], batch)
    except ValueError:
        raise ValueError(f"{name}: expected leading axes that broadcast with {against} {batch}, "
                         f"got shape {v.shape}") from None
    return v


def torques_from_foot_force(q_leg: Any, force: Any, leg: Any) -> np.ndarray:
    """Joint torques that balance a force applied at the foot: ``tau = J^T f``.

    Parameters
    ----------
    q_leg : array_like, shape (..., 3)
    force : array_like, shape (..., 3)
        The force the leg must push with, in the body frame (N) - e.g. minus the ground's reaction.
    leg : str or int

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        N m (Siciliano & Khatib 2016, Eq. (2.98)).

    Examples
    --------
    >>> torques_from_foot_force([0, 0.6, -1.2], [0, 0, -7.4], "FL").round(3).tolist()
    [-0.175, 0.112, 0.426]
    """
    J = foot_jacobian(q_leg, leg)
    f = _vectors(force, "force", J.shape[:-2])
    with np.errstate(over="ignore", invalid="ignore"):
        tau = np.einsum("...ji,...j->...i", J, f)  # Eq. (2.98)
    require_finite_result("force", tau)
    return tau


def foot_force_from_torques(q_leg: Any, tau: Any, leg: Any, gravity_torque: Any = None) -> np.ndarray:
    """The ground's force on a standing foot, from the leg's joint torques: ``f = J^{-T} (tau_g - tau)``.

    Parameters
    ----------
    q_leg : array_like, shape (..., 3)
    tau : array_like, shape (..., 3)
        Torques the motors apply at the joints (N m).
    leg : str or int
    gravity_torque : array_like, shape (..., 3), optional
        Joint torques gravity asks of the leg's own links, ``tau_g`` (MuJoCo's ``qfrc_bias`` at
        rest). Omitted, the legs are taken as massless.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Body frame (N). A quasi-static estimate: the leg's accelerations are neglected.

    Raises
    ------
    ValueError
        If the leg is singular (fully stretched or folded: ``J`` cannot be inverted), if ``tau`` or
        ``gravity_torque`` has leading axes that do not broadcast with ``q_leg``'s, or if the force
        overflows (torques near the largest float).

    Examples
    --------
    >>> q = [0, 0.6, -1.2]
    >>> foot_force_from_torques(q, torques_from_foot_force(q, [0, 0, -7.4], "FL"), "FL").round(3).tolist()
    [0.0, -0.0, 7.4]
    """
    J = foot_jacobian(q_leg, leg)
    t = _vectors(tau, "tau", J.shape[:-2])
    if gravity_torque is not None:
        g = _vectors(gravity_torque, "gravity_torque", np.broadcast_shapes(J.shape[:-2], t.shape[:-1]),
                     "those of q_leg and tau,")
        with np.errstate(over="ignore"):
            t = t - g
    if np.any(np.abs(np.linalg.det(J)) < 1e-9):
        raise ValueError("q_leg: the leg is singular there (stretched or folded); J^T cannot be inverted")
    JT = np.swapaxes(J, -1, -2)
    with np.errstate(over="ignore", invalid="ignore"):
        f = -np.linalg.solve(JT, t[..., None])[..., 0]
    require_finite_result("tau, gravity_torque", f)
    return f
