"""Power and endurance of a walking robot: the motors' electrical power, the battery, the cost of transport.

LittleDog carries a 2.1 Ah lithium-polymer battery at 14.8 V (LittleDog User Guide, Sec. 3.ii),
"approximately 30 minutes" of operation (Sec. 1): 31.08 Wh, so about 62 W on average. The twelve joint motors draw
``V i`` each (:func:`robokit.controllers.dc_motor.electrical_power`: copper loss plus mechanical
power); a joint that brakes a load (negative power) returns energy to the supply only if the drivers
regenerate, and a simple H-bridge driver does not, so by default a joint's negative power is lost
(clipped to zero per joint, not netted against the others). The cost of transport ``E / (m g d)``
(Gabrielli & von Karman 1950) makes a gait's energy comparable across sizes and speeds.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, v1.0.2, 2006.
.. [2] G. Gabrielli and T. von Karman, "What price speed? Specific power required for propulsion
   of vehicles", *Mechanical Engineering* 72(10), 775-781, 1950.
.. [3] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..controllers.dc_motor import DCMotor, electrical_power
from .littledog import GUIDE
from ..validation import as_array, require_finite_result, as_positive

__all__ = ["battery_energy", "trial_power", "endurance", "cost_of_transport"]


def battery_energy(capacity_ah: float = GUIDE["battery_capacity"], voltage: float = GUIDE["battery_voltage"]) -> float:
    """Energy stored in a battery (J): ``capacity (A h) x 3600 s/h x voltage``.

    Parameters
    ----------
    capacity_ah : float, default 2.1
        Capacity (A h, > 0): LittleDog's pack (LittleDog User Guide, Sec. 3.ii).
    voltage : float, default 14.8
        Nominal voltage (V, > 0): four lithium-polymer cells.

    Returns
    -------
    float
        The defaults give 111 888 J = 31.08 Wh.

    Notes
    -----
    Nominal energy; the usable share is smaller (cut-off voltage, ageing, cold).

    Examples
    --------
    >>> battery_energy(), round(battery_energy() / 3600, 2)     # J, Wh
    (111888.0, 31.08)
    """
    ah = as_positive(capacity_ah, "capacity_ah")
    v = as_positive(voltage, "voltage")
    energy = ah * 3600.0 * v                                   # 1 A h = 3600 C; E = Q V
    require_finite_result("capacity_ah, voltage", energy)
    return energy


def trial_power(voltage: Any, joint_velocity: Any, motor: DCMotor, regenerative: bool = False) -> np.ndarray:
    """Total electrical power of all motors at each sample (W), from logged voltages and joint speeds.

    Parameters
    ----------
    voltage : array_like, shape (N, M)
        Voltage per sample and joint (V), e.g. ``M = 12`` joints; saturated at ``motor.voltage_max``.
    joint_velocity : array_like, shape (N, M)
        Joint speeds (rad/s).
    motor : DCMotor
        The motor of every joint.
    regenerative : bool, default False
        Whether braking joints return energy to the battery. ``False``: each joint's negative power
        is lost (clipped to 0 per joint before the sum), as with drivers that cannot regenerate.

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``sum_j max(V_j i_j, 0)`` (or ``sum_j V_j i_j`` with regeneration).

    Notes
    -----
    ``V i = R i^2 + k_e omega_m i`` per motor (Franklin et al. 2015, Sec. 2.3;
    :func:`robokit.controllers.dc_motor.electrical_power`).

    Examples
    --------
    >>> from robokit.controllers.dc_motor import LITTLEDOG_MOTOR
    >>> v = [[1.6, 10.0, 2.0]]              # hold 0.4 N m; drive at 5 rad/s; back-driven at 5 rad/s
    >>> w = [[0.0, 5.0, 5.0]]
    >>> np.round(trial_power(v, w, LITTLEDOG_MOTOR), 4).tolist()
    [17.52]
    >>> np.round(trial_power(v, w, LITTLEDOG_MOTOR, regenerative=True), 4).tolist()
    [15.52]
    """
    if not isinstance(motor, DCMotor):
        raise TypeError(f"motor: expected a DCMotor, got {type(motor).__name__}")
    v = as_array(voltage, "voltage", ndim=2)
    w = as_array(joint_velocity, "joint_velocity", ndim=2)
    if w.shape != v.shape:
        raise ValueError(f"joint_velocity: expected the shape of voltage {v.shape}, got {w.shape}")
    p = electrical_power(v, w, motor).total                     # V i per joint
    if not regenerative:
        p = np.maximum(p, 0.0)                                  # a braking joint's power is lost
    return p.sum(axis=1)


def endurance(energy_j: float, mean_power_w: float) -> float:
    """Running time (s) of a battery of ``energy_j`` at an average draw of ``mean_power_w``.

    Examples
    --------
    >>> round(endurance(battery_energy(), 62.0) / 60, 1)     # the guide's "about 30 minutes"
    30.1
    """
    e = as_positive(energy_j, "energy_j")
    p = as_positive(mean_power_w, "mean_power_w")
    t = e / p                                                   # t = E / P
    require_finite_result("energy_j, mean_power_w", t)
    return t


def cost_of_transport(energy_j: float, mass: float, distance: float, g: float = 9.81) -> float:
    """Dimensionless cost of transport ``E / (m g d)``: energy per weight per distance travelled.

    Parameters
    ----------
    energy_j : float
        Energy spent (J, >= 0).
    mass : float
        Mass moved (kg, > 0): 3.0 for LittleDog.
    distance : float
        Distance travelled (m, > 0).
    g : float, default 9.81
        Gravity (m/s^2, > 0).

    Notes
    -----
    Gabrielli & von Karman (1950), their specific resistance ``P / (W v)``, integrated over a trip.

    Examples
    --------
    >>> round(cost_of_transport(62.0 * 10.0, 3.0, 1.0), 2)     # 62 W for 10 s to walk 1 m
    21.07
    """
    e = as_positive(energy_j, "energy_j", allow_zero=True)
    m = as_positive(mass, "mass")
    d = as_positive(distance, "distance")
    gravity = as_positive(g, "g")
    cot = e / (m * gravity * d)                                 # COT = E / (m g d)
    require_finite_result("energy_j, mass, distance, g", cot)
    return cot
