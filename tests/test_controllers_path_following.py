"""Visual-path following (Eq. (6)-(8)): the path, the reference point, the law, its linearisation."""
from __future__ import annotations

import math

import control
import numpy as np
import pytest

from robokit.controllers import (PathFollower, PathSingularityError, VisualPath, lateral_step_response, path_following_command, path_following_damping, path_following_gains, path_following_poles, path_from_poses, reference_point, simulate_path_following)
from robokit.controllers.path_following import saturate_command
from robokit.controllers.path_following_loop import path_following_linearisation
from robokit.geometry import wrap_angle
from robokit.sim import unicycle_step

XI = 1 / math.sqrt(2)


def line_path(length=20.0, n=401):
    s = np.linspace(0.0, length, n)
    return VisualPath(np.column_stack([s, 0 * s, 0 * s]), s, 0 * s)


def circle_path(radius=2.0, n=4001, turns=1.0):
    """Exact counter-clockwise circle about the origin, starting at (0, -R) heading +x."""
    a = -np.pi / 2 + np.linspace(0.0, 2 * np.pi * turns, n)
    poses = np.column_stack([radius * np.cos(a), radius * np.sin(a), wrap_angle(a + np.pi / 2)])
    return VisualPath(poses, radius * (a - a[0]), np.full(n, 1 / radius))


# --- the path -----------------------------------------------------------------------------------

def test_two_key_poses_give_a_straight_line():
    path = path_from_poses([[1.0, 1.0, 9.0], [4.0, 5.0, 9.0]], spacing=0.1)
    assert path.length == pytest.approx(5.0, rel=1e-12)
    assert np.abs(path.curvature).max() < 1e-12
    assert np.allclose(path.poses[:, 2], math.atan2(4, 3))          # headings from the line, not the poses'
    assert np.allclose(np.diff(path.s), 0.1)


