"""A brushed DC motor behind a gearbox, one per joint: torque, current and power from voltage and speed.

The armature-controlled DC motor of Franklin, Powell & Emami-Naeini (2015), Sec. 2.3: the current
``i`` through the winding resistance ``R`` is driven by the applied voltage less the back-EMF,
``R i = V - k_e omega_m``, and the motor torque is ``tau_m = k_t i``. A gearbox of ratio ``N`` and
efficiency ``eta`` links motor and joint: ``omega_m = N dq/dt`` and the joint torque is
``eta N k_t i`` less the joint's viscous friction ``b dq/dt``. So, for a joint,

    tau = eta N k_t (V - k_e N dq/dt) / R - b dq/dt = K V - B dq/dt,
    K = eta N k_t / R,   B = eta N^2 k_t k_e / R + b,

and a joint of inertia ``J`` (link plus the rotor's reflected inertia ``N^2 J_rotor``) obeys
``J q'' + B q' = K V``: ``q / V = K / (s (J s + B))`` (:mod:`robokit.controllers.joint_servo`).

The winding inductance ``L`` is neglected: its electrical time constant ``L / R`` (tens of
microseconds for a small coreless motor, whose inductance is a fraction of a millihenry) is far
below the servo's 2 ms period, so the current follows the voltage within one tick. The efficiency
is one constant in both directions of power flow (a back-driven gearbox loses more; a refinement
left out). With ``k_t = k_e`` (true of any DC motor in SI units) the electrical power ``V i`` splits
exactly into copper loss ``R i^2`` and the mechanical power ``k_e omega_m i`` at the shaft.

The LittleDog User Guide gives no motor data, so :data:`LITTLEDOG_MOTOR` holds assumed values, of
the order of a 22 mm coreless precious-metal-brush DC motor with a planetary gearhead (the class of
the maxon RE-max or Faulhaber 2224 SR families), chosen so that a knee or hip-pitch joint holding
its share of the 3 kg robot (0.3-0.6 N m) draws well under the continuous current and the joint's
no-load speed is about 15 rad/s.

References
----------
.. [1] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015.
.. [2] Boston Dynamics, *LittleDog User Guide*, v1.0.2, 2006.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any, NamedTuple

import numpy as np

from ..validation import as_array, require_finite_result, as_positive

__all__ = ["DCMotor", "LITTLEDOG_MOTOR", "MotorPower", "joint_torque", "motor_current", "voltage_for_torque",
           "electrical_power", "reflected_inertia"]


@dataclasses.dataclass(frozen=True)
class DCMotor:
    """A brushed DC motor with a gearbox, as seen from the joint (SI units).

    Parameters
    ----------
    resistance : float
        Winding resistance ``R`` (ohm, > 0).
    torque_constant : float
        ``k_t`` (N m / A, > 0), motor side.
    back_emf_constant : float
        ``k_e`` (V s / rad, > 0), motor side; equal to ``k_t`` in SI units for an ideal motor.
    gear_ratio : float
        ``N`` = motor speed / joint speed (> 0).
    efficiency : float
        Gearbox efficiency ``eta`` in (0, 1].
    rotor_inertia : float
        Rotor inertia (kg m^2, >= 0), motor side.
    viscous_friction : float
        ``b`` (N m s / rad, >= 0), at the joint.
    voltage_max : float, default 14.8
        The driver's saturation (V, > 0): the battery voltage (LittleDog User Guide, Sec. 3.ii).
    continuous_current : float, default inf
        The motor's rated continuous current (A, > 0; ``inf`` when unknown), for thermal checks.

    Raises
    ------
    ValueError, TypeError
        A parameter that is not a finite number in its range (the message names it).

    Notes
    -----
    Franklin et al. (2015), Sec. 2.3. The joint-side constants of the module docstring are the
    properties :attr:`torque_per_volt` (``K``), :attr:`damping` (``B``), :attr:`no_load_speed` and
    :attr:`stall_torque`.

    Examples
    --------
    >>> m = DCMotor(2.0, 0.01, 0.01, 100.0, 0.8, 1e-7, 0.0)
    >>> round(m.torque_per_volt, 6), round(m.damping, 6), round(m.no_load_speed, 3)
    (0.4, 0.4, 14.8)
    """

    resistance: float
    torque_constant: float
    back_emf_constant: float
    gear_ratio: float
    efficiency: float
    rotor_inertia: float
    viscous_friction: float
    voltage_max: float = 14.8
    continuous_current: float = math.inf

    def __post_init__(self) -> None:
        for name in ("resistance", "torque_constant", "back_emf_constant", "gear_ratio", "voltage_max"):
            object.__setattr__(self, name, as_positive(getattr(self, name), name))
        for name in ("rotor_inertia", "viscous_friction"):
            object.__setattr__(self, name, as_positive(getattr(self, name), name, allow_zero=True))
        eta = as_positive(self.efficiency, "efficiency")
        if eta > 1:
            raise ValueError(f"efficiency: expected a fraction in (0, 1], got {eta}")
        object.__setattr__(self, "efficiency", eta)
        current = self.continuous_current
        if not (isinstance(current, float) and current == math.inf):
            current = as_positive(current, "continuous_current")
        object.__setattr__(self, "continuous_current", float(current))

    @property
    def torque_per_volt(self) -> float:
        """``K = eta N k_t / R`` (N m / V): the joint's stall torque per volt (Sec. 2.3)."""
        return self.efficiency * self.gear_ratio * self.torque_constant / self.resistance

    @property
    def damping(self) -> float:
        """``B = eta N^2 k_t k_e / R + b`` (N m s / rad): back-EMF plus viscous damping at the joint."""
        return (self.efficiency * self.gear_ratio ** 2 * self.torque_constant * self.back_emf_constant
                / self.resistance + self.viscous_friction)

    @property
    def no_load_speed(self) -> float:
        """Joint speed (rad/s) at ``voltage_max`` with no load: ``K V_max / B``."""
        return self.torque_per_volt * self.voltage_max / self.damping

    @property
    def stall_torque(self) -> float:
        """Joint torque (N m) at ``voltage_max`` and zero speed: ``K V_max``."""
        return self.torque_per_volt * self.voltage_max


