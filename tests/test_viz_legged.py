"""LittleDog in meshcat and the trial figures: the drawn robot is the kinematics' robot, the replay has
one keyframe per sampled row and shows what the log says, the camera looks at the robot, every figure
has labelled axes with units."""
from __future__ import annotations

import re

import matplotlib
import numpy as np
import pytest
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from robokit.geometry import se3_from_rt, so3_exp, transform_points
from robokit.legged.leg_kinematics import leg_points
from robokit.legged.littledog import JOINTS, LEGS, LOWER_LEG, MARKERS
from robokit.viz import (Scene, add_littledog, animate_tracks, animate_trial, look_from, plot_foot_forces, plot_gait_diagram, plot_joint_tracking, plot_support)
from robokit.viz.legged import joint_path, pose_littledog
from robokit.viz.legged_plots import support_outline
from tests.legged_logs import synthetic_log

matplotlib.use("Agg")
PREFIX = "/meshcat/"


def _transforms(scene):
    """The last 4x4 set at each path (meshcat sends them column-major)."""
    out = {}
    for c in scene.commands:
        if c["type"] == "set_transform":
            out[c["path"][len(PREFIX):]] = np.array(c["matrix"]).reshape(4, 4).T
    return out


def _world(transforms, path):
    """Compose the transforms of every ancestor of ``path`` (a node with none set is the identity)."""
    T = np.eye(4)
    parts = path.split("/")
    for k in range(1, len(parts) + 1):
        T = T @ transforms.get("/".join(parts[:k]), np.eye(4))
    return T


def _objects(scene):
    return {c["path"][len(PREFIX):] for c in scene.commands if c["type"] == "set_object"}


def _random_pose(rng):
    return se3_from_rt(so3_exp(rng.normal(0, 0.3, 3)), rng.normal(0, 0.5, 3))


def _check_robot(scene, path, T, q):
    tf = _transforms(scene)
    for i, leg in enumerate(LEGS):
        expected = transform_points(T, leg_points(q[3 * i:3 * i + 3], leg))          # hip, pitch, knee, foot
        nodes = [joint_path(path, leg, j) for j in JOINTS] + [joint_path(path, leg, "knee") + "/foot"]
        drawn = np.array([_world(tf, n)[:3, 3] for n in nodes])
        np.testing.assert_allclose(drawn, expected, atol=1e-12)
        # the lower leg's cylinder runs along its y axis from the knee to the foot
        link = _world(tf, joint_path(path, leg, "knee") + "/link")
        np.testing.assert_allclose(link[:3, 3], expected[2:].mean(axis=0), atol=1e-12)
        assert abs(link[:3, 1] @ (expected[3] - expected[2])) == pytest.approx(LOWER_LEG, abs=1e-12)
    markers = np.array([_world(tf, f"{path}/markers/{k}")[:3, 3] for k in range(4)])
    np.testing.assert_allclose(markers, transform_points(T, MARKERS), atol=1e-12)


def test_the_drawn_robot_is_the_kinematics_robot():
    rng = np.random.default_rng(4)
    T, q = _random_pose(rng), rng.uniform(-1.0, 1.0, 12)
    scene = add_littledog(Scene(), "dog", T, q)
    expected = {"dog/trunk", *(f"dog/markers/{k}" for k in range(4))}
    for leg in LEGS:
        expected |= {joint_path("dog", leg, j) + "/link" for j in JOINTS} | {joint_path("dog", leg, "knee") + "/foot"}
    assert _objects(scene) == expected
    _check_robot(scene, "dog", T, q)
    # posed again: only transforms are sent, and they follow the new angles
    n = len(scene.commands)
    T2, q2 = _random_pose(rng), rng.uniform(-1.0, 1.0, 12)
    pose_littledog(scene, "dog", T2, q2)
    assert len(scene.commands) == n + 13 and _objects(scene) == expected
    _check_robot(scene, "dog", T2, q2)


