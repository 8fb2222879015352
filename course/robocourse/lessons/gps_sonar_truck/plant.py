"""The given plant of assignment 05's loop exercise: the truck, its GPS, compass and sonars, in plain numpy.

The grading worker has no robokit, so the notebook gives this code as a cell (the text below the
marker line ``# --- the notebook's cell ---``; tests/test_exercises_05_loop.py checks that the cell
is this text) and the student's controller is run against it. Every number it uses comes from the
course (a dict of plain data made by :mod:`.loop` from robokit's truck, receiver, compass and sonar
models); the grader does not trust it: :func:`.loop.mission_outcome` replays the commands on
robokit's :class:`~robokit.outdoor.SkidSteerTruck` and :class:`~robokit.outdoor.Field`.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] A. Mandow et al., "Experimental kinematics for wheeled skid-steer mobile robots", IROS 2007.
"""
from __future__ import annotations

# --- the notebook's cell ---
import math

import numpy as np


def truck_step(pose, wheels, command, dt, truck):
    """Advance the truck ``dt`` seconds under ``command = [left, right]`` wheel speeds (m/s).

    Parameters
    ----------
    pose : array_like, shape (3,)
        ``[x east, y north, theta]`` (m, m, rad counter-clockwise from east).
    wheels : array_like, shape (2,)
        The motors' speeds now (m/s).
    command : array_like, shape (2,)
        Set points, clipped to the truck's ``max_wheel_speed``.
    dt : float
    truck : dict
        ``track``, ``max_wheel_speed``, ``motor_tau``, ``icr_factor``, ``slip``.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The new pose and wheel speeds.

    Notes
    -----
    First-order motor lag, the skid-steer velocities of Mandow et al. (2007, Sec. III, with a slip
    factor) and the arc of constant speed and turn rate: ``robokit.outdoor.SkidSteerTruck.step``.
    """
    top = truck["max_wheel_speed"]
    cmd = np.clip(np.asarray(command, dtype=float), -top, top)
    wheels = np.asarray(wheels, dtype=float)
    new = wheels + (cmd - wheels) * (1 - math.exp(-dt / truck["motor_tau"]))     # motor lag
    left, right = (wheels + new) / 2
    k = 1 - truck["slip"]
    v, w = k * (left + right) / 2, k * (right - left) / (truck["icr_factor"] * truck["track"])
    x, y, th = pose
    turn = w * dt
    if abs(turn) < 1e-9:
        x, y = x + v * dt * math.cos(th + turn / 2), y + v * dt * math.sin(th + turn / 2)
    else:
        x, y = x + v / w * (math.sin(th + turn) - math.sin(th)), y + v / w * (math.cos(th) - math.cos(th + turn))
    return np.array([x, y, (th + turn + math.pi) % (2 * math.pi) - math.pi]), new


def sonar_range(pose, course, which):
    """Range (m) sonar ``which`` (0 outer left, 1 middle left, 2 middle right, 3 outer right) reads.

    The nearest obstacle along any of the rays fanned across the sensor's cone, clipped to the
    sensor's span and rounded to its resolution, as ``course["sonar"]`` describes.
    """
    s = course["sonar"]
    mx, my, yaw = s["mounts"][which]
    x, y, th = pose
    ox, oy = x + mx * math.cos(th) - my * math.sin(th), y + mx * math.sin(th) + my * math.cos(th)
    angles = th + yaw + np.linspace(-s["half_angle"], s["half_angle"], s["rays"])
    dx, dy = np.cos(angles), np.sin(angles)
    best = np.full(len(angles), np.inf)
    for cx, cy, r in course["circles"]:                   # |o + t d - c| = r
        fx, fy = ox - cx, oy - cy
        b, c = dx * fx + dy * fy, fx * fx + fy * fy - r * r
        disc = b * b - c
        t = np.where(c <= 0, 0.0, -b - np.sqrt(np.maximum(disc, 0.0)))
        best = np.where((disc >= 0) & (t >= 0), np.minimum(best, t), best)
    for cx, cy, length, width, yaw_box in course["boxes"]:    # slabs, in the box's frame
        cb, sb = math.cos(yaw_box), math.sin(yaw_box)
        px, py = (ox - cx) * cb + (oy - cy) * sb, -(ox - cx) * sb + (oy - cy) * cb
        ux, uy = dx * cb + dy * sb, -dx * sb + dy * cb
        near, far = np.zeros(len(angles)), np.full(len(angles), np.inf)
        for p, u, half in ((px, ux, length / 2), (py, uy, width / 2)):
            with np.errstate(divide="ignore", invalid="ignore"):
                t1, t2 = (-half - p) / u, (half - p) / u
            inside = abs(p) <= half
            lo = np.where(u == 0, np.where(inside, -np.inf, np.inf), np.minimum(t1, t2))
            hi = np.where(u == 0, np.where(inside, np.inf, -np.inf), np.maximum(t1, t2))
            near, far = np.maximum(near, lo), np.minimum(far, hi)
        best = np.where(near <= far, np.minimum(best, near), best)
    d = min(float(best.min()), s["max_range"])
    return round(max(d, s["min_range"]) / s["resolution"]) * s["resolution"]


def run_mission(course, controller):
    """Drive ``course`` with ``controller(fix, compass, ranges)``; return the commands it sent.

    Every ``course["dt"]`` seconds (one sonar slot) the controller is called with

    * ``fix``: ``[latitude, longitude]`` in degrees, every ``fix_every`` steps (``None`` between);
    * ``compass``: the heading in whole degrees clockwise from north, every ``compass_every``
      steps (``None`` between);
    * ``ranges``: the four sonars' latest ranges (m), ``[outer left, middle left, middle right,
      outer right]``; one sensor pings per step, in turn (the daisy chain);

    and returns ``[left, right]`` wheel speeds (m/s), or ``None`` to end the mission. The run also
    ends after ``course["steps"]`` steps.

    Returns
    -------
    list of [left, right]
        One command per step driven.
    """
    pose, wheels = np.array(course["start"], dtype=float), np.zeros(2)
    ranges = [course["sonar"]["max_range"]] * 4
    lat0, lon0 = np.radians(course["origin"])
    radius = course["earth_radius"]
    commands = []
    for k in range(course["steps"]):
        fix = compass = None
        if k % course["fix_every"] == 0:                 # the GPS error this fix carries (m, east and north)
            east, north = pose[:2] + course["gps_errors"][k // course["fix_every"]]
            fix = [math.degrees(lat0 + north / radius), math.degrees(lon0 + east / (radius * math.cos(lat0)))]
        if k % course["compass_every"] == 0:
            true = 90.0 - math.degrees(pose[2])
            compass = round(true + course["compass_errors"][k // course["compass_every"]]) % 360
        ranges[k % 4] = sonar_range(pose, course, k % 4)
        command = controller(fix, compass, list(ranges))
        if command is None:
            break
        pose, wheels = truck_step(pose, wheels, command, course["dt"], course["truck"])
        commands.append([float(command[0]), float(command[1])])
    return commands
