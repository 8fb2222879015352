"""When map alignment beats odometry (issue 35, deliverable 5): robocourse's omni_localization.alignment.

Small synthetic pose graphs only (no rendered office): a square driven once and closed at the start,
a straight drive with one loop in the middle, Manhattan-world walks.
"""
from __future__ import annotations

import numpy as np
import pytest

from robokit.geometry import se2_between, se2_compose
from robokit.mapping import PoseGraph, manhattan_world_graph, pose_graph_from_odometry, relax
from robocourse.lessons.omni_localization import alignment as al

SIGMA = (0.05, 0.05, 0.02)


def _dead_reckoning(truth, steps):
    odo = [truth[0]]
    for step in steps:
        odo.append(se2_compose(odo[-1], step))
    return np.array(odo)


def square(loop_error=(0.0, 0.0, 0.0)):
    """A 4 m square, a node every metre, driven once back to the start; odometry over-turns each corner
    by 0.03 rad; one loop edge from the start to the return, its measurement composed with ``loop_error``."""
    truth = [np.zeros(3)]
    for k in range(16):
        truth.append(se2_compose(truth[-1], [1.0, 0.0, np.pi / 2 if k % 4 == 3 else 0.0]))
    truth = np.array(truth)
    steps = se2_between(truth[:-1], truth[1:])
    steps[3::4, 2] += 0.03
    z = se2_compose(se2_between(truth[0], truth[16]), loop_error)
    g = pose_graph_from_odometry(_dead_reckoning(truth, steps), loop_edges=[[0, 16]], loop_measurements=[z],
                                 sigma_odometry=SIGMA, sigma_loop=SIGMA)
    return g, truth


