"""Clusters of a particle cloud: when has a Monte-Carlo localizer settled on one place?

ROS amcl groups its particles by the occupied cells of the same (x, y, theta) histogram that
KLD-sampling counts (0.5 m, 0.5 m, 10 degrees): two occupied cells that touch, faces, edges or
corners, belong to one cluster (``pf_cluster_stats``). Ge et al. (2023, Sec. 4.1) count the
iterations until "the particles had converged to a single cluster"; :func:`pose_clusters` gives the
clusters, :func:`largest_cluster_share` how much of the cloud the biggest one holds, and
:func:`largest_cluster_mean` its mean pose, the estimate amcl publishes.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
.. [2] D. Fox, "Adapting the sample size in particle filters through KLD-sampling", *International
   Journal of Robotics Research* 22(12), 985-1003, 2003.
"""
from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..geometry.planar import as_planar
from ..validation import as_array
from .particle_filter import ROS_KLD_BIN_SIZE, pose_bins, weighted_pose_mean

__all__ = ["pose_clusters", "largest_cluster_share", "largest_cluster_mean"]

_OFFSETS = np.array([d for d in itertools.product((-1, 0, 1), repeat=3) if any(d)], np.int64)


def pose_clusters(particles: Any, bin_size: Any = ROS_KLD_BIN_SIZE) -> np.ndarray:
    """Label each particle with its cluster: connected occupied cells of the pose histogram.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
        Poses ``[x, y, theta]``.
    bin_size : array_like, shape (3,), default (0.5 m, 0.5 m, 10 degrees)
        The histogram's cells (ROS amcl's KLD bins).

    Returns
    -------
    numpy.ndarray of int, shape (N,)
        Cluster labels ``0 .. C-1``, numbered in the order the particles first meet them.

    Raises
    ------
    ValueError
        For particles that are not an (N, 3) array of finite numbers, or a bad bin size.

    Notes
    -----
    ROS amcl's ``pf_cluster_stats`` (via ``pf_kdtree_cluster``): cells whose indices differ by at most
    one in every axis are neighbours (26 of them). Unlike amcl we also join cells across the
    heading's wrap at +-pi, so one cluster pointing west is never split in two. Fox (2003), Sec. 3,
    for the histogram. Connected components by :func:`scipy.ndimage.label` over the cloud's bounding
    box of cells when it is small, else by :func:`scipy.sparse.csgraph.connected_components` over the
    occupied cells only (the readable reference; both give the same labels).

    Examples
    --------
    >>> cloud = [[0.1, 0.1, 0.0], [0.6, 0.1, 0.0], [5.0, 0.0, 0.0], [0.1, 0.1, 3.14], [0.1, 0.1, -3.14]]
    >>> pose_clusters(cloud).tolist()        # two touching cells; a far one; a pair across +-pi
    [0, 0, 1, 2, 2]
    """
    P = as_planar(particles, "particles", shape=(None, 3), min_count=1)
    size = as_array(bin_size, "bin_size", shape=(3,))
    cells = pose_bins(P, size)               # checks bin_size, refuses a bin beyond int64
    if np.abs(P[:, :2] / size[:2]).max() >= 2.0 ** 40:
        raise ValueError(f"particles: expected positions within 2**40 histogram cells of the origin, got "
                         f"{np.abs(P[:, :2]).max():.3g} m with cells of {size[:2].tolist()} m")
    n_heading = int(np.ceil(2 * np.pi / size[2]))
    cells[:, 2] = np.mod(cells[:, 2], n_heading)
    lo = cells.min(axis=0) - 1
    span = cells.max(axis=0) - lo + 2
    if int(span[0]) * int(span[1]) * (int(span[2]) + n_heading) >= 2 ** 62:     # the cell keys below are int64
        raise ValueError(f"particles: expected a cloud spanning fewer histogram cells, got {span[:2].tolist()} "
                         f"cells of {size[:2].tolist()} m")

    box = float(span[0] - 2) * float(span[1] - 2) * n_heading          # the cloud's bounding box, in cells
    labels = _components_dense(cells, n_heading) if box <= min(_DENSE_CELLS, _DENSE_PER_PARTICLE * len(P)) else \
        _components_sparse(cells, n_heading, lo, span)
    _, first, component = np.unique(labels, return_index=True, return_inverse=True)
    renumber = np.empty(len(first), np.int64)                # number clusters as the particles meet them
    renumber[np.argsort(first)] = np.arange(len(first))
    return renumber[component.ravel()]


