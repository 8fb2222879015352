"""NN-ratio matching (Lin et al. Sec. 3) and recall vs 1-precision (Lin et al. Sec. 2.iii)."""
import cv2
import numpy as np
import pytest
from matplotlib import cbook
from PIL import Image

from robokit.vision.descriptors import detect_plot_features, detect_sift_features
from robokit.vision.evaluation import apply_homography, matching_score, recall_precision, similarity_homography
from robokit.vision.features import Features, Keypoints
from robokit.vision.matching import PAIR_BLOCK, gated_ratio_match, k_nearest, pair_distances, ratio_match, two_nearest
from robokit.vision.matching import distance_ratio


@pytest.fixture(scope="module")
def photo():
    with cbook.get_sample_data("grace_hopper.jpg") as f:
        img = np.array(Image.open(f).convert("L"))
    return cv2.resize(img, (640, 480), interpolation=cv2.INTER_AREA)


def test_ratio_test_accepts_distinct_and_rejects_ambiguous():
    train = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 10.0], [0.2, 10.0]])
    query = np.array([[0.05, 0.0], [0.1, 10.0], [5.0, 5.0]])
    m = ratio_match(query, train, ratio=0.65)
    assert m.query.tolist() == [0] and m.train.tolist() == [0]
    assert m.ratio[0] == pytest.approx(0.05 / 0.95)


def test_pair_distances_are_the_whole_array_expression_block_by_block():
    rng = np.random.default_rng(3)
    query, train = rng.random((300, 128), np.float32), rng.random((500, 128), np.float32)
    qi, ti = rng.integers(0, 300, 2 * PAIR_BLOCK + 17), rng.integers(0, 500, 2 * PAIR_BLOCK + 17)
    d32 = pair_distances(query, train, qi, ti, precision="float32")
    assert d32.dtype == np.float32 and np.array_equal(d32, np.linalg.norm(query[qi] - train[ti], axis=1))
    d64 = pair_distances(query, train, qi, ti)
    assert np.array_equal(d64, np.sqrt(((query[qi].astype(np.float64) - train[ti]) ** 2).sum(axis=1)))
    assert np.array_equal(pair_distances(query, train, qi, ti, validate=False), d64)
    assert pair_distances(query, train, [], []).shape == (0,)
    with pytest.raises(ValueError, match="query_index, train_index"):
        pair_distances(query, train, [300], [0])
    with pytest.raises(ValueError, match="train_index"):
        pair_distances(query, train, [0, 1], [0])
    with pytest.raises(ValueError, match="query: expected descriptors of length 128"):
        pair_distances(query[:, :64], train, [0], [0])


def test_gated_matching_with_every_pair_is_plain_ratio_matching():
    rng = np.random.default_rng(4)
    train = rng.normal(size=(120, 32)).astype(np.float32)
    query = train[:60] + rng.normal(scale=0.3, size=(60, 32)).astype(np.float32)
    qi, ti = np.meshgrid(np.arange(60), np.arange(120), indexing="ij")
    for ratio in (0.5, 0.65, 0.8):
        a = ratio_match(query, train, ratio=ratio)
        b = gated_ratio_match(query, train, qi.ravel(), ti.ravel(), ratio=ratio)
        assert np.array_equal(a.query, b.query) and np.array_equal(a.train, b.train)
        assert np.allclose(a.distance, b.distance) and np.allclose(a.ratio, b.ratio)
    # a gate that leaves each query a single candidate: the ratio passes, max_distance still applies
    c = gated_ratio_match(query, train, np.arange(60), np.arange(60), max_distance=1.5)
    assert np.array_equal(c.query, c.train) and np.all(c.distance <= 1.5) and 0 < len(c) < 60


def test_exact_duplicates_are_ambiguous_whatever_the_rounding():
    # large, irregular values: a dot-product distance would leave rounding noise of ~1e-8 and let
    # one of two identical candidates win the ratio test
    rng = np.random.default_rng(5)
    desc = (rng.normal(size=(200, 128)) * 37.3).astype(np.float32)
    twin = np.vstack([desc, desc])
    idx = np.arange(200)
    m = gated_ratio_match(desc, twin, np.r_[idx, idx], np.r_[idx, idx + 200])
    assert len(m) == 0
    assert len(ratio_match(desc, twin)) == 0
    assert distance_ratio([0.0, 1.0, 1.0], [0.0, 2.0, np.inf]).tolist() == [1.0, 0.5, 0.0]
    for best, second in [([np.nan], [1.0]), ([-1.0], [1.0]), ([2.0], [1.0]), ([1.0], [np.nan]), ([1.0, 2.0], [3.0])]:
        with pytest.raises(ValueError, match="best|second"):
            distance_ratio(best, second)
    everything = gated_ratio_match(desc, twin, np.r_[idx], np.r_[idx], max_distance=np.inf)
    assert len(everything) == 200                      # inf is "no bound", like None
    for bad in (0.0, -1.0, np.nan):
        with pytest.raises(ValueError, match="max_distance"):
            gated_ratio_match(desc, twin, [0], [0], max_distance=bad)
    with pytest.raises(ValueError, match="query_index, train_index"):
        gated_ratio_match(desc, twin, [0, 200], [0, 1])
    with pytest.raises(ValueError, match="train_index"):
        gated_ratio_match(desc, twin, [0, 1], [0])
    with pytest.raises(ValueError, match="ratio"):
        gated_ratio_match(desc, twin, [0], [0], ratio=1.5)


