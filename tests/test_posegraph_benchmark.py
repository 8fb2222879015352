"""Lesson 02's real pose graph: the shipped Intel file, its reading, and both solvers on it."""
import hashlib
import re
from importlib import resources

import numpy as np
import pytest

from robocourse.lessons.omni_localization import benchmark
from robocourse.lessons.omni_localization.benchmark import (GTSAM_CHI2, N_EDGES, N_POSES, SHA256, benchmark_graph,
                                                            solve_benchmark)
from robokit.mapping import pose_graph_cost, read_g2o, relax, write_g2o

FOLDER = resources.files("robocourse") / "data" / "posegraphs"


@pytest.fixture(scope="module")
def graph():
    return benchmark_graph()


@pytest.fixture(scope="module")
def runs(graph):
    return solve_benchmark(graph, max_sweeps=150)


def test_the_shipped_file_is_the_upstream_one():
    data = (FOLDER / "intel.g2o").read_bytes()
    readme = (FOLDER / "README.md").read_text()
    assert hashlib.sha256(data).hexdigest() == SHA256 and SHA256 in readme
    assert "BSD" in readme and "Copyright (C) 2011 Rainer Kuemmerle" in (FOLDER / "LICENSE.g2o").read_text()
    tags = [line.split()[0] for line in data.decode().splitlines() if line.strip()]
    assert (tags.count("VERTEX_SE2"), tags.count("EDGE_SE2"), len(tags)) == (N_POSES, N_EDGES, N_POSES + N_EDGES)
    assert f"{N_POSES} robot poses" in readme and f"{N_EDGES} relative-pose measurements" in readme


def test_the_reader_keeps_the_files_numbers(graph):
    text = (FOLDER / "intel.g2o").read_text()
    vertex = re.search(r"^VERTEX_SE2 1 (\S+) (\S+) (\S+)", text, re.M).groups()
    edge = text.split("EDGE_SE2 ", 1)[1].split()[:11]            # the first edge line: "441 442 ... 5000"
    assert graph.ids.tolist() == list(range(N_POSES)) and graph.fixed == 0
    np.testing.assert_array_equal(graph.poses[1], np.array(vertex, float))
    assert graph.ids[graph.edges[0]].tolist() == [int(edge[0]), int(edge[1])]
    np.testing.assert_array_equal(graph.measurements[0], np.array(edge[2:5], float))
    np.testing.assert_array_equal(graph.information[0], np.diag(np.array(edge[5:], float)[[0, 3, 5]]))
    consecutive = np.diff(graph.ids[graph.edges], axis=1).ravel() == 1
    assert (consecutive.sum(), (~consecutive).sum()) == (942, 895)       # the README's split
    assert pose_graph_cost(read_g2o(write_g2o(graph))) == pose_graph_cost(graph)


def test_least_squares_reaches_the_independent_optimum(graph, runs):
    # GTSAM_CHI2 is GTSAM 4.3.0's optimum evaluated with our cost, rounded to 4 decimals (no
    # published optimum exists for this file): Gauss-Newton must land on it to that precision
    ls = runs.least_squares
    assert ls.converged and ls.iterations <= 10
    assert ls.cost == pytest.approx(GTSAM_CHI2, abs=1e-4)
    assert ls.cost == pytest.approx(pose_graph_cost(graph, ls.poses), rel=1e-12)
    assert ls.cost < 0.45 * runs.initial_cost


def test_relaxation_lowers_the_cost_and_stays_above_least_squares(graph, runs):
    sweeps, costs = runs.relaxation_curve
    assert sweeps.tolist() == [1, 10, 100, 150] and runs.relaxation.iterations == 150
    assert runs.initial_cost > costs[0] > costs[1] > costs[2] > costs[3] == runs.relaxation.cost
    assert runs.relaxation.cost > runs.least_squares.cost
    assert runs.initial_cost == pose_graph_cost(graph) and runs.relaxation.time > 0


def test_relaxation_in_stages_is_one_run(graph, runs):
    # solve_benchmark stops at 1, 10, 100 sweeps to record the cost and carries poses and node
    # variances on: the same sweeps as one call of relax
    one = relax(graph, max_iterations=150)
    np.testing.assert_allclose(runs.relaxation.poses, one.poses, rtol=0, atol=1e-12)


def test_both_solvers_start_from_the_files_estimates(graph):
    before = graph.poses.copy()
    still = solve_benchmark(graph, max_sweeps=0)
    assert still.relaxation.cost == still.initial_cost and still.relaxation.iterations == 0
    assert not still.relaxation.converged and still.relaxation_curve[0].size == 0
    np.testing.assert_array_equal(graph.poses, before)


def test_the_default_cap_follows_fast_mode(monkeypatch, graph):
    monkeypatch.setattr(benchmark, "RELAX_SWEEPS", (7, 3))
    assert solve_benchmark(graph, fast=True).relaxation.iterations == 3
    assert solve_benchmark(graph, fast=False).relaxation.iterations == 7


def test_a_damaged_copy_and_bad_arguments_are_refused(monkeypatch, graph):
    with pytest.raises(TypeError, match="graph: expected a PoseGraph"):
        solve_benchmark(str(FOLDER / "intel.g2o"))
    with pytest.raises(ValueError, match="max_sweeps"):
        solve_benchmark(graph, max_sweeps=-1)
    with pytest.raises(TypeError, match="max_sweeps"):
        solve_benchmark(graph, max_sweeps=2.5)
    with pytest.raises(ValueError, match="method"):
        solve_benchmark(graph, method="levenberg")
    monkeypatch.setattr(benchmark, "SHA256", "0" * 64)
    with pytest.raises(ValueError, match="SHA-256 4d87aaf9.*reinstall robocourse"):
        benchmark_graph()
