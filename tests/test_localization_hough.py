"""Hough-transform global localization (Se et al. Sec. 5) on synthetic lab maps."""
import numpy as np
import pytest

from robokit.localization.egomotion import InsufficientMatchesError
from robokit.localization.hough import candidate_matches, global_localize, hough_accumulator
from robokit.geometry import pqt_world_to_robot
from robokit.mapping.landmarks import LandmarkMap
from robokit.vision.stereo import StereoCalibration, disparity_to_point

RIG = StereoCalibration(focal=400.0, c0=319.5, r0=239.5, baseline=0.12)


def lab_landmarks(rng, n_landmarks=5000, dim=16):
    """True landmark positions and descriptors of a 10 m x 10 m lab (60 % on walls, 40 % furniture)."""
    wall = rng.integers(0, 6, n_landmarks)
    u = rng.uniform(-5, 5, n_landmarks)
    x = np.where(wall == 0, -5.0, np.where(wall == 1, 5.0, u))
    z = np.where(wall == 2, -5.0, np.where(wall == 3, 5.0, u))
    inside = wall >= 4
    x[inside], z[inside] = rng.uniform(-4.5, 4.5, (2, inside.sum()))
    world = np.column_stack([x, rng.uniform(-1.0, 1.5, n_landmarks), z])
    desc = rng.normal(size=(n_landmarks, dim)).astype(np.float32)
    desc /= np.linalg.norm(desc, axis=1, keepdims=True)
    return world, desc


def stereo_view(rng, world, desc, pose, clutter=0.3, descriptor_noise=0.05, max_range=8.0):
    """Noisy stereo observations of the landmarks visible from ``pose`` plus clutter features.

    Returns robot-frame points, covariances, descriptors and the true landmark row (-1 for
    clutter). Image noise follows Se et al. Sec. 3.1 (sigma_c = sigma_r = sigma_d = 1 px).
    """
    dim = desc.shape[1]
    robot = pqt_world_to_robot(world, pose)
    visible = (robot[:, 2] > 0.5) & (robot[:, 2] < max_range) & (np.abs(robot[:, 0]) < 0.75 * robot[:, 2]) \
        & (np.abs(robot[:, 1]) < 0.55 * robot[:, 2])
    rows = np.nonzero(visible)[0]
    v = robot[rows]
    c = RIG.c0 + RIG.focal * v[:, 0] / v[:, 2] + rng.normal(size=rows.size)
    r = RIG.r0 - RIG.focal * v[:, 1] / v[:, 2] + rng.normal(size=rows.size)
    d = RIG.focal * RIG.baseline / v[:, 2] + rng.normal(size=rows.size)
    ok = d > 1
    pts, cov = disparity_to_point(c[ok], r[ok], d[ok], RIG)
    rows = rows[ok]
    vd = desc[rows] + rng.normal(scale=descriptor_noise, size=(rows.size, dim)).astype(np.float32)
    n_clutter = int(clutter * rows.size)
    cl = rng.uniform([-2, -1, 1], [2, 1.5, 5], (n_clutter, 3))
    cl_pts, cl_cov = disparity_to_point(RIG.c0 + RIG.focal * cl[:, 0] / cl[:, 2],
                                        RIG.r0 - RIG.focal * cl[:, 1] / cl[:, 2],
                                        RIG.focal * RIG.baseline / cl[:, 2], RIG)
    cd = rng.normal(size=(n_clutter, dim)).astype(np.float32)
    cd /= np.linalg.norm(cd, axis=1, keepdims=True)
    return (np.vstack([pts, cl_pts]), np.concatenate([cov, cl_cov]), np.vstack([vd, cd]),
            np.concatenate([rows, -np.ones(n_clutter, int)]))


def lab_map_and_view(rng, pose, n_landmarks=5000, dim=16, clutter=0.3, descriptor_noise=0.05):
    """A mapped lab (landmark covariance 2 cm per axis) and a noisy stereo view from ``pose``."""
    world, desc = lab_landmarks(rng, n_landmarks, dim)
    lm = LandmarkMap(dim)
    lm.add(world, np.stack([np.diag([4e-4, 4e-4, 4e-4])] * n_landmarks), desc)
    return lm, stereo_view(rng, world, desc, pose, clutter, descriptor_noise)


