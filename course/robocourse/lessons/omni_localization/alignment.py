"""When aligning the map beats odometry: which loops are kept, how far off each loop edge is, redrawn odometry.

Lesson 02 aligns its topological map after loop closure by relaxation (the paper's Sec. "Loop
closure alignment", Eqs. (1)-(3), after Duckett et al. 2000) and by least squares
(:func:`robokit.mapping.optimize_pose_graph`). Neither promises that every node moves closer to
the truth. A loop edge measures one relative pose: it corrects the odometry *between* its two
nodes and nothing else. The odometry before the loop's first node and after its last is still
dead reckoning, and its drift, which may have partly cancelled the drift the loop removes, is now
uncovered. This module measures that on a graph whose true poses are known:

* :func:`loop_subsets` names sets of loop edges to keep (all of them, the first, the last, a few
  spread along the tour, a few bunched in one place, each alone);
* :func:`held_share` is the share of the odometry chain that the kept loops hold at both ends;
* :func:`alignment_errors` aligns the chain plus the kept loops both ways and measures every
  node against the truth;
* :func:`loop_edge_errors` compares each loop edge with the truth's relative pose and with the
  uncertainty the builder assumed for it;
* :func:`odometry_redraws` draws the odometry noise again (from the edges' own information
  matrices) and counts how often least squares lands further from the truth than odometry.

Every function takes a pose graph made from a run: node ``k`` and node ``k + 1`` joined by an
odometry edge for every ``k`` (:meth:`robokit.mapping.TopologicalMap.graph`,
:func:`robokit.mapping.pose_graph_from_odometry`, :func:`robokit.mapping.manhattan_world_graph`).
Those rows are the odometry; every row joining two nodes that are not consecutive is a loop edge.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] T. Duckett, S. Marsland and J. Shapiro, "Learning globally consistent maps by relaxation",
   Proc. IEEE Int. Conf. on Robotics and Automation (ICRA), 3841-3846, 2000.
.. [3] R. Kummerle, G. Grisetti, H. Strasdat, K. Konolige and W. Burgard, "g2o: A general framework
   for graph optimization", Proc. IEEE ICRA, 3607-3613, 2011.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from robokit.geometry import se2_between, se2_compose
from robokit.geometry.planar import as_planar
from robokit.mapping import PoseGraph, optimize_pose_graph, relax
from robokit.mapping.pose_graph import as_pose_graph
from robokit.mapping.pose_graph_optimize import pose_graph_residuals
from robokit.validation import as_array, as_int, as_rng

__all__ = ["METHODS", "AlignmentErrors", "LoopEdgeErrors", "loop_rows", "loop_subsets", "held_share", "with_loops",
           "alignment_errors", "loop_edge_errors", "odometry_redraws"]

#: The three maps compared: dead reckoning, relaxation (Eqs. (1)-(3)) and least squares.
METHODS = ("odometry", "relaxation", "least squares")


def _chain(graph: Any) -> tuple[PoseGraph, np.ndarray, np.ndarray]:
    """The graph, whether each row joins consecutive nodes, and the row of each chain edge (k, k + 1)."""
    g = as_pose_graph(graph)
    lo, hi = np.sort(g.edges, axis=1).T if g.n_edges else (np.zeros(0, int), np.zeros(0, int))
    consecutive = hi - lo == 1
    first = np.full(g.n_poses - 1, -1)
    rows = np.flatnonzero(consecutive)[::-1]          # reversed: the first row of a pair is written last
    first[lo[rows]] = rows
    if np.any(first < 0):
        k = int(np.flatnonzero(first < 0)[0])
        raise ValueError(f"graph: expected a graph from a run, an odometry edge joining node k and k + 1 for every "
                         f"k, got none between nodes {k} and {k + 1}")
    backwards = np.flatnonzero(g.edges[first, 0] != np.arange(g.n_poses - 1))
    if len(backwards):                               # redrawing writes k -> k + 1 measurements into these rows
        k = int(backwards[0])
        raise ValueError(f"graph: expected each odometry edge stored from node k to k + 1, got edge "
                         f"{g.edges[first[k]].tolist()} between nodes {k} and {k + 1}")
    return g, consecutive, first


def loop_rows(graph: PoseGraph) -> np.ndarray:
    """The rows of ``graph.edges`` that are loop closures, in the order the tour closes them.

    Parameters
    ----------
    graph : PoseGraph
        From a run: an odometry edge between nodes ``k`` and ``k + 1`` for every ``k``.

    Returns
    -------
    numpy.ndarray of int
        Rows joining two nodes that are not consecutive, sorted by their later node, then by
        their earlier one.

    Raises
    ------
    TypeError
        If ``graph`` is not a PoseGraph.
    ValueError
        If a pair of consecutive nodes has no edge (not a graph from a run).

    Notes
    -----
    The paper's map has an edge for every node "added or recognized" (Sec. "Loop closure
    alignment", unnumbered): the added ones join consecutive nodes, the recognised ones are the
    loops.

    Examples
    --------
    >>> from robokit.mapping import pose_graph_from_odometry
    >>> g = pose_graph_from_odometry(np.zeros((6, 3)), loop_edges=[[5, 0], [1, 3]])
    >>> loop_rows(g).tolist()
    [6, 5]
    """
    g, consecutive, _ = _chain(graph)
    rows = np.flatnonzero(~consecutive)
    lo, hi = np.sort(g.edges[rows], axis=1).T if rows.size else (rows, rows)
    return rows[np.lexsort((lo, hi))]


def _keep(graph: Any, keep: Any) -> tuple[PoseGraph, np.ndarray, np.ndarray]:
    """The graph, its loop rows, and the validated rows of ``keep`` (default: every loop row)."""
    g, consecutive, first = _chain(graph)
    loops = loop_rows(g)
    if keep is None:
        return g, loops, loops
    rows = as_array(keep, "keep", dtype=np.int64)
    if rows.ndim != 1:
        raise ValueError(f"keep: expected a 1-D array of edge rows, got shape {rows.shape}")
    bad = rows[~np.isin(rows, loops)]
    if bad.size:
        raise ValueError(f"keep: expected rows of loop edges (rows of graph.edges joining nodes that are not "
                         f"consecutive: {loops.tolist()}), got row {int(bad[0])}")
    if len(np.unique(rows)) != len(rows):
        raise ValueError(f"keep: expected each row once, got {rows.tolist()}")
    return g, loops, rows


def loop_subsets(graph: PoseGraph, *, k: int = 3) -> dict[str, np.ndarray]:
    """Named sets of loop edges to keep: all, first, last, ``k`` spread, ``k`` bunched, each alone.

    Parameters
    ----------
    graph : PoseGraph
        From a run (see :func:`loop_rows`).
    k : int, default 3
        Loops in the spread and in the bunched set (at most the number of loops).

    Returns
    -------
    dict of str to numpy.ndarray of int
        Rows of ``graph.edges`` per set, in this order: ``"all loops"``, ``"first loop only"``
        (the loop closed earliest in the tour), ``"last loop only"`` (closed last),
        ``"{k} spread along the tour"`` (the first, the last and loops evenly between them in the
        order the tour closes them), ``"{k} bunched in one place"`` (``k`` loops closed one after
        another whose ends lie closest together: the smallest sum of the ranges of their earlier
        and of their later nodes), then ``"only a-b"`` for each loop between nodes ``a`` and
        ``b``. Empty for a graph without loops.

    Raises
    ------
    TypeError, ValueError
        For a graph that is not from a run, or ``k`` below 1.

    Notes
    -----
    Which recognitions to keep is the question of issue 35; the paper keeps every one (Sec. "Loop
    closure alignment").

    Examples
    --------
    >>> from robokit.mapping import pose_graph_from_odometry
    >>> g = pose_graph_from_odometry(np.zeros((12, 3)), loop_edges=[[0, 4], [5, 9], [6, 9], [0, 11]])
    >>> {name: rows.tolist() for name, rows in loop_subsets(g, k=2).items()}      # doctest: +NORMALIZE_WHITESPACE
    {'all loops': [11, 12, 13, 14], 'first loop only': [11], 'last loop only': [14],
     '2 spread along the tour': [11, 14], '2 bunched in one place': [12, 13],
     'only 0-4': [11], 'only 5-9': [12], 'only 6-9': [13], 'only 0-11': [14]}
    """
    g = as_pose_graph(graph)
    k = as_int(k, "k", minimum=1)
    loops = loop_rows(g)
    if loops.size == 0:
        return {}
    k = min(k, loops.size)
    lo, hi = np.sort(g.edges[loops], axis=1).T
    spread = loops[np.unique(np.linspace(0, loops.size - 1, k).round().astype(int))]
    windows = np.lib.stride_tricks.sliding_window_view
    extent = np.ptp(windows(lo, k), axis=1) + np.ptp(windows(hi, k), axis=1)
    start = int(np.argmin(extent))
    out = {"all loops": loops, "first loop only": loops[:1], "last loop only": loops[-1:],
           f"{k} spread along the tour": spread, f"{k} bunched in one place": loops[start:start + k]}
    out.update({f"only {a}-{b}": np.array([row]) for row, a, b in zip(loops, lo, hi)})
    return out


def held_share(graph: PoseGraph, keep: Any = None) -> float:
    """Share of the odometry chain that the kept loops hold at both ends.

    Parameters
    ----------
    graph : PoseGraph
        From a run (see :func:`loop_rows`).
    keep : array_like of int, optional
        Rows of loop edges kept (default: every loop).

    Returns
    -------
    float
        The fraction of the odometry edges ``(k, k + 1)`` that lie on a cycle: between the two
        nodes ``a < b`` of some kept loop, ``a <= k < b``. 0 without loops; 1 when the loops
        together span the whole tour.

    Raises
    ------
    TypeError, ValueError
        For a graph that is not from a run, or rows in ``keep`` that are not loop edges.

    Notes
    -----
    An odometry edge on no cycle (a bridge of the graph) is measured by nothing else: its error
    stays in every alignment, and everything beyond it moves with it. With the chain as a
    spanning tree, the cycle a loop closes is the stretch of chain between its nodes.

    Examples
    --------
    >>> from robokit.mapping import pose_graph_from_odometry
    >>> g = pose_graph_from_odometry(np.zeros((11, 3)), loop_edges=[[2, 5], [4, 8]])
    >>> held_share(g), held_share(g, keep=[10]), held_share(g, keep=[])
    (0.6, 0.3, 0.0)
    """
    g, _, rows = _keep(graph, keep)
    if g.n_poses < 2:
        return 0.0
    lo, hi = np.sort(g.edges[rows], axis=1).T if rows.size else (rows, rows)
    marks = np.zeros(g.n_poses, int)
    np.add.at(marks, lo, 1)
    np.add.at(marks, hi, -1)
    return float(np.mean(np.cumsum(marks)[:-1] > 0))


def with_loops(graph: PoseGraph, keep: Any = None) -> PoseGraph:
    """The graph with every odometry edge and only the kept loop edges (same poses, fixed node, ids).

    Parameters
    ----------
    graph : PoseGraph
        From a run (see :func:`loop_rows`).
    keep : array_like of int, optional
        Rows of loop edges to keep (default: all; an empty list keeps none).

    Returns
    -------
    PoseGraph
        Odometry rows first, in their order, then the kept loop rows in the order given.

    Raises
    ------
    TypeError, ValueError
        For a graph that is not from a run, or rows in ``keep`` that are not loop edges.

    Examples
    --------
    >>> from robokit.mapping import pose_graph_from_odometry
    >>> g = pose_graph_from_odometry(np.zeros((5, 3)), loop_edges=[[0, 4], [1, 3]])
    >>> with_loops(g, keep=[5]).edges.tolist()
    [[0, 1], [1, 2], [2, 3], [3, 4], [1, 3]]
    """
    g, consecutive, _ = _chain(graph)
    _, _, rows = _keep(g, keep)
    idx = np.concatenate([np.flatnonzero(consecutive), rows]).astype(np.int64)
    return PoseGraph(g.poses, g.edges[idx], g.measurements[idx], g.information[idx], ids=g.ids, fixed=g.fixed)


@dataclasses.dataclass
class AlignmentErrors:
    """The outcome of :func:`alignment_errors`.

    Attributes
    ----------
    rms, worst : dict of str to float
        Per method of :data:`METHODS`, the root-mean-square and the largest distance (m) of the
        node positions from the truth.
    poses : dict of str to numpy.ndarray, shape (N, 3)
        Per method, the node poses.
    held : float
        :func:`held_share` of the kept loops.
    n_loops : int
        Loop edges kept.
    sweeps : int
        Relaxation sweeps done.
    converged : bool
        Whether relaxation met its tolerance and least squares its stopping test.
    """

    rms: dict
    worst: dict
    poses: dict
    held: float
    n_loops: int
    sweeps: int
    converged: bool


def _truth(truth: Any, graph: PoseGraph) -> np.ndarray:
    return as_planar(truth, "truth", shape=(graph.n_poses, 3))


def alignment_errors(graph: PoseGraph, truth: Any, keep: Any = None, *, max_sweeps: int = 20000) -> AlignmentErrors:
    """Align the odometry chain plus the kept loop edges by relaxation and least squares; errors vs the truth.

    Parameters
    ----------
    graph : PoseGraph
        From a run (see :func:`loop_rows`); its poses are the odometry (the starting estimate).
    truth : array_like, shape (N, 3)
        The nodes' true poses, in the frame of the graph's poses.
    keep : array_like of int, optional
        Rows of loop edges kept (default: every loop; empty: none, all three maps are odometry).
    max_sweeps : int, default 20000
        Most relaxation sweeps. :func:`robokit.mapping.relax` stops at 1000 by default, enough for
        the lesson's well-looped map (about 600) but not for a weakly looped one: a correction
        travels one edge per sweep, and a long un-looped stretch needs several thousand.

    Returns
    -------
    AlignmentErrors

    Raises
    ------
    TypeError, ValueError
        For a graph not from a run, a truth of another shape, rows in ``keep`` that are not loop
        edges, or ``max_sweeps`` below 1.

    Notes
    -----
    Relaxation is the paper's Eqs. (1)-(3) (Sec. "Loop closure alignment", after Duckett et al.
    2000); least squares minimises g2o's ``sum e^T Omega e`` (Kummerle et al. 2011). Positions only
    are compared: the graph's frame is the odometry's, the truth's must be the same (node 0 of a
    lesson map is the tour's first pose in both).

    Examples
    --------
    A square driven twice whose odometry over-turns every corner, closed at each return to the
    start:

    >>> from robokit.mapping import pose_graph_from_odometry
    >>> truth = np.array([[0, 0, 0], [2, 0, np.pi / 2], [2, 2, np.pi], [0, 2, -np.pi / 2]] * 2 + [[0, 0, 0]])
    >>> steps = se2_between(truth[:-1], truth[1:]) + [0.0, 0.0, 0.05]
    >>> odo = [truth[0]]
    >>> for step in steps:
    ...     odo.append(se2_compose(odo[-1], step))
    >>> g = pose_graph_from_odometry(odo, loop_edges=[[0, 4], [4, 8]], loop_measurements=[[0, 0, 0]] * 2)
    >>> out = alignment_errors(g, truth)
    >>> {m: round(out.rms[m], 2) for m in METHODS}, out.held
    ({'odometry': 0.31, 'relaxation': 0.06, 'least squares': 0.06}, 1.0)
    """
    g, _, rows = _keep(graph, keep)
    true = _truth(truth, g)
    max_sweeps = as_int(max_sweeps, "max_sweeps", minimum=1)
    sub = with_loops(g, rows)
    relaxed = relax(sub, max_iterations=max_sweeps)
    least = optimize_pose_graph(sub)
    poses = {"odometry": sub.poses.copy(), "relaxation": relaxed.poses, "least squares": least.poses}
    dist = {m: np.hypot(*(p[:, :2] - true[:, :2]).T) for m, p in poses.items()}
    return AlignmentErrors({m: float(np.sqrt(np.mean(d ** 2))) for m, d in dist.items()},
                           {m: float(d.max()) for m, d in dist.items()}, poses, held_share(g, rows), len(rows),
                           relaxed.iterations, bool(relaxed.converged and least.converged))


@dataclasses.dataclass
class LoopEdgeErrors:
    """The outcome of :func:`loop_edge_errors`, one entry per loop edge.

    Attributes
    ----------
    rows : numpy.ndarray of int, shape (K,)
        Rows of ``graph.edges``.
    edges : numpy.ndarray of int, shape (K, 2)
        Their node pairs.
    translation : numpy.ndarray, shape (K,)
        Distance (m) between the measured relative position and the true one.
    heading : numpy.ndarray, shape (K,)
        Measured minus true relative heading (rad, in [-pi, pi)).
    sigma : numpy.ndarray, shape (K, 3)
        Standard deviations the graph assumes for the edge's error ``[x, y, theta]`` (m, m, rad):
        the square roots of its covariance's diagonal.
    chi2 : numpy.ndarray, shape (K,)
        ``e^T Omega e`` of the edge at the true poses: about 3 on average (3 degrees of freedom)
        when the assumed uncertainty is the real one, much more for an edge off by more than it.
    """

    rows: np.ndarray
    edges: np.ndarray
    translation: np.ndarray
    heading: np.ndarray
    sigma: np.ndarray
    chi2: np.ndarray


def loop_edge_errors(graph: PoseGraph, truth: Any, keep: Any = None) -> LoopEdgeErrors:
    """How far each loop edge's measurement is from the truth, next to the uncertainty it was given.

    Parameters
    ----------
    graph : PoseGraph
        From a run (see :func:`loop_rows`).
    truth : array_like, shape (N, 3)
        The nodes' true poses.
    keep : array_like of int, optional
        Rows of the loop edges to examine (default: every loop, in :func:`loop_rows` order).

    Returns
    -------
    LoopEdgeErrors

    Raises
    ------
    TypeError, ValueError
        For a graph not from a run, a truth of another shape, or rows that are not loop edges.

    Notes
    -----
    The error is g2o's ``e = z^-1 (+) (p_a^-1 (+) p_b)`` at the true poses (Kummerle et al. 2011),
    the measured pose ``z`` against the truth's relative pose, in ``z``'s end frame, where the
    information matrix ``Omega`` is expressed. The paper gives each edge one variance ``omega_ij``
    (Sec. "Loop closure alignment", Eq. (1)); ``sigma`` shows the full diagonal the graph holds.

    Examples
    --------
    A loop edge that says "back where I started" when the robot stopped 0.3 m short, with an
    assumed sigma of 0.1 m:

    >>> from robokit.mapping import pose_graph_from_odometry
    >>> truth = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0.3, 0]])
    >>> g = pose_graph_from_odometry(truth, loop_edges=[[0, 3]], loop_measurements=[[0, 0, 0]])
    >>> err = loop_edge_errors(g, truth)
    >>> err.edges.tolist(), err.translation.round(2).tolist(), err.sigma[0, :2].tolist(), err.chi2.round(1).tolist()
    ([[0, 3]], [0.3], [0.1, 0.1], [9.0])
    """
    g, _, rows = _keep(graph, keep)
    true = _truth(truth, g)
    e = pose_graph_residuals(g, true)[rows]
    info = g.information[rows]
    sigma = np.sqrt(np.diagonal(np.linalg.inv(info), axis1=1, axis2=2)) if rows.size else np.zeros((0, 3))
    return LoopEdgeErrors(rows, g.edges[rows], np.hypot(e[:, 0], e[:, 1]), e[:, 2], sigma,
                          np.einsum("ki,kij,kj->k", e, info, e))


def _redrawn(g: PoseGraph, first: np.ndarray, true: np.ndarray, rng: np.random.Generator) -> PoseGraph:
    """The graph with its odometry measurements drawn again around the truth and the poses dead-reckoned."""
    z_true = se2_between(true[:-1], true[1:])
    info = g.information[first]
    noise = np.einsum("kij,kj->ki", np.linalg.cholesky(np.linalg.inv(info)), rng.normal(size=z_true.shape))
    z = se2_compose(z_true, noise)                   # g2o's error at the truth is then -noise, to first order
    odo = np.empty_like(true)
    odo[0] = true[0]
    for k, step in enumerate(z):                     # dead reckoning, step after step
        odo[k + 1] = se2_compose(odo[k], step, validate=False)
    anchor = se2_compose(true[g.fixed], se2_between(odo[g.fixed], odo[0]))    # the fixed node on its true pose
    meas = g.measurements.copy()
    meas[first] = z
    return PoseGraph(se2_compose(anchor, se2_between(odo[0], odo)), g.edges, meas, g.information, ids=g.ids,
                     fixed=g.fixed)


def odometry_redraws(graph: PoseGraph, truth: Any, keep: Any = None, *, draws: int = 40, rng: Any = 0) -> np.ndarray:
    """Least squares' RMS error over odometry's, for odometry noise drawn again ``draws`` times.

    The tour, the nodes and the kept loop edges (with their measured values) stay; each draw
    replaces every odometry measurement by the true relative pose composed with noise from that
    edge's own information matrix, dead-reckons the nodes from it, aligns by least squares and
    compares both with the truth.

    Parameters
    ----------
    graph : PoseGraph
        From a run (see :func:`loop_rows`).
    truth : array_like, shape (N, 3)
        The nodes' true poses.
    keep : array_like of int, optional
        Rows of loop edges kept (default: every loop).
    draws : int, default 40
        Noise draws.
    rng : numpy.random.Generator or int, default 0
        Seeds the draws: the same seed draws the same odometry whatever ``keep`` is, so loop sets
        are compared on the same recordings.

    Returns
    -------
    numpy.ndarray, shape (draws,)
        ``rms(least squares) / rms(odometry)`` per draw: below 1 where the alignment helped.

    Raises
    ------
    TypeError, ValueError
        For a graph not from a run, a truth of another shape, rows that are not loop edges, or
        ``draws`` below 1.

    Notes
    -----
    Least squares only (Kummerle et al. 2011): relaxation (Eqs. (1)-(3)) needs thousands of
    sweeps per weakly looped graph (:func:`alignment_errors`) and lands near it. The noise is the
    one the graph assumes, so the draws are what the estimator's own model predicts; on the lesson's
    map the odometry's cost at the truth is near ``3M`` for ``M`` odometry edges, so that model is
    the simulated one.

    Examples
    --------
    A walk with 3 loops holding 44 % of it, then one with 30 loops holding 92 %:

    >>> from robokit.mapping import manhattan_world_graph
    >>> for n_poses, seed in ((60, 2), (200, 1)):
    ...     g, truth = manhattan_world_graph(n_poses, seed=seed)
    ...     ratios = odometry_redraws(g, truth, draws=8)
    ...     print(len(loop_rows(g)), round(held_share(g), 2), ratios.round(2))
    3 0.44 [1.   0.87 1.13 1.09 0.69 0.95 0.98 0.99]
    30 0.92 [0.14 0.27 0.28 0.66 0.39 0.6  0.36 0.24]
    """
    g, _, first = _chain(graph)
    _, _, rows = _keep(g, keep)
    true = _truth(truth, g)
    draws = as_int(draws, "draws", minimum=1, maximum=100_000)
    rng = as_rng(rng)
    out = np.empty(draws)
    for d in range(draws):
        redrawn = with_loops(_redrawn(g, first, true, rng), rows)
        least = optimize_pose_graph(redrawn).poses
        rms = [np.sqrt(np.mean(np.sum((p[:, :2] - true[:, :2]) ** 2, axis=1))) for p in (redrawn.poses, least)]
        out[d] = rms[1] / rms[0] if rms[0] > 0 else 1.0
    return out
