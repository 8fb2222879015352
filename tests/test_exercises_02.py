"""Assignment 02: registration, check() rejecting wrong answers, and an open exercise that is fair."""
from __future__ import annotations

import numpy as np
import pytest

from robocourse.lessons.omni_localization import exercises as module
from robocourse.grading import check
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes
from robokit.vision import histogram_distance
from robokit.geometry import se2_between
from robokit.sim.motion import OFFICE_TOUR, waypoint_path
from robocourse.exercises.plain import to_plain
from robocourse.lessons.omni_localization import relaxation_runs

EXERCISES = {ex.id: ex for ex in module.EXERCISES}


def test_assignment_is_registered():
    assert module.ASSIGNMENT == "02_omni_localization"
    assert [e.id for e in exercises_for("02_omni_localization")] == list(EXERCISES)
    assert 7 <= len(EXERCISES) <= 8 and len(module.WRITTEN) >= 2
    assert sum(e.points for e in EXERCISES.values()) == 15


def test_cases_differ_between_seeds():
    for ex in EXERCISES.values():
        assert ex.make_cases(1) != ex.make_cases(2) or ex.id in ("02.path_following_command",), ex.id


def _wrong_hsi(pixels):  # forgets the 2 pi - theta branch for B > G
    p = np.asarray(pixels, float)
    r, g, b = p[:, 0], p[:, 1], p[:, 2]
    if p.ndim != 2 or p.shape[1] != 3 or np.isnan(p).any() or (p < 0).any() or (p > 1).any():
        raise ValueError("pixels")
    den = np.sqrt((r - g) ** 2 + (r - b) * (g - b))
    theta = np.arccos(np.clip(np.divide(0.5 * ((r - g) + (r - b)), den, out=np.ones_like(r), where=den > 0), -1, 1))
    return np.column_stack([theta, p.max(1) - p.min(1), p.mean(1)])


def _wrong_histogram(image, bins=32, min_saturation=0.15, min_intensity=0.04, max_intensity=0.98):
    if bins < 1 or np.shape(image)[-1] != 3:
        raise ValueError("bins")
    hsi = module.rgb_to_hsi(image)                      # counts every pixel, grey ones too
    h = np.bincount(np.minimum((hsi[..., 0] * bins / (2 * np.pi)).astype(int), bins - 1).ravel(), minlength=bins)
    return h / h.sum()


def _wrong_distance(h, H):  # squared distance, not Eq. (5)
    h, H = np.asarray(h, float), np.asarray(H, float)
    if h.shape[-1] != H.shape[-1]:
        raise ValueError("H")
    return ((H - h) ** 2).sum(axis=-1)


def _wrong_counts(query, node_descriptors, candidates, ratio=0.8):  # nearest neighbour, no ratio test
    if any(not 0 <= c < len(node_descriptors) for c in candidates):
        raise ValueError("candidates")
    q = np.asarray(query, float)
    out = []
    for c in candidates:
        t = np.asarray(node_descriptors[c], float)
        if t.shape[1] != q.shape[1]:
            raise ValueError("descriptors")
        out.append(len(q))
    return np.array(out)


def _distinct_counts(query, node_descriptors, candidates, ratio=module.RATIO):  # drops a node's repeated descriptors
    return module.fine_stage_counts(query, [np.unique(np.asarray(n, float), axis=0) for n in node_descriptors],
                                    candidates, ratio)


def _fixed_sweeps(poses, edges, measurements, edge_variances, tolerance=1e-3, max_sweeps=5000):  # no stopping test
    out = module.relax_map(poses, edges, measurements, edge_variances, tolerance=1e-12, max_sweeps=min(60, max_sweeps))
    return dict(out, converged=True)


