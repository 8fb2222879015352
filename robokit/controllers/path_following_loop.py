"""The path-following law of Eq. (8) linearised about the path, analysed with python-control, and simulated.

Near the path, with ``v > 0`` and the reference point's curvature cancelled by Eq. (8)'s third
term (:mod:`robokit.controllers.path_following`), the errors obey::

    dd/dt           = v theta_tilde
    dtheta_tilde/dt = -k2 v (d - d_ref) - k3 v theta_tilde

whatever the curvature (the ``c(s)`` terms cancel exactly, not only to first order). ``d_ref`` is
the input: a sideways step of the path (or an offset the robot is asked to keep). Its
characteristic polynomial is ``s^2 + k3 v s + k2 v^2``; with ``k2 = alpha^2`` and
``k3 = 2 xi alpha`` the poles are ``-alpha v (xi +- j sqrt(1 - xi^2))`` rad/s: natural frequency
``alpha v`` and damping ``xi``, so a faster robot converges in the same distance, not the same
time. A robot that starts ``d0`` metres beside the path and parallel to it has
``d(t) = d0 (1 - y(t))``, ``y`` the unit-step response: :func:`lateral_step_response`.
:func:`simulate_path_following` runs the nonlinear law (Eq. (6) integrated exactly by
:func:`robokit.sim.unicycle_step`) for comparison.

References
----------
.. [1] C. Canudas de Wit, H. Khennouf, C. Samson and O. J. Sordalen, "Nonlinear control design for
   mobile robots", in Y. F. Zheng (ed.), *Recent Trends in Mobile Robots*, World Scientific Series
   in Robotics and Automated Systems vol. 11, World Scientific, 1993, pp. 121-156.
.. [2] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015.
.. [3] The python-control developers, *python-control: the Python Control Systems Library*,
   version 0.10, https://python-control.org.
"""
from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..config import lazy_module
from ..sim import unicycle_step
from ..geometry.planar import as_planar
from ..validation import (as_array, as_finite_scalar, as_positive, describe, require_finite_result,
                          require_sample_count)
from .path_following import XI, path_following_gains, reference_command
from .path_geometry import VisualPath, reference_point

control = lazy_module("control")   # python-control, loaded on first use (0.75 s of every import otherwise)

__all__ = ["path_following_linearisation", "path_following_poles", "path_following_damping",
           "lateral_step_response", "FollowTrace", "simulate_path_following"]


def path_following_linearisation(alpha: float, v: float, xi: float = XI) -> control.StateSpace:
    """Eq. (8) linearised about the path: states ``(d, theta_tilde)``, input ``d_ref``, output ``d``.

    Parameters
    ----------
    alpha : float
        Natural frequency (rad per metre of path).
    v : float
        Forward speed (m/s, > 0).
    xi : float, default 1/sqrt(2)
        Damping ratio.

    Returns
    -------
    control.StateSpace
        ``A = [[0, v], [-k2 v, -k3 v]]``, ``B = [[0], [k2 v]]``, ``C = [[1, 0]]``, ``D = 0``, with
        ``k2 = alpha^2``, ``k3 = 2 xi alpha``; named states ``d``, ``theta_tilde``.

    Raises
    ------
    ValueError
        For non-positive or non-finite arguments, or values that overflow.

    Notes
    -----
    Linearisation of Eq. (6) in path coordinates under the law of Eq. (8) (module docstring):
    ``sin(theta_tilde) ~ theta_tilde``, ``sin(theta_tilde)/theta_tilde ~ 1``.

    Examples
    --------
    >>> sys = path_following_linearisation(2.0, 0.3)
    >>> np.round(sys.A, 4).tolist()
    [[0.0, 0.3], [-1.2, -0.8485]]
    """
    k2, k3 = path_following_gains(alpha, xi)
    vv = as_positive(v, "v")
    A = np.array([[0.0, vv], [-k2 * vv, -k3 * vv]])
    B = np.array([[0.0], [k2 * vv]])
    require_finite_result("alpha, v, xi", A, B)
    return control.ss(A, B, [[1.0, 0.0]], [[0.0]], states=["d", "theta_tilde"], inputs=["d_ref"], outputs=["d"])


