"""Vehicle kinematics: exact arcs against small-step integration, drive models, and the skid-steer
model's inverse with saturation."""
import numpy as np
import pytest

from robokit.geometry import wrap_angle
from robokit.sim.vehicle import diff_drive_velocities, skid_steer_velocities, skid_steer_wheel_speeds, unicycle_step


def euler(pose, v, omega, dt, steps):
    p = np.array(pose, float)
    h = dt / steps
    for _ in range(steps):
        p = p + h * np.array([v * np.cos(p[2]), v * np.sin(p[2]), omega])
    return p


@pytest.mark.parametrize("v, omega", [(0.5, 0.4), (1.2, -2.0), (0.3, 1e-12), (-0.4, 0.7)])
def test_arc_matches_many_small_euler_steps(v, omega):
    pose = np.array([1.0, 2.0, 0.3])
    exact = unicycle_step(pose, v, omega, 2.0)
    p = euler(pose, v, omega, 2.0, 20000)
    np.testing.assert_allclose(exact[:2], p[:2], atol=2e-4)
    assert wrap_angle(exact[2] - p[2]) == pytest.approx(0, abs=1e-6)


def test_arc_special_cases_batches_and_fast_path():
    pose = np.array([1.0, 2.0, 0.3])
    np.testing.assert_allclose(unicycle_step(pose, 1.0, 0.0, 1.0), [1 + np.cos(0.3), 2 + np.sin(0.3), 0.3])
    np.testing.assert_allclose(unicycle_step(pose, 0.0, 1.0, 0.5), [1.0, 2.0, 0.8])          # turn on the spot
    np.testing.assert_allclose(unicycle_step([0.0, 0.0, 0.0], 1.0, np.pi, 1.0), [0.0, 2 / np.pi, -np.pi], atol=1e-12)
    batch = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 0.3], [-3.0, 1.0, 2.5]])
    v, w = np.array([0.5, 1.0, 0.2]), np.array([0.0, -0.4, 3.0])
    out = unicycle_step(batch, v, w, 0.7)
    for k in range(3):
        np.testing.assert_array_equal(out[k], unicycle_step(batch[k], v[k], w[k], 0.7))
    np.testing.assert_array_equal(unicycle_step(batch, v, w, 0.7, validate=False), out)


def test_drive_kinematics():
    v, w = diff_drive_velocities(1.0, 3.0, wheel_radius=0.05, track=0.25)
    assert v == pytest.approx(0.1) and w == pytest.approx(0.4)
    v, w = skid_steer_velocities(0.2, 0.4, track=0.3, icr_factor=2.0)
    assert v == pytest.approx(0.3) and w == pytest.approx(0.2 / 0.6)
    v, w = skid_steer_velocities(0.2, 0.4, track=0.3, icr_factor=1.0, slip=0.1)
    assert v == pytest.approx(0.9 * 0.3) and w == pytest.approx(0.9 * 0.2 / 0.3)   # a differential drive, slipping
    v, w = skid_steer_velocities(np.array([0.1, -0.3]), np.array([0.1, 0.3]), track=0.2)
    np.testing.assert_allclose(v, [0.1, 0.0])
    np.testing.assert_allclose(w, [0.0, 0.6 / 0.3])


def test_forward_and_inverse_round_trip():
    rng = np.random.default_rng(5)
    track, top, icr, slip = 0.21, 1.0, 1.6, 0.07
    v = rng.uniform(-0.4, 0.4, 200)
    omega = rng.uniform(-2.0, 2.0, 200)
    wheels = skid_steer_wheel_speeds(v, omega, track, top, icr, slip)
    assert np.abs(wheels).max() <= top                                     # all within reach: no saturation
    back_v, back_w = skid_steer_velocities(wheels[:, 0], wheels[:, 1], track, icr, slip)
    np.testing.assert_allclose(back_v, v, atol=1e-12)
    np.testing.assert_allclose(back_w, omega, atol=1e-12)
    for wl, wr in rng.uniform(-top, top, (50, 2)):                         # and wheels -> body -> wheels
        np.testing.assert_allclose(skid_steer_wheel_speeds(*skid_steer_velocities(wl, wr, track, icr, slip), track,
                                                           top, icr, slip), [wl, wr], atol=1e-12)


def test_saturation_gives_up_speed_before_the_turn():
    track, top = 0.21, 1.0
    w = skid_steer_wheel_speeds(5.0, 2.0, track, top)                      # far too fast
    assert np.abs(w).max() == pytest.approx(top)
    v, omega = skid_steer_velocities(*w, track)
    assert omega == pytest.approx(2.0) and 0 < v < 5.0                     # the turn is kept, the speed gives way
    w = skid_steer_wheel_speeds(0.3, 50.0, track, top)                     # a turn beyond the wheels: spin in place
    np.testing.assert_allclose(w, [-top, top])
    w = skid_steer_wheel_speeds(-5.0, -2.0, track, top)                    # backwards too
    assert skid_steer_velocities(*w, track)[1] == pytest.approx(-2.0) and np.abs(w).max() == pytest.approx(top)


@pytest.mark.parametrize("call, match", [
    (lambda: skid_steer_velocities(0.2, 0.4, track=0.3, icr_factor=0.5), "icr_factor: expected an expansion factor >= 1"),
    (lambda: skid_steer_velocities(0.2, 0.4, track=0.3, slip=1.0), r"slip: expected a ratio in \[0, 1\)"),
    (lambda: skid_steer_velocities(0.2, np.nan, track=0.3), "v_right"),
    (lambda: skid_steer_wheel_speeds(0.2, 0.4, track=0.3, max_wheel_speed=0.0), "max_wheel_speed"),
    (lambda: diff_drive_velocities(1.0, 1.0, wheel_radius=-0.1, track=0.3), "wheel_radius"),
    (lambda: unicycle_step([0, 0, 0], 1.0, 0.0, -1.0), "dt"),
    (lambda: unicycle_step([0, 0], 1.0, 0.0, 1.0), "pose"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()
