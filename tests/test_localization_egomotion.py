"""RANSAC ego-motion (Lin et al. Sec. 4-7) on synthetic correspondences with known pose."""
import numpy as np
import pytest

from robokit.localization.egomotion import (DegenerateCorrespondenceError, InsufficientMatchesError,
                                            continuation_matches, fit_pose, pose_from_two,
                                            ransac_pose, ransac_sample_count, track)
from robokit.geometry import pqt_robot_to_world, pqt_world_to_robot
from robokit.mapping.landmarks import LandmarkMap

TRUE = np.array([0.35, 1.20, np.deg2rad(17.0)])


def _scene(rng, n=200, noise=0.01):
    world = rng.uniform([-4, 0, -4], [4, 2.5, 4], (n, 3))
    robot = pqt_world_to_robot(world, TRUE) + rng.normal(scale=noise, size=(n, 3))
    return robot, world


def _err(pose):
    return np.hypot(*(pose[:2] - TRUE[:2])), abs(np.angle(np.exp(1j * (pose[2] - TRUE[2]))))


def test_sample_count_formula():
    assert ransac_sample_count(0.5, 2, 0.99) == 17    # log(0.01) / log(0.75) = 16.01
    assert ransac_sample_count(0.0) == 1
    assert ransac_sample_count(0.8, 2, 0.99) == 113
    m = ransac_sample_count(0.3, 3, 0.95)
    assert 1 - (1 - 0.7 ** 3) ** m >= 0.95 > 1 - (1 - 0.7 ** 3) ** (m - 1)
    with pytest.raises(ValueError, match="contamination: expected a ratio in"):
        ransac_sample_count(1.0)
    with pytest.raises(ValueError, match="confidence"):
        ransac_sample_count(0.2, 2, 1.0)


def test_two_point_pose_is_exact_and_refuses_coincident_points():
    rng = np.random.default_rng(0)
    robot, world = _scene(rng, 2, noise=0.0)
    assert np.allclose(pose_from_two(robot, world), TRUE)
    with pytest.raises(DegenerateCorrespondenceError, match="coincident"):
        pose_from_two(np.array([[1.0, 0, 2], [1.0, 1.0, 2]]), world)  # same X, Z: no heading
    assert issubclass(DegenerateCorrespondenceError, ValueError)


def test_least_squares_fit_and_covariance():
    rng = np.random.default_rng(1)
    robot, world = _scene(rng, 300, noise=0.02)
    pose, cov, rms = fit_pose(robot, world)
    dt, dth = _err(pose)
    assert dt < 0.01 and dth < np.deg2rad(0.3)
    assert np.all(np.isfinite(cov)) and np.all(np.linalg.eigvalsh(cov) > 0)
    # the error is consistent with the reported covariance
    e = pose - TRUE
    assert e @ np.linalg.solve(cov, e) < 16.0
    with pytest.raises(DegenerateCorrespondenceError):
        fit_pose(np.tile([[1.0, 0.5, 2.0]], (5, 1)), world[:5])
    with pytest.raises(ValueError, match="at least 2 points"):
        fit_pose(robot[:1], world[:1])


def test_ransac_recovers_the_pose_with_half_outliers():
    rng = np.random.default_rng(2)
    robot, world = _scene(rng, 200)
    bad = rng.permutation(200)[:100]
    world[bad] = rng.uniform([-4, 0, -4], [4, 2.5, 4], (100, 3))
    res = ransac_pose(robot, world, rng=3)
    dt, dth = _err(res.pqt)
    assert res.source == "ransac"
    assert dt < 0.01 and dth < np.deg2rad(0.3)
    truly_good = np.ones(200, bool)
    truly_good[bad] = False
    assert np.mean(res.inliers == truly_good) > 0.97
    assert res.iterations < 500  # adaptive count: eps ~ 0.5 needs ~17 samples
    assert res.rms < 0.05


def test_too_few_or_degenerate_matches_fall_back_to_odometry():
    rng = np.random.default_rng(4)
    robot, world = _scene(rng, 10)
    odo = TRUE + [0.05, -0.05, 0.01]
    res = ransac_pose(robot, world, odometry=odo)
    assert res.source == "odometry" and np.allclose(res.pqt, odo) and res.n_inliers == 0
    with pytest.raises(InsufficientMatchesError, match="only 10 matches"):
        ransac_pose(robot, world)
    with pytest.raises(InsufficientMatchesError, match="only 1 matches"):
        ransac_pose(robot[:1], world[:1])
    same = np.tile(robot[:1], (30, 1))
    res = ransac_pose(same, np.tile(world[:1], (30, 1)), odometry=odo)
    assert res.source == "odometry" and np.all(np.isfinite(res.pqt))
    # pure outliers: nothing reaches 15 supporting matches
    res = ransac_pose(robot, rng.permutation(world), min_matches=8, odometry=odo)
    assert res.source == "odometry"


