"""Lesson 03 on a real map: the same AMCL from a uniform start in a real building and in the corridor.

Ge et al. (2023), Sec. 1: a particle filter on a LiDAR grid map localizes a robot where the
geometry is salient, and fails in repeated, symmetrical or similar structures such as a long
corridor. This module puts that claim to the test on real data. The map is the occupancy grid of
the Willow Garage office building that the ROS navigation tutorials serve with ``map_server``
(shipped in ``robocourse/data/maps``, BSD licence, source named in its README); the robot is
simulated on it (the map's occupied cells are its walls, :meth:`robokit.sim.Layout.from_cells`,
scanned by the lesson's RPLIDAR-like LiDAR), so that map has no error at all, while the corridor's
is a 5 cm grid built from noisy scans: a difference that favours the building in the strictest
judgement. Both places get the same filter: ROS amcl's defaults,
its default ``max_particles`` of 5000 (ten times Table 2's 500, so that a cloud spread over a whole
building section still puts particles near the truth) and the robot's own odometry noise.

- :func:`willow_section` reads the map with the course's map_server reader and cuts a part of it:
  :data:`SECTIONS` names two, the rooms (a large room, smaller rooms, a corridor) and the same with
  the row of five offices of one size and layout below them.
- :func:`building_routes` draws drives through a map's free space (shortest paths that keep away
  from walls, between random places).
- :func:`global_localization_runs` runs the filter from a uniform cloud along each drive and
  records amcl's published pose (the mean of the heaviest cluster) against the truth.
- :func:`real_map_comparison` makes the runs in each section and in the corridor, cached like the
  lesson's other datasets.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [3] E. W. Dijkstra, "A note on two problems in connexion with graphs", *Numerische Mathematik* 1,
   269-271, 1959.
"""
from __future__ import annotations

import dataclasses
import hashlib
import inspect
from importlib import resources
from typing import Any, Callable

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse import csgraph

from robocourse.lessons.corridor_localization.experiment import (MAPPING_ALPHAS, CorridorMap, as_corridor_map,
                                                                 corridor_lidar)
from robocourse.lessons.corridor_localization.trials import (AMCL_SETTINGS, RATE, RIGHT_PLACE, SPEED, amcl_localizer,
                                                             as_tolerance, middle_line_drive)
from robocourse.source import code_version_of
from robokit.cache import cache_dir, cache_key, read_arrays, write_arrays
from robokit.config import fast_mode
from robokit.geometry import wrap_angle
from robokit.localization import largest_cluster_mean
from robokit.mapping import OccupancyGrid, likelihood_field, load_map
from robokit.parallel import map_runs
from robokit.sim import Layout, noisy_odometry, waypoint_path
from robokit.validation import as_array, as_callable, as_choice, as_int, as_positive, as_rng

__all__ = ["SECTIONS", "AMCL_PARTICLES", "RUNS", "DRIVE_LENGTH", "willow_map", "willow_section", "building_routes",
           "GlobalRuns", "global_localization_runs", "global_localization_batch", "real_map_comparison"]

#: The parts of the Willow Garage map the lesson localizes in, ``(x0, y0, x1, y1)`` in the map's metres:
#: the rooms, and the rooms with the row of look-alike offices below them.
SECTIONS = {"rooms": (2.0, 10.0, 22.0, 24.0), "rooms and offices": (2.0, 4.0, 22.0, 24.0)}
#: amcl's default ``max_particles`` (its ``min_particles`` 100 is the KLD floor).
AMCL_PARTICLES = 5000
#: Drives per place and metres per drive: (full size, fast mode).
RUNS, DRIVE_LENGTH = (10, 4), (15.0, 10.0)
#: Keep this far from walls when planning drives (the Kobuki's radius plus a margin, metres).
CLEARANCE = 0.35


