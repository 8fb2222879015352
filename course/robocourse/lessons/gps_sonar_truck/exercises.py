"""Exercises of assignment 05 (GPS waypoint navigation and sonar obstacle avoidance, Hamid et al.).

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] National Marine Electronics Association, *NMEA 0183 Standard for Interfacing Marine
   Electronic Devices*, version 4.11, 2018.
"""
from __future__ import annotations

import datetime as dt

import numpy as np

from robokit.controllers.heading import design_heading_gains
from robokit.outdoor.geodesy import haversine_distance_bearing
from robokit.outdoor.navigator import avoidance_decision
from robokit.outdoor.nmea import fix_position, nmea_checksum
from robokit.outdoor.nmea_write import format_sentence, gga_sentence, hdg_sentence, random_sentences, rmc_sentence
from robokit.outdoor.sonar import pulse_width_to_cm_inches
from robokit.validation import as_array, as_points
from robocourse.exercises.compare import close, exact
from robocourse.exercises.spec import Case, Exercise

ASSIGNMENT = "05_gps_sonar_truck"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"05.calibration_drive": 2, "05.bearing_near_waypoint": 2, "05.gps_accuracy": 2}


def compass_bias(fixes, compass_deg) -> float:
    """The compass's constant error (degrees, reported minus true) from a straight drive (the open exercise's answer).

    Parameters
    ----------
    fixes : array_like, shape (N, 2)
        GPS positions (east, north metres) along a straight drive at constant heading.
    compass_deg : array_like, shape (N,)
        Compass headings (degrees clockwise from north) read at the same times.

    Returns
    -------
    float
        Bias in degrees in (-180, 180].

    Raises
    ------
    ValueError
        Fewer than two fixes, or not one compass reading per fix.

    Notes
    -----
    The direction of travel is the principal axis of the fixes (a total-least-squares line), refitted
    without the fixes more than three robust standard deviations (1.4826 times the median distance)
    off the previous line until that set stops changing (at most five fits), so that a few poor fixes
    do not tilt it. The
    line is oriented from the first to the last fix; the bias is the circular mean of the readings
    minus that course. One way among several: the cases accept any estimate within a degree.

    Examples
    --------
    >>> t = np.arange(100.0)
    >>> fixes = np.column_stack([0.7 * t, np.zeros_like(t)])        # due east: course 90 degrees
    >>> round(compass_bias(fixes, np.full(100, 93.0)), 6)
    3.0
    """
    p = as_points(fixes, "fixes", 2, min_count=2)
    c = as_array(compass_deg, "compass_deg", shape=(len(p),))
    keep = np.ones(len(p), dtype=bool)
    for _ in range(5):
        centre = p[keep].mean(axis=0)
        axis = np.linalg.svd(p[keep] - centre, full_matrices=False)[2][0]
        off = np.abs((p - centre) @ np.array([-axis[1], axis[0]]))      # distance from the line
        spread = 1.4826 * np.median(off[keep])
        if spread == 0 or len(p) < 5 or np.array_equal(keep, off <= 3 * spread):
            break
        keep = off <= 3 * spread
    if np.dot(axis, p[-1] - p[0]) < 0:
        axis = -axis
    course = np.arctan2(axis[0], axis[1])                       # clockwise from north
    diff = np.radians(c) - course
    bias = np.degrees(np.arctan2(np.sin(diff).mean(), np.cos(diff).mean()))
    return float(bias if bias > -180.0 else 180.0)


