"""Autonomous navigation along a recorded visual path: localize, filter, follow (the paper's on-line stage).

Source: "Robust omnidirectional vision based mobile robot hierarchical localization and autonomous
navigation", Sec. 'Visual-servoing for navigation' and Sec. 'Experimental results' (Fig. 13: starts
"near the navigation path with the orientation similar to the desired paths" converge to the
target node). One loop, every ``dt`` seconds:

1. the path follower (:class:`robokit.controllers.PathFollower`, Eq. (7) and Eq. (8), saturated)
   computes ``(v, omega)`` from the EKF's pose estimate, never from the truth;
2. the true robot drives the exact arc of Eq. (6) (:func:`robokit.sim.unicycle_step`);
3. odometry reports the ``(v, omega)`` of that step with noise; the EKF
   (:class:`robokit.localization.pose_ekf.UnicycleEKF`) takes it as the velocity over the step,
   then predicts;
4. every ``fix_period`` seconds the localizer is asked for a fix ``[x, y, theta]`` of the true
   pose (the lesson plugs in the omnidirectional hierarchical localizer; tests use
   :func:`gaussian_localizer`); a fix, when there is one, updates the EKF.

The robot stands still until its first fix (global localization), which also starts the EKF.
Fixes arrive without delay: the paper does not give the localizer's latency.

References
----------
.. [1] C. Canudas de Wit, H. Khennouf, C. Samson and O. J. Sordalen, "Nonlinear control design for
   mobile robots", in Y. F. Zheng (ed.), *Recent Trends in Mobile Robots*, World Scientific Series
   in Robotics and Automated Systems vol. 11, World Scientific, 1993, pp. 121-156.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import numpy as np

from ..controllers.path_following import XI, PathFollower
from ..controllers.path_geometry import VisualPath, reference_point
from ..geometry import wrap_angle
from ..localization.pose_ekf import UnicycleEKF
from ..sim import unicycle_step
from ..geometry.planar import as_planar
from ..validation import (as_array, as_callable, as_int, as_positive, as_rng, describe,
                          require_angles, require_finite_result, require_sample_count)

__all__ = ["FollowResult", "follow_path", "gaussian_localizer", "perturbed_starts"]


@dataclasses.dataclass(eq=False)
class FollowResult:
    """One run of :func:`follow_path`.

    Attributes
    ----------
    times : numpy.ndarray, shape (K,)
        Control instants (s) from the first fix.
    true_poses, estimated_poses : numpy.ndarray, shape (K, 3)
        The robot's true pose and the EKF's estimate at each instant.
    covariances : numpy.ndarray, shape (K, 3, 3)
        The EKF's pose covariance at each instant.
    commands : numpy.ndarray, shape (K, 2)
        ``(v, omega)`` sent at each instant; ``(0, 0)`` at the last.
    cross_track : numpy.ndarray, shape (K,)
        True distance to the path ``d`` (m, positive to its left).
    fixes : numpy.ndarray, shape (M, 4)
        ``[t, x, y, theta]`` of every fix the localizer gave.
    reached : bool
        The follower declared the goal reached (by its estimate) before ``max_time``.
    final_error : float
        True distance (m) from the robot to the goal at the end.
    """

    times: np.ndarray
    true_poses: np.ndarray
    estimated_poses: np.ndarray
    covariances: np.ndarray
    commands: np.ndarray
    cross_track: np.ndarray
    fixes: np.ndarray
    reached: bool
    final_error: float


def gaussian_localizer(noise: Any = (0.10, 0.15, 0.05), *, dropout: float = 0.0, outlier_rate: float = 0.0,
                       outlier_offset: float = 2.0) -> Callable[[np.ndarray, np.random.Generator], np.ndarray | None]:
    """A stand-in localizer: the true pose plus Gaussian noise, sometimes nothing, sometimes a false fix.

    Parameters
    ----------
    noise : array_like, shape (3,), default (0.10, 0.15, 0.05)
        Standard deviations (m, m, rad) added to ``[x, y, theta]``; the default takes the paper's
        errors ("less than 10 cm in x direction and 15 cm in y direction", Fig. 9) and a heading
        error of 3 degrees (the paper gives none).
    dropout : float, default 0
        Probability that no fix comes (``None``: too few matches).
    outlier_rate : float, default 0
        Probability that the fix is displaced by ``outlier_offset`` metres in a random direction
        (a false recognition, the failure the paper reports).
    outlier_offset : float, default 2
        Size (m) of such a displacement.

    Returns
    -------
    callable
        ``localize(true_pose, rng) -> [x, y, theta]`` or ``None``, as :func:`follow_path` asks.

    Notes
    -----
    Sec. 'Experimental results': localization errors of Fig. 9 and their Gaussian spread (Fig. 10).

    Examples
    --------
    >>> localize = gaussian_localizer((0.1, 0.1, 0.05))
    >>> fix = localize(np.array([1.0, 2.0, 0.0]), np.random.default_rng(0))
    >>> np.round(fix, 3).tolist()
    [1.013, 1.987, 0.032]
    """
    sd = as_array(noise, "noise", shape=(3,))
    if np.any(sd < 0):
        raise ValueError(f"noise: expected non-negative standard deviations, got {sd.tolist()}")
    p_none = as_positive(dropout, "dropout", allow_zero=True)
    p_out = as_positive(outlier_rate, "outlier_rate", allow_zero=True)
    for name, p in (("dropout", p_none), ("outlier_rate", p_out)):
        if p > 1:
            raise ValueError(f"{name}: expected a probability in [0, 1], got {p}")
    jump = as_positive(outlier_offset, "outlier_offset", allow_zero=True)

    def localize(true_pose: np.ndarray, rng: np.random.Generator) -> np.ndarray | None:
        if p_none and rng.random() < p_none:
            return None
        fix = np.asarray(true_pose, dtype=float) + sd * rng.standard_normal(3)
        if p_out and rng.random() < p_out:
            a = rng.uniform(-np.pi, np.pi)
            fix[:2] += jump * np.array([np.cos(a), np.sin(a)])
        fix[2] = wrap_angle(fix[2])
        return fix

    return localize


def perturbed_starts(path: VisualPath, n: int, *, offset: float = 0.3, heading: float = 0.3,
                     rng: Any = None) -> np.ndarray:
    """Start poses near the beginning of the path, heading roughly along it (the paper's Fig. 13).

    Parameters
    ----------
    path : VisualPath
    n : int
        Number of starts.
    offset : float, default 0.3
        Largest sideways distance (m) from the path; the start's foot on the path is drawn in
        the first ``offset`` metres of it.
    heading : float, default 0.3
        Largest heading difference (rad) from the path's direction there.
    rng : numpy.random.Generator or int, optional

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        ``[x, y, theta]``: uniform in arc length ``[0, offset]``, lateral offset
        ``[-offset, offset]`` and heading error ``[-heading, heading]``.

    Notes
    -----
    Sec. 'Experimental results': "the initial robot poses are collected near the navigation path
    with the orientation similar to the desired paths" (Fig. 13); the distributions are ours.

    Examples
    --------
    >>> from robokit.controllers import path_from_poses
    >>> starts = perturbed_starts(path_from_poses([[0, 0, 0], [5, 0, 0]]), 3, rng=1)
    >>> starts.shape, bool(np.all(np.abs(starts[:, 1]) <= 0.3)), bool(np.all(np.abs(starts[:, 2]) <= 0.3))
    ((3, 3), True, True)
    """
    if not isinstance(path, VisualPath):
        raise TypeError(f"path: expected a VisualPath, got {describe(path)}")
    count = as_int(n, "n", minimum=0, maximum=10 ** 6)
    r = as_positive(offset, "offset", allow_zero=True)
    h = as_positive(heading, "heading", allow_zero=True)
    require_angles(h, "heading")
    g = as_rng(rng)
    s = g.uniform(0.0, min(r, path.length), count)
    x, y, th = (np.interp(s, path.s, path.poses[:, i]) for i in range(3))
    th = np.interp(s, path.s, np.unwrap(path.poses[:, 2]))
    lateral = g.uniform(-r, r, count)
    out = np.column_stack([x - lateral * np.sin(th), y + lateral * np.cos(th),
                           wrap_angle(th + g.uniform(-h, h, count))])
    return out.reshape(count, 3)


def follow_path(path: VisualPath, start_pose: Any, *, localize: Callable, dt: float = 0.1, fix_period: float = 0.5,
                alpha: float = 2.0, v_max: float = 0.3, w_max: float = 1.0, xi: float = XI,
                goal_tolerance: float = 0.1, odometry_noise: Any = (0.01, 0.02), sigma_fix: Any = (0.10, 0.15, 0.05),
                sigma_odometry: Any = None, gate: float | None = None, relocalize_after: int = 3,
                max_time: float | None = None, rng: Any = None) -> FollowResult:
    """Drive along ``path`` from ``start_pose``: visual fixes and odometry in the EKF, Eq. (8) on the estimate.

    Parameters
    ----------
    path : VisualPath
        The recorded path (:func:`robokit.controllers.path_from_poses`).
    start_pose : array_like, shape (3,)
        True start ``[x, y, theta]``.
    localize : callable
        ``localize(true_pose, rng)`` returns a fix ``[x, y, theta]`` or ``None``.
    dt : float, default 0.1
        Control and odometry period (s).
    fix_period : float, default 0.5
        Time (s) between localization requests (2 Hz), rounded to whole steps.
    alpha, xi, v_max, w_max, goal_tolerance : float
        The path follower's (:class:`robokit.controllers.PathFollower`).
    odometry_noise : array_like, shape (2,), default (0.01, 0.02)
        Standard deviations (m/s, rad/s) added to the odometry's ``(v, omega)``.
    sigma_fix : array_like, shape (3,), default (0.10, 0.15, 0.05)
        Standard deviations the EKF assumes for a fix (m, m, rad).
    sigma_odometry : array_like, shape (2,), optional
        Standard deviations the EKF assumes for odometry; default ``odometry_noise`` (at least
        1e-3 each, so the covariance is positive definite).
    gate : float, optional
        Normalised-innovation gate for fixes (:meth:`UnicycleEKF.update_pose`), e.g.
        ``scipy.stats.chi2.ppf(0.999, 3)``; ``None`` uses every fix.
    relocalize_after : int, default 3
        With a gate: after this many fixes rejected in a row the estimate, not the fixes, is taken
        to be wrong (a false first fix, say) and the filter restarts from the newest fix.
    max_time : float, optional
        Time limit (s); default ``3 * path.length / v_max + 30``.
    rng : numpy.random.Generator or int, optional
        Randomness of the odometry and of the localizer.

    Returns
    -------
    FollowResult

    Raises
    ------
    ValueError, TypeError
        For invalid arguments, or a fix that is not three finite numbers.
    PathSingularityError
        If the estimate reaches the path's centre of curvature.

    Notes
    -----
    Sec. 'Visual-servoing for navigation': the law of Eq. (8) with ``v = V_max`` and the
    saturation rule, fed by an EKF over ``(x, y, theta, v, omega)`` so that localization noise is
    not passed straight to ``(v, omega)``; Fig. 13's convergence from perturbed starts.

    Examples
    --------
    >>> from robokit.controllers import path_from_poses
    >>> path = path_from_poses([[0, 0, 0], [2, 0, 0], [3, 1, 0]])
    >>> run = follow_path(path, [0.0, 0.2, 0.1], localize=gaussian_localizer((0.05, 0.05, 0.02)), rng=0)
    >>> run.reached, round(run.final_error, 2), len(run.fixes)
    (True, 0.09, 23)
    """
    if not isinstance(path, VisualPath):
        raise TypeError(f"path: expected a VisualPath, got {describe(path)}")
    pose = as_planar(start_pose, "start_pose", shape=(3,)).copy()
    find = as_callable(localize, "localize", optional=False)
    h = as_positive(dt, "dt")
    every = max(1, int(round(as_positive(fix_period, "fix_period") / h)))
    follower = PathFollower(path, alpha, v_max, w_max, xi, goal_tolerance=goal_tolerance)
    odo_sd = as_array(odometry_noise, "odometry_noise", shape=(2,))
    require_angles(odo_sd[1], "odometry_noise", "an angular-rate spread (element 1, rad/s)")
    if np.any(odo_sd < 0):
        raise ValueError(f"odometry_noise: expected non-negative standard deviations, got {odo_sd.tolist()}")
    fix_sd = as_array(sigma_fix, "sigma_fix", shape=(3,))
    odo_sigma = np.maximum(odo_sd, 1e-3) if sigma_odometry is None else as_array(sigma_odometry, "sigma_odometry",
                                                                                shape=(2,))
    for name, sd in (("sigma_fix", fix_sd), ("sigma_odometry", odo_sigma)):
        if np.any(sd <= 0):
            raise ValueError(f"{name}: expected positive standard deviations, got {sd.tolist()}")
    R_fix, R_odo = np.diag(fix_sd ** 2), np.diag(odo_sigma ** 2)
    require_finite_result("sigma_fix, sigma_odometry", R_fix, R_odo)
    g = None if gate is None else as_positive(gate, "gate")
    restart = as_int(relocalize_after, "relocalize_after", minimum=1)
    limit = 3 * path.length / follower.v_max + 30 if max_time is None else as_positive(max_time, "max_time")
    require_sample_count(limit / h, "max_time, dt")
    rng = as_rng(rng)

    def ask(t: float) -> np.ndarray | None:
        fix = find(pose.copy(), rng)
        if fix is None:
            return None
        fix = as_array(fix, "localize's fix", shape=(3,))
        fixes.append([t, *fix])
        return fix

    fixes: list[list[float]] = []
    t, fix = 0.0, None
    while fix is None and t <= limit:            # stand still until the first fix (global localization)
        fix = ask(t)
        t = t if fix is not None else t + every * h
    times, truth, est, covs, cmds, cross = [], [], [], [], [], []
    if fix is not None:
        P0 = np.diag(np.concatenate([fix_sd ** 2, odo_sigma ** 2]))
        ekf = UnicycleEKF(np.concatenate([fix, [0.0, 0.0]]), P0)
        step, ref, rejected = 0, None, 0
        while True:
            v, w = follower.command(ekf.pose)
            ref = reference_point(path, pose, previous=None if ref is None else ref.index, window=1.0, validate=False)
            times.append(t), truth.append(pose.copy()), est.append(ekf.pose), cross.append(ref.d)
            covs.append(ekf.covariance[:3, :3])
            if follower.done or t + h > limit + 1e-9:
                cmds.append((0.0, 0.0))
                break
            cmds.append((v, w))
            pose = unicycle_step(pose, v, w, h, validate=False)       # Eq. (6), the true robot
            noisy = np.array([v, w]) + odo_sd * rng.standard_normal(2)
            ekf.update_velocity(noisy[0], noisy[1], R_odo)         # the velocity over the step just driven
            ekf.predict(h)
            step += 1
            t = step * h + fixes[0][0]
            if step % every == 0 and (fix := ask(t)) is not None:
                rejected = 0 if ekf.update_pose(fix, R_fix, gate=g) else rejected + 1
                if rejected >= restart:                           # the estimate is what is wrong
                    ekf = UnicycleEKF(np.concatenate([fix, ekf.state[3:]]), P0)
                    rejected = 0
    final = float(math.hypot(*(pose[:2] - path.poses[-1, :2])))
    return FollowResult(np.array(times), np.array(truth).reshape(-1, 3), np.array(est).reshape(-1, 3),
                        np.array(covs).reshape(-1, 3, 3), np.array(cmds).reshape(-1, 2), np.array(cross),
                        np.array(fixes).reshape(-1, 4), bool(follower.reached), final)
