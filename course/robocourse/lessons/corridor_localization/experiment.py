"""Lesson 03's mapping stage in the long corridor: the hybrid map and the keyframe comparison.

Ge et al. (2023) drive their robot once along the corridor's middle line and build a *hybrid map*
(Sec. 3.4, Fig. 8): an occupancy grid from the LiDAR, and an image map of ORB keyframes turned into
bag-of-words vectors, each keyframe geo-tagged with the robot's pose at its timestamp (Eq. (18)).
This module re-runs that stage on :func:`robokit.sim.long_corridor`, with the lesson's two sensors
(Sec. 4: an RPLIDAR A2, 360 degrees and 8-10 m, above a monocular camera of 1280 x 960 pixels at
30 frames per second; :func:`corridor_lidar`, :func:`corridor_camera`), which every recording, map
and run of the lesson uses:

1. :func:`calibration_run` records the paper's 10 m calibration video (30 frames per second,
   1502 frames in the paper) and returns every frame's ORB descriptors: Eq. (15) takes ``F_min``
   from it, and :func:`keyframe_comparison` re-runs Table 1 on it (our rule vs an ORB-SLAM-like one).
2. :func:`training_vocabulary` trains the vocabulary tree on images of a *different* corridor (other
   textures, another door layout), as DBoW2's vocabularies are trained offline on other data.
3. :func:`corridor_map` drives the mapping run: scans at 10 Hz build the log-odds grid from the
   known poses (the paper runs Gmapping; the simulator's poses stand in for its output), camera
   frames half a period later go through the keyframe rule, and the keyframes are geo-tagged by
   interpolating the scan-time poses at their timestamps (Eq. (18)) and added to the database. Its
   ``clutter`` maps the corridor with cabinets along the walls (:func:`robokit.sim.long_corridor`),
   where the lesson re-runs Table 2.

Everything is cached (keyed by the parameters and the code that makes it); a cache is never needed
for correctness. Poses are robokit's ``[x, y, theta]``: the corridor runs along +x from 0 to
36.10 m with its middle line on y = 0. The recordings are rendered in worker processes
(:func:`robokit.parallel.map_runs`): a plain script that makes them needs the
``if __name__ == "__main__":`` guard.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
.. [2] R. Mur-Artal, J. M. M. Montiel and J. D. Tardos, "ORB-SLAM: a versatile and accurate monocular
   SLAM system", *IEEE Transactions on Robotics* 31(5), 1147-1163, 2015.
.. [3] D. Galvez-Lopez and J. D. Tardos, "Bags of binary words for fast place recognition in image
   sequences", *IEEE Transactions on Robotics* 28(5), 1188-1197, 2012.
"""
from __future__ import annotations

import dataclasses
import hashlib
from typing import Any, Callable

import numpy as np

from robocourse.source import code_version_of
from robokit.cache import CACHE_READ_ERRORS, cache_dir, cache_key, read_arrays, write_arrays
from robokit.config import fast_mode
from robokit.mapping import LikelihoodField, OccupancyGrid, geo_tag, likelihood_field, occupancy_grid_mapping
from robokit.parallel import map_runs
from robokit.sim import (Lidar, PinholeCamera, camera_mount, corridor_path, describe_sensor, long_corridor,
                         waypoint_path)
from robokit.sim.world import World
from robokit.validation import as_array, as_callable, as_choice, as_int, as_positive
from robokit.vision import (BowDatabase, Features, Keypoints, Vocabulary, detect_orb_features, feature_threshold,
                            select_keyframes, select_keyframes_orbslam)
from robokit.vision.orb import ORB_FEATURES

__all__ = ["CorridorMap", "corridor_map", "as_corridor_map", "mapping_grid", "clutter_map", "CalibrationRun",
           "calibration_run", "keyframe_comparison", "training_vocabulary", "MAPPING_ALPHAS", "corridor_lidar",
           "corridor_camera"]


