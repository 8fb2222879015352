"""Bag of binary words (Ge et al. 2023, Sec. 3.3): Hamming distance, ORB, vocabulary tree, TF-IDF,
L1 score and the inverted-index database, against hand-worked values, OpenCV and brute force."""
from __future__ import annotations

import cv2
import numpy as np
import pytest

import robokit.sim as sim
from robokit.vision import (BowDatabase, BowVector, DatabaseFileError, TooFewDescriptorsError, Vocabulary,
                            VocabularyFileError, detect_orb_features, hamming_distance, hamming_distances,
                            hamming_match, l1_score, tf_idf)


def random_descriptors(n, seed):
    return np.random.default_rng(seed).integers(0, 256, (n, 32), dtype=np.uint8)


def flip_bits(desc, n_bits, seed):
    """Copy of ``desc`` with ``n_bits`` random bits flipped per row."""
    rng = np.random.default_rng(seed)
    bits = np.unpackbits(desc, axis=1)
    for row in bits:
        row[rng.choice(bits.shape[1], n_bits, replace=False)] ^= 1
    return np.packbits(bits, axis=1)


# --- Hamming distance and matching --------------------------------------------------------------

def test_hamming_distances_equal_a_bit_count_and_opencv():
    a, b = random_descriptors(70, 1), random_descriptors(90, 2)
    bits_a, bits_b = np.unpackbits(a, axis=1), np.unpackbits(b, axis=1)
    brute = (bits_a[:, None, :] != bits_b[None, :, :]).sum(-1)
    np.testing.assert_array_equal(hamming_distances(a, b), brute)
    matches = cv2.BFMatcher(cv2.NORM_HAMMING).match(a, b)
    np.testing.assert_array_equal([m.distance for m in matches], brute.min(axis=1))
    # odd widths are zero-padded internally
    np.testing.assert_array_equal(hamming_distance(a[:, :5], b[:70, :5]),
                                  (bits_a[:, :40] != bits_b[:70, :40]).sum(-1))


def test_hamming_match_agrees_with_bfmatcher_knn_and_ratio():
    train = random_descriptors(200, 3)
    query = np.concatenate([flip_bits(train[:60], 20, 4), random_descriptors(40, 5)])
    knn = cv2.BFMatcher(cv2.NORM_HAMMING).knnMatch(query, train, k=2)
    expect = [(i, m.trainIdx) for i, (m, n) in enumerate(knn) if m.distance < 0.75 * n.distance and m.distance <= 50]
    got = hamming_match(query, train)
    assert list(zip(got.query.tolist(), got.train.tolist())) == expect
    assert len(expect) == 60                   # the noisy copies, and nothing random
    cross = cv2.BFMatcher(cv2.NORM_HAMMING, crossCheck=True).match(query, train)
    mutual = hamming_match(query, train, ratio=1.0, max_distance=None, cross_check=True)
    assert sorted((m.queryIdx, m.trainIdx) for m in cross) == sorted(zip(mutual.query.tolist(),
                                                                         mutual.train.tolist()))


@pytest.mark.parametrize("n_train", [1, 2, 300])
def test_hamming_match_equals_the_distance_table_with_ties(n_train):
    train = random_descriptors(n_train, 6)
    if n_train > 2:
        train[250:] = train[:50]                        # some train rows twice: ties at the nearest
        train[60:70] = flip_bits(train[70:80], 1, 9)    # and near-ties one bit apart
    query = np.concatenate([flip_bits(train[: min(n_train, 80)], 6, 7), random_descriptors(30, 8)])
    query = np.concatenate([query, query[-40:-20]])     # repeated queries: ties for the cross check
    table = hamming_distances(query, train)
    best = np.argmin(table, axis=1)                     # first minimum: the lowest index
    nearest = table[np.arange(len(query)), best].astype(float)
    second = np.sort(table, axis=1)[:, 1] if n_train > 1 else np.full(len(query), np.inf)
    for ratio, bound, cross in ((1.0, None, False), (0.75, 50, False), (1.0, None, True), (0.9, 80, True)):
        keep = (nearest < ratio * second) & (nearest <= (np.inf if bound is None else bound))
        if cross:
            keep &= np.argmin(table, axis=0)[best] == np.arange(len(query))
        m = hamming_match(query, train, ratio=ratio, max_distance=bound, cross_check=cross)
        np.testing.assert_array_equal(m.query, np.flatnonzero(keep))
        np.testing.assert_array_equal(m.train, best[keep])
        np.testing.assert_array_equal(m.distance, nearest[keep])
        assert len(m) > 0 or n_train == 2


