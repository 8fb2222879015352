"""Lesson 04's terrain experiment: LittleDog walks over step boards blind, with a map, and with the map MoCap located.

The LittleDog program's robots walked over terrain boards that the Vicon MoCap system located by the
markers on them, as it located the robot (LittleDog User Guide, Sec. 1). :func:`terrain_table` asks
what that knowledge is worth. Over seeded random courses of step boards
(:func:`robokit.legged.terrain.step_terrain`, 1-4 cm: up to a third of the guide's 12 cm ground
clearance, Sec. 3), each laid down up to 5 cm and 0.1 rad away from its nominal place, the
lesson's crawl and trot walk 1 m (0.3 m in fast mode) in up to six ways:

* ``blind`` - the flat plan, on the boards;
* ``reacting`` - the flat plan under a reactive host (:class:`robokit.legged.PostureFeedback` at the
  lesson's first gain, :data:`~robocourse.lessons.littledog.experiment.HOST_GAINS`), which levels
  the trunk from what the MoCap sees but knows nothing of the boards;
* ``unlocated`` - planned on the boards' map at their nominal place: the shapes known, not where
  they lie;
* ``mocap`` - planned on the map placed where the MoCap sees its markers (one second of frames
  with the lesson's marker noise, :func:`robokit.legged.terrain.locate_terrain`);
* ``true`` - planned on the map where the boards truly are;
* ``mocap+reacting`` - the MoCap-located map and the reactive host together.

A walk succeeds when the robot does not fall and ends within :data:`SUCCESS_TOLERANCE` (10 %) of
the planned distance: the flat walks end within 5 % (the crawl creeps 5 cm ahead over 1 m, the
trot 6 mm short), so 10 % is twice the flat error, while a stumble that costs a few steps, or a
walk stuck against a riser, falls outside it.

The trials are independent and run in worker processes (:func:`robokit.parallel.map_runs`); the
table is cached, keyed by its parameters and the code it uses.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Secs. 1 and 3.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import mujoco
import numpy as np

from robocourse import FAST
from robocourse.source import code_version_of
from robokit.cache import cache_dir, cache_key, read_arrays, write_arrays
from robokit.geometry import wrap_angle
from robokit.legged.gait import walking_plan
from robokit.legged.gait_schedule import crawl_gait, trot_gait
from robokit.legged.leg_kinematics import UnreachableFootError
from robokit.legged.mocap import simulate_mocap
from robokit.legged.posture import PostureFeedback
from robokit.legged.simulation import SensorSettings, simulate_walk
from robokit.legged.terrain import locate_terrain, step_terrain, terrain_transform
from robokit.parallel import map_runs
from robokit.validation import as_array, as_callable, as_int, as_positive

from .experiment import HOST_GAINS, LESSON_CRAWL, LESSON_DISTANCE, LESSON_TROT

__all__ = ["TERRAIN_TRIALS", "TERRAIN_MODES", "TABLE_MODES", "TERRAIN_GAITS", "PLACEMENT", "SUCCESS_TOLERANCE", "MOCAP_FRAMES",
           "terrain_table"]

TERRAIN_TRIALS = 2 if FAST else 10
"""Random courses per row of the table: 10 (2 in fast mode)."""
TERRAIN_MODES = ("blind", "reacting", "unlocated", "mocap", "true", "mocap+reacting")
"""What a plan can know of the terrain (the module docstring says each)."""
TABLE_MODES = ("blind", "mocap", "true")
"""The modes the table walks by default, the three the issue asks for; add ``unlocated`` to see what the
MoCap adds, at a third more walks (the default table takes 29 s of one core's time)."""
TERRAIN_GAITS = ("crawl", "trot")
"""The lesson's two gaits (:data:`~robocourse.lessons.littledog.experiment.LESSON_CRAWL`, ``LESSON_TROT``)."""
PLACEMENT = (0.05, 0.05, 0.1)
"""How far a course lies from its nominal place: x, y (m) and yaw (rad), each uniform in +-these."""
SUCCESS_TOLERANCE = 0.1
"""A walk succeeds within this fraction of the planned distance (and without a fall)."""
MOCAP_FRAMES = 100
"""MoCap frames (one second at 100 Hz) the terrain is located from before the walk."""

_ARRAYS = ("distance", "fell", "walked", "tilt_deg", "located_mm", "located_deg", "flat_distance", "flat_fell",
           "flat_tilt_deg")


def _gait(name: str):
    return crawl_gait(**LESSON_CRAWL) if name == "crawl" else trot_gait(**LESSON_TROT)


def _course(seed: int, k: int, heights: tuple):
    """Course ``k``: its map at the nominal place, the same boards where they truly lie, and the map
    the MoCap locates (the true placement and the MoCap's noise drawn from the course's own seed)."""
    gen = np.random.default_rng([seed, k])
    nominal = step_terrain(gen, heights=heights)
    true = dataclasses.replace(nominal, pose=tuple(gen.uniform(-1.0, 1.0, 3) * PLACEMENT))
    sensors = SensorSettings()
    frames = simulate_mocap(np.repeat(terrain_transform(true)[None], MOCAP_FRAMES, axis=0), np.array(true.markers),
                            sensors.mocap_noise, sensors.mocap_dropout, gen, bursts=sensors.mocap_bursts,
                            burst_length=sensors.mocap_burst_length)
    return nominal, true, locate_terrain(nominal, frames.positions, frames.visible)


def _tilt_deg(out) -> float:
    """The largest angle (deg) between the trunk's up axis and the vertical over a trial."""
    up_z = out.log.T_world_body()[:, 2, 2]
    return float(np.degrees(np.arccos(np.clip(up_z, -1.0, 1.0))).max())


def _trial(shared: tuple, task: tuple) -> tuple:
    """One walk: ``(distance, fell, walked, tilt_deg)``; a plan asking for feet out of reach is not
    walked. Mode ``"flat"``: the flat plan on flat ground."""
    distance, heights, seed = shared
    k, gait, mode = task
    nominal, true, located = _course(seed, k, heights)
    known = {"flat": None, "blind": None, "reacting": None, "unlocated": nominal, "mocap": located, "true": true,
             "mocap+reacting": located}[mode]
    host = PostureFeedback(gain=HOST_GAINS[0]) if mode.endswith("reacting") else None
    plan = walking_plan(_gait(gait), distance, terrain=known)
    try:
        out = simulate_walk(plan, terrain=None if mode == "flat" else true, host=host, rng=seed)
    except UnreachableFootError:    # the host refuses a plan whose feet are out of reach
        return 0.0, False, False, float("nan")
    return out.distance, out.fell, True, _tilt_deg(out)


def _located_errors(seed: int, trials: int, heights: tuple) -> tuple[np.ndarray, np.ndarray]:
    """How far the MoCap's placement of each course is from the truth: (mm, deg)."""
    mm, deg = np.zeros(trials), np.zeros(trials)
    for k in range(trials):
        _, true, located = _course(seed, k, heights)
        mm[k] = 1000 * np.hypot(*np.subtract(located.pose[:2], true.pose[:2]))
        deg[k] = abs(np.degrees(wrap_angle(located.pose[2] - true.pose[2])))
    return mm, deg


def _run(trials: int, distance: float, heights: tuple, seed: int, gaits: tuple, modes: tuple, workers: Any,
         progress: Any) -> dict:
    shared = (distance, heights, seed)
    tasks = [(k, g, m) for g in gaits for m in modes for k in range(trials)] + [(0, g, "flat") for g in gaits]
    out = map_runs(_trial, shared, tasks, workers=workers, desc="terrain walks", unit="walk", progress=progress)
    out, flat = out[:-len(gaits)], out[-len(gaits):]
    shape = (len(gaits), len(modes), trials)
    cols = [np.array([o[i] for o in out]).reshape(shape) for i in range(4)]
    mm, deg = _located_errors(seed, trials, heights)
    return {"distance": cols[0], "fell": cols[1].astype(bool), "walked": cols[2].astype(bool), "tilt_deg": cols[3],
            "located_mm": mm, "located_deg": deg, "flat_distance": np.array([f[0] for f in flat]),
            "flat_fell": np.array([f[1] for f in flat]), "flat_tilt_deg": np.array([f[3] for f in flat])}


def _rows(data: dict, gaits: tuple, modes: tuple, distance: float) -> list:
    rows = []
    for i, gait in enumerate(gaits):
        rows.append({"gait": gait, "mode": "flat ground", "trials": 1, "successes": int(_succeeded(
            data["flat_distance"][i], data["flat_fell"][i], True, distance)), "falls": int(data["flat_fell"][i]),
            "unwalked": 0, "mean_distance": float(data["flat_distance"][i]),
            "mean_tilt_deg": float(data["flat_tilt_deg"][i])})
        for j, mode in enumerate(modes):
            d, fell, walked = data["distance"][i, j], data["fell"][i, j], data["walked"][i, j]
            ok = _succeeded(d, fell, walked, distance)
            rows.append({"gait": gait, "mode": mode, "trials": len(d), "successes": int(ok.sum()),
                         "falls": int(fell.sum()), "unwalked": int((~walked).sum()), "mean_distance": float(d.mean()),
                         "mean_tilt_deg": float(np.nanmean(data["tilt_deg"][i, j])) if walked.any() else float("nan")})
    for row in rows:
        row["success_rate"] = row["successes"] / row["trials"]
    return rows


def _succeeded(d: Any, fell: Any, walked: Any, distance: float) -> np.ndarray:
    return np.asarray(walked) & ~np.asarray(fell) & (np.abs(np.asarray(d) - distance) <= SUCCESS_TOLERANCE * distance)


def terrain_table(trials: int = TERRAIN_TRIALS, *, distance: float = LESSON_DISTANCE, heights: Any = (0.01, 0.04),
                  gaits: Any = TERRAIN_GAITS, modes: Any = TABLE_MODES, seed: int = 0, workers: Any = None,
                  progress: Any = None) -> dict:
    """The lesson's gaits over random step boards, blind and with the terrain known three ways.

    Parameters
    ----------
    trials : int, default :data:`TERRAIN_TRIALS`
        Random courses (1 to 1000); every gait and mode walks the same ones.
    distance : float, default :data:`~robocourse.lessons.littledog.experiment.LESSON_DISTANCE`
        Metres each walk plans (0.05 to 3).
    heights : (float, float), default (0.01, 0.04)
        Lowest and tallest board (m; :func:`robokit.legged.terrain.step_terrain`).
    gaits : sequence of str, default :data:`TERRAIN_GAITS`
        Some of ``"crawl"``, ``"trot"``.
    modes : sequence of str, default :data:`TABLE_MODES`
        Some of :data:`TERRAIN_MODES`: ``"blind"``, ``"reacting"``, ``"unlocated"``, ``"mocap"``,
        ``"true"``, ``"mocap+reacting"``.
    seed : int, default 0
        Seeds the courses, their placement, the MoCap's noise and every walk.
    workers : int, optional
        Worker processes (:func:`robokit.parallel.map_runs`).
    progress : callable, optional
        ``progress(done, total)`` as walks finish.

    Returns
    -------
    dict
        ``rows``: one dict per gait on flat ground (one walk) and per gait and mode, with ``gait``,
        ``mode``, ``trials``, ``successes``, ``success_rate``, ``falls``, ``unwalked`` (plans the
        host refused: feet out of reach), ``mean_distance`` (m) and ``mean_tilt_deg`` (the
        trunk's largest tilt in a walk, averaged); the per-walk arrays ``distance``, ``fell``,
        ``walked``, ``tilt_deg`` (gait x mode x trial); ``located_mm`` and ``located_deg`` (how far
        the MoCap's placement of each course is from the truth); ``gaits``, ``modes``,
        ``distance_planned``, ``heights`` and ``success_tolerance``.

    Raises
    ------
    ValueError, TypeError
        For values outside the ranges above or an unknown gait or mode.

    Examples
    --------
    >>> table = terrain_table(1, distance=0.1, gaits=("crawl",), modes=("blind", "true"), workers=1)
    >>> [(r["mode"], r["trials"]) for r in table["rows"]]
    [('flat ground', 1), ('blind', 1), ('true', 1)]
    >>> bool(table["located_mm"][0] < 1.0)                  # the MoCap places the boards within a millimetre
    True
    """
    trials = as_int(trials, "trials", minimum=1, maximum=1000)
    distance = as_positive(distance, "distance")
    if not 0.05 <= distance <= 3.0:
        raise ValueError(f"distance: expected 0.05 to 3 m, got {distance}")
    lo, hi = (float(h) for h in as_array(heights, "heights", shape=(2,)))
    step_terrain(0, heights=(lo, hi))              # refuses bad heights by name before any walk
    gaits, modes = _names(gaits, "gaits", TERRAIN_GAITS), _names(modes, "modes", TERRAIN_MODES)
    seed = as_int(seed, "seed", minimum=0)
    workers = None if workers is None else as_int(workers, "workers", minimum=1, maximum=64)
    progress = as_callable(progress, "progress")
    meta = {"trials": trials, "distance": distance, "heights": [lo, hi], "gaits": list(gaits), "modes": list(modes),
            "seed": seed, "code": code_version_of(__name__), "mujoco": mujoco.__version__}
    target = cache_dir("littledog") / f"terrain-{cache_key(**meta)}.npz"
    data = read_arrays(target, _ARRAYS, meta)
    if data is None:
        data = _run(trials, distance, (lo, hi), seed, gaits, modes, workers, progress)
        write_arrays(target, data, meta)
    return {"rows": _rows(data, gaits, modes, distance), **{k: data[k] for k in _ARRAYS}, "gaits": gaits,
            "modes": modes, "distance_planned": distance, "heights": (lo, hi), "success_tolerance": SUCCESS_TOLERANCE}


def _names(value: Any, name: str, allowed: tuple) -> tuple:
    want = f"a non-empty sequence of distinct names from {list(allowed)}"
    if isinstance(value, (str, bytes)) or not isinstance(value, (tuple, list)):
        raise TypeError(f"{name}: expected {want}, got {type(value).__name__}")
    if not value or any(not isinstance(v, str) or v not in allowed for v in value) or len(set(value)) != len(value):
        raise ValueError(f"{name}: expected {want}, got {list(value)!r}")
    return tuple(value)