def test_default_pose_stands_on_the_ground():
    scene = add_littledog(Scene())
    tf = _transforms(scene)
    feet = np.array([_world(tf, joint_path("littledog", leg, "knee") + "/foot")[:3, 3] for leg in LEGS])
    np.testing.assert_allclose(feet[:, 2], 0.01, atol=1e-12)                       # foot radius above z = 0


def _keys(scene):
    """path -> property -> (F, k) values of the last animation (quaternions back to [w, x, y, z])."""
    anim = [c for c in scene.commands if c["type"] == "set_animation"][-1]
    out = {}
    for a in anim["animations"]:
        props = {}
        for track in a["clip"]["tracks"]:
            v = np.array([k["value"] for k in track["keys"]])
            assert [k["time"] for k in track["keys"]] == list(range(len(v)))
            props[track["name"][1:]] = v[:, [3, 0, 1, 2]] if track["name"] == ".quaternion" else v
        out[a["path"][len(PREFIX):]] = props
    return anim, out


def _matrix(props, k, static=None):
    """The node's transform at frame ``k``: its static one with the animated properties replaced."""
    T = np.eye(4) if static is None else static.copy()
    if "quaternion" in props:
        T[:3, :3] = Rotation.from_quat(props["quaternion"][k], scalar_first=True).as_matrix()
    if "position" in props:
        T[:3, 3] = props["position"][k]
    if "scale" in props:
        T[:3, :3] = T[:3, :3] * props["scale"][k]
    return T


def test_replay_has_one_keyframe_per_sampled_row_and_shows_the_log():
    log = synthetic_log(40, seed=2)
    scene = animate_trial(Scene(), log, every=3, mocap=True)
    rows = np.arange(0, 40, 3)
    anim, keys = _keys(scene)
    assert anim["animations"][0]["clip"]["fps"] == pytest.approx(100 / 3)
    assert all(len(v) == len(rows) for props in keys.values() for v in props.values())
    np.testing.assert_array_equal(keys["littledog"]["position"], log.body_pos[rows])
    # the animated joints put the feet where the log's (kinematic) feet are, frame by frame
    static = _transforms(scene)
    for f, r in enumerate(rows):
        frame = {**static, **{path: _matrix(props, f, static.get(path)) for path, props in keys.items()}}
        for i, leg in enumerate(LEGS):
            foot = _world(frame, joint_path("littledog", leg, "knee") + "/foot")
            np.testing.assert_allclose(foot[:3, 3], log.feet[r, i], atol=1e-12)
        np.testing.assert_allclose(keys["littledog_overlay/com"]["position"][f], [*log.com[r, :2], 0.001])
        visible = keys["littledog_overlay/mocap/1"]["scale"][f, 0] == 1.0
        assert visible == log.mocap_visible[r, 1]
    # force arrows: as long as force x scale, hidden without compression
    arrow = keys[joint_path("littledog", "HL", "knee") + "/force"]["scale"]
    force = np.clip(log.foot_force[rows, 2], 0, None)
    np.testing.assert_allclose(np.where(force * 0.004 > 1e-4, arrow[:, 1], 0), np.where(force * 0.004 > 1e-4, force * 0.004, 0))


def test_support_polygon_triangles_cover_the_stance_feet():
    log = synthetic_log(40, seed=3)
    scene = animate_trial(Scene(), log, every=1)
    _, keys = _keys(scene)
    unit = np.array([[0, 0, 0, 1.0], [1, 0, 0, 1], [0, 1, 0, 1]]).T
    n_checked = 0
    for r in range(40):
        stance = log.feet[r, log.contact[r], :2]
        drawn = []
        for k in range(2):
            parent = _matrix(keys[f"littledog_overlay/support/tri{k}"], r)
            child = _matrix(keys[f"littledog_overlay/support/tri{k}/shape"], r)
            if parent[0, 0] ** 2 + parent[1, 0] ** 2 > 1e-9:                  # shown
                drawn.append((parent @ child @ unit)[:2].T)
        hull = stance[ConvexHull(stance).vertices]
        assert len(drawn) == len(hull) - 2                                 # a fan of m - 2 triangles
        vertices = np.unique(np.round(np.vstack(drawn), 9), axis=0)
        np.testing.assert_allclose(vertices, np.unique(np.round(hull, 9), axis=0), atol=1e-9)
        area = sum(0.5 * abs(np.linalg.det(np.column_stack([t[1] - t[0], t[2] - t[0]]))) for t in drawn)
        assert area == pytest.approx(ConvexHull(stance).volume, rel=1e-9)      # no overlap, no gap
        n_checked += 1
    assert n_checked == 40


