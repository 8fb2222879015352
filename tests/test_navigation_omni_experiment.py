"""Lesson 02's experiments: the cached navigation runs come back exactly, the trials are what they say."""
from __future__ import annotations

import numpy as np
import pytest

from robokit.cache import cache_dir
from robokit.geometry import se2_compose
from robocourse.lessons.omni_localization import experiment
from robocourse.lessons.omni_localization import navigation
from robokit.sim import OFFICE_TEST_POSES


@pytest.fixture(scope="module")
def setup():
    return experiment.office_setup(fast=True)


def test_the_map_starts_where_the_truth_starts_and_relaxation_helps(setup):
    assert np.allclose(setup.raw.poses[0], setup.truth[0])          # the map's frame is the odometry's
    error = {name: np.sqrt(np.mean(np.sum((m.poses[:, :2] - setup.truth[:, :2]) ** 2, axis=1)))
             for name, m in (("raw", setup.raw), ("relaxed", setup.relaxed))}
    assert error["relaxed"] < 0.5 * error["raw"], error


def test_coarse_answers_are_node_poses_and_local_errors_exclude_the_map(setup):
    trials = experiment.localization_trials(setup, OFFICE_TEST_POSES[:3], modes=("coarse", "fine"))
    for est in trials.estimates["coarse"]:
        assert np.min(np.abs(setup.relaxed.poses - est).sum(axis=1)) < 1e-12
    for k, r in enumerate(trials.results["fine"]):        # the node's true pose composed with the relative pose
        relative = np.zeros(3) if r.relative is None else r.relative.pose
        local = se2_compose(setup.truth[r.node], relative)
        assert np.allclose(trials.local_errors["fine"][k], np.abs(local[:2] - OFFICE_TEST_POSES[k][:2]))

def test_navigation_runs_are_cached_judged_on_the_truth_and_a_corrupt_cache_is_rerun(setup):
    kwargs = dict(n_path_nodes=3, max_time=8.0, seed=5)
    before = set(cache_dir("navigation").glob("*.npz"))
    first = navigation.navigation_trials(setup, 1, **kwargs)
    new = set(cache_dir("navigation").glob("*.npz")) - before
    again = navigation.navigation_trials(setup, 1, **kwargs)
    assert np.array_equal(first.path.poses, again.path.poses) and np.array_equal(first.nodes, again.nodes)
    for a, b in zip(first.runs, again.runs):
        assert np.array_equal(a.true_poses, b.true_poses) and np.array_equal(a.fixes, b.fixes)
        assert a.reached == b.reached and a.final_error == b.final_error
    goal = setup.truth[first.nodes[-1], :2]                   # the target node's true position, not the map's
    assert np.allclose(first.goal_errors, [np.hypot(*(r.true_poses[-1, :2] - goal)) for r in first.runs])
    assert np.array_equal(first.success, first.goal_errors <= first.success_radius)
    for target in new:
        target.write_bytes(b"not a zip")
    rerun = navigation.navigation_trials(setup, 1, **kwargs)
    assert np.array_equal(rerun.runs[0].true_poses, first.runs[0].true_poses)


def test_bad_arguments_name_themselves(setup):
    with pytest.raises(TypeError, match="setup"):
        experiment.localization_trials("office", OFFICE_TEST_POSES)
    with pytest.raises(ValueError, match="modes"):
        experiment.localization_trials(setup, OFFICE_TEST_POSES, modes=("guess",))
    with pytest.raises(ValueError, match="n_path_nodes"):
        navigation.navigation_trials(setup, 1, n_path_nodes=len(setup.relaxed), clearance=2.0)