def test_kdtree_and_opencv_agree():
    rng = np.random.default_rng(3)
    train = rng.normal(size=(300, 16)).astype(np.float32)
    query = train[:100] + rng.normal(scale=0.05, size=(100, 16)).astype(np.float32)
    a = ratio_match(query, train, method="kdtree")
    b = ratio_match(query, train, method="opencv")
    assert np.array_equal(a.query, b.query) and np.array_equal(a.train, b.train)
    assert np.allclose(a.distance, b.distance, atol=1e-4)
    assert len(a) > 90 and np.array_equal(a.train, a.query)
    d, i = two_nearest(query, train)
    assert d.shape == (100, 2) and np.all(d[:, 0] <= d[:, 1])


@pytest.mark.parametrize("method", ["kdtree", "opencv", "flann"])
def test_a_descriptor_index_survives_pickling(method):
    # sent to worker processes, an index rebuilds its search structure (OpenCV's does not pickle)
    import pickle
    from robokit.vision.matching import DescriptorIndex
    rng = np.random.default_rng(8)
    train = rng.normal(size=(500, 32)).astype(np.float32)
    query = train[::5] + rng.normal(scale=0.2, size=(100, 32)).astype(np.float32)
    index = DescriptorIndex(train, method, seed=4)
    copy = pickle.loads(pickle.dumps(index))
    for a, b in zip(index.query(query, 3), copy.query(query, 3)):
        np.testing.assert_array_equal(a, b)
    assert len(copy.match(query)) > 50
    empty = pickle.loads(pickle.dumps(DescriptorIndex(np.zeros((0, 32), np.float32), method)))
    assert len(empty) == 0


@pytest.mark.parametrize("dim", [16, 128])
def test_k_nearest_methods_agree_including_the_distance_bound(dim):
    rng = np.random.default_rng(5)
    train = rng.normal(size=(400, dim)).astype(np.float32)
    query = train[::4] + rng.normal(scale=0.3, size=(100, dim)).astype(np.float32)
    bound = float(np.median(np.linalg.norm(query - train[::4], axis=1)))   # about half beyond it
    ref_d = np.sort(np.linalg.norm(query[:, None] - train[None], axis=2), axis=1)[:, :3]
    for method in ("kdtree", "bruteforce", "opencv"):
        d, i = k_nearest(query, train, 3, method=method)
        assert d.shape == i.shape == (100, 3)
        assert np.allclose(d, ref_d, atol=1e-3), method
        assert np.allclose(np.linalg.norm(query[:, None] - train[i], axis=2), d, atol=1e-3), method
        db, _ = k_nearest(query, train, 3, method=method, max_distance=bound)
        assert np.array_equal(np.isinf(db), ref_d > bound) and 20 < np.isinf(db[:, 0]).sum() < 80, method
    with pytest.raises(ValueError, match="train: expected at least 3"):
        k_nearest(query, train[:2], 3)
    with pytest.raises(ValueError, match="method"):
        k_nearest(query, train, 3, method="annoy")


def test_matching_degenerate_inputs():
    assert len(ratio_match(np.zeros((0, 8)), np.ones((5, 8)))) == 0
    assert len(ratio_match(np.ones((3, 8)), np.ones((1, 8)))) == 0
    with pytest.raises(ValueError, match="ratio: expected a value in"):
        ratio_match(np.ones((3, 8)), np.ones((4, 8)), ratio=1.5)
    with pytest.raises(ValueError, match="query: expected descriptors of length 8"):
        two_nearest(np.ones((3, 4)), np.ones((4, 8)))
    with pytest.raises(ValueError, match="train: expected at least 2"):
        two_nearest(np.ones((3, 8)), np.ones((1, 8)))


def test_similarity_homography_and_bad_homographies():
    h = similarity_homography((101, 201), 2.0, np.pi / 2)
    assert np.allclose(apply_homography(h, [[100, 50]]), [[100, 50]])
    # counter-clockwise on screen (y down): +x maps to -y
    assert np.allclose(apply_homography(h, [[110, 50]]), [[100, 30]])
    with pytest.raises(ValueError, match="homography: expected an invertible"):
        apply_homography(np.zeros((3, 3)), [[1, 2]])
    with pytest.raises(ValueError, match="homography: expected shape"):
        apply_homography(np.eye(2), [[1, 2]])


