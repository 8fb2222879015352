"""Scene.bounding_box knows where the drawn objects are; fit_view() puts the camera where they fill the view."""
import numpy as np
import pytest
from meshcat.geometry import MeshGeometry

from robokit.geometry import rot_x, rot_z, se3_from_rt
from robokit.sim import box_room
from robokit.viz import Scene, add_landmarks, add_littledog, add_world, fit_view
from robokit.viz.scene import viewer_javascript
from robokit.viz.framing import FAR, FOV, NEAR


def moved(x=0.0, y=0.0, z=0.0, R=np.eye(3)):
    return se3_from_rt(R, [x, y, z])


def box_of(scene, paths=None):
    lo, hi = scene.bounding_box(paths)
    return np.round(np.concatenate([lo, hi]), 6).tolist()


# --- bounds -------------------------------------------------------------------------------------

def test_an_empty_scene_has_no_bounds():
    assert Scene().bounding_box() is None
    assert Scene().add_box("a", (1, 1, 1)).bounding_box("b") is None


def test_a_box_turned_45_degrees_about_z():
    # half extents 1 x 0.5: turned 45 degrees each reaches (1 + 0.5) / sqrt(2) = 1.06066 along x and y
    scene = Scene().add_box("b", (2.0, 1.0, 0.5), moved(1.0, 2.0, 3.0, rot_z(np.pi / 4)))
    r = 1.5 / np.sqrt(2)
    assert box_of(scene) == np.round([1 - r, 2 - r, 2.75, 1 + r, 2 + r, 3.25], 6).tolist()


def test_a_group_moves_its_children_and_a_later_transform_counts():
    scene = Scene().add_box("robot/body", (2.0, 1.0, 0.5))
    scene.set_transform("robot", moved(5.0, 0.0, 0.25))
    assert box_of(scene) == [4.0, -0.5, 0.0, 6.0, 0.5, 0.5]
    scene.set_transform("robot", moved(0.0, 0.0, 0.0, rot_z(np.pi / 2)))       # the group turned: x <-> y
    assert box_of(scene) == [-0.5, -1.0, -0.25, 0.5, 1.0, 0.25]
    scene.set_transform("robot/body", moved(1.0, 0.0, 0.0))                   # body 1 m along the group's x = world y
    assert box_of(scene) == [-0.5, 0.0, -0.25, 0.5, 2.0, 0.25]


def test_each_kind_of_object():
    s = Scene()
    s.add_sphere("ball", 0.5, moved(10.0, 0.0, 0.0))
    assert box_of(s, "ball") == [9.5, -0.5, -0.5, 10.5, 0.5, 0.5]
    # a cylinder's axis is its local y; turned +90 degrees about x, local y goes to world z
    s.add_cylinder("can", 2.0, 0.3, moved(0.0, 0.0, 1.0, rot_x(np.pi / 2)), radius_top=0.1)
    assert box_of(s, "can") == [-0.3, -0.3, 0.0, 0.3, 0.3, 2.0]
    s.add_mesh("tri", [[0, 0, 0], [2, 0, 0], [0, 3, 1]], [[0, 1, 2]], moved(-1.0, 0.0, 0.0))
    assert box_of(s, "tri") == [-1.0, 0.0, 0.0, 1.0, 3.0, 1.0]
    s.add_points("cloud", [[1, 2, 3], [-1, 0, 5]])
    assert box_of(s, "cloud") == [-1.0, 0.0, 3.0, 1.0, 2.0, 5.0]
    s.add_line("path", [[0, 0, 0], [4, -2, 0]])
    assert box_of(s, "path") == [0.0, -2.0, 0.0, 4.0, 0.0, 0.0]
    s.add_triad("axes", moved(1.0, 1.0, 1.0), scale=0.5)
    assert box_of(s, "axes") == [1.0, 1.0, 1.0, 1.5, 1.5, 1.5]
    add_landmarks(s, "lm", [[0.0, 0.0, 7.0]], [np.diag([0.04, 0.09, 0.01])], nsigma=2.0)   # radii 0.4, 0.6, 0.2
    assert box_of(s, "lm/ellipsoid0") == [-0.4, -0.6, 6.8, 0.4, 0.6, 7.2]
    assert box_of(s, ["ball", "path"]) == [0.0, -2.0, -0.5, 10.5, 0.5, 0.5]
    assert box_of(s) == [-1.0, -2.0, -0.5, 10.5, 3.0, 7.2]


