"""The paper's experiment in simulation: drive a waypoint course with obstacles, through NMEA and sonar.

Every control step (one sonar slot, 49 ms) the true truck moves, one sonar of the daisy chain pings
(or all four free-run with cross-talk), the compass sends ``$HCHDG`` every other step, the GPS sends
``$GPRMC``, ``$GPGGA`` and ``$GPRMB`` (its own range, bearing, cross-track error, closing velocity
and arrival status for the active leg) once a second, and the :class:`~robokit.outdoor.navigator.Navigator` -
which sees only that text and the sonar ranges - answers with a speed and yaw rate. Results follow
the experiment of Hamid et al. (2009): waypoints reached, collisions, path length
relative to the straight legs, and time. A collision ends the run, as it would end a real trial:
a truck that touched an obstacle does not go on to "reach" the later waypoints.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..validation import as_choice, as_int, as_mapping, as_positive, describe
from .field import Course
from .geodesy import LocalTangentPlane
from .gps import Compass, GPSReceiver
from .navigator import Navigator
from .sonar import LVMaxSonarEZ, read_sensors
from .truck import PAPER_TRUCK, SkidSteerTruck, TruckState

__all__ = ["RunResult", "simulate", "summarize_runs"]


@dataclasses.dataclass(eq=False)
class RunResult:
    """Outcome of one simulated mission.

    Attributes
    ----------
    reached : int
        Waypoints the navigator reached (by its own estimate), in order.
    n_waypoints : int
    collisions : int
        1 if the truck's body touched an obstacle (which ended the run), else 0.
    encounters : int
        Entries into AVOID from GOTO: a new obstacle met while heading for the waypoint.
    reentries : int
        Entries into AVOID from BYPASS: the truck was still getting past an obstacle.
    time : float
        Mission time (s) until the last waypoint, a collision or the time limit.
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
    avoidances : int
        Times the navigator entered its AVOID state, ``encounters + reentries`` (derived).
    """

    reached: int
    n_waypoints: int
    collisions: int
    encounters: int
    reentries: int
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
    def avoidances(self) -> int:
        """Entries into AVOID, new obstacles and re-entries together."""
        return self.encounters + self.reentries

    @property
    def success(self) -> bool:
        """Every waypoint reached with no collision."""
        return self.reached == self.n_waypoints and self.collisions == 0


def simulate(course: Course, seed: int = 0, *, firing: str = "chained", crosstalk: bool = True,
             truck: SkidSteerTruck | None = None,
             max_time: float | None = None, dt: float = 0.049, keep_nmea: int = 200,
             gps_noise: float = 2.5, compass_accuracy: float = math.radians(2.0),
             navigator_options: dict | None = None) -> RunResult:
    """Run one mission on ``course`` and return its :class:`RunResult`.

    Parameters
    ----------
    course : Course
        From :func:`robokit.outdoor.field.random_course`.
    seed : int, default 0
        Non-negative integer that seeds the GPS, compass and sonar noise and the real truck's slip.
    firing : {"chained", "free", "off"}, default "chained"
        Sonar firing: one sensor per 49 ms slot in a loop, all free-running with cross-talk, or
        no sonar at all (the baseline that shows what the sonars are for). Free-running sensors
        keep their own 49 ms cycles: each starts at a random phase and its clock runs up to 0.5 %
        fast or slow, so the phases drift slowly against each other.
    crosstalk : bool, default True
        With ``firing="free"``, whether a sensor hears the others' pings. ``False`` keeps the
        free-running sensors' four-times-faster update without cross-talk, to tell the two apart.
    truck : SkidSteerTruck, optional
        The real truck; default: the paper's truck with slip drawn in [0.02, 0.12] and track
        expansion in [1.3, 1.8] (the navigator always assumes the nominal 0.05 and 1.5).
    max_time : float, optional
        Time limit (s); default three times the straight-leg length at cruise speed plus 120 s.
    dt : float, default 0.049
        Control step = one sonar reading cycle (datasheet: 49 ms).
    keep_nmea : int, default 200
        Number of sentences kept in the result (for display).
    gps_noise : float, default 2.5
        Standard deviation (m) of the wandering GPS error per axis.
    compass_accuracy : float, default ``radians(2.0)``
        Bound (rad) of the compass's total error after calibration (:class:`~robokit.outdoor.gps.Compass`;
        the paper: +-2 degrees, +-5 degrees at extreme latitudes; 1 degree resolution).
    navigator_options : dict, optional
        Extra keyword arguments for :class:`~robokit.outdoor.navigator.Navigator`, e.g.
        ``{"guidance": "rmb"}`` to steer by the receiver's own $GPRMB bearing and range.

    Returns
    -------
    RunResult

    Raises
    ------
    TypeError, ValueError
        For a course that is not a :class:`Course`, an unknown firing mode or a non-positive step.

    Notes
    -----
    The loop is the system of Hamid et al. (2009) with our sensor models, one phase per method of
    :class:`_Mission`: set-up, sensors (GPS and compass as NMEA text, sonars), navigator, truck,
    bookkeeping, result. The run stops at the first contact with an obstacle.

    Examples
    --------
    >>> from robokit.outdoor import Course, Field
    >>> course = Course(Field(circles=[[7.0, 10.0, 0.4]]), np.array([[14.0, 10.0]]), np.array([2.0, 10.0, 0.0]))
    >>> run = simulate(course, seed=2, gps_noise=0.5)
    >>> run.reached, run.collisions, run.avoidances >= 1
    (1, 0, True)
    """
    if not isinstance(course, Course):
        raise TypeError(f"course: expected a Course from random_course(), got {type(course).__name__}")
    rng = np.random.default_rng(as_int(seed, "seed", minimum=0))
    as_choice(firing, "firing", ("chained", "free", "off"))
    if not isinstance(crosstalk, (bool, np.bool_)):
        raise TypeError(f"crosstalk: expected True or False, got {describe(crosstalk)}")
    if truck is not None and not isinstance(truck, SkidSteerTruck):
        raise TypeError(f"truck: expected a SkidSteerTruck or None, got {describe(truck)}")
    max_time = None if max_time is None else as_positive(max_time, "max_time")
    gps_noise = as_positive(gps_noise, "gps_noise", allow_zero=True)
    compass_accuracy = as_positive(compass_accuracy, "compass_accuracy", allow_zero=True)
    navigator_options = as_mapping(navigator_options, "navigator_options")
    mission = _Mission(course, rng, firing, bool(crosstalk), truck, as_positive(dt, "dt"), as_int(keep_nmea, "keep_nmea", minimum=0),
                       gps_noise, compass_accuracy, navigator_options, max_time)
    while mission.t < mission.limit and not mission.nav.done and not mission.collisions:
        mission.send_nmea()
        mission.ping_sonars()
        v, omega = mission.navigate()
        mission.drive(v, omega)
        mission.log()
    return mission.result()


class _Mission:
    """One mission's state, advanced one control step at a time by :func:`simulate`'s phases."""

    def __init__(self, course: Course, rng: np.random.Generator, firing: str, crosstalk: bool,
                 truck: SkidSteerTruck | None,
                 dt: float, keep: int, gps_noise: float, compass_accuracy: float, navigator_options: dict | None,
                 max_time: float | None):
        # set-up; the order of the random draws below is part of every seeded result
        self.course, self.field, self.rng, self.firing, self.dt, self.keep = course, course.field, rng, firing, dt, keep
        self.crosstalk = crosstalk
        self.real = truck if truck is not None else dataclasses.replace(
            PAPER_TRUCK, slip=float(rng.uniform(0.02, 0.12)), icr_factor=float(rng.uniform(1.3, 1.8)))
        plane = LocalTangentPlane(*self.field.origin)
        legs = np.vstack([course.start[:2], course.waypoints])
        straight = float(np.sum(np.hypot(*np.diff(legs, axis=0).T)))
        self.route = np.column_stack(plane.to_geodetic(course.waypoints))   # what the receiver stores
        self.route_start = np.column_stack(plane.to_geodetic(course.start[:2].reshape(1, 2)))[0]
        self.nav = Navigator(self.route, PAPER_TRUCK, **dict(navigator_options or {}))
        self.offset = plane.to_local(self.nav.plane.lat0, self.nav.plane.lon0)  # navigator's frame -> field frame
        self.limit = 3 * straight / self.nav.cruise_speed + 120.0 if max_time is None else max_time
        self.gps = GPSReceiver(plane, noise=gps_noise, rng=rng)
        self.compass = Compass(accuracy=compass_accuracy, rng=rng)
        self.sonar = LVMaxSonarEZ()
        self.state = TruckState(np.array(course.start, dtype=float))
        self.ranges = np.full(4, self.sonar.max_range)
        self.phases = rng.uniform(0, dt, 4)                 # free-running sensors' power-up phases
        self.clock_errors = rng.uniform(-0.005, 0.005, 4)   # and their clocks' errors: the phases drift
        self.t, self.k, self.length, self.collisions = 0.0, 0, 0.0, 0
        self.entries = {"GOTO": 0, "BYPASS": 0}             # entries into AVOID, by the state before
        self.previous = self.nav.state
        self.truth, self.estimate, self.states, self.range_log = [], [], [], []
        self.fixes, self.gps_errors, self.nmea = [], [], []
        self.arrival_errors: list[float] = []
        self.arrival_points = [np.array(course.start[:2], dtype=float)]

    def send_nmea(self) -> None:
        """Sensors, text: a GPS fix (RMC + GGA + RMB) every 20 steps (1 Hz), a compass HDG every other step."""
        lines = []
        if self.k % 20 == 0:
            active = min(self.nav.target, len(self.route) - 1)      # the receiver follows the same route
            origin = self.route[active - 1] if active else self.route_start
            lines = self.gps.fix(self.t, self.state.pose[:2], self.state.v, self.state.pose[2],
                                 destination=self.route[active], destination_id=f"{active + 1:03d}",
                                 origin=origin, origin_id=f"{active:03d}", arrival_radius=self.nav.arrival_radius)
            self.fixes.append(self.state.pose[:2] + self.gps.last_error)
            self.gps_errors.append(float(np.hypot(*self.gps.last_error)))
        if self.k % 2 == 0:
            lines.append(self.compass.reading(self.state.pose[2]))
        for line in lines:
            self.nav.feed(line)
            if len(self.nmea) < self.keep:
                self.nmea.append(line)

    def ping_sonars(self) -> None:
        """Sensors, sonar: one sensor of the daisy chain per step, or all four free-running (own drifting clocks)."""
        if self.firing == "chained":
            i = self.k % 4
            self.ranges[i] = read_sensors(self.field, self.state.pose, [i], [self.t], sensor=self.sonar,
                                          rng=self.rng)[0]
        elif self.firing == "free":
            times = self.t + (self.phases + self.t * self.clock_errors) % self.dt
            self.ranges[:] = read_sensors(self.field, self.state.pose, [0, 1, 2, 3], times, sensor=self.sonar,
                                          others=dict(enumerate(times)) if self.crosstalk else None, rng=self.rng)

    def navigate(self) -> tuple[float, float]:
        """Navigator: ``(v, omega)`` from the latest text and ranges; note arrivals and avoidances."""
        before = self.nav.target
        v, omega = self.nav.update(self.ranges, self.dt)
        if self.nav.target > before:  # arrival declared: how far is the truck really?
            self.arrival_errors.append(math.hypot(*(self.state.pose[:2] - self.course.waypoints[before])))
            self.arrival_points.append(self.state.pose[:2].copy())
        if self.nav.state == "AVOID" and self.previous != "AVOID":
            self.entries[self.previous] = self.entries.get(self.previous, 0) + 1
        self.previous = self.nav.state
        return v, omega

    def drive(self, v: float, omega: float) -> None:
        """Truck: the nominal model's wheel commands drive the real truck; a contact ends the run."""
        new = self.real.step(self.state, self.nav.truck.wheel_commands(v, omega, validate=False), self.dt, validate=False)
        self.length += math.hypot(*(new.pose[:2] - self.state.pose[:2]))
        self.state = new
        self.collisions = int(self.field.collides(self.state.pose, self.real.length, self.real.width))
        self.t += self.dt
        self.k += 1

    def log(self) -> None:
        """Bookkeeping: true pose, the navigator's estimate (field frame), state and ranges."""
        self.truth.append(self.state.pose.copy())
        self.estimate.append(self.nav.position + self.offset if self.nav.position is not None
                             else self.state.pose[:2] * np.nan)
        self.states.append(self.nav.state)
        self.range_log.append(self.ranges.copy())

    def result(self) -> RunResult:
        """The figures of Hamid et al.'s experiment, path ratio over the legs actually driven."""
        legs = np.vstack(self.arrival_points + ([self.state.pose[:2]] if not self.nav.done else []))
        direct = float(np.sum(np.hypot(*np.diff(legs, axis=0).T)))
        return RunResult(reached=len(self.nav.arrivals), n_waypoints=len(self.course.waypoints),
                         collisions=int(self.collisions),
                         encounters=int(self.entries["GOTO"]), reentries=int(self.entries["BYPASS"]), time=self.t,
                         path_length=self.length, path_ratio=self.length / direct if direct > 0 else math.nan,
                         arrival_errors=np.array(self.arrival_errors), gps_errors=np.array(self.gps_errors),
                         truth=np.array(self.truth), estimate=np.array(self.estimate),
                         fixes=np.array(self.fixes).reshape(-1, 2), states=self.states, ranges=np.array(self.range_log),
                         nmea=self.nmea, parse_errors=len(self.nav.parse_errors))