def willow_map() -> OccupancyGrid:
    """The Willow Garage office map of the ROS navigation tutorials, read as map_server reads it.

    Returns
    -------
    robokit.mapping.OccupancyGrid
        584 x 526 cells of 0.1 m (58.4 m x 52.6 m), origin at (0, 0).

    Notes
    -----
    ``robocourse/data/maps/willow-full.{pgm,yaml}``; source and licence in that folder's README.
    Read with :func:`robokit.mapping.load_map` (map_server's format and thresholds).

    Examples
    --------
    >>> willow_map().shape
    (526, 584)
    """
    with resources.as_file(resources.files("robocourse") / "data" / "maps" / "willow-full.yaml") as path:
        return load_map(path)


def willow_section(name: str = "rooms") -> OccupancyGrid:
    """A part of :func:`willow_map` the lesson localizes in (:data:`SECTIONS`).

    Parameters
    ----------
    name : {"rooms", "rooms and offices"}, default "rooms"

    Returns
    -------
    robokit.mapping.OccupancyGrid

    Raises
    ------
    ValueError, TypeError
        For an unknown name.

    Examples
    --------
    >>> section = willow_section()
    >>> section.shape, section.bounds
    ((140, 200), (2.0, 10.0, 22.0, 24.0))
    """
    return willow_map().crop(SECTIONS[as_choice(name, "name", list(SECTIONS))])


def _free_graph(grid: OccupancyGrid, clearance: float) -> tuple[sparse.csr_matrix, np.ndarray, np.ndarray]:
    """The 8-connected graph of free cells at least ``clearance`` from anything not free (or off the grid).

    Edge costs are lengths weighted by ``1 + 1 / distance to the nearest wall``, so shortest paths
    keep to the middle of corridors. Returns the graph, each node's cell ``(i, j)`` and its clearance.
    """
    # beyond the grid's edge counts as a wall: the simulated LiDAR sees nothing there
    d = ndimage.distance_transform_edt(np.pad(grid.free_mask(), 1))[1:-1, 1:-1] * grid.resolution
    ok = d >= clearance
    index = np.full(ok.shape, -1)
    index[ok] = np.arange(int(ok.sum()))
    cost = 1.0 + 1.0 / np.maximum(d, grid.resolution)
    rows, cols = ok.shape
    a_idx, b_idx, weight = [], [], []
    for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
        a = (slice(0, rows - di), slice(max(0, -dj), cols - max(0, dj)))
        b = (slice(di, rows), slice(max(0, dj), cols + min(0, dj)))
        both = ok[a] & ok[b]
        a_idx.append(index[a][both])
        b_idx.append(index[b][both])
        weight.append(np.hypot(di, dj) * grid.resolution * 0.5 * (cost[a][both] + cost[b][both]))
    i, j, w = np.concatenate(a_idx), np.concatenate(b_idx), np.concatenate(weight)
    n = int(ok.sum())
    graph = sparse.csr_matrix((np.concatenate([w, w]), (np.concatenate([i, j]), np.concatenate([j, i]))), shape=(n, n))
    return graph, np.argwhere(ok), d[ok]


def _route_from(graph: sparse.csr_matrix, xy: np.ndarray, s: int, length: float,
                rng: np.random.Generator) -> np.ndarray | None:
    """A drive of ``length`` metres from node ``s`` towards a random far node (up to 20 tried), or None."""
    dist, pred = csgraph.dijkstra(graph, indices=s, return_predecessors=True)
    far = np.flatnonzero(np.isfinite(dist) & (dist >= length))      # cost >= length: a candidate
    for node in rng.permutation(far)[:20]:
        path = [int(node)]
        while path[-1] != s:
            path.append(int(pred[path[-1]]))
        points = xy[path[::-1]]
        points = np.vstack([points[::5], points[-1:]])               # every fifth cell, and the goal
        steps = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
        if steps[-1] >= length:
            cut = int(np.searchsorted(steps, length))
            share = (length - steps[cut - 1]) / (steps[cut] - steps[cut - 1])
            return np.vstack([points[:cut], points[cut - 1] + share * (points[cut] - points[cut - 1])])
    return None


