"""SIFT on omni images (lesson 02's paper, Sec. "Local image features"): radial orientation, KD-tree
matching against brute force and FLANN, and the "matched accurate rate > 80 %" against ground truth."""
import cv2
import numpy as np
import pytest

from robokit.sim import OmniCamera, office_floor, omni_ground_truth_inliers, omni_view_pair
from robokit.vision import DescriptorIndex, ImageSizeError, detect_sift_features, omni_sift
from robokit.vision.omni_features import annulus_mask
from robokit.vision.matching import FLANN_CHECKS, k_nearest, ratio_match

CAM = OmniCamera()
CENTRE = (CAM.cx, CAM.cy)
# (map node, query): four rooms, two corridor pairs, robot moved 0.1-0.5 m and turned
MOVES = [((12.0, 3.5, 0.0), (12.3, 3.6, 1.0)), ((5.5, 3.5, 0.0), (5.8, 3.2, -2.0)),
         ((2.5, 10.5, 0.0), (2.9, 10.7, 2.5)), ((13.0, 10.5, 0.0), (12.9, 10.1, -0.8)),
         ((7.7, 6.4, 0.0), (7.4, 6.65, -3.0)), ((10.0, 6.0, 0.0), (10.5, 6.0, 1.5))]
TURN = ((12.0, 3.5, 0.0), (12.0, 3.5, 2.0))


@pytest.fixture(scope="module")
def frames():
    world = office_floor()
    poses = {p for pair in MOVES + [TURN] for p in pair}
    return {p: CAM.observe(world, np.array(p), rng=0) for p in poses}          # 13 renders


@pytest.fixture(scope="module")
def features(frames):
    cache = {}

    def get(pose, orientation):
        if (pose, orientation) not in cache:
            cache[pose, orientation] = omni_sift(frames[pose].image, CENTRE, CAM.radii, orientation=orientation)
        return cache[pose, orientation]
    return get


def _accuracy(frames, features, pair, orientation, ratio=0.8):
    """(matches, correct) of a map node -> query pair, judged by the omni ground truth."""
    node, query = pair
    f1, f2 = features(node, orientation), features(query, orientation)
    m = DescriptorIndex(f1.descriptors).match(f2.descriptors, ratio=ratio)
    ok = omni_ground_truth_inliers(CAM, frames[node].depth, CAM.transform_at(node), CAM.transform_at(query),
                                   f1.keypoints.xy[m.train], f2.keypoints.xy[m.query])
    return len(m), int(ok.sum())


def test_kdtree_bruteforce_and_opencv_find_the_same_neighbours_flann_nearly(features):
    f1, f2 = features(*MOVES[0][:1], "radial"), features(MOVES[0][1], "radial")
    exact = {m: DescriptorIndex(f1.descriptors, m).query(f2.descriptors, k=2) for m in ("kdtree", "bruteforce", "opencv")}
    d0, i0 = exact["bruteforce"]
    for d, i in exact.values():
        assert np.array_equal(i, i0) and np.allclose(d, d0, atol=1e-6)
    # squared Euclidean (the paper's) ranks as Euclidean: the same order by an independent computation
    sq = ((f2.descriptors[:, None, :].astype(float) - f1.descriptors[None]) ** 2).sum(-1)
    assert np.array_equal(np.argsort(sq, axis=1, kind="stable")[:, :2], i0)
    # FLANN is approximate: measured 98.8 % exact first neighbours at 128 checks, 100 % at 256
    d, i = DescriptorIndex(f1.descriptors, "flann").query(f2.descriptors, k=2)
    assert FLANN_CHECKS == 128 and (i[:, 0] == i0[:, 0]).mean() > 0.97
    assert np.all(d[:, 0] >= d0[:, 0] - 1e-6)                         # never nearer than the true nearest
    assert np.array_equal(DescriptorIndex(f1.descriptors, "flann", checks=512).query(f2.descriptors, k=2)[1], i0)
    # ... and the ratio test barely notices: the same accepted matches but at most one
    a = DescriptorIndex(f1.descriptors, "flann").match(f2.descriptors)
    b = DescriptorIndex(f1.descriptors, "bruteforce").match(f2.descriptors)
    assert len(set(zip(a.query, a.train)) ^ set(zip(b.query, b.train))) <= 1
    # the same FLANN index every run (seeded), and k_nearest / ratio_match offer the same searches
    again = DescriptorIndex(f1.descriptors, "flann").query(f2.descriptors, k=2)[1]
    assert np.array_equal(again, i)
    assert np.array_equal(k_nearest(f2.descriptors, f1.descriptors, 2, method="flann")[1], i)
    assert len(ratio_match(f2.descriptors, f1.descriptors, ratio=0.8, method="flann")) == len(a)