#: LittleDog's joint motor: ASSUMED values (the guide gives none), of the order of a 22 mm coreless
#: motor with a three-stage planetary gearhead. K = 0.25 N m/V, B = 0.255 N m s/rad, no-load speed
#: 14.5 rad/s, stall torque 3.7 N m, reflected inertia 2.56e-3 kg m^2; holding 0.4 N m takes
#: 0.53 A (0.85 W of copper loss), under half the continuous 1.2 A.
LITTLEDOG_MOTOR = DCMotor(resistance=3.0, torque_constant=0.0125, back_emf_constant=0.0125, gear_ratio=80.0,
                          efficiency=0.75, rotor_inertia=4.0e-7, viscous_friction=0.005, voltage_max=14.8,
                          continuous_current=1.2)


class MotorPower(NamedTuple):
    """Electrical power drawn by each motor (W), split where it goes.

    Examples
    --------
    >>> MotorPower(1.0, 2.0, 3.0).total
    3.0
    """

    copper: float | np.ndarray      #: ``R i^2``, heat in the winding (>= 0)
    mechanical: float | np.ndarray  #: ``k_e omega_m i``, to the shaft (negative when the joint drives the motor)
    total: float | np.ndarray       #: ``V i`` = copper + mechanical, drawn from the supply


def _inputs(voltage: Any, joint_velocity: Any, motor: Any, validate: bool,
            first: str = "voltage") -> tuple[np.ndarray, np.ndarray]:
    """Validated, broadcast (first, joint_velocity) arrays; as given on the fast path."""
    if not validate:
        return voltage, joint_velocity
    if not isinstance(motor, DCMotor):
        raise TypeError(f"motor: expected a DCMotor, got {type(motor).__name__}")
    a = as_array(voltage, first)
    w = as_array(joint_velocity, "joint_velocity")
    try:
        np.broadcast_shapes(a.shape, w.shape)
    except ValueError:
        raise ValueError(f"{first}, joint_velocity: expected shapes that broadcast (one value per joint), "
                         f"got {a.shape} and {w.shape}") from None
    return a, w