# Se et al. Sec. 6 test poses (cm, degrees) converted to metres and radians; signs as printed
POSES = [(0.45, 0.90, 25), (0.90, 1.80, -5), (0.70, 3.00, -40), (0.0, -1.50, 0), (0.0, 0.0, 0),
         (0.0, 0.0, 15), (-1.00, 0.10, -90), (-0.10, -0.70, 130)]


def test_candidates_respect_descriptor_and_height():
    rng = np.random.default_rng(0)
    lm, (pts, cov, desc, truth) = lab_map_and_view(rng, np.array([0.0, 0.0, 0.0]), n_landmarks=1000)
    fi, li = candidate_matches(pts, desc, lm)
    real = truth[fi] >= 0
    assert np.mean(li[real] == truth[fi][real]) > 0.3
    assert np.all(np.abs(pts[fi, 1] - lm.positions[li, 1]) <= 0.2)
    found = {f for f, l in zip(fi, li) if truth[f] == l}
    assert len(found) > 0.9 * np.sum(truth >= 0)


def test_single_vote_fills_its_rectangle():
    acc, thetas = hough_accumulator([[0.0, 1.0]], [np.eye(2) * 1e-6], [[2.0, 3.0]], [np.eye(2) * (0.1 / 2.8) ** 2],
                                    (0, 4, 0, 4), bin_size=0.04)
    assert acc.shape == (180, 100, 100) and acc.max() == 1
    t = np.argmin(np.abs(thetas - 0.0))
    # theta ~ 0: (p, q) = (2, 3) - (0, 1) = (2, 2), +-0.1 m, i.e. about 5 bins x 5 bins each side
    assert acc[t, 50, 50] == 1 and acc[t, 50, 52] == 1 and acc[t, 50, 56] == 0
    assert 5 <= acc[t].sum(axis=0).max() <= 6  # +-0.1 m in X at 4 cm bins
    assert acc.sum() > 0 and np.all(acc >= 0)
    with pytest.raises(ValueError, match="bounds: expected x_min < x_max"):
        hough_accumulator([[0.0, 1.0]], [np.eye(2)], [[2.0, 3.0]], [np.eye(2)], (4, 0, 0, 4))


@pytest.mark.parametrize("case", range(len(POSES)))
def test_global_localization_in_a_synthetic_lab(case):
    x, z, deg = POSES[case]
    pose = np.array([x, z, np.deg2rad(deg)])
    rng = np.random.default_rng(100 + case)
    lm, (pts, cov, desc, truth) = lab_map_and_view(rng, pose)
    best, hyps = global_localize(pts, cov, desc, lm)
    err_t = np.hypot(*(best.pqt[:2] - pose[:2]))
    err_r = abs(np.angle(np.exp(1j * (best.pqt[2] - pose[2]))))
    assert err_t < 0.05 and err_r < np.deg2rad(1.2), (err_t, np.rad2deg(err_r))
    assert best.n_matches >= 15 and len(hyps) <= 10
    assert np.mean(truth[best.feature_index] == best.landmark_row) > 0.95
    assert all(h.n_matches <= best.n_matches for h in hyps)


def test_unknown_scene_raises_instead_of_returning_nan():
    rng = np.random.default_rng(7)
    lm, (pts, cov, desc, _) = lab_map_and_view(rng, np.zeros(3), n_landmarks=500)
    other = rng.normal(size=desc.shape).astype(np.float32)
    other /= np.linalg.norm(other, axis=1, keepdims=True)
    with pytest.raises(InsufficientMatchesError):
        global_localize(pts, cov, other, lm)
    with pytest.raises(InsufficientMatchesError, match="only 0 potential matches"):
        global_localize(pts[:0], cov[:0], desc[:0], lm)


def test_hough_inputs_are_validated():
    rng = np.random.default_rng(3)
    lm, (pts, cov, desc, _) = lab_map_and_view(rng, np.zeros(3), n_landmarks=300)
    with pytest.raises(TypeError, match="landmarks: expected LandmarkMap"):
        global_localize(pts, cov, desc, lm.positions)
    with pytest.raises(ValueError, match="descriptors: expected shape"):
        global_localize(pts, cov, desc[:, :8], lm)
    with pytest.raises(ValueError, match="bounds: the Hough space would have"):
        global_localize(pts, cov, desc, lm, bounds=(-100, 100, -100, 100))
