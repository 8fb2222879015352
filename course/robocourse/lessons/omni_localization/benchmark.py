"""Lesson 02's two map aligners on a real pose graph: g2o's Intel Research Lab benchmark.

The lesson aligns its own simulated map by the paper's relaxation (Eqs. (1)-(3), after Duckett et
al. 2000) and by least squares. This module runs both on a public benchmark recorded by a real
robot, the Intel Research Lab graph that ships with g2o (Kummerle et al. 2011): 943 poses, 1837
edges, shipped in ``robocourse/data/posegraphs`` with its source, licence (BSD) and SHA-256 in the
README beside it.

- :func:`benchmark_graph` reads the shipped file and checks it is the upstream one (SHA-256 and
  counts).
- :func:`solve_benchmark` runs relaxation (at most :data:`RELAX_SWEEPS` sweeps) and Gauss-Newton
  least squares from the same start, the file's own vertex estimates, and reports for each the cost
  ``chi2 = sum e^T Omega e`` (:func:`robokit.mapping.pose_graph_cost`), the iterations and the wall
  time. Nothing is cached: the times are the point.

**Reference value.** We found no optimum published for this file. The "intel" optima in the
certifiable-SLAM literature (Rosen et al. 2019, Table 1: 52.35) are for another graph of the same
lab (1,728 poses, 2,512 measurements) and another cost (isotropic weights, chordal rotation
distance), so they do not apply. As an independent check we give :data:`GTSAM_CHI2`, the optimum
GTSAM's Levenberg-Marquardt (Dellaert 2012) reaches on this file, computed once by us and evaluated
with our cost; it is a measurement of ours, not a published number.

**What relaxation reaches.** From the file's estimates relaxation lowers the cost fast, passes
through a minimum of the cost after a few hundred sweeps and then settles, after about 10,600
sweeps (3-4 s on the course machine), at its own fixed point, about 9 % above the least-squares
optimum. Its fixed point is not the least-squares one: relaxation keeps one scalar variance per
edge (on 1821 of the 1837 edges the information is 500 m^-2 per coordinate and 5000 rad^-2 for
the heading; relaxation gives the heading the positions' variance, 1/500) and its node variances
(Eq. (2)) enter the weights. The heading's weight is not what keeps it there: with the heading's
information set to the positions' on every edge, the gap we measured grows, to 17 %
(:mod:`robokit.mapping.relaxation` lists the differences). :attr:`BenchmarkRuns.relaxation_curve`
records the cost along the way.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] T. Duckett, S. Marsland and J. Shapiro, "Learning globally consistent maps by relaxation",
   Proc. IEEE Int. Conf. on Robotics and Automation (ICRA), 3841-3846, 2000.
.. [3] R. Kummerle, G. Grisetti, H. Strasdat, K. Konolige and W. Burgard, "g2o: A general framework
   for graph optimization", Proc. IEEE Int. Conf. on Robotics and Automation (ICRA), 3607-3613, 2011.
.. [4] D. M. Rosen, L. Carlone, A. S. Bandeira and J. J. Leonard, "SE-Sync: A certifiably correct
   algorithm for synchronization over the special Euclidean group", *International Journal of
   Robotics Research* 38(2-3), 95-125, 2019.
.. [5] F. Dellaert, "Factor graphs and GTSAM: A hands-on introduction", Technical Report
   GT-RIM-CP&R-2012-002, Georgia Institute of Technology, 2012.
"""
from __future__ import annotations

import dataclasses
import hashlib
from importlib import resources

import numpy as np

from robokit.config import fast_mode
from robokit.mapping import PoseGraph, optimize_pose_graph, pose_graph_cost, read_g2o, relax
from robokit.mapping.pose_graph import as_pose_graph
from robokit.validation import as_choice, as_int

__all__ = ["SHA256", "N_POSES", "N_EDGES", "RELAX_SWEEPS", "GTSAM_CHI2", "benchmark_graph", "SolverRun",
           "BenchmarkRuns", "solve_benchmark"]

