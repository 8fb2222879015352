"""fit_se3 / fit_rigid: the one weighted rigid fit (Umeyama 1991), checked against scipy's
Rotation.align_vectors, noise-free round trips, hand-made reflections and the planar formula."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robokit.geometry import (DegenerateFitError, fit_rigid, fit_se2, fit_se3, rot_z, se3_from_rt, so3_exp,
                              transform_points)


def random_problem(rng, n):
    R = so3_exp(rng.normal(size=3) * 1.5)
    t = rng.normal(size=3)
    src = rng.uniform(-1, 1, (n, 3))
    return R, t, src, src @ R.T + t


@pytest.mark.parametrize("n", [3, 4, 7, 50])
def test_noise_free_round_trip_recovers_the_transform(n):
    rng = np.random.default_rng(n)
    for _ in range(20):
        R, t, src, tgt = random_problem(rng, n)
        T = fit_se3(src, tgt)
        assert np.abs(T[:3, :3] - R).max() < 1e-12 and np.abs(T[:3, 3] - t).max() < 1e-12
        assert T[3].tolist() == [0.0, 0.0, 0.0, 1.0]
        assert np.abs(transform_points(T, src) - tgt).max() < 1e-12


@pytest.mark.parametrize("seed", range(5))
def test_noisy_weighted_fit_matches_scipy_align_vectors(seed):
    rng = np.random.default_rng(seed)
    R, t, src, tgt = random_problem(rng, 12)
    tgt = tgt + rng.normal(scale=0.05, size=tgt.shape)
    w = rng.uniform(0.1, 3.0, 12)
    T = fit_se3(src, tgt, w)
    # scipy solves the rotation of the weighted-centred sets (Wahba's problem); the translation
    # follows from the weighted centroids
    cs, ct = np.average(src, axis=0, weights=w), np.average(tgt, axis=0, weights=w)
    rot, _ = Rotation.align_vectors(tgt - ct, src - cs, weights=w)
    assert np.abs(T[:3, :3] - rot.as_matrix()).max() < 1e-9
    assert np.abs(T[:3, 3] - (ct - rot.as_matrix() @ cs)).max() < 1e-9
    # and it is a minimum: small rotations and shifts of the answer cost more
    def cost(Rm, tv):
        return float((w * ((src @ Rm.T + tv - tgt) ** 2).sum(1)).sum())
    best = cost(T[:3, :3], T[:3, 3])
    for _ in range(20):
        dR, dt = so3_exp(rng.normal(scale=1e-3, size=3)), rng.normal(scale=1e-3, size=3)
        assert cost(dR @ T[:3, :3], T[:3, 3] + dt) > best


def test_a_mirrored_set_gets_the_best_rotation_not_a_reflection():
    rng = np.random.default_rng(3)
    src = rng.uniform(-1, 1, (6, 3))
    tgt = src * [1.0, 1.0, -1.0]                         # a mirror image: no rotation fits it exactly
    a, b = src - src.mean(0), tgt - tgt.mean(0)
    U, _, Vt = np.linalg.svd(b.T @ a)
    assert np.linalg.det(U @ Vt) < 0                     # Arun et al.'s plain SVD answer is a reflection
    T = fit_se3(src, tgt)
    assert abs(np.linalg.det(T[:3, :3]) - 1.0) < 1e-12
    rot, _ = Rotation.align_vectors(b, a)
    assert np.abs(T[:3, :3] - rot.as_matrix()).max() < 1e-9


def test_three_points_and_a_coplanar_set_are_fitted_exactly():
    rng = np.random.default_rng(4)
    for _ in range(20):
        R, t, src, _ = random_problem(rng, 5)
        src[:, 2] = 0.0                                  # coplanar: the correlation matrix has rank 2
        tgt = src @ R.T + t
        for k in (3, 5):
            T = fit_se3(src[:k], tgt[:k])
            assert np.abs(T[:3, :3] - R).max() < 1e-10 and np.abs(T[:3, 3] - t).max() < 1e-10


def test_zero_weight_drops_a_point_and_batches_match_single_fits():
    rng = np.random.default_rng(5)
    R, t, src, tgt = random_problem(rng, 6)
    bad = tgt.copy()
    bad[2] += 3.0
    w = np.ones(6)
    w[2] = 0.0
    T = fit_se3(src, bad, w)
    assert np.abs(T[:3, :3] - R).max() < 1e-12 and np.abs(T[:3, 3] - t).max() < 1e-12
    srcs = rng.uniform(-1, 1, (4, 5, 3))
    tgts = srcs + rng.normal(size=(4, 1, 3)) + rng.normal(scale=0.1, size=(4, 5, 3))
    weights = rng.uniform(0.5, 2.0, (4, 5))
    batch = fit_se3(srcs, tgts, weights)
    for i in range(4):
        assert np.abs(batch[i] - fit_se3(srcs[i], tgts[i], weights[i])).max() < 1e-12


def test_planar_points_agree_with_fit_se2_and_its_closed_form():
    rng = np.random.default_rng(6)
    src = rng.uniform(-2, 2, (8, 2))
    theta, xy = 2.5, np.array([0.3, -1.2])
    c, s = np.cos(theta), np.sin(theta)
    tgt = src @ np.array([[c, -s], [s, c]]).T + xy + rng.normal(scale=0.05, size=(8, 2))
    w = rng.uniform(0.2, 1.0, 8)
    pose = fit_se2(src, tgt, w)
    # the planar closed form by hand: theta = atan2(sum w (a x b), sum w (a . b)) of centred points
    a = src - np.average(src, axis=0, weights=w)
    b = tgt - np.average(tgt, axis=0, weights=w)
    hand = np.arctan2((w * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])).sum(), (w * (a * b).sum(1)).sum())
    assert abs(pose[2] - hand) < 1e-12
    T = fit_se3(np.column_stack([src, np.zeros(8)]), np.column_stack([tgt, np.zeros(8)]), w)
    assert np.abs(T[:3, :3] - rot_z(pose[2])).max() < 1e-12 and np.abs(T[:2, 3] - pose[:2]).max() < 1e-12


def test_degenerate_sets_raise_a_named_value_error():
    assert issubclass(DegenerateFitError, ValueError)
    line = np.outer(np.arange(5.0), [1.0, 2.0, -1.0])
    with pytest.raises(DegenerateFitError, match="source, target"):
        fit_se3(line, line + 1.0)                         # collinear: free rotation about the line
    with pytest.raises(DegenerateFitError, match="source"):
        fit_se3(np.eye(3)[:2], np.eye(3)[:2])             # two points
    with pytest.raises(DegenerateFitError):
        fit_se3(np.ones((4, 3)), np.eye(4, 3))            # coincident source points
    pts = np.eye(3)
    with pytest.raises(DegenerateFitError):
        fit_se3(np.vstack([pts, pts]), np.vstack([pts, pts]), [1, 1, 0, 0, 0, 0])   # two weighted points
    with pytest.raises(ValueError, match="target"):
        fit_se3(pts, np.eye(4, 3))
    with pytest.raises(ValueError, match="weights"):
        fit_se3(pts, pts, [1.0, -1.0, 1.0])
    with pytest.raises(ValueError, match="source"):
        fit_se3(np.eye(3)[:, :2], np.eye(3)[:, :2])       # planar points: fit_se2's job
    # the fast path flags the degenerate problem instead of raising
    fit = fit_rigid(np.stack([line, np.eye(5, 3)]), np.stack([line, np.eye(5, 3)]), validate=False)
    assert fit.degenerate.tolist() == [True, False]


def test_huge_coordinates_do_not_overflow():
    rng = np.random.default_rng(7)
    R, t, src, tgt = random_problem(rng, 5)
    T = fit_se3(src * 1e300, tgt * 1e300)
    assert np.all(np.isfinite(T)) and np.abs(T[:3, :3] - R).max() < 1e-9


def test_fit_se3_gives_T_world_body_from_markers():
    markers = np.array([[0.10, 0.03, 0.0115], [0.10, -0.04, 0.0115], [-0.11, 0.035, 0.0115], [-0.05, -0.02, 0.04]])
    T = se3_from_rt(so3_exp([0.1, -0.2, 2.0]), [1.0, 2.0, 0.13])
    assert np.abs(fit_se3(markers, transform_points(T, markers)) - T).max() < 1e-12


def _umeyama_svd_2d(source, target):
    """Umeyama's Eqs. (34)-(43) without scale, by numpy's SVD (the 3-D path's algorithm, in 2-D)."""
    a, b = source - source.mean(0), target - target.mean(0)
    U, sv, Vt = np.linalg.svd(b.T @ a / len(a))
    S = np.diag([1.0, np.sign(np.linalg.det(U) * np.linalg.det(Vt)) or 1.0])
    return U @ S @ Vt, sv


def test_the_planar_closed_form_equals_the_svd_rotation():
    """fit_rigid's d = 2 branch (atan2 of the correlation matrix) gives Umeyama's SVD rotation."""
    rng = np.random.default_rng(5)
    for k in range(300):
        n = int(rng.integers(2, 9))
        src = rng.normal(size=(n, 2)) * rng.uniform(0.01, 100)
        if k % 3 == 0:
            tgt = src * [1.0, -1.0] + rng.normal(scale=0.5, size=(n, 2))     # a mirror: a reflection fits best
        else:
            th = rng.uniform(-np.pi, np.pi)
            tgt = src @ np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]).T + rng.normal(scale=0.3, size=(n, 2))
        want, sv = _umeyama_svd_2d(src, tgt)
        if sv[0] - sv[1] < 1e-6 * sv[0]:
            continue                                  # no unique rotation: nothing to compare
        fit = fit_rigid(src, tgt, validate=False)
        np.testing.assert_allclose(fit.R, want, atol=1e-9)
        assert np.isclose(np.linalg.det(fit.R), 1.0)
    # a set whose best reflection and best rotation tie has no unique rotation: flagged
    sq = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    assert fit_rigid(sq, sq * [1.0, -1.0], validate=False).degenerate
    assert not fit_rigid(sq, sq, validate=False).degenerate