@pytest.mark.parametrize("extract", [detect_plot_features, detect_sift_features], ids=["plot", "sift"])
def test_recall_precision_on_boat_and_leuven_like_pairs(photo, extract):
    h = similarity_homography(photo.shape, 1.25, np.deg2rad(30))
    zoomed = cv2.warpPerspective(photo, h, (640, 480))
    darker = np.clip(0.45 * photo.astype(float) + 15, 0, 255).astype(np.uint8)
    fa = extract(photo)
    for other, hh, min_recall in ((zoomed, h, 0.3), (darker, np.eye(3), 0.8)):
        r = recall_precision(fa, extract(other), hh, other.shape)
        assert np.allclose(r["thresholds"], np.linspace(0.15, 0.7, 12))
        assert np.all(np.diff(r["recall"]) >= 0) and np.all(np.diff(r["n_false"]) >= 0)
        assert r["recall"][-1] >= min_recall
        assert r["one_minus_precision"][-1] < 0.1
        assert np.all((r["recall"] <= 1) & (r["one_minus_precision"] >= 0))


def test_recall_precision_detects_wrong_ground_truth(photo):
    fa = detect_sift_features(photo, n_features=300)
    h = similarity_homography(photo.shape, 1.0, np.deg2rad(20))
    fb = detect_sift_features(cv2.warpPerspective(photo, h, (640, 480)), n_features=300)
    good = recall_precision(fa, fb, h, photo.shape)
    wrong = recall_precision(fa, fb, similarity_homography(photo.shape, 1.0, np.deg2rad(-20)), photo.shape)
    assert good["recall"][-1] > 0.5 and good["one_minus_precision"][-1] < 0.1
    assert wrong["one_minus_precision"][-1] > 0.8
    with pytest.raises(ValueError, match="image_shape_b: expected"):
        recall_precision(fa, fb, h, 480)
    with pytest.raises(TypeError, match="features_b: expected Features"):
        recall_precision(fa, fb.descriptors, h, photo.shape)
    empty = recall_precision(fa.subset(slice(0, 0)), fb, h, photo.shape)
    assert empty["n_correspondences"] == 0 and not np.any(np.isnan(empty["recall"]))


def test_matching_score_counts_correct_matches_over_the_shared_keypoints():
    def feats(xy, desc):
        n = len(xy)
        return Features(Keypoints(np.array(xy, float), np.ones(n), np.ones(n), np.zeros(n)), np.array(desc, np.float32))

    e = np.eye(4)
    h = np.array([[1.0, 0, 10], [0, 1, 0], [0, 0, 1]])              # B is A shifted 10 px right
    a = feats([[5, 50], [20, 50], [40, 50], [95, 50]], e)          # the last one leaves B
    b = feats([[15, 50], [30, 50], [50.5, 50], [8, 50]], [e[0], e[2], e[1], e[3]])   # the last one is not in A
    m = matching_score(a, b, h, (100, 100), (100, 100))
    # A0 -> B0 right; A1 -> B2 and A2 -> B1 land 20 px from where they should; A3 is outside B
    assert (m["n_correct"], m["n_matches"], m["n_overlap"]) == (1, 3, 3)
    assert m["score"] == pytest.approx(1 / 3)
    assert matching_score(a, b, h, (100, 100), (100, 100), tolerance=25)["n_correct"] == 3
    assert matching_score(a, b, np.eye(3), (100, 100), (100, 100))["n_correct"] == 0
    empty = matching_score(a.subset(slice(0, 0)), b, h, (100, 100), (100, 100))
    assert empty == {"score": 0.0, "n_correct": 0, "n_matches": 0, "n_overlap": 0}
    with pytest.raises(ValueError, match="ratio: expected a threshold in"):
        matching_score(a, b, h, (100, 100), (100, 100), ratio=1.5)
    with pytest.raises(ValueError, match="image_shape_a: expected"):
        matching_score(a, b, h, 100, (100, 100))
    with pytest.raises(TypeError, match="features_a: expected Features"):
        matching_score(a.descriptors, b, h, (100, 100), (100, 100))


def test_matching_score_counts_each_partner_once_so_repeated_keypoints_cannot_inflate_it(photo):
    # a detector that reports every keypoint three times (e.g. three orientations at one place)
    # must not score higher than the same detector reporting it once
    h = similarity_homography(photo.shape, zoom=1.2)
    warped = cv2.warpPerspective(photo, h, (640, 480))
    fa, fb = detect_sift_features(photo), detect_sift_features(warped)
    once = matching_score(fa, fb, h, photo.shape, warped.shape)
    kp = fa.keypoints
    tripled = Features(Keypoints(np.tile(kp.xy, (3, 1)), np.tile(kp.scale, 3), np.tile(kp.response, 3),
                                 np.tile(kp.orientation, 3)), np.tile(fa.descriptors, (3, 1)))
    thrice = matching_score(tripled, fb, h, photo.shape, warped.shape)
    assert 0.2 < once["score"] <= 1 and thrice["n_correct"] == once["n_correct"]
    assert thrice["score"] <= once["score"]