#: The shipped file (``robocourse/data/posegraphs/intel.g2o``) must be the upstream one: its SHA-256,
#: vertices and edges (README.md beside it).
SHA256 = "4d87aaf96e1e04e47c723c371386b15358c71e98c05dad16b786d585f9fd70ff"
N_POSES, N_EDGES = 943, 1837
#: Most relaxation sweeps: (full size, fast mode). Relaxation converges (total change under 1e-6)
#: after about 10,600 sweeps, 3-4 s on the course machine; fast mode stops after 1000 (0.3 s).
RELAX_SWEEPS = (20000, 1000)
#: Not a published value (none was found for this file): the optimum of GTSAM 4.3.0 (PyPI wheel),
#: computed once by us as an independent check and evaluated with
#: :func:`robokit.mapping.pose_graph_cost`: 546.46111166. Made with ``gtsam.readG2o`` (the file's
#: edges as ``BetweenFactorPose2``), the first pose held by a ``NonlinearEqualityPose2``, the file's
#: vertex estimates as the start and ``LevenbergMarquardtOptimizer`` with relative and absolute error
#: tolerances of 1e-12: 4 iterations. GTSAM's own error at that optimum is 2 x 273.23156 = 546.4631,
#: not the same number: it measures a residual by the SE(2) logarithm, not g2o's ``[x, y, theta]``.
GTSAM_CHI2 = 546.4611

_FILE = ("data", "posegraphs", "intel.g2o")


def benchmark_graph() -> PoseGraph:
    """The Intel Research Lab pose graph of g2o, read from the copy the course ships.

    Returns
    -------
    robokit.mapping.PoseGraph
        943 poses (the file's vertex estimates, ids 0..942) and 1837 edges; the first pose is fixed
        (the file has no ``FIX`` line, and g2o then holds its first vertex).

    Raises
    ------
    ValueError
        If the shipped file is not the upstream one (its SHA-256 or its counts differ): a damaged
        installation, reinstall robocourse.

    Notes
    -----
    The file of Kummerle et al. (2011), as released with g2o; source, licence and checksum in
    ``robocourse/data/posegraphs/README.md``. Read with :func:`robokit.mapping.read_g2o`.

    Examples
    --------
    >>> graph = benchmark_graph()
    >>> graph.n_poses, graph.n_edges, graph.fixed
    (943, 1837, 0)
    """
    data = (resources.files("robocourse").joinpath(*_FILE)).read_bytes()
    digest = hashlib.sha256(data).hexdigest()
    if digest != SHA256:
        raise ValueError(f"robocourse/{'/'.join(_FILE)}: SHA-256 {digest}, expected {SHA256} (the upstream file, "
                         "README.md beside it): a damaged installation, reinstall robocourse")
    graph = read_g2o(data.decode("utf-8"))
    if (graph.n_poses, graph.n_edges) != (N_POSES, N_EDGES):
        raise ValueError(f"robocourse/{'/'.join(_FILE)}: {graph.n_poses} poses and {graph.n_edges} edges, expected "
                         f"{N_POSES} and {N_EDGES}")
    return graph


@dataclasses.dataclass(frozen=True)
class SolverRun:
    """One solver's run on a pose graph (:func:`solve_benchmark`).

    Attributes
    ----------
    name : str
        ``"relaxation"`` or ``"least squares"``.
    cost : float
        ``chi2`` of the result (:func:`robokit.mapping.pose_graph_cost`).
    iterations : int
        Relaxation sweeps, or least-squares linearisations.
    time : float
        Wall-clock seconds of the solver (as it reports them: the iterations, not the checks of
        its arguments).
    converged : bool
        Whether its stopping test was met before its cap.
    poses : numpy.ndarray, shape (N, 3)
        The poses it reached.
    """

    name: str
    cost: float
    iterations: int
    time: float
    converged: bool
    poses: np.ndarray


@dataclasses.dataclass(frozen=True)
class BenchmarkRuns:
    """Both solvers from the same start (:func:`solve_benchmark`).

    Attributes
    ----------
    initial_cost : float
        ``chi2`` at the start (the graph's own poses).
    relaxation, least_squares : SolverRun
    relaxation_curve : tuple of numpy.ndarray
        ``(sweeps, costs)``: relaxation's cost after 1, 10, 100, ... sweeps and after its last one.
    """

    initial_cost: float
    relaxation: SolverRun
    least_squares: SolverRun
    relaxation_curve: tuple[np.ndarray, np.ndarray]

    @property
    def runs(self) -> tuple[SolverRun, SolverRun]:
        """``(relaxation, least_squares)``, in the order a table lists them."""
        return self.relaxation, self.least_squares


