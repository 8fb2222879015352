"""Lesson 02's experiments in the simulated office: the map, localization, node recognition, navigation.

The paper's experiments (Sec. "Experimental results") re-run on :func:`robokit.sim.office_floor`:

1. :func:`office_setup` drives the exploration tour (Fig. 6a) with an omni camera and noisy
   odometry, builds the topological map from the recording, and aligns it twice: by relaxation
   (Eqs. (1)-(3)) and by least squares. The map is cached (keyed by its parameters and the code
   that makes it); the recording is not stored: the map is built from its images as they are
   rendered.
2. :func:`localization_trials` localizes omni images taken at test places (Figs. 8, 9 and 11) with
   the coarse stage only, the fine stage only and the hierarchy, timing each stage.
3. :func:`route_recognition` asks which node the robot is at, at key nodes along the route (Fig. 12).
4. :func:`robocourse.lessons.omni_localization.navigation.navigation_trials` follows a visual path from perturbed
   starts with the omni camera in the loop (Fig. 13).

Poses are robokit's ``[x, y, theta]`` in the office's world frame (the paper's ``(x, z, theta)``);
the map's frame is the odometry's, which starts at the tour's first true pose, so map poses and
ground truth compare directly.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] T. Duckett, S. Marsland and J. Shapiro, "Learning globally consistent maps by relaxation",
   Proc. IEEE Int. Conf. on Robotics and Automation (ICRA), 3841-3846, 2000.
"""
from __future__ import annotations

import dataclasses
import json
import time
from typing import Any, Callable

import numpy as np

from robokit.config import fast_mode
from robocourse.source import code_version_of
from robokit.cache import CACHE_READ_ERRORS, cache_dir, cache_key, read_arrays, write_arrays
from robokit.files import write_atomically
from robokit.geometry import se2_between, se2_compose
from robokit.localization.hierarchical import HierarchicalLocalizer
from robokit.mapping import (PoseGraphResult, RelaxationResult, TopologicalMap, build_topological_map,
                       optimize_pose_graph, relax)
from robokit.progress import progress_bar
from robokit.sim import OmniCamera, describe_sensor, office_floor, office_tour, record_stream
from robokit.sim.world import World
from robokit.validation import as_points, as_rng, as_callable, as_choice, as_int, as_positive

__all__ = ["OfficeSetup", "office_setup", "as_setup", "localization_trials",
           "LocalizationTrials", "route_recognition"]

MODES = ("coarse", "fine", "hierarchical")
#: Odometry noise of the tour (Thrun et al. 2005, Table 5.6 alphas), the builder assumes the same.
TOUR_ALPHAS = (0.005, 0.0005, 0.005, 0.0005)


@dataclasses.dataclass
class OfficeSetup:
    """The recorded tour's topological map and the two alignments of it.

    Attributes
    ----------
    world, camera : World, OmniCamera
    n_frames : int
        Omni frames recorded along the tour.
    n_features : int
        SIFT features per image the map was built with (queries use the same).
    raw : TopologicalMap
        The map as built: nodes at their odometry poses.
    relaxed, optimized : TopologicalMap
        The same map after relaxation (the paper's Eqs. (1)-(3)) and after least squares.
    relaxation : RelaxationResult
    least_squares : PoseGraphResult
    truth : numpy.ndarray, shape (N, 3)
        True poses of the nodes (the tour's pose at each node's frame).
    build_seconds : float
        Time it took to record the tour and build the map (stored with the cached map).
    key : str
        Identifies the recording, the map and the code that made them (keys later caches).
    """

    world: World
    camera: OmniCamera
    n_frames: int
    n_features: int
    raw: TopologicalMap
    relaxed: TopologicalMap
    optimized: TopologicalMap
    relaxation: RelaxationResult
    least_squares: PoseGraphResult
    truth: np.ndarray
    build_seconds: float
    key: str


