"""IMU model: noise and bias statistics, gyro integration (exact for a constant rate, first order
otherwise, a bias drifts as |b| t), the specific force against MuJoCo's own accelerometer."""
from __future__ import annotations

import numpy as np
import pytest

from robokit.geometry import rot_x, rot_y, rot_z, so3_exp, so3_log
from robokit.legged.imu import integrate_gyro, simulate_imu, specific_force
from robokit.legged.state_estimation import orientation_errors


def test_biases_add_and_noise_has_the_asked_spread():
    n = 20000
    w, f = np.zeros((n, 3)), np.tile([0.0, 0.0, 9.81], (n, 1))
    imu = simulate_imu(w, f, 0, gyro_noise=0.005, acc_noise=0.05, gyro_bias=[0.02, -0.01, 0.0],
                       acc_bias=[0.1, 0.0, -0.2])
    assert np.abs(imu.gyro.mean(0) - [0.02, -0.01, 0.0]).max() < 4 * 0.005 / np.sqrt(n)
    assert np.abs(imu.acc.mean(0) - [0.1, 0.0, 9.61]).max() < 4 * 0.05 / np.sqrt(n)
    assert np.abs(imu.gyro.std(0) / 0.005 - 1).max() < 0.03 and np.abs(imu.acc.std(0) / 0.05 - 1).max() < 0.03
    ideal = simulate_imu(w[:3], f[:3], 0)
    assert np.array_equal(ideal.gyro, w[:3]) and np.array_equal(ideal.acc, f[:3])
    with pytest.raises(ValueError, match="specific_force_body"):
        simulate_imu(w, f[:-1], 0)
    with pytest.raises(ValueError, match="gyro_bias"):
        simulate_imu(w, f, 0, gyro_bias=[0.0, 0.0])


def test_a_constant_rate_integrates_exactly_and_a_bias_drifts_as_b_t():
    axis = np.array([0.3, -0.4, 0.5])
    R0 = rot_x(0.4) @ rot_z(1.0)
    R = integrate_gyro(R0, np.tile(axis, (301, 1)), 0.01)   # 2.1 rad: below pi
    k = np.arange(301)[:, None]
    assert np.abs(R - R0 @ so3_exp(k * 0.01 * axis)).max() < 1e-12
    drift = orientation_errors(R, np.repeat(R0[None], 301, 0))
    assert np.abs(drift - np.linalg.norm(axis) * k[:, 0] * 0.01).max() < 1e-12


def wobble(rate, duration=10.0):
    """Roll, pitch and yaw oscillating together: the axis of rotation turns (analytic rates)."""
    t = np.arange(int(round(duration * rate)) + 1) / rate
    phi, th, psi = 0.3 * np.sin(2 * t), 0.2 * np.sin(3 * t + 1), 0.5 * np.sin(t)
    dphi, dth, dpsi = 0.6 * np.cos(2 * t), 0.6 * np.cos(3 * t + 1), 0.5 * np.cos(t)
    R = rot_z(psi) @ rot_y(th) @ rot_x(phi)
    omega = np.stack([dphi - dpsi * np.sin(th), dth * np.cos(phi) + dpsi * np.sin(phi) * np.cos(th),
                      -dth * np.sin(phi) + dpsi * np.cos(phi) * np.cos(th)], 1)
    return R, omega


def test_body_rates_of_the_test_trajectory_match_finite_differences():
    R, omega = wobble(10000.0, 1.0)
    fd = so3_log(np.swapaxes(R[:-1], 1, 2) @ R[1:]) * 10000.0
    assert np.abs(fd - 0.5 * (omega[:-1] + omega[1:])).max() < 1e-6


def test_gyro_integration_is_first_order_in_the_time_step():
    errors = []
    for rate in (100.0, 200.0, 400.0):
        R, omega = wobble(rate)
        errors.append(orientation_errors(integrate_gyro(R[0], omega, 1.0 / rate), R).max())
    assert errors[0] < 0.05
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 1.8) & (ratios < 2.2)), ratios            # halving dt halves the error


def test_specific_force_by_hand():
    assert np.allclose(specific_force([[0.0, 0.0, 0.0]], np.eye(3)[None]), [[0.0, 0.0, 9.81]])
    assert np.allclose(specific_force([[0.0, 0.0, -9.81]], rot_x(0.7)[None]), 0.0)      # free fall
    # tipped 90 deg about x: the body's y axis points up, so gravity's reaction is along +y
    assert np.allclose(specific_force([[0.0, 0.0, 0.0]], rot_x(np.pi / 2)[None]), [[0.0, 9.81, 0.0]])
    with pytest.raises(ValueError, match="R_world_body"):
        specific_force(np.zeros((2, 3)), np.eye(3)[None])


def test_specific_force_matches_mujoco_accelerometer_on_a_spinning_arm():
    mujoco = pytest.importorskip("mujoco")
    xml = """<mujoco><option gravity="0 0 -9.81" timestep="0.0005"/>
      <worldbody><body name="arm" pos="0 0 0.5" euler="0.3 0.2 0">
        <joint name="spin" type="hinge" axis="0 0 1" damping="0"/>
        <geom type="box" size="0.2 0.02 0.02" mass="1"/>
        <site name="imu" pos="0.15 0.01 0" euler="0.1 -0.4 0.7"/>
      </body></worldbody>
      <sensor><accelerometer site="imu"/></sensor></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qvel[0] = 3.0                                   # rad/s about the (tilted) hinge axis
    for _ in range(200):
        mujoco.mj_step(model, data)
    mujoco.mj_forward(model, data)
    mujoco.mj_rnePostConstraint(model, data)
    R = data.site_xmat[0].reshape(3, 3)
    # the site's world acceleration from the rigid-body kinematics: centripetal + tangential
    body = model.body("arm").id
    axis = data.xmat[body].reshape(3, 3) @ [0.0, 0.0, 1.0]
    r = data.site_xpos[0] - data.xanchor[0]
    w, dw = data.qvel[0] * axis, data.qacc[0] * axis
    acc_world = np.cross(dw, r) + np.cross(w, np.cross(w, r))
    assert np.abs(specific_force(acc_world[None], R[None])[0] - data.sensordata[:3]).max() < 1e-6