#: Up to this many histogram cells in the cloud's bounding box, and this many per particle,
#: :func:`pose_clusters` labels a dense array (one byte and one int32 a cell); beyond either, only the
#: occupied cells (a converged cloud with one far stray has a large, nearly empty box).
_DENSE_CELLS, _DENSE_PER_PARTICLE = 2_000_000, 64


def _components_sparse(cells: np.ndarray, n_heading: int, lo: np.ndarray, span: np.ndarray) -> np.ndarray:
    """Each particle's connected component, found among the occupied cells only (the readable reference)."""
    def key(c: np.ndarray) -> np.ndarray:       # one integer per cell (..., 3), the heading wrapped
        return ((c[..., 0] - lo[0]) * span[1] + (c[..., 1] - lo[1])) * (span[2] + n_heading) \
            + np.mod(c[..., 2], n_heading)

    # the occupied cells in lexicographic order (keys grow with it), each particle's among them
    keys, first, member = np.unique(key(cells), return_index=True, return_inverse=True)
    occupied = cells[first]
    # every cell's 26 neighbours at once: (26, cells) keys, looked up among the (sorted) occupied keys
    k = key(occupied[None, :, :] + _OFFSETS[:, None, :])
    at = np.minimum(np.searchsorted(keys, k), len(keys) - 1)
    hit = keys[at] == k
    r, c = np.nonzero(hit)[1], at[hit]
    graph = coo_matrix((np.ones(len(r)), (r, c)), shape=(len(occupied), len(occupied)))
    _, cell_label = connected_components(graph, directed=False)
    return cell_label[member.ravel()]


def _components_dense(cells: np.ndarray, n_heading: int) -> np.ndarray:
    """Each particle's connected component, labelled on a dense array of the cloud's bounding box.

    The same partition as :func:`_components_sparse` (labels may differ): ``scipy.ndimage.label``
    with all 26 neighbours, then the components that touch across the heading's wrap (the last
    heading slice against the first, one cell either way in x and y) are joined.
    """
    ix, iy, ih = cells[:, 0] - cells[:, 0].min(), cells[:, 1] - cells[:, 1].min(), cells[:, 2]
    occupied = np.zeros((ix.max() + 1, iy.max() + 1, n_heading), bool)
    occupied[ix, iy, ih] = True
    grid, count = ndimage.label(occupied, structure=np.ones((3, 3, 3), bool))
    if n_heading <= 2 or not (occupied[:, :, 0].any() and occupied[:, :, -1].any()):
        return grid[ix, iy, ih]              # nothing to join across the wrap (n <= 2: neighbours already)
    nx, ny = occupied.shape[:2]
    last, first = np.pad(grid[:, :, -1], 1), grid[:, :, 0]
    pairs = []
    for dx, dy in itertools.product((0, 1, 2), repeat=2):
        across = last[dx:dx + nx, dy:dy + ny]
        both = (across > 0) & (first > 0)
        pairs.append(np.column_stack([across[both], first[both]]))
    pairs = np.concatenate(pairs)
    if not len(pairs):
        return grid[ix, iy, ih]
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(count + 1, count + 1))
    _, joined = connected_components(graph, directed=False)
    return joined[grid[ix, iy, ih]]


def _cluster_labels(particles: Any, bin_size: Any, labels: Any) -> np.ndarray:
    if labels is None:
        return pose_clusters(particles, bin_size)
    P = as_planar(particles, "particles", shape=(None, 3), min_count=1)
    as_array(bin_size, "bin_size", shape=(3,))
    try:
        lab = np.asarray(labels)
    except (ValueError, TypeError):
        lab = np.empty(0, object)               # ragged: refused below
    if lab.shape != (len(P),) or lab.dtype.kind not in "iu" or np.any(lab < 0) or np.any(lab >= len(P)):
        raise ValueError(f"labels: expected one cluster label per particle ({len(P)}), integers from 0 to "
                         f"{len(P) - 1} as pose_clusters numbers them, got a {lab.dtype} array of shape {lab.shape}"
                         + (f" from {lab.min()} to {lab.max()}" if lab.size and lab.dtype.kind in "iu" else ""))
    return lab


