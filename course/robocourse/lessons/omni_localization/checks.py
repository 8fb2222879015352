"""Lesson 02's coarse-to-fine checks measured: more candidates when unverified, Monte-Carlo when in doubt.

Li et al. (2011), Sec. "Hierarchical localization", Fig. 5: the coarse stage passes a few candidates
to the fine stage; "if the localization result is still ambiguous, epipolar geometry constraints and
Monte-Carlo localization strategy are employed to verify the result". Two checks follow that text:

- the *widening* check of :class:`robokit.localization.HierarchicalLocalizer` (``max_rounds``): a
  fine stage that finds no verified metric pose among its ``top_k`` candidates takes the next ``top_k``;
- the *Monte-Carlo* check (:func:`robokit.localization.appearance_mcl.monte_carlo_check`): the robot
  drives on about a metre and image-based MCL decides between the candidates' places.

:func:`query_places` draws query places near the recorded tour, as the lesson's 11 cases lie; :func:`check_trials` localizes each with and without the checks and records which stage decided.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] E. Menegatti, M. Zoccarato, E. Pagello and H. Ishiguro, "Image-based Monte Carlo localisation
   with omnidirectional images", *Robotics and Autonomous Systems* 48(1), 17-30, 2004.
"""
from __future__ import annotations

import dataclasses
import time
from typing import Any, Callable

import numpy as np

from robocourse.lessons.omni_localization.experiment import TOUR_ALPHAS, OfficeSetup, as_setup
from robocourse.source import code_version_of
from robokit.cache import cache_dir, cache_key, read_arrays, write_arrays
from robokit.geometry import wrap_angle
from robokit.localization import HierarchicalLocalizer
from robokit.localization.appearance_mcl import monte_carlo_check
from robokit.mapping.omni_views import HISTOGRAM_STEP
from robokit.parallel import map_runs
from robokit.sim import noisy_odometry
from robokit.validation import as_array, as_callable, as_choice, as_int, as_points, as_positive, as_rng
from robokit.vision import histogram_distance, hue_histogram, hue_mask

__all__ = ["query_places", "drive_on", "CheckTrials", "WAYS", "check_trials", "mask_trials"]


def query_places(setup: OfficeSetup, n: int, *, near: float = 1.0, clearance: float = 0.4, rng: Any = 0) -> np.ndarray:
    """``n`` random query poses in free space within ``near`` metres of a map node, random headings.

    Parameters
    ----------
    setup : OfficeSetup
    n : int
        How many (1 to 1000).
    near, clearance : float, default 1.0, 0.4
        Metres: at most this far from the nearest node's true position; at least this far from walls.
    rng : Generator or int, default 0

    Returns
    -------
    numpy.ndarray, shape (n, 3)

    Raises
    ------
    TypeError, ValueError
        For a bad setup or parameter, or when no such place is found in 100 n draws.

    Notes
    -----
    Li et al. (2011), Sec. "Experimental results": 11 test locations (Fig. 8); more of them, drawn
    like the lesson's, make the mean error of Fig. 9 less of a matter of luck.

    Examples
    --------
    >>> from robocourse.lessons.omni_localization.experiment import office_setup
    >>> query_places(office_setup(fast=True), 3).shape
    (3, 3)
    """
    setup = as_setup(setup)
    n = as_int(n, "n", minimum=1, maximum=1000)
    near, clearance = as_positive(near, "near"), as_positive(clearance, "clearance", allow_zero=True)
    g = as_rng(rng)
    x0, y0, x1, y1 = setup.world.bounds
    out = []
    for _ in range(100 * n):
        p = np.array([g.uniform(x0, x1), g.uniform(y0, y1), g.uniform(-np.pi, np.pi)])
        if (setup.world.is_free(p[None, :2], clearance=clearance)[0]
                and np.hypot(*(setup.truth[:, :2] - p[:2]).T).min() <= near):
            out.append(p)
            if len(out) == n:
                return np.array(out)
    raise ValueError(f"n, near, clearance: found only {len(out)} places within {near} m of a node and {clearance} m "
                     f"of walls in {100 * n} draws, expected {n}")


