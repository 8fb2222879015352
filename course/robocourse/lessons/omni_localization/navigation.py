"""Lesson 02's navigation experiment: a visual path through the office map, the omni camera in the loop.

The paper's Fig. 13 re-run (Sec. "Visual-servoing for navigation"): the robot starts near a visual
path through consecutive nodes of the relaxed map, the omni camera renders an image at its true
pose once per ``fix_period``, the hierarchical localizer turns it into a fix, the EKF fuses the fixes
with odometry and Eq. (8) steers (:func:`robokit.navigation.follow_path`). Success is judged on the
truth: the robot's true final position against the goal node's true position, the place the paper's
robot must converge to.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] C. Canudas de Wit, H. Khennouf, C. Samson and O. J. Sordalen, "Nonlinear control design for
   mobile robots", in *Recent Trends in Mobile Robots*, World Scientific, 121-156, 1993.
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

from robocourse.source import code_version_of
from robokit.cache import (cache_dir, cache_key, read_arrays, record_names, records_from_arrays,
                     records_to_arrays, write_arrays)
from robokit.controllers.path_geometry import VisualPath, path_from_poses
from robokit.localization.hierarchical import HierarchicalLocalizer, Localization
from robokit.parallel import map_runs
from robokit.validation import as_array, as_rng, as_callable, as_choice, as_int, as_positive
from robocourse.lessons.omni_localization.experiment import OfficeSetup, as_setup
from robokit.navigation.visual_path import FollowResult, follow_path, perturbed_starts

__all__ = ["omni_localizer", "navigation_trials", "NavigationTrials"]


def omni_localizer(setup: OfficeSetup, *, noise: float = 1.0, map: str = "relaxed") -> Callable:
    """A ``localize(true_pose, rng)`` for :func:`robokit.navigation.follow_path`: the omni camera in the loop.

    It renders the omni image at the true pose (with ``noise`` grey levels of pixel noise),
    localizes it hierarchically, and returns the metric pose, or ``None`` when the image is not
    recognised.

    Parameters
    ----------
    setup : OfficeSetup
    noise : float, default 1.0
        Pixel noise of the rendered images (grey levels).
    map : {"relaxed", "optimized", "raw"}, default "relaxed"

    Returns
    -------
    callable
        ``localize(true_pose, rng) -> numpy.ndarray (3,) or None``; its ``calls`` and ``failures``
        attributes count the queries.

    Raises
    ------
    TypeError, ValueError
        For a bad setup, noise or map name.

    Notes
    -----
    Sec. "Visual-servoing for navigation": the robot recognises the most likely node and is
    steered along the visual path; the fixes feed the EKF.

    Examples
    --------
    >>> from robocourse.lessons.omni_localization.experiment import office_setup
    >>> setup = office_setup(fast=True)
    >>> localize = omni_localizer(setup)
    >>> fix = localize(setup.truth[3], np.random.default_rng(0))
    >>> bool(fix is None or np.hypot(*(fix[:2] - setup.truth[3, :2])) < 3.0), localize.calls
    (True, 1)
    """
    setup = as_setup(setup)
    noise = as_positive(noise, "noise", allow_zero=True)
    tmap = getattr(setup, as_choice(map, "map", ("relaxed", "optimized", "raw")))
    loc = HierarchicalLocalizer(tmap, setup.camera, n_features=setup.n_features)

    def localize(true_pose: np.ndarray, rng: np.random.Generator) -> np.ndarray | None:
        localize.calls += 1
        try:
            image = setup.camera.observe(setup.world, np.asarray(true_pose, float), noise=noise, rng=rng).image
        except ValueError:       # the (non-colliding) simulated robot drove into furniture: no view
            localize.failures += 1
            return None
        r: Localization = loc.localize(image)
        if not r.recognised:
            localize.failures += 1
            return None
        return r.pose

    localize.calls, localize.failures = 0, 0
    return localize


def _open_stretch(setup: OfficeSetup, count: int, clearance: float) -> int:
    """First node of ``count`` consecutive nodes whose smooth path keeps ``clearance`` from everything.

    The search starts a third of the way into the map: near the fixed first node the map is exact,
    which would hide the map's error from the experiment."""
    n = len(setup.relaxed) - count + 1
    for first in [(n // 3 + k) % n for k in range(n)]:
        poses = setup.relaxed.poses[first:first + count]
        if np.hypot(*(poses[-1, :2] - poses[0, :2])) < 1.0:
            continue
        try:   # the path in the map, and where it lies in truth (the map's error moves it)
            paths = [path_from_poses(poses), path_from_poses(setup.truth[first:first + count])]
        except ValueError:
            continue
        if all(setup.world.is_free(p.poses[:, :2], clearance=clearance).all() for p in paths):
            return first
    raise ValueError(f"n_path_nodes: no {count} consecutive nodes keep {clearance:.2f} m from walls and furniture")


@dataclasses.dataclass
class NavigationTrials:
    """Results of :func:`navigation_trials`.

    Attributes
    ----------
    path : VisualPath
        The visual path through the relaxed map's nodes (map frame).
    nodes : numpy.ndarray of int
        The map nodes it runs through; the last is the target.
    runs : list of FollowResult
        One per start (poses in the world frame; the estimates in the map's frame).
    goal_errors : numpy.ndarray, shape (n,)
        True distance (m) from each run's final position to the target node's *true* position.
    success : numpy.ndarray of bool, shape (n,)
        ``goal_errors <= success_radius``.
    success_radius : float
    """

    path: VisualPath
    nodes: np.ndarray
    runs: list
    goal_errors: np.ndarray
    success: np.ndarray
    success_radius: float


def navigation_trials(setup: OfficeSetup, n_starts: int, *, first_node: int | None = None, n_path_nodes: int = 5,
                      clearance: float = 0.3, fix_period: float = 1.0, alpha: float = 2.0, offset: float = 0.3, heading: float = 0.3,
                      max_time: float = 60.0, success_radius: float = 0.3, localize: Callable | None = None,
                      seed: int = 3, cache: bool = True, progress: Callable | None = None) -> NavigationTrials:
    """Follow the visual path through consecutive map nodes from ``n_starts`` perturbed starts (Fig. 13).

    Parameters
    ----------
    setup : OfficeSetup
    n_starts : int
    first_node : int, optional
        The path runs through the relaxed map's nodes ``first_node .. first_node + n_path_nodes - 1``;
        default: the first such stretch (searching from a third of the way into the map, away from
        the exactly known first node) at least 1 m long whose path keeps ``clearance + offset`` from
        walls and furniture (the simulated robot does not collide, it would drive through).
    n_path_nodes : int, default 5
    clearance : float, default 0.3
        Metres, see ``first_node``.
    fix_period : float, default 1.0
        Seconds between omni fixes (the EKF integrates odometry in between).
    alpha : float, default 2.0
        Natural frequency of the path-following law (1/m), Eq. (8).
    offset, heading : float
        Start perturbation: up to ``offset`` metres and ``heading`` radians from the path's start.
    max_time : float or None, default 60
        Seconds per run (``None``: :func:`follow_path`'s default, three times the path's length over
        the top speed plus 30 s).
    success_radius : float, default 0.3
        A run succeeds when it ends within this distance (m) of the target node's true position.
    localize : callable, optional
        Default :func:`omni_localizer` (the omni camera in the loop).
    seed : int, default 3
        Seeds the starts; run ``k`` draws its odometry noise and its localizer's (the default's pixel
        noise) from ``(seed, k)``, so the runs are independent: with the default localizer they are
        made side by side (:func:`robokit.parallel.map_runs`, ``ROBOKIT_WORKERS``; a plain script needs
        the ``if __name__ == "__main__":`` guard), a given ``localize`` is called here, in order.
    cache : bool, default True
        With the default localizer, load the runs from / save them to
        ``robokit.cache.cache_dir("navigation")``, keyed by every parameter, the map and the code (each
        run renders and localizes an omni image per fix: minutes at full size the first time).
    progress : callable ``(done, total)``, optional

    Returns
    -------
    NavigationTrials

    Raises
    ------
    TypeError, ValueError
        For a bad setup or parameters, or a node range outside the map.

    Notes
    -----
    Sec. "Visual-servoing for navigation" (Eqs. (6)-(8), the EKF) and Fig. 13.

    Examples
    --------
    With Gaussian fixes instead of the camera (fast):

    >>> from robokit.navigation.visual_path import gaussian_localizer
    >>> from robocourse.lessons.omni_localization.experiment import office_setup
    >>> trials = navigation_trials(office_setup(fast=True), 1, localize=gaussian_localizer(), cache=False)
    >>> len(trials.runs), trials.goal_errors.shape, trials.nodes.size
    (1, (1,), 5)
    """
    setup = as_setup(setup)
    n_starts = as_int(n_starts, "n_starts", minimum=1, maximum=1000)
    clearance = as_positive(clearance, "clearance", allow_zero=True)
    offset = as_positive(offset, "offset", allow_zero=True)
    radius = as_positive(success_radius, "success_radius")
    count = as_int(n_path_nodes, "n_path_nodes", minimum=2, maximum=len(setup.relaxed))
    if first_node is None:
        first = _open_stretch(setup, count, clearance + offset)
    else:
        first = as_int(first_node, "first_node", minimum=0, maximum=len(setup.relaxed) - count)
    progress = as_callable(progress, "progress")
    default_localizer = localize is None
    localize = None if default_localizer else as_callable(localize, "localize", optional=False)
    seed = as_int(seed, "seed", minimum=0)
    rng = as_rng(seed)
    path = path_from_poses(as_array(setup.relaxed.poses[first:first + count], "poses"))
    starts = perturbed_starts(path, n_starts, offset=offset, heading=heading, rng=rng)
    target = None
    if cache and default_localizer:
        meta = {"setup": setup.key, "first": first, "count": count, "fix_period": fix_period, "alpha": alpha,
                "offset": offset, "heading": heading, "max_time": max_time, "rng": seed, "n": n_starts,
                "code": code_version_of(__name__)}
        target = cache_dir("navigation") / f"office-{cache_key(**meta)}.npz"
        data = read_arrays(target, record_names(FollowResult, n_starts), meta)
        if data is not None:
            results = records_from_arrays(data, FollowResult, n_starts)
            return _judged(setup, path, first, count, results, radius)
    # each run seeded by its own number, so the runs are independent and made side by side (the
    # default localizer is built for each run, in its worker; a given one is called here, in order)
    follow = {"fix_period": fix_period, "alpha": alpha, "max_time": max_time}
    results = map_runs(_follow_from_start, (setup, path, localize, follow, seed),
                       list(enumerate(starts)), workers=None if default_localizer else 1,
                       desc="following the path", progress=progress)
    if target is not None:
        write_arrays(target, records_to_arrays(results, FollowResult), meta)
    return _judged(setup, path, first, count, results, radius)


def _follow_from_start(shared: tuple, task: tuple) -> FollowResult:
    """Run ``k`` of :func:`navigation_trials` from ``start`` (``task = (k, start)``), seeded by ``(seed, k)``."""
    setup, path, localize, follow, seed = shared
    k, start = task
    localize = omni_localizer(setup) if localize is None else localize
    return follow_path(path, start, localize=localize, rng=np.random.default_rng([seed, k]), **follow)


def _judged(setup: OfficeSetup, path: VisualPath, first: int, count: int, runs: list, radius: float
            ) -> NavigationTrials:
    goal = setup.truth[first + count - 1, :2]
    errors = np.array([np.hypot(*(r.true_poses[-1, :2] - goal)) for r in runs])
    return NavigationTrials(path, np.arange(first, first + count), runs, errors, errors <= radius, radius)