def building_routes(grid: OccupancyGrid, n: int, length: float, rng: Any = 0, *,
                    clearance: float = CLEARANCE) -> list[np.ndarray]:
    """``n`` drives of ``length`` metres through a map's free space, between random places.

    Parameters
    ----------
    grid : robokit.mapping.OccupancyGrid
    n : int
        Number of drives (1 to 1000).
    length : float
        Metres each drive covers (the path is cut there).
    rng : Generator or int, default 0
    clearance : float, default 0.35
        Minimum distance from anything not free (m).

    Returns
    -------
    list of numpy.ndarray, each (K, 2)
        Waypoints: a start at least ``2 clearance`` from walls, in the largest connected free area,
        then the shortest wall-weighted path towards a random place far enough away, cut where it
        has covered ``length``. The path's cells keep ``clearance``; the straight legs between every
        fifth cell may cut a corner by a few centimetres.

    Raises
    ------
    TypeError, ValueError
        For a bad grid or parameter, or a map with no place ``length`` metres from another.

    Notes
    -----
    Dijkstra (1959) on the 8-connected free cells, each step's cost its length times
    ``1 + 1 / d`` with ``d`` the cell's distance to the nearest wall (a remote-controlled robot keeps
    to the middle of a corridor).

    Examples
    --------
    >>> routes = building_routes(willow_section(), 2, 8.0, rng=0)
    >>> len(routes), [bool(7.9 < np.hypot(*np.diff(r, axis=0).T).sum() < 8.2) for r in routes]
    (2, [True, True])
    """
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(f"grid: expected a robokit.mapping.OccupancyGrid, got {type(grid).__name__}")
    n = as_int(n, "n", minimum=1, maximum=1000)
    length = as_positive(length, "length")
    clearance = as_positive(clearance, "clearance")
    rng = as_rng(rng)
    graph, cells, room = _free_graph(grid, clearance)
    if len(cells) == 0:
        raise ValueError(f"clearance: expected free space {clearance} m from walls, found none")
    _, label = csgraph.connected_components(graph, directed=False)
    starts = np.flatnonzero((label == np.argmax(np.bincount(label))) & (room >= 2 * clearance))
    if len(starts) == 0:
        raise ValueError(f"clearance: expected a place {2 * clearance} m from walls to start from, found none")
    xy = (cells[:, ::-1] + 0.5) * grid.resolution + grid.origin
    routes = []
    for _ in range(n):
        for s in rng.permutation(starts)[:10]:            # a few starts before giving up
            route = _route_from(graph, xy, int(s), length, rng)
            if route is not None:
                routes.append(route)
                break
        else:
            raise ValueError(f"length: found no drive of {length} m in the free space from 10 starts")
    return routes