def drive_on(setup: OfficeSetup, start: Any, *, length: float = 1.0, step: float = 0.25,
             clearance: float = 0.3) -> np.ndarray:
    """True poses of a short drive from ``start``: straight ahead, or after a turn if ahead is blocked.

    The robot tries its heading, then left, behind and right (quarter turns on the spot); it takes
    the first direction whose ``length`` metres stay ``clearance`` from walls, or, when none does,
    the one that stays free longest, shortened to what is free. Returns ``[start, pose after step,
    ...]``, shape (K + 1, 3).

    Raises
    ------
    TypeError, ValueError
        For a bad setup, start, length or step.

    Notes
    -----
    The drive of the Monte-Carlo check (Li et al. 2011, Sec. "Hierarchical localization"; image-based
    Monte-Carlo localization as Menegatti et al. 2004 run it on a moving robot).

    Examples
    --------
    >>> from robocourse.lessons.omni_localization.experiment import office_setup
    >>> drive_on(office_setup(fast=True), [12.0, 2.5, 0.0]).shape
    (5, 3)
    """
    setup = as_setup(setup)
    start = as_array(start, "start", shape=(3,))
    length, step = as_positive(length, "length"), as_positive(step, "step")
    clearance = as_positive(clearance, "clearance", allow_zero=True)
    if length > 100:
        raise ValueError(f"length: expected at most 100 m, got {length}")
    if step > length or length / step > 1000:
        raise ValueError(f"step: expected at most length ({length}) and at least length / 1000, got {step}")
    s = np.arange(1, int(np.floor(length / step + 1e-9)) + 1) * step
    best = None
    for turn in (0.0, np.pi / 2, np.pi, -np.pi / 2):
        th = float(wrap_angle(start[2] + turn))
        pts = start[:2] + s[:, None] * [np.cos(th), np.sin(th)]
        free = setup.world.is_free(pts, clearance=clearance)
        reach = int(np.argmin(free)) if not free.all() else len(s)
        if best is None or reach > best[1]:
            best = (th, reach, pts)
        if reach == len(s):
            break
    th, reach, pts = best
    reach = max(reach, 1)
    poses = np.column_stack([pts[:reach], np.full(reach, th)])
    return np.vstack([start, poses])


@dataclasses.dataclass
class CheckTrials:
    """What :func:`check_trials` measured, one row per place.

    Attributes
    ----------
    places : numpy.ndarray (n, 3)
    errors : dict of str to numpy.ndarray (n, 2)
        Signed error ``[x, y]`` (m, estimate minus truth) of ``"top_k"`` (the plain hierarchy), ``"widened"`` (with the widening
        check), ``"monte_carlo"`` (the widened answer, or the Monte-Carlo check's where the widened
        answer was ambiguous or had no metric pose) and ``"fine"`` (every node matched).
    rounds : numpy.ndarray of int (n,)
        Batches of candidates the widened search matched.
    doubtful : numpy.ndarray of bool (n,)
        The widened answer was ambiguous or had no metric pose: the Monte-Carlo check ran.
    overturned : numpy.ndarray of bool (n,)
        The Monte-Carlo check chose another place than the widened answer's.
    seconds : dict of str to numpy.ndarray (n,)
        Query time of each way (the Monte-Carlo check's: the widened query plus the check, which
        localizes the first image again for its hypotheses).
    """

    places: np.ndarray
    errors: dict
    rounds: np.ndarray
    doubtful: np.ndarray
    overturned: np.ndarray
    seconds: dict

    @property
    def distances(self) -> dict:
        """Position error (m) of each way, shape (n,)."""
        return {w: np.hypot(e[:, 0], e[:, 1]) for w, e in self.errors.items()}


WAYS = ("top_k", "widened", "monte_carlo", "fine")
_FIELDS = ("places", "rounds", "doubtful", "overturned") + tuple(f"{kind}_{w}" for kind in ("errors", "seconds")
                                                                  for w in WAYS)


