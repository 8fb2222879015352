"""The corridor moving strategy: bring the robot onto the middle line, facing along the corridor.

Ge et al. (2023), Sec. 3.1, give the conditions the robot must reach (Eq. (4), ``|d_L - d_R| <=
e4``, with the door rule after it) and say that "the robot can slightly adjust its position and
orientation" until they hold; they give no control law. The law here is ours: a unicycle aims at a
point on the middle line a look-ahead distance ahead (the pure-pursuit idea of Coulter 1992), turns
in place while its heading is far from that aim, and drives slowly otherwise. Every command comes
from the scan alone (:func:`robokit.mapping.corridor_scan.corridor_state`), never from the true pose.

Frames: ``lateral_offset`` is the robot's offset from the middle line, positive to the left of the
corridor direction it will face; ``heading_error`` is its heading minus that direction. Robokit
poses are ``[x, y, theta]`` where the paper writes ``(x, z, theta)``.

References
----------
.. [1] Ge, Zhang, Wang, Hu, Wang and Jiang, "Visual-feature-assisted mobile robot localization in
   a long corridor environment", *Frontiers of Information Technology & Electronic Engineering*
   24(6), 2023, doi:10.1631/FITEE.2200208.
.. [2] R. C. Coulter, "Implementation of the pure pursuit path tracking algorithm", Technical
   Report CMU-RI-TR-92-01, Carnegie Mellon University, 1992.
.. [3] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..geometry import wrap_angle
from ..mapping.corridor_areas import as_scan
from ..mapping.corridor_scan import CorridorState, corridor_state
from ..sim import Lidar, World, unicycle_step
from ..validation import as_array, as_rng, as_choice, as_finite_scalar, as_int, as_positive

__all__ = ["centering_command", "CenteringResult", "move_to_middle_line"]

# the command law's defaults (centering_command), which move_to_middle_line drives with
_LOOKAHEAD, _K_OMEGA, _K_V, _V_MIN, _V_MAX, _W_MAX = 0.15, 1.5, 0.5, 0.02, 0.15, 0.6


def centering_command(lateral_offset: float, heading_error: float, *, lookahead: float = _LOOKAHEAD,
                      k_omega: float = _K_OMEGA, k_v: float = _K_V, v_min: float = _V_MIN, v_max: float = _V_MAX,
                      w_max: float = _W_MAX, deadband: float = 0.0) -> tuple[float, float]:
    """Speed and turn rate ``(v, omega)`` that bring a unicycle onto the corridor's middle line.

    Parameters
    ----------
    lateral_offset : float
        Offset ``y`` from the middle line, positive to the left (m).
    heading_error : float
        Heading ``e`` minus the corridor direction to face (rad).
    lookahead : float, default 0.15
        Distance ``L`` ahead on the middle line that the robot aims at (m).
    k_omega : float, default 1.5
        Proportional gain of the turn rate on the aiming error (1/s).
    k_v : float, default 0.5
        Speed per metre of offset (1/s), between ``v_min`` and ``v_max`` (m/s).
    v_min, v_max, w_max : float
        Speed floor and limits (m/s, m/s, rad/s); ``v_min <= v_max``.
    deadband : float, default 0
        Within this offset (m) the robot only turns to face along the corridor (``v = 0``).

    Returns
    -------
    (v, omega) : float, float

    Notes
    -----
    Ours (Ge et al. 2023, Sec. 3.1 give the goal, Eq. (4), not the law). Aim ``e* = -arctan(y /
    L)``; ``omega = sat(k_omega wrap(e* - e), w_max)``; ``v = clip(k_v |y|, v_min, v_max)
    max(0, cos(e* - e))^2``, so the robot turns in place while its heading is more than 90 deg from
    the aim and never drives away from it; inside ``deadband`` it turns in place onto the corridor
    direction (``e* = 0``), so it does not creep on while its heading settles. Near the line ``dy/dt = v sin e`` with ``e -> e*``
    gives ``dy/dt ~ -(v / L) y``: the offset decays with time constant ``L / v`` (stable for any
    ``v > 0``). A short ``L`` makes the path nearly turn-drive-turn: a little over ``|y|`` long.

    Examples
    --------
    >>> v, w = centering_command(0.3, 0.0)       # left of the line, facing along: turn right, drive
    >>> round(v, 4), round(w, 4)
    (0.03, -0.6)
    >>> [round(u, 4) for u in centering_command(0.005, 0.1, deadband=0.01)]   # inside: turn only
    [0.0, -0.15]
    """
    y = as_finite_scalar(lateral_offset, "lateral_offset")
    e = as_finite_scalar(heading_error, "heading_error")
    L = as_positive(lookahead, "lookahead")
    kw, kv = as_positive(k_omega, "k_omega"), as_positive(k_v, "k_v")
    vmin, vmax = as_positive(v_min, "v_min", allow_zero=True), as_positive(v_max, "v_max")
    wmax = as_positive(w_max, "w_max")
    band = as_positive(deadband, "deadband", allow_zero=True)
    if vmin > vmax:
        raise ValueError(f"v_min: expected at most v_max = {vmax}, got {vmin}")
    return _command(y, e, L, kw, kv, vmin, vmax, wmax, band)


def _command(y: float, e: float, L: float, kw: float, kv: float, vmin: float, vmax: float, wmax: float,
             band: float) -> tuple[float, float]:
    """:func:`centering_command` of checked arguments."""
    inside = abs(y) <= band
    delta = float(wrap_angle((0.0 if inside else -np.arctan2(y, L)) - e, validate=False))   # aim minus heading
    omega = float(np.clip(kw * delta, -wmax, wmax))
    v = 0.0 if inside else float(np.clip(kv * abs(y), vmin, vmax) * max(0.0, np.cos(delta)) ** 2)
    return v, omega + 0.0


@dataclasses.dataclass(frozen=True)
class CenteringResult:
    """The run of :func:`move_to_middle_line`.

    Attributes
    ----------
    poses : numpy.ndarray, shape (K, 3)
        True poses, the start first.
    reached : bool
        The last ``settle`` scans all satisfied the stop rule.
    distance_moved : float
        Path length driven (m; turning in place adds nothing).
    final : CorridorState
        Analysis of the last scan.
    lateral_offset, heading_error : float
        The last estimates (m, rad), relative to the direction faced.
    """

    poses: np.ndarray
    reached: bool
    distance_moved: float
    final: CorridorState
    lateral_offset: float
    heading_error: float


def move_to_middle_line(world: World, pose: Any, lidar: Lidar, *, rng: Any = 0, tol: float = 0.04,
                        heading_tol: float = np.deg2rad(2.0), max_steps: int = 600, dt: float = 0.1,
                        direction: Any = None, width: Any = None, recess: Any = None,
                        settle: int = 3) -> CenteringResult:
    """Drive a simulated robot onto the middle line, facing along the corridor, from its scans alone.

    Parameters
    ----------
    world : World
        A corridor world (e.g. :func:`robokit.sim.long_corridor`).
    pose : array_like, shape (3,)
        True start pose ``[x, y, theta]``; only the simulator uses it.
    lidar : Lidar
        The scanner (its ``r_max`` is Eq. (6)-(7)'s ``r_max``).
    rng : Generator or int, default 0
        Range noise.
    tol : float, default 0.04
        ``e4`` of Eq. (4) (m). The loop stops when the estimated offset is within ``tol / 4`` (half
        of Eq. (4)'s band, a margin for range noise) and the heading error within ``heading_tol``
        on ``settle`` consecutive scans.
    heading_tol : float, default 2 deg
    max_steps : int, default 600
    dt : float, default 0.1
        Control period (s).
    direction : {None, "nearest", "opposite"}, default None
        Face the corridor direction nearer the start heading (``None``, ``"nearest"``) or the
        other one. A corridor scan cannot tell its two directions apart, so this is the only choice.
    width, recess : float, optional
        Corridor width and door recess (m); default ``world.info["width"]`` and ``["recess"]``
        (map knowledge, not the pose).
    settle : int, default 3

    Returns
    -------
    CenteringResult
        ``reached`` is false when ``max_steps`` ran out or a scan showed no corridor walls.

    Notes
    -----
    Ge et al. (2023), Sec. 3.1: scan, analyse (:func:`robokit.mapping.corridor_scan.corridor_state`:
    Eqs. (1)-(4), (9)), command (:func:`centering_command`, ours), move (the unicycle arc, Thrun et
    al. 2005, Eq. (5.9), :func:`robokit.sim.unicycle_step`). The corridor axis is known modulo pi
    from a scan; the loop keeps the branch nearest the previous heading error (it turns at most
    ``w_max dt`` per step), and the offset changes sign when the branch faces the other way.

    Examples
    --------
    >>> from robokit.sim import Lidar, long_corridor
    >>> res = move_to_middle_line(long_corridor(), [15.0, 0.4, 0.5], Lidar(noise=0.01))
    >>> res.reached, bool(abs(res.poses[-1, 1]) < 0.02), bool(abs(np.rad2deg(res.poses[-1, 2])) < 2.0)
    (True, True, True)
    >>> round(res.distance_moved, 2)
    0.77
    """
    if not isinstance(world, World):
        raise TypeError(f"world: expected a robokit.sim World, got {type(world).__name__}")
    if not isinstance(lidar, Lidar):
        raise TypeError(f"lidar: expected a robokit.sim Lidar, got {type(lidar).__name__}")
    p = as_array(pose, "pose", shape=(3,))
    gen = as_rng(rng)
    e4 = as_positive(tol, "tol")
    etol = as_positive(heading_tol, "heading_tol")
    steps = as_int(max_steps, "max_steps", minimum=0, maximum=10 ** 6)
    dt = as_positive(dt, "dt")
    opposite = as_choice("nearest" if direction is None else direction, "direction",
                            ["nearest", "opposite"]) == "opposite"
    w = as_positive(world.info.get("width", np.nan) if width is None else width, "width")
    dda = as_positive(world.info.get("recess", 0.0) if recess is None else recess, "recess", allow_zero=True)
    n_settle = as_int(settle, "settle", minimum=1)
    poses, dist, good = [p.copy()], 0.0, 0
    e_prev, y, e = None, 0.0, 0.0
    # the arguments are checked here once and each scan by as_scan: the scan's analysis and the command trust them
    for _ in range(steps + 1):
        r, a = as_scan(lidar.scan(world, p, gen), lidar.angles)
        state = corridor_state(r, a, w, lidar.r_max, recess=dda, tol=e4, validate=False)
        if state.lateral_offset is None:
            break
        e0 = -state.axis                                    # heading error to the nearer direction
        if e_prev is None:
            e_prev = e0 + (np.pi if opposite else 0.0)
        k = int(np.round((e_prev - e0) / np.pi))           # the branch nearest the last estimate
        e = e0 + k * np.pi
        y = -state.lateral_offset if k % 2 else state.lateral_offset
        e_prev = e
        heading = float(wrap_angle(e, validate=False))
        good = good + 1 if abs(y) <= e4 / 4 and abs(heading) <= etol else 0
        if good >= n_settle or len(poses) > steps:
            break
        v, omega = _command(y, heading, _LOOKAHEAD, _K_OMEGA, _K_V, _V_MIN, _V_MAX, _W_MAX, e4 / 4)
        p = unicycle_step(p, v, omega, dt, validate=False)
        poses.append(p)
        dist += abs(v) * dt
    return CenteringResult(np.array(poses), good >= n_settle, float(dist), state, float(y),
                           float(wrap_angle(e)))