def test_the_camera_looks_at_the_robot_and_follows_it():
    log = synthetic_log(40)
    scene = animate_trial(Scene(), log)
    target = [c for c in scene.commands if c["type"] == "set_target"][-1]["value"]
    target = np.array([target[0], -target[2], target[1]])                                 # y-up back to z-up
    lo, hi = add_littledog(Scene(), "littledog", log.T_world_body()[0], log.q[0]).bounding_box()  # the robot as it starts
    assert np.all(target > lo - 0.03) and np.all(target < hi + 0.03)                     # looked at: at its box
    position = np.array([c for c in scene.commands if c.get("property") == "position"][-1]["value"])
    assert 0.2 < np.linalg.norm(position[[0, 2, 1]] * [1, -1, 1] - (lo + hi) / 2) < 1.0    # close to a 0.3 m robot
    assert [c["path"] for c in scene.commands if c["type"] == "robokit_follow"] == ["/meshcat/littledog"]
    page = scene.html()
    assert re.search(r"viewer\.controls\.target\.set\([-\d.e]+, [-\d.e]+, [-\d.e]+\); viewer\.controls\.update\(\)", page)
    assert 'viewer.scene_tree.find(["meshcat", "littledog"])' in page
    still = animate_trial(Scene(), log, frame=False)
    assert not [c for c in still.commands if c["type"] in ("set_target", "robokit_follow")]


def test_look_from_keeps_its_old_callers():
    scene = look_from(Scene(), [5.0, -5.0, 8.0])
    assert [c["type"] for c in scene.commands] == ["set_property"] and "controls.target" not in scene.html()
    with pytest.raises(ValueError, match="position: expected a point away from the target"):
        look_from(Scene(), [1.0, 2.0, 3.0], target=[1.0, 2.0, 3.0])


def test_bad_replays_are_refused():
    log = synthetic_log(3)
    with pytest.raises(ValueError, match="log: expected at least 2 rows after taking every 3th"):
        animate_trial(Scene(), log, every=3)
    with pytest.raises(TypeError, match="log: expected a robokit.legged.TrialLog"):
        animate_trial(Scene(), {"q": np.zeros((3, 12))})
    with pytest.raises(ValueError, match=r"tracks\['a'\]\['scale'\]: expected 3 or more frames"):
        animate_tracks(Scene(), {"a": {"position": np.zeros((3, 3)), "scale": np.ones((2, 3))}})
    with pytest.raises(ValueError, match=r"tracks\['a'\]: expected properties among"):
        animate_tracks(Scene(), {"a": {"colour": np.zeros((3, 3))}})


def test_support_outline_is_the_convex_hull():
    rng = np.random.default_rng(9)
    for _ in range(50):
        pts = rng.normal(size=(rng.integers(3, 7), 2))
        v = support_outline(pts)
        hull = ConvexHull(pts)
        assert len(v) == len(hull.vertices)
        edges = np.roll(v, -1, axis=0) - v
        rel = pts[:, None, :] - v[None]
        cross = edges[None, :, 0] * rel[..., 1] - edges[None, :, 1] * rel[..., 0]
        assert np.all(cross >= -1e-12)                                  # counter-clockwise, every point inside
    np.testing.assert_array_equal(support_outline([[0, 0], [1, 1], [2, 2]]), [[0, 0], [2, 2]])   # collinear: a segment


def _has_units(label):
    return bool(re.search(r"\[[^\]]+\]", label))