def _check_place(shared: tuple, task: tuple) -> tuple:
    """One place, four ways (a worker's run): seeded by ``(seed, index)``."""
    setup, map_name, length, step, seed = shared
    i, p = task
    g = np.random.default_rng([seed, i])
    tmap = getattr(setup, map_name)
    kw = {"n_features": setup.n_features}
    locs = {"top_k": HierarchicalLocalizer(tmap, setup.camera, max_rounds=1, **kw),
            "widened": HierarchicalLocalizer(tmap, setup.camera, **kw),
            "fine": HierarchicalLocalizer(tmap, setup.camera, mode="fine", **kw)}
    image = setup.camera.observe(setup.world, p, rng=g).image
    err, sec, answers = {}, {}, {}
    for name, loc in locs.items():
        t0 = time.perf_counter()
        answers[name] = loc.localize(image)
        sec[name] = time.perf_counter() - t0
        err[name] = answers[name].pose[:2] - p[:2]
    answer = answers["widened"]
    doubtful = bool(answer.ambiguous or not answer.metric)
    err["monte_carlo"], sec["monte_carlo"], overturned = err["widened"], sec["widened"], False
    if doubtful:
        truth = drive_on(setup, p, length=length, step=step)
        odometry = noisy_odometry(truth, TOUR_ALPHAS, g)
        images = [setup.camera.observe(setup.world, q, rng=g).image for q in truth[1:]]
        t0 = time.perf_counter()
        check = monte_carlo_check(locs["widened"], image, images, odometry, alphas=TOUR_ALPHAS, rng=g)
        sec["monte_carlo"] += time.perf_counter() - t0
        err["monte_carlo"], overturned = check.pose[:2] - p[:2], not check.confirmed
    return answer.rounds, doubtful, overturned, err, sec


def check_trials(setup: OfficeSetup, places: Any, *, map: str = "relaxed", length: float = 1.0, step: float = 0.25,
                 seed: int = 0, cache: bool = True, workers: int | None = None,
                 progress: Callable | None = None) -> CheckTrials:
    """Localize an omni image at each place four ways: top-k, widened, with the Monte-Carlo check, fine.

    Parameters
    ----------
    setup : OfficeSetup
    places : array_like, shape (n, 3)
    map : {"relaxed", "optimized", "raw"}, default "relaxed"
    length, step : float, default 1.0, 0.25
        The Monte-Carlo check's drive (:func:`drive_on`).
    seed : int, default 0
        Place ``i`` is seeded by ``(seed, i)``: rendering noise, odometry noise and particles.
    cache : bool, default True
        Load from / save to ``cache_dir("maps")``, keyed by the map, the places, the parameters and
        the code (the times are those of the run that made the file).
    workers : int, optional
        Worker processes (:func:`robokit.parallel.map_runs`; a plain script needs the
        ``if __name__ == "__main__":`` guard).
    progress : callable ``(done, total)``, optional

    Returns
    -------
    CheckTrials

    Raises
    ------
    TypeError, ValueError
        For a bad setup, places or parameter.

    Notes
    -----
    Li et al. (2011), Sec. "Hierarchical localization" and Fig. 5 (module docstring).

    Examples
    --------
    >>> from robocourse.lessons.omni_localization.experiment import office_setup
    >>> trials = check_trials(office_setup(fast=True), [[12.0, 2.5, 0.3]], cache=False, workers=1)
    >>> sorted(trials.errors), trials.errors["fine"].shape, bool(trials.rounds[0] >= 1)
    (['fine', 'monte_carlo', 'top_k', 'widened'], (1, 2), True)
    """
    setup = as_setup(setup)
    P = as_points(places, "places", 3, min_count=1)
    map = as_choice(map, "map", ("relaxed", "optimized", "raw"))
    length, step = as_positive(length, "length"), as_positive(step, "step")
    seed = as_int(seed, "seed", minimum=0)
    progress = as_callable(progress, "progress")
    meta = {"setup": setup.key, "map": map, "places": cache_key(places=P.round(9).tolist()), "length": length,
            "step": step, "seed": seed, "code": code_version_of(__name__)}
    target = cache_dir("maps") / f"checks-{cache_key(**meta)}.npz"
    if cache:
        data = read_arrays(target, _FIELDS, meta)
        if data is not None:
            return CheckTrials(data["places"], {w: data[f"errors_{w}"] for w in WAYS}, data["rounds"],
                               data["doubtful"], data["overturned"], {w: data[f"seconds_{w}"] for w in WAYS})
    out = map_runs(_check_place, (setup, map, length, step, seed), list(enumerate(P)), workers=workers,
                   desc="checks", unit="place", progress=progress)
    trials = CheckTrials(P, {w: np.array([o[3][w] for o in out]).reshape(-1, 2) for w in WAYS}, np.array([o[0] for o in out], int),
                         np.array([o[1] for o in out], bool), np.array([o[2] for o in out], bool),
                         {w: np.array([o[4][w] for o in out]) for w in WAYS})
    if cache:
        write_arrays(target, {"places": P, "rounds": trials.rounds, "doubtful": trials.doubtful,
                              "overturned": trials.overturned,
                              **{f"errors_{w}": trials.errors[w] for w in WAYS},
                              **{f"seconds_{w}": trials.seconds[w] for w in WAYS}}, meta)
    return trials