def drive(a=8, b=14, before=0.15, inside=-0.1, n=30):
    """A straight 29 m drive; odometry turns ``before`` rad wrongly before node ``a`` and ``inside`` rad
    between ``a`` and ``b``; one exact loop edge from ``a`` to ``b``."""
    truth = np.column_stack([np.arange(n, dtype=float), np.zeros(n), np.zeros(n)])
    steps = se2_between(truth[:-1], truth[1:])
    steps[a // 2, 2] += before
    steps[(a + b) // 2, 2] += inside
    g = pose_graph_from_odometry(_dead_reckoning(truth, steps), loop_edges=[[a, b]],
                                 loop_measurements=[se2_between(truth[a], truth[b])], sigma_odometry=SIGMA,
                                 sigma_loop=SIGMA)
    return g, truth


def _ratio(out, method):
    return out.rms[method] / out.rms["odometry"]


# --- the loop structure that makes alignment help ------------------------------------------------

def test_well_spread_correct_loops_beat_odometry_by_a_margin():
    g, truth = manhattan_world_graph(200, seed=1)        # 30 loops holding 92 % of the walk
    out = al.alignment_errors(g, truth)
    assert out.n_loops == 30 and out.held > 0.9
    assert out.converged
    for method in ("relaxation", "least squares"):
        assert _ratio(out, method) < 0.3, (method, out.rms)
        assert out.worst[method] < 0.5 * out.worst["odometry"], (method, out.worst)


def test_a_correct_loop_back_to_the_start_helps():
    g, truth = square()
    out = al.alignment_errors(g, truth)
    assert out.held == 1.0
    assert _ratio(out, "relaxation") < 0.5 and _ratio(out, "least squares") < 0.3, out.rms


@pytest.mark.parametrize("loop_error", [(0.0, 0.0, 0.3), (0.5, 0.0, 0.0)], ids=["17 deg off", "0.5 m off"])
def test_a_loop_edge_off_beyond_its_sigma_makes_alignment_worse_than_odometry(loop_error):
    g, truth = square(loop_error)
    errors = al.loop_edge_errors(g, truth)
    assert errors.chi2[0] > 50                           # 3 on average for an edge within its sigma
    out = al.alignment_errors(g, truth)
    assert out.rms["relaxation"] > out.rms["odometry"] and out.rms["least squares"] > out.rms["odometry"], out.rms


def test_an_exact_loop_in_mid_tour_can_undo_drift_that_was_cancelling():
    # the loop edge is the truth's relative pose, so the loss is not its error: before node 8 the odometry
    # turned 0.15 rad too far, between 8 and 14 0.1 rad back; the loop removes the 0.1 and the 16 nodes
    # after it swing with the 0.15 that no loop sees
    g, truth = drive()
    assert al.loop_edge_errors(g, truth).chi2[0] == pytest.approx(0.0, abs=1e-12)
    out = al.alignment_errors(g, truth)
    assert out.held == pytest.approx(6 / 29)
    for method in ("relaxation", "least squares"):
        assert out.rms[method] > 1.3 * out.rms["odometry"], out.rms
        heading = out.poses[method][14, 2] - truth[14, 2]
        assert heading == pytest.approx(0.15, abs=0.02)      # node 14 inherits node 8's heading error
    # the same loop when the two drifts add up: it helps
    g, truth = drive(inside=0.1)
    out = al.alignment_errors(g, truth)
    assert out.rms["least squares"] < 0.8 * out.rms["odometry"], out.rms


def test_redrawn_odometry_single_short_loop_loses_often_spread_loops_almost_never():
    g, truth = manhattan_world_graph(200, seed=1)
    loops = al.loop_rows(g)
    lo, hi = np.sort(g.edges[loops], axis=1).T
    short = loops[[np.argmin(hi - lo)]]                  # a 10-step loop: 5 % of the walk held
    assert al.held_share(g, short) < 0.1
    everything = al.odometry_redraws(g, truth, draws=30, rng=3)
    one = al.odometry_redraws(g, truth, short, draws=30, rng=3)
    assert np.mean(everything > 1) == 0.0 and np.median(everything) < 0.4
    assert np.mean(one > 1) > 0.2 and np.median(one) > 0.85


def test_redraws_are_seeded_and_shared_between_loop_sets():
    g, truth = manhattan_world_graph(60, seed=2)
    first = al.odometry_redraws(g, truth, draws=4, rng=7)
    assert np.array_equal(first, al.odometry_redraws(g, truth, draws=4, rng=7))
    assert not np.array_equal(first, al.odometry_redraws(g, truth, draws=4, rng=8))
    none = al.odometry_redraws(g, truth, [], draws=4, rng=7)  # no loops: least squares keeps the odometry
    assert np.allclose(none, 1.0)


def test_alignment_errors_relaxes_past_relax_default_sweeps():
    # a correction travels one edge per sweep: a long un-looped tail needs more than relax's default 1000
    g, truth = drive()
    assert not relax(g).converged
    out = al.alignment_errors(g, truth)
    assert out.converged and out.sweeps > 1000
    short = al.alignment_errors(g, truth, max_sweeps=1000)
    assert not short.converged


# --- the sets of loops and what they hold --------------------------------------------------------

def test_loop_rows_and_subsets():
    g = pose_graph_from_odometry(np.zeros((12, 3)), loop_edges=[[9, 6], [0, 11], [0, 4], [5, 9]])
    assert al.loop_rows(g).tolist() == [13, 14, 11, 12]            # by later node, then earlier
    sets = al.loop_subsets(g, k=2)
    assert list(sets)[:5] == ["all loops", "first loop only", "last loop only", "2 spread along the tour",
                              "2 bunched in one place"]
    assert sets["first loop only"].tolist() == [13] and sets["last loop only"].tolist() == [12]
    assert sets["2 spread along the tour"].tolist() == [13, 12]
    assert sets["2 bunched in one place"].tolist() == [14, 11]     # 5-9 and 6-9
    assert sets["only 6-9"].tolist() == [11] and len(sets) == 5 + 4
    assert al.loop_subsets(g, k=10)["4 spread along the tour"].tolist() == [13, 14, 11, 12]
    assert al.loop_subsets(pose_graph_from_odometry(np.zeros((3, 3)))) == {}


def test_held_share_counts_the_odometry_edges_inside_kept_loops():
    g = pose_graph_from_odometry(np.zeros((11, 3)), loop_edges=[[5, 2], [4, 8], [0, 1]])
    assert al.held_share(g) == pytest.approx(0.6)                  # [2, 8) of 10 edges
    assert al.held_share(g, [10]) == pytest.approx(0.3)
    assert al.held_share(g, []) == 0.0


def test_with_loops_keeps_the_chain_and_the_chosen_loops():
    g = pose_graph_from_odometry(np.zeros((5, 3)), loop_edges=[[0, 4], [1, 3]], sigma_loop=0.3)
    sub = al.with_loops(g, [5])
    assert sub.edges.tolist() == [[0, 1], [1, 2], [2, 3], [3, 4], [1, 3]]
    assert np.allclose(sub.information[-1], np.eye(3) / 0.09)
    assert al.with_loops(g, []).n_edges == 4


def test_loop_edge_errors_report_sigma_and_chi2():
    truth = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0.3, 0]])
    g = pose_graph_from_odometry(truth, loop_edges=[[0, 3]], loop_measurements=[[0, 0, 0.1]], sigma_loop=(0.1, 0.2, 0.05))
    err = al.loop_edge_errors(g, truth)
    assert err.rows.tolist() == [3] and err.edges.tolist() == [[0, 3]]
    assert err.translation[0] == pytest.approx(0.3, abs=0.02)
    assert err.heading[0] == pytest.approx(-0.1)
    assert np.allclose(err.sigma[0], [0.1, 0.2, 0.05])
    assert err.chi2[0] > 4.0