def calibration_drive(rng: np.random.Generator, length: float = 120.0, *, heading: float | None = None,
                       bias: float | None = None, gps_sigma: float = 0.8, poor: int = 0, poor_at: str = "start",
                       wander: float = 0.0):
    """A straight drive at 0.7 m/s with 1 Hz fixes and whole-degree compass readings: (fixes, compass, true bias).

    The bias has a random sign and a magnitude in [1.5, 5] degrees unless given; ``poor`` fixes at the
    ``poor_at`` end ("start": after power-up, "end": under trees, "both") lie 5-10 m to one side; ``wander``
    (m) adds a slowly varying GPS error (Gauss-Markov, 30 s correlation time) on top of the scatter.
    """
    n = max(2, int(round(length / 0.7)))
    psi = float(rng.uniform(0, 360)) if heading is None else heading
    b = float(rng.choice([-1.0, 1.0]) * rng.uniform(1.5, 5.0)) if bias is None else bias
    t = np.arange(n) * 0.7
    start = rng.uniform(10, 40, 2)
    truth = start + np.column_stack([t * np.sin(np.radians(psi)), t * np.cos(np.radians(psi))])
    fixes = truth + rng.normal(0, gps_sigma, (n, 2))
    if wander:
        phi = np.exp(-1.0 / 30.0)
        drift = np.zeros((n, 2))
        drift[0] = rng.normal(0, wander, 2)
        for k in range(1, n):
            drift[k] = phi * drift[k - 1] + np.sqrt(1 - phi * phi) * rng.normal(0, wander, 2)
        fixes += drift
    side = np.array([np.cos(np.radians(psi)), -np.sin(np.radians(psi))])
    for end in ("start", "end"):
        if poor and poor_at in (end, "both"):
            rows = slice(0, poor) if end == "start" else slice(n - poor, n)
            fixes[rows] += rng.uniform(5.0, 10.0, (poor, 1)) * side * rng.choice([-1.0, 1.0])
    compass = np.round(psi + b + rng.normal(0, 0.5, n)) % 360.0
    return np.round(fixes, 2), compass, b


#: The kinds of calibration drive in the open exercise's cases: (label, keyword arguments of calibration_drive).
#: ``poor=True`` means a random number (2-8) of poor fixes.
BIAS_DRIVES = (
    ("straight drive", {}),
    ("heading close to north: readings either side of 0/360, poor first fixes", {"heading": 359.6, "poor": True}),
    ("poor first fixes after power-up", {"poor": True}),
    ("poor first fixes after power-up", {"poor": True}),
    ("poor last fixes (under trees at the end)", {"poor": True, "poor_at": "end"}),
    ("poor last fixes (under trees at the end)", {"poor": True, "poor_at": "end"}),
    ("poor first and last fixes", {"poor": True, "poor_at": "both"}),
    ("poor first and last fixes", {"poor": True, "poor_at": "both"}),
    ("slowly wandering GPS error, poor first fixes", {"wander": 0.4, "length": 200.0, "poor": True}),
    ("slowly wandering GPS error, poor last fixes", {"wander": 0.4, "length": 200.0, "poor": True, "poor_at": "end"}),
)


def _bias_cases(rng: np.random.Generator) -> list[Case]:
    cases, first = [], None
    for label, kwargs in BIAS_DRIVES:
        kw = dict(kwargs)
        if kw.get("poor") is True:
            kw["poor"] = int(rng.integers(2, 9))
        f, c, _ = calibration_drive(rng, **kw)
        first = first or (f, c)
        cases.append(Case((f.tolist(), c.tolist()), label=label))
    f, c = first
    return cases + [Case(([f[0].tolist()], [c[0]]), raises="ValueError", label="a single fix"),
                    Case((f.tolist(), c[:-1].tolist()), raises="ValueError", label="one reading missing")]


def _checksum_cases(rng: np.random.Generator) -> list[Case]:
    sentences = random_sentences(6, rng)
    return [
        Case(("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,",), label="body only"),
        Case((sentences[0],), label="full sentence: ignore '$' and everything from '*'"),
        Case((sentences[2],), label="compass sentence"),
        Case((sentences[3][1:sentences[3].index("*")],), label="body of an RMB"),
        Case((sentences[4],), label="generic sentence type"),
        Case(("",), raises="ValueError", label="empty body"),
        Case(("GPGGA,12\u00e9",), raises="ValueError", label="non-ASCII character"),
    ]


