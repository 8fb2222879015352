"""The closed loop of lesson 02: visual fixes and odometry through the EKF, Eq. (8) on the estimate."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from robokit.controllers import path_from_poses, reference_point
from robokit.navigation import follow_path, perturbed_starts
from robokit.navigation.visual_path import gaussian_localizer

#: Through a doorway and round a corner, like the paper's rooms and corridor (11.5 m, radius >= 1.1 m).
KEY = [[0, 0, 0], [2, 0, 0], [4, 0.5, 0], [5, 2, 0], [5, 4, 0], [6, 5, 0], [8, 5, 0]]


@pytest.fixture(scope="module")
def path():
    return path_from_poses(KEY)


@pytest.fixture(scope="module")
def twenty_runs(path):
    starts = perturbed_starts(path, 20, offset=0.3, heading=0.3, rng=7)
    return starts, [follow_path(path, s, localize=gaussian_localizer(), fix_period=0.5, rng=100 + i)
                    for i, s in enumerate(starts)]


def test_perturbed_starts_are_near_the_start_and_roughly_aligned(path):
    starts = perturbed_starts(path, 200, offset=0.3, heading=0.2, rng=1)
    refs = [reference_point(path, s) for s in starts]
    assert all(abs(r.d) <= 0.3 + 1e-9 and -1e-9 <= r.s <= 0.3 + 1e-9 for r in refs)
    assert all(abs(r.theta_tilde) <= 0.2 + 1e-9 for r in refs)
    assert np.array_equal(starts, perturbed_starts(path, 200, offset=0.3, heading=0.2, rng=1))
    assert np.std([r.d for r in refs]) > 0.1                               # spread over both sides


def test_twenty_perturbed_starts_reach_the_goal(twenty_runs):
    """Fig. 13 of the paper: starts near the path converge; fixes at 2 Hz with the paper's errors."""
    _, runs = twenty_runs
    reached = np.array([r.reached for r in runs])
    final = np.array([r.final_error for r in runs])
    assert reached.mean() == 1.0, f"success {reached.mean():.0%}"
    assert final.max() < 0.25 and final.mean() < 0.15, final


def test_the_robot_ends_on_the_path_and_the_filter_beats_the_raw_fixes(twenty_runs):
    _, runs = twenty_runs
    for r in runs:
        settled = r.times > r.times[0] + 15.0                               # after about 4.5 m
        assert np.sqrt(np.mean(r.cross_track[settled] ** 2)) < 0.08
        est_error = np.hypot(*(r.estimated_poses[:, :2] - r.true_poses[:, :2]).T)
        fix_times = np.searchsorted(r.times, r.fixes[:, 0])
        fix_error = np.hypot(*(r.fixes[:, 1:3] - r.true_poses[np.minimum(fix_times, len(r.times) - 1), :2]).T)
        assert np.sqrt(np.mean(est_error ** 2)) < 0.6 * np.sqrt(np.mean(fix_error ** 2))
        assert len(r.fixes) == pytest.approx(r.times[-1] / 0.5 + 1, abs=1)  # 2 Hz


def test_the_commands_respect_the_limits_and_stop_at_the_end(twenty_runs):
    _, runs = twenty_runs
    for r in runs:
        assert np.all(np.abs(r.commands[:, 1]) <= 1.0 + 1e-12) and np.all(r.commands[:, 0] <= 0.3 + 1e-12)
        assert tuple(r.commands[-1]) == (0.0, 0.0)
        assert len(r.times) == len(r.true_poses) == len(r.estimated_poses) == len(r.cross_track) == len(r.covariances)
        steps = np.linalg.norm(np.diff(r.true_poses[:, :2], axis=0), axis=1)
        assert np.allclose(steps, r.commands[:-1, 0] * 0.1, atol=1e-3)    # the truth moved by the commands


def test_the_robot_waits_for_its_first_fix(path):
    calls = []

    def late(pose, rng):
        calls.append(pose.copy())
        return None if len(calls) < 4 else pose + 0.01

    run = follow_path(path, [0.0, 0.1, 0.0], localize=late, max_time=5.0, rng=0)
    assert np.allclose(calls[:4], [0.0, 0.1, 0.0])                         # it did not move while waiting
    assert run.times[0] == pytest.approx(1.5) and run.fixes[0, 0] == pytest.approx(1.5)
    never = follow_path(path, [0.0, 0.1, 0.0], localize=lambda p, r: None, max_time=3.0)
    assert not never.reached and len(never.times) == 0 and never.final_error == pytest.approx(math.hypot(8, 4.9))


def test_a_gate_keeps_false_recognitions_from_pulling_the_robot_off(path):
    """The paper's failures come from false recognitions; a chi-square gate on the fix rejects them."""
    liar = gaussian_localizer(outlier_rate=0.15, outlier_offset=1.5)
    gated = [follow_path(path, [0.0, 0.1, 0.0], localize=liar, gate=chi2.ppf(0.999, 3), rng=s) for s in range(6)]
    naive = [follow_path(path, [0.0, 0.1, 0.0], localize=liar, rng=s) for s in range(6)]

    def rms(runs):
        return np.mean([np.sqrt(np.mean(r.cross_track ** 2)) for r in runs])

    assert all(r.reached for r in gated)
    assert rms(gated) < 0.85 * rms(naive)                                 # measured 0.077 against 0.103 m


def test_a_fix_that_is_not_a_pose_is_refused(path):
    with pytest.raises(ValueError, match="localize's fix: expected shape"):
        follow_path(path, [0.0, 0.0, 0.0], localize=lambda p, r: p[:2])
    with pytest.raises(ValueError, match="localize's fix: expected finite"):
        follow_path(path, [0.0, 0.0, 0.0], localize=lambda p, r: p * np.nan)
