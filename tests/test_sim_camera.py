"""Pinhole, stereo and omni cameras agree with the renderer (issue 4 acceptance)."""
import dataclasses

import cv2
import numpy as np
import pytest

from robokit.geometry import se2_to_se3, se3_from_rt
from robokit.sim import camera as cm
from robokit.sim.omni import OmniCamera
from robokit.sim.world import World
from robokit.sim.view_matches import ground_truth_inliers, sift_view_pair
from robokit.sim.worlds_outdoor import open_field
from robokit.sim.worlds import box_room, lab_room, long_corridor, office_floor

CAM = cm.PinholeCamera.from_fov(np.deg2rad(65), 640, 480)


def dot_world(a=0.37, b=0.41):
    """box_room with one wall tile replaced by a dark texture carrying a single bright dot."""
    base = box_room()
    target = next(s for s in base.surfaces if s.name == "wall/1/1")  # the wall at y = 4, facing -y
    tex = np.full((200, 200, 3), 30, np.uint8)
    cv2.circle(tex, (int(a * 200), int(b * 200)), 3, (255, 0, 255), -1)  # magenta: no other texture has it
    swapped = [dataclasses.replace(s, texture=tex) if s is target else s for s in base.surfaces]
    world = World(swapped, "dot", base.interior, base.height)
    # centre of the drawn disc in texture coordinates (texel centres at i + 0.5)
    point = target.point((int(a * 200) + 0.5) / 200, (int(b * 200) + 0.5) / 200)
    return world, point


def bright_centroid(image):
    g = image[..., 0].astype(float)
    m = (g > 100) & (image[..., 2] > 100) & (image[..., 1] < 60)
    v, u = np.nonzero(m)
    w = g[m]
    return np.array([(u * w).sum() / w.sum(), (v * w).sum() / w.sum()])


@pytest.mark.parametrize("pose", [[3.0, 1.0, np.pi / 2], [2.0, 2.0, 1.2], [4.2, 1.5, 2.0]])
def test_point_on_wall_is_painted_where_it_projects(pose):
    world, X = dot_world()
    T = CAM.transform_at(pose)
    frame = CAM.render(world, T)
    uv, z = CAM.project(X, T)
    assert np.linalg.norm(bright_centroid(frame.image) - uv[0]) < 1.0


def test_rendered_depth_backprojects_to_the_wall_within_1mm():
    world = box_room()
    T = CAM.transform_at([2.0, 1.5, 0.7])
    frame = CAM.render(world, T)
    rng = np.random.default_rng(0)
    pix = np.column_stack([rng.integers(0, 640, 300), rng.integers(0, 480, 300)]).astype(float)
    depth = frame.depth[pix[:, 1].astype(int), pix[:, 0].astype(int)]
    P = CAM.backproject(pix, depth, T)
    # every back-projected point lies on a wall, the floor or the ceiling of the 6 x 4 x 2.5 room
    gaps = np.min(np.abs(np.column_stack([P[:, 0], P[:, 0] - 6, P[:, 1], P[:, 1] - 4, P[:, 2], P[:, 2] - 2.5])), axis=1)
    assert gaps.max() < 1e-3
    uv, z = CAM.project(P, T)
    np.testing.assert_allclose(uv, pix, atol=1e-6)
    np.testing.assert_allclose(z, depth, rtol=1e-6)


def test_stereo_disparity_is_f_b_over_z():
    world, X = dot_world()
    rig = cm.StereoRig(CAM, baseline=0.2, trinocular=True)
    T = CAM.transform_at([3.0, 1.2, np.pi / 2])
    views = rig.render(world, T)
    uv_l, Z = CAM.project(X, T)
    cl, cr, ct = (bright_centroid(views[k].image) for k in ("left", "right", "top"))
    expected = CAM.fx * 0.2 / Z[0]
    assert abs((cl[0] - cr[0]) - expected) < 1.0 and abs(cl[1] - cr[1]) < 1.0
    # the top camera sits above the left one, so the point appears lower (larger v) in its image
    assert abs((ct[1] - cl[1]) - CAM.fy * 0.2 / Z[0]) < 1.0 and abs(cl[0] - ct[0]) < 1.0
    np.testing.assert_allclose(rig.depth(rig.disparity(Z)), Z)


def test_omni_projection_round_trip_and_renderer():
    cam = OmniCamera()
    rng = np.random.default_rng(1)
    az = rng.uniform(-np.pi, np.pi, 200)
    el = rng.uniform(*cam.elevation_range, 200)
    r = rng.uniform(0.5, 10, 200)
    P = np.column_stack([r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), -r * np.sin(el)])
    uv, ranges = cam.project(P)
    assert np.isfinite(uv).all()
    np.testing.assert_allclose(cam.backproject(uv, ranges), P, atol=1e-9)
    # renderer: the dot appears where the model projects it, at the right range
    world, X = dot_world()
    T = cam.transform_at([3.0, 2.0, 0.3])
    frame = cam.render(world, T)
    uvx, rx = cam.project(X, T)
    c = bright_centroid(frame.image)
    assert np.linalg.norm(c - uvx[0]) < 1.0
    assert abs(frame.depth[int(round(c[1])), int(round(c[0]))] - rx[0]) < 0.02


@pytest.mark.parametrize("builder, pose", [
    (lab_room, [5.0, 2.0, np.pi / 2]), (long_corridor, [3.0, 0.0, 0.0]), (office_floor, [10.0, 4.3, -np.pi / 2]),
    (box_room, [1.0, 1.0, 0.4]), (open_field, [50.0, 30.0, 0.3]),
])
def test_sift_finds_hundreds_of_keypoints_and_correct_matches(builder, pose):
    pair = sift_view_pair(builder(), CAM, pose, step=0.3)
    print(f"{builder.__name__}: {pair.keypoints} keypoints, {pair.matches} matches, inlier ratio "
          f"{pair.inlier_ratio:.3f}")
    assert pair.keypoints >= 200
    assert pair.matches >= 50
    assert pair.inlier_ratio > 0.8