def corridor_lidar() -> Lidar:
    """The RPLIDAR-A2-like scanner of the lesson: 360 beams, 8 m range, 1 cm noise, 0.45 m high.

    Returns
    -------
    Lidar

    Notes
    -----
    Ge et al. (2023), Sec. 4: an RPLIDAR A2 (360 degrees, effective radius 8-10 m), mounted above the
    camera so the camera does not block its beams.

    Examples
    --------
    >>> corridor_lidar().r_max, corridor_lidar().beams
    (8.0, 360)
    """
    return Lidar(noise=0.01, height=0.45)


def corridor_camera() -> PinholeCamera:
    """The forward-looking camera of the lesson: 640 x 480 pixels, 65 degrees wide, 0.35 m high, below the LiDAR.

    Returns
    -------
    PinholeCamera

    Notes
    -----
    Ge et al. (2023), Sec. 4: a monocular camera with 1280 x 960 pixels at 30 frames per second,
    mounted lower than the LiDAR. We render at half that size to keep the lesson fast. Fast mode
    renders fewer frames, never smaller ones: at 320 x 240 ORB finds fewer than its 500 features
    (about 410 mid-corridor, 340-380 in the last 6 m), so Eq. (15)'s threshold (413 there) refused
    every frame past x = 27.5 m and the keyframe database stopped 8 m before the run's end; at
    640 x 480 it ends 2-4 m before (lesson 03 prints where, in its kidnapping section).

    Examples
    --------
    >>> corridor_camera().width, corridor_camera().height
    (640, 480)
    """
    return PinholeCamera.from_fov(np.deg2rad(65.0), 640, 480, mount=camera_mount(0.35))


#: Odometry noise of the simulated Kobuki base (Thrun et al. 2005, Table 5.6 alphas, our choice).
MAPPING_ALPHAS = (0.01, 0.001, 0.01, 0.001)
#: ORB features per image: OpenCV's default, robokit's :data:`robokit.vision.orb.ORB_FEATURES`.
N_FEATURES = ORB_FEATURES
#: Frames the mapping run's keyframe rule waits (condition (2) says more than 10 frames at 30 frames
#: per second, a third of a second; the mapping run's camera runs at 10 frames per second).
MAPPING_FRAME_GAP = 3
#: Condition (3)'s band of shared matches, the paper's. ORB's mutual matches fall through the band's
#: floor within a few frames, on our views and on a real photograph moved alike (lesson 03, Sec. 4;
#: :mod:`.orb_realism`), and the printed rule stalls; the mapping run takes such a frame
#: (``below_band="take"``, see docs/DECISIONS.md).
SHARED_RANGE = (0.70, 0.90)


def _code() -> dict:
    return code_version_of(__name__)


def _descriptor_stack(descriptors: list) -> tuple[np.ndarray, np.ndarray]:
    counts = np.array([len(d) for d in descriptors], int)
    flat = np.concatenate([d for d in descriptors] + [np.zeros((0, 32), np.uint8)]).astype(np.uint8)
    return flat, counts


def _per_frame(flat: np.ndarray, counts: np.ndarray) -> list:
    """Stacked per-frame rows (descriptors or keypoints) split back into one array per frame."""
    return np.split(flat, np.cumsum(counts)[:-1]) if len(counts) else []


#: Where the calibration video runs along the middle line (m): 10 m, as Ge et al. (2023), Sec. 3.2.
CALIBRATION_STRETCH = (12.0, 22.0)


#: Frames per task when a recording is rendered in worker processes (a frame takes about 10 ms).
_FRAMES_PER_TASK = 64


def _orb_batch(shared: tuple, task: tuple) -> list:
    """ORB features (or only their descriptors) of frames ``first ..`` at ``poses``; frame ``k``'s pixel
    noise is seeded by ``(seed, k)``."""
    world, camera, seed, whole = shared
    first, poses = task
    found = [detect_orb_features(camera.observe(world, pose, rng=np.random.default_rng([seed, first + k])).image,
                                 N_FEATURES) for k, pose in enumerate(poses)]
    return found if whole else [f.descriptors for f in found]


