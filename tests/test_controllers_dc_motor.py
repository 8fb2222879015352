"""The geared DC motor of robokit.controllers.dc_motor: hand-worked numbers, its inverse, the power balance,
the neglected inductance checked against a simulation that keeps it, and LittleDog's assumed motor."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from robokit.controllers import (LITTLEDOG_MOTOR, DCMotor, electrical_power, joint_torque, motor_current,
                                 reflected_inertia, voltage_for_torque)

MOTOR = DCMotor(resistance=2.0, torque_constant=0.02, back_emf_constant=0.02, gear_ratio=50.0, efficiency=0.8,
                rotor_inertia=1e-6, viscous_friction=0.01, voltage_max=12.0)


def test_hand_worked_torque_current_and_power():
    # V = 6 V at 2 rad/s: omega_m = 100 rad/s, back-EMF 2 V, i = (6 - 2) / 2 = 2 A,
    # tau = 0.8 * 50 * 0.02 * 2 - 0.01 * 2 = 1.6 - 0.02 = 1.58 N m
    assert motor_current(6.0, 2.0, MOTOR) == pytest.approx(2.0)
    assert joint_torque(6.0, 2.0, MOTOR) == pytest.approx(1.58)
    p = electrical_power(6.0, 2.0, MOTOR)
    assert (p.copper, p.mechanical, p.total) == pytest.approx((8.0, 4.0, 12.0))    # 2^2 * 2, 2 V * 2 A, 6 V * 2 A
    # K = eta N kt / R = 0.4 N m/V, B = eta N^2 kt ke / R + b = 0.4 + 0.01
    assert MOTOR.torque_per_volt == pytest.approx(0.4) and MOTOR.damping == pytest.approx(0.41)
    assert MOTOR.stall_torque == pytest.approx(4.8) and MOTOR.no_load_speed == pytest.approx(4.8 / 0.41)
    assert reflected_inertia(MOTOR) == pytest.approx(2500e-6)


def test_the_driver_saturates_the_voltage():
    assert joint_torque(100.0, 0.0, MOTOR) == pytest.approx(joint_torque(12.0, 0.0, MOTOR))
    assert motor_current(-100.0, 0.0, MOTOR) == pytest.approx(-6.0)
    assert electrical_power(100.0, 0.0, MOTOR).total == pytest.approx(12.0 * 6.0)


def test_voltage_for_torque_inverts_joint_torque_vectorised():
    rng = np.random.default_rng(0)
    w = rng.uniform(-5, 5, (50, 12))
    tau = rng.uniform(-0.5, 0.5, (50, 12))
    v = voltage_for_torque(tau, w, LITTLEDOG_MOTOR)
    assert v.shape == (50, 12)
    inside = np.abs(v) <= LITTLEDOG_MOTOR.voltage_max
    assert inside.mean() > 0.5
    np.testing.assert_allclose(joint_torque(v, w, LITTLEDOG_MOTOR)[inside], tau[inside], rtol=0, atol=1e-12)
    # elementwise equal to scalar calls (vectorisation)
    assert joint_torque(v[3, 4], w[3, 4], LITTLEDOG_MOTOR) == pytest.approx(joint_torque(v, w, LITTLEDOG_MOTOR)[3, 4])


def test_power_balance_and_gearbox_output():
    rng = np.random.default_rng(1)
    v = rng.uniform(-14.8, 14.8, 200)
    w = rng.uniform(-10, 10, 200)
    p = electrical_power(v, w, LITTLEDOG_MOTOR)
    i = motor_current(v, w, LITTLEDOG_MOTOR)
    np.testing.assert_allclose(p.copper + p.mechanical, p.total, atol=1e-12)
    np.testing.assert_allclose(p.total, v * i, atol=1e-12)
    assert np.all(p.copper >= 0)
    # at the joint: tau dq/dt = eta * (shaft power) - b dq^2 (kt = ke; constant efficiency)
    m = LITTLEDOG_MOTOR
    np.testing.assert_allclose(joint_torque(v, w, m) * w, m.efficiency * p.mechanical - m.viscous_friction * w ** 2,
                               atol=1e-12)


def test_neglecting_the_inductance_is_right_at_the_servo_rate():
    # keep the inductance (0.2 mH, a small coreless motor's order): L di/dt = V - R i - ke omega_m.
    # After a voltage step the current reaches the resistive model's value long before the 2 ms tick ends.
    L, m, w = 2e-4, LITTLEDOG_MOTOR, 3.0
    sol = solve_ivp(lambda t, i: [(8.0 - m.resistance * i[0] - m.back_emf_constant * m.gear_ratio * w) / L],
                    (0, 0.002), [0.0], rtol=1e-10, atol=1e-12, dense_output=True)
    assert L / m.resistance < 0.002 / 20
    assert sol.sol(0.002)[0] == pytest.approx(motor_current(8.0, w, m), rel=1e-9)
    assert sol.sol(0.0005)[0] == pytest.approx(motor_current(8.0, w, m), rel=1e-3)


def test_littledog_motor_is_sized_for_the_robot():
    m = LITTLEDOG_MOTOR
    quarter_weight = 3.0 / 4 * 9.81
    # a knee or hip pitch holds a quarter of the robot at a lever of 4-8 cm: 0.3-0.6 N m
    for lever in (0.04, 0.08):
        tau = quarter_weight * lever
        assert 0.29 < tau < 0.6
        current = motor_current(voltage_for_torque(tau, 0.0, m), 0.0, m)
        assert current < 0.7 * m.continuous_current
    assert motor_current(voltage_for_torque(0.4, 0.0, m), 0.0, m) < 0.5 * m.continuous_current
    assert 10.0 < m.no_load_speed < 20.0
    assert m.stall_torque > 5 * 0.6           # headroom to accelerate the leg and catch a fall


@pytest.mark.parametrize("field, value, exc", [("resistance", 0.0, ValueError), ("efficiency", 1.2, ValueError),
                                              ("gear_ratio", math.nan, ValueError), ("rotor_inertia", -1.0, ValueError),
                                              ("continuous_current", -math.inf, ValueError),
                                              ("voltage_max", "14.8", TypeError)])
def test_motor_validates_its_parameters(field, value, exc):
    args = dict(resistance=2.0, torque_constant=0.02, back_emf_constant=0.02, gear_ratio=50.0, efficiency=0.8,
                rotor_inertia=1e-6, viscous_friction=0.0)
    args[field] = value
    with pytest.raises(exc, match=field):
        DCMotor(**args)


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="voltage"):
        joint_torque([1.0, math.nan], 0.0, MOTOR)
    with pytest.raises(ValueError, match="voltage, joint_velocity"):
        motor_current(np.zeros(12), np.zeros(3), MOTOR)
    with pytest.raises(ValueError, match="torque"):
        voltage_for_torque(math.inf, 0.0, MOTOR)
    with pytest.raises(TypeError, match="motor"):
        electrical_power(1.0, 0.0, "motor")
    with pytest.raises(TypeError, match="motor"):
        reflected_inertia(None)
