"""LittleDog in meshcat: the robot drawn from its kinematics, posed by its joints, and a trial replayed.

The robot is a scene graph that mirrors the kinematic chain of
:mod:`robokit.legged.leg_kinematics`: the trunk's node holds ``T_world_body``; under it each leg has
three joint nodes, each placed where its joint sits in its parent's frame and turned by its joint
angle. Posing the robot therefore sets one transform per joint, and a replay animates one
quaternion per joint per frame. Paths under ``path`` (default ``"littledog"``)::

    littledog                                 the trunk's frame (T_world_body)
    littledog/trunk, littledog/markers/<k>    the trunk box and the four MoCap markers
    littledog/<leg>/hip_roll                  at the hip, turned about x by q_roll
    littledog/<leg>/hip_roll/hip_pitch        at the pitch axis (HIP_OFFSETS out), turned about y
    littledog/<leg>/hip_roll/hip_pitch/knee   at the knee (UPPER_LEG down), turned about y
    .../<joint>/link, .../knee/foot           the link that joint moves; the foot sphere

:func:`joint_path` spells them. :func:`animate_trial` adds world-frame overlays under
``<path>_overlay``: the support polygon (``support/tri<k>``, ``support/edge<k>``), the centre-of-mass
projection (``com``) and the MoCap measurements (``mocap/<k>``); the foot-force arrows hang under
each knee (``.../knee/force``).

References
----------
.. [1] R. B. McGhee and A. A. Frank, "On the stability properties of quadruped creeping gaits",
   *Mathematical Biosciences* 3, 331-351, 1968 (support polygon; centre-of-mass projection).
.. [2] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Sec. 3 (the single-axis force
   sensor in each lower leg).
.. [3] B. Siciliano and O. Khatib (eds.), *Springer Handbook of Robotics*, 2nd ed., Springer, 2016,
   Ch. 2 "Kinematics" (elementary rotations composed along a chain).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..geometry import as_se3, rot_x, rot_y, se3_from_rt
from ..legged.leg_kinematics import body_ik, leg_index
from ..legged.littledog import (FOOT_RADIUS, HIP_OFFSETS, HIP_POSITIONS, JOINTS, LEGS, LOWER_LEG, MARKERS,
                                STANCE_FEET, STANDING_HEIGHT, TRUNK_SIZE, UPPER_LEG)
from ..legged.terrain import Terrain, terrain_transform
from ..legged.trial_log import TrialLog
from ..validation import as_array, as_choice, as_int, as_positive, as_text, describe
from .animation import HIDDEN_SCALE, animate_tracks
from .legged_plots import support_outline
from .scene import Scene, as_scene
from . import framing

__all__ = ["joint_path", "add_littledog", "pose_littledog", "animate_trial", "add_terrain", "GROUND_Z"]

GROUND_Z = 0.001
"""Height (m) at which ground overlays are drawn: just above meshcat's grid, so they are not hidden."""
_COLORS = {"board": 0xB08A5A, "trunk": 0x2B2B8C, "link": 0x404048, "foot": 0x151515, "marker": 0xEEEEEE, "mocap": 0xE0309A,
           "support": 0x2E9E4F, "com": 0xF2B705, "force": 0xE8551C}
_RADII = (0.012, 0.011, 0.008)                    # hip stub, upper and lower leg, as in the MJCF
_SIDE = np.array([1.0 if leg.endswith("L") else -1.0 for leg in LEGS])
_HALF_TURN = rot_x(np.pi / 2)                     # a cylinder's y axis onto z
_VIEW = np.array([0.55, -1.0, 0.6])             # towards the camera: front right, above
_ROOM = 0.6                                      # framing margin: the legs swing out of the standing box


def joint_path(path: str, leg: Any, joint: str) -> str:
    """The scene path of one joint's node of the robot drawn at ``path``.

    Parameters
    ----------
    path : str
    leg : str or int
        ``"FL"``, ``"FR"``, ``"HL"``, ``"HR"`` or 0-3.
    joint : {"hip_roll", "hip_pitch", "knee"}

    Returns
    -------
    str

    Examples
    --------
    >>> joint_path("littledog", "HR", "knee")
    'littledog/HR/hip_roll/hip_pitch/knee'
    """
    as_text(path, "path", empty=False)
    leg = LEGS[leg_index(leg)]
    depth = JOINTS.index(as_choice(joint, "joint", JOINTS)) + 1
    return "/".join([path.strip("/"), leg, *JOINTS[:depth]])