def test_hamming_rejects_bad_descriptors():
    with pytest.raises(ValueError, match="query"):
        hamming_match([[0, 256]], [[0, 1]])
    with pytest.raises(ValueError, match="train"):
        hamming_match(random_descriptors(3, 0), random_descriptors(3, 1)[:, :16])
    assert len(hamming_match(np.zeros((0, 32), np.uint8), random_descriptors(3, 1))) == 0


def test_orb_on_a_rendered_corridor_and_a_blank_wall():
    world = sim.long_corridor()
    cam = sim.PinholeCamera.from_fov(np.deg2rad(65), 320, 240, mount=sim.camera_mount(0.5))
    f = detect_orb_features(cam.observe(world, [5.0, 0, 0]).image)
    assert 200 < len(f) <= 500 and f.descriptors.dtype == np.uint8 and f.descriptors.shape[1] == 32
    assert np.all((f.keypoints.orientation >= 0) & (f.keypoints.orientation < 2 * np.pi))
    blank = detect_orb_features(np.full((240, 320, 3), 128, np.uint8))
    assert len(blank) == 0 and blank.descriptors.shape == (0, 32) and blank.descriptors.dtype == np.uint8


# --- TF-IDF and the L1 score: a hand-worked example -----------------------------------------------

def test_tf_idf_and_l1_score_by_hand():
    # 4 words, 3 training images: image 0 has words {0, 1}, image 1 {1, 2}, image 2 {1, 3}
    # -> n_i = [1, 3, 1, 1], IDF = log2(3 / n_i) = [log2 3, 0, log2 3, log2 3]   (Eq. (16))
    idf = np.log2(3.0 / np.array([1, 3, 1, 1]))
    l3 = np.log2(3.0)
    # query image: word ids [0, 0, 1, 2] -> TF = [2/4, 1/4, 1/4]; eta = [0.5 l3, 0, 0.25 l3]
    v = tf_idf([0, 0, 1, 2], idf)
    assert v.words.tolist() == [0, 2]           # word 1 has weight 0: left out
    np.testing.assert_allclose(v.weights, [0.5 * l3, 0.25 * l3], rtol=1e-15)
    # L1-normalised: a = [2/3, 0, 1/3, 0]; b from ids [0, 3, 3] -> eta = [l3/3, 2 l3/3] -> [1/3, 0, 0, 2/3]
    w = tf_idf([0, 3, 3], idf)
    # |a - b|_1 = 1/3 + 1/3 + 2/3 = 4/3  ->  s = 1 - 0.5 * 4/3 = 1/3          (Eq. (17))
    assert l1_score(v, w) == pytest.approx(1.0 / 3.0, abs=1e-15)
    assert l1_score(v, v) == pytest.approx(1.0, abs=1e-15)
    assert l1_score(v, tf_idf([1, 3], idf)) == 0.0          # only word 3 (b): no common word
    assert l1_score(v, BowVector.empty()) == 0.0
    # plain data works as well as BowVectors
    assert l1_score(([0, 2], [2.0, 1.0]), ([3, 0], [2.0, 1.0])) == pytest.approx(1.0 / 3.0, abs=1e-15)


def test_l1_score_and_tf_idf_reject_bad_vectors():
    with pytest.raises(ValueError, match="unique"):
        l1_score(([1, 1], [0.5, 0.5]), ([1], [1.0]))
    with pytest.raises(ValueError, match="non-negative"):
        l1_score(([1], [-1.0]), ([1], [1.0]))
    with pytest.raises(ValueError, match="word_ids"):
        tf_idf([4], np.ones(4))


# --- the vocabulary tree --------------------------------------------------------------------------

def reference_words(voc, desc):
    """A readable per-descriptor descent: at each node go to the nearest child (first of equals)."""
    out = []
    for d in desc:
        node = 0
        while voc.children[node, 0] >= 0:
            kids = [c for c in voc.children[node] if c >= 0]
            dist = [int(np.unpackbits(d ^ voc.centres[c]).sum()) for c in kids]
            node = kids[int(np.argmin(dist))]
        out.append(voc.word_of_node[node])
    return np.array(out)