def _orb_frames(world: World, camera: PinholeCamera, poses: np.ndarray, seed: int, progress: Callable | None,
                desc: str, *, keypoints: bool = False) -> list:
    """Render every pose and detect its ORB features, batches side by side (:func:`robokit.parallel.map_runs`);
    descriptor arrays, or whole ``Features`` with ``keypoints``."""
    tasks = [(k, poses[k:k + _FRAMES_PER_TASK]) for k in range(0, len(poses), _FRAMES_PER_TASK)]
    batches = map_runs(_orb_batch, (world, camera, seed, keypoints), tasks, desc=desc,
                       unit=f"{_FRAMES_PER_TASK} frames", progress=progress)
    return [d for batch in batches for d in batch]


# --- the calibration run and Table 1 -------------------------------------------------------------

@dataclasses.dataclass
class CalibrationRun:
    """The 10 m calibration video: ORB ``features`` per frame, ``positions`` (N, 2), ``f_min`` (Eq. (15)).

    Attributes
    ----------
    features : list of robokit.vision.Features
        Each frame's ORB keypoints and descriptors (``descriptors`` lists the descriptors alone).
    positions : numpy.ndarray (N, 2)
        Where each frame was taken (metres).
    frame_rate, speed : float
        Frames per second and metres per second.
    f_min : float
        Eq. (15) over the frames' feature counts.
    """

    features: list
    positions: np.ndarray
    frame_rate: float
    speed: float
    f_min: float

    @property
    def descriptors(self) -> list:
        """Each frame's ORB descriptors, (n_k, 32) uint8."""
        return [f.descriptors for f in self.features]

    @property
    def counts(self) -> np.ndarray:
        """ORB features per frame."""
        return np.array([len(f) for f in self.features], int)


def _keypoint_rows(f: Features) -> np.ndarray:
    """A frame's keypoints as rows ``x, y, scale, response, orientation`` (what the calibration run stores)."""
    return np.c_[f.keypoints.xy, f.keypoints.scale, f.keypoints.response, f.keypoints.orientation]


def calibration_run(*, fast: bool | None = None, start: float = CALIBRATION_STRETCH[0],
                    length: float = CALIBRATION_STRETCH[1] - CALIBRATION_STRETCH[0], speed: float = 0.2,
                    frame_rate: float = 30.0, progress: Callable | None = None) -> CalibrationRun:
    """Record the paper's calibration video: ``length`` metres along the middle line at ``frame_rate``.

    Parameters
    ----------
    fast : bool, optional
        2 m instead of ``length`` (which is still checked) (default: :func:`robokit.config.fast_mode`).
    start : float, default 12.0
        Where along the corridor the section starts (m).
    length : float, default 10.0
    speed : float, default 0.2
        m/s; with 30 frames per second, 10 m gives 1501 frames (the paper's Table 1 has 1502).
    frame_rate : float, default 30.0
    progress : callable ``(done, total)``, optional
        Told about the rendering (only when it is not cached).

    Returns
    -------
    CalibrationRun

    Raises
    ------
    ValueError, TypeError
        For a section outside the corridor or non-positive rates.

    Notes
    -----
    Ge et al. (2023), Sec. 3.2, condition (1) and Eq. (15) (a video over 10 m of the corridor
    calibrates ``F_min``) and Table 1 (1502 images of a 10 m section). Cached under
    ``robokit.cache.cache_dir("corridor")``.

    Examples
    --------
    >>> run = calibration_run(fast=True)
    >>> len(run.descriptors) == len(run.positions), bool(run.f_min > 0)
    (True, True)
    """
    fast = fast_mode() if fast is None else bool(fast)
    length = as_positive(length, "length")
    length = 2.0 if fast else length
    start = as_positive(start, "start")
    speed, frame_rate = as_positive(speed, "speed"), as_positive(frame_rate, "frame_rate")
    progress = as_callable(progress, "progress")
    world = long_corridor()
    if start + length > world.info["length"] - 0.5:
        raise ValueError(f"start, length: expected a section inside the corridor (0 .. {world.info['length']} m), "
                         f"got {start} .. {start + length}")
    if length / speed * frame_rate > 20000:
        raise ValueError(f"length, speed, frame_rate: expected at most 20000 frames, got {length / speed * frame_rate:.3g}")
    camera = corridor_camera()
    path = waypoint_path([[start, 0.0], [start + length, 0.0]], speed, rate=frame_rate)
    meta = {"camera": describe_sensor(camera), "start": start, "length": length, "speed": speed,
            "rate": frame_rate, "features": N_FEATURES, "code": _code()}
    target = cache_dir("corridor") / f"calibration-{cache_key(**meta)}.npz"
    data = read_arrays(target, ("flat", "counts", "keypoints", "positions"), meta)
    if data is None:
        found = _orb_frames(world, camera, path.poses, 5, progress, "calibration run", keypoints=True)
        flat, counts = _descriptor_stack([f.descriptors for f in found])
        data = {"flat": flat, "counts": counts, "keypoints": np.concatenate([_keypoint_rows(f) for f in found]
                                                                             + [np.zeros((0, 5))]),
                "positions": path.poses[:, :2]}
        write_arrays(target, data, meta)
    kps = _per_frame(data["keypoints"], data["counts"])
    features = [Features(Keypoints(k[:, :2], k[:, 2], k[:, 3], k[:, 4]), d)
                for k, d in zip(kps, _per_frame(data["flat"], data["counts"]))]
    return CalibrationRun(features, data["positions"], frame_rate, speed, float(feature_threshold(data["counts"])))


