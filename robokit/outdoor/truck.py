"""The skid-steer RC truck of Hamid et al.: body, four driven wheels, slip, and motor lag.

Hamid et al. (seed 000 Q3, Sec. 2) use a 50 x 25 x 15 cm RC truck whose four wheels are driven
independently, so it steers by driving its left and right sides at different speeds and can turn on
the spot. A skid-steer vehicle turns less than a differential drive of the same track would,
because its wheels must slide sideways; a common model keeps differential-drive kinematics with an
*effective* track ``chi * B`` (``chi > 1``, the instantaneous-centre-of-rotation expansion of Mandow
et al., "Experimental kinematics for wheeled skid-steer mobile robots", IROS 2007, Sec. III) and a
longitudinal slip ratio ``s`` that scales the wheel speeds. Each side's motor follows its speed
command with a first-order lag ``tau``.

Pose ``[x, y, theta]``: field frame x east, y north, ``theta`` counter-clockwise from east.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..geometry import wrap_angle
from ..validation import as_array, check_positive

__all__ = ["SkidSteerTruck", "TruckState", "PAPER_TRUCK"]


@dataclasses.dataclass(frozen=True)
class SkidSteerTruck:
    """Geometry and drive parameters of a skid-steer truck (SI units).

    Attributes
    ----------
    length, width, height : float
        Body size (m); the paper's truck is 0.50 x 0.25 x 0.15.
    track : float
        Lateral distance between left and right wheel centres (m).
    max_wheel_speed : float
        Largest ground speed of one side (m/s).
    motor_tau : float
        Time constant of the first-order motor lag (s).
    icr_factor : float
        Track expansion ``chi`` (>= 1) from side skidding; 1 is an ideal differential drive.
    slip : float
        Longitudinal slip ratio in [0, 0.5): ground speed = (1 - slip) * wheel speed.
    """

    length: float = 0.50
    width: float = 0.25
    height: float = 0.15
    track: float = 0.21
    max_wheel_speed: float = 1.0
    motor_tau: float = 0.3
    icr_factor: float = 1.5
    slip: float = 0.05

    def __post_init__(self):
        for name in ("length", "width", "height", "track", "max_wheel_speed", "motor_tau"):
            check_positive(getattr(self, name), name)
        if not 1.0 <= float(self.icr_factor) <= 5.0:
            raise ValueError(f"icr_factor: expected a number in [1, 5], got {self.icr_factor!r}")
        if not 0.0 <= float(self.slip) < 0.5:
            raise ValueError(f"slip: expected a ratio in [0, 0.5), got {self.slip!r}")

    @property
    def max_turn_rate(self) -> float:
        """Yaw rate (rad/s) when the two sides run at full speed in opposite directions."""
        return 2 * (1 - self.slip) * self.max_wheel_speed / (self.icr_factor * self.track)

    def body_velocity(self, wheel_speeds: Any) -> tuple[float, float]:
        """Forward speed ``v`` (m/s) and yaw rate ``omega`` (rad/s) from ``[left, right]`` wheel speeds.

        Notes
        -----
        ``v = (1 - s)(w_L + w_R) / 2``, ``omega = (1 - s)(w_R - w_L) / (chi B)`` (Mandow et al. 2007,
        Eq. (5) with a symmetric ICR and slip ratio ``s``).
        """
        wl, wr = as_array(wheel_speeds, "wheel_speeds", shape=(2,))
        k = 1 - self.slip
        return k * (wl + wr) / 2, k * (wr - wl) / (self.icr_factor * self.track)

    def wheel_commands(self, v: float, omega: float) -> np.ndarray:
        """``[left, right]`` wheel speeds that give ``v`` and ``omega`` under this model, saturated.

        When a side would exceed ``max_wheel_speed`` the forward speed is reduced first, so the turn
        (what keeps the truck off obstacles) is kept.

        Notes
        -----
        Inverse of :meth:`body_velocity` (Mandow et al. 2007, Eq. (5)).
        """
        k = 1 - self.slip
        half = omega * self.icr_factor * self.track / (2 * k)
        half = float(np.clip(half, -self.max_wheel_speed, self.max_wheel_speed))
        room = self.max_wheel_speed - abs(half)
        fwd = float(np.clip(v / k, -room, room))
        return np.array([fwd - half, fwd + half])

    def step(self, state: "TruckState", command: Any, dt: float) -> "TruckState":
        """Advance ``dt`` seconds with ``command = [left, right]`` wheel-speed set points.

        The motors respond with an exact first-order lag; the pose is integrated along the arc of
        constant ``v`` and ``omega`` over the step (exact for constant body velocity).

        Notes
        -----
        Arc integration of the unicycle model (Thrun, Burgard & Fox, *Probabilistic Robotics*, 2005,
        Sec. 5.3, Eq. 5.9) with the skid-steer velocities of Mandow et al. (2007).
        """
        cmd = np.clip(as_array(command, "command", shape=(2,)), -self.max_wheel_speed, self.max_wheel_speed)
        h = check_positive(dt, "dt")
        a = 1 - np.exp(-h / self.motor_tau)
        w0 = state.wheels
        w1 = w0 + (cmd - w0) * a
        v, om = self.body_velocity((w0 + w1) / 2)
        x, y, th = state.pose
        if abs(om) < 1e-9:
            x, y = x + v * h * np.cos(th), y + v * h * np.sin(th)
        else:
            x += v / om * (np.sin(th + om * h) - np.sin(th))
            y -= v / om * (np.cos(th + om * h) - np.cos(th))
        th = wrap_angle(th + om * h)
        return TruckState(np.array([x, y, th]), w1, v, om)


@dataclasses.dataclass(frozen=True, eq=False)
class TruckState:
    """Pose ``[x, y, theta]``, wheel speeds ``[left, right]`` and the body ``v``, ``omega`` of the last step."""

    pose: np.ndarray
    wheels: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(2))
    v: float = 0.0
    omega: float = 0.0


#: The paper's truck with our assumed drive parameters (the paper gives only the body size).
PAPER_TRUCK = SkidSteerTruck()