def _joint_offsets() -> np.ndarray:
    """(4, 3, 3): where each joint sits in its parent's frame (trunk, roll, pitch)."""
    off = np.zeros((4, 3, 3))
    off[:, 0] = HIP_POSITIONS
    off[:, 1, 1] = _SIDE * HIP_OFFSETS
    off[:, 2, 2] = -UPPER_LEG
    return off


def _joint_quaternions(q: np.ndarray) -> np.ndarray:
    """(..., 4, 3, 4) quaternions [w, x, y, z] of the joint nodes: roll about x, pitch and knee about y."""
    half = q.reshape(q.shape[:-1] + (4, 3)) / 2
    out = np.zeros(half.shape + (4,))
    out[..., 0] = np.cos(half)
    out[..., 0, 1] = np.sin(half[..., 0])           # [cos, sin, 0, 0]: about x
    out[..., 1:, 2] = np.sin(half[..., 1:])         # [cos, 0, sin, 0]: about y
    return out


def _pose_args(T_world_body: Any, q: Any) -> tuple[np.ndarray, np.ndarray]:
    T = (se3_from_rt(np.eye(3), [0.0, 0.0, STANDING_HEIGHT]) if T_world_body is None
         else as_se3(T_world_body, "T_world_body"))
    q = body_ik(STANCE_FEET).q[0] if q is None else as_array(q, "q", shape=(12,))
    return T, q


def add_littledog(scene: Scene, path: str = "littledog", T_world_body: Any = None, q: Any = None) -> Scene:
    """Draw LittleDog: trunk box, each leg's hip stub, upper and lower leg, feet, MoCap markers.

    Parameters
    ----------
    scene : Scene
    path : str, default "littledog"
        Root of the robot's nodes (module docstring).
    T_world_body : array_like (4, 4), optional
        The trunk's pose; standing (trunk centre at ``STANDING_HEIGHT`` above the origin) if omitted.
    q : array_like (12,), optional
        Joint angles (rad), leg-major; the nominal stance (``body_ik(STANCE_FEET)``) if omitted.

    Returns
    -------
    Scene

    Notes
    -----
    Sizes from :mod:`robokit.legged.littledog` (the MJCF's radii for the links); the chain is the
    one of :func:`robokit.legged.leg_kinematics.leg_points`.

    Examples
    --------
    >>> from robokit.viz import Scene, fit_view
    >>> scene = add_littledog(Scene())                   # standing at the origin
    >>> fit_view(scene, direction=(0.55, -1.0, 0.6))        # seen from its front right, filling the view
    Scene(title='robokit scene', commands=59)
    """
    as_scene(scene, path)
    T, q = _pose_args(T_world_body, q)
    root = path.strip("/")
    scene.add_box(f"{root}/trunk", TRUNK_SIZE, color=_COLORS["trunk"])
    for k, m in enumerate(MARKERS):
        scene.add_sphere(f"{root}/markers/{k}", 0.006, se3_from_rt(np.eye(3), m), color=_COLORS["marker"])
    for i, leg in enumerate(LEGS):
        lengths = (HIP_OFFSETS[i], UPPER_LEG, LOWER_LEG)
        stub = se3_from_rt(np.eye(3), [0.0, _SIDE[i] * HIP_OFFSETS[i] / 2, 0.0])
        scene.add_cylinder(f"{joint_path(root, leg, 'hip_roll')}/link", lengths[0], _RADII[0], stub,
                           color=_COLORS["link"])
        for j, joint in ((1, "hip_pitch"), (2, "knee")):
            along = se3_from_rt(_HALF_TURN, [0.0, 0.0, -lengths[j] / 2])
            scene.add_cylinder(f"{joint_path(root, leg, joint)}/link", lengths[j], _RADII[j], along,
                               color=_COLORS["link"])
        scene.add_sphere(f"{joint_path(root, leg, 'knee')}/foot", FOOT_RADIUS,
                         se3_from_rt(np.eye(3), [0.0, 0.0, -LOWER_LEG]), color=_COLORS["foot"])
    return pose_littledog(scene, root, T, q)


