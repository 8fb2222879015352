"""Assignment 05's loop exercise: drive the lesson's truck through a seeded course, graded on the outcome.

The student assembles the truck's software of Hamid et al. (2009) into one controller: GPS fixes
to distance and bearing, the compass into a heading loop, the four sonars into avoidance, waypoint
after waypoint. The worker runs it against the plain-numpy plant of :mod:`.plant` and returns the
commands it sent; :func:`mission_outcome` replays them on robokit's truck in robokit's field and
judges what happened: each waypoint reached in order (a GPS fix of the run within the arrival
radius, the test the truck itself can make), no contact with an obstacle, within the step budget.

Cases are the lesson's courses (:func:`robokit.outdoor.random_course`, a smaller field), the lesson's
real truck (slip and track expansion drawn as :func:`robokit.outdoor.simulate` draws them), the
receiver's wandering error (:class:`robokit.outdoor.GPSReceiver`) and the compass's error
(:class:`robokit.outdoor.Compass`) drawn in advance.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
"""
from __future__ import annotations

import dataclasses
import inspect
import math
from typing import Any

import numpy as np

from robokit.validation import as_positive
from robokit.controllers.heading import design_heading_gains
from robokit.outdoor import (PAPER_LAYOUT, PAPER_TRUCK, Compass, Course, Field, GPSReceiver, LVMaxSonarEZ, Navigator,
                             SkidSteerTruck, TruckState, avoidance_decision, haversine_distance_bearing, random_course)
from robokit.outdoor.field import UNIMAP_ORIGIN
from robokit.outdoor.geodesy import EARTH_MEAN_RADIUS, LocalTangentPlane
from robocourse.lessons.gps_sonar_truck.plant import run_mission, truck_step
from robocourse.exercises.spec import Case

__all__ = ["COURSE", "FRONT", "SIDE", "CRUISE_SPEED", "NAVIGATOR", "POSTS", "nominal_truck", "course_case",
           "make_controller", "drive_course", "mission_outcome", "replay"]

_NAV = inspect.signature(Navigator).parameters
#: The lesson's avoidance thresholds (m) and cruise speed (m/s): :class:`robokit.outdoor.Navigator`'s.
FRONT, SIDE, CRUISE_SPEED = _NAV["front"].default, _NAV["side"].default, _NAV["cruise_speed"].default
#: The lesson navigator's settings, handed to the student with each course as a starting point: its
#: thresholds, speeds and bypass (:class:`robokit.outdoor.Navigator`), and the heading loop's spec
#: (overshoot fraction, 2 % settling time in s) it designs its gains for.
NAVIGATOR = {"front": FRONT, "side": SIDE, "cruise_speed": CRUISE_SPEED,
             "bypass_side": _NAV["bypass_side"].default, "bypass_distance": _NAV["bypass_distance"].default,
             "overshoot": 0.05, "settling_time": 1.5}
#: The loop cases' courses: :func:`robokit.outdoor.random_course` on a smaller field than the
#: lesson's 100 m x 60 m (two legs of 12 m or more), with most obstacles on the legs; the arrival
#: radius (m); GPS fix and compass periods in control steps (the lesson's 1 Hz and every other step).
COURSE = {"size": (40.0, 30.0), "n_waypoints": 2, "n_obstacles": 5, "on_path": 0.6, "arrival_radius": 2.5,
          "fix_every": 20, "compass_every": 2, "dt": 0.049}
#: Posts added on each leg where a truck that trusts its fixes will really drive: the leg shifted
#: against the GPS error of the moment it gets there (radius range m, where along the leg, and the
#: room kept from the other obstacles, the start and the waypoints, m).
POSTS = {"radius": (0.3, 0.6), "along": (0.25, 0.75), "gap": 2.5, "clear": 4.0, "tries": 8}
#: Rays fanned across each sonar's cone.
SONAR_RAYS = 9


def nominal_truck() -> dict:
    """The paper's truck as the controller knows it (the real one's slip and track expansion differ).

    Examples
    --------
    >>> nominal_truck()["track"], nominal_truck()["icr_factor"]
    (0.21, 1.5)
    """
    t = dataclasses.asdict(PAPER_TRUCK)
    return {k: float(t[k]) for k in ("track", "max_wheel_speed", "motor_tau", "icr_factor", "slip")}