def _out(x: np.ndarray) -> float | np.ndarray:
    return float(x) if np.ndim(x) == 0 else x


def motor_current(voltage: Any, joint_velocity: Any, motor: DCMotor, *, validate: bool = True) -> float | np.ndarray:
    """Winding current (A): ``i = (V - k_e N dq/dt) / R``, with ``V`` saturated at ``+-voltage_max``.

    Parameters
    ----------
    voltage : float or array_like
        Commanded voltage per joint (V); the driver clips it to ``+-motor.voltage_max``.
    joint_velocity : float or array_like
        Joint speed (rad/s), broadcast against ``voltage``.
    motor : DCMotor
    validate : bool, default True
        Validate the inputs; ``False`` is the simulation's fast path (finite arrays of matching shapes).

    Returns
    -------
    float or numpy.ndarray

    Notes
    -----
    Armature circuit of Franklin et al. (2015), Sec. 2.3, with the inductance neglected (module
    docstring); motor speed ``omega_m = N dq/dt``.

    Examples
    --------
    >>> round(motor_current(14.8, 0.0, LITTLEDOG_MOTOR), 4)           # stall
    4.9333
    >>> round(motor_current(20.0, 0.0, LITTLEDOG_MOTOR), 4)           # saturated at 14.8 V
    4.9333
    """
    v, w = _inputs(voltage, joint_velocity, motor, validate)
    vm = motor.voltage_max
    v = np.clip(v, -vm, vm)
    omega_m = motor.gear_ratio * w                                      # gearbox: omega_m = N dq/dt
    return _out((v - motor.back_emf_constant * omega_m) / motor.resistance)     # Sec. 2.3: R i = V - k_e omega_m


def joint_torque(voltage: Any, joint_velocity: Any, motor: DCMotor) -> float | np.ndarray:
    """Torque at the joint (N m): ``eta N k_t i - b dq/dt``, with ``V`` saturated at ``+-voltage_max``.

    Parameters
    ----------
    voltage, joint_velocity, motor
        As in :func:`motor_current`.

    Returns
    -------
    float or numpy.ndarray
        ``K V - B dq/dt`` before saturation (:attr:`DCMotor.torque_per_volt`, :attr:`DCMotor.damping`).

    Notes
    -----
    Motor torque ``k_t i`` (Franklin et al. 2015, Sec. 2.3) through a gearbox of ratio ``N`` and
    efficiency ``eta``, less the joint's viscous friction.

    Examples
    --------
    >>> round(joint_torque(14.8, 0.0, LITTLEDOG_MOTOR), 3)              # stall torque
    3.7
    >>> np.round(joint_torque([2.0, -2.0], [1.0, 0.0], LITTLEDOG_MOTOR), 4).tolist()
    [0.245, -0.5]
    """
    v, w = _inputs(voltage, joint_velocity, motor, True)
    i = motor_current(v, w, motor, validate=False)
    tau = motor.efficiency * motor.gear_ratio * motor.torque_constant * np.asarray(i)    # Sec. 2.3: tau_m = k_t i
    return _out(tau - motor.viscous_friction * w)


