"""The pose EKF over (x, y, theta, v, omega): Jacobians, updates, and consistency (NEES) by Monte Carlo."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from robokit.geometry import wrap_angle
from robokit.localization.pose_ekf import (UnicycleEKF, ekf_predict, ekf_update, nees, nees_bounds, unicycle_jacobian,
                                           unicycle_process_noise)
from robokit.sim import unicycle_step


def _motion(x, dt):
    out = np.empty(5)
    out[:3] = unicycle_step(x[:3], x[3], x[4], dt)
    out[3:] = x[3:]
    return out


@pytest.mark.parametrize("x", [[1.0, 2.0, 0.3, 0.5, 0.7], [0.0, 0.0, -2.0, 0.3, 0.0], [0.0, 0.0, 3.1, 1.0, -2.0],
                               [0.0, 0.0, 0.0, 0.3, 1e-3], [5.0, -1.0, -3.0, -0.4, 4.0]])
@pytest.mark.parametrize("dt", [0.1, 1.0])
def test_the_jacobian_is_the_finite_difference_of_unicycle_step(x, dt):
    x, h = np.asarray(x), 1e-5
    J = np.empty((5, 5))
    for j in range(5):
        e = np.eye(5)[j] * h
        diff = _motion(x + e, dt) - _motion(x - e, dt)
        diff[2] = wrap_angle(diff[2])
        J[:, j] = diff / (2 * h)
    assert np.allclose(unicycle_jacobian(x, dt), J, atol=1e-6)


def test_on_a_straight_line_the_process_noise_is_the_textbook_white_acceleration():
    dt, sa, sw = 0.2, 0.5, 1.0
    Q = unicycle_process_noise([0.0, 0.0, 0.0, 1.0, 0.0], dt, sa, sw)
    gamma = np.array([dt ** 2 / 2, dt])                               # Bar-Shalom's Gamma for one axis
    assert np.allclose(Q[np.ix_([0, 3], [0, 3])], sa ** 2 * np.outer(gamma, gamma))
    assert np.allclose(Q[np.ix_([2, 4], [2, 4])], sw ** 2 * np.outer(gamma, gamma))
    assert np.all(np.linalg.eigvalsh(Q) > -1e-15)


def test_predict_moves_along_the_arc_and_propagates_the_covariance():
    rng = np.random.default_rng(0)
    x = np.array([1.0, -1.0, 2.5, 0.4, 0.9])
    A = rng.normal(size=(5, 5))
    P, Q = A @ A.T + np.eye(5), np.diag([1e-4, 1e-4, 1e-3, 1e-2, 1e-2])
    x1, P1 = ekf_predict(x, P, 0.5, Q)
    assert np.allclose(x1, _motion(x, 0.5))
    F = unicycle_jacobian(x, 0.5)
    assert np.allclose(P1, F @ P @ F.T + Q)


def test_an_update_with_equal_variances_lands_halfway_and_halves_the_variance():
    x, P = ekf_update([0.0, 5.0], np.diag([2.0, 1.0]), [1.0], [[1.0, 0.0]], [[2.0]])
    assert x.tolist() == [0.5, 5.0] and np.allclose(P, np.diag([1.0, 1.0]))


def test_the_joseph_form_equals_the_textbook_form_for_the_optimal_gain():
    rng = np.random.default_rng(3)
    A, B = rng.normal(size=(5, 5)), rng.normal(size=(3, 3))
    P, R, H = A @ A.T + 0.1 * np.eye(5), B @ B.T + 0.1 * np.eye(3), rng.normal(size=(3, 5))
    x, z = rng.normal(size=5), rng.normal(size=3)
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    x1, P1 = ekf_update(x, P, z, H, R)
    assert np.allclose(x1, x + K @ (z - H @ x)) and np.allclose(P1, (np.eye(5) - K @ H) @ P)


def test_the_heading_innovation_is_wrapped():
    ekf = UnicycleEKF([0.0, 0.0, math.pi - 0.05, 0.0, 0.0], np.eye(5) * 0.01)
    assert ekf.update_pose([0.0, 0.0, -math.pi + 0.05], np.eye(3) * 0.01)   # 0.1 rad away, across +-pi
    assert abs(wrap_angle(ekf.pose[2] - math.pi)) < 1e-12                    # halfway: exactly pi, not 0
    assert -math.pi <= ekf.pose[2] < math.pi


def test_a_gate_rejects_a_false_fix():
    ekf = UnicycleEKF([0.0, 0.0, 0.0, 0.3, 0.0], np.diag([0.01, 0.01, 0.01, 1e-3, 1e-3]))
    gate = chi2.ppf(0.999, 3)
    assert not ekf.update_pose([2.0, 0.0, 0.0], np.diag([0.01, 0.02, 0.003]), gate=gate)
    assert np.allclose(ekf.pose, 0.0) and ekf.nis > gate
    assert ekf.update_pose([0.1, 0.0, 0.0], np.diag([0.01, 0.02, 0.003]), gate=gate)


@pytest.mark.parametrize("R, match", [(np.diag([1.0, -1.0]), "positive-definite"), (np.zeros((2, 2)), "positive-definite"),
                                      ([[1.0, 0.5], [0.0, 1.0]], "symmetric"), ([[np.nan, 0], [0, 1]], "finite"),
                                      (np.eye(3), "shape")])
def test_bad_covariances_are_refused(R, match):
    ekf = UnicycleEKF(np.zeros(5), np.eye(5))
    with pytest.raises(ValueError, match=f"R: .*{match}"):
        ekf.update_velocity(0.3, 0.0, R)
    with pytest.raises(ValueError, match="P0: .*positive-definite"):
        UnicycleEKF(np.zeros(5), np.diag([1.0, 1.0, 1.0, 1.0, 0.0]))
    with pytest.raises(ValueError, match="z: .*finite"):
        ekf.update_pose([0.0, np.nan, 0.0], np.eye(3))


def test_nees_and_its_bounds():
    assert nees([0.1, -0.2], np.diag([0.01, 0.04])) == pytest.approx(2.0)
    assert np.allclose(nees(np.array([[1.0, 0.0], [0.0, 2.0]]), np.stack([np.eye(2), 4 * np.eye(2)])), [1.0, 1.0])
    # the interval holds 95 % of the averages of 50 chi-square(5) draws (simulated independently)
    lo, hi = nees_bounds(5, 50)
    means = np.random.default_rng(4).chisquare(5, size=(20000, 50)).mean(axis=1)
    assert np.mean((means > lo) & (means < hi)) == pytest.approx(0.95, abs=0.005)


def _monte_carlo(runs, steps, *, rng, fix_scale=1.0, accel_scale=1.0):
    """Truth from the filter's own model; the filter told ``fix_scale`` x the fix variance."""
    dt, every = 0.1, 5
    sa, sw, odo, fix = 0.5, 1.0, np.array([0.02, 0.03]), np.array([0.10, 0.15, 0.05])
    P0 = np.diag([0.1, 0.1, 0.05, 0.01, 0.01])
    out = np.empty((runs, steps))
    for r in range(runs):
        x = np.array([0.0, 0.0, 0.0, 0.3, 0.0])
        ekf = UnicycleEKF(x + rng.multivariate_normal(np.zeros(5), P0), P0,
                          sigma_accel=sa * accel_scale, sigma_alpha=sw * accel_scale)
        for k in range(steps):
            ekf.update_velocity(*(x[3:] + odo * rng.standard_normal(2)), np.diag(odo ** 2))
            a = np.array([sa, sw]) * rng.standard_normal(2)            # accelerations held over the step
            x = np.concatenate([unicycle_step(x[:3], *(x[3:] + a * dt / 2), dt), x[3:] + a * dt])
            ekf.predict(dt)
            if (k + 1) % every == 0:                                    # a visual fix at 2 Hz
                ekf.update_pose(x[:3] + fix * rng.standard_normal(3), np.diag(fix ** 2) * fix_scale)
            e = x - ekf.state
            e[2] = wrap_angle(e[2])
            out[r, k] = nees(e, ekf.covariance)
    return out