@pytest.fixture(scope="module")
def clustered_images():
    """12 images drawn from 60 prototypes with 10 flipped bits each (a vocabulary has structure to find)."""
    protos = random_descriptors(60, 10)
    rng = np.random.default_rng(11)
    return [flip_bits(protos[rng.integers(0, 60, 150)], 10, 100 + i) for i in range(12)]


def test_vectorised_descent_equals_the_reference_descent(clustered_images):
    voc = Vocabulary.train(clustered_images, branching=5, levels=3, rng=0)
    assert 25 < voc.n_words <= 125
    probe = np.concatenate([clustered_images[0][:100], random_descriptors(100, 12)])
    np.testing.assert_array_equal(voc.words(probe), reference_words(voc, probe))


def test_idf_counts_training_images(clustered_images):
    voc = Vocabulary.train(clustered_images, branching=5, levels=3, rng=0)
    n_i = np.zeros(voc.n_words)
    for d in clustered_images:
        n_i[np.unique(reference_words(voc, d))] += 1
    expect = np.where(n_i > 0, np.log2(12 / np.maximum(n_i, 1)), 0.0)
    np.testing.assert_allclose(voc.idf, expect, rtol=1e-15)
    v = voc.transform(clustered_images[3])
    assert np.all(np.diff(v.words) > 0) and v.weights.sum() == pytest.approx(1.0)


def test_training_centres_are_bit_majorities():
    # two obvious clusters: all-zero-ish and all-one-ish bytes, k = 2, L = 1
    low = flip_bits(np.zeros((9, 32), np.uint8), 3, 0)
    high = flip_bits(np.full((9, 32), 255, np.uint8), 3, 1)
    voc = Vocabulary.train([low, high], branching=2, levels=1, rng=3)
    centres = {tuple(c) for c in voc.centres[1:]}
    assert centres == {(0,) * 32, (255,) * 32}


