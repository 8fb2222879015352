"""Waypoint navigation from NMEA text, with the four-sonar obstacle-avoidance state machine.

Hamid et al. (2009): the truck follows GPS waypoints; when a sonar sees an obstacle
it turns left or right (it has no rear sensor, so it never backs up), and once past the obstacle it
re-computes the bearing to the waypoint from its current position. :class:`Navigator` does exactly
that, reading only what the real truck reads - NMEA sentences from the GPS and compass (parsed with
:mod:`robokit.outdoor.nmea`) and the four sonar ranges - and writing a forward speed and yaw rate.

States: ``GOTO`` (steer the bearing to the waypoint), ``AVOID`` (turn on the spot away from the
obstacle until the front is clear), ``BYPASS`` (drive straight a short distance to get past it),
then ``GOTO`` again; ``DONE`` after the last waypoint.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..controllers import HeadingController, design_heading_gains
from ..geometry import wrap_angle
from ..validation import as_array, as_points, as_choice, as_positive
from .geodesy import LocalTangentPlane
from .gps import compass_to_heading
from .nmea import GGA, HDG, RMB, RMC, NMEAError, parse_sentence
from .truck import SkidSteerTruck

__all__ = ["avoidance_decision", "Navigator", "DECISIONS", "GUIDANCE"]

#: The three moves of the paper's avoidance behaviour.
DECISIONS = ("forward", "left", "right")
#: Where the bearing and distance to the waypoint come from: our own estimate, or the receiver's $GPRMB.
GUIDANCE = ("estimate", "rmb")


def avoidance_decision(ranges: Any, front: float = 1.2, side: float = 0.8, prefer: str = "left", *,
                       validate: bool = True) -> str:
    """Decide the move from the four sonar ranges ``[outer_left, middle_left, middle_right, outer_right]``.

    Parameters
    ----------
    ranges : array_like, shape (4,)
        Metres, in the order of :data:`robokit.outdoor.sonar.PAPER_LAYOUT`; ``inf`` (nothing in
        range) is accepted, NaN and negative ranges are not.
    front : float, default 1.2
        The front is blocked when a middle sensor reads less than this.
    side : float, default 0.8
        A side is blocked when its outer (45 degree) sensor reads less than this.
    prefer : {"left", "right"}, default "left"
        Turn used when both sides are equally free (e.g. the side of the waypoint).
    validate : bool, default True
        Check the arguments; ``False`` skips it (a controller's inner loop, with four floats).

    Returns
    -------
    str
        ``"forward"`` when nothing is blocked; otherwise ``"left"`` or ``"right"``: away from a
        blocked side, or, when the front is blocked, towards the side whose two sensors see more room.

    Raises
    ------
    ValueError
        Wrong shape, negative or NaN ranges, non-positive thresholds, unknown ``prefer``.

    Notes
    -----
    Hamid et al. (2009): the outer sensors watch the sides, the middle pair the
    front; the robot avoids by moving left or right only.
    """
    if validate:
        ranges = as_array(ranges, "ranges", shape=(4,), finite=False)
        if np.any(np.isnan(ranges)) or np.any(ranges < 0):
            raise ValueError(f"ranges: expected four non-negative distances, got {ranges.tolist()}")
        front, side = as_positive(front, "front"), as_positive(side, "side")
        as_choice(prefer, "prefer", ("left", "right"))
    outer_l, mid_l, mid_r, outer_r = ranges
    front_blocked = min(mid_l, mid_r) < front
    left_blocked, right_blocked = outer_l < side, outer_r < side
    if not (front_blocked or left_blocked or right_blocked):
        return "forward"
    if not front_blocked and left_blocked != right_blocked:
        return "right" if left_blocked else "left"
    room_l, room_r = min(outer_l, mid_l), min(outer_r, mid_r)
    if room_l > room_r:
        return "left"
    if room_r > room_l:
        return "right"
    return prefer


class Navigator:
    """GPS waypoint follower with sonar obstacle avoidance, fed with NMEA text.

    Parameters
    ----------
    waypoints : array_like, shape (K, 2)
        Waypoints as ``[latitude, longitude]`` in radians (what a receiver stores).
    truck : SkidSteerTruck
        The *nominal* model used to turn speed commands into wheel speeds (the real truck's slip
        may differ).
    cruise_speed : float, default 0.7
        Forward speed (m/s) on clear ground.
    arrival_radius : float, default 2.0
        A waypoint counts as reached when the position estimate is this close (m).
    gps_gain : float, default 0.3
        Weight of each GPS fix in the complementary filter that blends fixes with dead reckoning.
    front, side : float
        Thresholds of :func:`avoidance_decision`.
    bypass_distance : float, default 1.5
        Straight run (m) after the front clears, before heading for the waypoint again.
    bypass_side : float, default 0.35
        During that run a side counts as blocked only below this range (m), less than ``side``: the
        outer sensor on the obstacle's side sees the obstacle being passed, and without this
        hysteresis every such reading would send the truck back to AVOID (as AVOID's own exit test
        asks for more room than its entry test). Must not exceed ``side``.
    gains : array_like, optional
        ``[kp, kd]`` of the heading loop; default :func:`design_heading_gains` for 5 % overshoot
        and 1.5 s settling with the truck's motor lag.
    guidance : {"estimate", "rmb"}, default "estimate"
        ``"estimate"``: bearing and distance to the waypoint computed by us, in the local tangent
        plane, from the position estimate (GPS fixes blended with dead reckoning). ``"rmb"``: the
        receiver's own bearing and range from its latest ``$GPRMB`` about the active waypoint, as
        the paper's truck reads them, and arrival when that sentence's arrival status is "A" (the
        receiver's own test on the unrounded range; the range field's 0.001 nautical mile steps
        are 1.852 m); until such a sentence arrives the truck waits.

    Notes
    -----
    Position estimate: dead reckoning with the compass heading and the commanded speed, pulled
    towards each GPS fix (a complementary filter; e.g. Thrun et al. 2005, Sec. 3.2 in its
    steady-state, fixed-gain form).

    Examples
    --------
    >>> from robokit.outdoor.truck import PAPER_TRUCK
    >>> nav = Navigator(np.radians([[6.4594, 100.3509]]), PAPER_TRUCK)
    >>> nav.state, nav.arrival_radius, nav.bypass_distance, nav.side, nav.bypass_side
    ('GOTO', 2.0, 1.5, 0.8, 0.35)
    >>> nav.update([6.45, 6.45, 6.45, 6.45], 0.049)           # no GPS fix or compass heading yet: wait
    (0.0, 0.0)
    """

    def __init__(self, waypoints: Any, truck: SkidSteerTruck, *, cruise_speed: float = 0.7,
                 arrival_radius: float = 2.0, gps_gain: float = 0.3, front: float = 1.2, side: float = 0.8,
                 bypass_distance: float = 1.5, bypass_side: float = 0.35, gains: Any = None,
                 guidance: str = "estimate") -> None:
        wp = as_points(waypoints, "waypoints", 2, min_count=1)
        if np.any(np.abs(wp[:, 0]) >= np.pi / 2):
            raise ValueError("waypoints: expected [lat, lon] in radians with |lat| < pi/2 (did you pass degrees?)")
        if not isinstance(truck, SkidSteerTruck):
            raise TypeError(f"truck: expected a SkidSteerTruck, got {type(truck).__name__}")
        self.truck = truck
        self.plane = LocalTangentPlane(float(wp[0, 0]), float(wp[0, 1]))
        self.waypoints = self.plane.to_local(wp[:, 0], wp[:, 1]).reshape(-1, 2)
        self.cruise_speed = as_positive(cruise_speed, "cruise_speed")
        self.arrival_radius = as_positive(arrival_radius, "arrival_radius")
        self.gps_gain = as_positive(gps_gain, "gps_gain")
        self.front = as_positive(front, "front")
        self.side = as_positive(side, "side")
        self.bypass_distance = as_positive(bypass_distance, "bypass_distance")
        self.bypass_side = as_positive(bypass_side, "bypass_side")
        if self.bypass_side > self.side:
            raise ValueError(f"bypass_side: expected at most side = {self.side}, got {self.bypass_side}")
        kp, kd = design_heading_gains(truck.motor_tau, 0.05, 1.5) if gains is None else as_array(gains, "gains", shape=(2,))
        self.heading_loop = HeadingController(kp, kd, max_rate=0.8 * truck.max_turn_rate)
        self.guidance = as_choice(guidance, "guidance", GUIDANCE)
        self.rmb: tuple[float, float] | None = None     # latest (range m, field bearing rad) about the target
        self.rmb_arrived = False                         # and its arrival status
        self.state = "GOTO"
        self.target = 0
        self.position: np.ndarray | None = None
        self.heading: float | None = None
        self.turn = "left"
        self.bypassed = 0.0
        self.hold = 0.0
        self.parse_errors: list[NMEAError] = []
        self.arrivals: list[tuple[int, np.ndarray]] = []
        self._heading_age = 0.0

    # --- sensing -------------------------------------------------------------------------------

    def feed(self, line: str) -> None:
        """Read one NMEA sentence (GPS fix or compass); bad sentences are kept in :attr:`parse_errors`.

        Notes
        -----
        RMC position, RMB range and bearing to the active waypoint (kept when its destination id
        is ``f"{target + 1:03d}"``) and HDG heading, as the truck of Hamid et al. reads them (2009).
        """
        try:
            rec = parse_sentence(line)
        except NMEAError as exc:
            self.parse_errors.append(exc)
            return
        if isinstance(rec, RMB):
            if (rec.status == "A" and rec.destination_id == f"{self.target + 1:03d}"
                    and rec.range_m is not None and rec.bearing_deg is not None):
                self.rmb = (rec.range_m, compass_to_heading(rec.bearing_deg))
                self.rmb_arrived = rec.arrival == "A"
        elif isinstance(rec, HDG):
            if rec.heading_deg is not None:
                h = compass_to_heading(rec.true_heading_deg)
                self.heading_loop.measure(h, max(self._heading_age, 1e-3))
                self.heading, self._heading_age = h, 0.0
        elif isinstance(rec, (RMC, GGA)) and rec.latitude is not None and rec.longitude is not None:
            if (isinstance(rec, RMC) and not rec.valid) or (isinstance(rec, GGA) and not rec.valid):
                return
            if isinstance(rec, GGA):  # the RMC of the same fix already updated the estimate
                return
            fix = self.plane.to_local(math.radians(rec.latitude), math.radians(rec.longitude))
            if self.position is None:
                self.position = fix.astype(float)
            else:
                self.position = self.position + self.gps_gain * (fix - self.position)

    # --- acting --------------------------------------------------------------------------------

    @property
    def done(self) -> bool:
        """True once every waypoint has been reached."""
        return self.state == "DONE"

    def update(self, ranges: Any, dt: float) -> tuple[float, float]:
        """One control step: latest sonar ``ranges`` (4,) in metres -> ``(v, omega)`` command.

        Returns ``(0, 0)`` until the first GPS fix and compass heading have arrived.

        Notes
        -----
        GOTO / AVOID / BYPASS behaviour of Hamid et al. (2009); see the module docstring.
        """
        r = as_array(ranges, "ranges", shape=(4,), finite=False)
        h = as_positive(dt, "dt")
        self._heading_age += h
        if self.position is None or self.heading is None or self.state == "DONE":
            return 0.0, 0.0
        distance, bearing = self._to_target()
        if self.rmb_arrived if self.guidance == "rmb" else distance < self.arrival_radius:
            self.arrivals.append((self.target, self.position.copy()))
            self.target, self.rmb, self.rmb_arrived = self.target + 1, None, False
            if self.target == len(self.waypoints):
                self.state = "DONE"
                return 0.0, 0.0
            distance, bearing = self._to_target()
        if math.isnan(bearing):     # "rmb": no sentence about this waypoint yet
            return 0.0, 0.0
        side_of_goal = "left" if wrap_angle(bearing - self.heading) > 0 else "right"
        decision = avoidance_decision(r, self.front, self.side, prefer=side_of_goal)
        v, reference = self._behave(decision, bearing, r, h)
        omega = self.heading_loop.command(reference, self.heading)
        if self.state == "AVOID":
            omega = math.copysign(0.6 * self.truck.max_turn_rate, 1.0 if self.turn == "left" else -1.0)
        if self.heading is not None:  # dead reckoning between GPS fixes
            self.position = self.position + v * h * np.array([math.cos(self.heading), math.sin(self.heading)])
        return v, omega

    def _to_target(self) -> tuple[float, float]:
        """Distance (m) and field bearing (rad) to the active waypoint, from :attr:`guidance`'s source."""
        if self.guidance == "rmb":
            return self.rmb if self.rmb is not None else (math.inf, math.nan)
        delta = self.waypoints[self.target] - self.position
        return math.hypot(*delta), math.atan2(delta[1], delta[0])

    def _behave(self, decision: str, bearing: float, r: np.ndarray, dt: float) -> tuple[float, float]:
        if self.state == "GOTO":
            if decision != "forward":
                self.state, self.turn = "AVOID", decision
            else:
                err = wrap_angle(bearing - self.heading)
                return self.cruise_speed * max(0.0, math.cos(err)) ** 2, bearing
        if self.state == "AVOID":
            clear = min(r[1], r[2]) > self.front * 1.3 and r[0 if self.turn == "left" else 3] > self.side
            if clear:
                self.state, self.bypassed, self.hold = "BYPASS", 0.0, self.heading
            else:
                return 0.0, self.heading
        # BYPASS: straight on past the obstacle, unless something blocks the way (sides: hysteresis)
        decision = avoidance_decision(r, self.front, self.bypass_side, prefer=self.turn)
        if decision != "forward":
            self.state = "AVOID"
            if decision != self.turn and min(r[1], r[2]) >= self.front:
                self.turn = decision
            return 0.0, self.heading
        v = 0.6 * self.cruise_speed
        self.bypassed += v * dt
        if self.bypassed >= self.bypass_distance:
            self.state = "GOTO"
        return v, self.hold
