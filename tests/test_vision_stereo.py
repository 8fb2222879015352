"""Rectified stereo (Lin et al. Sec. 3; Se et al. Sec. 2.2 and 3.1) on synthetic ground truth."""
import cv2
import numpy as np
import pytest
from matplotlib import cbook
from PIL import Image
from scipy.stats import chi2

from robokit.vision.descriptors import detect_plot_features, detect_sift_features
from robokit.vision.evaluation import similarity_homography
from robokit.vision.features import Features
from robokit.vision.stereo import (NotRectifiedError, StereoCalibration, disparity_to_point, match_stereo,
                                   triangulate_svd)

RIG = StereoCalibration(focal=400.0, c0=319.5, r0=239.5, baseline=0.12)


@pytest.fixture(scope="module")
def photo():
    with cbook.get_sample_data("grace_hopper.jpg") as f:
        img = np.array(Image.open(f).convert("L"))
    return cv2.resize(img, (640, 480), interpolation=cv2.INTER_AREA)


def _random_points(rng, n):
    z = rng.uniform(1.0, 8.0, n)
    x = rng.uniform(-0.6, 0.6, n) * z
    y = rng.uniform(-0.4, 0.4, n) * z
    return np.column_stack([x, y, z])


def test_disparity_formulas_invert_the_projection():
    pts = _random_points(np.random.default_rng(0), 50)
    (cl, rl), (cr, rr) = (a.T for a in RIG.project(pts))
    assert np.allclose(rl, rr)
    est, _ = disparity_to_point(cl, rl, cl - cr, RIG)
    assert np.allclose(est, pts)
    assert np.allclose(triangulate_svd(*RIG.projection_matrices(), np.column_stack([cl, rl]),
                                       np.column_stack([cr, rr])), pts)


def test_svd_triangulation_handles_a_general_camera_pair():
    rng = np.random.default_rng(4)
    pts = rng.uniform([-1, -1, 3], [1, 1, 6], (30, 3))
    k = np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]])
    ang = 0.1
    rot = np.array([[np.cos(ang), 0, np.sin(ang)], [0, 1, 0], [-np.sin(ang), 0, np.cos(ang)]])
    pl = k @ np.hstack([np.eye(3), np.zeros((3, 1))])
    pr = k @ np.hstack([rot, [[-0.3], [0.05], [0.0]]])
    proj = lambda p: (np.c_[pts, np.ones(30)] @ p.T)[:, :2] / (np.c_[pts, np.ones(30)] @ p.T)[:, 2:]  # noqa: E731
    assert np.allclose(triangulate_svd(pl, pr, proj(pl), proj(pr)), pts, atol=1e-8)
    with pytest.raises(ValueError, match="point at infinity"):
        triangulate_svd(*RIG.projection_matrices(), [[100.0, 50.0]], [[100.0, 50.0]])


def test_points_lie_within_their_propagated_three_sigma():
    rng = np.random.default_rng(1)
    pts = _random_points(rng, 4000)
    (cl, rl), (cr, _) = (a.T for a in RIG.project(pts))
    # Se et al. Sec. 3.1: sigma_r = sigma_c = 1 px, sigma_d^2 = 1
    c = cl + rng.normal(size=cl.size)
    r = rl + rng.normal(size=cl.size)
    d = (cl - cr) + rng.normal(size=cl.size)
    est, cov = disparity_to_point(c, r, d, RIG)
    err = est - pts
    m2 = np.einsum("ni,nij,nj->n", err, np.linalg.inv(cov), err)
    inside = m2 <= chi2.ppf(0.9973, 3)
    # first-order propagation is slightly optimistic for the farthest points (d ~ 6 px)
    assert inside.mean() > 0.985
    near = (cl - cr) > 20
    assert abs(np.mean(m2[near]) - 3.0) < 0.3  # chi-square with 3 dof when the linearisation holds
    # the depth direction dominates and grows with Z^2 (Se et al. Fig. 2)
    assert np.all(cov[:, 2, 2] > cov[:, 0, 0]) and np.all(cov[:, 2, 2] > cov[:, 1, 1])
    far, close = np.argmax(pts[:, 2]), np.argmin(pts[:, 2])
    assert cov[far, 2, 2] > 100 * cov[close, 2, 2]


def test_disparity_input_is_validated():
    with pytest.raises(ValueError, match="d: expected positive disparities"):
        disparity_to_point([1.0], [2.0], [0.0], RIG)
    with pytest.raises(ValueError, match="r: expected shape"):
        disparity_to_point([1.0, 2.0], [2.0], [3.0, 1.0], RIG)
    with pytest.raises(TypeError, match="rig"):
        disparity_to_point([1.0], [2.0], [3.0], "rig")
    with pytest.raises(ValueError, match="baseline"):
        StereoCalibration(400.0, 320.0, 240.0, -0.1)


def test_rig_from_projections_refuses_unrectified_pairs():
    pl, pr = RIG.projection_matrices()
    assert StereoCalibration.from_projections(3 * pl, pr) == RIG
    bad = pr.copy()
    bad[1, 3] = 20.0  # vertical offset between the cameras
    with pytest.raises(NotRectifiedError, match="rectified"):
        StereoCalibration.from_projections(pl, bad)
    assert issubclass(NotRectifiedError, ValueError)