def test_paths_are_prefixes_of_whole_names_and_a_replaced_object_counts_once():
    s = Scene().add_box("robot", (1, 1, 1)).add_box("robot2", (1, 1, 1), moved(10.0))
    assert box_of(s, "robot") == [-0.5, -0.5, -0.5, 0.5, 0.5, 0.5]
    assert box_of(s, "/robot2/") == [9.5, -0.5, -0.5, 10.5, 0.5, 0.5]
    s.add_sphere("robot2", 0.1, moved(10.0))                       # replaces the box at that path
    assert box_of(s, "robot2") == [9.9, -0.1, -0.1, 10.1, 0.1, 0.1]
    s.set_object("robot2", MeshGeometry("v 0 0 0\n", "obj"))           # a mesh file: not measured, not counted
    assert s.bounding_box("robot2") is None


def test_a_world_and_a_robot_are_bounded_where_they_are():
    world = box_room()
    lo, hi = add_world(Scene(), world).bounding_box()
    corners = np.concatenate([s.corners for s in world.surfaces])
    floor_and_walls = corners.min(axis=0), corners.max(axis=0)
    assert np.allclose(lo, floor_and_walls[0]) and hi[2] <= floor_and_walls[1][2] + 1e-9
    dog = add_littledog(Scene())
    lo, hi = dog.bounding_box()
    assert lo[2] == pytest.approx(0.0, abs=0.01)                   # standing on the ground: feet at z = 0
    assert 0.15 < hi[2] < 0.3 and 0.3 < hi[0] - lo[0] < 0.5       # trunk 0.2 m up, 0.3 m long + feet


@pytest.mark.parametrize("paths, match", [(42, "paths"), ([], "paths"), (["a", 3], "paths"), ("/", "paths")])
def test_bounds_refuses_bad_paths(paths, match):
    with pytest.raises((TypeError, ValueError), match=match):
        Scene().bounding_box(paths)


# --- frame --------------------------------------------------------------------------------------

def camera_of(scene):
    """Camera position, orbit target, near and far from the recorded commands (meshcat's (x, z, -y) to world)."""
    cmds = scene.commands
    prop = {c["property"]: c["value"] for c in cmds if c["type"] == "set_property"}
    target = [c["value"] for c in cmds if c["type"] == "set_target"][-1]
    world = lambda v: np.array([v[0], -v[2], v[1]])
    return world(prop["position"]), world(target), prop["near"], prop["far"]


def project(points, position, target, aspect, fov_deg=75.0):
    """Normalised image coordinates in [-1, 1] and depths of points seen by a pinhole camera at
    ``position`` looking at ``target`` with world z up (three.js's lookAt), written out again."""
    forward = (target - position) / np.linalg.norm(target - position)
    right = np.cross(forward, [0, 0, 1])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rel = np.asarray(points) - position
    depth = rel @ forward
    t = np.tan(np.radians(fov_deg) / 2)
    return np.column_stack([rel @ right / (depth * t * aspect), rel @ up / (depth * t)]), depth


def corners(lo, hi):
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def test_the_constants_are_those_of_the_bundled_viewer():
    assert f"PerspectiveCamera({FOV:g},1,{NEAR:g}".replace("0.", ".") in viewer_javascript()
    assert f"PerspectiveCamera(75,1,.01,{FAR:g})" in viewer_javascript()


@pytest.mark.parametrize("size, centre", [((100.0, 60.0, 0.02), (50.0, 30.0, -0.01)), ((0.3, 0.2, 0.25), (1.0, -2.0, 0.1)),
                                          ((3.0, 12.0, 2.5), (0.0, 0.0, 1.25))])
