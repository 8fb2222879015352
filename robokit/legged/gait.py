"""Gaits of a quadruped: a statically stable crawl and a trot, planned in Cartesian terms.

A gait is a periodic pattern of stance and swing (:class:`GaitSchedule` of
:mod:`robokit.legged.gait_schedule`, re-exported here: period, duty factor, when in the cycle each
leg lifts). :func:`walking_plan` turns one into a walk: where the body is
and where every foot is at every host-loop instant (100 Hz on LittleDog, LittleDog User Guide,
Sec. 2), which feet are down, and the static stability margin of :mod:`robokit.legged.support`.
Leg inverse kinematics turns the foot positions into joint set-points. :func:`swing_trajectory`
is the path of a foot in the air.

* The crawl (:func:`crawl_gait`) lifts one leg at a time in the order hind-left, front-left,
  hind-right, front-right, the creeping sequence McGhee & Frank (1968) found the most stable of
  the six. Three feet are always down, so the robot can be statically stable at every instant -
  but only if the centre of mass is over the triangle of those three feet. The plan shifts the
  body while all four feet are down so that, before each leg lifts, the trunk centre is inside the
  triangle of the other three by at least ``margin``, and keeps it still while the leg swings.
* The trot (:func:`trot_gait`) swings diagonal pairs (front-left with hind-right, front-right
  with hind-left). Two feet are down for most of the cycle: a line, not a polygon, so static
  stability does not apply (the margin is ``-inf`` there); it balances dynamically. The body
  moves at constant speed.

Frames: world x forward (the walking direction), y left, z up; the body starts at the world origin
at ``body_height`` and stays level. Legs in the model's order ``("FL", "FR", "HL", "HR")``.

References
----------
.. [1] R. B. McGhee and A. A. Frank, "On the stability properties of quadruped creeping gaits",
   *Mathematical Biosciences* 3, 331-351, 1968.
.. [2] K. M. Lynch and F. C. Park, *Modern Robotics: Mechanics, Planning, and Control*, Cambridge
   University Press, 2017.
.. [3] Boston Dynamics, *LittleDog User Guide*, v1.0.2, 2006.
"""
from __future__ import annotations

import itertools
import math
from typing import Any, NamedTuple

import numpy as np

from ..validation import array_ndim, as_array, broadcast_to, as_positive, require_sample_count
from .gait_schedule import (CRAWL_SEQUENCE, TROT_PAIRS, GaitSchedule, as_gait_schedule, crawl_gait,
                            stance_pattern, trot_gait)
from .littledog import LEGS, STANCE_FEET, STANDING_HEIGHT
from .support import SupportPolygonError, nearest_boundary_point, stability_margins, support_polygon
from .terrain import Terrain, edge_distance, height_at

__all__ = ["FOOTHOLD_CLEARANCE", "GaitSchedule", "crawl_gait", "trot_gait", "stance_pattern", "swing_trajectory", "WalkPlan",
           "walking_plan", "CRAWL_SEQUENCE", "TROT_PAIRS"]

_EPS = 1e-9      # s and m: below this, two instants or two footholds are the same
#: Most steps (``distance / step_length``) a plan may take: a bound no walk comes near.
MAX_STEPS = 100_000
#: On terrain, how far (m) a foothold may move away from the body's middle to leave a board edge.
OUTWARD_SHIFT = 0.005
#: On terrain, how far (m) :func:`walking_plan` keeps footholds from board edges by default.
FOOTHOLD_CLEARANCE = 0.025


def _smoothstep(u: np.ndarray) -> np.ndarray:
    """Quintic rest-to-rest profile 10u^3 - 15u^4 + 6u^5: zero velocity and acceleration at 0 and 1."""
    return u ** 3 * (10.0 + u * (-15.0 + 6.0 * u))