def _two_plane_pair(photo, z_near=2.1, z_far=4.3, split=320):
    """Right image of a scene made of two fronto-parallel textured planes (left half nearer)."""
    d_near, d_far = RIG.focal * RIG.baseline / z_near, RIG.focal * RIG.baseline / z_far
    shift = lambda d: cv2.warpAffine(photo, np.float32([[1, 0, -d], [0, 1, 0]]), (640, 480),  # noqa: E731
                                     flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)
    cols = np.arange(640)[None, :]
    right = np.where(cols + d_near < split, shift(d_near), shift(d_far))
    return right.astype(np.uint8), (z_near, z_far)


@pytest.mark.parametrize("extract", [detect_plot_features, detect_sift_features], ids=["plot", "sift"])
def test_stereo_matching_recovers_depth_of_textured_planes(photo, extract):
    right, (z_near, z_far) = _two_plane_pair(photo)
    fl, fr = extract(photo), extract(right)
    m = match_stereo(fl, fr, max_disparity=60)
    assert len(m) > 150
    xy = fl.keypoints.xy[m.left]
    pts, cov = disparity_to_point(xy[:, 0], xy[:, 1], m.disparity, RIG)
    away = np.abs(xy[:, 0] - 320) > 30          # keep clear of the occlusion boundary
    z_true = np.where(xy[:, 0] < 320, z_near, z_far)
    zscore = (pts[:, 2] - z_true) / np.sqrt(cov[:, 2, 2])
    assert np.mean(np.abs(zscore[away]) <= 3) > 0.97
    assert np.all(np.abs(fl.keypoints.xy[m.left, 1] - fr.keypoints.xy[m.right, 1]) <= 1.5)
    assert len(np.unique(m.right)) == len(m)


def test_ambiguous_and_unrectified_input(photo):
    f = detect_plot_features(photo, max_keypoints=400)
    # a right image with every feature duplicated is ambiguous everywhere
    kp = f.keypoints
    from robokit.vision.features import Keypoints
    twin = Keypoints(np.vstack([kp.xy - [10, 0], kp.xy - [10.5, 0]]), np.tile(kp.scale, 2),
                     np.tile(kp.response, 2), np.tile(kp.orientation, 2))
    dup = Features(twin, np.vstack([f.descriptors, f.descriptors]))
    assert len(match_stereo(f, dup, require_rectified=False)) == 0
    h = similarity_homography(photo.shape, 1.0, np.deg2rad(8))
    rotated = cv2.warpPerspective(photo, h, (640, 480))
    with pytest.raises(NotRectifiedError, match="rectified pair"):
        match_stereo(f, detect_plot_features(rotated, max_keypoints=400))
    empty = Features(Keypoints.empty(), np.zeros((0, 128), np.float32))
    assert len(match_stereo(f, empty)) == 0 and len(match_stereo(empty, f)) == 0
    with pytest.raises(ValueError, match="max_disparity"):
        match_stereo(f, f, min_disparity=10, max_disparity=5)


def _one(x, y, scale, theta, desc):
    from robokit.vision.features import Keypoints
    return Features(Keypoints([[x, y]], [scale], [1.0], [theta]), np.asarray([desc], np.float32))


def test_orientation_scale_and_disparity_constraints():
    d = np.eye(8)[0]
    left = _one(100.0, 50.0, 2.0, 0.5, d)
    assert len(match_stereo(left, _one(90.0, 50.4, 2.2, 0.6, d), require_rectified=False)) == 1
    assert len(match_stereo(left, _one(90.0, 50.4, 2.2, 1.2, d), require_rectified=False)) == 0  # orientation
    assert len(match_stereo(left, _one(90.0, 50.4, 4.0, 0.6, d), require_rectified=False)) == 0  # scale
    assert len(match_stereo(left, _one(90.0, 53.0, 2.2, 0.6, d), require_rectified=False)) == 0  # epipolar
    assert len(match_stereo(left, _one(110.0, 50.0, 2.2, 0.6, d), require_rectified=False)) == 0  # negative d
    assert len(match_stereo(left, _one(90.0, 50.0, 2.2, 0.6, np.eye(8)[1]), require_rectified=False)) == 0
    m = match_stereo(left, _one(90.0, 50.4, 2.2, 0.6, d), require_rectified=False)
    assert m.disparity[0] == pytest.approx(10.0)


def test_project_refuses_points_behind_the_rig():
    with pytest.raises(ValueError, match="points: expected Z > 0"):
        RIG.project([[0.0, 0.0, -1.0]])


def test_observe_stereo_gives_points_in_the_robot_frame(photo):
    from robokit.vision.stereo import observe_stereo
    right, (z_near, z_far) = _two_plane_pair(photo)
    obs = observe_stereo(detect_plot_features(photo), detect_plot_features(right), RIG)
    assert len(obs) > 150 and obs.covariances.shape == (len(obs), 3, 3)
    assert len(obs.features) == len(obs) and obs.features.descriptors.shape[1] == 128
    x = obs.features.keypoints.xy[:, 0]
    away = np.abs(x - 320) > 30
    z_true = np.where(x < 320, z_near, z_far)
    assert np.median(np.abs(obs.points[away, 2] - z_true[away])) < 0.05
    flat = np.full((480, 640), 100, np.uint8)
    assert len(observe_stereo(detect_plot_features(flat), detect_plot_features(right), RIG)) == 0
