"""Lesson 02's checks measured (robocourse.lessons.omni_localization.checks) and the landmark map.

References: the simulator's true poses and surfaces; a map whose nodes are moved by a known amount.
"""
from __future__ import annotations

import numpy as np
import pytest

from robocourse.lessons.omni_localization import checks, experiment, landmarks
from robokit.sim import OFFICE_TEST_POSES


@pytest.fixture(scope="module")
def setup():
    return experiment.office_setup(fast=True)


def test_query_places_are_free_near_a_node_and_seeded(setup):
    places = checks.query_places(setup, 8, near=0.8, clearance=0.3, rng=4)
    assert places.shape == (8, 3)
    assert setup.world.is_free(places[:, :2], clearance=0.3).all()
    nearest = np.min(np.hypot(setup.truth[:, None, 0] - places[:, 0], setup.truth[:, None, 1] - places[:, 1]), axis=0)
    assert np.all(nearest <= 0.8)
    assert np.array_equal(places, checks.query_places(setup, 8, near=0.8, clearance=0.3, rng=4))
    with pytest.raises(ValueError, match="n"):
        checks.query_places(setup, 3, near=0.01, clearance=5.0)


def test_a_drive_turns_away_from_a_wall_and_stays_free(setup):
    # facing the office's east wall from 0.5 m: straight on is blocked, a quarter turn is not
    start = np.array([15.4, 2.5, 0.0])
    poses = checks.drive_on(setup, start, length=1.0, step=0.25)
    assert np.array_equal(poses[0], start) and len(poses) == 5
    assert abs(poses[1, 2]) > 1.0                               # it turned
    assert setup.world.is_free(poses[1:, :2], clearance=0.3).all()
    steps = np.hypot(*np.diff(poses[1:, :2], axis=0).T)
    assert np.allclose(steps, 0.25)
    with pytest.raises(ValueError, match="step"):
        checks.drive_on(setup, start, length=0.2, step=0.5)


def test_check_trials_agree_with_their_parts_and_come_back_from_the_cache(setup, monkeypatch, tmp_path):
    monkeypatch.setenv("ROBOKIT_CACHE", str(tmp_path))          # a cache of this test's own
    runs = []
    real = checks.map_runs
    monkeypatch.setattr(checks, "map_runs", lambda *a, **k: runs.append(1) or real(*a, **k))
    places = np.array(OFFICE_TEST_POSES[:2])
    first = checks.check_trials(setup, places, workers=1)
    assert runs == [1]
    for way in checks.WAYS:
        assert first.errors[way].shape == (2, 2)
    # the Monte-Carlo answer is the widened one wherever the check did not run or did not overturn it
    same = ~first.overturned
    assert np.array_equal(first.errors["monte_carlo"][same], first.errors["widened"][same])
    assert np.all(first.rounds >= 1)
    assert np.allclose(first.distances["fine"], np.hypot(*first.errors["fine"].T))
    # the same call is read back from the cache: no run is made; another seed is run again
    again = checks.check_trials(setup, places, workers=1)
    assert runs == [1] and all(np.array_equal(first.errors[w], again.errors[w]) for w in checks.WAYS)
    checks.check_trials(setup, places, seed=1, workers=1)
    assert runs == [1, 1]
    with pytest.raises(ValueError, match="map"):
        checks.check_trials(setup, places, map="best")


def test_mask_trials_count_pixels_and_rank_the_nearest_node(setup):
    out = checks.mask_trials(setup, OFFICE_TEST_POSES[:3], [0.0, 0.15, 1.0])
    assert out["kept"][0] > out["kept"][1] >= out["kept"][2] == 0.0      # a higher threshold keeps fewer pixels
    for key in ("top1", "top1_darker", "top1_noisy"):
        assert np.all((out[key] >= 0) & (out[key] <= out[key.replace("1", "5")]) & (out[key.replace("1", "5")] <= 1))
    # a query at a node's own pose, lit as in the map and noiseless, has that node's histogram: first
    at_nodes = checks.mask_trials(setup, setup.truth[[2, 20, 40]], [0.15], noise=0.0)
    assert at_nodes["top1"][0] == 1.0
    with pytest.raises(ValueError, match="thresholds"):
        checks.mask_trials(setup, OFFICE_TEST_POSES[:1], [1.5])
    with pytest.raises(ValueError, match="noise"):
        checks.mask_trials(setup, OFFICE_TEST_POSES[:1], [0.15], noise=-1.0)


def test_landmarks_lie_on_the_world_and_move_with_the_map(setup):
    true_map = setup.raw.with_poses(setup.truth)           # nodes where they were: no map error
    points, pairs = landmarks.landmark_map(true_map, setup.camera)
    assert len(points) > 100 and np.all(pairs[:, 1] == pairs[:, 0] + 1)
    # crossings lie on the world's walls and objects (the simulator knows where they are) far more
    # often than points spread evenly over the floor do
    on_world = ~setup.world.is_free(points, clearance=0.25)
    g = np.random.default_rng(0)
    x0, y0, x1, y1 = setup.world.bounds
    spread = np.column_stack([g.uniform(x0, x1, 2000), g.uniform(y0, y1, 2000)])
    baseline = (~setup.world.is_free(spread, clearance=0.25)).mean()
    assert on_world.mean() > 2 * baseline and on_world.mean() > 0.5, (on_world.mean(), baseline)
    # a map moved by (1, 2) m moves its landmarks by the same
    moved = true_map.with_poses(true_map.poses + [1.0, 2.0, 0.0])
    shifted, _ = landmarks.landmark_map(moved, setup.camera)
    assert np.allclose(shifted, points + [1.0, 2.0])
    with pytest.raises(ValueError, match="min_angle"):
        landmarks.landmark_map(setup.relaxed, setup.camera, min_angle=2.0)
    with pytest.raises(TypeError, match="tmap"):
        landmarks.landmark_map("map", setup.camera)