def test_the_filter_is_consistent_nees_within_the_chi2_bounds():
    runs, steps = 50, 200
    N = _monte_carlo(runs, steps, rng=np.random.default_rng(11))
    lo, hi = nees_bounds(5, runs)
    per_step = N.mean(axis=0)
    inside = np.mean((per_step > lo) & (per_step < hi))
    assert inside >= 0.90, f"average NEES inside [{lo:.2f}, {hi:.2f}] at {inside:.0%} of the steps"
    lo_all, hi_all = nees_bounds(5, runs * steps)                      # loose: steps are correlated
    assert 0.95 * lo_all < N.mean() < 1.05 * hi_all, N.mean()


def test_an_overconfident_filter_fails_the_nees_test():
    runs, steps = 50, 200
    N = _monte_carlo(runs, steps, rng=np.random.default_rng(11), fix_scale=0.1, accel_scale=0.3)
    lo, hi = nees_bounds(5, runs)
    per_step = N.mean(axis=0)
    assert np.mean((per_step > lo) & (per_step < hi)) < 0.2 and N.mean() > 2 * hi


def test_nees_refuses_a_covariance_that_is_not_positive_definite():
    # a negative-definite P had given a NEES of -1 without a word
    from robokit.localization.pose_ekf import nees

    for P, what in [(-np.eye(2), "positive-definite"), (np.zeros((2, 2)), "positive-definite"),
                    ([[1.0, 2.0], [0.0, 1.0]], "symmetric")]:
        with pytest.raises(ValueError, match=f"P: expected {what}"):
            nees([0.1, 0.2], P)
    stack = np.tile(np.eye(2), (3, 1, 1))
    stack[1] = -np.eye(2)
    with pytest.raises(ValueError, match="P: expected positive-definite"):
        nees(np.ones((3, 2)), stack)
