"""The topological map of lesson 02: key images as nodes, relative poses as edges.

Lesson 02's paper (Sec. "Environment map") builds a two-level map. At the global level a graph:
node ``i`` holds the global feature of its key image (a hue histogram) and a local map ``M_i`` of
SIFT features, a pose ``(x_i, z_i, theta_i)`` "initialized to the robot odometry position when the
node is created" and a variance ``omega_i``; an edge holds the relative transformation between the
base references of two local maps, ``rt_ij = (x_ij, z_ij, theta_ij)``, with a variance
``omega_ij`` (Sec. "Loop closure alignment"). robokit writes poses ``[x, y, theta]`` in its world
frame (x, y on the floor, theta counter-clockwise): the paper's ``(x, z, theta)`` with ``z`` renamed
``y``. An edge's measurement is the pose of node ``j`` in node ``i``'s frame, ``[dx, dy, dtheta]``,
with a full 3 x 3 covariance (the paper's scalar ``omega_ij`` is its mean position variance, see
:func:`robokit.mapping.pose_graph.edge_variances`).

:class:`TopologicalMap` holds plain arrays (it saves to and loads from one ``.npz``), one KD-tree
descriptor index per node built when the map is made (the paper: "the implementation of the map
structure is based on KD-tree"), and the two searches of the hierarchical localizer:
:meth:`~TopologicalMap.rank_by_histogram` (the coarse stage, Eq. (5) against every node at once)
and :meth:`~TopologicalMap.match_counts` (the fine stage, SIFT matches against a few candidates).
:meth:`~TopologicalMap.graph` hands the nodes and edges to relaxation or least squares
(:mod:`robokit.mapping.pose_graph`), :meth:`~TopologicalMap.with_poses` takes the answer back.
Building a map from a recorded run is :func:`robokit.mapping.build_topological_map`.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
"""
from __future__ import annotations

import copy
import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from ..files import NpzFileError, as_file_path, read_npz, save_npz, write_atomically
from ..geometry.planar import as_planar
from ..validation import as_array, as_choice, as_int, as_positive
from ..vision.colour import histogram_distance
from ..vision.features import Features, Keypoints
from ..vision.matching import METHODS, DescriptorIndex
from ..vision.matching import Matches
from .omni_views import OmniView
from .pose_graph import PoseGraph, information_from_covariance

__all__ = ["EmptyMapError", "ODOMETRY_EDGE", "LOOP_EDGE", "OMNI_RATIO", "TopologicalMap", "MAX_MAP_BYTES",
           "MAX_MAP_VALUES"]

#: SIFT distance-ratio bound between omni views, for the map builder, the localizer's fine stage and
#: lesson 02's assignment alike: 0.7 rather than Lowe's 0.8, since unrelated omni views of the office
#: share about 9 matches at 0.7 and 27 at 0.8 (views 1-2 m apart: 46 and 62).
OMNI_RATIO = 0.7

#: Edge kinds: consecutive key images (odometry) and a place recognised again (loop closure).
ODOMETRY_EDGE, LOOP_EDGE = 0, 1
#: The largest map file :meth:`TopologicalMap.load` reads (bytes), and values per array.
MAX_MAP_BYTES, MAX_MAP_VALUES = 256 * 1024**2, 1 << 26
_FORMAT = 1


class EmptyMapError(ValueError):
    """Raised when a map without nodes is searched or built."""


def _rows(value: Any, name: str, shape: tuple, dtype: Any = float) -> np.ndarray:
    arr = as_array(value, name, dtype=dtype)
    if arr.size == 0 and shape[0] is None:
        arr = arr.reshape((0, *shape[1:]))
    return as_array(arr, name, shape=shape, dtype=dtype)


def _edges(n: int, edges: Any, measurements: Any, covariances: Any, kinds: Any) -> tuple:
    """Validated edge arrays of a map with ``n`` nodes."""
    edges = _rows(edges, "edges", (None, 2), dtype=np.int64)
    e = len(edges)
    if e and (edges.min() < 0 or edges.max() >= n or np.any(edges[:, 0] == edges[:, 1])):
        bad = int(np.flatnonzero((edges < 0).any(1) | (edges >= n).any(1) | (edges[:, 0] == edges[:, 1]))[0])
        raise ValueError(f"edges: expected pairs of two different nodes in 0..{n - 1}, got {edges[bad].tolist()} "
                         f"in row {bad}")
    measurements = _rows(measurements, "measurements", (e, 3))
    covariances = _rows(covariances, "covariances", (e, 3, 3))
    if e and (np.abs(covariances - np.swapaxes(covariances, 1, 2)).max() > 1e-12
              or np.linalg.eigvalsh(covariances)[:, 0].min() <= 0):
        raise ValueError("covariances: expected symmetric positive-definite 3 x 3 matrices")
    kinds = as_array(kinds, "kinds", shape=(e,), dtype=np.int64) if e else np.zeros(0, np.int64)
    if np.any((kinds != ODOMETRY_EDGE) & (kinds != LOOP_EDGE)):
        raise ValueError(f"kinds: expected {ODOMETRY_EDGE} (odometry) or {LOOP_EDGE} (loop closure) per edge")
    return edges, measurements, covariances, kinds


