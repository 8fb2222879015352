"""Robot motion: odometry noise and the paths the lessons drive (kinematics: :mod:`robokit.sim.vehicle`).

Planar poses are ``[x, y, theta]`` (see :mod:`robokit.geometry`). The odometry noise model is the
four-parameter model of Thrun et al. (2005), Sec. 5.4: a motion between two poses is
decomposed into a rotation ``delta_rot1``, a translation ``delta_trans`` and a rotation
``delta_rot2`` (Table 5.5), each corrupted by zero-mean Gaussian noise whose variance grows with
the motion (Table 5.6, ``sample_motion_model_odometry``):

    var(rot1) = a1 rot1^2 + a2 trans^2,  var(trans) = a3 trans^2 + a4 (rot1^2 + rot2^2),
    var(rot2) = a1 rot2^2 + a2 trans^2.

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features",
   IEEE/RSJ International Conference on Intelligent Robots and Systems (IROS), 2002.
.. [3] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering*, 2023,
   doi:10.1631/FITEE.2200208.
.. [4] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..geometry import wrap_angle
from ..geometry.planar import as_planar
from ..validation import (as_array, as_points, as_rng, require_finite_result, as_positive, require_sample_count,
                          describe)
from .world import World

__all__ = ["odometry_increment", "increment_variances", "odometry_covariance", "sample_motion_model_odometry",
           "noisy_odometry", "Trajectory", "waypoint_path",
           "corridor_path", "lab_lap", "office_tour", "OFFICE_TOUR", "OFFICE_TEST_POSES"]


#: Odometry steps shorter than this (m) are turns on the spot to :func:`odometry_covariance`.
SPOT_TURN = 0.01


def odometry_increment(previous: Any, current: Any) -> np.ndarray:
    """Decompose the motion between two poses into ``[delta_rot1, delta_trans, delta_rot2]``.

    Parameters
    ----------
    previous, current : array_like, shape (3,) or (N, 3)

    Returns
    -------
    numpy.ndarray, shape (3,) or (N, 3)

    Notes
    -----
    Thrun et al. (2005), Table 5.5 lines 2-4 (``rot1 = 0`` for a pure rotation).

    Examples
    --------
    >>> np.round(odometry_increment([0.0, 0.0, 0.0], [1.0, 1.0, 0.0]), 4).tolist()   # turn, drive, turn back
    [0.7854, 1.4142, -0.7854]
    """
    a = as_array(previous, "previous")
    b = as_array(current, "current")
    if a.shape != b.shape or a.shape[-1:] != (3,):
        raise ValueError(f"current: expected the shape of previous {a.shape} with 3 columns, got {b.shape}")
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    trans = np.hypot(dx, dy)                                                          # Table 5.5, line 3
    rot1 = np.where(trans > 1e-12, wrap_angle(np.arctan2(dy, dx) - a[..., 2]), 0.0)  # line 2
    rot2 = wrap_angle(b[..., 2] - a[..., 2] - rot1)                                   # line 4
    return np.stack([rot1, trans, rot2], axis=-1)


def _alphas(alphas: Any) -> np.ndarray:
    a = as_array(alphas, "alphas", shape=(4,))
    if np.any(a < 0):
        raise ValueError(f"alphas: expected four non-negative noise parameters, got {a.tolist()}")
    return a


def increment_variances(delta: Any, alphas: Any) -> np.ndarray:
    """Variances of the noise on odometry increments ``[delta_rot1, delta_trans, delta_rot2]``.

    Parameters
    ----------
    delta : array_like, shape (3,) or (N, 3)
        Increments from :func:`odometry_increment`.
    alphas : array_like, shape (4,)
        Noise parameters ``a1..a4`` (non-negative).

    Returns
    -------
    numpy.ndarray, same shape as ``delta``
        ``[a1 rot1^2 + a2 trans^2, a3 trans^2 + a4 (rot1^2 + rot2^2), a1 rot2^2 + a2 trans^2]``.

    Notes
    -----
    Thrun et al. (2005), Table 5.6, lines 5-7 (the arguments of ``sample``).

    Examples
    --------
    >>> increment_variances([0.0, 1.0, 0.5], [0.01, 0.001, 0.01, 0.001]).tolist()
    [0.001, 0.01025, 0.0035]
    """
    d = as_array(delta, "delta")
    if d.shape[-1:] != (3,) or d.ndim > 2:
        raise ValueError(f"delta: expected shape (3,) or (N, 3), got shape {d.shape}")
    out = _increment_variances(d, _alphas(alphas))
    require_finite_result("delta, alphas", out)
    return out


def _increment_variances(d: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Unchecked :func:`increment_variances` (float arrays)."""
    r1, t, r2 = d[..., 0], d[..., 1], d[..., 2]
    return np.stack([a[0] * r1 ** 2 + a[1] * t ** 2,                     # Table 5.6, line 5
                     a[2] * t ** 2 + a[3] * (r1 ** 2 + r2 ** 2),          # line 6
                     a[0] * r2 ** 2 + a[1] * t ** 2], axis=-1)            # line 7