def pose_littledog(scene: Scene, path: str, T_world_body: Any, q: Any) -> Scene:
    """Move the robot drawn by :func:`add_littledog` to a trunk pose and joint angles.

    Parameters
    ----------
    scene : Scene
    path : str
    T_world_body : array_like (4, 4)
    q : array_like (12,)
        Joint angles (rad), leg-major.

    Returns
    -------
    Scene
        With 13 transforms set: the trunk's and one per joint (``joint_path``: at the joint's place
        in its parent, turned by its angle: ``R_x(q_roll)``, ``R_y(q_pitch)``, ``R_y(q_knee)``).

    Notes
    -----
    The chain of :func:`robokit.legged.leg_kinematics.foot_position` (Siciliano & Khatib 2016,
    Eq. (2.40)), one node per elementary rotation.

    Examples
    --------
    >>> from robokit.viz import Scene
    >>> scene = add_littledog(Scene())
    >>> pose_littledog(scene, "littledog", np.eye(4), np.zeros(12)).commands[-1]["path"]
    '/meshcat/littledog/HR/hip_roll/hip_pitch/knee'
    """
    as_scene(scene, path)
    if T_world_body is None or q is None:
        raise TypeError(f"T_world_body, q: expected a 4x4 pose and 12 joint angles, got "
                        f"{describe(T_world_body)} and {describe(q)}")
    T, q = _pose_args(T_world_body, q)
    root = path.strip("/")
    scene.set_transform(root, T)
    offsets = _joint_offsets()
    for i, leg in enumerate(LEGS):
        for j, joint in enumerate(JOINTS):
            R = rot_x(q[3 * i]) if j == 0 else rot_y(q[3 * i + j])
            scene.set_transform(joint_path(root, leg, joint), se3_from_rt(R, offsets[i, j]))
    return scene


def _yaw_quaternion(angle: np.ndarray) -> np.ndarray:
    return np.stack([np.cos(angle / 2), 0 * angle, 0 * angle, np.sin(angle / 2)], axis=-1)


def _support_tracks(feet: np.ndarray, contact: np.ndarray, overlay: str) -> dict:
    """Tracks that draw each frame's support polygon: two filled triangles (a fan) and four edges.

    A triangle node maps the unit triangle (0,0), (1,0), (0,1) onto (v0, v1, v2): the affine map
    ``M = [v1 - v0, v2 - v0] = U S V^T`` (SVD) is a position, a turn (U), a scale (S) on the node and
    a second turn (V^T) on its child, all of which meshcat can animate."""
    F = len(feet)
    hidden3 = np.full(3, HIDDEN_SCALE)
    tri = [{"position": np.zeros((F, 3)), "quaternion": np.tile([1.0, 0, 0, 0], (F, 1)), "scale": np.tile(hidden3, (F, 1)),
            "child": np.tile([1.0, 0, 0, 0], (F, 1))} for _ in range(2)]
    edge = [{"position": np.zeros((F, 3)), "quaternion": np.tile([1.0, 0, 0, 0], (F, 1)),
             "scale": np.tile(hidden3, (F, 1))} for _ in range(4)]
    for f in range(F):
        v = support_outline(feet[f, contact[f], :2])
        m = len(v)
        for k in range(m - 2):                             # the fan (v0, v[k+1], v[k+2])
            M = np.column_stack([v[k + 1] - v[0], v[k + 2] - v[0]])
            U, S, Vt = np.linalg.svd(M)
            if np.linalg.det(U) < 0:                       # both turns proper: flip one singular pair
                U[:, 1], Vt[1] = -U[:, 1], -Vt[1]
            tri[k]["position"][f] = [v[0, 0], v[0, 1], GROUND_Z]
            tri[k]["quaternion"][f] = _yaw_quaternion(np.arctan2(U[1, 0], U[0, 0]))
            tri[k]["scale"][f] = [max(S[0], HIDDEN_SCALE), max(S[1], HIDDEN_SCALE), 1.0]
            tri[k]["child"][f] = _yaw_quaternion(np.arctan2(Vt[1, 0], Vt[0, 0]))
        for k in range(m if m >= 3 else m - 1):
            a, b = v[k], v[(k + 1) % m]
            edge[k]["position"][f] = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, GROUND_Z]
            edge[k]["quaternion"][f] = _yaw_quaternion(np.arctan2(b[1] - a[1], b[0] - a[0]))
            edge[k]["scale"][f] = [max(np.linalg.norm(b - a), HIDDEN_SCALE), 1.0, 1.0]
    tracks = {}
    for k, t in enumerate(tri):
        tracks[f"{overlay}/support/tri{k}"] = {p: t[p] for p in ("position", "quaternion", "scale")}
        tracks[f"{overlay}/support/tri{k}/shape"] = {"quaternion": t["child"]}
    for k, e in enumerate(edge):
        tracks[f"{overlay}/support/edge{k}"] = e
    return tracks