def _cloud_weights(weights: Any, n: int) -> np.ndarray:
    if weights is None:
        return np.ones(n)
    w = as_array(weights, "weights", ndim=1)
    if len(w) != n:
        raise ValueError(f"weights: expected one weight per row of particles ({n}), got {len(w)}")
    if np.any(w < 0) or not w.sum() > 0:
        raise ValueError(f"weights: expected non-negative weights with a positive sum, got sum {w.sum()}")
    return w


def largest_cluster_share(particles: Any, weights: Any = None, bin_size: Any = ROS_KLD_BIN_SIZE, *,
                          labels: Any = None) -> float:
    """The share of the cloud (by weight, or by count) in its largest cluster.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
    weights : array_like, shape (N,), optional
        Non-negative; default equal weights (the share of particles).
    bin_size : array_like, shape (3,), default (0.5 m, 0.5 m, 10 degrees)
    labels : array_like of int, shape (N,), optional
        The particles' clusters, when :func:`pose_clusters` has already labelled them (with the same
        ``bin_size``); default: label them here.

    Returns
    -------
    float
        In (0, 1]; 1 when the whole cloud is one cluster.

    Raises
    ------
    ValueError
        For bad particles, negative, non-finite or all-zero weights, or a length mismatch.

    Notes
    -----
    Ge et al. (2023), Sec. 4.1: a run has converged when the particles form a single cluster
    (see :func:`pose_clusters`).

    Examples
    --------
    >>> largest_cluster_share([[0.1, 0.1, 0.0], [0.6, 0.1, 0.0], [5.0, 0.0, 0.0]])
    0.6666666666666666
    >>> largest_cluster_share([[0.1, 0.1, 0.0], [0.6, 0.1, 0.0], [5.0, 0.0, 0.0]], [0.1, 0.1, 0.8])
    0.8
    """
    labels = _cluster_labels(particles, bin_size, labels)
    w = _cloud_weights(weights, len(labels))
    totals = np.bincount(labels, weights=w)
    return float(totals.max() / totals.sum())


def largest_cluster_mean(particles: Any, weights: Any = None, bin_size: Any = ROS_KLD_BIN_SIZE, *,
                         labels: Any = None) -> np.ndarray:
    """The weighted mean pose of the heaviest cluster: the estimate ROS amcl publishes.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
    weights : array_like, shape (N,), optional
        Non-negative; default equal weights.
    bin_size : array_like, shape (3,), default (0.5 m, 0.5 m, 10 degrees)
    labels : array_like of int, shape (N,), optional
        As in :func:`largest_cluster_share`.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``[x, y, theta]``, theta the circular mean.

    Raises
    ------
    ValueError
        For bad particles or weights (see :func:`largest_cluster_share`).

    Notes
    -----
    ROS amcl's ``pf_cluster_stats`` and its pose hypothesis: the cluster with the largest total weight
    and its mean. The mean of *all* particles is pulled away by a few strays in another cluster.

    Examples
    --------
    >>> cloud = [[10.0, 0.0, 0.0], [10.2, 0.0, 0.0], [10.1, 0.0, 0.0], [30.0, 0.0, 0.0]]
    >>> largest_cluster_mean(cloud).round(3).tolist()       # the stray at x = 30 m does not count
    [10.1, 0.0, 0.0]
    """
    labels = _cluster_labels(particles, bin_size, labels)
    P = np.asarray(particles, float)
    w = _cloud_weights(weights, len(labels))
    heaviest = int(np.argmax(np.bincount(labels, weights=w)))
    keep = labels == heaviest
    return weighted_pose_mean(P[keep], w[keep] if w[keep].sum() > 0 else None)
