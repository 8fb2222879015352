"""Lesson 03: AMCL from a uniform start against how repetitive the corridor is, under two amcl settings.

Ge et al. (2023), Table 2, report AMCL with 500 particles reaching the paper's 0.05 m / 0.5 degree
criterion in 47.3 % and 52.9 % of runs after 9.43 m and 12.27 m. They call their corridor one with
many symmetrical and similar areas (Sec. 4) and name two pairs of look-alike areas as examples (Sec.
4.2, Fig. 12); they do not list amcl's settings. In the lesson's plain corridor the doors stand every
4.5 m on each wall, with nothing else along the walls. This module asks how much each of two things moves
AMCL's result there: the corridor's repetitiveness, set by :func:`robokit.sim.long_corridor`'s
``clutter`` (the share of wall stretches with a cabinet of their own: our device, not the paper's,
which removed fire extinguishers and garbage cans from its corridor, Sec. 4), and amcl's settings
(:data:`~robocourse.lessons.corridor_localization.trials.AMCL_SETTINGS`: what ROS's TurtleBot 2
package sets for the Kobuki base of the paper's robot, whose ``min_particles`` is Table 2's 500, with
amcl's "diff" odometry model as shipped or its "diff-corrected" one; the lesson's Table 2 runs ROS's
defaults).

- :func:`~robocourse.lessons.corridor_localization.experiment.clutter_map` makes a corridor and the
  grid of its mapping run (laser only: AMCL needs no camera).
- :func:`clutter_comparison` runs the same drives, from Table 2's ten start poses
  (:data:`~robocourse.lessons.corridor_localization.trials.START_POSES`), with each setting in each
  corridor (:func:`~robocourse.lessons.corridor_localization.real_map.global_localization_batch`), and
  caches them like the lesson's other datasets.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from robocourse.lessons.corridor_localization.experiment import clutter_map, corridor_lidar
from robocourse.lessons.corridor_localization.real_map import GlobalRuns, global_localization_batch
from robocourse.lessons.corridor_localization.trials import AMCL_SETTINGS, START_POSES, middle_line_drive
from robocourse.source import code_version_of
from robokit.cache import cache_dir, cache_key, read_arrays, write_arrays
from robokit.config import fast_mode
from robokit.validation import as_array, as_callable, as_choice, as_int, as_positive

__all__ = ["SHARES", "SETTINGS", "RUNS", "DRIVE_LENGTH", "clutter_comparison"]

#: Clutter shares compared: (full size, fast mode).
SHARES = ((0.0, 0.5, 1.0), (0.0, 1.0))
#: The settings compared by default: TurtleBot 2's, with amcl's "diff" and "diff-corrected" odometry models
#: (Table 2 above runs ROS's defaults).
SETTINGS = ("turtlebot2", "turtlebot2-corrected")
#: Drives per start pose and metres per drive: (full size, fast mode); fast mode uses the first
#: three start poses.
RUNS, DRIVE_LENGTH = (2, 1), (20.0, 10.0)


_FIELDS = ("estimates", "truth", "travelled", "particles")


def clutter_comparison(*, shares: Any = None, settings: Any = SETTINGS, runs: int | None = None,
                       positions: Any = None, length: float | None = None, seed: int = 0, cache: bool = True,
                       progress: Callable | None = None) -> dict[str, dict[float, GlobalRuns]]:
    """AMCL from a uniform start along the same drives, per setting and clutter share.

    Parameters
    ----------
    shares : sequence of float, optional
        Clutter shares, different, each in [0, 1] (default :data:`SHARES`: 0, 0.5, 1; 0 and 1 in fast
        mode).
    settings : sequence of str, default :data:`SETTINGS`
        Names of ``AMCL_SETTINGS``, each run with its ``max_particles``.
    runs : int, optional
        Drives per start pose (default :data:`RUNS`: 2; 1 in fast mode).
    positions : sequence of int, optional
        Indices into Table 2's start poses (default all ten; the first three in fast mode).
    length : float, optional
        Metres per drive (default :data:`DRIVE_LENGTH`: 20; 10 in fast mode; at most 100).
    seed : int, default 0
        Drive ``r`` is seeded by ``(seed, r)`` in every corridor and setting, so they share the
        odometry noise, the scans' noise where the corridors agree, and the filters' draws.
    cache : bool, default True
        Load from / save to ``cache_dir("corridor")``, keyed by the parameters and the code.
    progress : callable ``(done, total)``, optional

    Returns
    -------
    dict
        ``{setting: {share: GlobalRuns}}``.

    Raises
    ------
    TypeError, ValueError
        For a bad share, setting or parameter.

    Notes
    -----
    Ge et al. (2023), Sec. 4.1 and Table 2 (AMCL from particles scattered over the whole map); the
    drives start at Table 2's ten poses and follow the middle line, turning 0.8 m before an end.

    Examples
    --------
    >>> out = clutter_comparison(shares=[0.0], settings=["defaults"], runs=1, positions=[0, 5], length=2.0,
    ...                          cache=False)
    >>> list(out), list(out["defaults"]), out["defaults"][0.0].errors.shape[0]
    (['defaults'], [0.0], 2)
    """
    fast = fast_mode()
    shares = SHARES[fast] if shares is None else as_array(shares, "shares", shape=(None,))
    if not len(shares) or np.any((np.asarray(shares) < 0) | (np.asarray(shares) > 1)):
        raise ValueError(f"shares: expected one or more clutter shares in [0, 1], got {list(shares)}")
    shares = [float(s) for s in shares]
    if len(set(shares)) < len(shares):
        raise ValueError(f"shares: expected different clutter shares, got {shares}")
    if isinstance(settings, str) or not hasattr(settings, "__iter__"):
        raise TypeError(f"settings: expected a sequence of names of AMCL_SETTINGS, got {type(settings).__name__}")
    settings = [as_choice(s, "settings", tuple(AMCL_SETTINGS)) for s in settings]
    if not settings:
        raise ValueError("settings: expected at least one name of AMCL_SETTINGS, got none")
    runs = RUNS[fast] if runs is None else as_int(runs, "runs", minimum=1, maximum=100)
    length = DRIVE_LENGTH[fast] if length is None else as_positive(length, "length")
    if length > 100:
        raise ValueError(f"length: expected at most 100 m, got {length}")
    if positions is None:
        positions = range(3 if fast else len(START_POSES))
    elif isinstance(positions, (str, bytes)) or not hasattr(positions, "__iter__"):
        raise TypeError(f"positions: expected a sequence of start indices, got {type(positions).__name__}")
    starts = [START_POSES[as_int(p, "positions", minimum=0, maximum=len(START_POSES) - 1)] for p in positions]
    if not starts:
        raise ValueError("positions: expected at least one start index, got none")
    seed = as_int(seed, "seed", minimum=0)
    progress = as_callable(progress, "progress")
    meta = {"shares": shares, "settings": settings, "runs": runs, "length": length,
            "seed": seed, "starts": [list(s) for s in starts], "amcl": AMCL_SETTINGS, "code": code_version_of(__name__)}
    target = cache_dir("corridor") / f"clutter-{cache_key(**meta)}.npz"
    names = [f"{name}_{k}_{f}" for name in settings for k in range(len(shares)) for f in _FIELDS]
    if cache:
        data = read_arrays(target, names, meta)
        if data is not None:
            return {name: {share: GlobalRuns(*(data[f"{name}_{k}_{f}"] for f in _FIELDS))
                           for k, share in enumerate(shares)} for name in settings}
    groups, keys = [], []
    for share in shares:
        world, grid = clutter_map(share)
        walls = world.layout(corridor_lidar().height)
        drives = [middle_line_drive(start, world.info["length"], length) for start in starts for _ in range(runs)]
        for name in settings:
            groups.append(dict(grid=grid, walls=walls, drives=drives, particles=AMCL_SETTINGS[name]["max_particles"],
                               settings=name, seed=seed))
            keys.append((name, share))
    out: dict[str, dict[float, GlobalRuns]] = {name: {} for name in settings}
    for (name, share), result in zip(keys, global_localization_batch(groups, progress=progress)):
        out[name][share] = result
    if cache:
        write_arrays(target, {f"{name}_{k}_{f}": getattr(out[name][share], f) for name in settings
                              for k, share in enumerate(shares) for f in _FIELDS}, meta)
    return out