def _position_cases(rng: np.random.Generator) -> list[Case]:
    lat, lon = rng.uniform(-80, 80, 3), rng.uniform(-179, 179, 3)
    when = dt.datetime(2012, 6, 4, 2, 30, int(rng.integers(60)))
    good = [rmc_sentence(when, float(lat[0]), float(lon[0]), speed_mps=1.0, course_deg=45.0),
            gga_sentence(when.time(), float(lat[1]), float(lon[1]), talker="GN"),
            rmc_sentence(when, -abs(float(lat[2])), -abs(float(lon[2])), talker="GN")]
    bad_checksum = good[0][:-2] + ("00" if good[0][-2:] != "00" else "01")
    too_far = format_sentence("GPGGA", ["023000", "9130.0000", "N", "10021.0300", "E", "1", "08", "1.0",
                                        "12.0", "M", "", "M", "", ""])
    return [
        Case((good[0],), label="RMC, GP talker"),
        Case((good[1],), label="GGA, GN talker"),
        Case((good[2],), label="southern and western hemispheres"),
        Case(("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A",), label="textbook RMC"),
        Case((bad_checksum,), raises="ValueError", label="wrong checksum"),
        Case((too_far,), raises="ValueError", label="latitude above 90 degrees"),
        Case(("$GNRMC,,V,,,,,,,,,,N*4D",), raises="ValueError", label="no fix: empty position"),
        Case((hdg_sentence(120.0),), raises="ValueError", label="not a position sentence"),
    ]


def _haversine_cases(rng: np.random.Generator) -> list[Case]:
    lat0, lon0 = np.radians(6.459), np.radians(100.35)
    near = rng.normal(0, 3e-4, (3, 2))
    far = rng.uniform([-1.2, -3.0], [1.2, 3.0], (2, 2))
    cases = [Case((lat0, lon0, lat0 + 1e-5, lon0), label="10 cm north: bearing 0")]
    for d in near:
        cases.append(Case((lat0, lon0, float(lat0 + d[0]), float(lon0 + d[1])), label="across a football field"))
    cases.append(Case((float(far[0, 0]), float(far[0, 1]), float(far[1, 0]), float(far[1, 1])), label="far apart"))
    cases.append(Case((0.0, 0.0, 0.0, -0.01), label="due west: bearing 3 pi / 2"))
    cases.append(Case((48.1, 11.5, 48.2, 11.6), raises="ValueError", label="degrees instead of radians"))
    return cases


def _pulse_cases(rng: np.random.Generator) -> list[Case]:
    widths = rng.uniform(882, 37338, 3)  # 6 to 254 inches
    return [Case((147.0,), label="one inch"), Case((14700.0,), label="100 inches")] + \
        [Case((float(w),), label="inside the sensor's range") for w in widths] + \
        [Case((-10.0,), raises="ValueError", label="negative width"),
         Case((float("nan"),), raises="ValueError", label="NaN")]


def _avoid_cases(rng: np.random.Generator) -> list[Case]:
    far = 6.45
    near = [round(float(x), 2) for x in rng.uniform(0.3, 0.75, 4)]
    return [
        Case(([far, far, far, far],), label="nothing in range"),
        Case(([far, near[0], near[1], far],), label="front blocked, sides equal: preferred side"),
        Case(([far, near[0], near[1], far],), {"prefer": "right"}, label="front blocked, prefer right"),
        Case(([near[2], 0.9, 1.0, far],), label="front blocked, less room on the left"),
        Case(([far, 1.1, 0.95, near[3]],), label="front blocked, less room on the right"),
        Case(([near[1], far, far, far],), label="left side only"),
        Case(([far, far, far, near[2]],), label="right side only"),
        Case(([1.0, 2.0, 3.0],), raises="ValueError", label="three ranges"),
        Case(([1.0, -2.0, 3.0, 4.0],), raises="ValueError", label="negative range"),
    ]


