"""LiDAR against closed-form ranges; odometry noise statistics and paths (kinematics: test_sim_vehicle.py)."""
import numpy as np
import pytest

from robokit.geometry import wrap_angle
from robokit.sim import motion as mo
from robokit.sim.layout import Layout
from robokit.sim.lidar import Lidar, scan_points
from robokit.sim.worlds import box_room, lab_room, long_corridor, office_floor


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
    r = Layout(segments=[[[1, -1], [1, 1]]]).raycast([0, 0], [0.0, np.pi])
    assert r[0] == pytest.approx(1.0) and np.isinf(r[1])


def test_scan_uses_the_cached_layout_of_the_world_slice():
    world = long_corridor()
    assert world.layout(0.25) is world.layout(0.25)
    lidar = Lidar(beams=90)
    sensor = lidar.sensor_pose([5.0, 0.2, 0.4])
    true = world.layout(lidar.height).raycast(sensor[:2], lidar.angles + sensor[2])
    expected = np.where((true >= lidar.r_min) & (true <= lidar.r_max), true, np.inf)
    np.testing.assert_array_equal(lidar.scan(world, [5.0, 0.2, 0.4]), expected)


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


@pytest.mark.parametrize("make, world", [(mo.lab_lap, lab_room), (mo.corridor_path, long_corridor),
                                         (mo.office_tour, office_floor)])
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
    (lambda: mo.office_tour(lab_room()), "world"),
    (lambda: mo.office_tour(office_floor(), speed=0.0), "speed"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_office_tour_visits_every_room_and_closes_loops():
    w = office_floor()
    tour = mo.office_tour(w, rate=2.0)
    xy = tour.poses[:, :2]
    for name, (x0, y0, x1, y1) in w.info["rooms"].items():
        inside = (xy[:, 0] > x0) & (xy[:, 0] < x1) & (xy[:, 1] > y0) & (xy[:, 1] < y1)
        assert inside.sum() > 20, name                                   # > 10 s in every room
    corridor = (xy[:, 1] > 5.0) & (xy[:, 1] < 7.0)
    assert corridor.sum() > 40
    # the start is revisited twice: after the R1 lap and at the end of the floor loop
    near_start = np.linalg.norm(xy - xy[0], axis=1) < 0.3
    visits = np.flatnonzero(np.diff(near_start.astype(int)) == 1)
    assert len(visits) >= 2
    length = np.linalg.norm(np.diff(xy, axis=0), axis=1).sum()
    assert 90.0 < length < 110.0
    tests = np.array(mo.OFFICE_TEST_POSES)
    assert len(tests) == 11 and np.all(w.is_free(tests[:, :2], clearance=0.3))
    off_path = np.linalg.norm(tests[:, None, :2] - xy[None], axis=2).min(axis=1)
    assert np.all((off_path > 0.15) & (off_path < 0.35)), off_path


def test_odometry_covariance_matches_monte_carlo_of_the_noise_model():
    from robokit.geometry import se2_between, wrap_angle
    truth = mo.waypoint_path([[0, 0], [2, 0], [2, 1.5]], speed=0.5, rate=2).poses
    alphas = [0.02, 0.002, 0.02, 0.002]
    cov = mo.odometry_covariance(truth, alphas)
    assert cov.shape == (len(truth), 3, 3) and np.all(cov[0] == 0)
    rng = np.random.default_rng(0)
    ends = np.array([se2_between(o[0], o[-1]) for o in (mo.noisy_odometry(truth, alphas, rng) for _ in range(3000))])
    ends[:, 2] = wrap_angle(ends[:, 2] - np.mean(ends[:, 2]))
    empirical = np.cov(ends.T)
    assert np.allclose(empirical, cov[-1], rtol=0.15, atol=2e-4), (empirical, cov[-1])
    assert np.allclose(mo.increment_variances(np.zeros(3), alphas), 0.0)


def test_odometry_covariance_of_a_turn_on_the_spot_with_a_slip_is_a_small_rotations():
    """Noisy odometry of a turn moves millimetres in a random direction; that is no half turn."""
    from robokit.sim import odometry_covariance
    alphas = [0.005, 0.0005, 0.005, 0.0005]
    clean = odometry_covariance([[0.0, 0.0, 0.0], [0.0, 0.0, 0.3]], alphas)[-1]
    for slip in ([-0.003, 0.0], [0.003, 0.0], [0.0, -0.003]):
        slipped = odometry_covariance([[0.0, 0.0, 0.0], [*slip, 0.3]], alphas)[-1]
        assert slipped[2, 2] < 2 * clean[2, 2], (slip, slipped[2, 2], clean[2, 2])


def test_a_scan_over_a_layout_is_the_scan_over_the_world_it_came_from():
    from robokit.sim import Layout, long_corridor
    corridor, lidar = long_corridor(), Lidar(noise=0.01, height=0.45)
    pose = [12.3, 0.2, 0.4]
    np.testing.assert_array_equal(lidar.scan(corridor, pose, rng=3),
                                  lidar.scan_layout(corridor.layout(0.45), pose, rng=3))
    with pytest.raises(TypeError, match="layout"):
        lidar.scan_layout(corridor, pose)
    with pytest.raises(ValueError, match="robot_pose"):
        lidar.scan_layout(Layout(), [np.nan, 0.0, 0.0])


def test_noisy_odometry_composes_increments_as_table_5_6_does():
    """The loop in noisy_odometry is the readable per-step composition spelt out: same bits.

    With zero noise the increments are the true ones (Table 5.5), so the odometry is the
    step-by-step composition of Table 5.6, lines 8-10, which this reference writes as arrays.
    """
    rng = np.random.default_rng(5)
    for _ in range(20):
        steps = rng.normal(0.0, [0.1, 0.1, 0.6], (int(rng.integers(2, 200)), 3))
        truth = np.cumsum(steps, axis=0)
        truth[:, 2] = wrap_angle(truth[:, 2])
        d = mo.odometry_increment(truth[:-1], truth[1:])
        ref = [truth[0]]
        for k in range(len(d)):
            th = ref[-1][2] + d[k, 0]
            ref.append(np.stack([ref[-1][0] + d[k, 1] * np.cos(th), ref[-1][1] + d[k, 1] * np.sin(th),
                                 wrap_angle(th + d[k, 2])]))
        assert np.array_equal(mo.noisy_odometry(truth, [0.0, 0.0, 0.0, 0.0], rng=0), np.array(ref))


def test_noisy_odometry_refuses_a_trajectory_that_overflows():
    with pytest.raises(ValueError, match="poses"):
        mo.noisy_odometry([[0.0, 0.0, 0.1], [1e300, -1e300, 2.0], [-1e300, 1e300, -3.0]], [0.01, 0.001, 0.01, 0.001],
                          rng=0)
