"""The outdoor field of seed 000 Q3 as a 3D world (issue 4): closed, LiDAR-exact, camera-consistent,
and built from the same obstacle layout as lesson 05's 2D field."""
import dataclasses
import importlib
import inspect
import pkgutil

import cv2
import numpy as np
import pytest

from robokit.outdoor.field import Field, random_course
from robokit.sim import Layout, Lidar, PinholeCamera, field_world, camera_mount, open_field
from robokit.sim.worlds_outdoor import scatter_obstacles
from robokit.sim.worlds_outdoor import SIDES, build_open_field
from robokit.sim.world import World
from tests.test_sim_lidar_motion import analytic_box_ranges

CAM = PinholeCamera.from_fov(np.deg2rad(65), 640, 480)
BOX = [8.0, 6.0, 2.0, 1.0, 0.4]  # cx, cy, length, width, yaw


def small_field():
    return field_world((20.0, 12.0), boxes=[BOX], seed=1, border=3.0)


def test_open_field_is_closed_seeded_and_holds_its_layout():
    w = open_field()
    assert w.name == "open_field" and w.info["size"] == (100.0, 60.0)
    np.testing.assert_allclose(w.bounds, [-3, -3, 103, 63])  # the hedge closes the footprint
    fs = w.free_space()  # raises if the walls do not enclose the interior
    assert fs.resolution == 0.05 and not fs.free[0].any() and not fs.free[-1].any()
    np.testing.assert_allclose(w.interior, [50.0, 30.0])
    assert len(w.info["circles"]) + len(w.info["boxes"]) == 14 + 1  # scattered + the shed
    kinds = {kind for _, kind, _ in w.info["obstacles"]}
    assert "shed" in kinds and kinds <= {"tree", "post", "bale", "crate", "shed"}
    # every obstacle blocks: its centre is not free space, and a point outside the hedge is not either
    centres = np.vstack([w.info["circles"][:, :2], w.info["boxes"][:, :2]])
    assert not w.is_free(centres, clearance=0.0).any()
    assert not w.is_free([[-5.0, 30.0]], clearance=0.0)[0]
    # the skybox is not solid: nothing of it is in the LiDAR footprint
    assert all(not s.solid for s in w.surfaces if s.name.startswith("backdrop/"))
    # seeded and deterministic
    fresh = build_open_field(0, 100.0, 60.0, 14, True, 3.0)
    assert fresh is not w and np.array_equal(fresh.info["boxes"], w.info["boxes"])
    assert all(np.array_equal(s.texture, t.texture) for s, t in zip(w.surfaces, fresh.surfaces))
    other = open_field(seed=1)
    assert not np.array_equal(other.info["boxes"][1:], w.info["boxes"][1:])


def _slab_distance(o, angles, box):
    """Analytic ray-oriented-box distance (slab method in the box frame, Kay & Kajiya 1986)."""
    cx, cy, L, W, yaw = box
    c, s = np.cos(yaw), np.sin(yaw)
    rel = np.array([o[0] - cx, o[1] - cy])
    ox, oy = c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1]
    dx, dy = np.cos(angles - yaw), np.sin(angles - yaw)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.sort(np.stack([(-L / 2 - ox) / dx, (L / 2 - ox) / dx]), axis=0)
        ty = np.sort(np.stack([(-W / 2 - oy) / dy, (W / 2 - oy) / dy]), axis=0)
    t0, t1 = np.maximum(tx[0], ty[0]), np.minimum(tx[1], ty[1])
    return np.where((t1 >= t0) & (t0 > 0), t0, np.inf)


def _rect_exit(o, angles, x0, y0, x1, y1):
    """Distance from a point inside the rectangle (the hedge) to its boundary along each ray."""
    return analytic_box_ranges(o[0] - x0, o[1] - y0, angles, x1 - x0, y1 - y0)