def _gains_cases(rng: np.random.Generator) -> list[Case]:
    taus = rng.uniform(0.15, 0.4, 3)
    return [
        Case((0.3, 0.05, 1.5), label="the lesson's spec"),
        Case((float(taus[0]), 0.10, 1.0), label="10 % overshoot, 1 s"),
        Case((float(taus[1]), 0.02, 1.2), label="2 % overshoot"),
        Case((float(taus[2]), 0.20, 0.8), label="20 % overshoot"),
        Case((0.3, 1.5, 1.0), raises="ValueError", label="overshoot not a fraction"),
        Case((0.3, 0.05, -1.0), raises="ValueError", label="negative settling time"),
        Case((0.3, 0.05, 30.0), raises="ValueError", label="too slow: would need kd < 0"),
    ]


EXERCISES = [
    Exercise(
        id="05.nmea_checksum",
        function="nmea_checksum",
        signature="nmea_checksum(sentence: str) -> str",
        points=1,
        cases=_checksum_cases,
        answer=nmea_checksum,
        compare=exact(),
        kind="warm-up",
        description="XOR of the characters between '$' and '*' as two upper-case hex digits.",
    ),
    Exercise(
        id="05.fix_position",
        function="fix_position",
        signature="fix_position(sentence: str) -> list[float]",
        points=2,
        cases=_position_cases,
        answer=fix_position,
        compare=close(rtol=0, atol=1e-9),
        kind="transcription",
        description="[lat, lon] in degrees from an RMC or GGA sentence; ValueError on bad input.",
    ),
    Exercise(
        id="05.haversine",
        function="haversine",
        signature="haversine(lat1, lon1, lat2, lon2) -> numpy.ndarray  # [distance_m, bearing_rad]",
        points=2,
        cases=_haversine_cases,
        answer=haversine_distance_bearing,
        compare=close(rtol=1e-9, atol=1e-6),
        kind="transcription",
        description="Great-circle distance (mean radius) and initial bearing in [0, 2 pi).",
    ),
    Exercise(
        id="05.pulse_to_distance",
        function="pulse_to_distance",
        signature="pulse_to_distance(pulse_width_us: float) -> dict  # {'inches': .., 'cm': ..}",
        points=1,
        cases=_pulse_cases,
        answer=pulse_width_to_cm_inches,
        compare=close(rtol=1e-9, atol=1e-9),
        kind="warm-up",
        description="LV-MaxSonar-EZ pulse width (147 us per inch) to inches and centimetres.",
    ),
    Exercise(
        id="05.avoidance_decision",
        function="avoidance_decision",
        signature="avoidance_decision(ranges, front=1.2, side=0.8, prefer='left') -> str",
        points=2,
        cases=_avoid_cases,
        answer=avoidance_decision,
        compare=exact(),
        kind="transcription",
        description="'forward', 'left' or 'right' from the four sonar ranges.",
    ),
    Exercise(
        id="05.heading_gains",
        function="heading_gains",
        signature="heading_gains(tau: float, overshoot: float, settling_time: float) -> numpy.ndarray  # [kp, kd]",
        points=2,
        cases=_gains_cases,
        answer=design_heading_gains,
        compare=close(rtol=1e-6, atol=1e-9),
        kind="derivation",
        description="Rate-feedback gains that place the closed-loop poles for an overshoot/settling spec.",
    ),
    Exercise(
        id="05.compass_bias",
        function="compass_bias",
        signature="compass_bias(fixes: (N, 2), compass_deg: (N,)) -> float  # degrees, in (-180, 180]",
        points=3,
        cases=_bias_cases,
        answer=compass_bias,
        compare=close(rtol=0, atol=1.0),
        kind="open",
        description="Open: a compass's constant error from a straight GPS drive, by any method, within 1 degree.",
    ),
]
