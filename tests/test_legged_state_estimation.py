"""The fused body state: the synthetic walking comparison (fused vs IMU-only vs MoCap-with-hold),
the complementary filter's linearised response, the Kalman filter against batch least squares."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import signal
from scipy.spatial.transform import Rotation

from robokit.geometry import rot_x, rot_y, rot_z, se3_from_rt, so3_exp
from robokit.legged import MARKERS
from robokit.legged.imu import integrate_gyro, simulate_imu, specific_force
from robokit.legged.mocap import mocap_body_poses
from robokit.legged.mocap import simulate_mocap
from robokit.legged.state_estimation import fuse_body_state, orientation_errors, position_errors

DT = 0.01


def walking_trajectory(duration=30.0, rate=100.0):
    """A trunk walking a 1 m-radius circle at 0.1 m/s, bobbing 5 mm at 2 Hz, rolling 0.03 rad and
    yawing 0.05 rad with a 1 Hz stride, pitching 0.02 rad at 2 Hz (all analytic): times, poses,
    body rates, world accelerations."""
    t = np.arange(int(round(duration * rate)) + 1) / rate
    w0, f = 0.1, 2 * np.pi
    psi, dpsi = w0 * t + 0.05 * np.sin(f * t), w0 + 0.05 * f * np.cos(f * t)
    phi, dphi = 0.03 * np.sin(f * t), 0.03 * f * np.cos(f * t)
    th, dth = 0.02 * np.sin(2 * f * t + 0.5), 0.04 * f * np.cos(2 * f * t + 0.5)
    R = rot_z(psi) @ rot_y(th) @ rot_x(phi)
    omega = np.stack([dphi - dpsi * np.sin(th), dth * np.cos(phi) + dpsi * np.sin(phi) * np.cos(th),
                      -dth * np.sin(phi) + dpsi * np.cos(phi) * np.cos(th)], 1)
    p = np.stack([np.sin(w0 * t), 1 - np.cos(w0 * t), 0.1315 + 0.005 * np.sin(2 * f * t)], 1)
    a = np.stack([-w0 ** 2 * np.sin(w0 * t), w0 ** 2 * np.cos(w0 * t), -0.005 * (2 * f) ** 2 * np.sin(2 * f * t)], 1)
    return t, se3_from_rt(R, p), omega, a


def rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def dead_reckoning(R, acc, p0, v0):
    """IMU-only position: double integration of the rotated, gravity-free accelerometer."""
    a = np.einsum("nij,nj->ni", R, acc) - [0.0, 0.0, 9.81]
    v = v0 + np.cumsum(np.r_[np.zeros((1, 3)), a[:-1] * DT], 0)
    return p0 + np.cumsum(np.r_[np.zeros((1, 3)), v[:-1] * DT + 0.5 * a[:-1] * DT ** 2], 0)


def test_fusion_beats_imu_only_drift_and_mocap_hold_in_dropout_bursts():
    t, T, omega, a = walking_trajectory()
    R_true, p_true = T[:, :3, :3], T[:, :3, 3]
    bias = np.array([0.02, -0.015, 0.01])
    frames = simulate_mocap(T, MARKERS, noise=0.001, dropout=0.15, rng=42, bursts=0.003, burst_length=30)
    mocap = mocap_body_poses(MARKERS, frames.positions, frames.visible)
    imu = simulate_imu(omega, specific_force(a, R_true), 7, gyro_noise=0.005, acc_noise=0.05, gyro_bias=bias,
                       acc_bias=[0.1, -0.05, 0.08])
    est = fuse_body_state(imu.gyro, imu.acc, DT, mocap.T_world_body, mocap.ok)
    ok, lost = mocap.ok, ~mocap.ok
    assert 0.15 < lost.mean() < 0.3                                   # the trial has holes ...
    run = np.convolve(lost, np.ones(10), "valid") == 10
    assert run.sum() > 100                                            # ... and bursts of 10+ lost frames
    # IMU-only: the gyro bias turns into an angle growing like |b| t, the position runs away
    R_imu = integrate_gyro(R_true[0], imu.gyro, DT)
    e_R_imu = orientation_errors(R_imu, R_true)
    e_p_imu = position_errors(dead_reckoning(R_imu, imu.acc, p_true[0], [0.1, 0.0, 0.0]), p_true)
    # MoCap with hold, and the fused estimate
    e_R_hold = orientation_errors(mocap.T_world_body[:, :3, :3], R_true)
    e_p_hold = position_errors(mocap.T_world_body[:, :3, 3], p_true)
    e_R, e_p = orientation_errors(est.R, R_true), position_errors(est.p, p_true)
    # the numbers (seeds 42 and 7), RMS over the 30 s: IMU-only 0.39 rad / 347 m (final 0.59 rad,
    # 876 m); MoCap with hold 0.028 rad / 6.2 mm, in lost frames 0.046 rad / 13.4 mm; fused
    # 0.0064 rad / 1.7 mm, in lost frames 0.0084 rad / 3.6 mm, in ok frames 0.0057 rad / 0.59 mm where
    # the MoCap's own fit gives 0.021 rad / 1.05 mm
    assert e_R_imu[-1] > 0.4 and rms(e_R_imu) > 0.2 and e_p_imu[-1] > 100.0
    assert rms(e_R) < 0.01 and e_R.max() < 0.05 and rms(e_p) < 0.003
    assert rms(e_R) < rms(e_R_imu) / 20 and rms(e_p) < rms(e_p_imu) / 1000
    assert rms(e_R[lost]) < rms(e_R_hold[lost]) / 3 and rms(e_p[lost]) < rms(e_p_hold[lost]) / 3
    assert rms(e_R[ok]) < rms(e_R_hold[ok]) / 2 and rms(e_p[ok]) < rms(e_p_hold[ok])   # smoother than MoCap
    assert np.abs(est.gyro_bias[-1000:].mean(0) - bias).max() < 0.002
    # the velocity too: 0.1 m/s along the circle
    v_true = np.stack([0.1 * np.cos(0.1 * t), 0.1 * np.sin(0.1 * t),
                       0.005 * 4 * np.pi * np.cos(4 * np.pi * t)], 1)
    assert rms(est.v[500:] - v_true[500:]) < 0.03


def test_orientation_error_follows_the_linearised_filter():
    # at rest, level, MoCap in every frame; a gyro bias about z. The yaw error e obeys
    # e'' + k_p e' + k_i e = 0, e(0) = 0, e'(0) = b: b times the impulse response of 1/(s^2 + k_p s + k_i)
    n, b, kp, ki, dt = 3001, 0.01, 2.0, 0.5, 0.002
    T = np.repeat(np.eye(4)[None], n, 0)
    est = fuse_body_state(np.tile([0.0, 0.0, b], (n, 1)), np.tile([0.0, 0.0, 9.81], (n, 1)), dt, T,
                          np.ones(n, bool), k_p=kp, k_i=ki)
    yaw = np.arctan2(est.R[:, 1, 0], est.R[:, 0, 0])
    t = np.arange(n) * dt
    _, h = signal.impulse(([1.0], [1.0, kp, ki]), T=t)
    assert np.abs(yaw - b * h).max() < 0.01 * b * np.abs(h).max() + 1e-6
    # the bias estimate integrates k_i e: b times the step response of k_i / (s^2 + k_p s + k_i)
    _, step = signal.step(([ki], [1.0, kp, ki]), T=t)
    assert np.abs(est.gyro_bias[:, 2] - b * step).max() < 0.01 * b
    assert est.gyro_bias[-1, 2] > 0.75 * b


def test_kalman_filter_equals_batch_least_squares():
    # orientation known exactly (level, at rest, no gyro): the position part alone is a linear
    # Gaussian smoother problem whose last state equals the KF's last estimate
    rng = np.random.default_rng(0)
    n, dt, s_acc, s_m = 60, 0.01, 0.4, 0.002
    acc_world = rng.normal(scale=0.5, size=(n, 3))
    acc = acc_world + [0.0, 0.0, 9.81]
    z = rng.normal(scale=0.01, size=(n, 3)) + [0.0, 0.0, 0.13]
    ok = rng.random(n) > 0.3
    ok[0] = True
    T = np.repeat(np.eye(4)[None], n, 0)
    T[:, :3, 3] = z
    est = fuse_body_state(np.zeros((n, 3)), acc, dt, T, ok, sigma_acc=s_acc, sigma_mocap=s_m)
    A = np.array([[1.0, dt], [0.0, 1.0]])
    B = np.array([0.5 * dt ** 2, dt])
    Q = s_acc ** 2 * np.outer(B, B) + 1e-18 * np.eye(2)
    for axis in range(3):
        # unknowns x_0..x_{n-1} (2 each); rows whitened by their standard deviations
        rows, rhs = [], []
        L0 = np.diag([1 / s_m, 1.0])                                   # the prior: p0 = z_0, v0 = 0
        r = np.zeros((2, 2 * n)); r[:, :2] = L0; rows.append(r); rhs.append(L0 @ [z[0, axis], 0.0])
        Lq = np.linalg.cholesky(np.linalg.inv(Q)).T
        for k in range(1, n):
            r = np.zeros((2, 2 * n))
            r[:, 2 * k:2 * k + 2] = Lq
            r[:, 2 * k - 2:2 * k] = -Lq @ A
            rows.append(r); rhs.append(Lq @ (B * acc_world[k, axis]))     # sample k covers (t_{k-1}, t_k]
            if ok[k]:
                r = np.zeros((1, 2 * n)); r[0, 2 * k] = 1 / s_m; rows.append(r); rhs.append([z[k, axis] / s_m])
        x = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
        assert abs(x[-2] - est.p[-1, axis]) < 1e-6 and abs(x[-1] - est.v[-1, axis]) < 1e-4


def test_error_measures_against_scipy_and_by_hand():
    rng = np.random.default_rng(1)
    Ra, Rb = so3_exp(rng.normal(size=(50, 3))), so3_exp(rng.normal(size=(50, 3)))
    want = (Rotation.from_matrix(Rb).inv() * Rotation.from_matrix(Ra)).magnitude()
    assert np.abs(orientation_errors(Ra, Rb) - want).max() < 1e-9
    assert position_errors([[1.0, 2.0, 2.0]], [[0.0, 0.0, 0.0]]).tolist() == [3.0]
    with pytest.raises(ValueError, match="R_true"):
        orientation_errors(Ra, Rb[:3])
    with pytest.raises(ValueError, match="p_true"):
        position_errors(np.zeros((2, 3)), np.zeros((3, 3)))


def test_bad_inputs_are_named():
    n = 5
    args = (np.zeros((n, 3)), np.tile([0.0, 0.0, 9.81], (n, 1)), 0.01, np.repeat(np.eye(4)[None], n, 0),
            np.ones(n, bool))
    with pytest.raises(ValueError, match="T_mocap"):
        fuse_body_state(*args[:3], args[3][:-1], args[4])
    with pytest.raises(ValueError, match="mocap_ok"):
        fuse_body_state(*args[:4], np.ones(n + 1, bool))
    with pytest.raises(ValueError, match="k_p"):
        fuse_body_state(*args, k_p=-1.0)
    with pytest.raises(ValueError, match="sigma_mocap"):
        fuse_body_state(*args, sigma_mocap=0.0)
    with pytest.raises(ValueError, match="R0"):
        fuse_body_state(*args, R0=2 * np.eye(3))
