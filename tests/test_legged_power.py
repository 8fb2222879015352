"""Power and endurance (robokit.legged.power) against hand-worked numbers."""
from __future__ import annotations

import math

import numpy as np
import pytest

from robokit.controllers import LITTLEDOG_MOTOR, DCMotor
from robokit.legged import battery_energy, cost_of_transport, endurance, trial_power

# R = 2 ohm, kt = ke = 0.02, N = 50: back-EMF 1 V per rad/s at the joint
MOTOR = DCMotor(resistance=2.0, torque_constant=0.02, back_emf_constant=0.02, gear_ratio=50.0, efficiency=0.8,
                rotor_inertia=1e-6, viscous_friction=0.0, voltage_max=12.0)


def test_battery_and_the_guides_thirty_minutes():
    assert battery_energy() == pytest.approx(2.1 * 3600 * 14.8)          # 111 888 J
    assert battery_energy() / 3600 == pytest.approx(31.08)
    assert battery_energy(1.0, 10.0) == 36_000.0
    assert endurance(battery_energy(), 62.0) / 60 == pytest.approx(30.08, abs=0.01)
    # the average power the guide's "about 30 minutes" implies
    assert battery_energy() / (30 * 60) == pytest.approx(62.16, abs=0.01)


def test_trial_power_clips_each_joint_unless_regenerative():
    # joint 0: 6 V at 2 rad/s -> i = (6 - 2) / 2 = 2 A, 12 W
    # joint 1: 2 V at 4 rad/s -> i = (2 - 4) / 2 = -1 A, -2 W (back-driven: generating)
    # joint 2: -4 V at 0 rad/s -> i = -2 A, +8 W (holding the other way)
    # joint 3: 20 V (saturated to 12 V) at 0 rad/s -> i = 6 A, 72 W
    v = np.array([[6.0, 2.0, -4.0, 20.0], [0.0, 0.0, 0.0, 0.0]])
    w = np.array([[2.0, 4.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])   # row 2, joint 0: back-driven by 1 rad/s at 0 V
    p = trial_power(v, w, MOTOR)
    assert p.shape == (2,)
    assert p[0] == pytest.approx(12 + 0 + 8 + 72)
    assert p[1] == 0.0                                           # 0 V: no power drawn (it brakes, shorted)
    assert trial_power(v, w, MOTOR, regenerative=True)[0] == pytest.approx(12 - 2 + 8 + 72)


def test_trial_power_of_a_standing_robot_and_endurance():
    # every pitch and knee joint holding 0.4 N m, the hip rolls nothing: 8 x R i^2 with i = 0.4 / (eta N kt)
    hold = np.zeros(12)
    hold[[1, 2, 4, 5, 7, 8, 10, 11]] = 1.6                       # voltage_for_torque(0.4, 0) on LittleDog's motor
    n = 100
    p = trial_power(np.tile(hold, (n, 1)), np.zeros((n, 12)), LITTLEDOG_MOTOR)
    i = 0.4 / (0.75 * 80 * 0.0125)
    assert p == pytest.approx(np.full(n, 8 * 3.0 * i ** 2))    # 6.83 W
    assert endurance(battery_energy(), float(p.mean())) / 3600 == pytest.approx(31.08 / (8 * 3.0 * i ** 2))


def test_cost_of_transport_hand_worked():
    assert cost_of_transport(100.0, 3.0, 2.0) == pytest.approx(100 / (3 * 9.81 * 2))    # 1.699
    assert cost_of_transport(0.0, 3.0, 1.0) == 0.0
    assert cost_of_transport(9.81, 1.0, 1.0, g=9.81) == pytest.approx(1.0)


@pytest.mark.parametrize("call, name", [
    (lambda: battery_energy(-1.0), "capacity_ah"), (lambda: battery_energy(2.1, math.nan), "voltage"),
    (lambda: endurance(1.0, 0.0), "mean_power_w"), (lambda: cost_of_transport(1.0, 3.0, 0.0), "distance"),
    (lambda: cost_of_transport(-1.0, 3.0, 1.0), "energy_j"),
    (lambda: trial_power(np.zeros((3, 12)), np.zeros((3, 11)), MOTOR), "joint_velocity"),
    (lambda: trial_power(np.zeros(12), np.zeros(12), MOTOR), "voltage"),
    (lambda: trial_power(np.full((2, 12), np.nan), np.zeros((2, 12)), MOTOR), "voltage")])
def test_bad_input_is_named(call, name):
    with pytest.raises(ValueError, match=name):
        call()
    with pytest.raises(TypeError, match="motor"):
        trial_power(np.zeros((1, 12)), np.zeros((1, 12)), "motor")
