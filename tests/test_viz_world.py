"""robokit.viz 3D helpers produce static HTML carrying the objects; matplotlib map helpers draw."""
import base64
import re

import matplotlib

matplotlib.use("Agg")
import numpy as np
import pytest
import umsgpack

from robokit.sim import Lidar, PinholeCamera, box_room, field_world, lab_lap, lab_room
from robokit.viz import (Scene, add_camera, add_landmarks, add_particles, add_trajectory, add_world, animate_poses, look_from,
                         plot_covariance, plot_footprint, plot_occupancy, plot_scan, plot_trajectory)


def decoded(scene):
    blobs = re.search(r"robokitCommands = \[(.*?)\];", scene.html(), re.S).group(1)
    return [umsgpack.unpackb(base64.b64decode(b.strip().strip('"'))) for b in blobs.split(",") if b.strip()]


def test_world_scene_carries_textured_mesh_and_footprint():
    world = box_room()
    cmds = decoded(add_world(Scene(), world))
    mesh = next(c for c in cmds if c["path"] == "/meshcat/world/surfaces")
    geom = mesh["object"]["geometries"][0]
    assert set(geom["data"]["attributes"]) == {"position", "uv"}
    assert mesh["object"]["textures"][0]["image"] == mesh["object"]["images"][0]["uuid"]
    assert mesh["object"]["images"][0]["url"].startswith("data:image/png;base64,")
    n_faces = len(geom["data"]["index"]["array"].data) // 4 // 3
    visible = [s for s in world.surfaces if not (s.normal[2] < -0.5 and s.corner[2] >= world.height - 1e-6)]
    assert n_faces == 2 * len(visible)
    foot = next(c for c in cmds if c["path"] == "/meshcat/world/footprint")
    assert foot["object"]["object"]["type"] == "LineSegments"


def test_outdoor_backdrop_is_hidden_like_a_ceiling():
    world = field_world((20.0, 12.0), circles=[[5.0, 5.0, 0.5]], seed=0)

    def faces(**kw):
        mesh = next(c for c in decoded(add_world(Scene(), world, **kw)) if c["path"] == "/meshcat/world/surfaces")
        return len(mesh["object"]["geometries"][0]["data"]["index"]["array"].data) // 4 // 3

    backdrop = [s for s in world.surfaces if s.name.startswith("backdrop/")]
    assert len(backdrop) >= 9  # far ground, sky band and zenith
    assert faces(ceiling=True) == 2 * len(world.surfaces)
    assert faces() == 2 * (len(world.surfaces) - len(backdrop))


def test_helpers_record_their_objects():
    world = lab_room()
    cam = PinholeCamera.from_fov()
    scene = Scene()
    add_camera(scene, "cam", cam, cam.transform_at([5, 2, 1.57]))
    add_trajectory(scene, "traj", lab_lap(world).poses, every=50)
    add_particles(scene, "pf", np.random.default_rng(0).normal([5, 5, 0], 0.3, (50, 3)), weights=np.ones(50))
    cov = np.tile(np.diag([0.01, 0.04, 0.02]), (4, 1, 1))
    add_landmarks(scene, "lm", np.random.default_rng(1).uniform(0, 10, (4, 3)), cov)
    scene.add_box("robot", (0.4, 0.3, 0.2))
    animate_poses(scene, "robot", lab_lap(world).poses[::20])
    cmds = decoded(scene)
    paths = {c.get("path") for c in cmds}
    for p in ["/meshcat/cam/frustum", "/meshcat/traj/line", "/meshcat/pf/points", "/meshcat/pf/headings",
              "/meshcat/lm/points", "/meshcat/lm/ellipsoid3"]:
        assert p in paths, p
    anim = next(c for c in cmds if c["type"] == "set_animation")
    assert anim["animations"][0]["path"] == "/meshcat/robot"
    keys = anim["animations"][0]["clip"]["tracks"][0]["keys"]
    assert len(keys) == len(lab_lap(world).poses[::20])
    look_from(scene, [-5.0, -4.0, 9.0])
    cam = decoded(scene)[-1]
    assert cam["path"] == "/Cameras/default/rotated/<object>" and cam["value"] == [-5.0, 9.0, 4.0]
    ell = next(c for c in cmds if c.get("path") == "/meshcat/lm/ellipsoid0" and c["type"] == "set_transform")
    T = np.array(ell["matrix"]).reshape(4, 4).T
    assert np.allclose(np.abs(np.linalg.det(T[:3, :3])), 1)


def test_maps_draw_with_labelled_axes():
    import matplotlib.pyplot as plt

    world = box_room()
    lidar = Lidar(r_max=20)
    pose = [2.0, 1.5, 0.3]
    ax = plot_footprint(world)
    plot_scan(lidar.scan(world, pose), lidar.sensor_pose(pose), lidar.angles, ax=ax, rays=True)
    plot_trajectory(np.array([[1, 1, 0], [2, 1, 0.5], [3, 2, 1.0]]), ax=ax, every=1)
    plot_covariance([3, 3], [[0.04, 0.01], [0.01, 0.02]], ax=ax)
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "y [m]"
    fs = world.free_space(0.1)
    ax2 = plot_occupancy(np.where(fs.free, 0.0, 1.0), fs.origin, fs.resolution)
    assert ax2.images[0].get_extent()[1] == pytest.approx(fs.origin[0] + fs.free.shape[1] * 0.1)
    plt.close("all")


@pytest.mark.parametrize("call, match", [
    (lambda: add_world(Scene(), "lab"), "world"),
    (lambda: add_landmarks(Scene(), "lm", np.zeros((2, 3)), np.tile(-np.eye(3), (2, 1, 1))), "covariances"),
    (lambda: add_landmarks(Scene(), "lm", np.zeros((2, 3)), np.zeros((3, 3, 3))), "covariances"),
    (lambda: add_particles(Scene(), "pf", np.zeros((3, 3)), weights=[-1, 0, 0]), "weights"),
    (lambda: animate_poses(Scene(), "x", np.zeros((1, 3))), "transforms"),
    (lambda: look_from(Scene(), [0, 0, 0]), "position"),
    (lambda: plot_occupancy(np.full((3, 3), 2.0), (0, 0), 0.1), "grid"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()