def voltage_for_torque(torque: Any, joint_velocity: Any, motor: DCMotor) -> float | np.ndarray:
    """Voltage that gives ``torque`` at ``joint_velocity``: the exact inverse of :func:`joint_torque` before saturation.

    Parameters
    ----------
    torque : float or array_like
        Wanted joint torque (N m).
    joint_velocity, motor
        As in :func:`motor_current`.

    Returns
    -------
    float or numpy.ndarray
        ``V = (tau + b dq/dt) R / (eta N k_t) + k_e N dq/dt`` (V), NOT clipped: a magnitude above
        ``motor.voltage_max`` says the torque is out of reach at that speed.

    Notes
    -----
    Franklin et al. (2015), Sec. 2.3, solved for the voltage.

    Examples
    --------
    >>> round(voltage_for_torque(0.4, 0.0, LITTLEDOG_MOTOR), 4)      # holding a quarter of the robot
    1.6
    >>> v = voltage_for_torque(0.245, 1.0, LITTLEDOG_MOTOR)
    >>> round(v, 6), round(joint_torque(v, 1.0, LITTLEDOG_MOTOR), 6)
    (2.0, 0.245)
    """
    tau, w = _inputs(torque, joint_velocity, motor, True, first="torque")
    n = motor.gear_ratio
    current = (tau + motor.viscous_friction * w) / (motor.efficiency * n * motor.torque_constant)
    return _out(current * motor.resistance + motor.back_emf_constant * n * w)     # Sec. 2.3: V = R i + k_e omega_m


def electrical_power(voltage: Any, joint_velocity: Any, motor: DCMotor) -> MotorPower:
    """Electrical power per motor (W): copper loss, mechanical (shaft) power and their sum ``V i``.

    Parameters
    ----------
    voltage, joint_velocity, motor
        As in :func:`motor_current` (the voltage saturated at ``+-voltage_max``).

    Returns
    -------
    MotorPower
        ``copper = R i^2``, ``mechanical = k_e omega_m i`` and ``total = copper + mechanical = V i``,
        each a float or an array like the broadcast inputs. ``total`` is negative when the motor
        generates (a joint braking a load); whether that returns to the battery is
        :func:`robokit.legged.power.trial_power`'s choice.

    Notes
    -----
    Power balance of the armature circuit (Franklin et al. 2015, Sec. 2.3): ``V i = R i^2 + k_e
    omega_m i``; with ``k_t = k_e`` the mechanical term is the shaft torque times speed ``k_t i
    omega_m``, the gearbox's input.

    Examples
    --------
    >>> p = electrical_power(1.6, 0.0, LITTLEDOG_MOTOR)           # holding 0.4 N m: all heat
    >>> round(p.copper, 4), round(p.mechanical, 4), round(p.total, 4)
    (0.8533, 0.0, 0.8533)
    >>> p = electrical_power(10.0, 5.0, LITTLEDOG_MOTOR)
    >>> round(p.copper, 4), round(p.mechanical, 4), round(p.total, 4)
    (8.3333, 8.3333, 16.6667)
    """
    v, w = _inputs(voltage, joint_velocity, motor, True)
    i = np.asarray(motor_current(v, w, motor, validate=False))
    v = np.clip(v, -motor.voltage_max, motor.voltage_max)
    shape = np.shape(i)
    with np.errstate(over="ignore", invalid="ignore"):
        copper = motor.resistance * i ** 2                                          # Joule loss R i^2
        mechanical = motor.back_emf_constant * motor.gear_ratio * np.asarray(w) * i     # k_e omega_m i
        total = np.asarray(v) * i                                                   # V i = R i^2 + k_e omega_m i
    require_finite_result("voltage, joint_velocity", copper, mechanical)
    return MotorPower(_out(copper), _out(np.broadcast_to(mechanical, shape)), _out(np.broadcast_to(total, shape)))


def reflected_inertia(motor: DCMotor) -> float:
    """Rotor inertia seen at the joint, ``N^2 J_rotor`` (kg m^2): MuJoCo's joint ``armature``.

    Notes
    -----
    Kinetic energy ``J_rotor omega_m^2 / 2 = (N^2 J_rotor) (dq/dt)^2 / 2`` (Franklin et al. 2015,
    Sec. 2.3, gear trains); gearbox inertia neglected.

    Examples
    --------
    >>> round(reflected_inertia(LITTLEDOG_MOTOR), 8)
    0.00256
    """
    if not isinstance(motor, DCMotor):
        raise TypeError(f"motor: expected a DCMotor, got {type(motor).__name__}")
    return motor.rotor_inertia * motor.gear_ratio ** 2