@dataclasses.dataclass
class GlobalRuns:
    """Global localizations from a uniform cloud along given drives.

    Attributes
    ----------
    estimates, truth : numpy.ndarray, shape (n, K, 3)
        amcl's published pose (the mean of the heaviest cluster) and the true pose after each filter
        update (NaN after a run's last update).
    travelled : numpy.ndarray, shape (n, K)
        Metres driven at each update (NaN after the last).
    particles : numpy.ndarray, shape (n, K)
        Particles the filter held after each update (KLD-sampling shrinks the cloud).
    """

    estimates: np.ndarray
    truth: np.ndarray
    travelled: np.ndarray
    particles: np.ndarray

    @property
    def errors(self) -> np.ndarray:
        """Position (m) and heading (rad) error after each update, shape (n, K, 2)."""
        d = self.estimates - self.truth
        out = np.full(d.shape[:-1] + (2,), np.nan)
        done = np.isfinite(d).all(axis=-1)            # updates that happened (the rest is padding)
        out[done] = np.column_stack([np.hypot(d[done, 0], d[done, 1]), np.abs(wrap_angle(d[done, 2]))])
        return out

    def last(self) -> np.ndarray:
        """Index of each run's last update, shape (n,)."""
        return np.sum(np.isfinite(self.travelled), axis=1) - 1

    def right_place(self, tolerance: Any = RIGHT_PLACE) -> np.ndarray:
        """Whether each run's last published pose is within ``tolerance`` = (m, rad) of the truth.

        Examples
        --------
        >>> truth = np.zeros((2, 1, 3))
        >>> runs = GlobalRuns(np.array([[[0.1, 0.0, 0.01]], [[3.0, 0.0, 0.01]]]), truth, np.ones((2, 1)), np.ones((2, 1)))
        >>> runs.right_place().tolist()
        [True, False]
        """
        tol = as_tolerance(tolerance)
        last = self.final_errors()
        return (last[:, 0] <= tol[0]) & (last[:, 1] <= tol[1])

    def final_errors(self) -> np.ndarray:
        """Each run's error after its last update, shape (n, 2)."""
        return self.errors[np.arange(len(self.travelled)), self.last()]

    def localized_after(self, tolerance: Any = RIGHT_PLACE) -> np.ndarray:
        """Metres driven until the published pose came within ``tolerance`` and stayed (NaN: never).

        Examples
        --------
        >>> estimates = np.array([[[2.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.2, 0.0, 0.0]]])
        >>> runs = GlobalRuns(estimates, np.zeros((1, 3, 3)), np.array([[0.0, 0.5, 1.0]]), np.ones((1, 3)))
        >>> runs.localized_after().tolist()
        [0.5]
        """
        tol = as_tolerance(tolerance)
        out = np.full(len(self.errors), np.nan)
        for r, (err, dist) in enumerate(zip(self.errors, self.travelled)):
            valid = np.isfinite(err[:, 0])
            bad = ~((err[valid, 0] <= tol[0]) & (err[valid, 1] <= tol[1]))
            if len(bad) and not bad[-1]:
                last_bad = np.flatnonzero(bad)
                out[r] = dist[valid][last_bad[-1] + 1 if len(last_bad) else 0]
        return out


def _one_run(shared: tuple, task: tuple) -> tuple[np.ndarray, ...]:
    """One drive ``truth`` of group ``g`` with a filter from a uniform cloud; seeded by ``(seed, run)``."""
    g, run, truth = task
    grid, field, walls, particles, settings, seed = shared[g]
    rng = np.random.default_rng([seed, run])
    lidar = corridor_lidar()
    odometry = noisy_odometry(truth, MAPPING_ALPHAS, rng)
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(truth[:, :2], axis=0).T))])
    mcl = amcl_localizer(grid, field, lidar, settings, particles, rng)
    mcl.initialize_uniform()
    estimates, seen, dist, held = [], [], [], []
    for k in range(len(truth)):
        if k > 0 and not mcl.due(odometry[k]):
            continue
        if not mcl.update(odometry[k], lidar.scan_layout(walls, truth[k], rng)):
            continue
        estimates.append(largest_cluster_mean(mcl.particles, mcl.weights))
        seen.append(truth[k])
        dist.append(travelled[k])
        held.append(len(mcl.particles))
    return (np.array(estimates).reshape(-1, 3), np.array(seen).reshape(-1, 3), np.array(dist, float),
            np.array(held, float))


