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
from robokit.outdoor.geodesy import EARTH_MEAN_RADIUS
from robokit.outdoor.nmea import fix_position, nmea_checksum
from robokit.outdoor.nmea_write import format_sentence, gga_sentence, hdg_sentence, random_sentences, rmc_sentence
from robokit.outdoor.sonar import pulse_width_to_cm_inches
from robokit.validation import as_array, as_points
from robocourse.exercises.compare import close, exact
from robocourse.exercises.plain import summarize
from robocourse.exercises.spec import Case, Exercise
from robocourse.lessons.gps_sonar_truck.loop import course_case, drive_course, make_controller, mission_outcome
from robocourse.lessons.gps_sonar_truck.plant import run_mission

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


def local_offset(origin, point) -> list:
    """East and north offsets (m) of ``point`` from ``origin`` in a flat map about the origin, on the sphere.

    Parameters
    ----------
    origin, point : array_like, shape (2,)
        ``[latitude, longitude]`` in degrees (north and east positive).

    Returns
    -------
    list of float
        ``[east, north]`` in metres: ``north = R dphi`` along the origin's meridian and
        ``east = R cos(phi0) dlambda`` along its parallel (a circle of radius ``R cos(phi0)``), with
        ``R`` the mean Earth radius and ``dlambda`` wrapped to (-180, 180] degrees.

    Raises
    ------
    ValueError
        For a latitude outside [-90, 90] or a longitude outside [-180, 180] degrees, or not two
        numbers per point.

    Notes
    -----
    The equirectangular map about the origin: the first-order local plane of the sphere, which
    robokit's :class:`~robokit.outdoor.geodesy.LocalTangentPlane` refines with the ellipsoid's two
    radii; over a football field it agrees with the haversine distance (Hamid et al. 2009 steer by
    it) to far below the GPS error.

    Examples
    --------
    >>> east, north = local_offset([0.0, 0.0], [0.001, 0.001])
    >>> round(east, 3), round(north, 3)
    (111.195, 111.195)
    """
    (lat0, lon0), (lat, lon) = (as_array(x, name, shape=(2,)) for x, name in ((origin, "origin"), (point, "point")))
    for name, la, lo in (("origin", lat0, lon0), ("point", lat, lon)):
        if abs(la) > 90 or abs(lo) > 180:
            raise ValueError(f"{name}: expected [latitude, longitude] in degrees within +-90 and +-180, got "
                             f"{[float(la), float(lo)]}")
    dlon = -((180.0 - (lon - lon0)) % 360.0 - 180.0)           # wrapped to (-180, 180]
    return [float(EARTH_MEAN_RADIUS * np.cos(np.radians(lat0)) * np.radians(dlon)),
            float(EARTH_MEAN_RADIUS * np.radians(lat - lat0))]


def _position_diagnosis(name: str, e: float, g: float) -> str:
    """What a wrong coordinate says about how the field was read (``e`` the truth, ``g`` the answer)."""
    deg = np.floor(abs(e))
    minutes = (abs(e) - deg) * 60
    if abs(g + e) < 1e-6:
        return f"{name}: right size, wrong sign: the hemisphere letter after the {name} field sets it"
    for read, why in ((deg + minutes / 100, "the minutes read as hundredths of a degree (a minute is 1/60 degree)"),
                      (deg * 100 + minutes, "the field returned as written: degrees and minutes run together"),
                      ((deg * 100 + minutes) / 100, "the field divided by 100: its minutes are not hundredths")):
        if abs(abs(g) - read) < 1e-6:
            return f"{name}: {g:.9f} is {why}"
    return f"{name}: expected {e:.9f}, got {g:.9f} (off by {g - e:.6g} degrees)"


def _same_position(expected, got) -> str | None:
    """Accept ``[lat, lon]`` within 1e-9 degrees; name the coordinate and what went wrong with it."""
    try:
        g = np.array(got, dtype=float)
    except (TypeError, ValueError):
        return f"expected [latitude, longitude] as two numbers, got {summarize(got)}"
    if g.shape != (2,):
        return f"expected [latitude, longitude] as two numbers, got {summarize(got)}"
    e = np.asarray(expected, dtype=float)
    if np.all(np.abs(g - e) <= 1e-9):
        return None
    if np.all(np.abs(g[::-1] - e) <= 1e-9):
        return "latitude and longitude swapped: the latitude field comes first"
    return "; ".join(_position_diagnosis(n, float(a), float(b))
                     for n, a, b in zip(("latitude", "longitude"), e, g) if abs(b - a) > 1e-9)


