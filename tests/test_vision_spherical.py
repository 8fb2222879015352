"""Two-view geometry on the sphere (robokit.vision.spherical) and planar RANSAC (robokit.vision.ransac).

References: synthetic scenes with known R, t; OpenCV's findEssentialMat / recoverPose on
pinhole-normalised points; the omni camera's own projection for floor points.
"""
import cv2
import numpy as np
import pytest

from robokit.geometry import fit_se2, se2_compose, skew, so3_exp
from robokit.sim import OmniCamera
from robokit.vision.ransac import ransac_se2
from robokit.vision.spherical import (as_bearings, decompose_essential, epipolar_error, essential_from_bearings,
                                      floor_points, ransac_essential)


def scene(n=60, seed=0, behind=True):
    """Points around camera 1, and a motion X2 = R X1 + t."""
    rng = np.random.default_rng(seed)
    X1 = rng.uniform(-5, 5, (n, 3))
    if not behind:
        X1[:, 2] = rng.uniform(2, 8, n)
    R = so3_exp(rng.normal(size=3) * 0.3)
    t = rng.normal(size=3)
    t *= 0.5 / np.linalg.norm(t)
    return X1, R, t, X1 @ R.T + t


def unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def same_up_to_sign(A, B):
    A, B = A / np.linalg.norm(A), B / np.linalg.norm(B)
    return min(np.abs(A - B).max(), np.abs(A + B).max())


@pytest.mark.parametrize("seed", range(5))
def test_eight_point_recovers_t_cross_r_from_bearings_all_around(seed):
    X1, R, t, X2 = scene(seed=seed)
    E = essential_from_bearings(X1, X2)                      # lengths do not matter: rays
    assert same_up_to_sign(E, skew(t) @ R) < 1e-9
    s = np.linalg.svd(E, compute_uv=False)
    assert np.allclose(s, [1, 1, 0], atol=1e-12)
    assert np.abs(epipolar_error(E, X1, X2)).max() < 1e-9


def test_minimal_eight_pairs_are_exact_and_seven_refused():
    X1, R, t, X2 = scene(n=8, seed=3)
    assert same_up_to_sign(essential_from_bearings(X1, X2), skew(t) @ R) < 1e-8
    with pytest.raises(ValueError, match="b1.*at least 8"):
        essential_from_bearings(X1[:7], X2[:7])


@pytest.mark.parametrize("seed", range(5))
def test_decomposition_picks_the_true_motion_with_rays_behind_the_camera(seed):
    X1, R, t, X2 = scene(seed=seed)
    assert (X1[:, 2] < 0).sum() > 10 and (X2[:, 2] < 0).sum() > 10      # many points "behind"
    R_est, t_est, front = decompose_essential(essential_from_bearings(X1, X2), X1, X2)
    assert np.abs(R_est - R).max() < 1e-8
    assert np.abs(t_est - unit(t)).max() < 1e-8
    assert front.all()


def test_pinhole_cheirality_would_choose_wrongly_where_rays_point_backwards():
    # all points behind camera 1's image plane: the z > 0 test rejects every one of them
    X1, R, t, X2 = scene(seed=7)
    back = X1[:, 2] < -1
    R_est, t_est, front = decompose_essential(essential_from_bearings(X1, X2), X1[back], X2[back])
    assert front.all() and np.abs(R_est - R).max() < 1e-6
    # the depths along the rays are the true ranges (up to the translation's scale)
    scale = np.linalg.norm(t)
    a = unit(X1[back]) @ R_est.T
    l1 = np.linalg.lstsq(np.column_stack([a[0], -unit(X2[back])[0]]), -scale * t_est, rcond=None)[0][0]
    assert l1 == pytest.approx(np.linalg.norm(X1[back][0]), rel=1e-6)


@pytest.mark.parametrize("seed", range(4))
def test_agrees_with_opencv_on_pinhole_normalised_points(seed):
    X1, R, t, X2 = scene(n=80, seed=seed, behind=False)
    keep = X2[:, 2] > 0.5
    X1, X2 = X1[keep], X2[keep]
    rng = np.random.default_rng(seed)
    p1 = X1[:, :2] / X1[:, 2:]
    p2 = X2[:, :2] / X2[:, 2:] + rng.normal(0, 1e-4, (len(X2), 2))
    E_cv, mask = cv2.findEssentialMat(p1, p2, np.eye(3), method=cv2.RANSAC, prob=0.999, threshold=1e-3)
    _, R_cv, t_cv, _ = cv2.recoverPose(E_cv[:3], p1, p2, np.eye(3))
    b1, b2 = np.column_stack([p1, np.ones(len(p1))]), np.column_stack([p2, np.ones(len(p2))])
    fit = ransac_essential(b1, b2, threshold=1e-3, rng=seed)
    R_est, t_est, _ = decompose_essential(fit.E, b1[fit.inliers], b2[fit.inliers])
    assert fit.ok and fit.n_inliers >= 0.95 * len(b1)
    assert np.abs(R_est - R_cv).max() < 2e-3 and np.abs(R_est - R).max() < 2e-3
    assert np.abs(t_est - t_cv.ravel()).max() < 2e-2 and np.abs(t_est - unit(t)).max() < 2e-2
    assert same_up_to_sign(fit.E, E_cv[:3]) < 2e-2


