"""Landmark database (Se et al. Sec. 3): Kalman fusion, backward transformation, ageing."""
import numpy as np
import pytest

from robokit.geometry import pqt_robot_to_world, pqt_world_to_robot
from robokit.mapping import LandmarkMap, kalman_fuse, transform_covariance


def _spd(rng, n, scale=0.01):
    m = rng.normal(size=(n, 3, 3)) * np.sqrt(scale)
    return m @ np.swapaxes(m, 1, 2) + 1e-4 * np.eye(3)


def test_kalman_fusion_formula_and_shrinking_uncertainty():
    rng = np.random.default_rng(1)
    s, r = rng.normal(size=(20, 3)), rng.normal(size=(20, 3))
    a, b = _spd(rng, 20), _spd(rng, 20)
    mean, cov = kalman_fuse(s, a, r, b)
    for i in range(20):
        ia, ib = np.linalg.inv(a[i]), np.linalg.inv(b[i])
        ref = np.linalg.inv(ia + ib)
        assert np.allclose(cov[i], ref)
        assert np.allclose(mean[i], ref @ (ia @ s[i] + ib @ r[i]))
        # fused covariance is below both inputs in the positive semi-definite order
        assert np.linalg.eigvalsh(a[i] - cov[i]).min() > -1e-12
        assert np.linalg.eigvalsh(b[i] - cov[i]).min() > -1e-12
    m1, c1 = kalman_fuse(s[0], a[0], r[0], b[0])
    assert np.allclose(m1, mean[0]) and np.allclose(c1, cov[0])
    # equal covariances: the average
    m2, c2 = kalman_fuse([0, 0, 0], np.eye(3), [2, 4, 6], np.eye(3))
    assert np.allclose(m2, [1, 2, 3]) and np.allclose(c2, 0.5 * np.eye(3))


def test_kalman_fusion_rejects_bad_covariances():
    with pytest.raises(ValueError, match="sigma: expected positive-definite"):
        kalman_fuse([0, 0, 0], np.zeros((3, 3)), [1, 1, 1], np.eye(3))
    with pytest.raises(ValueError, match="sigma_new: expected symmetric"):
        kalman_fuse([0, 0, 0], np.eye(3), [1, 1, 1], np.triu(np.ones((3, 3))))
    with pytest.raises(ValueError, match="r_new: expected shape"):
        kalman_fuse(np.zeros((2, 3)), np.stack([np.eye(3)] * 2), np.zeros((3, 3)), np.stack([np.eye(3)] * 2))


def test_backward_transformation_covariance_matches_monte_carlo():
    rng = np.random.default_rng(2)
    pt = np.array([[0.5, 0.3, 3.0]])
    cov = np.diag([0.001, 0.001, 0.02])[None]
    pqt = np.array([1.0, 2.0, 0.4])
    pqt_cov = np.diag([0.01 ** 2, 0.02 ** 2, np.deg2rad(1.0) ** 2])
    world, wcov = transform_covariance(pt, cov, pqt, pqt_cov)
    assert np.allclose(world, pqt_robot_to_world(pt, pqt))
    n = 40000
    samples_p = rng.multivariate_normal(pqt, pqt_cov, n)
    samples_r = rng.multivariate_normal(pt[0], cov[0], n)
    c, s = np.cos(samples_p[:, 2]), np.sin(samples_p[:, 2])
    out = np.column_stack([c * samples_r[:, 0] - s * samples_r[:, 2] + samples_p[:, 0], samples_r[:, 1],
                           s * samples_r[:, 0] + c * samples_r[:, 2] + samples_p[:, 1]])
    emp = np.cov(out.T)
    assert np.allclose(emp, wcov[0], rtol=0.05, atol=5e-5)
    # without the pose term the covariance would be too small
    _, only_obs = transform_covariance(pt, cov, pqt, np.zeros((3, 3)))
    assert np.trace(wcov[0]) > np.trace(only_obs[0])