def _same_offset(expected, got) -> str | None:
    """Accept ``[east, north]`` within 1 mm plus ``3 d^2 / R`` of the answer (``d`` its distance): any
    sound local plane of the task's sphere (radius ``EARTH_RADIUS``) differs from the equirectangular map
    by about ``d^2 / R`` times a factor that grows with the latitude's tangent; the cases stay below 60
    degrees and 2 km. An ellipsoid's plane (robokit's :class:`~robokit.outdoor.geodesy.LocalTangentPlane`)
    differs by 0.1-0.4 % of ``d`` and is rejected: the task fixes the sphere. Name the offset that is
    wrong and the likely term."""
    try:
        g = np.array(got, dtype=float)
    except (TypeError, ValueError, OverflowError):
        return f"expected [east, north] in metres, got {summarize(got)}"
    if g.shape != (2,):
        return f"expected [east, north] in metres, got {summarize(got)}"
    e = np.asarray(expected, dtype=float)
    d = float(np.hypot(*e))
    tol = 1e-3 + 3 * d * d / EARTH_MEAN_RADIUS
    if np.all(np.abs(g - e) <= tol):
        return None
    if np.all(np.abs(g[::-1] - e) <= tol):
        return "east and north swapped: [east, north] is [along the parallel, along the meridian]"
    notes = []
    for name, a, b, hint in (("east", e[0], g[0], "the longitude term: how long is a degree of longitude at "
                              "this latitude (the parallel is a circle of radius R cos(latitude))?"),
                             ("north", e[1], g[1], "the latitude term: an arc of the meridian, a circle of radius R")):
        if abs(b - a) <= tol:
            continue
        ratio = b / a if abs(a) > 1e-6 else float("nan")
        if abs(ratio + 1) < 1e-3:
            notes.append(f"{name} has the wrong sign")
        elif any(abs(ratio - k) < 1e-3 * k for k in (180 / np.pi, np.pi / 180)):
            notes.append(f"{name} is {ratio:.4g} times ours: degrees and radians mixed up")
        else:
            notes.append(f"{name}: expected {a:.4f} m, got {b:.4f} m ({ratio:.4f} times ours; check {hint})")
    return "; ".join(notes)


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
        Case((gga_sentence(when.time(), -float(rng.uniform(1, 9)), float(rng.uniform(1, 9))),),
             label="GGA near the equator and the prime meridian: leading zeros"),
        Case(("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A",), label="textbook RMC"),
        Case((bad_checksum,), raises="ValueError", label="wrong checksum"),
        Case((too_far,), raises="ValueError", label="latitude above 90 degrees"),
        Case(("$GNRMC,,V,,,,,,,,,,N*4D",), raises="ValueError", label="no fix: empty position"),
        Case((hdg_sentence(120.0),), raises="ValueError", label="not a position sentence"),
    ]


def _destination(lat0: float, lon0: float, d: float, bearing: float) -> list:
    """``[lat, lon]`` (degrees) ``d`` metres from ``[lat0, lon0]`` along the great circle at ``bearing`` (rad)."""
    p1, l1, delta = np.radians(lat0), np.radians(lon0), d / EARTH_MEAN_RADIUS
    p2 = np.arcsin(np.sin(p1) * np.cos(delta) + np.cos(p1) * np.sin(delta) * np.cos(bearing))
    l2 = l1 + np.arctan2(np.sin(bearing) * np.sin(delta) * np.cos(p1), np.cos(delta) - np.sin(p1) * np.sin(p2))
    return [round(float(np.degrees(p2)), 9), round(float((np.degrees(l2) + 180) % 360 - 180), 9)]