def _one_way_edges(poses, edges, measurements, edge_variances, tolerance=1e-3, max_sweeps=5000):
    """Each edge predicts only its second node (the inverted measurement forgotten): a loop that runs."""
    P, E, Z = np.asarray(poses, float), np.asarray(edges), np.asarray(measurements, float)
    w = np.asarray(edge_variances, float)
    if np.any(w <= 0) or E.max() >= len(P):
        raise ValueError("edge_variances")
    var = np.r_[0.0, np.cumsum(w[:len(P) - 1])]
    changes = []
    for _ in range(max_sweeps):
        a, b = E[:, 0], E[:, 1]
        c, s = np.cos(P[a, 2]), np.sin(P[a, 2])
        guess = np.column_stack([P[a, 0] + c * Z[:, 0] - s * Z[:, 1], P[a, 1] + s * Z[:, 0] + c * Z[:, 1],
                                 P[a, 2] + Z[:, 2]])
        weight = 1 / (var[a] + w)
        total = np.bincount(b, weight, minlength=len(P))
        new = P.copy()
        free = (np.arange(len(P)) != 0) & (total > 0)
        for k in (0, 1):
            new[free, k] = np.bincount(b, weight * guess[:, k], minlength=len(P))[free] / total[free]
        new[free, 2] = np.arctan2(np.bincount(b, weight * np.sin(guess[:, 2]), minlength=len(P)),
                                  np.bincount(b, weight * np.cos(guess[:, 2]), minlength=len(P)))[free]
        var[free] = np.bincount(b, minlength=len(P))[free] / total[free]
        step = new - P
        changes.append(float(np.hypot(step[:, 0], step[:, 1]).sum()
                             + np.abs((step[:, 2] + np.pi) % (2 * np.pi) - np.pi).sum()))
        P = new
        if changes[-1] < tolerance:
            break
    return {"poses": P.tolist(), "sweeps": len(changes), "converged": changes[-1] < tolerance, "changes": changes}


def _wrong_command(d, theta_tilde, curvature, v, k2, k3):  # drops the curvature term
    if k2 < 0 or k3 < 0 or 1 - curvature * d <= 0:
        raise ValueError("k2")
    return -k3 * abs(v) * theta_tilde - k2 * v * d * np.sinc(theta_tilde / np.pi)


def _fix_with(mistake):
    """node_fix_update with one slip: a wrong Jacobian term, the linear innovation, or no wrapping."""
    def update(x, P, node_pose, z, R):
        x, P, n, z, R = (np.asarray(a, float) for a in (x, P, node_pose, z, R))
        if n.shape != (3,) or np.any(np.linalg.eigvalsh(R) <= 0):
            raise ValueError("R, node_pose")
        c, s = np.cos(n[2]), np.sin(n[2])
        H = np.array([[c, s, 0, 0, 0], [-s, c, 0, 0, 0], [0, 0, 1, 0, 0]])
        if mistake == "sign":                       # rotates by +theta_n: d a / d y gets the wrong sign
            H[0, 1], H[1, 0] = -s, s
        h = H[:, :3] @ (x[:3] - n) if mistake != "linear" else H @ x
        y = z - h
        if mistake != "unwrapped":
            y[2] = (y[2] + np.pi) % (2 * np.pi) - np.pi
        K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
        return {"H": H, "x": x + K @ y, "P": (np.eye(5) - K @ H) @ P}
    return update


def _coarse_only(query_histogram, query_descriptors, node_histograms, node_descriptors):
    if len(node_histograms) == 0:
        raise ValueError("node_histograms")
    return int(np.argmin(histogram_distance(query_histogram, node_histograms)))


WRONG = {"02.rgb_to_hsi": _wrong_hsi, "02.hue_histogram": _wrong_histogram,
         "02.histogram_distance": _wrong_distance, "02.fine_stage_counts": _wrong_counts,
         "02.relax_map": _fixed_sweeps, "02.path_following_command": _wrong_command,
         "02.node_fix_update": _fix_with("sign"), "02.recognise_node": _coarse_only}


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_fails_a_wrong_implementation(exercise_id, capsys):
    with pytest.raises(AssertionError, match=exercise_id) as failed:
        check(exercise_id, WRONG[exercise_id])
    assert "FAIL" in str(failed.value)          # the failed cases, in the message students see


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_passes_the_reference(exercise_id, capsys):
    assert_check_passes(exercise_id, EXERCISES[exercise_id].answer, len(EXERCISES[exercise_id].make_cases(2024)))


@pytest.mark.parametrize("seed", range(12))
def test_the_open_exercise_is_fair(seed):
    """Its expected answer is the node found by matching against every node (no coarse stage), and the
    colour histogram alone is fooled in the look-alike cases, so the method matters."""
    fooled = 0
    for case in EXERCISES["02.recognise_node"].make_cases(seed):
        if case.raises:
            continue
        q_hist, q_desc, hists, nodes = case.args
        exhaustive = module.fine_stage_counts(q_desc, nodes, list(range(len(nodes))))
        answer = module.recognise_node(*case.args)
        assert answer == int(np.argmax(exhaustive)) and np.sort(exhaustive)[-1] > 2 * np.sort(exhaustive)[-2]
        fooled += _coarse_only(*case.args) != answer
    assert fooled >= 1


def _valid(exercise_id, seed=2024):
    ex = EXERCISES[exercise_id]
    return ex, [c for c in ex.make_cases(seed) if not c.raises]