@pytest.mark.parametrize("pose", [[4.0, 5.0, 0.3], [12.0, 2.0, 2.0], [7.0, 9.5, -1.0]])
def test_lidar_ranges_equal_analytic_distances_to_box_and_hedge(pose):
    world = small_field()
    lidar = Lidar(beams=720, r_min=0.0, r_max=100.0)
    ranges = lidar.scan(world, pose)
    ang = lidar.angles + pose[2]
    expected = np.minimum(_slab_distance(pose[:2], ang, BOX), _rect_exit(pose[:2], ang, -3, -3, 23, 15))
    assert np.isfinite(ranges).all()
    np.testing.assert_allclose(ranges, expected, rtol=0, atol=1e-9)
    assert np.isfinite(_slab_distance(pose[:2], ang, BOX)).sum() > 20  # the box is really seen


def _hedge(x0, y0, x1, y1):
    c = [(x0, y0), (x0, y1), (x1, y1), (x1, y0)]
    return [[c[k], c[(k + 1) % 4]] for k in range(4)]


def test_lesson05_course_and_3d_world_share_the_layout():
    course = random_course(7)
    world = course.field.world(seed=7)
    np.testing.assert_array_equal(world.info["boxes"], course.field.boxes)
    np.testing.assert_array_equal(world.info["circles"], course.field.circles)
    o = course.start[:2]
    # boxes are exact: a field of the course's boxes alone ray-casts like the 3D footprint
    boxes_only = Field(size=course.field.size, boxes=course.field.boxes)
    aim = np.arctan2(course.field.boxes[:, 1] - o[1], course.field.boxes[:, 0] - o[0])
    flat = boxes_only.raycast(np.tile(o, (len(aim), 1)), aim, 500.0)
    hedge = _rect_exit(o, aim, -3, -3, 103, 63)
    box_world = field_world(course.field.size, boxes=course.field.boxes, seed=7)
    np.testing.assert_allclose(box_world.layout(0.25).raycast(o, aim), np.minimum(flat, hedge), rtol=0, atol=1e-9)
    # circles are prisms with corners on the circle: hit no earlier, and at most r (1 - cos(pi / SIDES)) later
    c = course.field.circles
    aim = np.arctan2(c[:, 1] - o[1], c[:, 0] - o[0])
    t3 = world.layout(0.25).raycast(o, aim)
    t2 = np.minimum(course.field.raycast(np.tile(o, (len(aim), 1)), aim, 500.0), _rect_exit(o, aim, -3, -3, 103, 63))
    assert np.all(t3 >= t2 - 1e-9)
    assert np.all(t3 - t2 <= 0.8 * (1 - np.cos(np.pi / SIDES)) + 1e-9)


@pytest.mark.parametrize("seed", [3, 7])
def test_lidar_and_the_field_agree_on_the_same_geometry(seed):
    """A LiDAR scanning the 3D world of a field of boxes reads what the field's own ray caster
    (the sonars') returns for the same rays with the hedge added as walls: one geometry, one tie rule."""
    course = random_course(seed)
    field = Field(size=course.field.size, boxes=course.field.boxes)
    world = field.world(seed=seed)
    both = Layout(segments=_hedge(*world.info["hedge"]), boxes=field.boxes)
    lidar = Lidar(beams=720, r_min=0.0, r_max=500.0)
    for pose in [course.start, [*course.waypoints[0], 1.0], [*course.waypoints[-1], -2.0]]:
        sensor = lidar.sensor_pose(pose)
        np.testing.assert_allclose(lidar.scan(world, pose), both.raycast(sensor[:2], lidar.angles + sensor[2]),
                                   rtol=0, atol=1e-9)
        sonar_rays = field.raycast(np.tile(sensor[:2], (720, 1)), lidar.angles + sensor[2], 6.45)
        np.testing.assert_allclose(np.minimum(lidar.scan(world, pose), 6.45), np.minimum(sonar_rays, np.minimum(
            _rect_exit(sensor[:2], lidar.angles + sensor[2], *world.info["hedge"]), 6.45)), rtol=0, atol=1e-9)


