"""LittleDog's joint servo, designed on the model: the inertia each motor sees, and the PD gains.

The servo design of :mod:`robokit.controllers.joint_servo` needs the inertia about the joint. For a
leg joint that is the leg's own links about the axis (from MuJoCo's joint-space mass matrix, the
diagonal entry of the standing posture) plus the motor's rotor reflected through the gearbox, which
at LittleDog's scale is the larger part (:func:`robokit.controllers.reflected_inertia`).

References
----------
.. [1] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015, Secs. 3.3 (second-order response) and 4.3 (PD control).
.. [2] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Sec. 2 (servos at 500 Hz).
"""
from __future__ import annotations

import functools

import mujoco
import numpy as np

from ..controllers import LITTLEDOG_MOTOR, DCMotor, design_servo_gains, reflected_inertia
from ..validation import as_positive
from .leg_kinematics import body_ik
from .littledog import STANCE_FEET, STANDING_HEIGHT, littledog_model

__all__ = ["link_inertias", "servo_inertia", "littledog_servo_gains", "SERVO_BANDWIDTH"]

SERVO_BANDWIDTH = 15.0
"""Closed-loop bandwidth the servo is designed for (Hz); ours, well below the 250 Hz Nyquist rate of
the guide's 500 Hz servo."""


@functools.lru_cache(maxsize=1)
def _link_inertias() -> tuple:
    model = littledog_model()
    data = mujoco.MjData(model)
    data.qpos[:7] = [0, 0, STANDING_HEIGHT, 1, 0, 0, 0]
    data.qpos[7:] = body_ik(STANCE_FEET).q[0]
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    return tuple(np.diag(full)[6:])


def link_inertias() -> np.ndarray:
    """The legs' own inertia about each of the twelve joints in the standing posture (kg m^2).

    The diagonal of MuJoCo's joint-space mass matrix (``mj_fullM``) without motors: what a joint
    would feel if every other joint were locked.

    Returns
    -------
    numpy.ndarray, shape (12,)

    Examples
    --------
    >>> I = link_inertias()
    >>> bool(I[0] > I[2]), bool(np.allclose(I[:3], I[3:6]))     # roll swings the whole leg; legs alike
    (True, True)
    """
    return np.array(_link_inertias())


def servo_inertia(motor: DCMotor = LITTLEDOG_MOTOR) -> float:
    """The inertia the servo is designed for: the largest link inertia plus the reflected rotor (kg m^2).

    Examples
    --------
    >>> round(servo_inertia() - float(link_inertias().max()), 9) == round(reflected_inertia(LITTLEDOG_MOTOR), 9)
    True
    """
    if not isinstance(motor, DCMotor):
        raise TypeError(f"motor: expected a DCMotor, got {type(motor).__name__}")
    return float(link_inertias().max()) + reflected_inertia(motor)


def littledog_servo_gains(bandwidth_hz: float = SERVO_BANDWIDTH, motor: DCMotor = LITTLEDOG_MOTOR) -> tuple:
    """PD gains ``(kp, kd)`` (V/rad, V s/rad) of LittleDog's joint servo for a closed-loop bandwidth.

    Parameters
    ----------
    bandwidth_hz : float, default :data:`SERVO_BANDWIDTH`
    motor : DCMotor

    Returns
    -------
    tuple of float

    Examples
    --------
    >>> kp, kd = littledog_servo_gains()
    >>> kp > 0 and kd > 0
    True
    """
    bandwidth_hz = as_positive(bandwidth_hz, "bandwidth_hz")
    kp, kd = design_servo_gains(motor, servo_inertia(motor), bandwidth_hz)
    return float(kp), float(kd)