def _map_cached(meta: dict, build: Callable[[], tuple[TopologicalMap, np.ndarray, int]]
                ) -> tuple[TopologicalMap, np.ndarray, int, float, str]:
    """The map (with its nodes' true poses and the frame count) cached under ``meta``, or built.

    The recording itself is not needed once the map exists, so a cached map never loads the
    tour's images (hundreds of megabytes at full size)."""
    key = cache_key(**meta)
    target = cache_dir("maps") / f"office-{key}.npz"
    sidecar = target.with_suffix(".json")
    if target.exists() and sidecar.exists():
        try:
            stored = json.loads(sidecar.read_text())
            if stored.get("meta") == json.loads(json.dumps(meta)):
                tmap = TopologicalMap.load(target)
                truth = np.array(stored["truth"], float).reshape(len(tmap), 3)
                return tmap, truth, int(stored["frames"]), float(stored["seconds"]), key
        except CACHE_READ_ERRORS:
            pass  # a corrupt or foreign cache file is rebuilt
    t0 = time.perf_counter()
    tmap, truth, frames = build()
    seconds = time.perf_counter() - t0
    tmap.save(target)                        # atomic, as the sidecar below
    write_atomically(sidecar, lambda path: path.write_text(
        json.dumps({"meta": meta, "seconds": seconds, "frames": frames, "truth": truth.tolist()})))
    return tmap, truth, frames, seconds, key


def office_setup(*, fast: bool | None = None, progress: Callable | None = None) -> OfficeSetup:
    """Record the office tour with an omni camera, build its topological map and align it.

    Parameters
    ----------
    fast : bool, optional
        Smaller images and a sparser recording (default: :func:`robokit.config.fast_mode`).
    progress : callable ``(done, total)``, optional
        Told about the map building (only when it is not cached).

    Returns
    -------
    OfficeSetup

    Raises
    ------
    TypeError
        For a non-callable ``progress``.

    Notes
    -----
    Sec. "Experimental results" (Fig. 6a: the tour; Fig. 8: the map) and Sec. "Environment map"
    (key images, local-map partitioning, loop closure, Eqs. (1)-(3)). The paper records 640 x 480
    colour images; fast mode uses 320 x 240. The tour's frames are rendered in worker processes
    while the map is built from them (:func:`robokit.sim.record_stream`): a plain script needs the
    ``if __name__ == "__main__":`` guard.

    Examples
    --------
    The fast setup (320 x 240 images; the first call records and builds for about half a minute,
    later calls load the cache):

    >>> setup = office_setup(fast=True)
    >>> len(setup.raw) > 20, setup.truth.shape == setup.raw.poses.shape
    (True, True)
    """
    fast = fast_mode() if fast is None else bool(fast)
    progress = as_callable(progress, "progress")
    world = office_floor()
    camera = OmniCamera(width=320, height=240, face_size=200) if fast else OmniCamera()
    rate = 0.7 if fast else 1.0
    tour = office_tour(world)
    params = {"n_features": 300 if fast else 500, "alphas": list(TOUR_ALPHAS)}
    meta = {"world": world.name, "world_seed": world.info["seed"], "camera": describe_sensor(camera),
            "tour": cache_key(poses=tour.poses.round(9).tolist()), "rate": rate, "record_seed": 2, "params": params,
            "code": code_version_of(__name__)}

    def build():
        # the map is cached (below), so the recording is not stored at all: its images are used as the
        # workers render them, the map being built meanwhile
        with record_stream(world, tour, camera, rate=rate, odometry_alphas=TOUR_ALPHAS, seed=2) as run:
            tmap = build_topological_map(run.frames, run.odometry, camera, n_features=params["n_features"],
                                         odometry_alphas=TOUR_ALPHAS, progress=progress)
        return tmap, run.poses[tmap.frames], len(run)

    raw, truth, frames, seconds, key = _map_cached(meta, build)
    graph = raw.graph()
    relaxation = relax(graph)
    least_squares = optimize_pose_graph(graph)
    return OfficeSetup(world, camera, frames, params["n_features"], raw,
                       raw.with_poses(relaxation.poses, relaxation.variances), raw.with_poses(least_squares.poses),
                       relaxation, least_squares, truth, seconds, key)