def test_radial_orientation_makes_descriptors_turn_with_the_image():
    noise = np.random.default_rng(2).uniform(0, 255, (241, 241)).astype(np.float32)
    disc = cv2.GaussianBlur(noise, (0, 0), 1.5).astype(np.uint8)
    turn = cv2.getRotationMatrix2D((120, 120), 40, 1.0)
    turned = cv2.warpAffine(disc, turn, (241, 241))
    spread = {}
    for orientation in ("radial", "gradient", "upright"):
        a = omni_sift(disc, (120, 120), (20, 100), orientation=orientation)
        b = omni_sift(turned, (120, 120), (20, 100), orientation=orientation)
        moved = a.keypoints.xy @ turn[:, :2].T + turn[:, 2]
        near = np.linalg.norm(moved[:, None] - b.keypoints.xy[None], axis=2) < 1.0   # the same keypoint
        i, j = np.nonzero(near & (np.abs(a.keypoints.scale[:, None] / b.keypoints.scale[None] - 1) < 0.2))
        spread[orientation] = np.median(np.linalg.norm(a.descriptors[i] - b.descriptors[j], axis=1))
        if orientation == "radial":
            assert len(i) > 200
            # the twin's angle is the keypoint's own angle turned by 40 degrees (image axes: minus),
            # up to the angle that the twins' distance (< 1 px) subtends at the centre
            dtheta = np.rad2deg(b.keypoints.orientation[j] - a.keypoints.orientation[i])
            radius = np.hypot(*(a.keypoints.xy[i] - 120).T)
            assert np.all(np.abs((dtheta + 40 + 180) % 360 - 180) < np.rad2deg(1.0 / radius))
            m = DescriptorIndex(a.descriptors).match(b.descriptors)
            hit = np.linalg.norm(moved[m.train] - b.keypoints.xy[m.query], axis=1) < 2
            assert len(m) > 200 and hit.mean() > 0.99
    # measured medians: radial 0.08, gradient 0.14 (its orientation estimate wobbles), upright 0.88
    assert spread["radial"] < 0.7 * spread["gradient"] and spread["upright"] > 5 * spread["radial"]


def test_keypoints_stay_in_the_annulus_and_sift_is_plain_sift_there(frames):
    img = frames[MOVES[0][0]].image
    f = omni_sift(img, CENTRE, CAM.radii, orientation="gradient")
    r = np.hypot(*(f.keypoints.xy - CENTRE).T)
    assert len(f) > 300 and r.min() >= CAM.radii[0] and r.max() <= CAM.radii[1]
    ref = detect_sift_features(img)                                 # the unmasked library call
    inside = ref.subset((np.hypot(*(ref.keypoints.xy - CENTRE).T) >= CAM.radii[0] + 4)
                        & (np.hypot(*(ref.keypoints.xy - CENTRE).T) <= CAM.radii[1] - 4))
    found = np.linalg.norm(inside.keypoints.xy[:, None] - f.keypoints.xy[None], axis=2).min(axis=1) < 0.5
    assert found.mean() > 0.95                                      # the mask drops no inner keypoint
    radial = omni_sift(img, CENTRE, CAM.radii)
    assert len(radial) < len(f)                                     # one keypoint per orientation peak
    assert np.allclose(radial.keypoints.orientation,
                       np.mod(np.arctan2(*(radial.keypoints.xy - CENTRE)[:, ::-1].T), 2 * np.pi))
    assert len(omni_sift(np.full((480, 640), 90, np.uint8), CENTRE, CAM.radii)) == 0     # no texture, no features


def test_matched_accurate_rate_exceeds_80_percent_as_the_paper_claims(frames, features):
    per_pair = np.array([_accuracy(frames, features, pair, "radial") for pair in MOVES])
    rate = per_pair[:, 1] / per_pair[:, 0]
    # measured (ratio 0.8, tol 3 px): rooms 0.86-0.90, corridor 0.77-0.81, pooled 0.861; over 20
    # random pairs (benchmarks/bench_omni_features.py) pooled 0.873, worst pair 0.750 in the
    # corridor, where the paper also finds fewer features
    assert per_pair[:, 0].min() > 100
    assert per_pair[:, 1].sum() / per_pair[:, 0].sum() > 0.8
    assert rate[:4].min() > 0.8 and rate.min() > 0.75
    # (plain gradient SIFT: 0.879 pooled here, benchmarks/bench_omni_features.py compares them);
    # a turned robot defeats upright SIFT: no correct match
    up = np.array([_accuracy(frames, features, pair, "upright") for pair in MOVES[:2]])
    assert up[:, 1].sum() <= 0.1 * up[:, 0].sum()


def test_a_pure_turn_keeps_the_matches(frames, features):
    for orientation in ("radial", "gradient"):
        n, good = _accuracy(frames, features, TURN, orientation)
        assert n > 300 and good / n > 0.9                           # measured 0.941 and 0.937
    n, good = _accuracy(frames, features, TURN, "upright")
    assert good <= 0.1 * max(n, 1)


