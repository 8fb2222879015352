"""Pre-simulated runs in lesson 03's corridor for assignment 03's loop exercise, as plain data.

A run is what a Monte-Carlo localizer sees on a short drive along :func:`robokit.sim.long_corridor`
(the lesson's corridor and laser, :func:`~.experiment.corridor_lidar`, with fewer beams): a start
cloud of particles around a wrong guess (as if image retrieval had picked a neighbouring keyframe),
the odometry increment and the scan of every filter update (one every 0.25 m, about ROS amcl's
0.2 m), the corridor's distance grid, and the random numbers the filter draws (the motion noise of
every particle and the one number of each low-variance resampling). The truth, the poses the scans
were taken at, stays with the grader.

A run is kept only if it is fair: the reference filter (:func:`track`) settles well inside the
tolerance (also when it reports the mean after resampling and with other noise draws), while dead
reckoning from the start cloud's mean and the particle the first scan likes best, dead-reckoned
(:func:`one_shot`), end well outside it. About one drive in six is kept: in the others either the
filter itself fails (the walls say little about the position along the corridor, the lesson's point)
or a filter is not needed to pass. The whole corridor's distance grid goes with every run, so the
grid's extent says nothing about where the drive is.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005 (Tables 4.3, 4.4, 5.6,
   6.3 and 8.2).
"""
from __future__ import annotations

import functools
from typing import Any

import numpy as np

from robocourse.lessons.corridor_localization.experiment import MAPPING_ALPHAS, corridor_lidar
from robokit.geometry import se2_between, se2_compose, wrap_angle
from robokit.localization.beam_models import likelihood_field_log_weights
from robokit.localization.particle_filter import low_variance_resample, normalise_log_weights, weighted_pose_mean
from robokit.mapping.occupancy_grid import LikelihoodField
from robokit.sim import noisy_odometry
from robokit.sim.lidar import Lidar
from robokit.sim.worlds import long_corridor
from robokit.validation import as_array

__all__ = ["RUN", "TOLERANCE", "SETTLED", "corridor_distance", "simulate_run", "track", "dead_reckoning",
           "track_errors", "one_shot"]

#: A run's size and noise: updates, particles, laser beams, metres driven per update, the filter's
#: motion noise per update (forward m, sideways m, turn rad), the start cloud's half-widths
#: (along m, across m, heading rad) and how far (m) its centre lies from the truth.
RUN = {"updates": 20, "particles": 100, "beams": 90, "step": 0.25, "motion_std": (0.05, 0.02, 0.03),
       "spread": (1.2, 0.3, 0.1), "offset": (0.5, 1.0), "resolution": 0.1}
#: A loop has converged when each of its last :data:`SETTLED` estimates is within this many metres
#: and radians of the truth.
TOLERANCE = (0.25, 0.1)
SETTLED = 5
#: How a run must separate a filter from dead reckoning to be kept (module docstring): the
#: reference's worst settled error at most ``FAIR[0]`` of the tolerance, dead reckoning's best at
#: least ``FAIR[1]`` times it.
FAIR = (0.5, 2.0)


