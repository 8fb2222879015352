"""LiDAR against closed-form ranges; motion models and the odometry noise statistics."""
import numpy as np
import pytest

from robokit.geometry import wrap_angle
from robokit.sim import motion as mo
from robokit.sim.lidar import Lidar, ray_segment_ranges, scan_points
from robokit.sim.worlds import box_room, lab_room, long_corridor


def analytic_box_ranges(x, y, angles, w, d):
    c, s = np.cos(angles), np.sin(angles)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (w - x) / c, np.where(c < 0, -x / c, np.inf))
        ty = np.where(s > 0, (d - y) / s, np.where(s < 0, -y / s, np.inf))
    return np.minimum(tx, ty)


@pytest.mark.parametrize("pose", [[3.0, 2.0, 0.0], [0.7, 3.1, 2.2], [5.5, 0.4, -1.0]])
def test_box_room_ranges_equal_analytic_distances(pose):
    world = box_room()
    lidar = Lidar(beams=720, r_max=20.0, r_min=0.0)
    ranges = lidar.scan(world, pose)
    expected = analytic_box_ranges(pose[0], pose[1], lidar.angles + pose[2], 6.0, 4.0)
    np.testing.assert_allclose(ranges, expected, rtol=0, atol=1e-9)


def test_range_limits_and_noise():
    world = long_corridor()
    lidar = Lidar()  # RPLIDAR-like: 0.15 - 8 m
    r = lidar.scan(world, [2.0, 0.0, 0.0])
    assert np.isinf(r[0])
    assert r[90] == pytest.approx(1.085, abs=1e-9) and r[270] == pytest.approx(1.085, abs=1e-9)
    noisy = Lidar(noise=0.02).scan(world, [2.0, 0.0, 0.0], rng=1)
    ok = np.isfinite(r)
    assert np.array_equal(ok, np.isfinite(noisy))
    assert abs((noisy[ok] - r[ok]).std() - 0.02) < 0.004
    assert np.array_equal(noisy, Lidar(noise=0.02).scan(world, [2.0, 0.0, 0.0], rng=1))


def test_corridor_recesses_are_seen():
    world = long_corridor()
    lidar = Lidar(beams=360)
    door = world.info["doors"][0]  # the first north door
    x = (door[1] + door[2]) / 2
    r = lidar.scan(world, [x, 0.0, 0.0])
    assert r[90] == pytest.approx(1.085 + 0.07, abs=1e-9)  # Ge et al. Eq. (2): d = w/2 + d_da


def test_scan_points_lie_on_walls():
    world = box_room()
    lidar = Lidar(r_max=20.0)
    pose = [2.0, 1.0, 0.4]
    pts = scan_points(lidar.scan(world, pose), lidar.sensor_pose(pose), lidar.angles)
    gap = np.min(np.abs(np.column_stack([pts[:, 0], pts[:, 0] - 6, pts[:, 1], pts[:, 1] - 4])), axis=1)
    assert gap.max() < 1e-9


def test_ray_segment_misses_give_inf():
    r = ray_segment_ranges([0, 0], [0.0, np.pi], [[[1, -1], [1, 1]]])
    assert r[0] == pytest.approx(1.0) and np.isinf(r[1])


def test_unicycle_matches_small_step_integration():
    pose = np.array([1.0, 2.0, 0.3])
    exact = mo.unicycle_step(pose, 0.5, 0.4, 2.0)
    p = pose.copy()
    for _ in range(20000):
        p = p + 1e-4 * np.array([0.5 * np.cos(p[2]), 0.5 * np.sin(p[2]), 0.4])
    np.testing.assert_allclose(exact[:2], p[:2], atol=1e-4)
    assert wrap_angle(exact[2] - p[2]) == pytest.approx(0, abs=1e-6)
    np.testing.assert_allclose(mo.unicycle_step(pose, 1.0, 0.0, 1.0), [1 + np.cos(0.3), 2 + np.sin(0.3), 0.3])


def test_drive_kinematics():
    v, w = mo.diff_drive_velocities(1.0, 3.0, wheel_radius=0.05, track=0.25)
    assert v == pytest.approx(0.1) and w == pytest.approx(0.4)
    v, w = mo.skid_steer_velocities(0.2, 0.4, track=0.3, chi=2.0)
    assert v == pytest.approx(0.3) and w == pytest.approx(0.2 / 0.6)
    with pytest.raises(ValueError, match="chi"):
        mo.skid_steer_velocities(0.2, 0.4, track=0.3, chi=0.5)


def test_odometry_noise_statistics_match_the_model():
    alphas = np.array([0.05, 0.01, 0.02, 0.03])
    prev, now = np.array([0.0, 0.0, 0.0]), np.array([0.8, 0.3, 0.9])
    rot1, trans, rot2 = mo.odometry_increment(prev, now)
    samples = mo.sample_motion_model_odometry(prev, now, np.zeros((200000, 3)), alphas, rng=7)
    got = mo.odometry_increment(np.zeros_like(samples), samples)
    var = np.array([alphas[0] * rot1 ** 2 + alphas[1] * trans ** 2,
                    alphas[2] * trans ** 2 + alphas[3] * (rot1 ** 2 + rot2 ** 2),
                    alphas[0] * rot2 ** 2 + alphas[1] * trans ** 2])
    err = got - [rot1, trans, rot2]
    err[:, [0, 2]] = wrap_angle(err[:, [0, 2]])
    np.testing.assert_allclose(err.mean(axis=0), 0, atol=3e-3)
    np.testing.assert_allclose(err.var(axis=0), var, rtol=0.03)


def test_noisy_odometry_drifts_and_zero_noise_is_exact():
    path = mo.lab_lap(lab_room())
    exact = mo.noisy_odometry(path.poses, [0, 0, 0, 0])
    np.testing.assert_allclose(exact[:, :2], path.poses[:, :2], atol=1e-9)
    noisy = mo.noisy_odometry(path.poses, [0.01, 0.001, 0.01, 0.001], rng=3)
    drift = np.linalg.norm(noisy[-1, :2] - path.poses[-1, :2])
    assert 0.01 < drift < 3.0
    assert np.array_equal(noisy, mo.noisy_odometry(path.poses, [0.01, 0.001, 0.01, 0.001], rng=3))


@pytest.mark.parametrize("make, world", [(mo.lab_lap, lab_room), (mo.corridor_path, long_corridor)])
def test_paths_stay_in_free_space(make, world):
    w = world()
    path = make(w)
    assert np.all(w.is_free(path.poses[:, :2], clearance=0.3))
    steps = np.linalg.norm(np.diff(path.poses[:, :2], axis=0), axis=1)
    assert steps.max() <= 0.3 / 10 + 1e-9  # speed 0.3 m/s at 10 Hz


@pytest.mark.parametrize("call, match", [
    (lambda: Lidar(beams=0), "beams"),
    (lambda: Lidar(r_min=2.0, r_max=1.0), "r_max"),
    (lambda: Lidar().scan(box_room(), [np.nan, 1, 0]), "robot_pose"),
    (lambda: Lidar().scan(box_room(), [9.0, 1, 0]), "robot_pose"),
    (lambda: mo.sample_motion_model_odometry([0, 0, 0], [1, 0, 0], [0, 0, 0], [-1, 0, 0, 0]), "alphas"),
    (lambda: mo.waypoint_path([[0, 0]]), "waypoints"),
    (lambda: mo.unicycle_step([0, 0, 0], 1.0, 0.0, -1.0), "dt"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()