def test_map_integrates_frames_and_forgets_unseen_landmarks():
    rng = np.random.default_rng(3)
    truth = rng.uniform([-3, 0, 1], [3, 2, 6], (30, 3))
    m = LandmarkMap(16, max_missed=2)
    desc = rng.random((30, 16)).astype(np.float32)
    obs_cov = np.stack([np.diag([1e-3, 1e-3, 1e-2])] * 30)
    poses = [np.array([0.0, 0.0, 0.0]), np.array([0.1, 0.3, 0.05]), np.array([0.2, 0.6, 0.1])]
    ids = None
    for k, pqt in enumerate(poses):
        robot = pqt_world_to_robot(truth, pqt) + rng.normal(size=(30, 3)) * [0.03, 0.03, 0.1]
        lm = -np.ones(30, int) if k == 0 else np.searchsorted(m.ids, ids)
        ids = m.integrate(robot, obs_cov, desc, pqt, np.diag([1e-6, 1e-6, 1e-8]), lm)
    assert len(m) == 30 and np.all(m.observations == 3)
    first_cov = np.trace(obs_cov[0])
    assert np.all(np.trace(m.covariances, axis1=1, axis2=2) < 0.5 * first_cov)
    assert np.array_equal(m.descriptors, desc)
    # landmarks 0..9 are no longer seen: dropped after more than max_missed frames
    for _ in range(3):
        keep = np.nonzero(~np.isin(m.ids, ids[:10]))[0]
        m.fuse(keep, m.positions[keep], m.covariances[keep])
        dropped = m.end_frame(keep)
    assert np.array_equal(np.sort(dropped), np.sort(ids[:10])) and len(m) == 20
    with pytest.raises(ValueError, match="landmark: expected -1 or rows"):
        m.integrate(truth[:1], obs_cov[:1], desc[:1], poses[0], np.eye(3) * 1e-6, [99])
    with pytest.raises(ValueError, match="index: expected each landmark at most once"):
        m.fuse([0, 0], truth[:2], obs_cov[:2])


def test_association_uses_pose_uncertainty_and_descriptors():
    rng = np.random.default_rng(9)
    world = rng.uniform([-3, 0, 1], [3, 2, 6], (40, 3))
    desc = rng.normal(size=(40, 16)).astype(np.float32)
    desc /= np.linalg.norm(desc, axis=1, keepdims=True)
    m = LandmarkMap(16)
    m.add(world, np.stack([np.eye(3) * 1e-4] * 40), desc)
    pqt = np.array([0.2, 0.1, 0.05])
    obs = pqt_world_to_robot(world, pqt) + rng.normal(scale=0.01, size=(40, 3))
    cov = np.stack([np.eye(3) * 1e-4] * 40)
    assert np.array_equal(m.associate(obs, cov, desc, pqt), np.arange(40))
    # same geometry, wrong descriptors: nothing associates
    assert np.all(m.associate(obs, cov, np.roll(desc, 1, axis=0), pqt) == -1)
    # an observation 10 cm off is outside a 1 cm-sigma gate but inside a 10 cm-sigma one
    off = obs.copy()
    off[0, 2] += 0.1
    assert m.associate(off, cov, desc, pqt)[0] == -1
    assert m.associate(off, np.stack([np.eye(3) * 1e-2] * 40), desc, pqt)[0] == 0
    assert np.all(LandmarkMap(16).associate(obs, cov, desc, pqt) == -1)


def test_a_map_round_trips_through_its_arrays_and_bad_arrays_are_named():
    lm = LandmarkMap(4)
    rng = np.random.default_rng(0)
    lm.add(rng.normal(size=(5, 3)), np.tile(np.eye(3) * 0.01, (5, 1, 1)), rng.normal(size=(5, 4)))
    arrays = lm.to_arrays("m_")
    back = LandmarkMap.from_arrays(arrays, "m_")
    assert len(back) == len(lm) and np.array_equal(back.positions, lm.positions)
    assert np.array_equal(back.add(np.zeros((1, 3)), np.eye(3)[None] * 0.01, np.zeros((1, 4))),
                          lm.add(np.zeros((1, 3)), np.eye(3)[None] * 0.01, np.zeros((1, 4))))   # ids continue alike
    flat = {**arrays, "m_descriptors": np.zeros(5)}
    with pytest.raises(ValueError, match="descriptors of shape"):
        LandmarkMap.from_arrays(flat, "m_")
    with pytest.raises(ValueError, match="missing"):
        LandmarkMap.from_arrays({}, "m_")