@pytest.mark.parametrize("n", [1, 7, 100, 639, 640, 5000])
def test_bit_majority_counts_equal_a_per_cluster_bit_count(n):
    from robokit.vision.bag_of_words import bit_majority   # both of its counting ways, either side of 64 k rows
    rng = np.random.default_rng(n)
    k = 10
    desc = rng.integers(0, 256, (n, 32), dtype=np.uint8)
    desc[: n // 2, :4] = 0b10101010                          # some columns where members agree, some ties
    labels = rng.integers(0, k - 2, n)                       # the last two clusters stay empty
    centres, size = bit_majority(desc, labels, k)
    for j in range(k):
        members = np.unpackbits(desc[labels == j], axis=1)
        assert size[j] == len(members)
        expect = np.packbits(2 * members.sum(axis=0) >= len(members))     # ties give 1
        np.testing.assert_array_equal(centres[j], expect, err_msg=f"cluster {j} of {n} rows")


def test_too_few_descriptors_and_empty_images():
    with pytest.raises(TooFewDescriptorsError, match="branching=10"):
        Vocabulary.train([random_descriptors(9, 0)], branching=10)
    voc = Vocabulary.train([random_descriptors(40, 0), random_descriptors(40, 1)], branching=4, levels=2)
    for blank in (np.zeros((0, 32), np.uint8), []):
        v = voc.transform(blank)
        assert len(v) == 0 and v.words.dtype == np.int64 and v.weights.shape == (0,)


def test_vocabulary_save_load_and_a_foreign_file(tmp_path, clustered_images):
    voc = Vocabulary.train(clustered_images, branching=5, levels=2, rng=0)
    again = Vocabulary.load(voc.save(tmp_path / "voc.npz"))
    np.testing.assert_array_equal(again.words(clustered_images[1]), voc.words(clustered_images[1]))
    np.testing.assert_array_equal(again.idf, voc.idf)
    (tmp_path / "junk.npz").write_bytes(b"not a zip file")
    with pytest.raises(VocabularyFileError):
        Vocabulary.load(tmp_path / "junk.npz")
    np.savez(tmp_path / "other.npz", x=np.zeros(3))
    with pytest.raises(VocabularyFileError):
        Vocabulary.load(tmp_path / "other.npz")
    broken = voc.arrays()
    broken["children"] = broken["children"].copy()
    broken["children"][0, 0] = broken["children"][0, 1]       # a node with two parents
    np.savez(tmp_path / "broken.npz", **broken)
    with pytest.raises(VocabularyFileError, match="children"):
        Vocabulary.load(tmp_path / "broken.npz")


# --- the database ---------------------------------------------------------------------------------

def test_database_scores_equal_brute_force_eq17(clustered_images):
    voc = Vocabulary.train(clustered_images, branching=5, levels=3, rng=0)
    db = BowDatabase(voc)
    for d in clustered_images:
        db.add(d)
    for q in (clustered_images[2][:60], flip_bits(clustered_images[7], 6, 3)):
        v = voc.transform(q)
        results = db.query(v, max_results=None)
        brute = np.array([l1_score(v, db.vector(i)) for i in range(len(db))])
        assert {r.entry for r in results} == set(np.nonzero(brute > 0)[0].tolist())
        for r in results:
            assert abs(r.score - brute[r.entry]) < 1e-12
        scores = [r.score for r in results]
        assert scores == sorted(scores, reverse=True)
        assert [r.entry for r in db.query(q, max_results=3)] == [r.entry for r in results[:3]]
    assert db.query(np.zeros((0, 32), np.uint8)) == []
    empty_entry = db.add(np.zeros((0, 32), np.uint8))
    assert empty_entry == 12 and all(r.entry != 12 for r in db.query(clustered_images[0], None))


def test_database_save_load(tmp_path, clustered_images):
    db = BowDatabase(Vocabulary.train(clustered_images, branching=5, levels=2, rng=0))
    for d in clustered_images[:5]:
        db.add(d)
    again = BowDatabase.load(db.save(tmp_path / "db.npz"))
    assert len(again) == 5 and again.query(clustered_images[3]) == db.query(clustered_images[3])
    (tmp_path / "bad.npz").write_bytes(b"PK\x03\x04 truncated")
    with pytest.raises(DatabaseFileError):
        BowDatabase.load(tmp_path / "bad.npz")


# --- place recognition on rendered corridor images ------------------------------------------------

def test_corridor_place_recognition():
    """A vocabulary from another corridor; database images every metre; queries 0.1 m ahead."""
    cam = sim.PinholeCamera.from_fov(np.deg2rad(65), 320, 240, mount=sim.camera_mount(0.5))
    other = sim.long_corridor(seed=7)
    training = [detect_orb_features(cam.observe(other, [x, 0, 0]).image).descriptors for x in np.arange(2.5, 31, 2.0)]
    voc = Vocabulary.train(training, branching=8, levels=3, rng=0)
    world = sim.long_corridor()
    xs = np.arange(2.0, 31.0, 1.0)
    db = BowDatabase(voc)
    for x in xs:
        db.add(detect_orb_features(cam.observe(world, [x, 0, 0]).image).descriptors)
    exact = near = 0
    for i, x in enumerate(xs):
        best = db.query(detect_orb_features(cam.observe(world, [x + 0.1, 0, 0]).image).descriptors, 1)
        exact += bool(best) and best[0].entry == i
        near += bool(best) and abs(best[0].entry - i) <= 1
    # measured (k=8, L=3, 512 words): 28/29 at the same x, 29/29 within 1 m
    assert near / len(xs) >= 0.9 and exact / len(xs) >= 0.85, (exact, near)


def test_identical_training_descriptors_are_too_few_not_an_internal_error():
    # identical rows cannot be split into `branching` clusters; this had raised a ValueError about
    # an internal array ("centres: expected one row per node")
    d = np.zeros((50, 32), np.uint8)
    with pytest.raises(TooFewDescriptorsError, match="branching=3 distinct training descriptors, got 1 distinct of 100"):
        Vocabulary.train([d, d], branching=3, levels=2, rng=0)


def test_a_vocabulary_file_with_a_huge_branching_factor_is_refused(tmp_path, clustered_images):
    # a crafted file with a huge branching factor (10^6) had made transform allocate 15 GB
    arrays = Vocabulary.train(clustered_images, branching=5, levels=2, rng=0).arrays()
    wide = np.full((arrays["children"].shape[0], 10**4), -1, np.int64)
    wide[:, :5] = arrays["children"]
    arrays["children"] = wide
    np.savez(tmp_path / "wide.npz", **arrays)
    with pytest.raises(VocabularyFileError, match="branching factor"):
        Vocabulary.load(tmp_path / "wide.npz")
