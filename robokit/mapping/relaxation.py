"""Loop-closure alignment by relaxation (the paper's Eqs. (1)-(3), after Duckett et al. 2000).

Every node has a pose ``[x, y, theta]`` and a scalar variance ``omega_i``; every edge a relative
pose and a scalar variance ``omega_ij`` (:func:`robokit.mapping.pose_graph.edge_variances`). One sweep
re-estimates each node but the fixed one from its neighbours (Sec. 'Loop closure alignment'):

1. each neighbour ``j`` predicts node ``i``'s pose and variance (Eq. (1));
2. the variance of ``i`` is the harmonic mean of the predicted variances (Eq. (2));
3. the pose of ``i`` is the inverse-variance weighted mean of the predictions, the heading as the
   direction of the weighted mean of unit vectors (Eq. (3)).

Sweeps repeat until the total change of the coordinates falls under a threshold or a maximum
number of sweeps is reached.

Eq. (1) as printed has typos. It reads ``(x'_i)_j = x_j + r_ij cos(theta_ji + theta_j)``,
``(z'_i)_j = z_j + r_ij sin(theta_ji + theta_j)``, ``(theta'_i)_j = theta_j + omega_ij``: the
third line adds a *variance* ``omega_ij`` where a relative heading belongs, and ``r_ij``,
``theta_ji`` are not defined. Duckett, Marsland & Shapiro (2000) define them: ``r_ij`` and
``theta_ji`` are the polar coordinates (distance and bearing) of node ``i`` in the frame of node
``j``, and the heading line adds the measured relative heading ``phi_ji`` of ``i`` with respect to
``j``. We implement that version; it is exactly ``se2_compose(pose_j, z_ji)`` with ``z_ji`` the
pose of ``i`` in ``j``'s frame (an edge stored as ``(i, j)`` is used inverted, :func:`se2_inverse`).

**Jacobi, not Gauss-Seidel.** Duckett et al. update the nodes one after another, each using its
neighbours' newest values (Gauss-Seidel). :func:`relax` computes every node of a sweep from the
previous sweep's values (Jacobi): the sweep is a few vectorised numpy operations over all edges,
and its result does not depend on the order of the nodes, so a student's loop in any order
reproduces it exactly. The price is more sweeps (about twice as many on a chain-like graph).
:func:`relax_sweep` is the readable one-sweep version that :func:`relax` is tested against.

**Limitations** (what least squares, :func:`robokit.mapping.optimize_pose_graph`, does better):
one scalar variance per edge replaces the 3 x 3 information matrix (headings weighted as
positions, correlations ignored), the node variances of Eq. (2) enter the weights, so the fixed
point is close to, but not, the least-squares optimum, and corrections travel one edge per sweep,
so a long loop needs many sweeps.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] T. Duckett, S. Marsland and J. Shapiro, "Learning globally consistent maps by relaxation",
   Proc. IEEE Int. Conf. on Robotics and Automation (ICRA), 3841-3846, 2000.
"""
from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from ..geometry import se2_compose, se2_inverse, wrap_angle
from ..geometry.planar import as_planar
from ..validation import as_array, as_int, as_positive, require_finite_result
from .pose_graph import PoseGraph, as_pose_graph, require_connected, edge_variances

__all__ = ["RelaxationResult", "relax", "relax_sweep", "initial_variances"]


@dataclasses.dataclass
class RelaxationResult:
    """The outcome of :func:`relax`.

    Attributes
    ----------
    poses : numpy.ndarray, shape (N, 3)
        Relaxed poses (headings in [-pi, pi)); the fixed node keeps its pose.
    variances : numpy.ndarray, shape (N,)
        Node variances ``omega_i`` (Eq. (2)); the fixed node's is 0.
    iterations : int
        Sweeps done.
    changes : numpy.ndarray, shape (iterations,)
        Total change of each sweep: ``sum_i |(dx_i, dy_i)| + |dtheta_i|`` (metres plus radians).
    converged : bool
        Whether the last change fell under the tolerance.
    time : float
        Wall-clock seconds.
    """

    poses: np.ndarray
    variances: np.ndarray
    iterations: int
    changes: np.ndarray
    converged: bool
    time: float


