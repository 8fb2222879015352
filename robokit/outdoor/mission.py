"""The paper's experiment in simulation: drive a waypoint course with obstacles, through NMEA and sonar.

Every control step (one sonar slot, 49 ms) the true truck moves, one sonar of the daisy chain pings
(or all four free-run with cross-talk), the compass sends ``$HCHDG`` every other step, the GPS sends
``$GPRMC`` and ``$GPGGA`` once a second, and the :class:`~robokit.outdoor.navigator.Navigator` -
which sees only that text and the sonar ranges - answers with a speed and yaw rate. Results follow
the experiment of Hamid et al. (seed 000 Q3, Sec. 4): waypoints reached, collisions, path length
relative to the straight legs, and time.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..validation import as_rng, check_choice, check_int, check_positive
from .field import Course, random_course
from .geodesy import LocalTangentPlane
from .gps import Compass, GPSReceiver
from .navigator import Navigator
from .sonar import LVMaxSonarEZ, read_sensors
from .truck import PAPER_TRUCK, SkidSteerTruck, TruckState

__all__ = ["RunResult", "simulate", "run_courses", "summarize_runs"]


@dataclasses.dataclass(eq=False)
class RunResult:
    """Outcome of one simulated mission.

    Attributes
    ----------
    reached : int
        Waypoints the navigator reached (by its own estimate), in order.
    n_waypoints : int
    collisions : int
        Times the truck's body came into contact with an obstacle.
    avoidances : int
        Times the navigator entered its AVOID state.
    time : float
        Mission time (s) until the last waypoint or the time limit.
    path_length : float
        Distance the truck actually drove (m).
    path_ratio : float
        ``path_length`` over the straight-line legs joining the start and the true positions where
        each arrival was declared (1 = no detour).
    arrival_errors : numpy.ndarray
        True distance (m) from each reached waypoint when the navigator declared arrival; this is
        where GPS error shows.
    gps_errors : numpy.ndarray
        Horizontal error (m) of every GPS fix sent.
    truth, estimate : numpy.ndarray
        Logged true poses ``(T, 3)`` and estimated positions ``(T, 2)`` every step.
    fixes : numpy.ndarray
        GPS fixes in field metres ``(F, 2)``.
    states : list of str
        Navigator state every step.
    ranges : numpy.ndarray
        Latest sonar ranges ``(T, 4)``.
    nmea : list of str
        Every sentence sent (first ``keep_nmea`` only).
    parse_errors : int
        Sentences the navigator rejected.
    """

    reached: int
    n_waypoints: int
    collisions: int
    avoidances: int
    time: float
    path_length: float
    path_ratio: float
    arrival_errors: np.ndarray
    gps_errors: np.ndarray
    truth: np.ndarray
    estimate: np.ndarray
    fixes: np.ndarray
    states: list
    ranges: np.ndarray
    nmea: list
    parse_errors: int

    @property
    def success(self) -> bool:
        """Every waypoint reached with no collision."""
        return self.reached == self.n_waypoints and self.collisions == 0


def simulate(course: Course, seed: Any = 0, *, firing: str = "chained", truck: SkidSteerTruck | None = None,
             max_time: float | None = None, dt: float = 0.049, keep_nmea: int = 200,
             gps_sigma: float = 2.5, navigator_options: dict | None = None) -> RunResult:
    """Run one mission on ``course`` and return its :class:`RunResult`.

    Parameters
    ----------
    course : Course
        From :func:`robokit.outdoor.field.random_course`.
    seed : int or numpy.random.Generator
        Randomness of the GPS, compass, sonar noise and the real truck's slip.
    firing : {"chained", "free", "off"}, default "chained"
        Sonar firing: one sensor per 49 ms slot in a loop, all free-running with cross-talk, or
        no sonar at all (the baseline that shows what the sonars are for).
    truck : SkidSteerTruck, optional
        The real truck; default: the paper's truck with slip drawn in [0.02, 0.12] and track
        expansion in [1.3, 1.8] (the navigator always assumes the nominal 0.05 and 1.5).
    max_time : float, optional
        Time limit (s); default three times the straight-leg length at cruise speed plus 120 s.
    dt : float, default 0.049
        Control step = one sonar reading cycle (datasheet: 49 ms).
    keep_nmea : int, default 200
        Number of sentences kept in the result (for display).
    gps_sigma : float, default 2.5
        Standard deviation (m) of the wandering GPS error per axis.
    navigator_options : dict, optional
        Extra keyword arguments for :class:`~robokit.outdoor.navigator.Navigator`.

    Returns
    -------
    RunResult

    Notes
    -----
    The loop is the system of Hamid et al. (seed 000 Q3, Secs. 3-4) with our sensor models:
    :class:`~robokit.outdoor.gps.GPSReceiver`, :class:`~robokit.outdoor.gps.Compass`,
    :func:`~robokit.outdoor.sonar.read_sensors`, :class:`~robokit.outdoor.truck.SkidSteerTruck`.
    """
    if not isinstance(course, Course):
        raise TypeError(f"course: expected a Course from random_course(), got {type(course).__name__}")
    rng = as_rng(seed, "seed")
    check_choice(firing, "firing", ("chained", "free", "off"))
    h = check_positive(dt, "dt")
    keep = check_int(keep_nmea, "keep_nmea", minimum=0)
    real = truck if truck is not None else dataclasses.replace(
        PAPER_TRUCK, slip=float(rng.uniform(0.02, 0.12)), icr_factor=float(rng.uniform(1.3, 1.8)))
    field = course.field
    plane = LocalTangentPlane(*field.origin)
    legs = np.vstack([course.start[:2], course.waypoints])
    straight = float(np.sum(np.hypot(*np.diff(legs, axis=0).T)))
    opts = dict(navigator_options or {})
    nav = Navigator(np.column_stack(plane.to_geodetic(course.waypoints)), PAPER_TRUCK, **opts)
    offset = plane.to_local(nav.plane.lat0, nav.plane.lon0)  # navigator's frame -> field frame
    limit = 3 * straight / nav.cruise_speed + 120.0 if max_time is None else check_positive(max_time, "max_time")
    gps = GPSReceiver(plane, sigma=gps_sigma, rng=rng)
    compass = Compass(rng=rng)
    sonar = LVMaxSonarEZ()
    state = TruckState(np.array(course.start, dtype=float))
    ranges = np.full(4, sonar.max_range)
    phases = rng.uniform(0, h, 4)
    truth, est, states, rlog, fixes, gps_err, nmea = [], [], [], [], [], [], []
    collisions, contact, length, t, k = 0, False, 0.0, 0.0, 0
    arrival_true: list[float] = []
    arrival_points = [np.array(course.start[:2], dtype=float)]
    avoidances, previous = 0, nav.state
    while t < limit and not nav.done:
        if k % 20 == 0:
            lines = gps.fix(t, state.pose[:2], state.v, state.pose[2])
            fixes.append(state.pose[:2] + gps.last_error)
            gps_err.append(float(np.hypot(*gps.last_error)))
        else:
            lines = []
        if k % 2 == 0:
            lines.append(compass.reading(state.pose[2]))
        for line in lines:
            nav.feed(line)
            if len(nmea) < keep:
                nmea.append(line)
        if firing == "off":
            pass
        elif firing == "chained":
            i = k % 4
            ranges[i] = read_sensors(field, state.pose, [i], [t], sensor=sonar, rng=rng)[0]
        else:
            times = t + phases
            ranges[:] = read_sensors(field, state.pose, [0, 1, 2, 3], times, sensor=sonar,
                                     others=dict(enumerate(times)), rng=rng)
        before = nav.target
        v, omega = nav.update(ranges, h)
        if nav.target > before:  # arrival declared: how far is the truck really?
            arrival_true.append(math.hypot(*(state.pose[:2] - course.waypoints[before])))
            arrival_points.append(state.pose[:2].copy())
        avoidances += nav.state == "AVOID" and previous != "AVOID"
        previous = nav.state
        command = nav.truck.wheel_commands(v, omega)
        new = real.step(state, command, h)
        length += math.hypot(*(new.pose[:2] - state.pose[:2]))
        state = new
        hit = field.collides(state.pose, real.length, real.width)
        collisions += hit and not contact
        contact = hit
        t += h
        k += 1
        truth.append(state.pose.copy())
        est.append(nav.position + offset if nav.position is not None else state.pose[:2] * np.nan)
        states.append(nav.state)
        rlog.append(ranges.copy())
    legs = np.vstack(arrival_points + ([state.pose[:2]] if not nav.done else []))
    direct = float(np.sum(np.hypot(*np.diff(legs, axis=0).T)))
    return RunResult(reached=len(nav.arrivals), n_waypoints=len(course.waypoints), collisions=int(collisions),
                     avoidances=int(avoidances), time=t, path_length=length,
                     path_ratio=length / direct if direct > 0 else math.nan,
                     arrival_errors=np.array(arrival_true), gps_errors=np.array(gps_err),
                     truth=np.array(truth), estimate=np.array(est), fixes=np.array(fixes).reshape(-1, 2),
                     states=states, ranges=np.array(rlog), nmea=nmea, parse_errors=len(nav.parse_errors))


def run_courses(seeds: Any, *, firing: str = "chained", course_options: dict | None = None,
                progress: Any = None, **options: Any) -> list[RunResult]:
    """Simulate one mission per seed on :func:`~robokit.outdoor.field.random_course` ``(seed)``.

    Parameters
    ----------
    seeds : iterable of int
    firing : {"chained", "free"}
    course_options : dict, optional
        Keyword arguments of :func:`~robokit.outdoor.field.random_course`.
    progress : callable, optional
        ``progress(i, n)`` after each run (e.g. to print a progress bar).
    **options
        Passed to :func:`simulate`.

    Returns
    -------
    list of RunResult

    Notes
    -----
    The seeded repetition of Hamid et al.'s experiment (seed 000 Q3, Sec. 4) used by the lesson.
    """
    seeds = [check_int(s, "seeds[i]", minimum=0) for s in seeds]
    out = []
    for i, s in enumerate(seeds):
        course = random_course(s, **(course_options or {}))
        out.append(simulate(course, seed=10_000 + s, firing=firing, **options))
        if progress is not None:
            progress(i + 1, len(seeds))
    return out


def summarize_runs(results: list[RunResult]) -> dict:
    """Distribution of the mission figures over runs (plain data, for tables and tests).

    Returns
    -------
    dict
        ``runs``, ``success_rate``, ``waypoints_reached`` (total / total), ``collisions`` (total and
        per run), and ``min``/``median``/``max`` of ``path_ratio``, ``time`` and ``arrival_error``.

    Raises
    ------
    ValueError
        For an empty list.

    Notes
    -----
    The figures of the paper's experiment (Hamid et al., seed 000 Q3, Sec. 4) plus the GPS error.
    """
    if not results:
        raise ValueError("results: expected at least one RunResult, got an empty list")
    ratio = np.array([r.path_ratio for r in results])
    time = np.array([r.time for r in results])
    arr = np.concatenate([r.arrival_errors for r in results]) if results else np.array([])

    def stats(x):
        x = np.asarray(x, dtype=float)
        return {"min": float(x.min()), "median": float(np.median(x)), "max": float(x.max())} if x.size else {}

    return {"runs": len(results), "success_rate": float(np.mean([r.success for r in results])),
            "waypoints_reached": f"{sum(r.reached for r in results)}/{sum(r.n_waypoints for r in results)}",
            "collisions_total": int(sum(r.collisions for r in results)),
            "collisions_per_run": [r.collisions for r in results],
            "avoidances_per_run": [r.avoidances for r in results],
            "path_ratio": stats(ratio), "time_s": stats(time), "arrival_error_m": stats(arr),
            "gps_error_max_m": float(max(r.gps_errors.max() for r in results if r.gps_errors.size))}