def _sonar() -> dict:
    s = LVMaxSonarEZ()
    return {"mounts": [[m.x, m.y, m.yaw] for m in PAPER_LAYOUT], "half_angle": s.half_angle, "rays": SONAR_RAYS,
            "min_range": s.min_range, "max_range": s.max_range, "resolution": s.resolution}


def course_case(seed: int, label: str = "a course") -> Case:
    """One loop case: the course the worker drives (args) and what the replay needs (``expected``).

    Parameters
    ----------
    seed : int
        Seeds the course (:func:`robokit.outdoor.random_course`), the real truck and the sensor errors.
    label : str

    Returns
    -------
    Case
        ``args = (course,)``, a dict of plain data (see :func:`.plant.run_mission`); ``expected`` holds
        the course in field metres for :func:`mission_outcome`.
    """
    shape = {k: COURSE[k] for k in ("size", "n_waypoints", "n_obstacles", "on_path")}
    course = random_course(seed, **shape)
    rng = np.random.default_rng(seed + 1_000_003)
    real = dataclasses.replace(PAPER_TRUCK, slip=float(rng.uniform(0.02, 0.12)),      # as simulate() draws them
                               icr_factor=float(rng.uniform(1.3, 1.8)))
    legs = np.vstack([course.start[:2], course.waypoints])
    straight = float(np.sum(np.hypot(*np.diff(legs, axis=0).T)))
    dt = COURSE["dt"]
    steps = int(math.ceil((2 * straight / CRUISE_SPEED + 60.0) / dt))
    gps_errors = np.round(_gps_errors(len(range(0, steps, COURSE["fix_every"])), rng), 3).tolist()
    compass = Compass(rng=rng)
    n = len(range(0, steps, COURSE["compass_every"]))
    bound = math.degrees(compass.bound)
    compass_errors = np.round(np.clip(math.degrees(compass.bias) + rng.normal(0, math.degrees(compass.noise), n),
                                      -bound, bound), 3)
    lat0, lon0 = UNIMAP_ORIGIN
    R = EARTH_MEAN_RADIUS
    waypoints = [[math.degrees(lat0 + y / R), math.degrees(lon0 + x / (R * math.cos(lat0)))]
                 for x, y in course.waypoints]
    truck = {k: float(getattr(real, k)) for k in ("track", "max_wheel_speed", "motor_tau", "icr_factor", "slip")}
    args = {"dt": dt, "steps": steps, "fix_every": COURSE["fix_every"], "compass_every": COURSE["compass_every"],
            "arrival_radius": COURSE["arrival_radius"], "origin": [math.degrees(lat0), math.degrees(lon0)],
            "earth_radius": R, "waypoints": waypoints, "start": np.round(course.start, 4).tolist(),
            "truck": truck, "model": nominal_truck(), "navigator": dict(NAVIGATOR), "sonar": _sonar(), "gps_errors": gps_errors, "compass_errors": compass_errors.tolist()}
    expected = {"start": args["start"], "waypoints": course.waypoints.tolist(), "size": list(course.field.size),
                "truck": dict(truck, length=real.length, width=real.width), "gps_errors": gps_errors,
                "fix_every": COURSE["fix_every"], "steps": steps, "dt": dt, "arrival_radius": COURSE["arrival_radius"]}
    course = _with_posts(course, args, expected, rng)
    circles, boxes = course.field.circles.round(3).tolist(), course.field.boxes.round(3).tolist()
    args.update(circles=circles, boxes=boxes)
    expected.update(circles=circles, boxes=boxes)
    return Case((args,), label=f"{label}: {len(circles) + len(boxes)} obstacles, {straight:.0f} m of legs, "
                               f"budget {steps} steps", expected=expected)