def _arrays(poses, variances, edges, measurements, omega_edges, fixed):
    p = as_planar(poses, "poses", shape=(None, 3))
    n = len(p)
    if n == 0:
        raise ValueError("poses: expected at least one pose, got shape (0, 3)")
    var = as_array(variances, "variances", shape=(n,))
    if np.any(var < 0):
        raise ValueError(f"variances: expected non-negative node variances, got {float(var[var < 0][0])}")
    e = as_array(edges, "edges", dtype=np.int64)
    e = e.reshape(0, 2) if e.size == 0 and e.ndim <= 2 else e
    if e.ndim != 2 or e.shape[1] != 2:
        raise ValueError(f"edges: expected shape (M, 2), got shape {e.shape}")
    if ((e < 0) | (e >= n)).any() or (e[:, 0] == e[:, 1]).any():
        raise ValueError(f"edges: expected pairs of two different node indices in 0..{n - 1}")
    z = as_planar(measurements, "measurements", shape=(len(e), 3)) if len(e) else np.zeros((0, 3))
    w = as_array(omega_edges, "edge_variances", shape=(len(e),)) if len(e) else np.zeros(0)
    if np.any(w <= 0):
        raise ValueError(f"edge_variances: expected positive variances, got {float(w[w <= 0][0])}")
    fixed = as_int(fixed, "fixed", minimum=0, maximum=n - 1)
    return p, var, e, z, w, fixed


