"""LittleDog's joint servo (robokit.controllers.joint_servo on servo_loop): the plant against the motor's ODE,
the design against python-control's bandwidth, our discrete simulation against python-control's discrete
closed loop, an unstable gain reported, and the same gains at 500 Hz and 100 Hz."""
from __future__ import annotations

import math

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from robokit.controllers import (LITTLEDOG_MOTOR, design_servo_gains, discrete_servo_analysis, heading_plant, joint_plant, joint_torque, pd_servo_step, reflected_inertia, servo_analysis, servo_closed_loop, servo_plant)
from robokit.controllers.joint_servo import discrete_servo_response, joint_lag

M = LITTLEDOG_MOTOR
NOMINAL_LINK_INERTIA = 2.0e-4      # a leg's links about a knee, of the order of LittleDog's (kg m^2)
J = NOMINAL_LINK_INERTIA + reflected_inertia(M)
KP, KD = design_servo_gains(M, J, 15.0)


def _python_control_loop(kp, kd, rate_hz):
    """The sampled loop built directly from the physics (K, B, J) with python-control, independently."""
    dt = 1.0 / rate_hz
    K, B = M.torque_per_volt, M.damping
    Pz = control.c2d(control.tf([K], [J, B, 0.0]), dt, "zoh")
    Cz = control.tf([kp + kd / dt, -kd / dt], [1.0, 0.0], dt)        # kp + kd (1 - 1/z) / dt on q
    return control.feedback(kp * Pz, Cz / kp), Cz * Pz


def test_joint_plant_matches_the_motor_ode():
    # J q'' = joint_torque(V, q') from rest under a constant 2 V, integrated; vs the transfer function
    t = np.linspace(0, 0.08, 81)
    sol = solve_ivp(lambda _, x: [x[1], joint_torque(2.0, x[1], M) / J], (0, t[-1]), [0.0, 0.0], t_eval=t,
                    rtol=1e-10, atol=1e-13)
    y = control.forced_response(joint_plant(M, J), t, np.full_like(t, 2.0)).outputs
    np.testing.assert_allclose(y, sol.y[0], atol=1e-9)
    tau, gain = joint_lag(M, J)
    assert tau == pytest.approx(J / M.damping) and gain == pytest.approx(M.torque_per_volt / M.damping)
    assert heading_plant(tau, gain).den[0][0].tolist() == servo_plant(tau, gain).den[0][0].tolist()


@pytest.mark.parametrize("bandwidth, damping", [(15.0, 0.7), (12.0, 0.7), (25.0, 0.5), (15.0, 1.0)])
def test_designed_gains_meet_the_bandwidth_and_damping(bandwidth, damping):
    kp, kd = design_servo_gains(M, J, bandwidth, damping)
    tau, gain = joint_lag(M, J)
    T = servo_closed_loop(kp, kd, tau, gain)
    half_power = 20 * math.log10(1 / math.sqrt(2))            # "-3 dB" is |T| = 1/sqrt(2), -3.0103 dB
    assert control.bandwidth(T, dbdrop=half_power) / (2 * math.pi) == pytest.approx(bandwidth, rel=1e-4)
    _, zeta, _ = control.damp(T, doprint=False)
    assert zeta[0] == pytest.approx(damping, rel=1e-6)


def test_too_low_a_bandwidth_would_need_positive_rate_feedback():
    with pytest.raises(ValueError, match="bandwidth_hz"):
        design_servo_gains(M, J, 1.0)
    with pytest.raises(ValueError, match="inertia"):          # the link's inertia alone, without the rotor
        design_servo_gains(M, NOMINAL_LINK_INERTIA, 15.0)


@pytest.mark.parametrize("rate_hz", [500.0, 100.0])
def test_our_discrete_servo_matches_python_control(rate_hz):
    r = discrete_servo_response(KP, KD, M, J, rate_hz, steps=120, q_ref=1.0, saturate=False)
    T, _ = _python_control_loop(KP, KD, rate_hz)
    y = np.asarray(control.forced_response(T, r.t, np.ones_like(r.t)).outputs).ravel()
    np.testing.assert_allclose(r.q, y, rtol=0, atol=1e-9)
    a = servo_analysis(KP, KD, M, J, rate_hz, duration=119 / rate_hz)
    np.testing.assert_allclose(a.y, y, atol=1e-9)
    np.testing.assert_allclose(np.sort_complex(a.poles), np.sort_complex(T.poles()), atol=1e-9)


def test_discrete_servo_uses_the_servo_step_and_saturates():
    r = discrete_servo_response(KP, KD, M, J, 500.0, steps=200, q_ref=1.0)
    assert np.abs(r.voltage).max() == pytest.approx(M.voltage_max)
    lin = discrete_servo_response(KP, KD, M, J, 500.0, steps=200, q_ref=1.0, saturate=False)
    assert np.argmax(r.q > 0.9) > np.argmax(lin.q > 0.9)      # saturation slows the big step
    small = discrete_servo_response(KP, KD, M, J, 500.0, steps=200, q_ref=0.05)
    lin_small = discrete_servo_response(KP, KD, M, J, 500.0, steps=200, q_ref=0.05, saturate=False)
    np.testing.assert_array_equal(small.q, lin_small.q)       # a small step never saturates
    k = 37
    assert r.voltage[k] == pd_servo_step(1.0, r.q[k], r.q[k - 1], KP, KD, 0.002, M.voltage_max)