def global_localization_runs(grid: OccupancyGrid, walls: Layout, drives: list, *, particles: int = AMCL_PARTICLES,
                             settings: str = "defaults", seed: int = 0, workers: int | None = None,
                             progress: Callable | None = None) -> GlobalRuns:
    """amcl's global localization along each drive: a uniform cloud, then the filter as the robot moves.

    Parameters
    ----------
    grid : robokit.mapping.OccupancyGrid
        The map the filter localizes in (its free cells receive the uniform cloud).
    walls : robokit.sim.Layout
        What the simulated LiDAR sees (the map's own outline, or a world's walls).
    drives : list of array_like, each (K, 3)
        True poses at 10 Hz (:func:`robokit.sim.waypoint_path`), one drive per run.
    particles : int, default 5000
        amcl's ``max_particles`` (KLD-sampling may shrink the cloud to the settings' ``min_particles``).
    settings : {"defaults", "turtlebot2"}, default "defaults"
        amcl's settings (:data:`~robocourse.lessons.corridor_localization.trials.AMCL_SETTINGS`).
    seed : int, default 0
        Run ``r`` is seeded by ``(seed, r)`` (odometry noise, scans, filter).
    workers : int, optional
        Worker processes (:func:`robokit.parallel.map_runs`).
    progress : callable ``(done, total)``, optional

    Returns
    -------
    GlobalRuns

    Raises
    ------
    TypeError, ValueError
        For a bad map, layout, drive or parameter.

    Notes
    -----
    Thrun et al. (2005), Table 8.2 (MCL) and Sec. 8.3.7 (KLD-sampling), as ROS amcl runs them
    (:class:`robokit.localization.MonteCarloLocalizer`); Ge et al. (2023), Sec. 4.1 start AMCL the
    same way ("scattered particles evenly on the whole map"). :func:`global_localization_batch` makes
    the runs of several maps or settings side by side.

    Examples
    --------
    >>> section = willow_section()
    >>> walls = Layout.from_cells(section.occupied_mask(), section.resolution, section.origin)
    >>> drive = waypoint_path(building_routes(section, 1, 3.0, rng=1)[0], 0.3).poses
    >>> runs = global_localization_runs(section, walls, [drive], particles=300, workers=1)
    >>> runs.errors.shape[0], bool(np.nanmax(runs.particles) <= 300)
    (1, True)
    """
    group = _as_group(grid, walls, drives, particles, settings, seed)
    return _run_groups([group], workers, as_callable(progress, "progress"))[0]


def global_localization_batch(groups: list, *, workers: int | None = None,
                              progress: Callable | None = None) -> list[GlobalRuns]:
    """:func:`global_localization_runs` for several maps or settings at once: all their runs in one pool.

    Parameters
    ----------
    groups : list of dict
        Each the keyword arguments of one :func:`global_localization_runs` call: ``grid``, ``walls``
        and ``drives``, optionally ``particles``, ``settings`` and ``seed``.
    workers : int, optional
        Worker processes (:func:`robokit.parallel.map_runs`).
    progress : callable ``(done, total)``, optional
        Told as runs finish, over all the groups.

    Returns
    -------
    list of GlobalRuns
        One per group, equal to its :func:`global_localization_runs` (each run is seeded by its own
        group's ``(seed, run)``, whatever runs beside it).

    Raises
    ------
    TypeError, ValueError
        For a bad list, or a group :func:`global_localization_runs` would refuse (named by its index).

    Notes
    -----
    Thrun et al. (2005), Table 8.2 and Sec. 8.3.7, as :func:`global_localization_runs`. One pool
    keeps both cores busy to the end where a call per map would wait for its slowest run each time.

    Examples
    --------
    >>> section = willow_section()
    >>> walls = Layout.from_cells(section.occupied_mask(), section.resolution, section.origin)
    >>> drive = waypoint_path(building_routes(section, 1, 3.0, rng=1)[0], 0.3).poses
    >>> two = global_localization_batch([dict(grid=section, walls=walls, drives=[drive], particles=300),
    ...                                  dict(grid=section, walls=walls, drives=[drive], particles=400, seed=1)],
    ...                                 workers=1)
    >>> len(two), two[0].errors.shape[0]
    (2, 1)
    """
    if not isinstance(groups, (list, tuple)):
        raise TypeError(f"groups: expected a list of dicts of global_localization_runs' arguments, "
                        f"got {type(groups).__name__}")
    if not groups:
        raise ValueError("groups: expected at least one group of runs, got an empty list")
    params = {n: p for n, p in inspect.signature(_as_group).parameters.items() if p.kind is not p.KEYWORD_ONLY}
    required = {n for n, p in params.items() if p.default is p.empty}
    checked, fields = [], {}              # one likelihood field per grid, however many groups share it
    for i, group in enumerate(groups):
        if not isinstance(group, dict):
            raise TypeError(f"groups[{i}]: expected a dict of global_localization_runs' arguments, "
                            f"got {type(group).__name__}")
        unknown, missing = sorted(set(group) - set(params), key=repr), sorted(required - set(group))
        if unknown or missing:
            got = "; ".join(([f"unknown {unknown}"] if unknown else []) + ([f"no {missing}"] if missing else []))
            raise ValueError(f"groups[{i}]: expected the keys grid, walls, drives and optionally particles, settings, "
                             f"seed, got {got}")
        try:
            shared, truths = _as_group(**group, field=fields.get(id(group["grid"])))
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"groups[{i}]: {exc}") from None
        fields[id(group["grid"])] = shared[1]
        checked.append((shared, truths))
    names = [f"groups[{i}]: drives" for i in range(len(checked))]
    return _run_groups(checked, workers, as_callable(progress, "progress"), names)