def relax_sweep(poses: Any, variances: Any, edges: Any, measurements: Any, edge_variances: Any,
                fixed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """One relaxation sweep, Eqs. (1)-(3), written node by node (the readable version).

    Parameters
    ----------
    poses : array_like, shape (N, 3)
        Current estimates ``[x, y, theta]``.
    variances : array_like, shape (N,)
        Current node variances ``omega_i`` (>= 0).
    edges : array_like of int, shape (M, 2)
        Node index pairs ``(a, b)``.
    measurements : array_like, shape (M, 3)
        Pose of ``b`` in ``a``'s frame for each edge.
    edge_variances : array_like, shape (M,)
        Scalar variance ``omega_ab`` of each edge (> 0).
    fixed : int, default 0
        The node that keeps its pose and variance.

    Returns
    -------
    poses : numpy.ndarray, shape (N, 3)
    variances : numpy.ndarray, shape (N,)
        Every node computed from the *input* values (Jacobi); a node without edges is unchanged.

    Raises
    ------
    ValueError
        For shapes that do not agree, values that are not finite, negative variances or bad indices.

    Notes
    -----
    The paper's Sec. 'Loop closure alignment', Eqs. (1)-(3), with Eq. (1) as Duckett et al. (2000)
    define it (see the module docstring for the printed typo); the paper's ``z`` is our ``y``.
    Each edge counts as one neighbour, so ``n_i`` counts two edges between the same nodes twice.

    Examples
    --------
    Node 1 is predicted at x = 1 by node 0 (variance 0.1) and at x = 1.2 by node 2 (variance 0.3):

    >>> poses = [[0, 0, 0], [5, 5, 0], [2.2, 0, 0]]
    >>> new_poses, new_var = relax_sweep(poses, [0.0, 0.0, 0.2], [[0, 1], [1, 2]],
    ...                                  [[1, 0, 0], [1, 0, 0]], [0.1, 0.1])
    >>> print(np.round(new_poses[1], 4) + 0.0, round(float(new_var[1]), 4))
    [1.05 0.   0.  ] 0.15
    """
    poses, variances, edges, measurements, omega_edge, fixed = _arrays(poses, variances, edges, measurements,
                                                                        edge_variances, fixed)
    neighbours = [[] for _ in range(len(poses))]      # (j, pose of i in j's frame, omega_ij) per node i
    for (a, b), z, w in zip(edges, measurements, omega_edge):
        neighbours[b].append((a, z, w))
        neighbours[a].append((b, se2_inverse(z), w))
    new_poses, new_variances = poses.copy(), variances.copy()
    for i, estimates in enumerate(neighbours):
        if i == fixed or not estimates:
            continue
        xs, ys, thetas, omegas = [], [], [], []
        for j, (dx, dy, dtheta), w_ij in estimates:
            x_j, y_j, theta_j = poses[j]
            r_ij, bearing = math.hypot(dx, dy), math.atan2(dy, dx)     # polar coordinates of i in j's frame
            xs.append(x_j + r_ij * math.cos(bearing + theta_j))        # Eq. (1)
            ys.append(y_j + r_ij * math.sin(bearing + theta_j))        # Eq. (1)
            thetas.append(theta_j + dtheta)                            # Eq. (1), the relative heading (typo fixed)
            omegas.append(variances[j] + w_ij)                         # Eq. (1)
        n_i = len(estimates)
        omega_i = n_i / sum(1.0 / w for w in omegas)                   # Eq. (2)
        new_variances[i] = omega_i
        new_poses[i, 0] = sum(x * omega_i / w for x, w in zip(xs, omegas)) / n_i              # Eq. (3)
        new_poses[i, 1] = sum(y * omega_i / w for y, w in zip(ys, omegas)) / n_i              # Eq. (3)
        new_poses[i, 2] = math.atan2(sum(math.sin(t) / w for t, w in zip(thetas, omegas)),    # Eq. (3)
                                     sum(math.cos(t) / w for t, w in zip(thetas, omegas)))
    return new_poses, new_variances


def initial_variances(graph: PoseGraph) -> np.ndarray:
    """Node variances to start relaxation from: the smallest sum of edge variances to the fixed node.

    Parameters
    ----------
    graph : PoseGraph

    Returns
    -------
    numpy.ndarray, shape (N,)
        0 at the fixed node, ``inf`` at a node it cannot reach.

    Notes
    -----
    The paper initialises a new node's variance "with the variance of the previous node" and fixes
    the first node's "at a small value" (Sec. 'Loop closure alignment', unnumbered). Along an
    odometry chain, adding each edge's variance (Eq. (1)'s ``omega_j + omega_ij``) gives the
    variance of dead reckoning; on a general graph we take the cheapest chain (Dijkstra's shortest
    path with the edge variances as lengths). The fixed node's "small value" is 0, its limit: it
    only enters ``omega_j + omega_ij``, which stays positive.

    Examples
    --------
    >>> from robokit.mapping import pose_graph_from_odometry
    >>> g = pose_graph_from_odometry([[0, 0, 0], [1, 0, 0], [2, 0, 0]], sigma_odometry=0.1)
    >>> print(np.round(initial_variances(g), 4))
    [0.   0.01 0.02]
    """
    as_pose_graph(graph)
    n = graph.n_poses
    a, b = np.sort(graph.edges, axis=1).T
    pairs, inverse = np.unique(a * n + b, return_inverse=True)        # parallel edges: keep the smallest
    length = np.full(len(pairs), np.inf)
    np.minimum.at(length, inverse, edge_variances(graph))
    lengths = sp.csr_matrix((length, (pairs // n, pairs % n)), shape=(n, n))
    return dijkstra(lengths, directed=False, indices=graph.fixed)


def relax(graph: PoseGraph, *, max_iterations: int = 1000, tolerance: float = 1e-6,
          variances: Any = None) -> RelaxationResult:
    """Align a pose graph by relaxation: sweeps of Eqs. (1)-(3) until the total change is small.

    Parameters
    ----------
    graph : PoseGraph
        Connected; ``graph.poses`` is the starting estimate and the edges' scalar variances are
        :func:`robokit.mapping.pose_graph.edge_variances` of its information matrices.
    max_iterations : int, default 1000
        Most sweeps (0 returns the start).
    tolerance : float, default 1e-6
        Stop when a sweep's total change ``sum_i |(dx_i, dy_i)| + |dtheta_i|`` (metres plus
        radians, summed over nodes) falls under it.
    variances : array_like, shape (N,), optional
        Starting node variances ``omega_i`` (>= 0); default :func:`initial_variances`.

    Returns
    -------
    RelaxationResult

    Raises
    ------
    DisconnectedGraphError
        If some node is not linked to the fixed node.
    ValueError
        For bad options or variances.

    Notes
    -----
    The paper's relaxation (Sec. 'Loop closure alignment', Eqs. (1)-(3); Duckett et al. 2000) in
    Jacobi form, vectorised over the edges (module docstring: why, and the typo of Eq. (1)). The
    fixed node (the paper's first node, "the reference frame") keeps its pose.

    Examples
    --------
    A square whose odometry over-turns each corner by 0.1 rad, closed by recognising the start
    (as in :func:`robokit.mapping.optimize_pose_graph`, whose least-squares cost is 9.11):

    >>> from robokit.geometry import se2_compose
    >>> from robokit.mapping import pose_graph_cost, pose_graph_from_odometry
    >>> odo = [np.zeros(3)]
    >>> for _ in range(3):
    ...     odo.append(se2_compose(odo[-1], [1.0, 0.0, np.pi / 2 + 0.1]))
    >>> g = pose_graph_from_odometry(odo, loop_edges=[[3, 0]], loop_measurements=[[1, 0, np.pi / 2]])
    >>> res = relax(g)
    >>> res.converged, res.iterations, round(pose_graph_cost(g, res.poses), 2)
    (True, 18, 13.07)
    >>> print(np.round(res.poses[:, :2], 2) + 0.0)
    [[ 0.    0.  ]
     [ 0.98 -0.01]
     [ 0.95  0.95]
     [-0.01  0.98]]
    """
    as_pose_graph(graph)
    max_iterations = as_int(max_iterations, "max_iterations", minimum=0)
    tolerance = as_positive(tolerance, "tolerance")
    require_connected(graph)
    n = graph.n_poses
    if variances is None:
        var = initial_variances(graph)
    else:
        var = as_array(variances, "variances", shape=(n,)).copy()
        if np.any(var < 0):
            raise ValueError(f"variances: expected non-negative node variances, got {float(var[var < 0][0])}")
    start = time.perf_counter()
    # Each edge gives two directed predictions: b from a (the measurement) and a from b (its inverse).
    a, b = graph.edges[:, 0], graph.edges[:, 1]
    target, source = np.concatenate([b, a]), np.concatenate([a, b])
    relative = np.concatenate([graph.measurements, se2_inverse(graph.measurements)]) if graph.n_edges \
        else np.zeros((0, 3))
    omega_edge = np.tile(edge_variances(graph), 2)
    count = np.bincount(target, minlength=n)
    free = np.arange(n) != graph.fixed
    poses = graph.poses.copy()
    poses[:, 2] = wrap_angle(poses[:, 2])
    changes = []
    converged = False
    for _ in range(max_iterations):
        guess = se2_compose(poses[source], relative, validate=False)          # Eq. (1), all edges at once
        weight = 1.0 / (var[source] + omega_edge)                          # 1 / (omega'_i)_j, Eq. (1)
        total = np.bincount(target, weight, minlength=n)
        new = poses.copy()
        # Eq. (3), (1 / n_i) sum_j x'_j omega_i / omega'_j, is sum_j (x'_j / omega'_j) / sum_j (1 / omega'_j)
        # once Eq. (2)'s omega_i = n_i / sum_j (1 / omega'_j) is put in
        new[free, 0] = np.bincount(target, weight * guess[:, 0], minlength=n)[free] / total[free]   # Eq. (3)
        new[free, 1] = np.bincount(target, weight * guess[:, 1], minlength=n)[free] / total[free]   # Eq. (3)
        new[free, 2] = np.arctan2(np.bincount(target, weight * np.sin(guess[:, 2]), minlength=n),   # Eq. (3)
                                  np.bincount(target, weight * np.cos(guess[:, 2]), minlength=n))[free]
        var[free] = count[free] / total[free]                              # Eq. (2)
        step = new - poses
        change = float(np.sum(np.hypot(step[:, 0], step[:, 1])) + np.sum(np.abs(wrap_angle(step[:, 2]))))
        poses = new
        changes.append(change)
        if change < tolerance:
            converged = True
            break
    require_finite_result("graph, variances", poses, var, changes)
    poses[:, 2] = wrap_angle(poses[:, 2])                                  # arctan2 gives (-pi, pi]
    return RelaxationResult(poses, var, len(changes), np.array(changes), converged, time.perf_counter() - start)
