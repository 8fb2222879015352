"""Orientation, SIFT-style and reduced descriptors (Lin et al. Sec. 2.ii, Se et al. Sec. 4)."""
import cv2
import numpy as np
import pytest
from matplotlib import cbook
from PIL import Image

from robokit.vision.descriptors import (assign_orientations, detect_and_describe, detect_plot_features,
                                        reduced_descriptor, sift_descriptor, detect_sift_features)
from robokit.vision.evaluation import apply_homography, similarity_homography
from robokit.vision.features import Features, Keypoints
from robokit.vision.plot_detector import detect_plot


@pytest.fixture(scope="module")
def photo():
    with cbook.get_sample_data("grace_hopper.jpg") as f:
        img = np.array(Image.open(f).convert("L"))
    return cv2.resize(img, (640, 480), interpolation=cv2.INTER_AREA)


def _circ(a):
    return np.abs(np.angle(np.exp(1j * a)))


def test_orientation_of_a_ramp_points_uphill():
    y, x = np.mgrid[0:64, 0:64].astype(float)
    for angle in (0.3, 2.0, 4.0):
        img = 0.5 + 0.004 * (np.cos(angle) * x + np.sin(angle) * y)
        kp = Keypoints([[32.0, 32.0]], [2.0], [1.0], [0.0])
        out = assign_orientations(img, kp)
        assert len(out) == 1
        assert _circ(out.orientation[0] - angle) < np.deg2rad(2)


def test_orientation_follows_image_rotation(photo):
    kp = detect_plot(photo, max_keypoints=300)
    angle = np.deg2rad(40)
    h = similarity_homography(photo.shape, 1.0, angle)
    warped = cv2.warpPerspective(photo, h, (640, 480))
    kp = kp.subset(np.all((apply_homography(h, kp.xy) > 30) & (apply_homography(h, kp.xy) < [610, 450]), axis=1))
    a = assign_orientations(photo, kp, peak_ratio=1.0)
    moved = Keypoints(apply_homography(h, a.xy), a.scale, a.response, a.orientation)
    b = assign_orientations(warped, moved, peak_ratio=1.0)
    inside = np.ones(len(b), bool)
    # y points down, so an on-screen counter-clockwise rotation lowers atan2(dy, dx) by the angle
    err = _circ(b.orientation - (a.orientation - angle))
    assert len(a) == len(b) and inside.sum() > 100
    assert np.median(err[inside]) < np.deg2rad(5)


def test_descriptors_are_unit_vectors_with_the_papers_sizes(photo):
    f = detect_plot_features(photo, max_keypoints=200)
    assert isinstance(f, Features) and f.descriptors.shape == (len(f), 128)
    assert np.allclose(np.linalg.norm(f.descriptors, axis=1), 1, atol=1e-5)
    r = reduced_descriptor(photo, f.keypoints)
    assert r.shape == (len(f), 16) and np.allclose(np.linalg.norm(r, axis=1), 1, atol=1e-5)


def test_descriptor_is_rotation_invariant(photo):
    f = detect_plot_features(photo, max_keypoints=300)
    h = similarity_homography(photo.shape, 1.0, np.deg2rad(70))
    warped = cv2.warpPerspective(photo, h, (640, 480))
    kp = f.keypoints
    moved = Keypoints(apply_homography(h, kp.xy), kp.scale, kp.response,
                      np.mod(kp.orientation - np.deg2rad(70), 2 * np.pi))
    inside = np.all((moved.xy > 40) & (moved.xy < [600, 440]), axis=1)
    for fn, d in ((sift_descriptor, f.descriptors), (reduced_descriptor, reduced_descriptor(photo, kp))):
        w = fn(warped, moved)
        same = np.linalg.norm(d - w, axis=1)[inside]
        other = np.linalg.norm(d - np.roll(w, 7, axis=0), axis=1)[inside]
        assert np.median(same) < 0.5 * np.median(other)


def test_opencv_sift_wrapper_matches_our_conventions(photo):
    s = detect_sift_features(photo)
    assert isinstance(s, Features) and s.descriptors.shape[1] == 128 and len(s) > 200
    assert np.allclose(np.linalg.norm(s.descriptors, axis=1), 1, atol=1e-5)
    # our orientation histogram agrees with OpenCV's at OpenCV's own keypoints
    ours = assign_orientations(photo, Keypoints(s.keypoints.xy, s.keypoints.scale, s.keypoints.response,
                                                np.zeros(len(s))), peak_ratio=1.0)
    strong = s.keypoints.scale > 2.0
    assert np.median(_circ(ours.orientation - s.keypoints.orientation)[strong]) < np.deg2rad(10)
    r = detect_sift_features(photo, n_features=50, descriptor="reduced16")
    assert r.descriptors.shape[1] == 16 and len(r) <= 60


def test_interchangeable_and_empty_results():
    flat = np.full((60, 80), 128, np.uint8)
    for method in ("plot", "sift"):
        f = detect_and_describe(flat, method)
        assert len(f) == 0 and f.descriptors.shape == (0, 128)
        assert detect_and_describe(flat, method, descriptor="reduced16").descriptors.shape == (0, 16)
    with pytest.raises(ValueError, match="method: expected one of"):
        detect_and_describe(flat, "surf")
    with pytest.raises(ValueError, match="descriptor: expected one of"):
        detect_plot_features(flat, descriptor="128")
    with pytest.raises(TypeError, match="keypoints: expected Keypoints"):
        sift_descriptor(flat, np.zeros((3, 2)))
    with pytest.raises(ValueError, match="scale"):
        Keypoints([[1.0, 2.0]], [0.0], [1.0], [0.0])


def test_eight_bit_images_in_other_dtypes_give_the_same_orb_features():
    # img.astype(int) and 0..255 floats had given no features at all, silently
    from robokit.vision.orb import detect_orb_features

    rng = np.random.default_rng(0)
    image = ((rng.random((120, 160)) > 0.5) * 255).astype(np.uint8)
    want = detect_orb_features(image, 100)
    for other in (image.astype(int), image.astype(np.int16)):
        got = detect_orb_features(other, 100)
        np.testing.assert_array_equal(got.descriptors, want.descriptors)
    with pytest.raises(ValueError, match=r"image: expected float pixel values in \[0, 1\], got values from 0 to 255"):
        detect_orb_features(image.astype(float), 100)
    with pytest.raises(ValueError, match="expected 8-bit pixel values 0..255"):
        detect_orb_features(image.astype(int) * 4, 100)
    np.testing.assert_array_equal(detect_orb_features(image / 255.0, 100).descriptors, want.descriptors)