@dataclasses.dataclass(frozen=True, eq=False)
class TopologicalMap:
    """Nodes (key images) with poses and features, and edges with relative poses.

    Parameters
    ----------
    poses : array_like, shape (N, 3)
        Node poses ``[x, y, theta]`` (the robot's odometry pose at the key image, or relaxed).
    variances : array_like, shape (N,)
        Node variances ``omega_i`` (m^2, >= 0).
    histograms : array_like, shape (N, B)
        Hue histogram of each key image.
    frames : array_like of int, shape (N,)
        Index of each key image in the recorded run.
    keypoints : array_like, shape (M, 4)
        Every node's keypoints, node after node: ``x, y`` (pixels), scale, orientation.
    bearings : array_like, shape (M, 3)
        Their unit viewing rays (camera frame).
    descriptors : array_like, shape (M, D)
    offsets : array_like of int, shape (N + 1,)
        Node ``i`` owns feature rows ``offsets[i]:offsets[i + 1]``.
    edges : array_like of int, shape (E, 2)
    measurements : array_like, shape (E, 3)
        Pose of node ``j`` in node ``i``'s frame, ``[dx, dy, dtheta]``.
    covariances : array_like, shape (E, 3, 3)
        Symmetric positive-definite covariance of each measurement.
    kinds : array_like of int, shape (E,)
        :data:`ODOMETRY_EDGE` or :data:`LOOP_EDGE`.
    index : {"opencv", "kdtree", "bruteforce", "flann"}, default "opencv"
        The search behind each node's :class:`~robokit.vision.DescriptorIndex`. The three exact
        ones give the same matches; the paper's KD-tree degenerates towards an exhaustive search
        for 128-element descriptors, and OpenCV's brute force matched 5 candidates in 13 ms where
        the KD-tree took 40 ms (benchmarks/bench_hierarchical_localization.py).

    Raises
    ------
    EmptyMapError
        For a map without nodes.
    ValueError, TypeError
        For shapes that do not agree, NaN/inf (a NaN pose), negative variances, offsets that do
        not partition the features, edges out of range or covariances that are not positive
        definite.

    Notes
    -----
    Sec. "Environment map" and "Loop closure alignment" (see the module docstring).

    Examples
    --------
    Two nodes one metre apart, one feature each, joined by an odometry edge:

    >>> m = TopologicalMap(poses=[[0, 0, 0], [1, 0, 0]], variances=[0.0, 0.01], histograms=np.eye(2),
    ...                    frames=[0, 5], keypoints=np.ones((2, 4)), bearings=[[1, 0, 0], [0, 1, 0]],
    ...                    descriptors=np.eye(2, 128), offsets=[0, 1, 2], edges=[[0, 1]],
    ...                    measurements=[[1, 0, 0]], covariances=[np.eye(3) * 0.01], kinds=[ODOMETRY_EDGE])
    >>> len(m), m.n_edges, m.node_features(1).descriptors.shape
    (2, 1, (1, 128))
    >>> m.graph().n_poses, m.rank_by_histogram([0.0, 1.0])[0].tolist()
    (2, [1, 0])
    """

    poses: Any
    variances: Any
    histograms: Any
    frames: Any
    keypoints: Any
    bearings: Any
    descriptors: Any
    offsets: Any
    edges: Any
    measurements: Any
    covariances: Any
    kinds: Any
    index: str = "opencv"

    def __post_init__(self) -> None:
        poses = as_array(self.poses, "poses")
        if poses.size == 0:
            raise EmptyMapError(f"poses: expected a map with at least one node, got shape {poses.shape}")
        poses = as_planar(poses, "poses", shape=(None, 3))
        n = len(poses)
        variances = as_array(self.variances, "variances", shape=(n,))
        if np.any(variances < 0):
            raise ValueError(f"variances: expected non-negative node variances, got {variances.min()}")
        histograms = as_array(self.histograms, "histograms", shape=(n, None))
        frames = as_array(self.frames, "frames", shape=(n,), dtype=np.int64)
        offsets = as_array(self.offsets, "offsets", shape=(n + 1,), dtype=np.int64)
        keypoints = _rows(self.keypoints, "keypoints", (None, 4))
        m = len(keypoints)
        if offsets[0] != 0 or offsets[-1] != m or np.any(np.diff(offsets) < 0):
            raise ValueError(f"offsets: expected a non-decreasing partition 0..{m} of the features, got "
                             f"{offsets[0]}..{offsets[-1]}")
        bearings = _rows(self.bearings, "bearings", (m, 3))
        descriptors = as_array(self.descriptors, "descriptors", dtype=np.float32)
        descriptors = as_array(descriptors.reshape(0, 128) if descriptors.size == 0 else descriptors,
                               "descriptors", shape=(m, None), dtype=np.float32)
        edges, measurements, covariances, kinds = _edges(n, self.edges, self.measurements, self.covariances,
                                                         self.kinds)
        for name, value in (("poses", poses), ("variances", variances), ("histograms", histograms),
                            ("frames", frames), ("keypoints", keypoints), ("bearings", bearings),
                            ("descriptors", descriptors), ("offsets", offsets), ("edges", edges),
                            ("measurements", measurements), ("covariances", covariances), ("kinds", kinds)):
            object.__setattr__(self, name, value)
        # one KD-tree per node, built once (Sec. "Environment map": "based on KD-tree")
        index = as_choice(str(self.index) if isinstance(self.index, np.ndarray) else self.index, "index", METHODS)
        object.__setattr__(self, "index", index)
        object.__setattr__(self, "_indices", [DescriptorIndex(descriptors[a:b], index) if b - a >= 2 else None
                                              for a, b in zip(offsets[:-1], offsets[1:])])

    def __len__(self) -> int:
        return len(self.poses)

    def __repr__(self) -> str:
        loops = int(np.sum(self.kinds == LOOP_EDGE))
        return (f"TopologicalMap({len(self)} nodes, {self.n_edges} edges ({loops} loop closures), "
                f"{len(self.keypoints)} features)")

    @property
    def n_edges(self) -> int:
        """Number of edges."""
        return len(self.edges)

    def _node(self, i: Any) -> int:
        return as_int(i, "node", minimum=0, maximum=len(self) - 1)

    def node_features(self, i: int) -> Features:
        """The SIFT features of node ``i``'s key image (keypoint response is not kept: zeros)."""
        a, b = self.offsets[self._node(i)], self.offsets[self._node(i) + 1]
        kp = self.keypoints[a:b]
        return Features(Keypoints(kp[:, :2], kp[:, 2], np.zeros(b - a), kp[:, 3]), self.descriptors[a:b])

    def node_view(self, i: int) -> OmniView:
        """Node ``i``'s key image as an :class:`~robokit.mapping.OmniView` (histogram, features, bearings)."""
        i = self._node(i)
        return OmniView(self.histograms[i], self.node_features(i), self.bearings[self.offsets[i]:self.offsets[i + 1]])

    def rank_by_histogram(self, histogram: Any, *, exclude: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """Every node ordered by the hue-histogram distance of its key image to ``histogram``.

        Parameters
        ----------
        histogram : array_like, shape (B,)
        exclude : array_like of int or bool mask, optional
            Nodes left out of the ranking.

        Returns
        -------
        order : numpy.ndarray of int, shape (K,)
            Node indices, nearest first (ties by index).
        distances : numpy.ndarray, shape (K,)
            Their distances, ascending.

        Notes
        -----
        The coarse stage of Sec. "Hierarchical localization": Eq. (5) against every node in one
        vectorised step (:func:`robokit.vision.histogram_distance`).
        """
        if len(self.histograms) and np.size(histogram) != self.histograms.shape[1]:
            raise ValueError(f"histogram: expected {self.histograms.shape[1]} bins like the map's, got "
                             f"{np.size(histogram)}")
        d = histogram_distance(histogram, self.histograms)                      # Eq. (5)
        keep = np.ones(len(self), bool)
        if exclude is not None:
            ex = np.asarray(exclude)
            if ex.dtype == bool:
                if ex.shape != (len(self),):
                    raise ValueError(f"exclude: expected a mask of {len(self)} nodes, got shape {ex.shape}")
                ex = np.flatnonzero(ex)
            ex = as_array(ex, "exclude", ndim=1).astype(np.int64) if ex.size else np.zeros(0, np.int64)
            if ex.size and (ex.min() < 0 or ex.max() >= len(self)):
                raise ValueError(f"exclude: expected node indices in [0, {len(self)}), got {ex.min()}..{ex.max()}")
            keep[ex] = False
        order = np.flatnonzero(keep)[np.argsort(d[keep], kind="stable")]
        return order, d[order]

    def match_counts(self, descriptors: Any, nodes: Any, *, ratio: float = OMNI_RATIO) -> tuple[np.ndarray, list]:
        """Distance-ratio SIFT matches of query descriptors against each of ``nodes``.

        Parameters
        ----------
        descriptors : array_like, shape (Q, D)
        nodes : array_like of int, shape (K,)
        ratio : float, default 0.7
            Nearest / second-nearest distance bound (see :func:`robokit.mapping.build_topological_map`).

        Returns
        -------
        counts : numpy.ndarray of int, shape (K,)
        matches : list of robokit.vision.Matches
            ``matches[k].train`` indexes node ``nodes[k]``'s own features.

        Notes
        -----
        The fine stage of Sec. "Hierarchical localization": "each candidate in the map database is
        matched with the image for localization and the correct position is the one getting the
        largest number of matches", with the nodes' KD-trees.
        """
        q = as_array(descriptors, "descriptors", dtype=np.float32)
        q = q.reshape(0, self.descriptors.shape[1]) if q.size == 0 else q
        q = as_array(q, "descriptors", shape=(None, self.descriptors.shape[1]), dtype=np.float32)
        ratio = as_positive(ratio, "ratio")
        idx = np.atleast_1d(as_array(nodes, "nodes", dtype=np.int64))
        out = []
        for i in idx:
            index = self._indices[self._node(i)]
            out.append(Matches.empty() if index is None or len(q) == 0 else index.match(q, ratio=ratio))
        return np.array([len(m) for m in out], dtype=int), out

    def graph(self) -> PoseGraph:
        """The nodes and edges as a :class:`~robokit.mapping.PoseGraph` (node 0 fixed).

        Notes
        -----
        Sec. "Loop closure alignment": "The first node of the map is considered as the reference
        frame"; the edges' covariances (in each edge's start frame) become information matrices for
        g2o's error by :func:`robokit.mapping.pose_graph.information_from_covariance`.
        """
        return PoseGraph(self.poses, self.edges, self.measurements,
                         information_from_covariance(self.measurements, self.covariances), fixed=0)

    def with_poses(self, poses: Any, variances: Any = None) -> "TopologicalMap":
        """A copy with new node poses (e.g. after relaxation), features and edges shared.

        Raises
        ------
        ValueError
            For a shape other than (N, 3) or NaN/inf.
        """
        new = as_planar(poses, "poses", shape=(len(self), 3))
        var = self.variances if variances is None else as_array(variances, "variances", shape=(len(self),))
        if np.any(var < 0):
            raise ValueError(f"variances: expected non-negative node variances, got {var.min()}")
        out = copy.copy(self)                       # shares the features and their KD-trees
        object.__setattr__(out, "poses", new)
        object.__setattr__(out, "variances", var)
        return out

    def with_edges(self, edges: Any, measurements: Any, covariances: Any, kinds: Any) -> "TopologicalMap":
        """A copy with other edges (e.g. loop closures added), nodes, features and KD-trees shared.

        Raises
        ------
        ValueError
            As the constructor, for edges that do not fit the nodes.
        """
        out = copy.copy(self)
        for name, value in zip(("edges", "measurements", "covariances", "kinds"),
                               _edges(len(self), edges, measurements, covariances, kinds)):
            object.__setattr__(out, name, value)
        return out

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The map as a dict of plain arrays (what :meth:`save` writes; ``index`` as a 0-d string array)."""
        return {f.name: np.array(getattr(self, f.name)) if f.name == "index" else getattr(self, f.name)
                for f in dataclasses.fields(self)}

    def save(self, path: str | Path) -> Path:
        """Write the map as one compressed ``.npz`` of plain arrays, atomically: an interrupted save
        leaves the old file (or none), never a partial one.

        Returns
        -------
        pathlib.Path
        """
        arrays = {"format": np.array(_FORMAT), **self.to_arrays()}
        return write_atomically(as_file_path(path), lambda tmp: save_npz(tmp, arrays))

    @classmethod
    def load(cls, path: str | Path) -> "TopologicalMap":
        """Read a map written by :meth:`save` (validated like a new one).

        The file is read by :func:`robokit.files.read_npz` within :data:`MAX_MAP_BYTES` bytes and
        :data:`MAX_MAP_VALUES` values per array, checked before its data are read.

        Raises
        ------
        ValueError
            For a file that is not such a map (missing arrays, other format version, truncated,
            corrupt, a device, larger than the bounds, arrays of the wrong shape or type).
        FileNotFoundError
            If there is no such file.
        """
        path = as_file_path(path)
        names = [f.name for f in dataclasses.fields(cls)]
        try:
            data = read_npz(path, max_bytes=MAX_MAP_BYTES, max_values=MAX_MAP_VALUES)
            if int(data["format"]) != _FORMAT:
                raise ValueError(f"path: expected a topological map of format {_FORMAT}, got {int(data['format'])}")
            arrays = {k: data[k] for k in names if k != "index" or k in data}
            return cls(**arrays)
        except KeyError as exc:
            raise ValueError(f"path: expected a saved TopologicalMap, {exc.args[0]!r} is missing") from None
        except NpzFileError:
            raise
        except (TypeError, ValueError, IndexError) as exc:
            raise ValueError(f"path: {path.name} is not a saved TopologicalMap ({exc})") from None
