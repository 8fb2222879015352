"""Lesson 03's kidnapping (Ge et al. 2023, Sec. 4.2, Fig. 15): carry the robot away, watch both filters.

The robot drives from the corridor's entrance with both localizers of Table 2 tracking it; at one
start place it is lifted and put down at another that looks alike to the laser. amcl keeps its
(now wrong) pose; the paper's method retrieves an image every few seconds (Algorithm 1, lines 14-15,
go back to a retrieval every Delta t; Sec. 4.2 calls the 5 s interval the trigger). We re-initialise
its particles around the retrieved keyframe only when the two disagree (our reading).

One wrong retrieval would then throw away a converged filter, so by default a disagreement must be
confirmed: the next retrieval must disagree too, and agree with the first one carried forward by the
odometry between them (``confirm=2``; ``confirm=1`` acts on one retrieval, and with
``kidnap_distance=0`` re-initialises at every retrieval, Algorithm 1 taken literally).

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from robokit.geometry import se2_between, se2_compose
from robokit.localization import largest_cluster_mean
from robokit.sim import noisy_odometry, waypoint_path
from robokit.validation import as_rng, as_int, as_positive
from robocourse.lessons.corridor_localization.experiment import MAPPING_ALPHAS, CorridorMap, as_corridor_map
from robocourse.lessons.corridor_localization.trials import ELLIPSE_SIGMA, METHODS, PARTICLES, RATE, SPEED, START_POSES, corridor_localizer, retrieve_pose

__all__ = ["KidnapResult", "Confirmation", "kidnapping"]


class Confirmation:
    """When the retrievals overrule the filter: ``confirm`` of them in a row must disagree with its
    estimate (farther than ``distance``) and agree with one another, each earlier one carried forward
    by the odometry since it was taken.

    Ours, not the paper's: re-initialising on one disagreement (``confirm=1``, our reading of
    Algorithm 1, lines 14-15) lets one wrong retrieval throw a converged filter away.

    Examples
    --------
    >>> vote = Confirmation(confirm=2, distance=1.0)
    >>> vote.disagrees([10.0, 0, 0], [5.0, 0, 0], [0.0, 0, 0])      # one far retrieval: wait
    False
    >>> vote.disagrees([11.5, 0, 0], [6.5, 0, 0], [1.5, 0, 0])      # the next, 1.5 m on, agrees with it
    True
    """

    def __init__(self, confirm: int, distance: float) -> None:
        self.confirm = as_int(confirm, "confirm", minimum=1, maximum=10)
        self.distance = as_positive(distance, "distance", allow_zero=True)
        self.pending: list = []            # (retrieved pose, odometry pose) of the disagreeing run

    def disagrees(self, retrieved, estimate, odometry) -> bool:
        """Record one retrieval; ``True`` when the run of disagreements is confirmed (then it restarts)."""
        retrieved = np.asarray(retrieved, float)
        if np.hypot(*(retrieved[:2] - np.asarray(estimate, float)[:2])) <= self.distance:
            self.pending = []
            return False
        carried = [se2_compose(p, se2_between(o, odometry)) for p, o in self.pending]
        if any(np.hypot(*(c[:2] - retrieved[:2])) > self.distance for c in carried):
            self.pending = []              # the far retrievals disagree with one another: start again
        self.pending.append((retrieved, np.asarray(odometry, float)))
        if len(self.pending) < self.confirm:
            return False
        self.pending = []
        return True


@dataclasses.dataclass
class KidnapResult:
    """Fig. 15 re-run: the longitudinal error after the robot is carried from one place to another.

    Attributes
    ----------
    times : numpy.ndarray (K,)
        Seconds since the kidnapping, at each filter update after it.
    errors : dict of str to numpy.ndarray (K,)
        Longitudinal error (estimate x minus true x, metres) per method.
    jump : float
        How far the robot was carried (m).
    reinitialised : list of float
        Ours: the times (s after the kidnapping; negative before it) the retrieval re-initialised the
        particles.
    retrievals : list of tuple
        Ours: ``(time, retrieved pose, true pose, distance from the estimate)`` of every retrieval
        that found a keyframe.
    """

    times: np.ndarray
    errors: dict
    jump: float
    reinitialised: list
    retrievals: list = dataclasses.field(default_factory=list)

    def final_error(self, method: str) -> float:
        """The longitudinal error (m) at the last update: where the filter ended, not an average."""
        return float(self.errors[method][-1])


def kidnapping(setup: CorridorMap, *, origin: int = 5, destination: int = 6, period: float = 5.0,
               after: float = 20.0, kidnap_distance: float = 1.0, confirm: int = 2, seed: int = 0) -> KidnapResult:
    """Drive from the entrance, carry the robot from start ``origin`` to ``destination``, watch both filters.

    Parameters
    ----------
    setup : CorridorMap
    origin, destination : int, default 5, 6
        Indices into :data:`START_POSES` (the paper's #6 and #7, 0-based): where the robot is lifted and
        where it is put down, facing +x on the middle line. The odometry does not see the jump.
    period : float, default 5.0
        Ours: seconds between image retrievals (the paper's trigger interval, Sec. 4.2).
    after : float, default 20.0
        Seconds to drive on after the kidnapping.
    kidnap_distance : float, default 1.0
        Ours: a retrieval farther than this (m) from the filter's estimate re-initialises the
        particles around it (Algorithm 1, lines 14-15); with ``confirm=1``, 0 re-initialises at every
        retrieval, as the algorithm is printed.
    confirm : int, default 2
        Ours: how many retrievals in a row must disagree with the estimate, and agree with each other
        once carried forward by the odometry between them (within ``kidnap_distance``), before the
        particles are re-initialised. 1 re-initialises on the first disagreement (our reading of
        Algorithm 1), so one wrong retrieval throws a converged filter away.
    seed : int, default 0

    Returns
    -------
    KidnapResult

    Raises
    ------
    TypeError, ValueError
        For a bad setup, index or time.

    Notes
    -----
    Ge et al. (2023), Sec. 4.2 and Fig. 15: AMCL keeps the wrong pose (with amcl's default recovery
    rates of 0, no random particles are injected); their method re-localizes
    after the next 5 s retrieval. Both filters start tracking at the true pose at the entrance; ours
    retrieves every ``period`` seconds from the start, and a retrieval that agrees with the estimate
    (amcl's published pose, the heaviest cluster's mean) changes nothing. The confirmation rule is
    ours, not the paper's.

    Examples
    --------
    >>> from robocourse.lessons.corridor_localization.experiment import corridor_map
    >>> result = kidnapping(corridor_map(fast=True), origin=0, destination=2, after=6.0)
    >>> sorted(result.errors), round(result.jump, 1)
    (['amcl', 'ours'], 11.5)
    """
    setup = as_corridor_map(setup)
    a = as_int(origin, "origin", minimum=0, maximum=len(START_POSES) - 1)
    b = as_int(destination, "destination", minimum=0, maximum=len(START_POSES) - 1)
    period, after = as_positive(period, "period"), as_positive(after, "after")
    vote = Confirmation(confirm, as_positive(kidnap_distance, "kidnap_distance", allow_zero=True))
    if vote.distance == 0 and vote.confirm > 1:
        raise ValueError(f"kidnap_distance: 0 (re-initialise at every retrieval) needs confirm=1, got confirm="
                         f"{vote.confirm}: retrievals can never agree within 0 m")
    rng = as_rng(as_int(seed, "seed", minimum=0))
    x_a, x_b = START_POSES[a][0], START_POSES[b][0]
    if x_b + SPEED * after > setup.world.info["length"] - 0.8:
        raise ValueError(f"after: expected the drive after the kidnapping to end before the corridor does, got "
                         f"{after} s from x = {x_b} m")
    leg1 = waypoint_path([[1.0, 0.0], [x_a, 0.0]], SPEED, rate=RATE).poses
    leg2 = waypoint_path([[x_b, 0.0], [x_b + SPEED * after, 0.0]], SPEED, rate=RATE).poses
    truth = np.vstack([leg1, leg2])
    # the odometry integrates the true increments, and the kidnapping is not one of them
    steps = np.vstack([leg1, leg2 - leg2[0] + leg1[-1]])
    odometry = noisy_odometry(steps, MAPPING_ALPHAS, rng)
    kidnap = len(leg1)
    lidar, world = setup.lidar, setup.world
    filters = {m: corridor_localizer(setup, m, rng) for m in METHODS}
    for m, mcl in filters.items():
        mcl.initialize_gaussian(truth[0], np.diag([0.05, 0.05, 0.02]) ** 2, n=PARTICLES[m])
    times, errors, reinit, retrievals = [], {m: [] for m in METHODS}, [], []
    last_retrieval = -np.inf
    for k in range(len(truth)):
        scan = lidar.scan(world, truth[k], rng)
        updated = [mcl.update(odometry[k], scan) for mcl in filters.values()]
        t = (k - kidnap) / RATE
        if k > 0 and t - last_retrieval >= period - 1e-9:      # ours retrieves every period, all along
            last_retrieval = t
            pose_k = retrieve_pose(setup, truth[k], rng)[0]
            ours = filters["ours"]
            estimate = largest_cluster_mean(ours.particles, ours.weights)   # amcl's published pose
            if pose_k is not None:                                          # the image found a keyframe
                retrievals.append((t, pose_k, truth[k], float(np.hypot(*(pose_k[:2] - estimate[:2])))))
                if vote.disagrees(pose_k, estimate, odometry[k]):
                    ours.initialize_ellipse(pose_k, *ELLIPSE_SIGMA)
                    reinit.append(t)
        if k >= kidnap and any(updated):
            times.append(t)
            for m, mcl in filters.items():
                errors[m].append(float(largest_cluster_mean(mcl.particles, mcl.weights)[0] - truth[k, 0]))
    return KidnapResult(np.array(times), {m: np.array(v) for m, v in errors.items()}, float(x_b - x_a), reinit,
                        retrievals)