def keyframe_comparison(run: CalibrationRun, *, min_frame_gap: int = 10, shared_range: Any = SHARED_RANGE,
                        below_band: str = "take", matching: str = "mutual") -> dict:
    """Table 1 re-run: keyframes of our rule (conditions (1)-(4)) and of an ORB-SLAM-like rule.

    Parameters
    ----------
    run : CalibrationRun
    min_frame_gap : int, default 10
        Condition (2): frames that must pass since the last keyframe.
    shared_range : (float, float), default :data:`SHARED_RANGE`
        Condition (3)'s band (the paper's (0.70, 0.90)).
    below_band : {"take", "skip"}, default "take"
        A frame below the band (:class:`robokit.vision.KeyframeSelector`); ``"skip"`` is the rule as
        printed.
    matching : {"mutual", "tracked"}, default "mutual"
        What "matched points" means for both rules (:class:`robokit.vision.KeyframeSelector`): mutual
        nearest neighbours, or ORB-SLAM-style search windows (:func:`robokit.vision.tracked_fraction`).

    Returns
    -------
    dict
        ``{"ours": indices, "orbslam": indices, "images": N}``; the extraction rate is
        ``len(indices) / N``. Cached under ``robokit.cache.cache_dir("corridor")``, keyed by the run's
        descriptors and positions, the parameters and the code (a stale file is rebuilt).

    Raises
    ------
    TypeError
        For something that is not a CalibrationRun.

    Notes
    -----
    Ge et al. (2023), Sec. 3.2 and Table 1 (ORB-SLAM 42 of 1502 images, 2.8 %; theirs 103, 6.9 %).
    The ORB-SLAM-like rule is Mur-Artal et al. (2015), Sec. V-E, without map points (see
    :func:`robokit.vision.select_keyframes_orbslam`).

    Examples
    --------
    >>> table = keyframe_comparison(calibration_run(fast=True))
    >>> table["images"] > 0, 0 < len(table["ours"]) <= table["images"]
    (True, True)
    """
    if not isinstance(run, CalibrationRun):
        raise TypeError(f"run: expected a CalibrationRun (calibration_run()), got {type(run).__name__}")
    gap = as_int(min_frame_gap, "min_frame_gap", minimum=0)
    flat, counts = _descriptor_stack(run.descriptors)
    content = hashlib.sha256(flat.tobytes() + counts.tobytes() + np.asarray(run.positions, float).tobytes())
    band = as_array(shared_range, "shared_range", shape=(2,)).tolist()   # checked before any cache lookup
    matching = as_choice(matching, "matching", ("mutual", "tracked"))
    if matching == "tracked":
        for f in run.features:
            content.update(_keypoint_rows(f).tobytes())
    meta = {"run": content.hexdigest()[:16], "f_min": float(run.f_min), "gap": gap, "shared_range": band,
            "below_band": str(below_band), "matching": matching, "code": _code()}
    target = cache_dir("corridor") / f"keyframes-{cache_key(**meta)}.npz"
    data = read_arrays(target, ("ours", "orbslam"), meta)
    if data is None:
        frames = run.features if matching == "tracked" else run.descriptors
        ours = select_keyframes(frames, run.positions, run.f_min, min_frame_gap=gap, shared_range=shared_range,
                                below_band=below_band, matching=matching)
        orbslam = select_keyframes_orbslam(frames, run.positions, matching=matching)
        data = {"ours": np.asarray(ours, int), "orbslam": np.asarray(orbslam, int)}
        write_arrays(target, data, meta)
    return {"ours": data["ours"], "orbslam": data["orbslam"], "images": len(run.features)}