def test_point_on_an_obstacle_face_is_painted_where_it_projects():
    base = small_field()
    prefix = base.info["obstacles"][0][0]
    target = next(s for s in base.surfaces if s.name == f"{prefix}/side0/0")  # the box's -y face
    tex = np.full((160, 160, 3), 30, np.uint8)
    a, b = 0.43, 0.37
    cv2.circle(tex, (int(a * 160), int(b * 160)), 3, (255, 0, 255), -1)
    world = World([dataclasses.replace(s, texture=tex) if s is target else s for s in base.surfaces],
                  "dot", base.interior, base.height, free_resolution=0.05)
    X = target.point((int(a * 160) + 0.5) / 160, (int(b * 160) + 0.5) / 160)
    n = target.normal
    assert abs(n[2]) < 1e-12
    for dist, side in [(3.0, 0.0), (5.0, 0.6), (2.5, -0.5)]:
        eye = X[:2] + dist * n[:2] + side * np.array([-n[1], n[0]])
        T = CAM.transform_at([eye[0], eye[1], np.arctan2(X[1] - eye[1], X[0] - eye[0])])
        frame = CAM.render(world, T)
        g = frame.image.astype(float)
        uv, z = CAM.project(X, T)
        # magenta pixels at the face's depth (the posters on the hedge have magenta too)
        m = (g[..., 0] > 100) & (g[..., 2] > 100) & (g[..., 1] < 60) & (np.abs(frame.depth - z[0]) < 1.0)
        v, u = np.nonzero(m)
        centroid = np.array([(u * g[m, 0]).sum(), (v * g[m, 0]).sum()]) / g[m, 0].sum()
        assert np.linalg.norm(centroid - uv[0]) < 1.0
        # the rendered depth at that pixel puts the back-projected point on the face's plane
        px = np.round(uv)
        P = CAM.backproject(px, frame.depth[int(px[0, 1]), int(px[0, 0])], T)
        assert abs((P[0] - X) @ n) < 1e-3


def test_every_pixel_sees_something_with_finite_depth():
    world = open_field()
    for pose, pitch in [([1.0, 1.0, np.pi * 1.25], 0.0), ([50.0, 30.0, 0.0], -0.7), ([99.0, 59.0, 0.8], 0.5)]:
        cam = PinholeCamera.from_fov(mount=camera_mount(1.5, pitch=pitch))
        frame = cam.observe(world, pose)
        assert np.isfinite(frame.depth).all() and frame.depth.max() < 500  # every pixel hit a surface


def test_scatter_obstacles_respects_gaps_and_keep_clear():
    rng = np.random.default_rng(3)
    circles, boxes = scatter_obstacles(rng, 30, (60.0, 40.0), keep_clear=[((30.0, 20.0), 5.0)], min_gap=2.0)
    assert len(circles) + len(boxes) == 30
    centres = np.vstack([circles[:, :2], boxes[:, :2]])
    radii = np.concatenate([circles[:, 2], np.hypot(boxes[:, 2], boxes[:, 3]) / 2])
    d = np.linalg.norm(centres[:, None] - centres[None], axis=2) - radii[:, None] - radii[None]
    np.fill_diagonal(d, np.inf)
    assert d.min() >= 2.0
    assert np.all(np.linalg.norm(centres - [30.0, 20.0], axis=1) - radii >= 5.0)
    assert np.all((centres >= 2.0) & (centres <= [58.0, 38.0]))