def test_omni_ground_truth_rejects_wrong_matches_and_unknown_ranges(frames):
    node, query = MOVES[0]
    T1, T2 = CAM.transform_at(node), CAM.transform_at(query)
    rng = np.random.default_rng(0)
    r = rng.uniform(60, 220, 50)
    a = rng.uniform(0, 2 * np.pi, 50)
    uv1 = np.column_stack([CAM.cx + r * np.cos(a), CAM.cy + r * np.sin(a)])
    ranges = frames[node].depth
    X = CAM.backproject(uv1, ranges[np.round(uv1[:, 1]).astype(int), np.round(uv1[:, 0]).astype(int)], T1)
    uv2, _ = CAM.project(X, T2)
    seen = np.all(np.isfinite(uv2), axis=1)
    ok = omni_ground_truth_inliers(CAM, ranges, T1, T2, uv1[seen], uv2[seen])
    assert ok.all() and seen.sum() > 40
    assert not omni_ground_truth_inliers(CAM, ranges, T1, T2, uv1[seen], uv2[seen] + 3.5).any()
    outside = np.array([[2.0, 2.0]])                                    # the black corner: range inf
    assert not omni_ground_truth_inliers(CAM, ranges, T1, T2, outside, outside).any()


def test_omni_view_pair_reports_the_same_rate(frames, features):
    check = omni_view_pair(office_floor(), CAM, *MOVES[0])
    n, good = _accuracy(frames, features, MOVES[0], "radial")
    assert check.matches == n and check.inlier_ratio == pytest.approx(good / n)
    assert check.keypoints == len(features(MOVES[0][0], "radial"))


def test_descriptor_index_edge_cases():
    rng = np.random.default_rng(3)
    train = rng.normal(size=(30, 8)).astype(np.float32)
    for method in ("kdtree", "bruteforce", "opencv", "flann"):
        index = DescriptorIndex(train, method)
        d, i = index.query(train[:4], k=3)
        assert i[:, 0].tolist() == [0, 1, 2, 3] and np.allclose(d[:, 0], 0, atol=1e-5) and d.shape == (4, 3)
        assert index.count_matches(train[:4] + 0.01) == 4
        assert len(DescriptorIndex(train[:1], method).match(train[:4])) == 0      # no second neighbour
        assert len(DescriptorIndex(np.zeros((0, 8)), method).match(train)) == 0
        assert len(index.match(np.zeros((0, 8)))) == 0
        with pytest.raises(ValueError, match="train"):
            DescriptorIndex(train[:2], method).query(train, k=3)
        with pytest.raises(ValueError, match="query"):
            index.query(np.zeros((2, 5)))
    with pytest.raises(ValueError, match="method"):
        DescriptorIndex(train, "ball")
    with pytest.raises(ValueError, match="checks"):
        DescriptorIndex(train, "flann", checks=0)


def test_bad_input_is_named():
    img = np.zeros((480, 640), np.uint8)
    with pytest.raises(ImageSizeError, match="image.*annulus"):
        omni_sift(img[:240, :320], CENTRE, CAM.radii)                  # a query from another camera
    with pytest.raises(ValueError, match="radii"):
        omni_sift(img, CENTRE, (100, 50))
    with pytest.raises(ValueError, match="orientation"):
        omni_sift(img, CENTRE, CAM.radii, orientation="polar")
    with pytest.raises(ValueError, match="mask"):
        omni_sift(img, CENTRE, CAM.radii, mask=np.ones((10, 10), bool))
    with pytest.raises(ValueError, match="orientation"):
        detect_sift_features(cv2.GaussianBlur(np.random.default_rng(0).uniform(0, 255, (160, 200)), (0, 0), 2.0).astype(np.uint8),
                             orientation=lambda xy: np.zeros(len(xy) + 1))
    with pytest.raises(TypeError, match="orientation"):
        detect_sift_features(img, orientation="radial")
    with pytest.raises(ImageSizeError, match="shape"):
        annulus_mask((100, 100), (50, 50), (10, 60))
    with pytest.raises(TypeError, match="camera"):
        omni_ground_truth_inliers(object(), np.zeros((480, 640)), np.eye(4), np.eye(4), [[0, 0]], [[0, 0]])
    with pytest.raises(ValueError, match="ranges"):
        omni_ground_truth_inliers(CAM, np.zeros((10, 10)), np.eye(4), np.eye(4), [[0, 0]], [[0, 0]])
    with pytest.raises(ValueError, match="uv1"):
        omni_ground_truth_inliers(CAM, np.zeros((480, 640)), np.eye(4), np.eye(4), [[700, 0]], [[0, 0]])