# --- the vocabulary -----------------------------------------------------------------------------

def training_vocabulary(*, fast: bool | None = None, branching: int = 10, levels: int = 4,
                        progress: Callable | None = None) -> Vocabulary:
    """A vocabulary tree trained on a different corridor (other textures, doors facing), both directions.

    Parameters
    ----------
    fast : bool, optional
        Fewer training images and three levels (default: :func:`robokit.config.fast_mode`).
    branching, levels : int, default 10, 4
        ``k`` and ``L`` of the tree (up to ``k ** L`` words).
    progress : callable ``(done, total)``, optional

    Returns
    -------
    robokit.vision.Vocabulary

    Raises
    ------
    ValueError, TypeError
        For a bad branching factor or depth.

    Notes
    -----
    Ge et al. (2023), Sec. 3.3 and Fig. 7: the vocabulary is trained offline on many images; like
    DBoW2's vocabularies (Galvez-Lopez and Tardos 2012) ours never sees the corridor it is used in.
    Cached under ``robokit.cache.cache_dir("corridor")``.

    Examples
    --------
    >>> vocabulary = training_vocabulary(fast=True)
    >>> vocabulary.n_words > 100
    True
    """
    fast = fast_mode() if fast is None else bool(fast)
    branching = as_int(branching, "branching", minimum=2, maximum=64)
    levels = 3 if fast else as_int(levels, "levels", minimum=1, maximum=8)
    progress = as_callable(progress, "progress")
    world = long_corridor(layout="facing", seed=7)
    camera = corridor_camera()
    step = 1.0 if fast else 0.25
    xs = np.arange(1.0, world.info["length"] - 1.0, step)
    poses = np.vstack([np.column_stack([xs, np.zeros_like(xs), np.zeros_like(xs)]),
                       np.column_stack([xs[::-1], np.zeros_like(xs), np.full_like(xs, np.pi)])])
    meta = {"camera": describe_sensor(camera), "step": step, "branching": branching, "levels": levels,
            "features": N_FEATURES, "code": _code()}
    target = cache_dir("corridor") / f"vocabulary-{cache_key(**meta)}.npz"
    if target.exists():
        try:
            return Vocabulary.load(target)
        except CACHE_READ_ERRORS:
            pass  # a corrupt or foreign cache file is rebuilt
    images = _orb_frames(world, camera, poses, 7, progress, "vocabulary images")
    vocabulary = Vocabulary.train(images, branching=branching, levels=levels, rng=0)
    vocabulary.save(target)                  # atomic: a parallel build never reads half a file
    return vocabulary


# --- the mapping run ----------------------------------------------------------------------------

