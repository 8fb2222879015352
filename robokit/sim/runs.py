"""Recorded runs: drive a path through a world, log ground truth, odometry, images and scans.

A :class:`Run` is plain arrays (no pickled objects), saved as one compressed ``.npz`` file and
cached under ``robokit.cache.cache_dir("runs")`` keyed by every parameter of the recording and by the
code that renders it, so a lesson that records the same run twice renders it once, and a change
to the simulator never serves an old rendering. Every sensor is driven through one interface,
``observe(world, robot_pose, rng=...)``.

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features",
   IEEE/RSJ International Conference on Intelligent Robots and Systems (IROS), 2002.
.. [3] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering*, 2023,
   doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from ..cache import CACHE_READ_ERRORS, cache_dir, cache_key, code_version
from ..files import as_file_path, read_npz, save_npz, write_atomically
from ..parallel import iter_runs, map_runs
from ..progress import progress_bar
from ..validation import as_array, as_points, as_rng, as_int, as_positive
from .camera import PinholeCamera, StereoRig
from .motion import Trajectory, noisy_odometry
from .omni import OmniCamera
from .world import World

__all__ = ["Run", "record", "describe_sensor", "FrameStream", "record_stream", "MAX_RUN_BYTES"]

#: The largest run file :meth:`Run.load` reads (bytes; also its bound on values per array).
MAX_RUN_BYTES = 4 * 1024**3

_FORMAT = 1


@dataclasses.dataclass
class Run:
    """A recorded drive.

    Attributes
    ----------
    t : numpy.ndarray (N,)
        Timestamps (s).
    poses : numpy.ndarray (N, 3)
        Ground-truth planar poses ``[x, y, theta]``.
    odometry : numpy.ndarray (N, 3)
        Odometry poses (Thrun et al. 2005, Table 5.6 noise; see :func:`robokit.sim.noisy_odometry`).
    images : dict of str to numpy.ndarray (N, H, W, 3) uint8
        Per camera (stereo rigs give ``name/left``, ``name/right``, ...).
    depths : dict of str to numpy.ndarray (N, H, W) float32
        Matching depth images (Z for pinhole cameras, range for omni cameras).
    scans : dict of str to numpy.ndarray (N, B)
        LiDAR ranges (``inf`` = no return).
    meta : dict
        Recording parameters (world, rate, sensors, seed), JSON-serialisable.
    """

    t: np.ndarray
    poses: np.ndarray
    odometry: np.ndarray
    images: dict
    depths: dict
    scans: dict
    meta: dict

    def __len__(self) -> int:
        return len(self.t)

    def save(self, path: str | Path) -> Path:
        """Write the run as a compressed ``.npz`` (arrays only; ``meta`` as JSON text).

        Parameters
        ----------
        path : str or Path

        Returns
        -------
        Path
            The file written.

        Notes
        -----
        :func:`robokit.files.save_npz`, atomically; :meth:`load` reads it back through
        :func:`robokit.files.read_npz`, which never unpickles, so a run file can never execute code
        (course convention, DESIGN.md "Files").
        """
        arrays = {"t": self.t, "poses": self.poses, "odometry": self.odometry,
                  "meta": np.array(json.dumps({**self.meta, "format": _FORMAT}))}
        for group in ("images", "depths", "scans"):
            for name, arr in getattr(self, group).items():
                arrays[f"{group}:{name}"] = arr
        return write_atomically(as_file_path(path), lambda tmp: save_npz(tmp, arrays))

    @classmethod
    def load(cls, path: str | Path) -> "Run":
        """Read a run written by :meth:`save` (nothing is unpickled: no code is ever loaded).

        The file is read by :func:`robokit.files.read_npz` within :data:`MAX_RUN_BYTES`.

        Raises
        ------
        ValueError
            If the file is not a robokit run (:class:`robokit.files.NpzFileError` for one that is
            truncated, corrupt, a device or beyond the bound).
        """
        data = read_npz(path, max_bytes=MAX_RUN_BYTES, max_values=MAX_RUN_BYTES)
        if "meta" not in data or "poses" not in data:
            raise ValueError(f"path: expected a robokit run (.npz with meta and poses), got {path}")
        groups: dict[str, dict] = {"images": {}, "depths": {}, "scans": {}}
        for key in data:
            if ":" in key:
                group, name = key.split(":", 1)
                if group not in groups:
                    raise ValueError(f"path: {path} holds an unknown group {group[:40]!r}")
                groups[group][name] = data[key]
        return cls(data["t"], data["poses"], data["odometry"], groups["images"], groups["depths"],
                   groups["scans"], json.loads(str(data["meta"])))


def _cached(target: Path, meta: dict) -> Run | None:
    """The run cached at ``target`` if it is readable and was made with exactly ``meta``; ``None``
    for a missing, corrupt (a killed write, a damaged disk) or foreign file, which is then rebuilt."""
    if not target.exists():
        return None
    try:
        run = Run.load(target)
    except CACHE_READ_ERRORS:
        return None
    stored = {k: v for k, v in run.meta.items() if k != "format"}
    return run if stored == json.loads(json.dumps(meta)) else None


def describe_sensor(sensor: Any) -> dict:
    """JSON description of a sensor's parameters, for the key of a cache of what it recorded.

    Parameters
    ----------
    sensor : dataclass instance
        A camera, stereo rig, omni camera or LiDAR (any dataclass of numbers, arrays, tuples and
        nested dataclasses).

    Returns
    -------
    dict
        ``{"type": class name, field: value, ...}`` with arrays rounded to 12 decimals and listed.

    Raises
    ------
    TypeError
        If ``sensor`` is not a dataclass instance.

    Notes
    -----
    Course convention (DESIGN.md, "Caching"): equal sensors give equal descriptions across runs.

    Examples
    --------
    >>> from robokit.sim import Lidar
    >>> d = describe_sensor(Lidar(beams=8))
    >>> d["type"], d["beams"], d["offset"]
    ('Lidar', 8, [0.0, 0.0, 0.0])
    """
    if not dataclasses.is_dataclass(sensor) or isinstance(sensor, type):
        raise TypeError(f"sensor: expected a sensor dataclass (camera, rig or LiDAR), got {type(sensor).__name__}")
    out = {"type": type(sensor).__name__}
    for field in dataclasses.fields(sensor):
        value = getattr(sensor, field.name)
        if dataclasses.is_dataclass(value):          # e.g. the camera of a stereo rig
            value = describe_sensor(value)
        elif isinstance(value, np.ndarray):
            value = np.round(value, 12).tolist()
        elif isinstance(value, tuple):
            value = [float(v) for v in value]
        out[field.name] = value
    return out


def _readings(name: str, observation: Any) -> list[tuple[str, str, np.ndarray]]:
    """``(group, key, array)`` entries of a :class:`Run` from one sensor's ``observe`` output.

    The sensor interface: ``observe(world, robot_pose, rng=...)`` returns a range scan (an array,
    a LiDAR), a frame with ``image`` and ``depth`` (a camera) or a dict of frames (a stereo rig:
    ``name/left``, ``name/right``, ...).
    """
    if isinstance(observation, np.ndarray):
        return [("scans", name, observation)]
    views = observation.items() if isinstance(observation, dict) else [("", observation)]
    out = []
    for sub, frame in views:
        key = f"{name}/{sub}" if sub else name
        out += [("images", key, frame.image), ("depths", key, frame.depth)]
    return out


#: Camera frames per task when a recording is rendered in worker processes.
_FRAMES_PER_TASK = 16


def _noise_free_camera(sensor: Any) -> bool:
    """A robokit camera (exactly, not a subclass of the caller's): its ``observe`` draws nothing from rng."""
    if type(sensor) is StereoRig:
        return type(sensor.camera) is PinholeCamera
    return type(sensor) in (PinholeCamera, OmniCamera)


def _camera_frames(shared: tuple, poses: np.ndarray) -> list:
    """Each noise-free camera's readings at each pose (a dict per pose): one worker task of :func:`record`."""
    world, cameras = shared
    return [{name: _readings(name, camera.observe(world, pose)) for name, camera in cameras.items()}
            for pose in poses]


def _timed_poses(path: Any, rate: float | None) -> tuple[np.ndarray, np.ndarray]:
    """Timestamps and poses of ``path``, resampled at ``rate`` (linear, heading unwrapped) if given."""
    if isinstance(path, tuple) and len(path) == 2 and not isinstance(path, Trajectory):
        path = Trajectory(*path)
    if isinstance(path, Trajectory):
        t0, p0 = as_array(path.t, "path.t", ndim=1), as_points(path.poses, "path.poses", 3, min_count=1)
    else:
        p0 = as_points(path, "path", 3, min_count=1)
        t0 = np.arange(len(p0)) / as_positive(rate if rate is not None else 10.0, "rate")
    if len(t0) != len(p0) or np.any(np.diff(t0) <= 0):
        raise ValueError("path: expected strictly increasing timestamps, one per pose")
    if rate is None:
        return t0, p0
    t = np.arange(t0[0], t0[-1] + 1e-9, 1.0 / as_positive(rate, "rate"))
    unwrapped = np.unwrap(p0[:, 2])
    return t, np.column_stack([np.interp(t, t0, p0[:, 0]), np.interp(t, t0, p0[:, 1]),
                               np.angle(np.exp(1j * np.interp(t, t0, unwrapped)))])


def _drive(world: World, path: Any, rate: float | None, odometry_alphas: Any, seed: Any
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The validated timestamps, poses, odometry noise and seed of a recording (see :func:`record`)."""
    if not isinstance(world, World):
        raise TypeError(f"world: expected a robokit.sim World, got {type(world).__name__}")
    t, poses = _timed_poses(path, rate)
    bad = ~world.is_free(poses[:, :2], clearance=0.05)
    if bad.any():
        raise ValueError(f"path: expected poses inside the free space of {world.name!r}, got {bad.sum()} outside "
                         f"(first at {poses[np.argmax(bad), :2].round(3).tolist()})")
    return t, poses, as_array(odometry_alphas, "odometry_alphas", shape=(4,)), as_int(seed, "seed", minimum=0)


def record(world: World, path: Trajectory, sensors: dict, rate: float | None = None, *,
           odometry_alphas: Any = (0.01, 0.001, 0.01, 0.001), seed: int = 0, cache: bool = True) -> Run:
    """Drive ``path`` through ``world`` and record every sensor at ``rate``.

    Parameters
    ----------
    world : World
    path : Trajectory, (t, poses) tuple or array_like (N, 3)
        Timed ground-truth trajectory (a bare pose array is taken as sampled at ``rate``).
    sensors : dict of str to sensor
        Sensor dataclasses with ``observe(world, robot_pose, rng=...)``: ``PinholeCamera``,
        ``StereoRig``, ``OmniCamera`` or ``Lidar`` (their mounts define where they sit on the robot).
    rate : float, optional
        Recording rate in Hz; the path is resampled (linear interpolation). Default: the path's
        own samples.
    odometry_alphas : array_like (4,)
        Odometry noise parameters (Thrun et al. 2005, Table 5.6).
    seed : int, default 0
        Seeds the odometry noise and the noise of every sensor that draws any (robokit's LiDAR;
        robokit's cameras render without noise here).
    cache : bool, default True
        Load from / save to ``robokit.cache.cache_dir("runs")``, keyed by all parameters and the code
        that renders (a corrupt or foreign cache file is rebuilt, never loaded).

    Returns
    -------
    Run

    Raises
    ------
    TypeError, ValueError
        For an unknown sensor, a bad path or rate, or a path leaving the world's free space.

    Notes
    -----
    Ge et al. (2023, Sec. 3.4) record scans and keyframes with timestamps while the robot is
    remote-controlled; Se, Lowe & Little (2002, Sec. 3.6) record stereo frames and odometry
    around the lab. Every sensor goes through the one interface ``observe`` (see
    :func:`_readings`); deterministic, hence cacheable (DESIGN.md, "Caching"). The frames of
    robokit's cameras (``PinholeCamera``, ``OmniCamera``, a ``StereoRig`` of pinhole cameras) draw
    no noise here, so they are rendered side by side in worker processes
    (:func:`robokit.parallel.map_runs`, ``ROBOKIT_WORKERS``): a plain script that records needs the
    ``if __name__ == "__main__":`` guard. Every other sensor is observed in this process, in order,
    drawing its noise from ``seed``; the recording is the same either way.

    Examples
    --------
    >>> from robokit.sim import Lidar, box_room, waypoint_path
    >>> path = waypoint_path([[1.0, 1.0], [2.0, 1.0]], rate=2)
    >>> run = record(box_room(), path, {"laser": Lidar(beams=8)}, rate=1.0, cache=False)
    >>> len(run), run.scans["laser"].shape
    (4, (4, 8))
    """
    if not isinstance(sensors, dict) or not sensors:
        raise ValueError(f"sensors: expected a non-empty dict name -> sensor, got {sensors!r}")
    for name, s in sensors.items():
        if not (dataclasses.is_dataclass(s) and callable(getattr(s, "observe", None))) or not isinstance(name, str) \
                or "/" in name or ":" in name:
            raise TypeError(f"sensors: expected camera/LiDAR objects under plain string names, got {name!r}: "
                            f"{type(s).__name__}")
    t, poses, alphas, seed = _drive(world, path, rate, odometry_alphas, seed)
    digest = hashlib.sha256(np.ascontiguousarray(poses).tobytes() + t.tobytes()).hexdigest()[:16]
    geometry = hashlib.sha256(np.round(world.corner_array, 9).tobytes()).hexdigest()[:16]
    meta = {"world": world.name, "world_info": json.loads(json.dumps(world.info, default=str)), "geometry": geometry,
            "rate": rate, "path": digest, "sensors": {k: describe_sensor(s) for k, s in sensors.items()},
            "odometry_alphas": alphas.tolist(), "seed": int(seed),
            "code": code_version("sim", "geometry")}   # renderer, textures, sensors, noise, poses
    target = cache_dir("runs") / f"{world.name}-{cache_key(**meta)}.npz" if cache else None
    if target is not None and (cached := _cached(target, meta)) is not None:
        return cached
    rng = as_rng(int(seed))
    odometry = noisy_odometry(poses, alphas, rng)
    # robokit's cameras draw no noise here (none is asked for), so their frames are rendered side by
    # side in batches; every other sensor (a LiDAR's noisy scans, a sensor of the caller's) is
    # observed here, in order, drawing from rng as before
    cameras = {k: s for k, s in sensors.items() if _noise_free_camera(s)}
    per_sensor: dict[str, list] = {name: [] for name in sensors}     # each sensor's readings, pose by pose
    if len(cameras) < len(sensors):
        with progress_bar(len(poses), f"recording in {world.name}", unit="frame") as bar:
            for pose in poses:
                for name, sensor in sensors.items():
                    if name not in cameras:
                        per_sensor[name].append(_readings(name, sensor.observe(world, pose, rng=rng)))
                bar.update()
    if cameras:
        tasks = [poses[k:k + _FRAMES_PER_TASK] for k in range(0, len(poses), _FRAMES_PER_TASK)]
        for batch in map_runs(_camera_frames, (world, cameras), tasks, desc=f"rendering in {world.name}",
                              unit="batch"):
            for frame in batch:
                for name, readings in frame.items():
                    per_sensor[name].append(readings)
    logs: dict[str, dict[str, list]] = {"images": {}, "depths": {}, "scans": {}}
    for readings in (r for name in sensors for r in per_sensor[name]):      # keys in the sensors' order
        for group, key, array in readings:
            logs[group].setdefault(key, []).append(array)
    stacked = {group: {k: np.stack(v) for k, v in arrays.items()} for group, arrays in logs.items()}
    run = Run(t, poses, odometry, stacked["images"], stacked["depths"], stacked["scans"], meta)
    if target is not None:
        run.save(target)                     # atomic: parallel notebooks never read a half-written file
    return run


@dataclasses.dataclass
class FrameStream:
    """A drive whose camera images come one by one, as worker processes render them (:func:`record_stream`).

    Attributes
    ----------
    t, poses, odometry : numpy.ndarray
        As in :class:`Run`, all known at once.
    frames : iterator of numpy.ndarray (H, W, 3) uint8
        The camera's images in the order of ``poses``, each rendered once: iterate once.
    meta : dict
        The recording's parameters (world, rate, camera, odometry noise, seed).

    Notes
    -----
    Use it in a ``with`` block (or call :meth:`close`): the workers stop at its end even if the
    consumer stops early or fails, which a Jupyter kernel's kept traceback would otherwise delay.
    """

    t: np.ndarray
    poses: np.ndarray
    odometry: np.ndarray
    frames: Iterator
    meta: dict

    def __len__(self) -> int:
        return len(self.t)

    def close(self) -> None:
        """Stop the rendering (images not yet taken are dropped); the frames then end."""
        self.frames.close()

    def __enter__(self) -> "FrameStream":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _camera_images(shared: tuple, poses: np.ndarray) -> list:
    """The camera's image at each pose (no depth): one worker task of :func:`record_stream`."""
    world, camera = shared
    return [camera.observe(world, pose).image for pose in poses]


def _images(batches: Iterator) -> Iterator:
    try:
        for batch in batches:
            yield from batch
    finally:
        batches.close()         # the workers stop when the caller stops taking images


def record_stream(world: World, path: Trajectory, camera: Any, rate: float | None = None, *,
                  odometry_alphas: Any = (0.01, 0.001, 0.01, 0.001), seed: int = 0) -> FrameStream:
    """Drive ``path`` through ``world`` with one camera whose images arrive as they are rendered.

    The same drive as :func:`record` with the same arguments and ``sensors={name: camera}`` (the
    same timestamps, poses, odometry and images), but nothing is stored: a consumer that takes the
    images one by one (:func:`robokit.mapping.build_topological_map`) works on the first ones while
    worker processes render the next, and no depth images are made. Use it in a ``with`` block.

    Parameters
    ----------
    world : World
    path : Trajectory, (t, poses) tuple or array_like (N, 3)
    camera : PinholeCamera or OmniCamera
        A robokit camera (its frames draw no noise, so the workers can render them in any order).
    rate : float, optional
    odometry_alphas : array_like (4,)
    seed : int, default 0
        Seeds the odometry noise, as in :func:`record`.

    Returns
    -------
    FrameStream

    Raises
    ------
    TypeError, ValueError
        For another kind of camera (a stereo rig, a LiDAR, a subclass of the caller's), a bad path
        or rate, or a path leaving the world's free space.

    Notes
    -----
    As :func:`record` (Thrun et al. 2005, Table 5.6 odometry noise); the images are made by
    :func:`robokit.parallel.iter_runs` in batches, so a plain script needs the
    ``if __name__ == "__main__":`` guard.

    Examples
    --------
    >>> from robokit.sim import OmniCamera, office_floor
    >>> poses = [[14.0, 4.0, np.pi], [13.8, 4.0, np.pi]]
    >>> with record_stream(office_floor(), poses, OmniCamera(width=80, height=60), rate=1.0) as stream:
    ...     shapes = [image.shape for image in stream.frames]
    >>> len(stream), shapes
    (2, [(60, 80, 3), (60, 80, 3)])
    """
    if isinstance(camera, StereoRig) or not _noise_free_camera(camera):      # one noise-free image per pose
        raise TypeError(f"camera: expected a robokit PinholeCamera or OmniCamera, got {type(camera).__name__}")
    t, poses, alphas, seed = _drive(world, path, rate, odometry_alphas, seed)
    odometry = noisy_odometry(poses, alphas, as_rng(seed))
    meta = {"world": world.name, "rate": rate, "camera": describe_sensor(camera), "odometry_alphas": alphas.tolist(),
            "seed": seed}
    tasks = [poses[k:k + _FRAMES_PER_TASK] for k in range(0, len(poses), _FRAMES_PER_TASK)]
    batches = iter_runs(_camera_images, (world, camera), tasks, desc=f"rendering in {world.name}", unit="batch")
    return FrameStream(t, poses, odometry, _images(batches), meta)