def _as_group(grid: Any, walls: Any, drives: Any, particles: Any = AMCL_PARTICLES, settings: Any = "defaults",
              seed: Any = 0, *, field: Any = None) -> tuple:
    """One group of runs, checked: ``(grid, field, walls, particles, settings, seed)`` and the drives
    (``field``: the grid's likelihood field when another group already made it)."""
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(f"grid: expected a robokit.mapping.OccupancyGrid, got {type(grid).__name__}")
    if not isinstance(walls, Layout):
        raise TypeError(f"walls: expected a robokit.sim Layout, got {type(walls).__name__}")
    if not isinstance(drives, (list, tuple)) or not drives:
        raise ValueError(f"drives: expected a non-empty list of (K, 3) pose arrays, got {type(drives).__name__}")
    truths = [as_array(d, f"drives[{i}]", ndim=2) for i, d in enumerate(drives)]
    for i, t in enumerate(truths):
        if t.shape[1] != 3 or len(t) < 2:
            raise ValueError(f"drives[{i}]: expected at least two poses of shape (3,), got shape {t.shape}")
    settings = as_choice(settings, "settings", tuple(AMCL_SETTINGS))
    particles = as_int(particles, "particles", minimum=AMCL_SETTINGS[settings]["min_particles"], maximum=100_000)
    seed = as_int(seed, "seed", minimum=0)
    return (grid, likelihood_field(grid) if field is None else field, walls, particles, settings, seed), truths


def _run_groups(groups: list, workers: int | None, progress: Callable | None, names: list | None = None) -> list:
    """Every run of every checked group in one :func:`robokit.parallel.map_runs`; the results per group
    (``names``: how an error names each group's drives)."""
    tasks = [(g, run, truth) for g, (_, truths) in enumerate(groups) for run, truth in enumerate(truths)]
    out = map_runs(_one_run, tuple(shared for shared, _ in groups), tasks, workers=workers,
                   desc="global localization", unit="run", progress=progress)
    results, first = [], 0
    for g, (_, truths) in enumerate(groups):
        runs, first = out[first:first + len(truths)], first + len(truths)
        if min(len(run[2]) for run in runs) == 0:
            raise ValueError(f"{names[g] if names else 'drives'}: expected drives long enough for a filter update "
                             "(amcl's 0.2 m), got one shorter")
        results.append(GlobalRuns(*(_padded([run[k] for run in runs]) for k in range(4))))
    return results


def _padded(records: list) -> np.ndarray:
    """Runs' records of unequal length stacked, each padded with NaN to the longest."""
    width = max(len(r) for r in records)
    return np.array([np.concatenate([r, np.full((width - len(r),) + r.shape[1:], np.nan)]) for r in records])


def _corridor_drives(setup: CorridorMap, n: int, length: float, rng: np.random.Generator) -> list[np.ndarray]:
    """Drives along the corridor's middle line from random places, turning 0.8 m before an end."""
    L = setup.world.info["length"]
    drives = []
    for _ in range(n):
        start = np.array([rng.uniform(1.0, L - 1.0), 0.0, 0.0 if rng.random() < 0.5 else np.pi])
        drives.append(middle_line_drive(start, L, length))
    return drives


