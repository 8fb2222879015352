"""Planar pose graphs: the validated graph, its connectivity, and a builder from odometry.

A pose graph (Lu & Milios 1997) has one node per robot pose ``[x, y, theta]`` and one edge per
measured relative pose: the pose of node ``j`` in the frame of node ``i``, ``[dx, dy, dtheta]``,
with a 3 x 3 information matrix (inverse covariance). The paper's topological map is such a graph:
its nodes are the base references ``B_i`` of the local maps and its edges the relations
``rt_ij = rt(B_i, B_j) = (x_ij, z_ij, theta_ij)`` (Sec. 'Environment map', unnumbered). The paper
writes planar poses ``(x, z, theta)``; robokit writes them ``[x, y, theta]`` (x, y in metres, theta
in radians counter-clockwise from +x).

The least-squares error, cost and Jacobian and their solvers are in
:mod:`robokit.mapping.pose_graph_optimize`, the paper's relaxation in
:mod:`robokit.mapping.relaxation`, files in the g2o format in :mod:`robokit.mapping.g2o`, and
generated graphs with ground truth in :mod:`robokit.mapping.manhattan`.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] F. Lu and E. Milios, "Globally consistent range scan alignment for environment mapping",
   *Autonomous Robots* 4(4), 333-349, 1997.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..geometry import se2_between
from ..geometry.planar import as_planar
from ..validation import as_array, as_int

__all__ = ["PoseGraph", "DisconnectedGraphError", "as_pose_graph", "positive_definite", "edge_variances", "unreachable_nodes",
           "is_connected", "require_connected", "pose_graph_from_odometry", "information_from_covariance",
           "position_variance"]


class DisconnectedGraphError(ValueError):
    """A pose graph whose nodes cannot all be reached from the fixed node.

    Such a graph has no unique solution: a part that is not connected to the fixed node can be
    moved freely. ``unreachable`` holds the node indices, ``ids`` their vertex ids.
    """

    def __init__(self, message: str, unreachable: np.ndarray, ids: np.ndarray) -> None:
        super().__init__(message)
        self.unreachable = unreachable
        self.ids = ids


def _rows(value: Any, name: str, width: int, dtype: Any = float) -> np.ndarray:
    """``value`` as an (M, width) array; an empty list is zero rows."""
    arr = as_array(value, name, dtype=dtype)
    if arr.size == 0 and arr.ndim <= 2:
        return arr.reshape(0, width)
    if arr.ndim != 2 or arr.shape[1] != width:
        raise ValueError(f"{name}: expected shape (M, {width}), got shape {arr.shape}")
    return arr


@dataclasses.dataclass(eq=False)
class PoseGraph:
    """A planar pose graph, validated when made.

    Parameters
    ----------
    poses : array_like, shape (N, 3)
        Initial estimates ``[x, y, theta]`` of the N nodes (N >= 1), e.g. from odometry.
    edges : array_like of int, shape (M, 2)
        Node indices ``(i, j)`` (rows of ``poses``, not vertex ids) of each measurement; ``i != j``.
        Several edges between the same two nodes are allowed.
    measurements : array_like, shape (M, 3)
        The pose of node ``j`` in the frame of node ``i``, ``[dx, dy, dtheta]``.
    information : array_like, shape (M, 3, 3), optional
        Symmetric positive-definite information matrix (inverse covariance) of each measurement,
        ordered ``[dx, dy, dtheta]``; default identity. Symmetric to 1e-9 relative, then made
        exactly symmetric.
    ids : array_like of int, shape (N,), optional
        The nodes' vertex ids (unique; a g2o file's ids need be neither 0..N-1 nor sorted); default
        ``0..N-1``.
    fixed : int, default 0
        Index of the node held fixed (the gauge): the paper's "first node ... considered as the
        reference frame" (Sec. 'Loop closure alignment'). It keeps its pose in ``poses``.

    Raises
    ------
    ValueError
        For wrong shapes, values that are not finite, indices out of range, an edge from a node
        to itself, repeated ids, or an information matrix that is not symmetric positive definite
        (the message names the edge).
    TypeError
        For values that are not numbers (or not integers where indices are expected).

    Notes
    -----
    A graph is the data of Lu & Milios (1997) and of the g2o format; the paper's topological map is
    one (Sec. 'Environment map', unnumbered). Use :func:`dataclasses.replace` to change a field: the
    copy is validated again.

    Examples
    --------
    Three nodes on a line, one metre apart, measured by two odometry edges and one loop edge:

    >>> g = PoseGraph(poses=[[0, 0, 0], [1, 0, 0], [2, 0, 0]], edges=[[0, 1], [1, 2], [0, 2]],
    ...               measurements=[[1, 0, 0], [1, 0, 0], [2, 0, 0]])
    >>> g.n_poses, g.n_edges, g.information.shape
    (3, 3, (3, 3, 3))
    """

    poses: Any
    edges: Any
    measurements: Any
    information: Any = None
    ids: Any = None
    fixed: Any = 0

    def __post_init__(self) -> None:
        poses = as_planar(self.poses, "poses", shape=(None, 3))
        if len(poses) == 0:
            raise ValueError("poses: expected at least one pose, got shape (0, 3)")
        n = len(poses)
        edges = _rows(self.edges, "edges", 2, dtype=np.int64)
        m = len(edges)
        bad = (edges < 0) | (edges >= n)
        if bad.any():
            k = int(np.flatnonzero(bad.any(axis=1))[0])
            raise ValueError(f"edges: expected node indices in 0..{n - 1} (rows of poses), got {edges[k].tolist()} "
                             f"in row {k}")
        loops = np.flatnonzero(edges[:, 0] == edges[:, 1])
        if loops.size:
            raise ValueError(f"edges: expected two different nodes per edge, got {edges[loops[0]].tolist()} in row "
                             f"{loops[0]}")
        meas = _rows(self.measurements, "measurements", 3)
        if len(meas) != m:
            raise ValueError(f"measurements: expected one row per edge (edges has {m} rows), got {len(meas)} rows")
        if self.information is None:
            info = np.tile(np.eye(3), (m, 1, 1))
        else:
            info = as_array(self.information, "information")
            if info.size == 0 and m == 0:
                info = info.reshape(0, 3, 3)
            if info.ndim != 3 or info.shape[1:] != (3, 3) or len(info) != m:
                raise ValueError(f"information: expected shape ({m}, 3, 3) (one 3x3 matrix per row of edges), "
                                 f"got shape {info.shape}")
            info = _symmetric_positive_definite(info)
        ids = np.arange(n) if self.ids is None else as_array(self.ids, "ids", shape=(n,), dtype=np.int64)
        if len(np.unique(ids)) != n:
            values, counts = np.unique(ids, return_counts=True)
            raise ValueError(f"ids: expected unique vertex ids, got {int(values[counts > 1][0])} more than once")
        self.poses, self.edges, self.measurements, self.information, self.ids = poses, edges, meas, info, ids
        self.fixed = as_int(self.fixed, "fixed", minimum=0, maximum=n - 1)

    @property
    def n_poses(self) -> int:
        """Number of nodes N."""
        return len(self.poses)

    @property
    def n_edges(self) -> int:
        """Number of edges M."""
        return len(self.edges)


def positive_definite(information: np.ndarray) -> np.ndarray:
    """Which of a stack of symmetric 3 x 3 matrices are positive definite (all eigenvalues > 0).

    Parameters
    ----------
    information : numpy.ndarray, shape (M, 3, 3)
        Symmetric, finite (unchecked: the callers validated it).

    Returns
    -------
    numpy.ndarray of bool, shape (M,)

    Notes
    -----
    The condition for a Gaussian measurement's information matrix (e.g. Kummerle et al. 2011).

    Examples
    --------
    >>> positive_definite(np.stack([np.eye(3), np.diag([1.0, 1.0, 0.0])])).tolist()
    [True, False]
    """
    if len(information) == 0:
        return np.zeros(0, bool)
    return np.linalg.eigvalsh(information)[:, 0] > 0


def information_from_covariance(measurements: Any, covariances: Any) -> np.ndarray:
    """Information matrices for g2o's edge error, from covariances of the measurements in ``i``'s frame.

    A relative pose ``z = [dx, dy, dtheta]`` of node ``j`` in node ``i``'s frame usually comes with
    its covariance in that same frame (odometry propagated from ``i``, a visual estimate made at
    ``i``). g2o's error ``e = z^-1 (+) (p_i^-1 (+) p_j)`` (:func:`robokit.mapping.pose_graph_optimize.pose_graph_residuals`)
    is expressed in the frame of ``z``'s end instead: to first order ``e = J (z_hat - z)`` with
    ``J = blockdiag(R(dtheta)^T, 1)``, so its covariance is ``J C J^T`` and the information
    ``(J C J^T)^-1``. Using ``C^-1`` directly swaps the along- and cross-track weights of every edge
    that turns.

    Parameters
    ----------
    measurements : array_like, shape (M, 3)
    covariances : array_like, shape (M, 3, 3)
        Symmetric positive definite, in each measurement's start frame.

    Returns
    -------
    numpy.ndarray, shape (M, 3, 3)

    Raises
    ------
    ValueError
        For shapes that disagree, NaN/inf, or covariances that are not symmetric positive definite.

    Notes
    -----
    Kummerle et al. (2011), the SE(2) edge of g2o; first-order propagation (Smith, Self & Cheeseman
    1990).

    Examples
    --------
    A quarter turn: 0.1 m^2 along i's x becomes 0.1 m^2 along the error's -y:

    >>> info = information_from_covariance([[1.0, 1.0, np.pi / 2]], [np.diag([0.1, 0.01, 0.01])])
    >>> np.round(np.linalg.inv(info[0]).diagonal(), 6).tolist()
    [0.01, 0.1, 0.01]
    """
    z = as_planar(measurements, "measurements", shape=(None, 3))
    cov = as_array(covariances, "covariances", shape=(len(z), 3, 3))
    if len(z) and not np.all(positive_definite(0.5 * (cov + np.swapaxes(cov, 1, 2)))):
        raise ValueError("covariances: expected symmetric positive-definite 3 x 3 matrices")
    c, s = np.cos(z[:, 2]), np.sin(z[:, 2])
    J = np.zeros((len(z), 3, 3))
    J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1], J[:, 2, 2] = c, s, -s, c, 1.0      # R(dtheta)^T, 1
    rotated = J @ cov @ np.swapaxes(J, 1, 2)
    info = np.linalg.inv(0.5 * (rotated + np.swapaxes(rotated, 1, 2))) if len(z) else np.zeros((0, 3, 3))
    return 0.5 * (info + np.swapaxes(info, 1, 2))


def _symmetric_positive_definite(info: np.ndarray) -> np.ndarray:
    scale = np.maximum(np.abs(info).max(axis=(1, 2)), 1.0) if len(info) else np.zeros(0)
    asym = np.abs(info - np.swapaxes(info, 1, 2)).max(axis=(1, 2)) if len(info) else np.zeros(0)
    bad = np.flatnonzero(asym > 1e-9 * scale)
    if bad.size:
        raise ValueError(f"information: expected symmetric matrices, row {bad[0]} differs from its transpose by "
                         f"{asym[bad[0]]:.3g}")
    info = 0.5 * (info + np.swapaxes(info, 1, 2))
    bad = np.flatnonzero(~positive_definite(info))
    if bad.size:
        raise ValueError(f"information: expected positive-definite matrices, row {bad[0]} has smallest eigenvalue "
                         f"{np.linalg.eigvalsh(info[bad[0]])[0]:.3g} (a variance that is zero, negative or infinite)")
    return info


def as_pose_graph(graph: Any) -> PoseGraph:
    """Return ``graph`` if it is a :class:`PoseGraph` (the argument check of every solver).

    Raises
    ------
    TypeError
        Naming the argument ``graph`` and what came instead.

    Examples
    --------
    >>> as_pose_graph("map.g2o")
    Traceback (most recent call last):
    ...
    TypeError: graph: expected a PoseGraph (read a g2o file with read_g2o), got str
    """
    if not isinstance(graph, PoseGraph):
        raise TypeError(f"graph: expected a PoseGraph (read a g2o file with read_g2o), got {type(graph).__name__}")
    return graph


def edge_variances(graph: PoseGraph) -> np.ndarray:
    """The scalar variance ``omega_ij`` of every edge, as relaxation uses it.

    Parameters
    ----------
    graph : PoseGraph

    Returns
    -------
    numpy.ndarray, shape (M,)
        ``omega_ij = (C_xx + C_yy) / 2`` with ``C = Omega_ij^-1`` the edge's covariance: the mean
        variance of the measured position [m^2].

    Notes
    -----
    The paper gives each edge one variance ``omega_ij`` (Sec. 'Loop closure alignment', Eq. (1));
    a g2o edge carries a full 3 x 3 information matrix. We keep the mean of the position variances
    and drop the rest: the heading variance and every correlation. Relaxation therefore weights
    the heading estimates as it weights the positions and cannot use an anisotropic covariance;
    least squares (:func:`robokit.mapping.optimize_pose_graph`) uses all of it.

    Examples
    --------
    >>> g = PoseGraph([[0, 0, 0], [1, 0, 0]], [[0, 1]], [[1, 0, 0]], information=[np.diag([100.0, 25.0, 400.0])])
    >>> print(np.round(edge_variances(g), 6))           # (0.01 + 0.04) / 2
    [0.025]
    """
    g = as_pose_graph(graph)
    return position_variance(np.linalg.inv(g.information) if g.n_edges else np.zeros((0, 3, 3)))


def position_variance(covariances: np.ndarray) -> np.ndarray:
    """The paper's scalar variance of a pose covariance: the mean of its x and y variances.

    Parameters
    ----------
    covariances : numpy.ndarray, shape (..., 3, 3)
        Covariances of ``[x, y, theta]`` (unchecked: the callers made them).

    Returns
    -------
    numpy.ndarray, shape (...)
        ``(C_xx + C_yy) / 2`` [m^2]; it does not change when the frame turns.

    Notes
    -----
    One variance per edge and per node, as Sec. 'Loop closure alignment' keeps them (Eqs. (1)-(2));
    :func:`edge_variances` applies it to a pose graph's edges.

    Examples
    --------
    >>> print(position_variance(np.diag([0.01, 0.04, 0.0025])))
    0.025
    """
    return 0.5 * (covariances[..., 0, 0] + covariances[..., 1, 1])


def unreachable_nodes(graph: PoseGraph) -> np.ndarray:
    """Indices of the nodes that no chain of edges links to the fixed node.

    Parameters
    ----------
    graph : PoseGraph

    Returns
    -------
    numpy.ndarray of int
        Ascending node indices (empty for a connected graph).

    Notes
    -----
    Connected components of the undirected graph (scipy's ``connected_components``); the paper's
    relaxation fixes its first node (Sec. 'Loop closure alignment'), and a part not connected to
    it has no defined position.

    Examples
    --------
    >>> g = PoseGraph(np.zeros((4, 3)), [[0, 1], [2, 3]], np.zeros((2, 3)))
    >>> unreachable_nodes(g).tolist()
    [2, 3]
    """
    g = as_pose_graph(graph)
    n = g.n_poses
    adjacency = sp.coo_matrix((np.ones(g.n_edges), (g.edges[:, 0], g.edges[:, 1])), shape=(n, n))
    _, labels = connected_components(adjacency, directed=False)
    return np.flatnonzero(labels != labels[g.fixed])


def is_connected(graph: PoseGraph) -> bool:
    """Whether every node is linked to the fixed node by a chain of edges.

    Examples
    --------
    >>> is_connected(PoseGraph(np.zeros((2, 3)), [[0, 1]], [[1.0, 0.0, 0.0]]))
    True
    """
    return unreachable_nodes(graph).size == 0


def require_connected(graph: PoseGraph) -> None:
    """Raise :class:`DisconnectedGraphError` naming the nodes the fixed node cannot reach.

    Raises
    ------
    DisconnectedGraphError
        A ``ValueError`` whose message gives the count and the first vertex ids.

    Examples
    --------
    >>> require_connected(PoseGraph(np.zeros((3, 3)), [[0, 1]], [[1.0, 0.0, 0.0]], ids=[10, 11, 12]))
    Traceback (most recent call last):
    ...
    robokit.mapping.pose_graph.DisconnectedGraphError: graph: expected a connected pose graph, but 1 node (vertex
    ids 12) cannot be reached from the fixed node (vertex id 10)
    """
    g = as_pose_graph(graph)
    bad = unreachable_nodes(g)
    if bad.size:
        shown = ", ".join(str(i) for i in g.ids[bad[:10]]) + (", ..." if bad.size > 10 else "")
        raise DisconnectedGraphError(
            f"graph: expected a connected pose graph, but {bad.size} node{'s' if bad.size > 1 else ''} (vertex ids "
            f"{shown}) cannot be reached from the fixed node (vertex id {g.ids[g.fixed]})", bad, g.ids[bad])


def _sigmas(value: Any, name: str, count: int) -> np.ndarray:
    """Standard deviations: a scalar, one [x, y, theta] row, or one row per edge; as information."""
    s = as_array(value, name)
    if s.shape not in ((), (3,), (count, 3)):
        raise ValueError(f"{name}: expected a scalar, shape (3,) or shape ({count}, 3) (one row per edge), "
                         f"got shape {s.shape}")
    if np.any(s <= 0):
        raise ValueError(f"{name}: expected positive standard deviations, got {float(s[s <= 0].flat[0])}")
    with np.errstate(over="ignore", under="ignore"):
        info = 1.0 / np.broadcast_to(s, (count, 3)) ** 2
    if not np.all(np.isfinite(info) & (info > 0)):
        raise ValueError(f"{name}: expected standard deviations whose inverse square is a positive finite "
                         "number (1e-150 < sigma < 1e150)")
    return info


def pose_graph_from_odometry(odometry_poses: Any, loop_edges: Any = None, loop_measurements: Any = None, *,
                             sigma_odometry: Any = (0.1, 0.1, 0.05), sigma_loop: Any = (0.1, 0.1, 0.05)) -> PoseGraph:
    """Build a pose graph from a sequence of odometry poses plus extra (loop-closure) edges.

    Parameters
    ----------
    odometry_poses : array_like, shape (N, 3)
        The robot's poses as odometry reports them, in order; they are the initial estimates, and
        consecutive pairs give the odometry edges ``(k, k + 1)`` with measurement
        ``se2_between(odometry_poses[k], odometry_poses[k + 1])``.
    loop_edges : array_like of int, shape (K, 2), optional
        Node index pairs ``(i, j)`` of extra edges, e.g. a place recognised again.
    loop_measurements : array_like, shape (K, 3), optional
        Pose of ``j`` in ``i``'s frame for each loop edge; default zeros ("the same place").
    sigma_odometry : float or array_like, shape (3,) or (N - 1, 3), default (0.1, 0.1, 0.05)
        Standard deviations ``[x, y, theta]`` [m, m, rad] the estimator assumes for each odometry
        edge; the information is ``diag(1 / sigma^2)``.
    sigma_loop : float or array_like, shape (3,) or (K, 3), default (0.1, 0.1, 0.05)
        The same for the loop edges.

    Returns
    -------
    PoseGraph
        Odometry edges first (rows ``0..N-2``), then the loop edges; node 0 fixed.

    Raises
    ------
    ValueError
        For wrong shapes, values that are not finite, non-positive sigmas or indices out of range.

    Notes
    -----
    The paper's map building (Sec. 'Loop closure alignment', unnumbered): a node's pose is "initialized to the robot odometry position when
    the node is created" and a node "added or recognized" creates an edge holding the relative
    position from odometry. A constant sigma per edge
    is the simplest model; pass one row per edge to make it grow with the distance driven.

    Examples
    --------
    A square driven with a heading drift, closed by recognising the start:

    >>> odo = [[0, 0, 0], [1, 0, 1.6], [1.05, 1, 3.2], [0.1, 1.1, 4.8]]
    >>> g = pose_graph_from_odometry(odo, loop_edges=[[3, 0]], loop_measurements=[[1, 0, np.pi / 2]])
    >>> g.n_poses, g.n_edges, g.edges.tolist()
    (4, 4, [[0, 1], [1, 2], [2, 3], [3, 0]])
    """
    odo = as_planar(odometry_poses, "odometry_poses", shape=(None, 3))
    if len(odo) == 0:
        raise ValueError("odometry_poses: expected at least one pose, got shape (0, 3)")
    n = len(odo)
    chain = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    loops = np.zeros((0, 2), np.int64) if loop_edges is None else _rows(loop_edges, "loop_edges", 2, np.int64)
    k = len(loops)
    if loop_measurements is None:
        loop_z = np.zeros((k, 3))
    else:
        loop_z = _rows(loop_measurements, "loop_measurements", 3)
        if len(loop_z) != k:
            raise ValueError(f"loop_measurements: expected one row per row of loop_edges ({k}), got {len(loop_z)}")
    if k and ((loops < 0) | (loops >= n)).any():
        raise ValueError(f"loop_edges: expected node indices in 0..{n - 1} (rows of odometry_poses), got "
                         f"{loops[((loops < 0) | (loops >= n)).any(axis=1)][0].tolist()}")
    diagonal = np.concatenate([_sigmas(sigma_odometry, "sigma_odometry", n - 1), _sigmas(sigma_loop, "sigma_loop", k)])
    info = np.zeros((len(diagonal), 3, 3))
    info[:, [0, 1, 2], [0, 1, 2]] = diagonal
    z = se2_between(odo[:-1], odo[1:]) if n > 1 else np.zeros((0, 3))
    return PoseGraph(odo, np.concatenate([chain, loops]), np.concatenate([z, loop_z]), info)