@pytest.mark.parametrize("direction", [(0.5, -1.0, 0.9), (0.0, 0.0, 1.0), (-1.0, 0.2, 0.3), (2.0, 2.0, 0.5), (0.3, 1.0, -0.4)])
@pytest.mark.parametrize("height, width", [(420, 1000), (300, 600)])
def test_every_corner_is_in_view_and_the_box_fills_it(size, centre, direction, height, width):
    scene = Scene(height=height).add_box("thing", size, moved(*centre))
    margin = 0.1
    fit_view(scene, direction, margin=margin, width=width)
    position, target, near, far = camera_of(scene)
    lo, hi = np.array(centre) - np.array(size) / 2, np.array(centre) + np.array(size) / 2
    uv, depth = project(corners(lo, hi), position, target, width / height)
    edge = 1 / (1 + margin)
    assert np.all(np.abs(uv) <= edge + 1e-9)                              # all inside, with the margin
    binding = max(np.abs(uv[:, 0]).max(), np.abs(uv[:, 1]).max())
    guard = 0.05 * np.linalg.norm(np.array(size) / 2)                     # the camera stays out of the box
    assert depth.min() >= guard * (1 - 1e-9)
    if depth.min() > guard * (1 + 1e-6):                                  # no closer than needed, unless kept out
        assert binding == pytest.approx(edge, rel=1e-6)
    for axis in (0, 1):                                                   # the box's image is centred
        assert uv[:, axis].max() == pytest.approx(-uv[:, axis].min(), abs=1e-6)
    assert near < depth.min() and far > depth.max()                      # nothing of it clipped
    view = (position - target) / np.linalg.norm(position - target)
    if direction == (0.0, 0.0, 1.0):
        assert view[2] > 0.999999                                         # from above really looks down
    else:
        assert np.allclose(view, np.array(direction) / np.linalg.norm(direction))


def test_frame_looks_at_the_paths_or_bounds_given():
    scene = Scene().add_box("field", (100.0, 60.0, 0.02)).add_box("robot/body", (0.4, 0.3, 0.2), moved(20.0, 10.0, 0.1))
    fit_view(scene, (0, -1, 1), paths="robot")
    position, target, near, far = camera_of(scene)
    assert np.linalg.norm(target - [20.0, 10.0, 0.1]) < 0.1 and np.linalg.norm(position - target) < 2.0
    assert (near, far) == (NEAR, FAR)                                     # a small box keeps meshcat's planes
    fit_view(scene, (0, 0, 1), bounds=[[-50, -30, 0], [50, 30, 0]])
    position, target, near, far = camera_of(scene)
    assert np.allclose(target, 0, atol=0.05) and far > 4 * position[2] * 0.999


@pytest.mark.parametrize("call, match", [
    (lambda: fit_view(Scene()), "scene"),
    (lambda: fit_view(Scene().add_box("a", (1, 1, 1)), paths="b"), "scene"),
    (lambda: fit_view(Scene().add_box("a", (1, 1, 1)), (0, 0, 0)), "direction"),
    (lambda: fit_view(Scene().add_box("a", (1, 1, 1)), (1, 0)), "direction"),
    (lambda: fit_view(Scene().add_box("a", (1, 1, 1)), paths="a", bounds=[[0, 0, 0], [1, 1, 1]]), "paths, bounds"),
    (lambda: fit_view(Scene(), bounds=[[1, 0, 0], [0, 1, 1]]), "bounds"),
    (lambda: fit_view(Scene(), bounds=[[0, 0, 0], [1e300, 1e300, 1e300]]), "bounds"),
    (lambda: fit_view(Scene().add_box("a", (1, 1, 1)), margin=-0.1), "margin"),
    (lambda: fit_view(Scene().add_box("a", (1, 1, 1)), width=0), "width"),
    (lambda: fit_view("scene"), "scene"),
])
def test_frame_refuses_bad_input(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_the_notebook_frame_does_not_overflow_its_width():
    style = Scene()._repr_html_().split('style="')[1].split('"')[0]
    assert "width:100%" in style and "border:1px" in style and "box-sizing:border-box" in style