def path_following_poles(alpha: float, v: float, xi: float = XI) -> np.ndarray:
    """Closed-loop poles (rad/s) of :func:`path_following_linearisation`, by python-control.

    Returns
    -------
    numpy.ndarray, shape (2,), complex
        Sorted by imaginary part; ``-alpha v (xi -+ j sqrt(1 - xi^2))`` for ``xi < 1``.

    Notes
    -----
    ``control.poles`` of the linearised loop; the closed form follows from ``k2 = alpha^2``,
    ``k3 = 2 xi alpha`` (Sec. 'Visual-servoing for navigation', unnumbered).

    Examples
    --------
    >>> np.round(path_following_poles(1.0, 0.3), 4).tolist()
    [(-0.2121-0.2121j), (-0.2121+0.2121j)]
    """
    p = np.asarray(control.poles(path_following_linearisation(alpha, v, xi)), dtype=complex)
    require_finite_result("alpha, v, xi", p)
    return p[np.argsort(p.imag, kind="stable")]


def path_following_damping(alpha: float, v: float, xi: float = XI) -> dict:
    """Natural frequency and damping of the linearised loop, from ``control.damp``.

    Returns
    -------
    dict
        ``natural_frequency`` (rad/s), ``damping`` (ratio), ``time_constant`` (s, ``1 / (xi
        alpha v)``, of the envelope) and ``poles`` (as :func:`path_following_poles`).

    Notes
    -----
    ``control.damp`` (python-control 0.10); for ``xi = 1/sqrt(2)`` the step overshoot is
    ``exp(-pi xi / sqrt(1 - xi^2)) = 4.3 %`` (Franklin et al. 2015, Sec. 3.4), the paper's
    "small overshoot".

    Examples
    --------
    >>> info = path_following_damping(2.0, 0.3)
    >>> round(info["natural_frequency"], 4), round(info["damping"], 4), round(info["time_constant"], 3)
    (0.6, 0.7071, 2.357)
    """
    sys = path_following_linearisation(alpha, v, xi)
    wn, zeta, poles = control.damp(sys, doprint=False)
    order = np.argsort(np.asarray(poles).imag, kind="stable")
    p = np.asarray(poles, dtype=complex)[order]
    require_finite_result("alpha, v, xi", p, wn, zeta)
    return {"natural_frequency": float(np.asarray(wn)[0]), "damping": float(np.asarray(zeta)[0]),
            "time_constant": float(-1.0 / p.real.max()), "poles": p}


def lateral_step_response(alpha: float, v: float, xi: float = XI, t: Any = None, *, offset: float = 1.0
                          ) -> tuple[np.ndarray, np.ndarray]:
    """Lateral error ``d(t)`` of a robot that starts ``offset`` metres beside the path, parallel to it.

    Parameters
    ----------
    alpha, v, xi : float
        As in :func:`path_following_linearisation`.
    t : array_like, shape (N,), optional
        Equally spaced increasing times (s) from 0 (python-control asks for equal steps); default
        501 times over ten time constants of the envelope (:func:`path_following_damping`).
    offset : float, default 1
        Initial distance to the path (m; positive to its left).

    Returns
    -------
    (t, d) : numpy.ndarray, numpy.ndarray

    Raises
    ------
    ValueError
        For times that are not equally spaced and increasing from 0, or invalid gains or speed.

    Notes
    -----
    ``d(t) = offset (1 - y(t))`` with ``y`` the unit-step response of ``d`` to ``d_ref``
    (``control.step_response``): a step of the path by ``-offset`` is a start ``offset`` beside it.
    Linear, so valid while ``|theta_tilde|`` stays small (a few tenths of a radian).

    Examples
    --------
    >>> t, d = lateral_step_response(2.0, 0.3, t=np.linspace(0.0, 20.0, 201), offset=0.1)
    >>> round(float(d[0]), 4), round(float(d.min()), 4), round(float(abs(d[-1])), 4)   # 4.3 % overshoot
    (0.1, -0.0043, 0.0)
    >>> t, d = lateral_step_response(1.0, 0.3)        # ten time constants: 10 / (xi alpha v) = 47 s
    >>> len(t), round(float(t[-1]), 2)
    (501, 47.14)
    """
    if t is None:
        t = np.linspace(0.0, 10 * path_following_damping(alpha, v, xi)["time_constant"], 501)
    tt = as_array(t, "t", ndim=1, min_size=2)
    step = np.diff(tt)
    if tt[0] != 0 or not step[0] > 0 or not np.allclose(step, step[0], rtol=1e-9, atol=0.0):
        raise ValueError(f"t: expected equally spaced increasing times from 0 (np.linspace(0, T, n)), got "
                         f"{describe(t)} from {tt[0]} to {tt[-1]}")
    d0 = as_finite_scalar(offset, "offset")
    resp = control.step_response(path_following_linearisation(alpha, v, xi), T=tt)
    d = float(d0) * (1.0 - np.asarray(resp.outputs, dtype=float).ravel())
    require_finite_result("alpha, v, xi, t, offset", d)
    return np.asarray(resp.time, dtype=float), d