# --- bad input -------------------------------------------------------------------------------------

def _graph():
    return pose_graph_from_odometry(np.zeros((6, 3)), loop_edges=[[0, 5]])


@pytest.mark.parametrize("call, name", [
    (lambda: al.alignment_errors("graph.g2o", np.zeros((6, 3))), "graph"),
    (lambda: al.alignment_errors(_graph(), np.zeros((5, 3))), "truth"),
    (lambda: al.alignment_errors(_graph(), np.full((6, 3), np.nan)), "truth"),
    (lambda: al.alignment_errors(_graph(), np.zeros((6, 3)), keep=[0]), "keep"),       # an odometry row
    (lambda: al.alignment_errors(_graph(), np.zeros((6, 3)), keep=[5, 5]), "keep"),
    (lambda: al.alignment_errors(_graph(), np.zeros((6, 3)), keep=[[5]]), "keep"),
    (lambda: al.alignment_errors(_graph(), np.zeros((6, 3)), keep=[5.5]), "keep"),
    (lambda: al.alignment_errors(_graph(), np.zeros((6, 3)), max_sweeps=0), "max_sweeps"),
    (lambda: al.loop_subsets(_graph(), k=0), "k"),
    (lambda: al.odometry_redraws(_graph(), np.zeros((6, 3)), draws=0), "draws"),
    (lambda: al.odometry_redraws(_graph(), np.zeros((6, 3)), rng="seed"), "rng"),
    (lambda: al.loop_edge_errors(_graph(), np.zeros((6, 3)), keep=[9]), "keep"),
    (lambda: al.held_share(PoseGraph(np.zeros((3, 3)), [[0, 2]], [[0.0, 0.0, 0.0]])), "graph"),   # no chain
    # an odometry edge stored backwards (1 -> 0): redrawing would write a forward step into it
    (lambda: al.odometry_redraws(PoseGraph(np.zeros((3, 3)), [[1, 0], [1, 2]], np.zeros((2, 3))), np.zeros((3, 3))),
     "graph"),
])
def test_bad_input_is_refused_naming_the_argument(call, name):
    with pytest.raises((TypeError, ValueError)) as info:
        call()
    assert str(info.value).startswith(f"{name}:"), str(info.value)