@functools.lru_cache(maxsize=2)
def corridor_distance(resolution: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """The lesson corridor's distance grid: metres from each cell centre to the nearest wall, clipped at 2 m.

    Returns
    -------
    (distance, origin)
        ``distance`` (H, W); cell ``[i, j]`` covers ``origin + ([j, j+1), [i, i+1)) *
        resolution``; ``origin`` the grid's lower-left corner. Cached: about 0.5 s the first time.

    Examples
    --------
    >>> d, origin = corridor_distance()
    >>> d.shape, origin.tolist()
    ((32, 371), [-0.5, -1.585])
    """
    world = long_corridor()
    height = corridor_lidar().height
    x0, y0 = -0.5, -world.info["width"] / 2 - 0.5
    nx = int(np.ceil((world.info["length"] + 1.0) / resolution))
    ny = int(np.ceil((world.info["width"] + 1.0) / resolution))
    xs = x0 + (np.arange(nx) + 0.5) * resolution
    ys = y0 + (np.arange(ny) + 0.5) * resolution
    centres = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    distance = np.minimum(world.layout(height).clearance(centres), 2.0).reshape(ny, nx)
    distance.setflags(write=False)
    return distance, np.array([x0, y0])


def _drive(rng: np.random.Generator, length: float) -> np.ndarray:
    """True poses of one drive: ``RUN['updates']`` steps along the corridor, weaving a little."""
    T, step = RUN["updates"], RUN["step"]
    east = bool(rng.random() < 0.5)
    lo, hi = 1.5 + (0 if east else T * step), length - 1.5 - (T * step if east else 0)
    heading = 0.0 if east else np.pi
    pose = np.array([rng.uniform(lo, hi), rng.uniform(-0.2, 0.2), heading + rng.normal(0, 0.03)])
    poses = [pose]
    for _ in range(T):
        p = poses[-1]
        turn = rng.normal(0, 0.02) - 0.06 * p[1] * np.cos(heading) - 0.1 * wrap_angle(p[2] - heading)
        poses.append(se2_compose(p, [step + rng.normal(0, 0.01), 0.0, turn]))
    return np.array(poses)


def _candidate(rng: np.random.Generator) -> tuple[dict, np.ndarray]:
    world = long_corridor()
    distance, origin = corridor_distance(RUN["resolution"])
    poses = _drive(rng, world.info["length"])
    T, M = RUN["updates"], RUN["particles"]
    odometry = noisy_odometry(poses, MAPPING_ALPHAS, rng=rng)
    increments = se2_between(odometry[:-1], odometry[1:])
    base = corridor_lidar()
    lidar = Lidar(beams=RUN["beams"], r_max=base.r_max, noise=base.noise, height=base.height)
    scans = np.array([lidar.scan(world, p, rng=rng) for p in poses[1:]])
    heading = 0.0 if np.cos(poses[0, 2]) > 0 else np.pi
    offset = rng.uniform(*RUN["offset"]) * rng.choice([-1.0, 1.0])
    centre = np.array([poses[0, 0] + offset, 0.0, heading])
    particles = centre + rng.uniform(-1.0, 1.0, (M, 3)) * RUN["spread"]
    res = RUN["resolution"]
    run = {"particles": particles.round(4).tolist(), "odometry": increments.round(5).tolist(),
           "motion_std": list(RUN["motion_std"]), "noise": rng.standard_normal((T, M, 3)).round(3).tolist(),
           "scans": np.where(np.isfinite(scans), scans.round(4), np.inf).tolist(),
           "angles": lidar.angles.round(9).tolist(), "distance": distance.round(3).tolist(),
           "resolution": res, "origin": [float(origin[0]), float(origin[1])],
           # floored, never rounded: a number rounded up to 1/M is outside the resampling's range
           "uniforms": (np.floor(rng.uniform(0.0, 1.0 / M, T) * 1e6) / 1e6).tolist()}
    return run, poses[1:]


def track_errors(estimates: Any, truth: Any) -> np.ndarray:
    """Position (m) and heading (rad) error of each estimate, shape (T, 2)."""
    e, t = np.asarray(estimates, dtype=float), np.asarray(truth, dtype=float)
    return np.column_stack([np.hypot(e[:, 0] - t[:, 0], e[:, 1] - t[:, 1]), np.abs(wrap_angle(e[:, 2] - t[:, 2]))])


def _settled(estimates: Any, truth: Any) -> np.ndarray:
    """The worst position and heading error over the last :data:`SETTLED` updates, as fractions of the tolerance."""
    return (track_errors(estimates, truth)[-SETTLED:] / TOLERANCE).max(axis=0)


def simulate_run(rng: np.random.Generator, max_tries: int = 150) -> tuple[dict, np.ndarray]:
    """One fair run (module docstring) and its truth.

    Parameters
    ----------
    rng : numpy.random.Generator
    max_tries : int, default 150
        Drives to simulate before giving up.

    Returns
    -------
    (run, truth)
        ``run`` the plain-data inputs of :func:`track`; ``truth`` (T, 3) the poses the scans were taken at.

    Raises
    ------
    RuntimeError
        If no fair run turned up in ``max_tries`` drives (about one in six is fair: 150 fail together
        about once in 10^11).

    Examples
    --------
    >>> run, truth = simulate_run(np.random.default_rng(0))
    >>> len(run["scans"]), len(run["particles"]), truth.shape
    (20, 100, (20, 3))
    """
    for _ in range(max_tries):
        run, truth = _candidate(rng)
        other = dict(run, noise=rng.standard_normal(np.shape(run["noise"])).round(3).tolist())
        if min(_settled(dead_reckoning(run), truth)[0], _settled(one_shot(run), truth).max()) < FAIR[1]:
            continue
        worst = max(_settled(track(run), truth).max(), _settled(track(run, after_resampling=True), truth).max(),
                    _settled(track(other), truth).max())
        if worst <= FAIR[0]:
            return run, truth
    raise RuntimeError(f"no fair corridor run in {max_tries} drives")


def track(run: dict, *, after_resampling: bool = False) -> np.ndarray:
    """Monte-Carlo localization over a run: the estimate after each update (the loop exercise's reference).

    Each update: move every particle by the odometry increment plus its noise (``motion_std`` times
    the given standard normal draws), composed in the particle's own frame; weight each by the
    likelihood field of the update's scan (Table 6.3, :func:`likelihood_field_log_weights` with its
    defaults: ``sigma_hit`` 0.2 m, ``z_hit`` 0.95, ``z_rand`` 0.05, ``r_max`` 8 m, 2 m off the grid);
    the estimate is the weighted mean pose (circular in the heading); then low-variance resampling
    with the update's uniform.

    Parameters
    ----------
    run : dict
        ``particles`` (M, 3), ``odometry`` (T, 3) increments in the robot's frame, ``motion_std`` (3,),
        ``noise`` (T, M, 3), ``scans`` (T, B), ``angles`` (B,), ``distance`` (H, W), ``resolution``,
        ``origin`` (2,), ``uniforms`` (T,) each in ``[0, 1/M)``.
    after_resampling : bool, default False
        Report the plain mean of the resampled particles instead (a variant the cases must accept).

    Returns
    -------
    numpy.ndarray, shape (T, 3)

    Raises
    ------
    ValueError
        For inputs of the wrong shape, NaN ranges or a uniform outside ``[0, 1/M)``.
    """
    if not isinstance(run, dict):
        raise ValueError(f"run: expected a dict of the run's data, got {type(run).__name__}")
    missing = sorted({"particles", "odometry", "motion_std", "noise", "scans", "angles", "distance", "resolution",
                      "origin", "uniforms"} - set(run))
    if missing:
        raise ValueError(f"run: missing keys {missing}")
    P = as_array(run["particles"], "run['particles']", shape=(None, 3))
    U = as_array(run["odometry"], "run['odometry']", shape=(None, 3))
    T, M = len(U), len(P)
    noise = as_array(run["noise"], "run['noise']", shape=(T, M, 3))
    std = as_array(run["motion_std"], "run['motion_std']", shape=(3,))
    uniforms = as_array(run["uniforms"], "run['uniforms']", shape=(T,))
    scans = as_array(run["scans"], "run['scans']", finite=False, ndim=2)
    if len(scans) != T:
        raise ValueError(f"run['scans']: expected one scan per odometry increment ({T}), got {len(scans)}")
    field = LikelihoodField(as_array(run["distance"], "run['distance']", ndim=2), float(run["resolution"]),
                            as_array(run["origin"], "run['origin']", shape=(2,)), 2.0)
    out = []
    for t in range(T):
        P = se2_compose(P, U[t] + noise[t] * std)
        log_w = likelihood_field_log_weights(P, scans[t], run["angles"], field)
        w = normalise_log_weights(log_w).weights
        keep = low_variance_resample(w, start=float(uniforms[t]))
        out.append(weighted_pose_mean(P[keep]) if after_resampling else weighted_pose_mean(P, w))
        P = P[keep]
    return np.array(out)


def one_shot(run: dict) -> np.ndarray:
    """The shortcut that looks once: the particle the first scan likes best, moved by the odometry, (T, 3)."""
    field = LikelihoodField(np.asarray(run["distance"], dtype=float), float(run["resolution"]),
                            np.asarray(run["origin"], dtype=float), 2.0)
    odometry = np.asarray(run["odometry"], dtype=float)
    P = se2_compose(np.asarray(run["particles"], dtype=float),
                    odometry[0] + np.asarray(run["noise"][0], dtype=float) * np.asarray(run["motion_std"], dtype=float))
    pose = P[int(np.argmax(likelihood_field_log_weights(P, run["scans"][0], run["angles"], field)))]
    return np.vstack([pose, _carried(pose, odometry[1:])])


def dead_reckoning(run: dict) -> np.ndarray:
    """The shortcut that ignores the laser: the start cloud's mean pose moved by the odometry, (T, 3)."""
    start = weighted_pose_mean(np.asarray(run["particles"], dtype=float))
    return _carried(start, np.asarray(run["odometry"], dtype=float))


def _carried(pose: np.ndarray, increments: np.ndarray) -> np.ndarray:
    """``pose`` moved by each odometry increment in turn: the pose after each, (len(increments), 3)."""
    out = []
    for u in increments:
        pose = se2_compose(pose, u)
        out.append(pose)
    return np.array(out).reshape(-1, 3)