def test_ransac_rejects_false_matches_and_reports_failure_without_raising():
    X1, R, t, X2 = scene(n=100, seed=11)
    rng = np.random.default_rng(0)
    b1, b2 = unit(X1), unit(X2) + rng.normal(0, 1e-3, X2.shape)
    wrong = rng.permutation(100)[:35]
    b2[wrong] = b2[rng.permutation(wrong)]
    fit = ransac_essential(b1, b2, threshold=0.01, rng=1)
    truly_wrong = np.zeros(100, bool)
    truly_wrong[wrong] = epipolar_error(skew(t) @ R, b1[wrong], unit(b2[wrong])) > 0.01
    assert fit.ok and not fit.inliers[truly_wrong].any() and fit.inliers[~truly_wrong].mean() > 0.97
    assert fit.iterations >= 64
    R_est, t_est, _ = decompose_essential(fit.E, b1[fit.inliers], b2[fit.inliers])
    assert np.degrees(np.arccos((np.trace(R_est.T @ R) - 1) / 2)) < 0.3
    assert np.degrees(np.arccos(t_est @ unit(t))) < 3.0
    # pure noise: no model gathers min_inliers
    junk = ransac_essential(unit(rng.normal(size=(30, 3))), unit(rng.normal(size=(30, 3))), threshold=1e-4,
                            min_inliers=20, rng=0)
    assert not junk.ok and np.all(junk.E == 0)


def test_epipolar_error_is_an_angle_and_symmetric():
    E = skew([1.0, 0.0, 0.0])                                    # R = I, t = x
    # b2 tilted out of the epipolar plane (the xz plane) by a small angle a: Sampson shares it
    a = 1e-3
    b1, b2 = np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, np.sin(a), np.cos(a)]])
    assert epipolar_error(E, b1, b2)[0] == pytest.approx(a / np.sqrt(2), rel=1e-3)
    assert epipolar_error(E.T, b2, b1)[0] == pytest.approx(epipolar_error(E, b1, b2)[0])
    assert epipolar_error(np.stack([E, 2 * E]), b1, b2).shape == (2, 1)       # scale invariant
    assert np.ptp(epipolar_error(np.stack([E, 2 * E]), b1, b2)) < 1e-15


def test_floor_points_invert_the_omni_projection_of_floor_points():
    cam = OmniCamera()
    rng = np.random.default_rng(4)
    ang, rad = rng.uniform(-np.pi, np.pi, 50), rng.uniform(0.7, 2.5, 50)
    floor_body = np.column_stack([rad * np.cos(ang), rad * np.sin(ang), np.zeros(50)])
    T = cam.mount
    in_omni = (floor_body - T[:3, 3]) @ T[:3, :3]
    uv, _ = cam.project(in_omni)
    pts, ok = floor_points(cam.rays(uv), T, min_depression=np.arctan2(1.0, 2.6))
    assert ok.all()
    assert np.abs(pts - floor_body[:, :2]).max() < 1e-9
    # a point on a wall 0.5 m above the floor lifts twice as far as the wall: not on the floor
    wall = np.array([[1.2, 0.0, 0.5]])
    pts, ok = floor_points(cam.rays(cam.project((wall - T[:3, 3]) @ T[:3, :3])[0]), T)
    assert ok[0] and pts[0, 0] == pytest.approx(2.4)


def test_ground_plane_pose_from_two_omni_views_of_floor_features():
    cam = OmniCamera()
    rng = np.random.default_rng(5)
    floor = np.column_stack([rng.uniform(-2, 2, (80, 2)), np.zeros(80)])       # node frame = world
    query = np.array([0.25, -0.1, 0.4])                                          # pose of the query in the node
    T = cam.mount

    def bearings(pose):
        c, s = np.cos(pose[2]), np.sin(pose[2])
        body = (floor[:, :2] - pose[:2]) @ np.array([[c, -s], [s, c]])
        uv, _ = cam.project((np.column_stack([body, np.zeros(len(body))]) - T[:3, 3]) @ T[:3, :3])
        return uv + rng.normal(0, 0.3, uv.shape)

    uv_n, uv_q = bearings(np.zeros(3)), bearings(query)
    seen = ~np.isnan(uv_n).any(1) & ~np.isnan(uv_q).any(1)
    pn, vn = floor_points(cam.rays(uv_n[seen]), T)
    pq, vq = floor_points(cam.rays(uv_q[seen]), T)
    v = vn & vq
    pq_bad = pq[v].copy()
    pq_bad[:10] += rng.uniform(-1, 1, (10, 2))                                     # ten false matches
    fit = ransac_se2(pq_bad, pn[v], threshold=0.05, rng=0)
    assert fit.ok and not fit.inliers[:10].any()
    assert np.abs(fit.pose[:2] - query[:2]).max() < 0.01 and abs(fit.pose[2] - query[2]) < 0.005