@dataclasses.dataclass
class CorridorMap:
    """The hybrid map of the corridor (Ge et al. 2023, Sec. 3.4, Fig. 8) and the run that made it.

    Attributes
    ----------
    world : World
    lidar : Lidar
    camera : PinholeCamera
    grid : OccupancyGrid
        Log-odds grid of the mapping run's scans (0.05 m cells).
    field : LikelihoodField
        Distance to the nearest occupied cell, for the MCL's measurement model.
    database : BowDatabase
        One entry per keyframe, in keyframe order.
    keyframe_poses : numpy.ndarray (K, 3)
        The geo-tags: the scan-time poses interpolated at each keyframe's timestamp (Eq. (18)).
    keyframe_times : numpy.ndarray (K,)
    keyframe_truth : numpy.ndarray (K, 3)
        Where each keyframe was really taken.
    times, poses : numpy.ndarray (N,), (N, 3)
        The mapping run's scan times and poses.
    frame_count : int
        Camera frames the keyframe rule saw.
    f_min : float
        Eq. (15) threshold used (from :func:`calibration_run`).
    key : str
        Identifies the map and the code that made it (keys later caches).
    """

    world: World
    lidar: Lidar
    camera: PinholeCamera
    grid: OccupancyGrid
    field: LikelihoodField
    database: BowDatabase
    keyframe_poses: np.ndarray
    keyframe_times: np.ndarray
    keyframe_truth: np.ndarray
    times: np.ndarray
    poses: np.ndarray
    frame_count: int
    f_min: float
    key: str

    @property
    def n_keyframes(self) -> int:
        """Number of keyframes (database entries)."""
        return len(self.keyframe_poses)


def as_corridor_map(value: Any) -> CorridorMap:
    """Return ``value`` if it is a :class:`CorridorMap`, else raise a TypeError naming it.

    Examples
    --------
    >>> as_corridor_map(3)
    Traceback (most recent call last):
    ...
    TypeError: setup: expected a CorridorMap (corridor_map()), got int
    """
    if not isinstance(value, CorridorMap):
        raise TypeError(f"setup: expected a CorridorMap (corridor_map()), got {type(value).__name__}")
    return value


_MAP_ARRAYS = ("log_odds", "resolution", "origin", "kf_index", "kf_flat", "kf_counts", "kf_times", "kf_truth",
               "times", "poses", "frame_count")


def corridor_map(*, fast: bool | None = None, resolution: float = 0.05, clutter: float = 0.0,
                 progress: Callable | None = None) -> CorridorMap:
    """Drive the mapping run along the middle line and build the hybrid map.

    Parameters
    ----------
    fast : bool, optional
        A camera frame every fourth scan (default: :func:`robokit.config.fast_mode`).
    resolution : float, default 0.05
        Grid cell size (m, 0.01 to 1), Gmapping's default.
    clutter : float, default 0
        The corridor's share of wall stretches with a cabinet (:func:`robokit.sim.long_corridor`, 0 to
        1; 0: only doors along the walls). ``F_min`` and the vocabulary stay those of the plain
        corridor's calibration and training runs.
    progress : callable ``(done, total)``, optional
        Told about the rendering (only when the map is not cached).

    Returns
    -------
    CorridorMap

    Raises
    ------
    ValueError, TypeError
        For a bad resolution, clutter share or progress callback.

    Notes
    -----
    Ge et al. (2023), Sec. 3.4 (the hybrid map; keyframes tied to poses by timestamps, Eq. (18)) and
    Sec. 4 (the run stops about 0.8 m from the end walls). Scans are taken at 10 Hz while the robot
    drives at 0.3 m/s; camera frames at 10 Hz, half a period after each scan, go through the keyframe
    rule (Sec. 3.2) with ``F_min`` from :func:`calibration_run` and the frame gap scaled to the frame
    rate (:data:`MAPPING_FRAME_GAP`). The grid uses the run's true poses (the paper's Gmapping output).

    Examples
    --------
    >>> setup = corridor_map(fast=True)
    >>> setup.n_keyframes == len(setup.database), setup.grid.resolution
    (True, 0.05)
    """
    fast = fast_mode() if fast is None else bool(fast)
    resolution = _as_cell_size(resolution)
    progress = as_callable(progress, "progress")
    world, lidar, camera = long_corridor(clutter=clutter), corridor_lidar(), corridor_camera()
    f_min = calibration_run(fast=fast).f_min
    vocabulary = training_vocabulary(fast=fast)
    path = _mapping_path(world)
    every, gap = (4, 0) if fast else (1, MAPPING_FRAME_GAP)
    meta = {"camera": describe_sensor(camera), "lidar": describe_sensor(lidar), "corridor": _corridor_layout(world),
            "resolution": resolution, "f_min": f_min, "gap": gap, "every": every, "band": list(SHARED_RANGE),
            "features": N_FEATURES,
            "path": cache_key(poses=path.poses.round(9).tolist()), "code": _code()}
    key = cache_key(**meta)
    target = cache_dir("corridor") / f"map-{key}.npz"
    data = read_arrays(target, _MAP_ARRAYS, meta)
    if data is None:
        data = _build_map(world, lidar, camera, path, f_min, resolution, every, gap, progress)
        write_arrays(target, data, meta)
    grid = OccupancyGrid(data["log_odds"], float(data["resolution"]), data["origin"])
    database = BowDatabase(vocabulary)
    for d in _per_frame(data["kf_flat"], data["kf_counts"]):
        database.add(d)
    kf_poses = geo_tag(data["kf_times"], data["times"], data["poses"])
    return CorridorMap(world, lidar, camera, grid, likelihood_field(grid), database, kf_poses, data["kf_times"],
                       data["kf_truth"], data["times"], data["poses"], int(data["frame_count"]), f_min, key)