def _add_overlays(scene: Scene, root: str, overlay: str, support: bool, com: bool, forces: bool, mocap: bool) -> None:
    if support:
        for k in range(2):
            scene.add_mesh(f"{overlay}/support/tri{k}/shape", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]],
                           color=_COLORS["support"], opacity=0.45)
        for k in range(4):
            scene.add_box(f"{overlay}/support/edge{k}", (1.0, 0.004, 0.002), color=_COLORS["support"])
    if com:
        scene.add_cylinder(f"{overlay}/com", 0.002, 0.012, se3_from_rt(_HALF_TURN, np.zeros(3)), color=_COLORS["com"])
    if mocap:
        for k in range(len(MARKERS)):
            scene.add_sphere(f"{overlay}/mocap/{k}", 0.007, color=_COLORS["mocap"])
    if forces:
        head = 0.25                 # of the unit arrow; the arrow's node is scaled along its axis
        for leg in LEGS:
            arrow = f"{joint_path(root, leg, 'knee')}/force"
            scene.set_transform(arrow, se3_from_rt(rot_x(-np.pi / 2), [0.0, 0.0, -LOWER_LEG - FOOT_RADIUS]))
            # a cone, its tip (radius_top 0, at +y) turned over onto y = 0: the foot
            scene.add_cylinder(f"{arrow}/head", head, 0.014, se3_from_rt(rot_x(np.pi), [0.0, head / 2, 0.0]),
                               color=_COLORS["force"], radius_top=0.0)
            scene.add_cylinder(f"{arrow}/shaft", 1.0 - head, 0.006,
                               se3_from_rt(np.eye(3), [0.0, head + (1.0 - head) / 2, 0.0]), color=_COLORS["force"])


def animate_trial(scene: Scene, log: TrialLog, path: str = "littledog", every: int = 2, fps: float | None = None,
                  support: bool = True, com: bool = True, forces: bool = True, *, mocap: bool = False,
                  force_scale: float = 0.004, frame: bool = True) -> Scene:
    """Replay a trial log in meshcat: the robot walking, with what keeps it up drawn on the ground.

    Parameters
    ----------
    scene : Scene
    log : TrialLog
    path : str, default "littledog"
        Where the robot is drawn (:func:`add_littledog` is called; overlays go under
        ``<path>_overlay``).
    every : int, default 2
        Use every ``every``-th row (one animation frame each): a 10 s trial at 100 Hz with
        ``every=2`` is 500 frames, about 1.3 MB of keyframes (plus meshcat's 0.85 MB viewer).
    fps : float, optional
        Playback rate; real time (``host_rate / every``) if omitted.
    support : bool, default True
        The support polygon of the feet in (true) contact, filled on the ground; a segment when two
        feet stand, nothing when one does.
    com : bool, default True
        The centre of mass projected on the ground (a yellow disc).
    forces : bool, default True
        Foot forces as arrows: ``foot_force`` (N, compression) times ``force_scale`` (m/N) long,
        along each lower leg and ending at the foot - the single-axis sensor measures the push along
        the shank, so the arrow shows that, not a vertical ground reaction. Tension draws nothing.
    mocap : bool, default False
        The MoCap measurements (magenta spheres; hidden when a marker was not seen).
    force_scale : float, default 0.004
        m of arrow per N (7.4 N, a quarter of the weight, is 3 cm).
    frame : bool, default True
        Look at the robot from its front right, close enough for it to fill most of the view
        (:func:`robokit.viz.fit_view` on the robot as it starts), and follow it as it walks
        (:meth:`Scene.set_camera_follow`, offline pages).

    Returns
    -------
    Scene
        With one animation clip (:func:`robokit.viz.animate_tracks`): one keyframe per sampled row in
        every track.

    Raises
    ------
    ValueError, TypeError
        For a log that is not a TrialLog, fewer than two sampled rows, or bad options.

    Notes
    -----
    The support polygon is the convex hull of the stance feet and the centre of mass's vertical
    projection must lie in it for static stability (McGhee & Frank 1968, unnumbered); here both come
    from the simulator's truth (``feet``, ``contact``, ``com``), not from estimates.

    Examples
    --------
    >>> from robokit.legged import TrialLog
    >>> from robokit.legged.trial_log import empty_streams, trial_meta
    >>> from robokit.viz import Scene
    >>> streams = empty_streams(6)
    >>> streams["body_pos"][:, 2] = 0.13
    >>> streams["contact"][:] = True
    >>> scene = animate_trial(Scene(), TrialLog(streams, trial_meta()), every=2)
    >>> clip = scene.commands[-1]["animations"][0]["clip"]
    >>> clip["fps"], len(clip["tracks"][0]["keys"])           # 3 frames of rows 0, 2, 4
    (50.0, 3)
    """
    as_scene(scene, path)
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a robokit.legged.TrialLog, got {describe(log)}")
    every = as_int(every, "every", minimum=1)
    rows = np.arange(0, len(log), every)
    if len(rows) < 2:
        raise ValueError(f"log: expected at least 2 rows after taking every {every}th (an animation needs two frames), "
                         f"got {len(log)} row(s)")
    fps = float(log.meta["host_rate"]) / every if fps is None else as_positive(fps, "fps")
    force_scale = as_positive(force_scale, "force_scale")
    root, overlay = path.strip("/"), path.strip("/") + "_overlay"
    add_littledog(scene, root, log.T_world_body()[0], log.q[0])
    if frame:                     # on the robot alone: its unit force arrows are scaled by the animation
        framing.fit_view(scene, _VIEW, paths=root, margin=_ROOM)
        scene.set_camera_follow(root)
    _add_overlays(scene, root, overlay, bool(support), bool(com), bool(forces), bool(mocap))

    tracks: dict = {root: {"position": log.body_pos[rows], "quaternion": log.body_quat[rows]}}
    quats = _joint_quaternions(log.q[rows])
    for i, leg in enumerate(LEGS):
        for j, joint in enumerate(JOINTS):
            tracks[joint_path(root, leg, joint)] = {"quaternion": quats[:, i, j]}
    if forces:
        length = np.clip(log.foot_force[rows], 0.0, None) * force_scale
        for i, leg in enumerate(LEGS):
            on = length[:, i] > 1e-4
            scale = np.where(on[:, None], np.column_stack([np.ones_like(length[:, i]), length[:, i], np.ones_like(length[:, i])]),
                             HIDDEN_SCALE)
            tracks[f"{joint_path(root, leg, 'knee')}/force"] = {"scale": scale}
    if support:
        tracks.update(_support_tracks(log.feet[rows], log.contact[rows], overlay))
    if com:
        tracks[f"{overlay}/com"] = {"position": np.column_stack([log.com[rows, :2], np.full(len(rows), GROUND_Z)])}
    if mocap:
        for k in range(len(MARKERS)):
            seen = log.mocap_visible[rows, k]
            tracks[f"{overlay}/mocap/{k}"] = {"position": log.mocap[rows, k],
                                              "scale": np.where(seen[:, None], 1.0, HIDDEN_SCALE) * np.ones(3)}
    return animate_tracks(scene, tracks, fps, validate=False)