def test_margins_and_bandwidth_against_python_control_and_brute_force():
    a = servo_analysis(KP, KD, M, J, 500.0)
    T, L = _python_control_loop(KP, KD, 500.0)
    gm, pm, _, _, wc = control.stability_margins(L)[:5]
    assert (a.gain_margin, a.phase_margin_deg, a.crossover) == pytest.approx((gm, pm, wc))
    dt = 0.002
    w = np.linspace(1.0, math.pi / dt, 400_000)
    mag = np.abs(T(np.exp(1j * w * dt)))
    assert a.bandwidth_hz * 2 * math.pi == pytest.approx(w[np.argmax(mag < 1 / math.sqrt(2))], abs=1e-2)
    assert abs(a.bandwidth_hz - 15.0) < 0.1 * 15.0             # sampling at 33x the bandwidth keeps the design
    info = control.step_info(T)
    assert a.overshoot == pytest.approx(info["Overshoot"] / 100, abs=0.01)


def test_the_same_gains_at_100_hz_lose_their_margins():
    fast = servo_analysis(KP, KD, M, J, 500.0)
    slow = servo_analysis(KP, KD, M, J, 100.0)
    assert fast.stable and slow.stable
    assert fast.phase_margin_deg > 60 and slow.phase_margin_deg < 45
    assert fast.overshoot < 0.07 and slow.overshoot > 0.15
    assert fast.gain_margin > 5 * slow.gain_margin
    assert slow.gain_margin < 3                               # a gain 3x higher would not survive 100 Hz
    assert not servo_analysis(3 * KP, 3 * KD, M, J, 100.0).stable
    assert servo_analysis(3 * KP, 3 * KD, M, J, 500.0).stable


def test_an_unstable_gain_is_reported_not_raised():
    a = servo_analysis(10 * KP, KD, M, J, 100.0)
    assert not a.stable and np.abs(a.poles).max() > 1
    assert math.isnan(a.overshoot) and math.isnan(a.bandwidth_hz)
    assert a.gain_margin < 1                                  # python-control: the loop needs less gain
    assert np.all(np.isfinite(a.y)) and np.abs(a.y).max() > 10
    r = discrete_servo_response(10 * KP, KD, M, J, 100.0, steps=60, q_ref=0.01, saturate=False)
    assert np.abs(r.q[-1]) > 100 * 0.01                       # our simulation diverges too
    huge = discrete_servo_analysis(1e6, 1e3, 0.01, 100.0, duration=20.0)   # overflows: cut, still reported
    assert not huge.stable and np.all(np.isfinite(huge.y)) and len(huge.t) == len(huge.y)
    with pytest.raises(ValueError, match="kp, kd"):
        discrete_servo_response(1e6, 1e3, M, J, 100.0, steps=2000, saturate=False)


def test_pd_servo_step_vectorised_fast_path_and_bad_input():
    rng = np.random.default_rng(2)
    q_ref, q, q_prev = rng.normal(0, 0.3, (3, 12))
    kp = np.linspace(50, 150, 12)
    v = pd_servo_step(q_ref, q, q_prev, kp, KD, 0.002, 14.8)
    expected = [float(np.clip(kp[j] * (q_ref[j] - q[j]) - KD * (q[j] - q_prev[j]) / 0.002, -14.8, 14.8))
                for j in range(12)]
    np.testing.assert_allclose(v, expected, atol=1e-12)
    np.testing.assert_array_equal(pd_servo_step(q_ref, q, q_prev, kp, KD, 0.002, 14.8, validate=False), v)
    assert isinstance(pd_servo_step(0.1, 0.0, 0.0, KP, KD, 0.002, 14.8), float)
    bad = q_ref.copy()
    bad[5] = np.nan
    with pytest.raises(ValueError, match="q_ref"):
        pd_servo_step(bad, q, q_prev, KP, KD, 0.002, 14.8)
    with pytest.raises(ValueError, match="q_prev"):
        pd_servo_step(q_ref, q, q_prev[:3], KP, KD, 0.002, 14.8)
    with pytest.raises(ValueError, match="kp"):
        pd_servo_step(q_ref, q, q_prev, np.ones(3), KD, 0.002, 14.8)
    with pytest.raises(ValueError, match="kd"):
        pd_servo_step(q_ref, q, q_prev, KP, -1.0, 0.002, 14.8)
    with pytest.raises(ValueError, match="dt"):
        pd_servo_step(q_ref, q, q_prev, KP, KD, 0.0, 14.8)
