"""meshcat animations: objects moving, scaling or shown in turn, all in one clip.

A meshcat scene plays one animation clip (a new ``set_animation`` replaces the last), so every moving
part of a scene goes into one clip. :func:`animate_tracks` is the player: per scene path, per frame,
a position, an orientation and a scale. :func:`animate_poses` moves one object with it,
:func:`animate_snapshots` shows objects one after another (a particle cloud after each filter
update) and can move one object (the robot) in step with them; :func:`robokit.viz.legged.animate_trial`
replays a whole LittleDog trial.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from ..geometry.planar import as_planar
from ..geometry import se2_to_se3
from ..validation import as_array, as_int, as_positive, describe
from .scene import Scene, as_scene

__all__ = ["animate_tracks", "animate_poses", "animate_snapshots", "HIDDEN_SCALE"]

HIDDEN_SCALE = 1e-6
"""Scale of an object out of its turn (meshcat animates scale, not visibility)."""
_PROPERTIES = {"position": ("vector3", 3), "quaternion": ("quaternion", 4), "scale": ("vector3", 3)}


def _transforms(value: Any, name: str) -> np.ndarray:
    T = as_array(value, name)
    if T.ndim == 2 and T.shape[1] == 3:
        T = np.stack([se2_to_se3(p) for p in as_planar(T, name)])
    T = as_array(T, name, shape=(None, 4, 4))
    if len(T) < 2:
        raise ValueError(f"{name}: expected at least 2 poses, got {len(T)}")
    return T


def _checked_tracks(tracks: Any, scene: Scene) -> dict:
    if not isinstance(tracks, Mapping) or not tracks:
        raise TypeError(f"tracks: expected a non-empty dict of scene path -> {{property: array}}, got {describe(tracks)}")
    out, frames = {}, None
    for path, props in tracks.items():
        as_scene(scene, path)
        if not isinstance(props, Mapping) or not props:
            raise TypeError(f"tracks[{path!r}]: expected a non-empty dict of property -> array, got {describe(props)}")
        out[path] = {}
        for prop, values in props.items():
            if prop not in _PROPERTIES:
                raise ValueError(f"tracks[{path!r}]: expected properties among {list(_PROPERTIES)}, got {prop!r}")
            width = _PROPERTIES[prop][1]
            v = as_array(values, f"tracks[{path!r}][{prop!r}]", shape=(None, width))
            frames = len(v) if frames is None else frames
            if len(v) != frames or frames < 2:
                raise ValueError(f"tracks[{path!r}][{prop!r}]: expected {max(frames, 2)} or more frames, the same "
                                 f"in every track, got {len(v)}")
            if prop == "quaternion" and np.any(np.linalg.norm(v, axis=1) < 1e-12):
                raise ValueError(f"tracks[{path!r}]['quaternion']: expected non-zero quaternions [w, x, y, z]")
            out[path][prop] = v
    return out


def animate_tracks(scene: Scene, tracks: Any, fps: float = 10.0, repetitions: int = 1, *,
                   validate: bool = True) -> Scene:
    """Play one clip in which objects move, turn and scale, frame by frame (meshcat animation).

    Parameters
    ----------
    scene : Scene
    tracks : dict of str to dict of str to array_like
        Per scene path (an object or group already in the scene), per property, one row per frame:
        ``"position"`` (F, 3) metres and ``"quaternion"`` (F, 4) ``[w, x, y, z]``, both relative to
        the parent path, and ``"scale"`` (F, 3). Every array has the same number of frames F >= 2.
    fps : float, default 10
        Frames per second of playback.
    repetitions : int, default 1
    validate : bool, default True
        Validate the tracks; ``False`` is the fast path for helpers that built them.

    Returns
    -------
    Scene

    Raises
    ------
    ValueError, TypeError
        For an unknown property, a wrong shape, non-finite values or frame counts that differ.

    Notes
    -----
    meshcat's ``set_animation`` command: three.js keyframe tracks (``VectorKeyframeTrack`` for
    position and scale, ``QuaternionKeyframeTrack``, whose order is ``[x, y, z, w]``) with key ``k``
    at frame ``k``; one clip per path, all played together.

    Examples
    --------
    >>> from robokit.viz import Scene
    >>> scene = Scene().add_box("robot", size=(0.5, 0.25, 0.15))
    >>> animate_tracks(scene, {"robot": {"position": [[0, 0, 0], [1, 0, 0]], "scale": [[1, 1, 1], [2, 2, 2]]}})
    Scene(title='robokit scene', commands=3)
    >>> scene.commands[-1]["animations"][0]["clip"]["tracks"][1]["keys"][1]
    {'time': 1, 'value': [2.0, 2.0, 2.0]}
    """
    from meshcat.commands import SetAnimation

    if validate:
        as_scene(scene)
        tracks = _checked_tracks(tracks, scene)
        fps = as_positive(fps, "fps")
        repetitions = as_int(repetitions, "repetitions", minimum=1)
    clips = []
    for path, props in tracks.items():
        lowered = []
        for prop, values in props.items():
            v = np.asarray(values, float)
            if prop == "quaternion":
                v = v[:, [1, 2, 3, 0]]                       # three.js order
            lowered.append({"name": "." + prop, "type": _PROPERTIES[prop][0],
                            "keys": [{"time": k, "value": row} for k, row in enumerate(v.tolist())]})
        clips.append({"path": Scene.meshcat_path(path).lower(),
                      "clip": {"fps": fps, "name": "default", "tracks": lowered}})

    class _Animation:  # meshcat's Animation, keyed by our own paths
        def lower(self):
            return clips

    return scene.send(SetAnimation(_Animation(), play=True, repetitions=repetitions))


def _pose_tracks(T: np.ndarray) -> dict:
    return {"position": T[:, :3, 3], "quaternion": Rotation.from_matrix(T[:, :3, :3]).as_quat(scalar_first=True)}


def animate_poses(scene: Scene, path: str, transforms: Any, fps: float = 10.0, repetitions: int = 1) -> Scene:
    """Animate the object at ``path`` through a sequence of 4x4 poses (meshcat animation).

    Parameters
    ----------
    transforms : array_like (N, 4, 4) or (N, 3)
        Poses per frame; planar ``[x, y, theta]`` rows are lifted with :func:`robokit.geometry.se2_to_se3`.
    fps : float, default 10
        Frames per second of playback.
    repetitions : int, default 1

    Notes
    -----
    meshcat's ``set_animation`` command (three.js AnimationClip keyframe tracks).

    Examples
    --------
    >>> from robokit.viz import Scene, animate_poses
    >>> scene = Scene().add_box("robot", size=(0.5, 0.25, 0.15))
    >>> animate_poses(scene, "robot", [[0.0, 0.0, 0.0], [1.0, 0.0, 0.5], [2.0, 1.0, 1.0]], fps=2)
    Scene(title='robokit scene', commands=3)
    """
    as_scene(scene, path)
    T = _transforms(transforms, "transforms")
    return animate_tracks(scene, {path: _pose_tracks(T)}, as_positive(fps, "fps"),
                          as_int(repetitions, "repetitions", minimum=1), validate=False)


def animate_snapshots(scene: Scene, paths: Sequence[str], fps: float = 4.0, repetitions: int = 1, *,
                      moving: str | None = None, transforms: Any = None) -> Scene:
    """Show the objects at ``paths`` one per frame, in order (each hidden outside its frame).

    Parameters
    ----------
    scene : Scene
    paths : sequence of str
        Objects already in the scene, one per frame (at least two), e.g. a particle cloud after each
        filter update.
    fps : float, default 4
    repetitions : int, default 1
    moving : str, optional
        An object to move in step (e.g. the robot), through ``transforms``.
    transforms : array_like (len(paths), 4, 4) or (len(paths), 3), optional
        Its pose in each frame.

    Returns
    -------
    Scene

    Raises
    ------
    ValueError, TypeError
        For fewer than two paths, a bad path or a pose count that differs from the path count.

    Notes
    -----
    One meshcat clip (three.js keyframe tracks on each object's ``scale``): a snapshot is scaled to
    nothing outside its frame.

    Examples
    --------
    >>> from robokit.viz import Scene
    >>> scene = Scene().add_box("a", size=(1, 1, 1)).add_box("b", size=(1, 1, 1)).add_box("robot", size=(1, 1, 1))
    >>> animate_snapshots(scene, ["a", "b"], moving="robot", transforms=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    Scene(title='robokit scene', commands=7)
    """
    if isinstance(paths, str) or len(paths) < 2:
        raise ValueError(f"paths: expected a sequence of at least two scene paths, got {paths!r}")
    as_scene(scene, *paths)
    n = len(paths)
    tracks = {}
    for k, path in enumerate(paths):
        tracks[path] = {"scale": np.where(np.arange(n)[:, None] == k, 1.0, HIDDEN_SCALE) * np.ones(3)}
    if moving is not None:
        if not isinstance(moving, str):
            raise TypeError(f"moving: expected a scene path (str), got {type(moving).__name__}")
        as_scene(scene, moving)
        T = _transforms(transforms, "transforms")
        if len(T) != n:
            raise ValueError(f"transforms: expected one pose per path ({n}), got {len(T)}")
        tracks[moving] = _pose_tracks(T)
    elif transforms is not None:
        raise ValueError("transforms: given without the object to move (moving=None)")
    return animate_tracks(scene, tracks, as_positive(fps, "fps"), as_int(repetitions, "repetitions", minimum=1),
                          validate=False)
