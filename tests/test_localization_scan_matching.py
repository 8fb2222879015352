"""Correlative scan matching (Olson 2009) finds the heading and sideways position in the corridor."""
import numpy as np
import pytest

from robokit.geometry import wrap_angle
from robokit.localization import likelihood_field_log_weights, match_scan
from robokit.mapping import OccupancyGrid, likelihood_field, occupancy_grid_mapping
from robokit.sim import Lidar, corridor_path, long_corridor


@pytest.fixture(scope="module")
def corridor():
    world, lidar = long_corridor(), Lidar(noise=0.01, height=0.45)
    path = corridor_path(world, speed=0.3, rate=2.0)
    rng = np.random.default_rng(0)
    scans = np.array([lidar.scan(world, p, rng) for p in path.poses])
    grid = occupancy_grid_mapping(path.poses, scans, lidar.angles, (-0.5, -1.7, 36.6, 1.7), 0.05, r_max=lidar.r_max)
    return world, lidar, likelihood_field(grid)


def test_the_matcher_recovers_heading_and_sideways_position(corridor):
    world, lidar, field = corridor
    rng = np.random.default_rng(1)
    heading, lateral, along = [], [], []
    for _ in range(30):
        truth = np.array([rng.uniform(2.0, 34.0), rng.normal(0.0, 0.05), rng.choice([0.0, np.pi])])
        scan = lidar.scan(world, truth, rng)
        guess = truth + [rng.normal(0, 0.04), rng.normal(0, 0.04), np.deg2rad(rng.normal(0, 1.5))]
        best = match_scan(guess, scan, lidar.angles, field, window=(0.0, 0.15, np.deg2rad(3.0)), r_max=lidar.r_max)
        heading.append(abs(wrap_angle(best.pose[2] - truth[2])))
        lateral.append(abs(best.pose[1] - truth[1]))
        along.append(best.pose[0] - guess[0])
    assert np.mean(np.rad2deg(heading) <= 0.5) >= 0.9          # the filter's guesses: about 1.5 deg off
    assert np.median(lateral) < 0.02
    assert np.all(np.array(along) == 0.0)                      # a zero window keeps x exactly


def test_the_answer_fits_better_than_the_guess_when_the_truth_is_in_the_window(corridor):
    world, lidar, field = corridor
    rng = np.random.default_rng(2)
    for _ in range(5):
        truth = np.array([rng.uniform(2.0, 34.0), 0.0, 0.0])
        scan = lidar.scan(world, truth, rng)
        guess = truth + [0.0, 0.06, np.deg2rad(2.0)]
        got = match_scan(guess, scan, lidar.angles, field, window=(0.0, 0.1, np.deg2rad(3.0)), r_max=lidar.r_max)
        score = lambda pose: likelihood_field_log_weights(np.asarray(pose)[None], scan, lidar.angles, field,  # noqa: E731
                                                          sigma_hit=0.05, r_max=lidar.r_max, combine="product")[0]
        assert got.log_likelihood == pytest.approx(score(got.pose))
        assert score(got.pose) > score(guess) + 10.0              # 2 deg and 6 cm off cost a lot of beams
        assert abs(wrap_angle(got.pose[2] - truth[2])) < np.deg2rad(0.5)


@pytest.mark.parametrize("kwargs, error, match", [
    ({"steps": 4}, ValueError, "steps"), ({"window": (-0.1, 0.0, 0.0)}, ValueError, "window"),
    ({"window": (0.1, 0.1, 4.0)}, ValueError, "window"), ({"levels": 0}, ValueError, "levels"),
    ({"pose": [np.nan, 0.0, 0.0]}, ValueError, "pose"), ({"field": "map"}, TypeError, "field"),
    ({"sigma_hit": 0.0}, ValueError, "sigma_hit")])
def test_bad_input_is_named(kwargs, error, match):
    grid = OccupancyGrid.from_probability(np.eye(10), 0.1)
    args = {"pose": [0.5, 0.5, 0.0], "ranges": [1.0, 2.0], "angles": [0.0, 1.0], "field": likelihood_field(grid)}
    args.update(kwargs)
    with pytest.raises(error, match=match):
        match_scan(args.pop("pose"), args.pop("ranges"), args.pop("angles"), args.pop("field"), **args)