def _relax_in_stages(graph: PoseGraph, cap: int) -> tuple[SolverRun, tuple[np.ndarray, np.ndarray]]:
    """Relaxation up to ``cap`` sweeps, stopping at powers of ten to record the cost.

    A sweep depends only on the poses and node variances it starts from (Jacobi), so carrying both
    from one stage to the next gives exactly the sweeps of one long run.
    """
    stops = [int(s) for s in 10 ** np.arange(int(np.log10(max(cap, 1))) + 1) if s < cap] + [cap]
    current, variances = graph, None
    done, seconds, converged, sweeps, costs = 0, 0.0, False, [], []
    for stop in stops if cap else []:
        result = relax(current, max_iterations=stop - done, variances=variances)
        done, seconds, converged = done + result.iterations, seconds + result.time, result.converged
        current, variances = dataclasses.replace(current, poses=result.poses), result.variances
        sweeps.append(done)
        costs.append(pose_graph_cost(graph, current.poses))
        if converged:
            break
    run = SolverRun("relaxation", pose_graph_cost(graph, current.poses), done, seconds, bool(converged),
                    current.poses)
    return run, (np.array(sweeps, dtype=int), np.array(costs, dtype=float))


def solve_benchmark(graph: PoseGraph, *, max_sweeps: int | None = None, method: str = "gauss-newton",
                    fast: bool | None = None) -> BenchmarkRuns:
    """Align a pose graph by the paper's relaxation and by least squares, from the same start.

    Parameters
    ----------
    graph : robokit.mapping.PoseGraph
        Connected; its poses are the start of both solvers (:func:`benchmark_graph`: the file's own
        vertex estimates).
    max_sweeps : int, optional
        Most relaxation sweeps (>= 0); default :data:`RELAX_SWEEPS` for the mode. Relaxation stops
        earlier when a sweep's total change falls under :func:`robokit.mapping.relax`'s default
        tolerance.
    method : {"gauss-newton", "scipy"}, default "gauss-newton"
        The least-squares solver (:func:`robokit.mapping.optimize_pose_graph`); the lesson's is
        Gauss-Newton.
    fast : bool, optional
        Fast mode's sweep cap when ``max_sweeps`` is not given (default
        :func:`robokit.config.fast_mode`).

    Returns
    -------
    BenchmarkRuns

    Raises
    ------
    TypeError
        If ``graph`` is not a PoseGraph, or ``max_sweeps`` not an integer.
    ValueError
        For a negative ``max_sweeps`` or an unknown ``method``.
    robokit.mapping.DisconnectedGraphError
        If some pose is not linked to the fixed one.

    Notes
    -----
    Relaxation is Eqs. (1)-(3) of the paper after Duckett et al. (2000); least squares minimises
    g2o's ``chi2`` (Kummerle et al. 2011, Eq. (1)). Both are scored by that same ``chi2``, which
    only least squares minimises: relaxation stops at a different fixed point.

    Examples
    --------
    >>> runs = solve_benchmark(benchmark_graph(), max_sweeps=10)
    >>> runs.least_squares.converged, runs.least_squares.cost < runs.relaxation.cost < runs.initial_cost
    (True, True)
    >>> runs.relaxation.iterations, runs.relaxation_curve[0].tolist()
    (10, [1, 10])
    """
    graph = as_pose_graph(graph)
    fast = fast_mode() if fast is None else bool(fast)
    cap = RELAX_SWEEPS[1 if fast else 0] if max_sweeps is None else as_int(max_sweeps, "max_sweeps", minimum=0)
    method = as_choice(method, "method", ("gauss-newton", "scipy"))
    relaxation, curve = _relax_in_stages(graph, cap)
    solved = optimize_pose_graph(graph, method=method)
    least_squares = SolverRun("least squares", solved.cost, solved.iterations, solved.time, solved.converged,
                              solved.poses)
    return BenchmarkRuns(pose_graph_cost(graph), relaxation, least_squares, curve)
