"""MoCap simulation and the marker fit: statistics of the simulated noise and dropouts, the fit
against a generic nonlinear least-squares solver, the hold of the last good pose."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from robokit.geometry import DegenerateFitError, se3_from_rt, so3_exp, transform_points
from robokit.legged import MARKERS
from robokit.legged.mocap import TooFewMarkersError, fit_marker_pose, mocap_body_poses
from robokit.legged.mocap import simulate_mocap


def poses(n, seed=0):
    rng = np.random.default_rng(seed)
    return se3_from_rt(so3_exp(rng.normal(scale=0.5, size=(n, 3))), rng.normal(size=(n, 3)))


def test_noise_free_markers_are_the_transformed_body_points():
    T = poses(5)
    frames = simulate_mocap(T, MARKERS, noise=0.0, dropout=0.0, rng=0)
    assert frames.visible.all()
    for k in range(5):
        assert np.abs(frames.positions[k] - transform_points(T[k], MARKERS)).max() < 1e-15


def test_noise_and_dropout_statistics_and_hidden_entries_are_zero():
    T = poses(4000)
    frames = simulate_mocap(T, MARKERS, noise=0.001, dropout=0.15, rng=1)
    clean = simulate_mocap(T, MARKERS, noise=0.0, dropout=0.0, rng=1).positions
    vis = frames.visible
    err = (frames.positions - clean)[vis]
    assert abs(err.std() - 0.001) < 0.00003 and abs(err.mean()) < 0.00003
    # binomial: 16000 markers, p = 0.15 -> std of the fraction 0.0028
    assert abs((~vis).mean() - 0.15) < 0.012
    assert np.all(frames.positions[~vis] == 0.0)


def test_bursts_hide_whole_frames_for_burst_length_frames():
    T = poses(20000)
    frames = simulate_mocap(T, MARKERS, noise=0.0, dropout=0.0, rng=2, bursts=0.01, burst_length=25)
    lost = ~frames.visible.any(1)
    assert np.array_equal(lost, ~frames.visible.all(1))                # a burst hides every marker
    edges = np.flatnonzero(np.diff(np.r_[0, lost.astype(int), 0]))
    runs = edges[1::2] - edges[::2]
    assert len(runs) > 20 and runs[:-1].min() >= 25                     # (the last may be cut by the end)
    # a frame is lost if a burst started in it or in the 24 before: 1 - 0.99^25 = 0.222
    assert abs(lost.mean() - (1 - 0.99 ** 25)) < 0.02


def test_same_seed_same_frames_and_bursts_leave_the_noise_draws_alone():
    T = poses(50)
    a = simulate_mocap(T, MARKERS, 0.001, 0.1, 7)
    b = simulate_mocap(T, MARKERS, 0.001, 0.1, np.random.default_rng(7))
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.visible, b.visible)
    c = simulate_mocap(T, MARKERS, 0.001, 0.1, 7, bursts=0.05)
    keep = c.visible
    assert np.array_equal(a.positions[keep], c.positions[keep]) and np.all(a.visible[keep])


def test_fit_marker_pose_is_the_least_squares_optimum():
    rng = np.random.default_rng(3)
    T = poses(1, 3)[0]
    seen = transform_points(T, MARKERS) + rng.normal(scale=0.002, size=(4, 3))
    for vis in ([True] * 4, [True, False, True, True]):
        v = np.array(vis)
        fit = fit_marker_pose(MARKERS, seen, v)

        # a generic solver around the answer: the rotation as a perturbation of the fitted one
        sol = least_squares(lambda x: (MARKERS[v] @ (fit[:3, :3] @ so3_exp(x[:3])).T + x[3:] - seen[v]).ravel(),
                            np.r_[np.full(3, 1e-3), fit[:3, 3] + 1e-3], xtol=1e-15, ftol=1e-15, gtol=1e-15)
        assert np.abs(sol.x[:3]).max() < 1e-7 and np.abs(sol.x[3:] - fit[:3, 3]).max() < 1e-8
        assert np.abs(fit - T).max() > 1e-4                                 # the noise did move it
    # noise-free with three markers: exact
    exact = transform_points(T, MARKERS)
    assert np.abs(fit_marker_pose(MARKERS, exact, [False, True, True, True]) - T).max() < 1e-12


def test_too_few_or_collinear_markers_raise_named_errors():
    seen = transform_points(poses(1)[0], MARKERS)
    with pytest.raises(TooFewMarkersError, match="visible"):
        fit_marker_pose(MARKERS, seen, [True, False, False, True])
    assert issubclass(TooFewMarkersError, DegenerateFitError) and issubclass(TooFewMarkersError, ValueError)
    line = np.array([[0.0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.0, 0.1, 0.05]])
    with pytest.raises(DegenerateFitError):
        fit_marker_pose(line, line, [True, True, True, False])
    # hidden markers may hold anything, even NaN; a visible NaN is refused
    seen_nan = seen.copy()
    seen_nan[1] = np.nan
    assert np.all(np.isfinite(fit_marker_pose(MARKERS, seen_nan, [True, False, True, True])))
    with pytest.raises(ValueError, match="observed"):
        fit_marker_pose(MARKERS, seen_nan)


def test_mocap_body_poses_match_frame_by_frame_fits_and_hold_the_last_good_pose():
    T = poses(300, 4)
    frames = simulate_mocap(T, MARKERS, noise=0.001, dropout=0.3, rng=5, bursts=0.02, burst_length=5)
    vis = frames.visible.copy()
    vis[:3] = False                                                     # the trial starts blind
    out = mocap_body_poses(MARKERS, frames.positions, vis)
    assert np.array_equal(out.ok, vis.sum(1) >= 3)
    assert 0.2 < (~out.ok).mean() < 0.6
    last = None
    first = int(np.argmax(out.ok))
    for k in range(300):
        if out.ok[k]:
            last = fit_marker_pose(MARKERS, frames.positions[k], vis[k])
            assert np.abs(out.T_world_body[k] - last).max() < 1e-12
        else:
            want = last if last is not None else fit_marker_pose(MARKERS, frames.positions[first], vis[first])
            assert np.abs(out.T_world_body[k] - want).max() < 1e-12


def test_mocap_body_poses_flags_collinear_frames_and_refuses_a_blind_trial():
    line = np.array([[0.0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.0, 0.1, 0.05]])
    T = poses(3, 6)
    frames = simulate_mocap(T, line, 0.0, 0.0, 0)
    vis = np.array([[True] * 4, [True, True, True, False], [False, True, True, True]])
    out = mocap_body_poses(line, frames.positions, vis)
    assert out.ok.tolist() == [True, False, True]
    assert np.abs(out.T_world_body[1] - T[0]).max() < 1e-12
    with pytest.raises(TooFewMarkersError, match="visible"):
        mocap_body_poses(MARKERS, frames.positions, np.zeros((3, 4), bool))
    with pytest.raises(ValueError, match="visible"):
        mocap_body_poses(MARKERS, frames.positions, np.ones((3, 3), bool))