def _as_cell_size(resolution: Any) -> float:
    """A grid cell size in metres, 0.01 to 1 (the lesson's grids), or a named error."""
    resolution = as_positive(resolution, "resolution")
    if not 0.01 <= resolution <= 1.0:
        raise ValueError(f"resolution: expected a cell size between 0.01 and 1 m, got {resolution}")
    return resolution


def mapping_grid(world: World, lidar: Lidar, poses: Any, resolution: float = 0.05) -> OccupancyGrid:
    """The occupancy grid of a mapping run: ``lidar``'s scans at ``poses`` in a corridor ``world``.

    Parameters
    ----------
    world : robokit.sim.World
        A corridor (:func:`robokit.sim.long_corridor`: its ``info`` gives the length and width).
    lidar : robokit.sim.Lidar
    poses : array_like, shape (N, 3)
        Where each scan is taken (the grid uses these true poses: the paper's Gmapping output).
    resolution : float, default 0.05
        Cell size (m, 0.01 to 1).

    Returns
    -------
    robokit.mapping.OccupancyGrid
        Over the corridor and 0.5 m around it; the scans' noise is seeded by 3.

    Raises
    ------
    ValueError, TypeError
        For a world that is not a corridor, a bad LiDAR, poses or resolution.

    Notes
    -----
    Ge et al. (2023), Sec. 3.4 (the grid half of the hybrid map); Thrun et al. (2005), Table 9.1.

    Examples
    --------
    >>> world = long_corridor()
    >>> grid = mapping_grid(world, corridor_lidar(), [[5.0, 0.0, 0.0], [5.3, 0.0, 0.0]])
    >>> grid.resolution, bool(grid.occupied_mask().any())
    (0.05, True)
    """
    if not isinstance(world, World) or not {"length", "width"} <= set(world.info):
        raise TypeError(f"world: expected a corridor World (robokit.sim.long_corridor), got {type(world).__name__}")
    if not isinstance(lidar, Lidar):
        raise TypeError(f"lidar: expected a robokit.sim Lidar, got {type(lidar).__name__}")
    poses = as_array(poses, "poses", shape=(None, 3))
    resolution = _as_cell_size(resolution)
    rng = np.random.default_rng(3)
    scans = np.array([lidar.scan(world, p, rng) for p in poses]).reshape(len(poses), -1)
    L, W = world.info["length"], world.info["width"]
    return occupancy_grid_mapping(poses, scans, lidar.angles, (-0.5, -W / 2 - 0.5, L + 0.5, W / 2 + 0.5), resolution,
                                  r_max=lidar.r_max, sensor_offset=lidar.offset)


