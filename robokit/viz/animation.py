"""meshcat animations: one object moving through poses, or a sequence of snapshots shown in turn.

A meshcat scene plays one animation clip (a new ``set_animation`` replaces the last), so every moving
part of a scene goes into one clip: :func:`animate_poses` moves one object, :func:`animate_snapshots`
shows objects one after another (a particle cloud after each filter update) and can move one
object (the robot) in step with them.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..geometry import se2_to_se3
from ..validation import as_array, check_int, check_positive
from .scene import Scene, check_scene

__all__ = ["animate_poses", "animate_snapshots"]

_HIDDEN = 1e-6     # a snapshot out of its turn is scaled to nothing (meshcat animates scale, not visibility)


def _transforms(value: Any, name: str) -> np.ndarray:
    T = as_array(value, name)
    if T.ndim == 2 and T.shape[1] == 3:
        T = np.stack([se2_to_se3(p) for p in T])
    T = as_array(T, name, shape=(None, 4, 4))
    if len(T) < 2:
        raise ValueError(f"{name}: expected at least 2 poses, got {len(T)}")
    return T


def _play(scene: Scene, tracks: dict, fps: float, repetitions: int) -> Scene:
    """Send one clip whose ``tracks`` map a scene path to ``[(frame, property, type, value), ...]``."""
    from meshcat.animation import AnimationClip
    from meshcat.commands import SetAnimation

    clips = []
    for path, keys in tracks.items():
        clip = AnimationClip(fps=fps)
        for frame, prop, kind, value in keys:
            clip.set_property(frame, prop, kind, value)
        clips.append({"path": Scene.meshcat_path(path).lower(), "clip": clip.lower()})

    class _Animation:  # meshcat's Animation, keyed by our own paths
        def lower(self):
            return clips

    scene.send(SetAnimation(_Animation(), play=True, repetitions=repetitions))
    return scene


def _pose_keys(T: np.ndarray) -> list:
    from meshcat.animation import js_position, js_quaternion
    return [key for k, M in enumerate(T) for key in ((k, "position", "vector3", js_position(M)),
                                                      (k, "quaternion", "quaternion", js_quaternion(M)))]


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
    check_scene(scene, path)
    T = _transforms(transforms, "transforms")
    return _play(scene, {path: _pose_keys(T)}, check_positive(fps, "fps"),
                 check_int(repetitions, "repetitions", minimum=1))


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
    check_scene(scene, *paths)
    n = len(paths)
    tracks = {}
    for k, path in enumerate(paths):
        tracks[path] = [(f, "scale", "vector3", [1.0] * 3 if f == k else [_HIDDEN] * 3) for f in range(n)]
    if moving is not None:
        if not isinstance(moving, str):
            raise TypeError(f"moving: expected a scene path (str), got {type(moving).__name__}")
        check_scene(scene, moving)
        T = _transforms(transforms, "transforms")
        if len(T) != n:
            raise ValueError(f"transforms: expected one pose per path ({n}), got {len(T)}")
        tracks[moving] = _pose_keys(T)
    elif transforms is not None:
        raise ValueError("transforms: given without the object to move (moving=None)")
    return _play(scene, tracks, check_positive(fps, "fps"), check_int(repetitions, "repetitions", minimum=1))