def add_terrain(scene: Scene, terrain: Terrain, path: str = "terrain") -> Scene:
    """Draw a terrain's boards and their MoCap markers where the terrain lies.

    Parameters
    ----------
    scene : Scene
    terrain : Terrain
        Boards and markers in the terrain's frame, placed by its ``pose``
        (:mod:`robokit.legged.terrain`; LittleDog User Guide, Sec. 1: the MoCap tracks markers on the
        terrain as on the robot).
    path : str, default "terrain"
        Scene path: boards at ``<path>/board<k>``, markers at ``<path>/marker<k>``.

    Returns
    -------
    Scene

    Raises
    ------
    TypeError
        For a ``scene`` that is not a Scene or a ``terrain`` that is not a Terrain.

    Examples
    --------
    >>> from robokit.legged import Terrain
    >>> board = Terrain([[0.3, 0.5, -0.3, 0.3, 0.02]], markers=[[0.3, 0.3, 0.02]], pose=(1.0, 0.0, 0.0))
    >>> lo, hi = add_terrain(Scene(), board).bounding_box("terrain")     # the board 1 m further on
    >>> np.round(lo, 3).tolist(), np.round(hi, 3).tolist()
    ([1.294, -0.3, 0.0], [1.5, 0.306, 0.026])
    """
    scene = as_scene(scene, path)
    if not isinstance(terrain, Terrain):
        raise TypeError(f"terrain: expected a Terrain (robokit.legged.terrain), got {type(terrain).__name__}")
    T = terrain_transform(terrain)
    for k, (x0, x1, y0, y1, h) in enumerate(terrain.blocks):
        centre = se3_from_rt(np.eye(3), [(x0 + x1) / 2, (y0 + y1) / 2, h / 2])
        scene.add_box(f"{path}/board{k}", [x1 - x0, y1 - y0, h], T @ centre, color=_COLORS["board"])
    for k, m in enumerate(terrain.markers):
        scene.add_sphere(f"{path}/marker{k}", 0.006, T @ se3_from_rt(np.eye(3), m), color=_COLORS["marker"])
    return scene