def _offset_cases(rng: np.random.Generator) -> list[Case]:
    field = [6.459, 100.3505]                                   # the lesson's field (UNIMAP_ORIGIN)
    far_north = [round(float(rng.uniform(50, 60)), 6), round(float(rng.uniform(-20, 20)), 6)]
    south = [round(float(rng.uniform(-45, -30)), 6), round(float(rng.uniform(140, 150)), 6)]
    line = [round(float(rng.uniform(-10, 10)), 6), 179.9995]
    cases = [Case((field, _destination(*field, round(float(rng.uniform(30, 50)), 1), np.radians(60.0))),
                  label="the lesson's field: a waypoint tens of metres away at 60 degrees"),
             Case((field, _destination(*field, float(rng.uniform(5, 80)), float(rng.uniform(0, 2 * np.pi)))),
                  label="across the football field"),
             Case((far_north, _destination(*far_north, float(rng.uniform(300, 1500)), float(rng.uniform(0.3, 1.2)))),
                  label="far north, mostly east: a degree of longitude is short there"),
             Case((south, _destination(*south, float(rng.uniform(300, 1500)), float(rng.uniform(3.5, 4.5)))),
                  label="southern hemisphere, south-west"),
             Case((line, _destination(*line, float(rng.uniform(100, 200)), np.pi / 2)),
                  label="across the date line, due east"),
             Case((field, field), label="the origin itself")]
    return cases + [Case(([95.0, 10.0], field), raises="ValueError", label="a latitude beyond the pole"),
                    Case((field, [6.459]), raises="ValueError", label="a point without a longitude")]


def _course_cases(rng: np.random.Generator) -> list[Case]:
    seeds = [int(s) for s in rng.integers(0, 2 ** 31, 3)]
    cases = [course_case(s, label=f"course {i + 1}") for i, s in enumerate(seeds)]
    empty = dict(cases[0].args[0], waypoints=[])
    return cases + [Case((empty,), raises="ValueError", label="a course without waypoints")]


def _stand_still(course):
    return [[0.0, 0.0]] * course["steps"]


def _full_ahead(course):
    return [[course["truck"]["max_wheel_speed"]] * 2] * course["steps"]


def _sonars_off(course):
    return run_mission(course, make_controller(course, front=1e-9, side=1e-9))


def _truth_for_fixes(course):
    return drive_course(dict(course, gps_errors=[[0.0, 0.0]] * len(course["gps_errors"])))


#: Ways to a loop case's answer without the loop: standing still, full speed ahead, the reference
#: with its sonars off (GPS only: the posts are where it drives), and the reference steering by
#: the true position instead of the fixes (what a controller that simulates the plant itself knows).
COURSE_SHORTCUTS = {"stand still": _stand_still, "full speed ahead": _full_ahead,
                    "GPS only, the sonars ignored": _sonars_off, "the true position instead of the fixes": _truth_for_fixes}


def _pulse_cases(rng: np.random.Generator) -> list[Case]:
    widths = rng.uniform(882, 37338, 3)  # 6 to 254 inches
    return [Case((147.0,), label="one inch"), Case((14700.0,), label="100 inches")] + \
        [Case((float(w),), label="inside the sensor's range") for w in widths] + \
        [Case((-10.0,), raises="ValueError", label="negative width"),
         Case((float("nan"),), raises="ValueError", label="NaN")]


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
        compare=_same_position,
        kind="derivation",
        description="[lat, lon] in signed degrees from an RMC or GGA sentence, the fields' places and the "
                    "degrees-and-minutes format worked out from the receiver's examples; ValueError on bad input.",
    ),
    Exercise(
        id="05.local_offset",
        function="local_offset",
        signature="local_offset(origin: [lat, lon], point: [lat, lon]) -> [east_m, north_m]  # degrees in",
        points=2,
        cases=_offset_cases,
        answer=local_offset,
        compare=_same_offset,
        kind="derivation",
        description="The flat east-north map about a point, derived from the sphere (arcs of the meridian and "
                    "of the parallel); any sound local plane of that sphere (within 1 mm + 3 d^2 / R) passes.",
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
        points=2,
        cases=_bias_cases,
        answer=compass_bias,
        compare=close(rtol=0, atol=1.0),
        kind="open",
        description="Open: a compass's constant error from a straight GPS drive, by any method, within 1 degree.",
    ),
    Exercise(
        id="05.drive_course",
        function="drive_course",
        signature="drive_course(course: dict) -> list of [left, right]  # the wheel commands sent",
        points=3,
        cases=_course_cases,
        answer=drive_course,
        compare=mission_outcome,
        kind="loop",
        shortcuts=COURSE_SHORTCUTS,
        description="Loop: the truck's controller (fixes to distance and bearing, compass heading loop, sonar "
                    "avoidance, waypoint after waypoint) run on the given plant over hidden seeded courses; the "
                    "commands are replayed on robokit's truck: every waypoint reached by a fix within the "
                    "radius, in order, no contact, within the step budget; ValueError without waypoints.",
    ),
]