def swing_trajectory(p_start: Any, p_end: Any, phase: Any, height: float) -> np.ndarray:
    """Foot positions along a swing from ``p_start`` to ``p_end``: zero velocity and acceleration
    at lift-off and at touchdown.

    Parameters
    ----------
    p_start, p_end : array_like, shape (3,) or (M, 3)
        Lift-off and touchdown positions (m, z up).
    phase : array_like, shape (M,) or scalar
        Fraction of the swing, in [0, 1].
    height : float
        Lift (m, >= 0) above the straight line from ``p_start`` to ``p_end``, reached at mid-swing.

    Returns
    -------
    numpy.ndarray, shape (M, 3) or (3,)

    Raises
    ------
    ValueError, TypeError
        For shapes that do not broadcast, phases outside [0, 1], a negative height or non-finite
        values.

    Notes
    -----
    A quintic, not a cycloid. Along the step the foot follows the rest-to-rest quintic time
    scaling ``s = 10 u^3 - 15 u^4 + 6 u^5`` (Lynch & Park 2017, Sec. 9.2.2.1, unnumbered: the
    fifth-order polynomial with zero velocity and acceleration at both ends); upward it adds
    ``height * 64 u^3 (1 - u)^3``, which peaks at 1 for ``u = 1/2``. Both have zero velocity AND
    zero acceleration at ``u = 0`` and ``u = 1``, so the foot leaves and meets the ground without a
    jump in the acceleration the joint servos must track. A cycloid (``z = h (1 - cos 2 pi u) / 2``)
    also starts and ends at rest but with vertical acceleration ``2 pi^2 h`` that switches on at
    lift-off and off at touchdown.

    Examples
    --------
    >>> swing_trajectory([0, 0, 0.01], [0.08, 0, 0.01], [0.0, 0.5, 1.0], 0.03).round(3).tolist()
    [[0.0, 0.0, 0.01], [0.04, 0.0, 0.04], [0.08, 0.0, 0.01]]
    """
    a = _as_positions(p_start, "p_start")
    b = _as_positions(p_end, "p_end")
    u = as_array(phase, "phase")
    if u.ndim > 1:
        raise ValueError(f"phase: expected a scalar or shape (M,), got shape {u.shape}")
    if not np.all((u >= 0) & (u <= 1)):
        raise ValueError(f"phase: expected fractions of the swing in [0, 1], got values from {u.min()} to {u.max()}")
    h = as_positive(height, "height", allow_zero=True)
    shape = np.broadcast_shapes(u.shape, a.shape[:-1], b.shape[:-1]) if _broadcasts(u, a, b) else None
    if shape is None:
        raise ValueError(f"phase, p_start, p_end: expected one phase per position (M,) with (M, 3) or (3,), "
                         f"got shapes {u.shape}, {a.shape}, {b.shape}")
    a, b = broadcast_to(a, shape + (3,), "p_start"), broadcast_to(b, shape + (3,), "p_end")
    out = a + _smoothstep(u)[..., None] * (b - a)
    out[..., 2] += h * 64.0 * (u * (1.0 - u)) ** 3
    return out


def _as_positions(value: Any, name: str) -> np.ndarray:
    shape = (3,) if array_ndim(value, name) <= 1 else (None, 3)
    return as_array(value, name, shape=shape)


def _broadcasts(u: np.ndarray, a: np.ndarray, b: np.ndarray) -> bool:
    try:
        np.broadcast_shapes(u.shape, a.shape[:-1], b.shape[:-1])
        return True
    except ValueError:
        return False


class WalkPlan(NamedTuple):
    """A walk sampled at the host-loop rate: body pose, feet, stance and static stability margin.

    Attributes
    ----------
    t : numpy.ndarray, shape (N,)
        Sample times (s) from 0, every ``dt``.
    T_world_body : numpy.ndarray, shape (N, 4, 4)
        The trunk centre's pose (level, facing +x).
    feet_world : numpy.ndarray, shape (N, 4, 3)
        Foot-sphere centres (m) in the world, legs ``FL, FR, HL, HR``.
    stance : numpy.ndarray of bool, shape (N, 4)
        Feet planned on the ground.
    margin : numpy.ndarray, shape (N,)
        Static stability margin (m) of the trunk centre over the stance feet
        (:func:`robokit.legged.support.stability_margins`); ``-inf`` with fewer than three feet down.
    gait : str
        The schedule's name (``"crawl"``, ``"trot"``), carried into trial logs.

    Examples
    --------
    >>> plan = walking_plan(trot_gait(), 0.1)
    >>> plan.feet_world.shape == (len(plan.t), 4, 3), bool(np.isneginf(plan.margin).any())
    (True, True)
    """

    t: np.ndarray
    T_world_body: np.ndarray
    feet_world: np.ndarray
    stance: np.ndarray
    margin: np.ndarray
    gait: str = ""