class FollowTrace(NamedTuple):
    """A simulated run of Eq. (8) with perfect pose feedback (:func:`simulate_path_following`)."""

    t: np.ndarray             #: times (s), shape (K,)
    poses: np.ndarray         #: true poses, shape (K, 3)
    d: np.ndarray             #: distance to the path (m), shape (K,)
    theta_tilde: np.ndarray   #: heading error (rad), shape (K,)
    v: np.ndarray             #: commanded speed (m/s), shape (K,); the last is 0
    omega: np.ndarray         #: commanded turn rate (rad/s), shape (K,); the last is 0


def simulate_path_following(path: VisualPath, start_pose: Any, *, alpha: float, v: float, duration: float,
                            dt: float = 0.05, w_max: float | None = None, xi: float = XI) -> FollowTrace:
    """Drive Eq. (6) under the law of Eq. (8) with the true pose, from ``start_pose``.

    Parameters
    ----------
    path : VisualPath
    start_pose : array_like, shape (3,)
    alpha, xi : float
        Gains as in :func:`~robokit.controllers.path_following.path_following_gains`.
    v : float
        Forward speed (m/s, > 0).
    duration : float
        Longest simulated time (s); the run stops earlier when the reference point passes the end
        of the path.
    dt : float, default 0.05
        Control period (s); the command is held over each step.
    w_max : float, optional
        Turn-rate limit (rad/s) applied with :func:`saturate_command`; ``None`` for none.

    Returns
    -------
    FollowTrace

    Raises
    ------
    PathSingularityError
        If the robot reaches the path's centre of curvature.
    ValueError, TypeError
        For invalid arguments, or more than 10^7 steps.

    Notes
    -----
    Eq. (6) integrated exactly over each step (:func:`robokit.sim.unicycle_step`), Eq. (7) and
    Eq. (8) at every step, no noise: the reference for the linearised loop of
    :func:`path_following_linearisation`.

    Examples
    --------
    >>> from robokit.controllers import path_from_poses
    >>> line = path_from_poses([[0, 0, 0], [10, 0, 0]])
    >>> run = simulate_path_following(line, [0.0, 0.1, 0.0], alpha=2.0, v=0.3, duration=10.0)
    >>> len(run.t), round(float(run.d[0]), 3), round(float(abs(run.d[-1])), 3)
    (201, 0.1, 0.001)
    """
    if not isinstance(path, VisualPath):
        raise TypeError(f"path: expected a VisualPath, got {describe(path)}")
    pose = as_planar(start_pose, "start_pose", shape=(3,)).copy()
    k2, k3 = path_following_gains(alpha, xi)
    speed = as_positive(v, "v")
    T = as_positive(duration, "duration")
    h = as_positive(dt, "dt")
    wm = None if w_max is None else as_positive(w_max, "w_max")
    n = int(math.floor(T / h + 1e-9))
    require_sample_count(n, "duration, dt")
    t, poses, d, th, vs, ws = [], [], [], [], [], []
    ref = None
    for k in range(n + 1):
        ref = reference_point(path, pose, previous=None if ref is None else ref.index, window=1.0 + 2 * speed * h,
                              validate=False)
        t.append(k * h), poses.append(pose), d.append(ref.d), th.append(ref.theta_tilde)
        if k == n or ref.s >= path.length:
            vs.append(0.0), ws.append(0.0)
            break
        vc, wc = reference_command(ref, speed, k2, k3, wm)
        require_finite_result("start_pose, alpha, v, dt, xi", vc, wc)
        vs.append(vc), ws.append(wc)
        pose = unicycle_step(pose, vc, wc, h, validate=False)
    return FollowTrace(np.array(t), np.array(poses), np.array(d), np.array(th), np.array(vs), np.array(ws))