@pytest.mark.parametrize("call, match", [
    (lambda: open_field(size=(-1.0, 60.0)), r"size\[0\]: expected a positive number, got -1"),
    (lambda: open_field(size=(100.0, np.nan)), r"size: expected finite values, got NaN"),
    (lambda: open_field(size=(100.0,)), r"size: expected shape \(2\)"),
    (lambda: open_field(size=(8.0, 60.0)), r"size: expected at least 12 m x 10 m with a shed, got 8 m x 60 m"),
    (lambda: open_field(n_obstacles=400), r"n_obstacles: expected at most what fits .* got 400 \(only \d+ placed\)"),
    (lambda: open_field(n_obstacles=-1), r"n_obstacles: expected an integer >= 0, got -1"),
    (lambda: open_field(seed=-2), r"seed: expected an integer >= 0, got -2"),
    (lambda: open_field(border=0.0), r"border: expected a positive number, got 0"),
    (lambda: open_field(shed="yes"), r"shed: expected True or False, got 'yes'"),
    (lambda: field_world(circles=[[5.0, 5.0, -1.0]]), r"circles: expected positive sizes .* got -1"),
    (lambda: scatter_obstacles(0, 3, boxes=[[5.0, 5.0, 0.0, 1.0, 0.0]]), r"boxes: expected positive sizes"),
    (lambda: field_world(boxes=[[5.0, 5.0, 1.0, 1.0]]), r"boxes: expected shape \(N, 5\), got shape \(1, 4\)"),
    (lambda: field_world(circles=[[0.0, 0.0, 4.0]]), r"circles: expected obstacles inside the hedge"),
    (lambda: field_world(boxes=[[5.0, np.nan, 1.0, 1.0, 0.0]]), r"boxes: expected finite values"),
    (lambda: scatter_obstacles(0, 3, (0.0, 10.0)), r"size\[0\]: expected a positive number"),
    (lambda: scatter_obstacles(0, 3, min_gap=0.0), r"min_gap: expected a positive number"),
    (lambda: CAM.observe(open_field(), [-10.0, 30.0, 0.0]), r"robot_pose: expected a position inside 'open_field'"),
    (lambda: CAM.render(open_field(), np.diag([1.0, 1.0, 1.0, 1.0]) + np.array(
        [[0, 0, 0, 50], [0, 0, 0, 30], [0, 0, 0, 70], [0, 0, 0, 0]])), r"T_world_cam: expected a height"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_outdoor_textures_are_seeded_rgb_images():
    from robokit.sim import textures_outdoor as tox
    for fn in (tox.grass, tox.hedge, tox.bark, tox.straw, tox.planks, tox.painted_post, tox.sky):
        t = fn(64, 48, np.random.default_rng(0))
        assert t.shape == (48, 64, 3) and t.dtype == np.uint8 and t.std() > 3
        assert np.array_equal(t, fn(64, 48, np.random.default_rng(0)))
    with pytest.raises(ValueError, match="width"):
        tox.bark(4, 48)


def test_frustum_clipping_of_far_reaching_ground_keeps_the_picture(monkeypatch):
    import robokit.sim.render as rd
    world = open_field()
    T = CAM.transform_at([20.0, 10.0, 2.0])
    clipped = CAM.render(world, T)
    monkeypatch.setattr(rd, "_FAR_PIXELS", np.inf)  # rasterise the huge projected polygons as they are
    plain = CAM.render(world, T)
    np.testing.assert_array_equal(clipped.depth, plain.depth)
    # only ties between coplanar neighbouring ground tiles may flip, on their shared edges
    assert (clipped.image != plain.image).any(axis=2).mean() < 1e-3


def test_module_names_are_unique_and_not_shadowed():
    # sim/field.py (the 3D field world) once sat beside outdoor/field.py (the 2D Field); and a module
    # named like a function it exports is shadowed by it (``import robokit.sim.field_world`` would
    # give the function), so worlds_outdoor.py holds field_world, open_field and scatter_obstacles
    names = {}
    for package in ("robokit.sim", "robokit.outdoor", "robokit.controllers"):
        pkg = importlib.import_module(package)
        for sub in pkgutil.iter_modules(pkg.__path__):
            assert inspect.ismodule(getattr(pkg, sub.name, pkg)), f"{package}.{sub.name} is shadowed"
            assert sub.name not in names, f"{package}.{sub.name} and {names.get(sub.name)}.{sub.name}"
            names[sub.name] = package
    assert inspect.ismodule(importlib.import_module("robokit.sim.worlds_outdoor"))