def test_spline_through_circle_key_poses_has_the_circle_s_length_and_curvature():
    R = 2.0
    a = np.linspace(0.0, np.pi, 13)
    key = np.column_stack([R * np.cos(a), R * np.sin(a), a + np.pi / 2])
    path = path_from_poses(key, spacing=0.02)
    assert path.length == pytest.approx(np.pi * R, rel=1e-4)
    assert np.abs(np.hypot(path.poses[:, 0], path.poses[:, 1]) - R).max() < 1e-3
    inner = slice(len(path.s) // 10, -len(path.s) // 10)
    assert np.abs(path.curvature[inner] - 1 / R).max() < 0.01 / R
    steps = np.linalg.norm(np.diff(path.poses[:, :2], axis=0), axis=1)   # samples evenly spaced in arc length
    assert np.allclose(np.diff(path.s), path.length / 315) and np.allclose(steps, np.diff(path.s), rtol=1e-4)


def test_curvature_is_the_derivative_of_the_heading():
    key = [[0, 0, 0], [1.5, 0.2, 0], [3, 1.5, 0], [3.5, 3, 0], [5, 4, 0], [7, 4, 0]]
    path = path_from_poses(key, spacing=0.01)
    dtheta = np.gradient(np.unwrap(path.poses[:, 2]), path.s)           # central differences, independent
    assert np.abs(dtheta[2:-2] - path.curvature[2:-2]).max() < 2e-3
    assert np.abs(np.diff(path.curvature)).max() < 0.05                  # continuous (C2 spline)


@pytest.mark.parametrize("poses, match", [([0, 0, 0], "shape"), ([[0, 0, 0]], "two distinct"),
                                          ([[0, 0, 0], [0, 0, 1]], "two distinct"),
                                          ([[0, 0, 0], [1, 0, 0], [0, 0, 0]], "cusp")])
def test_paths_that_cannot_be_followed_are_refused(poses, match):
    with pytest.raises(ValueError, match=f"poses:.*{match}"):
        path_from_poses(poses)


# --- Eq. (7): the reference point ---------------------------------------------------------------

def test_reference_point_on_a_circle_matches_the_geometry():
    R, path = 2.0, circle_path()
    rng = np.random.default_rng(0)
    for _ in range(50):
        r, a, th = rng.uniform(1.4, 2.6), rng.uniform(-0.5, 2.5), rng.uniform(-np.pi, np.pi)
        ref = reference_point(path, [r * np.cos(a), r * np.sin(a), th])
        # on the polyline (chords of 3 mm) the foot moves along by up to |d| * 1.6e-3 rad
        assert np.allclose(ref.point, R * np.array([np.cos(a), np.sin(a)]), atol=1e-3)
        assert ref.d == pytest.approx(R - r, abs=1e-5)                   # inside = left of a CCW circle
        assert ref.theta_tilde == pytest.approx(wrap_angle(th - a - np.pi / 2), abs=1e-3)
        assert ref.curvature == pytest.approx(1 / R)
        assert ref.s == pytest.approx(R * (a + np.pi / 2), abs=1e-3)


def test_reference_point_is_the_nearest_point_by_brute_force():
    key = [[0, 0, 0], [2, 0.5, 0], [4, 2, 0], [4.5, 4, 0]]
    path, fine = path_from_poses(key, spacing=0.05), path_from_poses(key, spacing=0.001)
    rng = np.random.default_rng(1)
    for p in np.column_stack([rng.uniform(0, 5, 40), rng.uniform(-0.5, 4.5, 40), rng.uniform(-3, 3, 40)]):
        ref = reference_point(path, p)
        dist = np.hypot(*(fine.poses[:, :2] - p[:2]).T)
        assert math.hypot(*(ref.point - p[:2])) == pytest.approx(dist.min(), abs=3e-4)    # chords of 5 cm
        if 0 < ref.s < path.length:                                   # an interior foot: |d| is the distance
            assert abs(ref.d) == pytest.approx(dist.min(), abs=3e-4)


def test_a_search_window_keeps_the_reference_on_the_current_pass():
    phi = np.pi * np.array([0.25, 0.5, 0.75])
    bend = np.column_stack([3 + 0.3 * np.sin(phi), 0.3 - 0.3 * np.cos(phi), 0 * phi])
    key = np.vstack([[[x, 0, 0] for x in range(4)], bend, [[x, 0.6, 0] for x in range(3, -1, -1)]])
    hairpin = path_from_poses(key, spacing=0.02)
    robot = [1.5, 0.35, 0.0]                                  # 0.35 m left of the way out, 0.25 m from the way back
    everywhere = reference_point(hairpin, robot)
    assert everywhere.d == pytest.approx(0.25, abs=0.02) and everywhere.s > hairpin.length / 2   # spline: +-1 cm
    out = reference_point(hairpin, [1.5, 0.0, 0.0])
    local = reference_point(hairpin, robot, previous=out.index, window=1.0)
    assert local.d == pytest.approx(0.35, abs=0.02) and local.s == pytest.approx(out.s, abs=0.01)


def test_beyond_the_end_the_arc_length_runs_on():
    ref = reference_point(line_path(2.0, 5), [2.5, 0.1, 0.0])
    assert ref.s == pytest.approx(2.5) and ref.d == pytest.approx(0.1) and np.allclose(ref.point, [2.0, 0.0])


# --- Eq. (8): gains, law, saturation ------------------------------------------------------------

@pytest.mark.parametrize("alpha", [0.5, 1.0, 2.0, 4.0])
def test_gains_are_alpha_squared_and_two_xi_alpha(alpha):
    assert path_following_gains(alpha) == pytest.approx((alpha ** 2, math.sqrt(2) * alpha))
    assert path_following_gains(alpha, xi=0.3) == pytest.approx((alpha ** 2, 0.6 * alpha))


def test_the_law_by_hand():
    k2, k3, v = 4.0, 2.83, 0.3
    for d, th, c in [(0.2, 0.0, 0.0), (0.1, 0.5, 0.4), (-0.3, -1.2, -0.8), (0.0, 0.0, 0.5)]:
        sinc = math.sin(th) / th if th else 1.0
        want = -k3 * abs(v) * th - k2 * v * d * sinc + v * math.cos(th) * c / (1 - c * d)
        assert path_following_command(d, th, c, v, k2, k3) == pytest.approx(want, rel=1e-12, abs=1e-15)
    assert path_following_command(0.0, 0.0, 0.5, v, k2, k3) == pytest.approx(v * 0.5)   # a circle: omega = v c
    # sin(x)/x is continuous at 0, and the law is homogeneous of degree one in v >= 0
    assert path_following_command(0.2, 1e-9, 0.3, v, k2, k3) == pytest.approx(
        path_following_command(0.2, 0.0, 0.3, v, k2, k3), abs=1e-8)
    assert path_following_command(0.1, 0.5, 0.4, 2 * v, k2, k3) == pytest.approx(
        2 * path_following_command(0.1, 0.5, 0.4, v, k2, k3))


def test_the_law_broadcasts_like_a_loop():
    rng = np.random.default_rng(2)
    d, th, c = rng.uniform(-0.5, 0.5, 30), rng.uniform(-2, 2, 30), rng.uniform(-1, 1, 30)
    w = path_following_command(d, th, c, 0.3, 4.0, 2.8)
    assert w.shape == (30,)
    assert np.allclose(w, [path_following_command(*x, 0.3, 4.0, 2.8) for x in zip(d, th, c)])


@pytest.mark.parametrize("d, c", [(1.0, 1.0), (0.6, 2.0), (-0.6, -2.0)])
def test_the_centre_of_curvature_is_a_named_error(d, c):
    with pytest.raises(PathSingularityError, match="d, curvature"):
        path_following_command(d, 0.0, c, 0.3, 4.0, 2.8)
    assert issubclass(PathSingularityError, ValueError)


def test_saturation_keeps_the_curvature_and_is_the_paper_s_rule():
    v, w = saturate_command(0.3, -2.0, v_max=0.3, w_max=0.5)
    assert w == -0.5 and v == pytest.approx(0.3 * 0.5 / 2.0)            # Vmax Wmax / |omega|
    assert saturate_command(0.2, 0.1, 0.3, 0.5) == (0.2, 0.1)             # within the limits: untouched
    vs, ws = saturate_command(np.array([0.6, 0.3, 0.3]), np.array([0.2, 1.5, -0.1]), 0.3, 0.5)
    assert np.allclose(vs, [0.3, 0.1, 0.3]) and np.allclose(ws, [0.1, 0.5, -0.1])
    assert np.allclose(ws / vs, np.array([0.2, 1.5, -0.1]) / np.array([0.6, 0.3, 0.3]))


# --- the closed loop: sign convention, Lyapunov, convergence, rates -----------------------------

def _simulate_flipped(path, start, alpha, v, dt, duration):
    """The same law with the normal pointing RIGHT of the path (d's sign flipped)."""
    k2, k3 = path_following_gains(alpha)
    pose, ds = np.asarray(start, float), []
    for _ in range(int(duration / dt)):
        ref = reference_point(path, pose)
        ds.append(ref.d)
        w = path_following_command(-ref.d, ref.theta_tilde, ref.curvature, v, k2, k3)
        pose = unicycle_step(pose, v, w, dt)
    return np.array(ds)


def test_the_left_normal_is_the_stabilising_convention():
    line = line_path(40.0, 801)
    good = simulate_path_following(line, [0.0, 0.3, 0.0], alpha=2.0, v=0.3, duration=30.0, dt=0.05)
    assert abs(good.d[-1]) < 1e-3
    bad = _simulate_flipped(line, [0.0, 0.3, 0.0], alpha=2.0, v=0.3, dt=0.05, duration=30.0)
    assert np.abs(bad).max() > 1.0                                          # runs away from the path


@pytest.mark.parametrize("path", [line_path(40.0, 2001), circle_path(n=40001)], ids=["line", "circle"])
def test_the_lyapunov_function_never_grows(path):
    """On a polyline of 3 mm chords the interpolated heading adds ~1e-5 V; 0.3 mm chords keep to the law."""
    alpha = 2.0
    k2, _ = path_following_gains(alpha)
    run = simulate_path_following(path, [0.0, -2.0 + 0.5, 0.6] if path.curvature[0] else [0.0, 0.5, 0.6],
                                  alpha=alpha, v=0.3, duration=25.0, dt=0.01)
    V = k2 * run.d ** 2 / 2 + run.theta_tilde ** 2 / 2                      # dV/dt = -k3 |v| theta_tilde^2
    assert np.diff(V).max() <= 1e-6 * V[0]
    assert V[-1] < 1e-3 * V[0]


@pytest.mark.parametrize("path, start", [(line_path(40.0, 2001), [0.0, 0.02, 0.0]),
                                         (circle_path(), [0.0, -2.02, 0.0])], ids=["line", "circle"])
@pytest.mark.parametrize("alpha", [1.0, 2.0, 4.0])
def test_small_offsets_decay_as_the_linearised_poles_say(path, start, alpha):
    """Nonlinear simulation against python-control's response of the linearised loop (2 % of the offset)."""
    v = 0.3
    run = simulate_path_following(path, start, alpha=alpha, v=v, duration=15.0, dt=0.01)
    d0 = run.d[0]
    _, d_lin = lateral_step_response(alpha, v, t=run.t, offset=d0)
    assert np.abs(run.d - d_lin).max() < 0.02 * abs(d0)
    lin = control.initial_response(path_following_linearisation(alpha, v), run.t, initial_state=[d0, 0.0],
                                   return_states=True)
    assert np.abs(run.theta_tilde - np.asarray(lin.states)[1]).max() < 0.02 * alpha * abs(d0)


def test_large_offsets_converge_on_line_and_circle():
    for path, start in [(line_path(40.0, 2001), [0.0, -0.6, 0.5]), (circle_path(), [0.0, -2.5, -0.4])]:
        run = simulate_path_following(path, start, alpha=2.0, v=0.3, duration=30.0, dt=0.05, w_max=1.0)
        assert abs(run.d[-1]) < 1e-3 and abs(run.theta_tilde[-1]) < 1e-3
        assert np.abs(run.omega[:-1]).max() <= 1.0 + 1e-12


def test_the_oscillation_has_the_damped_frequency_of_the_poles():
    alpha, v, xi = 2.0, 0.3, 0.3
    run = simulate_path_following(line_path(60.0, 3001), [0.0, 0.01, 0.0], alpha=alpha, v=v, xi=xi,
                                  duration=40.0, dt=0.005)
    crossings = run.t[1:][np.diff(np.sign(run.d)) != 0]
    half_period = np.diff(crossings).mean()
    assert half_period == pytest.approx(np.pi / (alpha * v * math.sqrt(1 - xi ** 2)), rel=0.01)


# --- python-control: linearisation, poles, damping, step response -------------------------------

@pytest.mark.parametrize("alpha", [0.5, 1.0, 2.0, 4.0])
def test_poles_and_damping_are_alpha_v_xi(alpha):
    v = 0.3
    want = alpha * v * np.array([-XI - 1j * math.sqrt(1 - XI ** 2), -XI + 1j * math.sqrt(1 - XI ** 2)])
    assert np.allclose(path_following_poles(alpha, v), want, atol=1e-12)
    info = path_following_damping(alpha, v)
    assert info["natural_frequency"] == pytest.approx(alpha * v)
    assert info["damping"] == pytest.approx(XI)
    assert info["time_constant"] == pytest.approx(1 / (XI * alpha * v))


def test_the_linearisation_is_the_jacobian_of_the_nonlinear_error_dynamics():
    """Finite differences of Samson's path coordinates under Eq. (8) on a curved path (c = 0.5)."""
    alpha, v, c = 2.0, 0.3, 0.5
    k2, k3 = path_following_gains(alpha)

    def f(e):
        d, th = e
        w = path_following_command(d, th, c, v, k2, k3)
        return np.array([v * math.sin(th), w - c * v * math.cos(th) / (1 - c * d)])

    h = 1e-6
    J = np.column_stack([(f(np.eye(2)[j] * h) - f(-np.eye(2)[j] * h)) / (2 * h) for j in range(2)])
    assert np.allclose(path_following_linearisation(alpha, v).A, J, atol=1e-8)


def test_the_step_response_is_the_damped_oscillation():
    alpha, v, d0 = 2.0, 0.3, 0.1
    t = np.linspace(0.0, 30.0, 601)
    _, d = lateral_step_response(alpha, v, t=t, offset=d0)
    wn, wd = alpha * v, alpha * v * math.sqrt(1 - XI ** 2)
    closed = d0 * np.exp(-XI * wn * t) * (np.cos(wd * t) + XI / math.sqrt(1 - XI ** 2) * np.sin(wd * t))
    assert np.abs(d - closed).max() < 1e-6
    init = control.initial_response(path_following_linearisation(alpha, v), t, initial_state=[d0, 0.0])
    assert np.allclose(d, np.asarray(init.outputs).ravel(), atol=1e-9)
    assert -d.min() / d0 == pytest.approx(math.exp(-math.pi * XI / math.sqrt(1 - XI ** 2)), rel=1e-3)   # 4.3 %


# --- the follower ---------------------------------------------------------------------------------

def test_the_follower_reaches_the_goal_and_stops():
    path = path_from_poses([[0, 0, 0], [3, 0, 0], [5, 1.5, 0], [5.5, 3.5, 0]], spacing=0.02)
    follower = PathFollower(path, alpha=2.0, v_max=0.3, w_max=1.0)
    pose, progress, commands = np.array([0.0, -0.6, -1.0]), [], []     # right of the path, heading away
    for _ in range(2000):
        v, w = follower.command(pose)
        commands.append((v, w)), progress.append(follower.progress)
        if follower.done:
            break
        pose = unicycle_step(pose, v, w, 0.05)
    assert follower.done and follower.reached and commands[-1] == (0.0, 0.0)
    assert math.hypot(*(pose[:2] - path.goal[:2])) < 0.1
    assert np.all(np.diff(progress) >= -1e-9) and progress[-1] > 0.95
    commands = np.array(commands[:-1])
    assert np.all(np.abs(commands[:, 1]) <= 1.0 + 1e-12) and np.all(commands[:, 0] <= 0.3 + 1e-12)
    assert commands[:, 0].min() < 0.3                          # a saturated turn slowed the robot down


def test_the_follower_survives_an_estimate_that_jumps():
    """A false fix can throw the estimate across the path: the follower searches again, never divides by 0."""
    circle = circle_path()
    follower = PathFollower(circle, alpha=2.0, v_max=0.3, w_max=1.0)
    follower.command([0.0, -2.0, 0.0])
    v, w = follower.command([0.0, 0.0, 0.3])                   # the centre of curvature: 1 - c d = 0
    assert math.isfinite(v) and math.isfinite(w) and abs(w) <= 1.0
    v, w = follower.command([2.0, 1.0, 1.6])                    # 3 m of arc away, beyond the 1 m window
    assert follower.reference.s == pytest.approx(2.0 * (math.atan2(1.0, 2.0) + math.pi / 2), abs=0.01)
    assert follower.reference.d == pytest.approx(2.0 - math.hypot(2.0, 1.0), abs=1e-4)