class _Swing(NamedTuple):
    leg: int
    lift: float          # gait time (s)
    touchdown: float
    start: np.ndarray    # (3,) world foothold left
    end: np.ndarray      # (3,) world foothold reached
    top: float | None = None       # on terrain: the height (m) the foot is carried across at


def _progress(tau: Any, distance: float, speed: float, ramp: float) -> np.ndarray:
    """Nominal forward progress from 0 to ``distance``: the speed rises to ``speed`` over ``ramp``
    seconds (quintic), cruises and falls back to 0 over ``ramp`` seconds; ``tau = 0`` is the start."""
    def ramped(u):          # integral of the quintic speed ramp: u - ramp / 2 once it is done
        s = np.clip(u / ramp, 0.0, 1.0)
        return np.where(s < 1, ramp * s ** 4 * (2.5 + s * (-3.0 + s)), u - ramp / 2)
    tau = np.asarray(tau, float)
    cruise = distance / speed
    x = speed * (ramped(tau) - ramped(tau - cruise))
    return np.where(tau >= cruise + ramp, distance, np.clip(x, 0.0, distance))    # exactly there at the end


def _swings(schedule: GaitSchedule, footholds: np.ndarray, distance: float, tau0: float) -> list[_Swing]:
    """Every swing of the walk, in time order: each foot lands where it is centred under its hip
    half-way through its next stance, on the nominal progress; swings that would not move it are
    skipped, and the walk ends when all four feet stand ``distance`` ahead of where they began."""
    T, beta = schedule.period, schedule.duty_factor
    final_x = footholds[:, 0] + distance
    order = np.argsort(schedule.phase_offsets, kind="stable")
    out, k = [], math.floor(tau0 / T) - 1
    while np.any(np.abs(footholds[:, 0] - final_x) > _EPS):
        for leg in order:
            lift = (k + schedule.phase_offsets[leg]) * T
            if lift < tau0 - _EPS:
                continue
            touchdown = lift + schedule.swing_duration
            x = _progress(touchdown + beta * T / 2 - tau0, distance, schedule.speed, T) + final_x[leg] - distance
            if abs(x - footholds[leg, 0]) > _EPS:
                end = footholds[leg].copy()
                end[0] = x
                out.append(_Swing(int(leg), lift, touchdown, footholds[leg].copy(), end))
                footholds[leg] = end
        k += 1
    return out


def _nearest_point_inside(triangle: np.ndarray, inset: float, point: np.ndarray, leg: str) -> np.ndarray:
    """The point of a counter-clockwise triangle shrunk by ``inset`` (every edge moved inwards)
    nearest to ``point``: the triangle's points with stability margin >= ``inset``."""
    edge = np.roll(triangle, -1, axis=0) - triangle
    side = np.linalg.norm(np.roll(edge, -1, axis=0), axis=1)          # side opposite each vertex
    area = 0.5 * (edge[0, 0] * edge[1, 1] - edge[0, 1] * edge[1, 0])
    r = 2 * area / side.sum()                                          # inradius
    if not r > inset:
        raise ValueError(f"margin: expected less than the inradius {r:.4f} m of the support triangle when {leg} "
                         f"lifts, got {inset:.4f} (shorter steps or a wider stance make room)")
    incentre = side @ triangle / side.sum()
    inner = incentre + (r - inset) / r * (triangle - incentre)        # shrinking about the incentre keeps edges parallel
    near, inside = nearest_boundary_point(inner, point, validate=False)
    return point if inside >= 0 else near