def _map_and_view(rng, n=300, dim=16):
    world = rng.uniform([-5, 0, -5], [5, 2.5, 5], (n, 3))
    desc = rng.normal(size=(n, dim)).astype(np.float32)
    desc /= np.linalg.norm(desc, axis=1, keepdims=True)
    lm = LandmarkMap(dim)
    lm.add(world, np.stack([np.eye(3) * 1e-4] * n), desc)
    robot = pqt_world_to_robot(world, TRUE) + rng.normal(scale=0.01, size=(n, 3))
    noisy = desc + rng.normal(scale=0.03, size=desc.shape).astype(np.float32)
    return lm, robot, noisy


def test_continuation_window_finds_the_right_landmarks():
    rng = np.random.default_rng(5)
    lm, robot, desc = _map_and_view(rng)
    fi, li = continuation_matches(robot, desc, lm, TRUE + [0.05, 0.05, 0.01], window=0.3)
    assert fi.size > 250 and np.mean(fi == li) > 0.99
    # a wrong prediction puts the true landmarks outside the window
    fi, li = continuation_matches(robot, desc, lm, TRUE + [2.0, 0, 0], window=0.3)
    assert np.sum(fi == li) < 5


def test_tracking_uses_the_window_and_recovers_when_kidnapped():
    rng = np.random.default_rng(6)
    lm, robot, desc = _map_and_view(rng)
    res, fi, li, kidnapped = track(robot, desc, lm, TRUE + [0.05, -0.04, 0.02], rng=1)
    assert not kidnapped and res.source == "ransac" and max(_err(res.pqt)) < 0.01
    res, fi, li, kidnapped = track(robot, desc, lm, [3.0, -3.0, 2.0], rng=1)
    assert kidnapped and res.source == "ransac"
    dt, dth = _err(res.pqt)
    assert dt < 0.01 and dth < np.deg2rad(0.5) and np.all(fi == li)
    # scene changed completely: odometry is kept, no NaN
    other = rng.normal(size=desc.shape).astype(np.float32)
    res, fi, li, kidnapped = track(robot, other, lm, [3.0, -3.0, 2.0], rng=1)
    assert res.source == "odometry" and np.allclose(res.pqt, [3.0, -3.0, 2.0]) and fi.size == 0
    assert np.allclose(pqt_robot_to_world(pqt_world_to_robot(lm.positions[:3], TRUE), TRUE), lm.positions[:3])


def test_weighted_refinement_discounts_depth_uncertain_points():
    rng = np.random.default_rng(8)
    errs_w, errs_u, m2 = [], [], []
    for _ in range(30):
        world = rng.uniform([-4, 0, -4], [4, 2.5, 4], (60, 3))
        robot = pqt_world_to_robot(world, TRUE)
        depth_sigma = 0.005 + 0.05 * np.abs(robot[:, 2])          # stereo-like: grows with depth
        cov = np.zeros((60, 3, 3))
        cov[:, 0, 0] = cov[:, 1, 1] = 0.005 ** 2
        cov[:, 2, 2] = depth_sigma ** 2
        noisy = robot + rng.normal(size=(60, 3)) * np.sqrt(np.diagonal(cov, axis1=1, axis2=2))
        pw, cw, _ = fit_pose(noisy, world, robot_covariances=cov)
        pu, _, _ = fit_pose(noisy, world)
        errs_w.append(np.hypot(*(pw[:2] - TRUE[:2])))
        errs_u.append(np.hypot(*(pu[:2] - TRUE[:2])))
        e = pw - TRUE
        m2.append(e @ np.linalg.solve(cw, e))
    assert np.mean(errs_w) < 0.7 * np.mean(errs_u)
    assert 1.5 < np.mean(m2) < 4.5   # chi-square with 3 dof: the covariance is consistent


def test_bad_inputs_are_named():
    rng = np.random.default_rng(10)
    robot, world = _scene(rng, 20)
    with pytest.raises(ValueError, match=r"world_points: expected shape \(20, 3\)"):
        ransac_pose(robot, world[:5])
    with pytest.raises(ValueError, match="threshold: expected a positive number"):
        ransac_pose(robot, world, threshold=0.0)
    with pytest.raises(ValueError, match="odometry: expected shape"):
        track(robot, np.zeros((20, 16)), LandmarkMap(16), [0.0, 0.0])
    # an empty map cannot give a pose: odometry is kept
    res, fi, li, kidnapped = track(robot, np.zeros((20, 16)), LandmarkMap(16), [0.1, 0.2, 0.3])
    assert res.source == "odometry" and kidnapped and fi.size == 0