def as_setup(setup: Any) -> OfficeSetup:
    """``setup`` if it is an :class:`OfficeSetup`, else a TypeError naming it."""
    if not isinstance(setup, OfficeSetup):
        raise TypeError(f"setup: expected an OfficeSetup from office_setup(), got {type(setup).__name__}")
    return setup


@dataclasses.dataclass
class LocalizationTrials:
    """Results of :func:`localization_trials`, one row per test place.

    Attributes
    ----------
    places : numpy.ndarray (n, 3)
        True poses.
    estimates : dict of str to numpy.ndarray (n, 3)
        Per mode, the estimated poses (map frame).
    errors : dict of str to numpy.ndarray (n, 2)
        Per mode, ``|x error|`` and ``|y error|`` (m) against the truth: the map's error plus the
        localizer's.
    local_errors : dict of str to numpy.ndarray (n, 2)
        Per mode, the same for the recognised node's *true* pose composed with the estimated
        relative pose: the localizer's own error, without the map's.
    times : dict of str to dict of str to numpy.ndarray (n,)
        Per mode, seconds per stage (``histogram``, ``sift``, ``coarse``, ``matching``,
        ``verification``, ``total``).
    results : dict of str to list of Localization
    """

    places: np.ndarray
    estimates: dict
    errors: dict
    local_errors: dict
    times: dict
    results: dict