def _rest_to_rest(knot_t: np.ndarray, knot_p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Positions moving from knot to knot, each move a quintic rest-to-rest profile (C2 overall)."""
    k = np.clip(np.searchsorted(knot_t, t, side="right") - 1, 0, len(knot_t) - 2)
    span = knot_t[k + 1] - knot_t[k]
    u = np.clip((t - knot_t[k]) / np.where(span > 0, span, 1.0), 0.0, 1.0)
    s = _smoothstep(u)[:, None]
    return np.where(s < 1, knot_p[k] + s * (knot_p[k + 1] - knot_p[k]), knot_p[k + 1])   # exactly on the knots


def walking_plan(schedule: GaitSchedule, distance: float, *, nominal_feet: Any = None, body_height: float = STANDING_HEIGHT,
                 dt: float = 0.01, settle: float = 0.5, margin: float = 0.02, terrain: Terrain | None = None,
                 clearance: float = FOOTHOLD_CLEARANCE) -> WalkPlan:
    """Plan a straight walk of ``distance`` metres along +x, from standing to standing.

    Parameters
    ----------
    schedule : GaitSchedule
        :func:`crawl_gait`, :func:`trot_gait` or your own. A schedule that never lifts two legs at
        once is planned as a statically stable crawl, any other with the body at constant speed.
    distance : float
        How far (m, > 0) the body and every foot move.
    nominal_feet : array_like, shape (4, 3), optional
        Foot centres in the body frame when standing (legs ``FL, FR, HL, HR``); default LittleDog's
        ``(+-0.16, +-0.08, -0.1215)``.
    body_height : float, default :data:`~robokit.legged.littledog.STANDING_HEIGHT` (0.1315)
        Height (m) of the trunk centre; with the default feet the foot centres are at z = 0.01,
        the foot sphere's radius above the ground.
    dt : float, default 0.01
        Sample period (s): the 100 Hz host loop.
    settle : float, default 0.5
        Time (s, >= 0) standing still at the start and at the end.
    margin : float, default 0.02
        Crawl only: stability margin (m, > 0) the trunk centre must have over the three stance feet
        when a leg lifts.
    terrain : Terrain, optional
        The terrain map (:mod:`robokit.legged.terrain`) to plan on; default flat ground (the plan
        is then exactly the flat one, whatever ``clearance``).
    clearance : float, default :data:`FOOTHOLD_CLEARANCE` (0.025)
        With ``terrain``: how far (m, >= 0) a foothold must stay from every board edge.

    Returns
    -------
    WalkPlan
        The body starts at the world origin (feet at ``nominal_feet`` below it) and ends
        ``distance`` ahead with all four feet down in the same stance.

    Raises
    ------
    ValueError, TypeError
        For invalid arguments; a crawl schedule without a four-foot phase (``duty_factor`` 0.75:
        no time to shift the body); a ``margin`` that no point of some support triangle has (the
        triangle's inradius is smaller); more than ``MAX_STEPS`` steps or too many samples.

    Notes
    -----
    Footholds: each foot lands where it will be at its nominal place under the body half-way
    through its next stance, were the body moving along a nominal progress that accelerates over
    one period (quintic), cruises at ``step_length / period`` and stops at ``distance``. First and
    last steps are therefore shorter; a step that would not move a foot is skipped.

    Crawl (at most one leg up). The static stability criterion of McGhee & Frank (1968,
    unnumbered): the centre of mass over the support polygon. Before each lift-off the body moves,
    while all four feet are down, to the point nearest the nominal progress (at mid-swing) among
    those whose margin over the three feet that stay down is at least ``margin`` (that triangle
    shrunk by ``margin`` about its incentre); it stays there during the swing. The moves are quintic
    rest-to-rest (Lynch & Park 2017, Sec. 9.2.2.1), so the trunk's position, velocity and
    acceleration are continuous. The margin is then at least ``margin`` at every instant: during a
    swing the point is fixed; during a shift it moves on a straight line between two points that
    have the margin over triangles lying inside the four-foot polygon, and the margin over a convex
    polygon is concave along a line. The body accelerates only while four feet are down.

    Trot (two legs up): the body follows the nominal progress itself (constant speed between the
    ramps). Static stability does not apply: two stance feet span a line, and the margin is
    ``-inf`` except at the standing start and end.

    Terrain (footholds chosen on the map). Each foothold moves along x to the nearest point at
    least ``clearance`` from every board edge (:func:`~robokit.legged.terrain.edge_distance`; the
    least bad point if none is), looking up to half a step towards the body's middle and up to
    :data:`OUTWARD_SHIFT` away from it (the legs' reach); its height is the terrain's there
    (:func:`~robokit.legged.terrain.height_at`) plus the flat plan's, so the foot sphere rests on
    the board. A swing is carried: straight up to ``step_height`` above the highest of its start,
    its end and the boards along its way, across, and straight down, each move quintic
    rest-to-rest and timed by its length (the blended :func:`swing_trajectory`, tracked with the
    servos' lag, caught risers with the foot still low: measured in the MuJoCo simulation). The body stays
    level, ``body_height`` above the lowest terrain height under the four footholds (a leg on a
    board bends more; none stretches further than on the flat), and moves to each new one while
    the feet that change it swing (quintic rest-to-rest again, so it stays C2). The final stance is
    the flat one's unless a foothold had to leave an edge.

    The trunk's centre stands in for the centre of mass (the legs move it by millimetres). The
    plan does not check leg reach: that is the kinematics' job (the tests check it for LittleDog).

    Examples
    --------
    >>> plan = walking_plan(crawl_gait(), 0.2)
    >>> round(float(plan.t[-1]), 6), round(float(plan.T_world_body[-1, 0, 3]), 6), bool(plan.stance[-1].all())
    (17.6, 0.2, True)
    >>> round(float(plan.margin.min()), 6)
    0.02
    >>> from robokit.legged.terrain import Terrain
    >>> board = Terrain([[0.25, 0.6, -0.3, 0.3, 0.03]])              # a 3 cm board ahead
    >>> on = walking_plan(crawl_gait(), 0.2, terrain=board)
    >>> round(float(on.feet_world[-1, 0, 2]), 6), round(float(on.T_world_body[-1, 2, 3]), 6)   # FL on it
    (0.04, 0.1315)
    """
    schedule = as_gait_schedule(schedule)
    distance = as_positive(distance, "distance")
    feet0 = _standing_feet(nominal_feet)
    height = as_positive(body_height, "body_height")
    dt = as_positive(dt, "dt")
    settle = as_positive(settle, "settle", allow_zero=True)
    margin = as_positive(margin, "margin")
    clearance = as_positive(clearance, "clearance", allow_zero=True)
    if terrain is not None and not isinstance(terrain, Terrain):
        raise TypeError(f"terrain: expected a robokit.legged.Terrain or None, got {type(terrain).__name__}")
    T, beta = schedule.period, schedule.duty_factor
    if not distance / schedule.step_length <= MAX_STEPS:
        raise ValueError(f"distance, schedule: expected at most {MAX_STEPS} steps of step_length, got "
                         f"{distance / schedule.step_length:.3g}")
    require_sample_count((2 * settle + (distance / schedule.step_length + 4) * T) / dt, "distance, dt, settle, schedule")

    static = schedule.max_swinging == 1
    gaps = np.diff(np.sort(schedule.phase_offsets), append=schedule.phase_offsets.min() + 1) * T
    window = float(gaps.min() - schedule.swing_duration)          # four-foot time between swings
    if static and not window > _EPS:
        raise ValueError(f"schedule: a crawl shifts its body while four feet are down, expected a duty_factor above "
                         f"0.75 to leave time for it, got {beta}")
    tau0 = min(0.0, float(np.max(schedule.phase_offsets - beta)) * T)   # the last swing before 0 ended: start there
    footholds = feet0 + [0.0, 0.0, height]
    swings = _swings(schedule, footholds.copy(), distance, tau0)
    if terrain is not None:
        footholds, swings = _on_terrain(terrain, footholds, swings, schedule, clearance)

    def progress(tau):
        return _progress(np.asarray(tau) - tau0, distance, schedule.speed, T)

    if static:
        knots_t, knots_p = _crawl_body_knots(swings, footholds, progress, schedule.swing_duration, margin, tau0)
        knots_t.append(swings[-1].touchdown + window)                # the last shift: to standing, distance ahead
        knots_p.append(np.array([distance, 0.0]))
        tau_end = knots_t[-1]
    else:
        tau_end = max(swings[-1].touchdown, tau0 + distance / schedule.speed + T)
    t_walk = settle - tau0                                          # world time of gait time 0
    n = int(math.ceil((t_walk + tau_end + settle) / dt - _EPS)) + 1
    t = np.arange(n) * dt
    tau = t - t_walk
    if static:
        body_xy = _rest_to_rest(np.array(knots_t), np.array(knots_p), tau)
    else:
        body_xy = np.column_stack([progress(tau), np.zeros(n)])
    feet, stance = _feet_along(swings, footholds, tau, schedule.step_height)
    T_world_body = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    T_world_body[:, :2, 3], T_world_body[:, 2, 3] = body_xy, height
    if terrain is not None:
        T_world_body[:, 2, 3] += _body_rise(swings, footholds, feet0[:, 2] + height, tau, tau0)
    margins = stability_margins(feet[..., :2], stance, body_xy)
    return WalkPlan(t, T_world_body, feet, stance, margins, schedule.name)


def _standing_feet(nominal_feet: Any) -> np.ndarray:
    """The standing feet in the body frame (default LittleDog's), checked to span a support polygon."""
    feet0 = STANCE_FEET if nominal_feet is None else as_array(nominal_feet, "nominal_feet", shape=(4, 3))
    if not (np.all(feet0[:, 2] < 0) and np.all(np.abs(feet0) <= 10.0)):
        raise ValueError(f"nominal_feet: expected feet below the body (z < 0) within 10 m of it, got {feet0.tolist()}")
    try:
        support_polygon(feet0[:, :2])
    except ValueError as exc:
        raise ValueError(f"nominal_feet: the standing feet span no support polygon ({exc})") from None
    return feet0


def _crawl_body_knots(swings: list[_Swing], footholds: np.ndarray, progress: Any, swing_duration: float,
                      margin: float, tau0: float) -> tuple[list, list]:
    """A crawl's body stops: before each lift-off, the point nearest the nominal progress at mid-swing
    with ``margin`` over the three feet that stay down, held until touchdown (McGhee & Frank 1968)."""
    knots_t, knots_p, now = [tau0], [np.zeros(2)], footholds.copy()
    for sw in swings:
        others = [i for i in range(4) if i != sw.leg]
        try:
            triangle = support_polygon(now[others, :2])
        except SupportPolygonError:
            raise ValueError(f"nominal_feet: the three feet that stay down when {LEGS[sw.leg]} lifts are "
                             "collinear: no support triangle") from None
        goal = np.array([progress(sw.lift + swing_duration / 2), 0.0])
        target = _nearest_point_inside(triangle, margin + _EPS, goal, LEGS[sw.leg])
        knots_t += [sw.lift, sw.touchdown]
        knots_p += [target, target]
        now[sw.leg] = sw.end
    return knots_t, knots_p


def _feet_along(swings: list[_Swing], footholds: np.ndarray, tau: np.ndarray, step_height: float) -> tuple:
    """Every foot's world position and stance flag at gait times ``tau``: on the ground between swings,
    on :func:`swing_trajectory` during them."""
    feet = np.broadcast_to(footholds, (len(tau), 4, 3)).copy()
    stance = np.ones((len(tau), 4), bool)
    for sw in swings:
        i0, i1 = np.searchsorted(tau, [sw.lift - _EPS, sw.touchdown - _EPS])
        phase = np.clip((tau[i0:i1] - sw.lift) / (sw.touchdown - sw.lift), 0.0, 1.0)
        if sw.top is None:
            feet[i0:i1, sw.leg] = swing_trajectory(sw.start, sw.end, phase, step_height)
        else:
            feet[i0:i1, sw.leg] = _carried_swing(sw.start, sw.end, phase, sw.top)
        feet[i1:, sw.leg] = sw.end
        stance[i0:i1, sw.leg] = False
    return feet, stance


def _on_terrain(terrain: Terrain, footholds: np.ndarray, swings: list[_Swing], schedule: GaitSchedule,
                clearance: float) -> tuple[np.ndarray, list[_Swing]]:
    """The standing footholds and the swings of a flat plan moved onto the terrain map: each landing
    off the board edges and on the surface, each swing lifted over what lies on its way."""
    flat_z = footholds[:, 2]
    now = footholds.copy()
    now[:, 2] += height_at(terrain, now[:, :2])
    start = now.copy()
    inward = -np.sign([footholds[sw.leg, 0] for sw in swings])       # towards the middle of the body
    chosen = _flat_footholds(terrain, np.array([sw.end[:2] for sw in swings]), inward, clearance,
                             schedule.step_length / 2)
    out = []
    for sw, xy in zip(swings, chosen):
        end = np.array([xy[0], xy[1], flat_z[sw.leg] + height_at(terrain, xy)])
        path = now[sw.leg, :2] + np.linspace(0.0, 1.0, 17)[:, None] * (xy - now[sw.leg, :2])
        top = max(now[sw.leg, 2], end[2], flat_z[sw.leg] + float(height_at(terrain, path).max()))
        out.append(sw._replace(start=now[sw.leg].copy(), end=end, top=top + schedule.step_height))
        now[sw.leg] = end
    return start, out


def _flat_footholds(terrain: Terrain, xy: np.ndarray, inward: np.ndarray, clearance: float,
                    search: float) -> np.ndarray:
    """For each point (S, 2), the nearest point along x that is ``clearance`` from every board edge
    (5 mm candidates, inward first on a tie), else the farthest from one. The search runs ``search``
    towards the body's middle (``inward``, +-1 per point: the leg bends more) but only
    :data:`OUTWARD_SHIFT` away from it: the lesson's crawl already stretches its legs to within
    13 mm of their reach (10 mm let some plans reach too far)."""
    offsets = np.arange(-round(OUTWARD_SHIFT / 0.005), round(search / 0.005) + 1) * 0.005
    offsets = offsets[np.lexsort((-offsets, np.abs(offsets)))]
    candidates = xy[:, None, :] + (offsets[None, :] * inward[:, None])[..., None] * [1.0, 0.0]
    distance = edge_distance(terrain, candidates)
    ok = distance >= clearance
    pick = np.where(ok.any(axis=1), np.argmax(ok, axis=1), np.argmax(distance, axis=1))
    return candidates[np.arange(len(xy)), pick]


def _body_rise(swings: list[_Swing], footholds: np.ndarray, flat_z: np.ndarray, tau: np.ndarray,
               tau0: float) -> np.ndarray:
    """How far (m) the level body rises above the flat plan's height at gait times ``tau``: the lowest
    terrain height under the four footholds (so no leg stretches further than on flat ground),
    moved to each new one while the feet that change it swing (quintic rest-to-rest, so C2)."""
    now = footholds[:, 2] - flat_z
    knots_t, knots_z = [tau0], [now.min()]
    for (lift, touchdown), group in itertools.groupby(swings, key=lambda sw: (sw.lift, sw.touchdown)):
        before = now.min()
        for sw in group:
            now[sw.leg] = sw.end[2] - flat_z[sw.leg]
        knots_t += [lift, touchdown]
        knots_z += [before, now.min()]
    return _rest_to_rest(np.array(knots_t), np.array(knots_z)[:, None], tau)[:, 0]


def _carried_swing(start: np.ndarray, end: np.ndarray, phase: np.ndarray, top: float) -> np.ndarray:
    """A swing on terrain: straight up to ``top``, across, straight down, each a quintic rest-to-rest
    move (so C2) timed by its length: the foot is over no riser before it is above it."""
    lift, carry = np.array([start[0], start[1], top]), np.array([end[0], end[1], top])
    points = np.array([start, lift, carry, end])
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    knots = np.concatenate([[0.0], np.cumsum(lengths)]) / max(lengths.sum(), _EPS)
    return _rest_to_rest(knots, points, phase)