def _gps_errors(n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` successive errors (m, east and north) of the lesson's receiver (:class:`robokit.outdoor.GPSReceiver`
    with its default parameters): a Gauss-Markov bias plus white noise, one per fix (its ``fix``'s update)."""
    gps = GPSReceiver(LocalTangentPlane(*UNIMAP_ORIGIN), rng=rng)
    phi = math.exp(-gps.period / gps.tau)
    bias, out = gps.bias, np.empty((n, 2))
    for k in range(n):
        bias = phi * bias + math.sqrt(1 - phi * phi) * gps.noise * rng.normal(size=2)
        out[k] = bias + gps.white_noise * rng.normal(size=2)
    return out


def _with_posts(course: Any, args: dict, expected: dict, rng: np.random.Generator) -> Any:
    """``course`` with a post on each leg of the path a truck that trusts its fixes really drives.

    Such a truck steers its fixes onto the waypoints, so it drives off the straight legs by the GPS
    error of the moment and passes beside most obstacles placed on the legs themselves; the posts
    go where the reference controller, with its sonars off, truly drives on this course.
    """
    poses = _blind_poses(args)
    arrivals = _arrivals(poses, expected, len(poses))[0]
    legs = np.vstack([course.start[:2], course.waypoints])
    field, posts, begin = course.field, [], 0
    for end in arrivals:
        r = rng.uniform(*POSTS["radius"])
        for f in rng.uniform(*POSTS["along"], POSTS["tries"]):       # the first place with room around it
            centre = poses[begin + int(f * (end - begin)), :2]
            if (not field.n_obstacles or field.clearance(centre[None])[0] >= r + POSTS["gap"]) and \
                    np.hypot(*(legs - centre).T).min() >= r + POSTS["clear"]:
                posts.append([*centre, r])
                break
        begin = end
    if not posts:
        return course
    circles = np.vstack([field.circles.reshape(-1, 3), posts])
    return Course(Field(size=field.size, circles=circles, boxes=field.boxes if len(field.boxes) else None,
                        origin=field.origin), course.waypoints, course.start)


def _blind_poses(args: dict) -> np.ndarray:
    """The true poses of :func:`make_controller`'s run with its sonars off (nothing in range):
    :func:`.plant.run_mission`'s loop without the sonars' rays, for speed."""
    step, pose, wheels = make_controller(args), np.array(args["start"], dtype=float), np.zeros(2)
    lat0, lon0 = np.radians(args["origin"])
    R, nothing, poses = args["earth_radius"], [args["sonar"]["max_range"]] * 4, [pose]
    for k in range(args["steps"]):
        fix = compass = None
        if k % args["fix_every"] == 0:
            east, north = pose[:2] + args["gps_errors"][k // args["fix_every"]]
            fix = [math.degrees(lat0 + north / R), math.degrees(lon0 + east / (R * math.cos(lat0)))]
        if k % args["compass_every"] == 0:
            compass = round(90.0 - math.degrees(pose[2]) + args["compass_errors"][k // args["compass_every"]]) % 360
        command = step(fix, compass, nothing)
        if command is None:
            break
        pose, wheels = truck_step(pose, wheels, command, args["dt"], args["truck"])
        poses.append(pose)
    return np.array(poses)


def _wheels(v: float, omega: float, truck: dict) -> list:
    """``[left, right]`` for forward speed ``v`` and counter-clockwise turn rate ``omega`` on ``truck``."""
    k = 1 - truck["slip"]
    top = truck["max_wheel_speed"]
    half = min(max(omega * truck["icr_factor"] * truck["track"] / (2 * k), -top), top)
    base = min(max(v / k, -(top - abs(half))), top - abs(half))      # the turn first, speed with what is left
    return [base - half, base + half]


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def make_controller(course: dict, front: float = FRONT, side: float = SIDE):
    """The reference controller for :func:`.plant.run_mission`: ``step(fix, compass, ranges)``.

    GOTO (steer the bearing from the latest fix, slow down while it is off), AVOID (turn on the spot
    away from the obstacle until the front is clear), BYPASS (a short straight run) as the lesson's
    :class:`robokit.outdoor.Navigator`; arrival when a fix is within the arrival radius; ``None``
    after the last waypoint. Angles kept clockwise from north, as the compass and the bearing are.
    """
    if not course["waypoints"]:
        raise ValueError("course: expected at least one waypoint, got none")
    truck, nav = course["model"], course["navigator"]
    wps = np.radians(course["waypoints"])
    kp, kd = design_heading_gains(truck["motor_tau"], nav["overshoot"], nav["settling_time"])
    max_turn = 2 * truck["max_wheel_speed"] * (1 - truck["slip"]) / (truck["icr_factor"] * truck["track"])
    dt, period = course["dt"], course["dt"] * course["compass_every"]
    st = {"mode": "GOTO", "target": 0, "bearing": None, "heading": None, "rate": 0.0, "turn": "left", "run": 0.0}

    def step(fix, compass, ranges):
        if compass is not None:
            h = math.radians(compass)
            if st["heading"] is not None:
                st["rate"] = _wrap(h - st["heading"]) / period
            st["heading"] = h
        if fix is not None:
            d, b = haversine_distance_bearing(math.radians(fix[0]), math.radians(fix[1]), *wps[st["target"]])
            if d < course["arrival_radius"]:
                st["target"] += 1
                if st["target"] == len(wps):
                    return None
                d, b = haversine_distance_bearing(math.radians(fix[0]), math.radians(fix[1]), *wps[st["target"]])
            st["bearing"] = b
        if st["heading"] is None or st["bearing"] is None:
            return [0.0, 0.0]
        v, ref = _behave(st, ranges, front, side, nav)
        rate_cw = min(max(kp * _wrap(ref - st["heading"]) - kd * st["rate"], -0.8 * max_turn), 0.8 * max_turn)
        if st["mode"] == "AVOID":
            rate_cw = 0.6 * max_turn * (-1.0 if st["turn"] == "left" else 1.0)
        st["run"] += v * dt if st["mode"] == "BYPASS" else 0.0
        return _wheels(v, -rate_cw, truck)

    return step


def _behave(st: dict, r: list, front: float, side: float, nav: dict) -> tuple[float, float]:
    """The avoidance state machine: ``(forward speed, reference heading)``, updating ``st``."""
    err = _wrap(st["bearing"] - st["heading"])
    if st["mode"] == "GOTO":
        decision = avoidance_decision(r, front, side, "left" if err < 0 else "right", validate=False)
        if decision == "forward":
            return nav["cruise_speed"] * max(0.0, math.cos(err)) ** 2, st["bearing"]
        st["mode"], st["turn"] = "AVOID", decision
    if st["mode"] == "AVOID":
        if min(r[1], r[2]) > 1.3 * front and r[0 if st["turn"] == "left" else 3] > side:
            st["mode"], st["run"], st["hold"] = "BYPASS", 0.0, st["heading"]
        else:
            return 0.0, st["heading"]
    # past the obstacle: side hysteresis
    decision = avoidance_decision(r, front, nav["bypass_side"], st["turn"], validate=False)
    if decision != "forward":
        st["mode"] = "AVOID"
        if decision != st["turn"] and min(r[1], r[2]) >= front:
            st["turn"] = decision
        return 0.0, st["heading"]
    if st["run"] >= nav["bypass_distance"]:
        st["mode"] = "GOTO"
    return 0.6 * nav["cruise_speed"], st["hold"]


def drive_course(course: dict, front: float = FRONT, side: float = SIDE) -> list:
    """The loop exercise's reference: :func:`make_controller` driven by :func:`.plant.run_mission`.

    Parameters
    ----------
    course : dict
        A loop case's course (:func:`course_case`).
    front, side : float
        Avoidance thresholds (m), the lesson navigator's.

    Returns
    -------
    list of [left, right]
        The wheel commands sent, one per step.

    Raises
    ------
    TypeError, ValueError
        For a course that is not a dict of a case's keys, a course without waypoints, or thresholds
        that are not positive numbers.
    """
    if not isinstance(course, dict):
        raise TypeError(f"course: expected a dict (a loop case's course), got {type(course).__name__}")
    missing = sorted({"waypoints", "model", "navigator", "dt", "compass_every", "arrival_radius"} - set(course))
    if missing:
        raise ValueError(f"course: missing keys {missing}")
    front, side = as_positive(front, "front"), as_positive(side, "side")
    return run_mission(course, make_controller(course, front, side))


def replay(expected: dict, commands: Any) -> dict:
    """Drive robokit's truck by ``commands`` on the case's course: poses, fixes, arrivals, first contact.

    Returns
    -------
    dict
        ``poses`` (n + 1, 3), ``fixes`` (list of (step, east, north)), ``arrivals`` (step of the fix
        that reached each waypoint, in order), ``contact`` (step of the first contact or ``None``).
    """
    e = expected
    t = e["truck"]
    truck = SkidSteerTruck(track=t["track"], max_wheel_speed=t["max_wheel_speed"], motor_tau=t["motor_tau"],
                           icr_factor=t["icr_factor"], slip=t["slip"], length=t["length"], width=t["width"])
    field = Field(size=e["size"], circles=e["circles"] or None, boxes=e["boxes"] or None)
    state, poses = TruckState(np.array(e["start"], dtype=float)), [np.array(e["start"], dtype=float)]
    for cmd in commands:
        state = truck.step(state, cmd, e["dt"], validate=False)
        poses.append(state.pose)
    poses = np.array(poses)
    reach = math.hypot(t["length"], t["width"]) / 2
    near = np.flatnonzero(field.clearance(poses[1:, :2]) <= reach) + 1 if field.n_obstacles else []
    contact = next((int(k) for k in near if field.collides(poses[k], t["length"], t["width"])), None)
    last = min(len(commands) + 1, e["steps"]) if contact is None else contact
    arrivals, fixes = _arrivals(poses, e, last)
    return {"poses": poses, "fixes": fixes, "arrivals": arrivals, "contact": contact}


def _arrivals(poses: np.ndarray, e: dict, last: int) -> tuple[list, list]:
    """Steps of the fixes (before step ``last``) that reached each waypoint in order, and every fix
    ``(step, east, north)``."""
    wps, radius, target, arrivals, fixes = np.array(e["waypoints"]), e["arrival_radius"], 0, [], []
    for k in range(0, min(last, len(poses)), e["fix_every"]):
        fix = poses[k, :2] + e["gps_errors"][k // e["fix_every"]]
        fixes.append((k, *fix))
        if target < len(wps) and math.hypot(*(fix - wps[target])) < radius:
            arrivals.append(k)
            target += 1
    return arrivals, fixes


def _commands(got: Any, steps: int) -> np.ndarray | str:
    """The answer as an (n, 2) float array, or why it is not one."""
    if not isinstance(got, list):
        return f"expected a list of [left, right] wheel speeds, one per step, got {type(got).__name__}"
    try:
        arr = np.array(got, dtype=float).reshape(len(got), -1) if got else np.zeros((0, 2))
    except (TypeError, ValueError):
        return "expected a list of [left, right] pairs of numbers (one per step)"
    if arr.shape[1:] != (2,):
        return f"expected [left, right] pairs, got rows of {arr.shape[1]} values"
    if not np.all(np.isfinite(arr)):
        return f"every command must be finite: step {int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])} is not"
    if len(arr) > steps:
        return f"{len(arr)} commands, more than the course's budget of {steps} steps"
    return arr


def mission_outcome(expected: dict, got: Any) -> str | None:
    """Accept the commands when, replayed on robokit's truck (:func:`replay`), every waypoint is reached
    in order by a fix within the arrival radius and the truck touches no obstacle.

    Feedback shows the run: when each waypoint was reached, or the closest fix and the closest true
    approach to the first one missed; the contact (time, place, heading); the true position every
    20 s.
    """
    if not isinstance(expected, dict) or "truck" not in expected:
        return "expected a course's commands"
    cmd = _commands(got, expected["steps"])
    if isinstance(cmd, str):
        return cmd
    run = replay(expected, cmd)
    wps, dt, arrivals = np.array(expected["waypoints"]), expected["dt"], run["arrivals"]
    if run["contact"] is None and len(arrivals) == len(wps):
        return None
    notes = [f"waypoint {i + 1} reached at {k * dt:.1f} s" for i, k in enumerate(arrivals)]
    i = len(arrivals)
    if i < len(wps):
        after = arrivals[-1] if arrivals else -1
        fixes = [f for f in run["fixes"] if f[0] > after] or run["fixes"][-1:]
        k, x, y = min(fixes, key=lambda f: math.hypot(f[1] - wps[i][0], f[2] - wps[i][1]))
        true = np.hypot(*(run["poses"][max(after, 0):, :2] - wps[i]).T).min()
        notes.append(f"waypoint {i + 1} of {len(wps)} not reached: the closest fix was "
                     f"{math.hypot(x - wps[i][0], y - wps[i][1]):.1f} m away at {k * dt:.1f} s (arrival radius "
                     f"{expected['arrival_radius']} m; the truck itself came within {true:.1f} m)")
    if run["contact"] is not None:
        x, y, th = run["poses"][run["contact"]]
        notes.append(f"the truck touched an obstacle at {run['contact'] * dt:.1f} s at ({x:.1f}, {y:.1f}) m, "
                     f"heading {(90 - math.degrees(th)) % 360:.0f} deg from north: the run ends there")
    elif len(cmd) >= expected["steps"]:
        notes.append(f"the step budget ({expected['steps']} steps, {expected['steps'] * dt:.0f} s) ran out")
    else:
        notes.append(f"the controller ended the run after {len(cmd)} steps ({len(cmd) * dt:.1f} s)")
    every = int(round(20.0 / dt))
    path = " ".join(f"({p[0]:.0f}, {p[1]:.0f})" for p in run["poses"][::every][:12])
    return "; ".join(notes) + f"; true position (m, east and north) every 20 s from the start: {path}"