def clutter_map(clutter: float = 0.0, *, resolution: float = 0.05) -> tuple[World, OccupancyGrid]:
    """The lesson's corridor with ``clutter`` and the grid of its mapping run (laser only).

    Parameters
    ----------
    clutter : float, default 0
        :func:`robokit.sim.long_corridor`'s share of wall stretches with a cabinet (0 to 1).
    resolution : float, default 0.05
        Grid cell size (m, 0.01 to 1).

    Returns
    -------
    (World, OccupancyGrid)
        The grid is the one :func:`corridor_map` builds for the same corridor (cached on disk, so the
        hybrid map and AMCL's runs share one mapping run).

    Raises
    ------
    ValueError, TypeError
        For a share outside [0, 1] or a bad resolution.

    Notes
    -----
    Ge et al. (2023), Sec. 3.4 and Sec. 4: the mapping run drives the middle line at 0.3 m/s with
    a scan every 0.1 s (:func:`mapping_grid`).

    Examples
    --------
    >>> world, grid = clutter_map(1.0)
    >>> len(world.info["clutter"]) > 10, grid.resolution
    (True, 0.05)
    """
    resolution = _as_cell_size(resolution)
    world = long_corridor(clutter=clutter)
    return world, _mapping_run_grid(world, corridor_lidar(), _mapping_path(world).poses, resolution)


def _mapping_path(world: World):
    """The mapping run's path along a corridor's middle line: 0.3 m/s, a pose every 0.1 s (Sec. 4)."""
    return corridor_path(world, speed=0.3, rate=10.0)


def _corridor_layout(world: World) -> dict:
    """What a cache key needs of a corridor: its size, doors, seed and cabinets."""
    return {k: world.info.get(k) for k in ("length", "width", "recess", "layout", "doors", "seed", "clutter")}


def _mapping_run_grid(world: World, lidar: Lidar, poses: np.ndarray, resolution: float) -> OccupancyGrid:
    """:func:`mapping_grid` of a corridor's mapping run, cached by the corridor's layout (doors,
    cabinets, size), the LiDAR, the poses and the code."""
    meta = {"corridor": _corridor_layout(world), "lidar": describe_sensor(lidar), "resolution": resolution,
            "path": cache_key(poses=poses.round(9).tolist()), "code": _code()}
    target = cache_dir("corridor") / f"grid-{cache_key(**meta)}.npz"
    data = read_arrays(target, ("log_odds", "resolution", "origin"), meta)
    if data is None:
        grid = mapping_grid(world, lidar, poses, resolution)
        data = {"log_odds": grid.log_odds, "resolution": np.float64(grid.resolution), "origin": np.asarray(grid.origin)}
        write_arrays(target, data, meta)
    return OccupancyGrid(data["log_odds"], float(data["resolution"]), data["origin"])


def _build_map(world: World, lidar: Lidar, camera: PinholeCamera, path, f_min: float, resolution: float,
               every: int, gap: int, progress: Callable | None) -> dict:
    times, poses = path.t, path.poses
    grid = _mapping_run_grid(world, lidar, poses, resolution)
    # camera frames half a period after each scan: their poses are what Eq. (18) must recover
    frame_times = (times[:-1] + 0.5 * np.diff(times))[::every]
    # the true pose at each frame (the path is piecewise linear in time) is also its geo-tag: the
    # grid's pose log is the truth here, so Eq. (18) is exact; with a SLAM pose log it would carry
    # the log's error
    frame_truth = geo_tag(frame_times, times, poses)
    descriptors = _orb_frames(world, camera, frame_truth, 3, progress, "camera frames")
    positions = frame_truth[:, :2]
    index = np.asarray(select_keyframes(descriptors, positions, f_min, min_frame_gap=gap,
                                       shared_range=SHARED_RANGE, below_band="take"), int)
    flat, counts = _descriptor_stack([descriptors[i] for i in index])
    return {"log_odds": grid.log_odds, "resolution": np.float64(grid.resolution), "origin": np.asarray(grid.origin),
            "kf_index": index, "kf_flat": flat, "kf_counts": counts, "kf_times": frame_times[index],
            "kf_truth": frame_truth[index], "times": times, "poses": poses, "frame_count": np.int64(len(frame_times))}