def test_fit_se2_matches_a_known_transform_in_a_batch_and_with_weights():
    rng = np.random.default_rng(0)
    poses = rng.uniform([-2, -2, -3], [2, 2, 3], (5, 3))
    src = rng.uniform(-3, 3, (5, 7, 2))
    tgt = np.stack([se2_compose(p, np.column_stack([s, np.zeros(7)]))[:, :2] for p, s in zip(poses, src)])
    assert np.abs(fit_se2(src, tgt) - poses).max() < 1e-12
    # a weight of zero removes a corrupted point exactly
    bad = tgt[0].copy()
    bad[0] += 5.0
    w = np.ones(7)
    w[0] = 0.0
    assert np.abs(fit_se2(src[0], bad, w) - poses[0]).max() < 1e-12
    with pytest.raises(ValueError, match="source, target.*coincident"):
        fit_se2(np.zeros((3, 2)), np.ones((3, 2)))
    with pytest.raises(ValueError, match="weights"):
        fit_se2(src[0], tgt[0], -w)


def test_ransac_se2_brute_force_agreement_and_failure():
    rng = np.random.default_rng(3)
    src = rng.uniform(-3, 3, (12, 2))
    tgt = se2_compose([0.3, 0.2, -1.0], np.column_stack([src, np.zeros(12)]))[:, :2]
    tgt[:5] = rng.uniform(-3, 3, (5, 2))
    fit = ransac_se2(src, tgt, threshold=1e-6, min_inliers=3, rng=0, max_iterations=5000)
    # brute force over every pair finds the same support
    best = max((np.sum(np.linalg.norm(se2_compose(fit_se2(src[[i, j]], tgt[[i, j]]),
                                                  np.column_stack([src, np.zeros(12)]))[:, :2] - tgt, axis=1) < 1e-6)
                for i in range(12) for j in range(i + 1, 12)))
    assert fit.n_inliers == best == 7
    assert not ransac_se2(src[:3], tgt[:3], min_inliers=6).ok


@pytest.mark.parametrize("call, match", [
    (lambda: essential_from_bearings(np.zeros((8, 3)), np.ones((8, 3))), "b1.*zero"),
    (lambda: essential_from_bearings(np.ones((8, 3)), np.ones((9, 3))), "b2"),
    (lambda: essential_from_bearings(np.full((8, 3), np.nan), np.ones((8, 3))), "b1"),
    (lambda: ransac_essential(np.ones((9, 3)), np.ones((9, 3)), threshold=0.0), "threshold"),
    (lambda: decompose_essential(np.eye(3), np.ones((3, 3)), np.ones((3, 3))), "E: expected an essential"),
    (lambda: floor_points(np.ones((2, 3)), np.eye(4)), "T_body_camera.*above the floor"),
    (lambda: floor_points(np.ones((2, 3)), np.eye(4), min_depression=2.0), "min_depression"),
    (lambda: as_bearings(np.ones((2, 2)), "b"), "b"),
    (lambda: ransac_se2(np.ones((4, 2)), np.ones((5, 2))), "target"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_sample_count_of_an_almost_impossible_clean_sample_is_refused_not_overflowed():
    from robokit.vision.ransac import ransac_sample_count
    assert ransac_sample_count(0.5, 8, 0.99) == 1177          # log(0.01) / log(1 - 2^-8)
    with pytest.raises(ValueError, match="sample_size"):
        ransac_sample_count(0.999, 8)                          # (1e-3)^8 = 1e-24: 1 - p rounds to 1


def test_huge_but_finite_components_give_the_same_bearings_and_errors():
    """Scale-free quantities divide the scale out before a norm: 1e300 entries do not overflow (issue 38)."""
    from robokit.vision.spherical import as_bearings, epipolar_error
    np.testing.assert_allclose(as_bearings([[1e300, 0.0, 1e300], [0.0, 3.0, 4.0]], "b"),
                               [[2 ** -0.5, 0.0, 2 ** -0.5], [0.0, 0.6, 0.8]])
    rng = np.random.default_rng(3)
    E, b1, b2 = rng.normal(size=(3, 3)), rng.normal(size=(5, 3)), rng.normal(size=(5, 3))
    np.testing.assert_allclose(epipolar_error(E * 1e300, b1, b2), epipolar_error(E, b1, b2), rtol=1e-12)
    np.testing.assert_allclose(epipolar_error(E, b1 * 1e300, b2), epipolar_error(E, b1, b2), rtol=1e-12)
