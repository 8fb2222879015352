import base64
import re

import numpy as np
import pytest
import umsgpack

from robokit.viz import Scene


def _decoded(page):
    blobs = re.search(r"robokitCommands = \[(.*?)\];", page, re.S).group(1)
    return [umsgpack.unpackb(base64.b64decode(b.strip().strip('"'))) for b in blobs.split(",") if b.strip()]


def test_static_html_carries_the_scene():
    scene = Scene(title="demo")
    scene.add_box("robot/body", (0.5, 0.25, 0.15), color=0x3366CC)
    scene.add_triad("world")
    scene.add_points("cloud", np.random.default_rng(0).random((20, 3)))
    page = scene.html()
    assert "MeshCat.Viewer" in page and "<title>demo</title>" in page
    cmds = _decoded(page)
    assert [c["type"] for c in cmds] == ["set_object", "set_transform", "set_object", "set_transform",
                                         "set_object"]
    assert cmds[0]["path"] == "/meshcat/robot/body"
    assert cmds[0]["object"]["geometries"][0]["type"] == "BoxGeometry"
    assert cmds[0]["object"]["materials"][0]["color"] == 0x3366CC
    assert cmds[2]["object"]["object"]["type"] == "LineSegments"


def test_notebook_repr_is_an_offline_iframe(tmp_path):
    scene = Scene().add_sphere("s", 0.2)
    assert scene._repr_html_().startswith("<iframe srcdoc=")
    assert "http://" not in scene.html().split("<script>")[0]
    path = scene.save_html(tmp_path / "s.html")
    assert path.read_text() == scene.html()


@pytest.mark.parametrize("call, match", [
    (lambda s: s.add_box("b", (1, -1, 1)), "size"),
    (lambda s: s.add_box("", (1, 1, 1)), "path"),
    (lambda s: s.add_sphere("s", 0), "radius"),
    (lambda s: s.set_transform("s", np.eye(3)), "transform"),
    (lambda s: s.add_points("p", np.zeros((3, 2))), "points"),
    (lambda s: s.add_box("b", (1, 1, 1), color=(2, 0, 0)), "color"),
    (lambda s: s.add_line("l", [[0, 0, 0]]), "points"),
    (lambda s: s.add_cylinder("c", -1.0, 0.1), "length"),
    (lambda s: s.add_cylinder("c", 1.0, 0.1, radius_top=-0.1), "radius_top"),
    (lambda s: s.add_mesh("m", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]]), "faces"),
    (lambda s: s.add_mesh("m", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0.0, 1.5, 2.0]]), "faces"),
    (lambda s: s.set_camera_target([1.0, np.nan, 0.0]), "target"),
    (lambda s: s.set_camera_follow(""), "path"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call(Scene())


def test_cylinder_mesh_and_camera_commands():
    scene = Scene().add_cylinder("c", 0.2, 0.01, radius_top=0.0).add_mesh("m", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    cyl = scene.commands[0]["object"]["geometries"][0]
    assert (cyl["type"], cyl["height"], cyl["radiusTop"], cyl["radiusBottom"]) == ("CylinderGeometry", 0.2, 0.0, 0.01)
    scene.set_camera_target([1.0, 2.0, 3.0])
    assert scene.commands[-1] == {"type": "set_target", "path": "", "value": [1.0, 3.0, -2.0]}   # three.js y-up
    assert "viewer.controls.target.set(1.0, 3.0, -2.0)" in scene.html()
