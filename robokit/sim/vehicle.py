"""Vehicle kinematics: unicycle arc integration, differential drive and skid steering with its inverse.

Planar poses are ``[x, y, theta]`` (theta counter-clockwise from +x). A wheeled robot that keeps a
constant forward speed ``v`` and turn rate ``omega`` for ``dt`` seconds drives along a circular arc
(:func:`unicycle_step`). A differential drive gets ``v`` and ``omega`` from its wheel speeds
(:func:`diff_drive_velocities`). A skid-steer vehicle (four or more driven wheels, no steering)
must slide sideways to turn, so it turns less than a differential drive of the same track: the
ICR kinematics of Mandow et al. (2007, Sec. III) keep the differential-drive form with an
*effective* track ``icr_factor * B`` (the expansion of the instantaneous centres of rotation,
``icr_factor >= 1``; ``chi`` in the paper). We add a longitudinal slip ratio that scales both wheel
speeds by ``1 - slip`` (our addition, not part of their model) in :func:`skid_steer_velocities`;
:func:`skid_steer_wheel_speeds` inverts it for a controller, saturating the wheels without giving
up the turn. Odometry noise and paths are in :mod:`robokit.sim.motion`.

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] R. Siegwart, I. R. Nourbakhsh and D. Scaramuzza, *Introduction to Autonomous Mobile
   Robots*, 2nd ed., MIT Press, 2011.
.. [3] A. Mandow, J. L. Martinez, J. Morales, J. L. Blanco, A. Garcia-Cerezo and J. Gonzalez,
   "Experimental kinematics for wheeled skid-steer mobile robots", IEEE/RSJ International
   Conference on Intelligent Robots and Systems (IROS), 2007, pp. 1222-1227.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..geometry import wrap_angle
from ..geometry.planar import as_planar
from ..validation import as_array, as_positive, broadcast_to, require_angles

__all__ = ["unicycle_step", "diff_drive_velocities", "skid_steer_velocities", "skid_steer_wheel_speeds"]


def unicycle_step(pose: Any, v: Any, omega: Any, dt: float, *, validate: bool = True) -> np.ndarray:
    """Advance poses by driving at speed ``v`` and turn rate ``omega`` for ``dt`` seconds (exact arc).

    Parameters
    ----------
    pose : array_like, shape (3,) or (N, 3)
    v, omega : float or array_like (N,)
        Forward speed (m/s) and turn rate (rad/s), constant over the step.
    dt : float
        Duration (s, >= 0).
    validate : bool, default True
        Validate the inputs; ``False`` is the fast path for a simulation loop that already did.

    Returns
    -------
    numpy.ndarray, same shape as ``pose``
        Heading wrapped to ``[-pi, pi)``.

    Raises
    ------
    ValueError
        For a badly shaped or non-finite pose, speed or turn rate, or a negative ``dt``.

    Notes
    -----
    Thrun, Burgard & Fox (2005), Eq. (5.9): the circular arc of radius ``v / omega``. When the
    turn over the step is below 1e-9 rad the arc is the straight line along the mid-step heading
    (the limit of Eq. (5.9), without its cancellation).

    Examples
    --------
    >>> np.round(unicycle_step([0.0, 0.0, 0.0], 1.0, np.pi / 2, 1.0), 4).tolist()   # a quarter circle
    [0.6366, 0.6366, 1.5708]
    """
    if validate:
        P = as_planar(pose, "pose")
        single = P.ndim == 1
        P = P.reshape(-1, 3)
        v = broadcast_to(as_array(v, "v"), (len(P),), "v", "one per pose")
        w = broadcast_to(as_array(omega, "omega"), (len(P),), "omega", "one per pose")
        dt = as_positive(dt, "dt", allow_zero=True)
        require_angles(w * dt, "omega, dt", "heading changes omega * dt")
    else:
        P = np.asarray(pose, dtype=float)
        single = P.ndim == 1
        P, w = P.reshape(-1, 3), omega
    if single and np.ndim(v) == 0 and np.ndim(w) == 0:   # one pose: the same formulas on scalars, for speed
        x, y, th = P[0]
        turn = w * dt
        if abs(turn) < 1e-9:
            dx, dy = v * dt * np.cos(th + turn / 2), v * dt * np.sin(th + turn / 2)
        else:
            dx, dy = v / w * (np.sin(th + turn) - np.sin(th)), v / w * (np.cos(th) - np.cos(th + turn))
        return np.array([x + dx, y + dy, wrap_angle(th + turn)])
    th = P[:, 2]
    small = np.abs(w * dt) < 1e-9
    ws = np.where(small, 1.0, w)
    # Eq. (5.9): x' = x - v/w sin(th) + v/w sin(th + w dt), y' = y + v/w cos(th) - v/w cos(th + w dt)
    dx = np.where(small, v * dt * np.cos(th + w * dt / 2), v / ws * (np.sin(th + w * dt) - np.sin(th)))
    dy = np.where(small, v * dt * np.sin(th + w * dt / 2), v / ws * (np.cos(th) - np.cos(th + w * dt)))
    out = np.column_stack([P[:, 0] + dx, P[:, 1] + dy, wrap_angle(th + w * dt)])   # theta' = th + w dt
    return out[0] if single else out


def diff_drive_velocities(omega_left: Any, omega_right: Any, wheel_radius: float, track: float) -> tuple:
    """Body speed and turn rate of a differential drive from wheel angular speeds.

    Parameters
    ----------
    omega_left, omega_right : float or array_like
        Wheel angular speeds (rad/s).
    wheel_radius, track : float
        Wheel radius and distance between the wheels (m).

    Returns
    -------
    (v, omega)
        ``v = r (w_r + w_l) / 2`` (m/s), ``omega = r (w_r - w_l) / track`` (rad/s).

    Raises
    ------
    ValueError
        For non-finite speeds or a non-positive radius or track.

    Notes
    -----
    Siegwart, Nourbakhsh & Scaramuzza (2011), Sec. 3.2.1 (differential-drive forward kinematics).

    Examples
    --------
    >>> v, w = diff_drive_velocities(1.0, 3.0, wheel_radius=0.05, track=0.25)
    >>> round(float(v), 3), round(float(w), 3)
    (0.1, 0.4)
    """
    r = as_positive(wheel_radius, "wheel_radius")
    b = as_positive(track, "track")
    wl, wr = as_array(omega_left, "omega_left"), as_array(omega_right, "omega_right")
    return r * (wr + wl) / 2, r * (wr - wl) / b


def _skid_parameters(track: float, icr_factor: float, slip: float) -> tuple[float, float, float]:
    b = as_positive(track, "track")
    c = as_positive(icr_factor, "icr_factor")
    if c < 1:
        raise ValueError(f"icr_factor: expected an expansion factor >= 1, got {c}")
    s = as_positive(slip, "slip", allow_zero=True)
    if s >= 1:
        raise ValueError(f"slip: expected a ratio in [0, 1), got {s}")
    return b, c, s


def skid_steer_velocities(v_left: Any, v_right: Any, track: float, icr_factor: float = 1.5, slip: float = 0.0,
                          *, validate: bool = True) -> tuple:
    """Body speed and turn rate of a skid-steer vehicle from its left and right wheel speeds.

    Parameters
    ----------
    v_left, v_right : float or array_like
        Ground speeds the left and right wheel sets would have without slip (m/s).
    track : float
        Distance ``B`` between the left and right wheels (m).
    icr_factor : float, default 1.5
        ICR expansion factor ``chi >= 1``: skidding makes the vehicle turn as if its track were
        ``icr_factor * track``; 1 is the ideal differential drive.
    slip : float, default 0
        Longitudinal slip ratio ``s`` in [0, 1): the ground moves at ``(1 - s)`` times the wheel speed.
    validate : bool, default True
        Validate the inputs; ``False`` for callers whose parameters are already checked.

    Returns
    -------
    (v, omega)
        ``v = (1 - s)(v_l + v_r) / 2`` (m/s), ``omega = (1 - s)(v_r - v_l) / (chi B)`` (rad/s).

    Raises
    ------
    ValueError
        For non-finite speeds, a non-positive track, ``icr_factor < 1`` or a slip outside [0, 1).

    Notes
    -----
    The symmetric-ICR skid-steer kinematics with expansion factor ``chi`` (Mandow et al. 2007,
    Sec. III). The common longitudinal slip factor ``1 - s`` is our addition, not part of their
    model (``slip=0`` gives theirs).

    Examples
    --------
    >>> v, w = skid_steer_velocities(0.2, 0.4, track=0.3, icr_factor=2.0)
    >>> round(float(v), 4), round(float(w), 4)
    (0.3, 0.3333)
    """
    if validate:
        track, icr_factor, slip = _skid_parameters(track, icr_factor, slip)
        v_left, v_right = as_array(v_left, "v_left"), as_array(v_right, "v_right")
    k = 1 - slip
    return k * (v_left + v_right) / 2, k * (v_right - v_left) / (icr_factor * track)   # Mandow Sec. III, times 1 - s


def skid_steer_wheel_speeds(v: Any, omega: Any, track: float, max_wheel_speed: float, icr_factor: float = 1.5,
                            slip: float = 0.0, *, validate: bool = True) -> np.ndarray:
    """Left and right wheel speeds that give ``v`` and ``omega`` (inverse of :func:`skid_steer_velocities`), saturated.

    When a side would exceed ``max_wheel_speed`` the forward speed gives way first, so the turn
    (what keeps a vehicle off obstacles) is kept as long as the wheels can make it.

    Parameters
    ----------
    v, omega : float or array_like
        Wanted forward speed (m/s) and turn rate (rad/s).
    track, icr_factor, slip : float
        As in :func:`skid_steer_velocities`.
    max_wheel_speed : float
        Largest speed of one side (m/s).
    validate : bool, default True
        Validate the inputs.

    Returns
    -------
    numpy.ndarray, shape (..., 2)
        ``[left, right]`` wheel speeds, each within ``[-max_wheel_speed, max_wheel_speed]``.

    Raises
    ------
    ValueError
        For non-finite speeds or parameters out of range.

    Notes
    -----
    :func:`skid_steer_velocities` (Mandow et al. 2007, Sec. III, with our slip factor) solved for
    the wheel speeds: ``v_r,l = v / (1 - s) +- omega chi B / (2 (1 - s))``.

    Examples
    --------
    >>> np.round(skid_steer_wheel_speeds(0.4, 0.8, track=0.21, max_wheel_speed=1.0), 3).tolist()
    [0.274, 0.526]
    >>> np.round(skid_steer_wheel_speeds(5.0, 2.0, track=0.21, max_wheel_speed=1.0), 3).tolist()
    [0.37, 1.0]
    """
    if validate:
        track, icr_factor, slip = _skid_parameters(track, icr_factor, slip)
        max_wheel_speed = as_positive(max_wheel_speed, "max_wheel_speed")
        v, omega = as_array(v, "v"), as_array(omega, "omega")
    k = 1 - slip
    half = np.clip(omega * icr_factor * track / (2 * k), -max_wheel_speed, max_wheel_speed)  # (v_r - v_l) / 2
    room = max_wheel_speed - np.abs(half)
    fwd = np.clip(v / k, -room, room)                                                      # (v_r + v_l) / 2
    left, right = fwd - half, fwd + half
    return np.stack([left, right], axis=-1) if np.ndim(left) else np.array([left, right])