def test_sift_check_uses_the_vision_ratio_test():
    # the one Lowe ratio test (robokit.vision.ratio_match) with its range check, not a third copy
    with pytest.raises(ValueError, match=r"ratio: expected a value in \(0, 1\], got 1.5"):
        sift_view_pair(box_room(), CAM, [1.0, 1.0, 0.4], ratio=1.5)


def test_ground_truth_inliers_accepts_true_and_rejects_shuffled_correspondences():
    world = lab_room()
    T1, T2 = CAM.transform_at([5.0, 2.0, np.pi / 2]), CAM.transform_at([5.0, 2.3, np.pi / 2])
    depth = CAM.render(world, T1).depth
    rng = np.random.default_rng(0)
    uv1 = np.column_stack([rng.uniform(100, 540, 200), rng.uniform(100, 380, 200)])
    row, col = np.round(uv1[:, 1]).astype(int), np.round(uv1[:, 0]).astype(int)
    uv2, _ = CAM.project(CAM.backproject(uv1, depth[row, col], T1), T2)
    assert ground_truth_inliers(CAM, depth, T1, T2, uv1, uv2).all()
    assert ground_truth_inliers(CAM, depth, T1, T2, uv1, uv2 + [4.0, 0.0]).sum() == 0
    assert ground_truth_inliers(CAM, depth, T1, T2, uv1, uv2[::-1]).mean() < 0.1
    with pytest.raises(ValueError, match="uv2"):
        ground_truth_inliers(CAM, depth, T1, T2, uv1, uv2[:10])
    with pytest.raises(ValueError, match="uv1"):
        ground_truth_inliers(CAM, depth, T1, T2, uv1 + [1000.0, 0.0], uv2)
    with pytest.raises(TypeError, match="camera"):
        ground_truth_inliers("cam", depth, T1, T2, uv1, uv2)


def test_lighting_and_noise_change_the_image_reproducibly():
    world = box_room()
    T = CAM.transform_at([3.0, 2.0, 0.0])
    a = CAM.render(world, T).image
    dark = CAM.render(world, T, lighting={"gain": 0.5}).image
    assert dark.mean() < 0.6 * a.mean()
    n1 = CAM.render(world, T, noise=5, rng=3).image
    n2 = CAM.render(world, T, noise=5, rng=3).image
    assert np.array_equal(n1, n2) and not np.array_equal(n1, a)
    assert abs((n1.astype(float) - a).std() - 5) < 0.5
    # the noise is the generator's normal(0, sigma) draw, added and clipped: recordings made before
    # and after any speed-up of the noise see the same pixels
    expected = np.clip(a + np.random.default_rng(3).normal(0.0, 5.0, a.shape), 0, 255).astype(np.uint8)
    assert np.array_equal(n1, expected)


@pytest.mark.parametrize("call, match", [
    (lambda: cm.PinholeCamera(0.0, 500, 320, 240), "fx"),
    (lambda: cm.PinholeCamera(500, -1.0, 320, 240), "fy"),
    (lambda: cm.StereoRig(CAM, baseline=0.0), "baseline"),
    (lambda: cm.StereoRig(CAM, baseline=-0.1), "baseline"),
    (lambda: CAM.render(box_room(), np.full((4, 4), np.nan)), "T_world_cam"),
    (lambda: CAM.observe(box_room(), [np.nan, 1.0, 0.0]), "robot_pose"),
    (lambda: CAM.observe(box_room(), [-1.0, 1.0, 0.0]), "robot_pose"),       # outside the world
    (lambda: CAM.observe(box_room(), [0.01, 1.0, 0.0]), "robot_pose"),       # inside a wall
    (lambda: CAM.observe(lab_room(), [5.5, 5.0, 0.0]), "robot_pose"),        # inside the table
    (lambda: CAM.render(box_room(), se3_from_rt(np.eye(3), [3, 2, 3.0])), "T_world_cam"),  # above the ceiling
    (lambda: cm.StereoRig(CAM).observe(box_room(), [0.01, 1.0, 0.0]), "robot_pose"),
    (lambda: CAM.render("world", se2_to_se3([1, 1, 0], 1)), "world"),
    (lambda: World([], "empty", (0, 0), 2.5), "surfaces"),
    (lambda: OmniCamera(xi=0.0), "xi"),
    (lambda: OmniCamera().observe(box_room(), [7.0, 1.0, 0.0]), "robot_pose"),
    (lambda: OmniCamera().render(box_room(), se3_from_rt(np.eye(3), [7.0, 1.0, 1.0])), "T_world_omni"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_a_view_that_sees_no_surface_is_black_with_infinite_depth():
    import warnings
    from robokit.sim.render import render_pinhole
    cam = CAM
    T = np.eye(4)
    T[:3, 3] = [100.0, 100.0, 1.0]                  # far outside the room, looking away from it
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        image, depth = render_pinhole(box_room(), cam.K, cam.width, cam.height, T)
    assert image.shape == (cam.height, cam.width, 3) and not image.any() and np.isinf(depth).all()


@pytest.mark.parametrize("builder", [box_room, lab_room])
def test_the_renderers_mip_sizes_are_the_pyramids(builder):
    world = builder()
    arrays = world.surface_arrays
    for k, s in enumerate(world.surfaces):
        assert arrays["mip_levels"][k] == len(s.pyramid)
        assert [tuple(size) for size in arrays["mip_sizes"][k, :len(s.pyramid)]] == \
            [lv.shape[1::-1] for lv in s.pyramid]