def test_the_fine_stage_feedback_says_which_way_a_count_is_off():
    ex, cases = _valid("02.fine_stage_counts")
    duplicated = next(c for c in cases if "twice" in c.label)
    message = ex.compare(to_plain(ex.answer(*duplicated.args)), to_plain(_distinct_counts(*duplicated.args)))
    assert "more than the unambiguous matches" in message and "[0]" in message
    assert all(ex.compare(to_plain(ex.answer(*c.args, **c.kwargs)), to_plain(_distinct_counts(*c.args, **c.kwargs)))
               is None for c in cases if c is not duplicated)         # only the duplicates tell it apart


@pytest.mark.parametrize("seed", range(4))
def test_the_relaxation_cases_are_the_lessons_tour(seed):
    """Nodes on the office tour, the odometry drifted from the truth, at least one loop, a loop long enough
    to need hundreds of sweeps; the capped case stops unconverged."""
    tour = waypoint_path(OFFICE_TOUR, 0.3, rate=10.0).poses
    graph = relaxation_runs.tour_graph(seed)
    truth, n = np.asarray(graph["truth"]), len(graph["poses"])
    assert np.abs(truth[:, None, :2] - tour[None, :, :2]).sum(axis=2).min(axis=1).max() < 1e-5
    assert len(graph["edges"]) > n - 1 and np.abs(np.asarray(graph["poses"]) - truth).max() > 0.3
    ex, cases = _valid("02.relax_map", seed)
    runs = [ex.answer(*c.args, **c.kwargs) for c in cases]
    assert [r["converged"] for r in runs] == [True, True, False] and runs[2]["sweeps"] == 40
    assert min(r["sweeps"] for r in runs[:2]) > 150


def test_the_relaxation_outcome_allows_the_gauge_and_shows_the_run():
    ex, cases = _valid("02.relax_map")
    case = cases[0]
    expected = to_plain(ex.answer(*case.args, **case.kwargs))
    turned = np.asarray(expected["poses"])
    c, s = np.cos(0.3), np.sin(0.3)
    turned = np.column_stack([turned[:, :2] @ np.array([[c, s], [-s, c]]) + [2.0, -1.0], turned[:, 2] + 0.3])
    assert ex.compare(expected, dict(expected, poses=turned.tolist())) is None
    early = ex.compare(expected, to_plain(_fixed_sweeps(*case.args, **case.kwargs)))
    assert "your map is not the relaxed one" in early and "sweep 10:" in early
    wrong = ex.compare(expected, to_plain(_one_way_edges(*case.args, **case.kwargs)))
    assert "your map is not the relaxed one" in wrong and "your changes leave the reference's at sweep" in wrong
    slow = dict(expected, sweeps=2 * expected["sweeps"], changes=expected["changes"] * 2)
    assert "you stopped after" in ex.compare(expected, slow)
    assert "one per sweep" in ex.compare(expected, dict(expected, changes=expected["changes"][:-1]))


def test_the_relaxation_shortcuts_fail_every_case():
    ex = EXERCISES["02.relax_map"]
    for seed in range(3):
        for case in ex.make_cases(seed):
            if case.raises:
                continue
            expected = to_plain(ex.answer(*case.args, **case.kwargs))
            for name, shortcut in ex.shortcuts.items():
                assert ex.compare(expected, to_plain(shortcut(*case.args, **case.kwargs))) is not None, (name, seed)


@pytest.mark.parametrize("mistake, names", [("sign", ["H[0, 1] = da/dy", "H[1, 0] = db/dx"]),
                                            ("linear", ["z - H x"]), ("unwrapped", ["not wrapped"])])
def test_the_fix_update_feedback_names_the_slip(mistake, names):
    ex, cases = _valid("02.node_fix_update")
    messages = [ex.compare(to_plain(ex.answer(*c.args)), to_plain(_fix_with(mistake)(*c.args))) for c in cases]
    named = [m for m in messages if m and all(n in m for n in names)]
    assert named, messages
    if mistake != "sign":       # H right: the state is named, not the Jacobian
        assert all(m is None or m.startswith("'x': H is right") for m in messages)


def test_the_fix_jacobian_matches_finite_differences():
    ex, cases = _valid("02.node_fix_update")
    for case in cases:
        x, _, node, _, _ = case.args
        H = np.asarray(module.node_fix_jacobian(node))
        numeric = np.zeros((3, 5))
        for k in range(5):
            step = np.eye(5)[k] * 1e-6
            numeric[:, k] = (se2_between(node, (np.asarray(x) + step)[:3]) -
                             se2_between(node, (np.asarray(x) - step)[:3])) / 2e-6
        assert np.allclose(H, numeric, atol=1e-6), case.label