_FIELDS = ("estimates", "truth", "travelled", "particles")


def real_map_comparison(setup: CorridorMap, *, runs: int | None = None, length: float | None = None, seed: int = 0,
                        cache: bool = True, progress: Callable | None = None) -> dict[str, GlobalRuns]:
    """The same AMCL from a uniform start in each Willow section (:data:`SECTIONS`) and in the corridor.

    Parameters
    ----------
    setup : CorridorMap
        The corridor's map and world (:func:`~robocourse.lessons.corridor_localization.experiment.corridor_map`).
    runs : int, optional
        Drives per place (default :data:`RUNS`: 10; 4 in fast mode).
    length : float, optional
        Metres per drive (default :data:`DRIVE_LENGTH`: 15; 10 in fast mode).
    seed : int, default 0
    cache : bool, default True
        Load from / save to ``cache_dir("corridor")``, keyed by the parameters, the map and the code.
    progress : callable ``(done, total)``, optional

    Returns
    -------
    dict
        ``{section name: GlobalRuns, ..., "corridor": GlobalRuns}``.

    Raises
    ------
    TypeError, ValueError
        For a bad setup or parameter.

    Notes
    -----
    Ge et al. (2023), Sec. 1 (laser localization works where geometry is salient) and Sec. 4.1
    (AMCL from particles scattered evenly over the map).

    Examples
    --------
    >>> from robocourse.lessons.corridor_localization.experiment import corridor_map
    >>> places = real_map_comparison(corridor_map(fast=True), runs=1, length=2.0, cache=False)
    >>> list(places), places["rooms"].errors.shape[0]
    (['rooms', 'rooms and offices', 'corridor'], 1)
    """
    setup = as_corridor_map(setup)
    fast = fast_mode()
    runs = RUNS[fast] if runs is None else as_int(runs, "runs", minimum=1, maximum=100)
    length = DRIVE_LENGTH[fast] if length is None else as_positive(length, "length")
    if length > 100:
        raise ValueError(f"length: expected at most 100 m, got {length}")
    seed = as_int(seed, "seed", minimum=0)
    progress = as_callable(progress, "progress")
    willow = willow_map()                        # read once: both sections and the cache key come from it
    sections = {name: willow.crop(bounds) for name, bounds in SECTIONS.items()}
    places = list(SECTIONS) + ["corridor"]
    meta = {"setup": setup.key, "runs": runs, "length": length, "seed": seed, "sections": SECTIONS,
            "map": hashlib.sha256(willow.log_odds.tobytes()).hexdigest()[:16],
            "particles": AMCL_PARTICLES, "code": code_version_of(__name__)}
    target = cache_dir("corridor") / f"realmap-{cache_key(**meta)}.npz"
    names = {p: p.replace(" ", "_") for p in places}
    if cache:
        data = read_arrays(target, [f"{names[p]}_{f}" for p in places for f in _FIELDS], meta)
        if data is not None:
            return {p: GlobalRuns(*(data[f"{names[p]}_{f}"] for f in _FIELDS)) for p in places}
    rng = np.random.default_rng(seed)
    groups = []
    for k, section in enumerate(sections.values()):
        walls = Layout.from_cells(section.occupied_mask(), section.resolution, section.origin)
        drives = [waypoint_path(r, SPEED, rate=RATE).poses for r in building_routes(section, runs, length, rng)]
        groups.append(_as_group(section, walls, drives, seed=seed + k))
    groups.append(_as_group(setup.grid, setup.world.layout(setup.lidar.height),
                            _corridor_drives(setup, runs, length, rng), seed=seed + len(sections)))
    out = dict(zip(places, _run_groups(groups, None, progress)))
    if cache:
        write_arrays(target, {f"{names[p]}_{f}": getattr(r, f) for p, r in out.items() for f in _FIELDS}, meta)
    return out