def test_figures_have_labelled_axes_with_units():
    log = synthetic_log(40)
    ax = plot_gait_diagram(log.t, log.contact)
    assert _has_units(ax.get_xlabel()) and ax.get_ylabel() == "leg"
    # FL (top row) is dark exactly while it stands: the bars' total length is its stance time
    bars = ax.collections[1].get_paths()
    widths = sum(np.ptp(p.vertices[:, 0]) for p in bars)
    assert widths == pytest.approx(log.contact[:, 0].sum() * 0.01)
    ax = plot_joint_tracking(log, ["HL_knee", 0])
    assert _has_units(ax.get_xlabel()) and _has_units(ax.get_ylabel()) and len(ax.lines) == 6
    np.testing.assert_array_equal(ax.lines[2].get_ydata(), log.q[:, 8])
    axes = plot_foot_forces(log, detected=log.foot_force > 3.0)
    assert len(axes) == 4 and all(_has_units(a.get_ylabel()) for a in axes) and _has_units(axes[-1].get_xlabel())
    ax = plot_support(log.feet[0], log.contact[0], log.com[0])
    assert _has_units(ax.get_xlabel()) and _has_units(ax.get_ylabel())
    import matplotlib.pyplot as plt
    plt.close("all")


def test_support_margin_is_the_distance_to_the_nearest_edge():
    square = np.array([[0.1, 0.1], [-0.1, 0.1], [-0.1, -0.1], [0.1, -0.1]])
    ax = plot_support(square, [True] * 4, [0.03, 0.02])                # 0.07 m to the edge x = 0.1
    assert ax.get_title() == "support: stability margin 70 mm"
    ax = plot_support(square, [True, False, True, True], [-0.05, 0.05])  # outside the triangle y < x: negative
    assert ax.get_title() == f"support: stability margin {-1000 * 0.05 * np.sqrt(2):.0f} mm"
    ax = plot_support(square, [True, False, True, False], [0.0, 0.0])
    assert ax.get_title().startswith("support: no polygon")
    import matplotlib.pyplot as plt
    plt.close("all")


def test_two_feet_support_is_a_segment_and_the_arrow_ends_at_the_foot():
    from robokit.legged import TrialLog
    log = synthetic_log(6)
    streams = {k: np.array(v) for k, v in log.streams.items()}
    streams["contact"][:] = [True, False, False, True]                     # a trot's diagonal FL-HR
    log = TrialLog(streams, dict(log.meta))
    scene = animate_trial(Scene(), log, every=1)
    _, keys = _keys(scene)
    edge = keys["littledog_overlay/support/edge0"]
    np.testing.assert_allclose(edge["scale"][:, 0], np.linalg.norm(log.feet[:, 0, :2] - log.feet[:, 3, :2], axis=1))
    np.testing.assert_allclose(edge["position"][:, :2], (log.feet[:, 0, :2] + log.feet[:, 3, :2]) / 2)
    for name in ("tri0", "tri1", "edge1", "edge2", "edge3"):
        assert np.all(keys[f"littledog_overlay/support/{name}"]["scale"][:, 0] < 1e-5)   # hidden
    # each arrow's tip (its node's origin) touches the foot sphere, on the shank's line below the foot
    static = _transforms(scene)
    frame = {**static, **{path: _matrix(props, 0, static.get(path)) for path, props in keys.items()}}
    for i, leg in enumerate(LEGS):
        knee = _world(frame, joint_path("littledog", leg, "knee"))[:3, 3]
        foot = _world(frame, joint_path("littledog", leg, "knee") + "/foot")[:3, 3]
        arrow = _world(frame, joint_path("littledog", leg, "knee") + "/force")
        np.testing.assert_allclose(arrow[:3, 3], foot + 0.01 * (foot - knee) / LOWER_LEG, atol=1e-12)
        direction = arrow[:3, 1] / np.linalg.norm(arrow[:3, 1])        # the arrow runs away from the knee
        np.testing.assert_allclose(direction, (foot - knee) / LOWER_LEG, atol=1e-12)
