"""The skid-steer RC truck of Hamid et al.: body, four driven wheels, slip, and motor lag.

Hamid et al. (2009) use a 50 x 25 x 15 cm RC truck whose four wheels are driven
independently, so it steers by driving its left and right sides at different speeds and can turn on
the spot. Its kinematics are the skid-steer model of :mod:`robokit.sim.vehicle`: the ICR
kinematics of Mandow et al. (2007, Sec. III), a differential-drive form with an effective track
``icr_factor * B`` (``icr_factor > 1``, the expansion of the instantaneous centres of rotation),
and our longitudinal slip ratio ``s`` that scales the wheel speeds (not part of their model).
Each side's motor follows its speed command with a first-order lag ``tau``.

Pose ``[x, y, theta]``: field frame x east, y north, ``theta`` counter-clockwise from east.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] A. Mandow, J. L. Martinez, J. Morales, J. L. Blanco, A. Garcia-Cerezo and J. Gonzalez,
   "Experimental kinematics for wheeled skid-steer mobile robots", IEEE/RSJ International
   Conference on Intelligent Robots and Systems (IROS), 2007, pp. 1222-1227.
.. [3] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..sim.vehicle import skid_steer_velocities, skid_steer_wheel_speeds, unicycle_step
from ..validation import as_array, as_finite_scalar, as_positive

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
        ICR expansion factor (in [1, 5]) from side skidding; 1 is an ideal differential drive.
    slip : float
        Longitudinal slip ratio in [0, 0.5): ground speed = (1 - slip) * wheel speed.

    Raises
    ------
    TypeError, ValueError
        For a size, speed or time constant that is not a positive number, ``icr_factor`` outside
        [1, 5] or ``slip`` outside [0, 0.5).
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
            as_positive(getattr(self, name), name)
        if not 1.0 <= as_finite_scalar(self.icr_factor, "icr_factor") <= 5.0:
            raise ValueError(f"icr_factor: expected a number in [1, 5], got {self.icr_factor!r}")
        if not 0.0 <= as_finite_scalar(self.slip, "slip") < 0.5:
            raise ValueError(f"slip: expected a ratio in [0, 0.5), got {self.slip!r}")

    @property
    def max_turn_rate(self) -> float:
        """Yaw rate (rad/s) when the two sides run at full speed in opposite directions."""
        return self.body_velocity([-self.max_wheel_speed, self.max_wheel_speed])[1]

    def body_velocity(self, wheel_speeds: Any) -> tuple[float, float]:
        """Forward speed ``v`` (m/s) and yaw rate ``omega`` (rad/s) from ``[left, right]`` wheel speeds.

        Notes
        -----
        :func:`robokit.sim.vehicle.skid_steer_velocities` with this truck's track, ICR expansion
        factor and slip (Mandow et al. 2007, Sec. III; the slip factor is ours).

        Examples
        --------
        >>> v, omega = PAPER_TRUCK.body_velocity([0.3, 0.5])
        >>> round(float(v), 3), round(float(omega), 3)
        (0.38, 0.603)
        """
        wl, wr = as_array(wheel_speeds, "wheel_speeds", shape=(2,))
        return skid_steer_velocities(wl, wr, self.track, self.icr_factor, self.slip, validate=False)

    def wheel_commands(self, v: float, omega: float, *, validate: bool = True) -> np.ndarray:
        """``[left, right]`` wheel speeds that give ``v`` and ``omega`` under this model, saturated.

        When a side would exceed ``max_wheel_speed`` the forward speed is reduced first, so the turn
        (what keeps the truck off obstacles) is kept.

        Parameters
        ----------
        v, omega : float or array_like
            Wanted forward speed (m/s) and yaw rate (rad/s); arrays give ``(..., 2)`` speeds.
        validate : bool, default True
            Validate ``v`` and ``omega``; ``False`` is the fast path for a control loop whose
            navigator computed them (:func:`robokit.outdoor.simulate`).

        Raises
        ------
        TypeError, ValueError
            For a ``v`` or ``omega`` that is not a number (or numeric array), or is NaN or infinite.

        Notes
        -----
        :func:`robokit.sim.vehicle.skid_steer_wheel_speeds` (Mandow et al. 2007, Sec. III, inverted).

        Examples
        --------
        >>> np.round(PAPER_TRUCK.wheel_commands(0.5, 0.0), 3).tolist()
        [0.526, 0.526]
        """
        if validate:
            v, omega = as_array(v, "v"), as_array(omega, "omega")
        return skid_steer_wheel_speeds(v, omega, self.track, self.max_wheel_speed, self.icr_factor, self.slip,
                                       validate=False)

    def step(self, state: "TruckState", command: Any, dt: float, *, validate: bool = True) -> "TruckState":
        """Advance ``dt`` seconds with ``command = [left, right]`` wheel-speed set points.

        The motors respond with an exact first-order lag; the pose moves along the arc of constant
        ``v`` and ``omega`` (those of the mean wheel speed over the step).

        Parameters
        ----------
        state : TruckState
        command : array_like, shape (2,)
            Wheel-speed set points (m/s), clipped to ``max_wheel_speed``.
        dt : float
            Step (s, > 0).
        validate : bool, default True
            Validate the inputs; ``False`` is the fast path for a simulation loop whose states come
            from this method and whose commands come from :meth:`wheel_commands`.

        Raises
        ------
        TypeError, ValueError
            For a ``state`` that is not a :class:`TruckState` with a finite pose ``(3,)`` and wheel
            speeds ``(2,)``, a bad ``command`` or a non-positive ``dt``.

        Notes
        -----
        First-order lag ``w1 = w0 + (cmd - w0)(1 - exp(-dt / tau))`` (exact for a constant command);
        arc integration of Thrun, Burgard & Fox (2005), Eq. (5.9) (:func:`robokit.sim.vehicle.unicycle_step`)
        with the skid-steer velocities of Mandow et al. (2007), Sec. III.

        Examples
        --------
        >>> s = PAPER_TRUCK.step(TruckState(np.zeros(3)), [0.5, 0.5], 1.0)
        >>> np.round(s.pose, 3).tolist(), np.round(s.wheels, 3).tolist()
        ([0.229, 0.0, 0.0], [0.482, 0.482])
        """
        if validate:
            if not isinstance(state, TruckState):
                raise TypeError(f"state: expected a TruckState, got {type(state).__name__}")
            pose, w0 = as_array(state.pose, "state.pose", shape=(3,)), as_array(state.wheels, "state.wheels", shape=(2,))
            command, dt = as_array(command, "command", shape=(2,)), as_positive(dt, "dt")
        else:
            pose, w0 = state.pose, state.wheels
        cmd = np.clip(command, -self.max_wheel_speed, self.max_wheel_speed)
        a = 1 - np.exp(-dt / self.motor_tau)
        w1 = w0 + (cmd - w0) * a                                    # exact first-order lag
        v, om = skid_steer_velocities(*((w0 + w1) / 2), self.track, self.icr_factor, self.slip, validate=False)
        return TruckState(unicycle_step(pose, v, om, dt, validate=False), w1, v, om)


@dataclasses.dataclass(frozen=True, eq=False)
class TruckState:
    """Pose ``[x, y, theta]``, wheel speeds ``[left, right]`` and the body ``v``, ``omega`` of the last step.

    A plain record: :meth:`SkidSteerTruck.step` checks the state it is given.
    """

    pose: np.ndarray
    wheels: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(2))
    v: float = 0.0
    omega: float = 0.0


#: The paper's truck with our assumed drive parameters (the paper gives only the body size).
PAPER_TRUCK = SkidSteerTruck()