def _render(setup: OfficeSetup, pose: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    return setup.camera.observe(setup.world, pose, rng=rng).image


def localization_trials(setup: OfficeSetup, places: Any, *, modes: tuple = MODES, map: str = "relaxed",
                        rng: Any = 0, progress: Callable | None = None) -> LocalizationTrials:
    """Localize an omni image rendered at each place, with each mode of the localizer.

    Parameters
    ----------
    setup : OfficeSetup
    places : array_like, shape (n, 3)
        True poses (e.g. :data:`robokit.sim.OFFICE_TEST_POSES`, the paper's 11 cases of Fig. 8).
    modes : tuple of str, default ("coarse", "fine", "hierarchical")
    map : {"relaxed", "optimized", "raw"}, default "relaxed"
        Which alignment of the map to localize in.
    rng : Generator or int, default 0
        Seeds the rendering noise (the same image for every mode).
    progress : callable ``(done, total)``, optional

    Returns
    -------
    LocalizationTrials

    Raises
    ------
    TypeError, ValueError
        For a bad setup, places, mode or map name.

    Notes
    -----
    Sec. "Hierarchical localization" (Fig. 5) and "Experimental results" (Fig. 9: errors in x and
    y; Fig. 11: the modes compared in error and time).

    Examples
    --------
    >>> from robokit.sim import OFFICE_TEST_POSES
    >>> trials = localization_trials(office_setup(fast=True), OFFICE_TEST_POSES[:2], modes=("coarse",))
    >>> trials.errors["coarse"].shape, sorted(trials.times["coarse"])[:2]
    ((2, 2), ['coarse', 'histogram'])
    """
    setup = as_setup(setup)
    P = as_points(places, "places", 3, min_count=1)
    if not isinstance(modes, tuple) or not modes:
        raise TypeError(f"modes: expected a non-empty tuple of {MODES}, got {modes!r}")
    modes = tuple(as_choice(m, "modes", MODES) for m in modes)
    tmap = getattr(setup, as_choice(map, "map", ("relaxed", "optimized", "raw")))
    progress = as_callable(progress, "progress")
    rng = as_rng(rng)
    images = [_render(setup, p, rng) for p in P]
    estimates, errors, local_errors, times, results = {}, {}, {}, {}, {}
    bar = progress_bar(len(modes) * len(images), "localizing", unit="view", callback=progress)
    for mode in modes:
        loc = HierarchicalLocalizer(tmap, setup.camera, mode=mode, n_features=setup.n_features)
        out = []
        for img in images:
            out.append(loc.localize(img))
            bar.update()
        results[mode] = out
        estimates[mode] = np.array([r.pose for r in out])
        errors[mode] = np.abs(estimates[mode][:, :2] - P[:, :2])
        local = np.array([se2_compose(setup.truth[r.node], se2_between(r.node_pose, r.pose)) for r in out])
        local_errors[mode] = np.abs(local[:, :2] - P[:, :2])
        times[mode] = {stage: np.array([r.times[stage] for r in out]) for stage in out[0].times}
    bar.close()
    return LocalizationTrials(P, estimates, errors, local_errors, times, results)


def route_recognition(setup: OfficeSetup, n_nodes: int = 17, *, offset: float = 0.15, same_place: float = 0.5,
                      rng: Any = 1) -> dict:
    """Which node is the robot at? Asked at ``n_nodes`` key nodes spread along the route (Fig. 12).

    A query is rendered ``offset`` metres from each chosen node's true position, at a random
    heading; it counts as recognised when the localizer's node is the chosen node or another node
    whose true position is within ``same_place`` metres (the tour passes some places twice).

    Parameters
    ----------
    setup : OfficeSetup
    n_nodes : int, default 17
    offset, same_place : float
        Metres.
    rng : Generator or int, default 1

    Returns
    -------
    dict
        ``nodes`` (chosen node indices), ``answers`` (recognised node per query), ``correct`` (bool
        per query), ``match_counts`` (best count per query), ``features`` (query SIFT features),
        ``rate`` (fraction correct).

    Raises
    ------
    TypeError, ValueError
        For a bad setup or parameters.

    Notes
    -----
    Sec. "Experimental results", Fig. 12: 17 key nodes; failures "mostly" at nodes with very few
    features or very ambiguous ones.

    Examples
    --------
    >>> route = route_recognition(office_setup(fast=True), 3)
    >>> len(route["nodes"]), 0.0 <= route["rate"] <= 1.0
    (3, True)
    """
    setup = as_setup(setup)
    n_nodes = as_int(n_nodes, "n_nodes", minimum=1, maximum=len(setup.raw))
    offset = as_positive(offset, "offset", allow_zero=True)
    same_place = as_positive(same_place, "same_place")
    target = meta = None
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):   # a seed: the answer is deterministic
        meta = {"setup": setup.key, "n_nodes": n_nodes, "offset": offset, "same_place": same_place, "rng": int(rng),
                "code": code_version_of(__name__)}
        target = cache_dir("maps") / f"route-{cache_key(**meta)}.npz"
        data = read_arrays(target, _ROUTE_ARRAYS, meta)
        if data is not None:
            return {**data, "rate": float(data["correct"].mean())}
    rng = as_rng(rng)
    nodes = np.linspace(0, len(setup.raw) - 1, n_nodes).round().astype(int)
    loc = HierarchicalLocalizer(setup.relaxed, setup.camera, n_features=setup.n_features)
    answers, correct, counts, features = [], [], [], []
    for i in nodes:
        x, y, _ = setup.truth[i]
        a = rng.uniform(-np.pi, np.pi)
        pose = np.array([x + offset * np.cos(a), y + offset * np.sin(a), rng.uniform(-np.pi, np.pi)])
        if not setup.world.is_free(pose[None, :2], clearance=0.2)[0]:
            pose[:2] = [x, y]
        r = loc.localize(_render(setup, pose, rng))
        answers.append(r.node)
        near = np.hypot(*(setup.truth[r.node, :2] - setup.truth[i, :2])) <= same_place
        correct.append(bool(r.recognised and (r.node == i or near)))
        counts.append(int(r.match_counts.max()) if len(r.match_counts) else 0)
        features.append(int(len(setup.relaxed.node_features(i))))
    out = {"nodes": nodes, "answers": np.array(answers, int), "correct": np.array(correct, bool),
           "match_counts": np.array(counts, int), "features": np.array(features, int)}
    if target is not None:
        write_arrays(target, out, meta)
    return {**out, "rate": float(out["correct"].mean())}


#: The arrays of :func:`route_recognition`'s cache file.
_ROUTE_ARRAYS = ("nodes", "answers", "correct", "match_counts", "features")