def summarize_runs(results: list[RunResult]) -> dict:
    """Distribution of the mission figures over runs (plain data, for tables and tests).

    Returns
    -------
    dict
        ``runs``, ``success_rate``, ``waypoints_reached`` (total / total), ``collisions`` (total and
        per run), avoidances per run, ``encounters_per_100m`` and ``reentries_per_100m`` (entries
        into AVOID from GOTO and from BYPASS per 100 m driven, over all runs), and
        ``min``/``median``/``max`` of ``path_ratio``, ``time`` and ``arrival_error``.

    Raises
    ------
    ValueError
        For an empty list.

    Notes
    -----
    The figures of the paper's experiment (Hamid et al. 2009) plus the GPS error.

    Examples
    --------
    >>> from robokit.outdoor import random_course
    >>> course = random_course(0, n_waypoints=1, size=(30.0, 20.0), n_obstacles=2)
    >>> summary = summarize_runs([simulate(course, seed=10_000)])
    >>> summary["waypoints_reached"], summary["collisions_total"], summary["success_rate"]
    ('1/1', 0, 1.0)
    """
    if not isinstance(results, (list, tuple)) or not all(isinstance(r, RunResult) for r in results):
        raise TypeError(f"results: expected a list of RunResult (from simulate), got {describe(results)}")
    if not results:
        raise ValueError("results: expected at least one RunResult, got an empty list")
    ratio = np.array([r.path_ratio for r in results])
    time = np.array([r.time for r in results])
    arr = np.concatenate([r.arrival_errors for r in results])
    total = sum(r.path_length for r in results)     # metres driven, over all runs

    def stats(x):
        x = np.asarray(x, dtype=float)
        return {"min": float(x.min()), "median": float(np.median(x)), "max": float(x.max())} if x.size else {}

    return {"runs": len(results), "success_rate": float(np.mean([r.success for r in results])),
            "waypoints_reached": f"{sum(r.reached for r in results)}/{sum(r.n_waypoints for r in results)}",
            "collisions_total": int(sum(r.collisions for r in results)),
            "collisions_per_run": [r.collisions for r in results],
            "avoidances_per_run": [r.avoidances for r in results],
            "encounters_per_100m": 100 * sum(r.encounters for r in results) / max(total, 1e-9),
            "reentries_per_100m": 100 * sum(r.reentries for r in results) / max(total, 1e-9),
            "path_ratio": stats(ratio), "time_s": stats(time), "arrival_error_m": stats(arr),
            "gps_error_max_m": float(max(r.gps_errors.max() for r in results if r.gps_errors.size))}