def _perturb(delta: np.ndarray, a: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    sd = np.sqrt(_increment_variances(delta, a))
    noise = rng.standard_normal(delta.shape)
    return np.stack([delta[..., 0] - sd[..., 0] * noise[..., 0], delta[..., 1] - sd[..., 1] * noise[..., 1],
                     delta[..., 2] - sd[..., 2] * noise[..., 2]], axis=-1)


def odometry_covariance(odometry: Any, alphas: Any) -> np.ndarray:
    """Covariance of each odometry pose relative to the first, propagated to first order.

    Parameters
    ----------
    odometry : array_like, shape (N, 3)
        Consecutive odometry poses ``[x, y, theta]`` (N >= 1).
    alphas : array_like, shape (4,)
        The noise parameters an estimator assumes for them (Table 5.6).

    Returns
    -------
    numpy.ndarray, shape (N, 3, 3)
        ``Sigma_k``: covariance of ``se2_between(odometry[0], odometry[k])``; ``Sigma_0 = 0``.

    Raises
    ------
    ValueError
        For bad shapes, NaN/inf or negative alphas.

    Notes
    -----
    Each step's increment ``u = (trans cos rot1, trans sin rot1, rot1 + rot2)`` (Thrun et al. 2005,
    Table 5.5) has the covariance ``J diag(var) J^T`` of the variances of Table 5.6; composing
    ``r_{k+1} = r_k (+) u`` (Smith, Self & Cheeseman's compounding) propagates
    ``Sigma_{k+1} = A Sigma_k A^T + B Q_u B^T`` with ``A, B`` its Jacobians.

    Examples
    --------
    Two metres straight ahead in two steps: the heading's uncertainty spreads sideways (y):

    >>> odo = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
    >>> print(np.round(odometry_covariance(odo, [0.01, 0.001, 0.01, 0.001])[-1], 4))
    [[0.02  0.    0.   ]
     [0.    0.006 0.004]
     [0.    0.004 0.004]]
    """
    P = as_points(odometry, "odometry", 3, min_count=1)
    a = _alphas(alphas)
    delta = odometry_increment(P[:-1], P[1:])
    # Noisy odometry of a turn on the spot moves a few millimetres in a random direction, which
    # Table 5.5 decomposes with a rot1 of up to +-pi and would charge alpha1 rot1^2 of heading
    # variance for a direction that is only noise. Steps under SPOT_TURN metres are taken as turns on
    # the spot (rot1 = 0), and a backward step as a forward one with the translation signed (rot1
    # folded into (-pi/2, pi/2]); the increment (t cos rot1, t sin rot1, rot1 + rot2) is unchanged
    # by the fold and moves by under SPOT_TURN by the first rule.
    spot = delta[:, 1] < SPOT_TURN
    delta[spot, 2] = wrap_angle(delta[spot, 0] + delta[spot, 2])
    delta[spot, 0] = 0.0
    back = np.abs(delta[:, 0]) > np.pi / 2
    delta[back, 0] = wrap_angle(delta[back, 0] + np.pi)
    delta[back, 1] = -delta[back, 1]
    delta[back, 2] = wrap_angle(delta[back, 2] - np.pi)
    var = _increment_variances(delta, a)
    r1, t = delta[:, 0], delta[:, 1]
    c1, s1 = np.cos(r1), np.sin(r1)
    zeros, ones = np.zeros_like(t), np.ones_like(t)
    J = np.stack([np.stack([-t * s1, c1, zeros], -1), np.stack([t * c1, s1, zeros], -1),
                  np.stack([ones, zeros, ones], -1)], 1)                 # d u / d (rot1, trans, rot2)
    Q = J @ (var[:, :, None] * np.swapaxes(J, 1, 2))
    u = np.stack([t * c1, t * s1, wrap_angle(r1 + delta[:, 2])], -1)
    out = np.zeros((len(P), 3, 3))
    r = np.zeros(3)
    for k in range(len(delta)):   # sequential by nature: each step composes onto the last
        c, s = np.cos(r[2]), np.sin(r[2])
        A = np.array([[1.0, 0.0, -s * u[k, 0] - c * u[k, 1]], [0.0, 1.0, c * u[k, 0] - s * u[k, 1]], [0.0, 0.0, 1.0]])
        B = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        out[k + 1] = A @ out[k] @ A.T + B @ Q[k] @ B.T
        r = np.array([r[0] + c * u[k, 0] - s * u[k, 1], r[1] + s * u[k, 0] + c * u[k, 1], r[2] + u[k, 2]])
    return 0.5 * (out + np.swapaxes(out, 1, 2))


def _apply(pose: np.ndarray, d: np.ndarray) -> np.ndarray:
    th = pose[..., 2] + d[..., 0]                                     # Table 5.6, lines 8-10
    return np.stack([pose[..., 0] + d[..., 1] * np.cos(th), pose[..., 1] + d[..., 1] * np.sin(th),
                     wrap_angle(th + d[..., 2])], axis=-1)


def sample_motion_model_odometry(odom_prev: Any, odom_now: Any, poses: Any, alphas: Any, rng: Any = None) -> np.ndarray:
    """Sample successor poses given an odometry reading (for particle filters).

    Parameters
    ----------
    odom_prev, odom_now : array_like, shape (3,)
        Consecutive odometry poses (the reading ``u = (x_bar_{t-1}, x_bar_t)``).
    poses : array_like, shape (N, 3) or (3,)
        Poses ``x_{t-1}`` (e.g. particles).
    alphas : array_like, shape (4,)
        Noise parameters ``a1..a4`` (non-negative).
    rng : Generator or int, optional

    Returns
    -------
    numpy.ndarray, same shape as ``poses``

    Notes
    -----
    Thrun et al. (2005), Table 5.6 (``sample(b^2)`` draws a zero-mean Gaussian of
    variance ``b^2``).

    Examples
    --------
    >>> particles = sample_motion_model_odometry([0, 0, 0], [1, 0, 0], np.zeros((3, 3)), [0.01, 0.001, 0.01, 0.001],
    ...                                          rng=0)
    >>> np.round(particles, 3).tolist()       # three particles, each about 1 m ahead
    [[1.013, -0.004, -0.024], [1.054, -0.003, -0.015], [0.905, -0.037, -0.019]]
    """
    delta = odometry_increment(as_planar(odom_prev, "odom_prev", shape=(3,)), as_planar(odom_now, "odom_now", shape=(3,)))
    P = as_planar(poses, "poses")
    d = _perturb(np.broadcast_to(delta, P.shape), _alphas(alphas), as_rng(rng))
    return _apply(P, d)


def noisy_odometry(poses: Any, alphas: Any, rng: Any = None) -> np.ndarray:
    """Simulate wheel odometry along a true trajectory: accumulate noisy motion increments.

    Parameters
    ----------
    poses : array_like, shape (N, 3)
        Ground-truth poses.
    alphas : array_like, shape (4,)
        Noise parameters of Table 5.6 (``(0, 0, 0, 0)`` gives perfect odometry).
    rng : Generator or int, optional

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        Odometry poses, starting at the first true pose; each increment is the true increment
        (Table 5.5) corrupted as in Table 5.6, so drift grows like a random walk.

    Notes
    -----
    Thrun et al. (2005), Sec. 5.4.

    Examples
    --------
    >>> from robokit.sim import lab_lap, lab_room
    >>> lap = lab_lap(lab_room())
    >>> odo = noisy_odometry(lap.poses, [0.01, 0.001, 0.01, 0.001], rng=3)
    >>> np.round(odo[-1] - lap.poses[-1], 3).tolist()      # drift after one lap (m, m, rad)
    [-0.565, 0.162, -0.098]
    """
    P = as_points(poses, "poses", 3, min_count=1)
    a = _alphas(alphas)
    rng = as_rng(rng)
    out = np.empty_like(P)
    out[0] = P[0]
    with np.errstate(over="ignore", invalid="ignore"):     # an overflow is reported below, by name
        d = _perturb(odometry_increment(P[:-1], P[1:]), a, rng)
        # sequential by nature: each increment starts where the last ended. The loop is _apply's
        # arithmetic on one pose, spelt out on numpy's scalars (the same operations in the same
        # order, so the same bits) without its per-call array overhead (about 5x faster).
        x, y, theta = P[0]
        rot1, trans, rot2 = d[:, 0], d[:, 1], d[:, 2]
        for k in range(len(d)):
            th = theta + rot1[k]                                      # Table 5.6, lines 8-10
            x, y = x + trans[k] * np.cos(th), y + trans[k] * np.sin(th)
            theta = wrap_angle(th + rot2[k], validate=False)
            out[k + 1] = x, y, theta
    if not np.isfinite(out).all():
        raise ValueError("poses: expected a trajectory whose odometry stays finite, got increments that overflow "
                         f"(largest coordinate {np.abs(P[:, :2]).max():.3g})")
    return out


class Trajectory(NamedTuple):
    """A timed trajectory: ``t`` (N,) seconds and ``poses`` (N, 3) ``[x, y, theta]``.

    Examples
    --------
    >>> path = Trajectory(np.array([0.0, 1.0]), np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0]]))
    >>> path.t.tolist(), path.poses[-1].tolist()
    ([0.0, 1.0], [0.3, 0.0, 0.0])
    """

    t: np.ndarray
    poses: np.ndarray


def waypoint_path(waypoints: Any, speed: float = 0.3, turn_rate: float = 0.6, rate: float = 10.0) -> Trajectory:
    """A remote-controlled drive through waypoints: turn on the spot, then drive straight.

    Parameters
    ----------
    waypoints : array_like, shape (K, 2)
        At least two (x, y) points; the robot starts at the first, facing the second.
    speed : float, default 0.3
        Forward speed (m/s).
    turn_rate : float, default 0.6
        Turn rate for the on-the-spot turns (rad/s).
    rate : float, default 10
        Sampling rate of the returned poses (Hz).

    Returns
    -------
    Trajectory

    Notes
    -----
    Piecewise unicycle motion (Thrun et al. 2005, Sec. 5.3) with ``omega = 0`` or ``v = 0``;
    Ge et al. (2023, Sec. 3.4) drive their robot by remote control along the corridor's middle line.

    Examples
    --------
    >>> path = waypoint_path([[0.0, 0.0], [1.0, 0.0]], speed=0.5, rate=2)
    >>> path.t.tolist(), path.poses[:, 0].tolist()
    ([0.0, 0.5, 1.0, 1.5, 2.0], [0.0, 0.25, 0.5, 0.75, 1.0])
    """
    W = as_points(waypoints, "waypoints", 2, min_count=2)
    v = as_positive(speed, "speed")
    w = as_positive(turn_rate, "turn_rate")
    dt = 1.0 / as_positive(rate, "rate")
    heading = np.arctan2(*(W[1] - W[0])[::-1])
    knots_t, knots = [0.0], [np.array([W[0, 0], W[0, 1], heading])]
    for a, b in zip(W[:-1], W[1:]):
        target = np.arctan2(b[1] - a[1], b[0] - a[0])
        turn = wrap_angle(target - knots[-1][2])
        if abs(turn) > 1e-12:
            knots_t.append(knots_t[-1] + abs(turn) / w)
            knots.append(np.array([a[0], a[1], knots[-1][2] + turn]))
        length = float(np.linalg.norm(b - a))
        if length > 0:
            knots_t.append(knots_t[-1] + length / v)
            knots.append(np.array([b[0], b[1], knots[-1][2]]))
    kt, kp = np.array(knots_t), np.array(knots)
    require_sample_count(kt[-1] / dt, "waypoints, speed, turn_rate, rate")
    t = np.arange(0.0, kt[-1] + 1e-9, dt)
    poses = np.column_stack([np.interp(t, kt, kp[:, i]) for i in range(3)])
    poses[:, 2] = wrap_angle(poses[:, 2])
    return Trajectory(t, poses)


def corridor_path(world: Any, speed: float = 0.3, rate: float = 10.0, margin: float = 0.8) -> Trajectory:
    """Drive along the middle line of :func:`robokit.sim.long_corridor`, stopping ``margin`` m from the ends.

    Notes
    -----
    Ge et al. (2023), Sec. 3.4 and 4.1: remote-controlled along the middle line, stopping about
    0.8 m from the end wall.
    """
    if not isinstance(world, World) or "length" not in world.info:
        raise TypeError(f"world: expected the corridor World (long_corridor()), got {describe(world)}")
    length = float(world.info["length"])
    m = as_positive(margin, "margin")
    if not m < length / 2:
        raise ValueError(f"margin: expected less than half the corridor's {length:g} m, got {m:g}")
    return waypoint_path([[m, 0.0], [length - m, 0.0]], speed, rate=rate)


def lab_lap(world: Any, speed: float = 0.3, rate: float = 10.0) -> Trajectory:
    """One lap around the middle of :func:`robokit.sim.lab_room`, clear of the furniture.

    Notes
    -----
    Se, Lowe & Little (2002), Sec. 3.6: the robot "traverses around our 10m by 10m lab".

    Examples
    --------
    >>> from robokit.sim import lab_room
    >>> lap = lab_lap(lab_room())
    >>> len(lap.t), round(float(lap.t[-1]), 1), lap.poses[0].tolist()     # 10 Hz, 78 s at 0.3 m/s
    (784, 78.3, [3.0, 2.0, 0.0])
    """
    if not isinstance(world, World):
        raise TypeError(f"world: expected the lab World (lab_room()), got {describe(world)}")
    lap = [[3.0, 2.0], [7.5, 2.0], [7.8, 5.0], [7.5, 8.0], [3.0, 8.0], [2.6, 5.0], [3.0, 2.0]]
    return waypoint_path(lap, speed, rate=rate)


#: Waypoints of :func:`office_tour` in :func:`robokit.sim.office_floor`: a lap of R1, then R2, R3
#: and R4 each walked round their table through the doorways at x = 4 and x = 12, and back to R1.
OFFICE_TOUR = ((14.5, 4.0), (10.0, 4.0), (10.0, 1.0), (14.8, 0.8), (14.8, 4.0), (12.0, 4.0),   # R1, a loop
               (12.0, 6.0), (4.0, 6.0),                                                       # corridor west
               (4.0, 4.2), (6.2, 4.2), (6.2, 1.0), (1.6, 1.0), (1.6, 4.2), (4.0, 4.2), (4.0, 6.0),  # R2
               (4.0, 8.0), (5.8, 8.0), (5.8, 11.0), (1.6, 11.0), (1.6, 8.0), (4.0, 8.0), (4.0, 6.0),  # R3
               (12.0, 6.0),                                                                   # corridor east
               (12.0, 8.0), (14.6, 8.0), (14.6, 11.2), (10.0, 11.2), (10.0, 8.0), (12.0, 8.0),  # R4
               (12.0, 6.0), (12.0, 4.0), (14.5, 4.0))                                         # back into R1


#: Eleven test poses ``[x, y, theta]`` in :func:`robokit.sim.office_floor`, spread like the test
#: locations of lesson 02's paper (Sec. "Experimental results", Fig. 8): three in R1, two in the
#: corridor (the paper's cases 4 and 5), two in each of R2, R3 and R4; each 0.2-0.3 m off
#: :func:`office_tour`'s path, at a heading the tour never drove, and 0.3 m clear of everything.
OFFICE_TEST_POSES = ((13.0, 3.7, 2.0), (10.3, 2.2, -1.2), (14.5, 1.1, 0.8), (9.0, 6.3, 3.0), (6.5, 5.8, 0.2),
                     (3.0, 1.3, 0.5), (6.0, 3.0, 2.0), (2.2, 10.75, -0.4), (1.9, 9.0, 1.4), (12.5, 8.3, 0.8),
                     (14.3, 10.0, -2.5))


def office_tour(world: Any, speed: float = 0.3, rate: float = 10.0) -> Trajectory:
    """The exploration drive of :func:`robokit.sim.office_floor`: every room and the corridor, with loops.

    Parameters
    ----------
    world : World
        ``office_floor()``. The walls are the same for every seed, the tables are not: the tour
        keeps 0.3 m from everything for the default seed (1), and from walls only for others
        (:func:`robokit.sim.record` refuses a pose closer than 0.05 m).
    speed : float, default 0.3
        Forward speed (m/s).
    rate : float, default 10
        Sampling rate of the returned poses (Hz).

    Returns
    -------
    Trajectory
        Starts in R1 (lower right) at ``(14.5, 4.0)`` facing west, laps R1, crosses the corridor
        to R2, R3 and R4, each walked round its table, and returns to R1: it closes the R1 lap and
        the whole-floor loop (work for loop closure), about 98 m in all.

    Raises
    ------
    TypeError
        If ``world`` is not the office floor.
    ValueError
        For a non-positive speed or rate.

    Notes
    -----
    Lesson 02's paper, Sec. "Experimental results": "We firstly drive the robot to move along the
    path as shown in Fig. 6a" through "four rooms R1, R2, R3, R4 and a horizontal corridor",
    recording images "at a constant rate" (Sec. "System overview"). The waypoints are ours (the
    paper's figure is not reproduced in our copy); every pose keeps at least 0.3 m from walls,
    tables and cabinets of the default office (tests/test_sim_lidar_motion.py checks it with
    ``World.is_free``). The robot
    turns on the spot at each waypoint (:func:`waypoint_path`), as a robot "lead through all parts
    of the environment by hand" would.

    Examples
    --------
    >>> from robokit.sim import office_floor
    >>> tour = office_tour(office_floor())
    >>> len(tour.t), round(float(tour.t[-1]), 1), tour.poses[0].round(3).tolist()
    (4000, 399.9, [14.5, 4.0, -3.142])
    """
    if not isinstance(world, World) or world.name != "office_floor":
        raise TypeError(f"world: expected the office floor World (office_floor()), got {describe(world)}")
    return waypoint_path(OFFICE_TOUR, speed, rate=rate)