def mask_trials(setup: OfficeSetup, places: Any, thresholds: Any, *, bins: int = 32, gain: float = 0.7,
                noise: float = 2.0, rng: Any = 0) -> dict:
    """The coarse stage's pixel mask tried: pixels kept and nearest-node retrieval per saturation threshold.

    Every node's key image is rendered again at the node's true pose and every query at its place,
    as lit in the map, darker (``gain``) and with pixel noise (``noise``); per threshold the hue histograms of Eq. (5) are
    computed over the pixels :func:`robokit.vision.hue_mask` keeps, and each query's nodes ranked.

    Parameters
    ----------
    setup : OfficeSetup
    places : array_like, shape (n, 3)
        Query poses.
    thresholds : array_like, shape (m,)
        ``min_saturation`` values in [0, 1].
    bins : int, default 32
    gain : float, default 0.7
        The darker queries' lighting (``robokit.sim.textures.illuminate``).
    noise : float, default 2.0
        The noisy queries' Gaussian pixel noise (grey levels, standard deviation).
    rng : Generator or int, default 0
        Rendering noise.

    Returns
    -------
    dict
        ``kept`` (m,): mean share of the image's pixels that count; ``top1``, ``top5`` (m,): share of
        queries whose nearest node (by true position) ranks first / in the first five;
        ``top1_darker``, ``top5_darker``, ``top1_noisy``, ``top5_noisy`` (m,): the same for the darker
        and for the noisy queries.

    Raises
    ------
    TypeError, ValueError
        For a bad setup, places, threshold or gain.

    Notes
    -----
    Li et al. (2011), Sec. "Global image features" (the H plane's 1-D histogram, Eq. (5)); which
    pixels have a meaningful hue is our choice (:data:`robokit.vision.colour.MIN_SATURATION`).

    Examples
    --------
    >>> from robocourse.lessons.omni_localization.experiment import office_setup
    >>> out = mask_trials(office_setup(fast=True), [[12.0, 2.5, 0.3]], [0.15])
    >>> sorted(out), out["kept"].shape
    (['kept', 'top1', 'top1_darker', 'top1_noisy', 'top5', 'top5_darker', 'top5_noisy'], (1,))
    """
    setup = as_setup(setup)
    P = as_points(places, "places", 3, min_count=1)
    ts = as_array(thresholds, "thresholds", ndim=1)
    if not len(ts) or not np.all((ts >= 0) & (ts <= 1)):
        raise ValueError(f"thresholds: expected saturation thresholds in [0, 1], got {thresholds!r}")
    bins = as_int(bins, "bins", minimum=1)
    gain = as_positive(gain, "gain")
    noise = as_positive(noise, "noise", allow_zero=True)
    if noise > 100:
        raise ValueError(f"noise: expected at most 100 grey levels, got {noise}")
    g = as_rng(rng)
    step = HISTOGRAM_STEP

    def view(pose, lighting=None, sigma=0.0):
        return setup.camera.observe(setup.world, pose, rng=g, lighting=lighting, noise=sigma).image[::step, ::step]

    nodes = [view(p) for p in setup.truth]
    lit = [view(p) for p in P]
    dark = [view(p, {"gain": gain}) for p in P]
    noisy = [view(p, sigma=noise) for p in P]
    nearest = np.array([np.argmin(np.hypot(*(setup.truth[:, :2] - p[:2]).T)) for p in P])
    out = {k: np.zeros(len(ts)) for k in ("kept", "top1", "top5", "top1_darker", "top5_darker", "top1_noisy",
                                          "top5_noisy")}
    for k, t in enumerate(ts):
        H = np.array([hue_histogram(im, bins, min_saturation=t) for im in nodes])
        out["kept"][k] = np.mean([hue_mask(im, min_saturation=t).mean() for im in lit])
        for suffix, queries in (("", lit), ("_darker", dark), ("_noisy", noisy)):
            ranks = np.array([int(np.flatnonzero(np.argsort(histogram_distance(hue_histogram(q, bins, min_saturation=t),
                                                                               H), kind="stable") == n)[0])
                              for q, n in zip(queries, nearest)])
            out["top1" + suffix][k], out["top5" + suffix][k] = np.mean(ranks == 0), np.mean(ranks < 5)
    return out
