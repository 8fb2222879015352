"""A 2D obstacle layout: wall segments, circles and rotated boxes, with one ray caster and the queries.

Every planar question the course asks of a map goes through :class:`Layout`: what a LiDAR beam or
a sonar ray hits first (:meth:`Layout.raycast`), whether points are inside an obstacle
(:meth:`Layout.contains`), how far they are from the nearest one (:meth:`Layout.clearance`) and
whether a robot's rectangular body touches one (:meth:`Layout.collides`). The LiDAR casts over the
layout of a world's slice (:meth:`robokit.sim.World.layout`), lesson 05's field
(:class:`robokit.outdoor.Field`) is a layout of circles and boxes, and its sonars cast over it.

Obstacle arrays (checked by :func:`obstacle_array`): ``segments`` ``(M, 2, 2)`` end points (walls,
no inside), ``circles`` ``(N, 3)`` ``[x, y, r]`` and ``boxes`` ``(P, 5)``
``[cx, cy, length, width, yaw]`` (solid; yaw counter-clockwise from +x). Units are metres and radians.

References
----------
.. [1] C. Ericson, *Real-Time Collision Detection*, Morgan Kaufmann, 2005.
.. [2] J. O'Rourke, *Computational Geometry in C*, 2nd ed., Cambridge University Press, 1998.
.. [3] R. Goldman, "Intersection of two lines in three-space", in A. S. Glassner (ed.),
   *Graphics Gems*, Academic Press, 1990, p. 304.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..validation import as_array, as_points, as_positive

__all__ = ["Layout", "obstacle_array", "box_corners", "PARALLEL"]

#: A segment counts as parallel to a ray when ``|d x e| <= PARALLEL * |e|`` (the sine of the angle
#: between them is below 1e-12); parallel segments are never hit (see :meth:`Layout.raycast`).
PARALLEL = 1e-12

_COLUMNS = {"circles": (3, slice(2, 3), "radii, column 2"), "boxes": (5, slice(2, 4), "length and width, columns 2-3")}


def obstacle_array(value: Any, kind: str, name: str | None = None) -> np.ndarray:
    """Check an array of obstacles of one kind and return it as floats (empty for ``None``).

    Parameters
    ----------
    value : array_like or None
        ``segments`` ``(M, 2, 2)``, ``circles`` ``(N, 3)`` ``[x, y, r]`` or ``boxes`` ``(P, 5)``
        ``[cx, cy, length, width, yaw]``; one circle or box may be given as a flat row.
    kind : {"segments", "circles", "boxes"}
    name : str, optional
        Argument name for error messages (default ``kind``).

    Returns
    -------
    numpy.ndarray
        Shape ``(M, 2, 2)``, ``(N, 3)`` or ``(P, 5)``.

    Raises
    ------
    ValueError
        For a wrong shape, NaN or infinity, or a radius, length or width that is not positive.

    Notes
    -----
    Input checks of the course (DESIGN.md, "Errors"); the obstacle shapes are those of
    Ericson (2005), Ch. 4 (spheres and oriented boxes in 2D).

    Examples
    --------
    >>> obstacle_array([5.0, 2.0, 0.5], "circles").tolist()
    [[5.0, 2.0, 0.5]]
    >>> obstacle_array(None, "boxes").shape
    (0, 5)
    """
    name = name or kind
    if kind != "segments" and kind not in _COLUMNS:
        raise ValueError(f"kind: expected 'segments', 'circles' or 'boxes', got {kind!r}")
    arr = None if value is None else as_array(value, name)
    if kind == "segments":
        if arr is None or not arr.size:
            return np.zeros((0, 2, 2))
        return as_array(arr, name, shape=(None, 2, 2))
    cols, sizes, what = _COLUMNS[kind]
    if arr is None or not arr.size:
        return np.zeros((0, cols))
    arr = as_points(arr, name, cols)
    if np.any(arr[:, sizes] <= 0):
        raise ValueError(f"{name}: expected positive sizes ({what}), got {arr[:, sizes].min():.3g}")
    return arr


def box_corners(boxes: Any) -> np.ndarray:
    """Corners of rotated boxes ``[cx, cy, length, width, yaw]``, counter-clockwise.

    Parameters
    ----------
    boxes : array_like, shape (P, 5)

    Returns
    -------
    numpy.ndarray, shape (P, 4, 2)
        Starting at the ``(+length/2, +width/2)`` corner in the box frame.

    Notes
    -----
    Oriented box as centre, half-extents and rotation (Ericson 2005, Sec. 4.4).

    Examples
    --------
    >>> box_corners([[2.0, 1.0, 2.0, 1.0, 0.0]])[0].tolist()
    [[3.0, 1.5], [1.0, 1.5], [1.0, 0.5], [3.0, 0.5]]
    """
    b = obstacle_array(boxes, "boxes")
    half = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]], dtype=float) / 2
    local = half[None] * b[:, None, 2:4]
    c, s = np.cos(b[:, 4])[:, None], np.sin(b[:, 4])[:, None]
    return np.stack([b[:, None, 0] + c * local[..., 0] - s * local[..., 1],      # R(yaw) (x, y) + centre
                     b[:, None, 1] + s * local[..., 0] + c * local[..., 1]], axis=-1)


class Layout:
    """Walls, circles and rotated boxes in the plane (see the module notes for the arrays).

    Parameters
    ----------
    segments : array_like, shape (M, 2, 2), optional
        Wall segments: surfaces without an inside (a world's footprint).
    circles : array_like, shape (N, 3), optional
        Solid discs ``[x, y, r]``.
    boxes : array_like, shape (P, 5), optional
        Solid rotated rectangles ``[cx, cy, length, width, yaw]``.

    Raises
    ------
    ValueError
        For badly shaped or non-finite arrays, or non-positive sizes (:func:`obstacle_array`).

    Notes
    -----
    Straight edges (walls and the four sides of every box) are kept as ``p + s e``, ``s`` in
    [0, 1], for the ray caster; the arrays are read-only.

    Examples
    --------
    >>> lay = Layout(circles=[[4.0, 0.0, 1.0]], boxes=[[0.0, 5.0, 2.0, 2.0, 0.0]])
    >>> lay.raycast([0.0, 0.0], [0.0, np.pi / 2, np.pi]).tolist()
    [3.0, 4.0, inf]
    >>> lay.contains([[4.5, 0.0], [0.0, 0.0]]).tolist()
    [True, False]
    """

    def __init__(self, segments: Any = None, circles: Any = None, boxes: Any = None) -> None:
        self.segments = obstacle_array(segments, "segments")
        self.circles = obstacle_array(circles, "circles")
        self.boxes = obstacle_array(boxes, "boxes")
        self.corners = box_corners(self.boxes)
        sides = np.stack([self.corners, np.roll(self.corners, -1, axis=1)], axis=2).reshape(-1, 2, 2)
        edges = np.concatenate([self.segments, sides])
        self.box_radius = np.hypot(self.boxes[:, 2], self.boxes[:, 3]) / 2
        # the kernel's inputs: p + s e per edge as contiguous columns, |e| PARALLEL, and the bounding
        # boxes of edges, circles and boxes (in that order) for culling by max_range
        self._edges = np.ascontiguousarray(np.column_stack([edges[:, 0], edges[:, 1] - edges[:, 0]]).T)
        self._parallel = PARALLEL * np.hypot(self._edges[2], self._edges[3])
        reach = np.concatenate([self.circles[:, 2], self.box_radius])[:, None]
        centres = np.concatenate([self.circles[:, :2], self.boxes[:, :2]])
        self._low = np.concatenate([edges.min(axis=1), centres - reach])
        self._high = np.concatenate([edges.max(axis=1), centres + reach])
        self._split = (len(edges), len(edges) + len(self.circles))
        for arr in (self.segments, self.circles, self.boxes, self.corners, self.box_radius):
            arr.flags.writeable = False

    @classmethod
    def from_cells(cls, occupied: Any, resolution: float, origin: Any = (0.0, 0.0)) -> "Layout":
        """The outline of a grid's occupied cells as wall segments (a map's geometry for the LiDAR).

        Parameters
        ----------
        occupied : array_like of bool, shape (rows, cols)
            Occupied cells; row ``i``, column ``j`` covers ``x`` in ``origin[0] + [j, j + 1] *
            resolution`` and ``y`` in ``origin[1] + [i, i + 1] * resolution`` (the layout of
            :class:`robokit.mapping.OccupancyGrid`, row 0 at the bottom).
        resolution : float
            Cell size in metres.
        origin : array_like, shape (2,), default (0, 0)
            World coordinates of the corner of cell ``(0, 0)``.

        Returns
        -------
        Layout
            One segment per run of cell edges between an occupied and a free (or outside) cell,
            merged along rows and columns, so a ray stops on the first occupied cell it enters.

        Raises
        ------
        ValueError, TypeError
            For a mask that is not 2-D boolean-like, or a bad resolution or origin.

        Notes
        -----
        A grid map read as geometry (Thrun et al. 2005, Sec. 9.2: the occupancy grid; the beam model's
        ray casting, Sec. 6.3): the cells' boundary, so :meth:`raycast` serves a map the way it serves a
        world's walls (one ray caster). Merging runs keeps the segment count near the outline's length.

        Examples
        --------
        >>> walls = Layout.from_cells([[True, True], [False, False]], 0.5)   # the bottom row is occupied
        >>> len(walls.segments), walls.raycast([0.5, 0.75], [-np.pi / 2]).tolist()
        (4, [0.25])
        """
        occ = as_array(occupied, "occupied", ndim=2, dtype=bool)
        res = as_positive(resolution, "resolution")
        o = as_array(origin, "origin", shape=(2,))
        padded = np.pad(occ, 1)
        segments = []
        for grid, across in ((padded, False), (padded.T, True)):
            # edges between rows k-1 and k of ``grid`` (padded indices), at every column where the cells differ
            edge = grid[1:, 1:-1] != grid[:-1, 1:-1]                   # (rows + 1, cols)
            run = np.diff(np.pad(edge, ((0, 0), (1, 1))).astype(np.int8), axis=1)
            k, start = np.nonzero(run == 1)
            _, stop = np.nonzero(run == -1)                          # row-major: pairs with ``start``
            line, a, b = k * res, start * res, stop * res
            ends = np.stack([np.stack([a, line], 1), np.stack([b, line], 1)], 1)
            segments.append(ends[:, :, ::-1] if across else ends)
        return cls(segments=np.concatenate(segments) + o)

    def __repr__(self) -> str:
        return (f"{type(self).__name__}({len(self.segments)} segments, {len(self.circles)} circles, "
                f"{len(self.boxes)} boxes)")

    @property
    def n_obstacles(self) -> int:
        """Number of solid obstacles (circles plus boxes)."""
        return len(self.circles) + len(self.boxes)

    def box_corners(self) -> np.ndarray:
        """Corners of every box, shape ``(P, 4, 2)``, counter-clockwise (see :func:`box_corners`).

        Examples
        --------
        >>> Layout(boxes=[[0.0, 0.0, 2.0, 2.0, 0.0]]).box_corners()[0, 0].tolist()
        [1.0, 1.0]
        """
        return self.corners.copy()

    def raycast(self, origins: Any, angles: Any, max_range: float = math.inf, *, validate: bool = True) -> np.ndarray:
        """Distance along rays to the first obstacle they touch (``max_range`` where none is nearer).

        The tie rule: the range is the smallest ``t >= 0`` at which the ray ``o + t d`` touches an
        obstacle, every obstacle being a closed set (a segment with its end points, a disc with its
        circle, a box with its edges). So a ray that starts on a wall, on the boundary of a circle
        or box, or inside one reads 0; a ray that grazes a circle (tangent) or passes exactly through
        a box corner or a segment's end point hits it there. One exception, by choice: a segment
        parallel to the ray (``|d x e| <= 1e-12 |e|``, :data:`PARALLEL`) is never hit, not even when
        the ray runs along it. Seen edge-on a wall has no width, and in a closed outline (a world's
        footprint, a box) the ray meets the neighbouring edge at the shared end point at the same
        distance.

        Parameters
        ----------
        origins : array_like, shape (2,) or (K, 2)
            Ray start(s) in metres; one origin is shared by all rays (a scanner).
        angles : array_like, shape (K,)
            Ray directions in radians (counter-clockwise from +x).
        max_range : float, default inf
            Returned where nothing is hit nearer; a finite value also skips obstacles that cannot
            be within reach of any origin.
        validate : bool, default True
            Validate the inputs; ``False`` is the fast path for callers that already did
            (``origins`` as a float array, ``angles`` a 1-D float array, ``max_range`` > 0).

        Returns
        -------
        numpy.ndarray, shape (K,)

        Raises
        ------
        ValueError
            For badly shaped or non-finite origins or angles, a number of origins other than 1 or
            ``K``, or a ``max_range`` that is not positive.

        Notes
        -----
        Ray-segment intersection in 2D cross products (Goldman 1990; O'Rourke 1998, Sec. 7.2):
        with ``a = p - o``, ``t = (a x e) / (d x e)`` and ``s = (a x d) / (d x e)``; ray-circle
        intersection and point in oriented box (Ericson 2005, Secs. 5.3.2 and 5.1.4). Vectorised
        over all ray-obstacle pairs.

        Examples
        --------
        >>> walls = Layout(segments=[[[2.0, -1.0], [2.0, 1.0]]])
        >>> walls.raycast([0.0, 0.0], [0.0, np.pi]).tolist()
        [2.0, inf]
        >>> walls.raycast([[0.0, 0.0], [2.0, 0.0]], [np.pi, 0.5], max_range=5.0).tolist()
        [5.0, 0.0]
        """
        if validate:
            o = as_array(origins, "origins")
            o = o[None] if o.shape == (2,) else as_points(o, "origins", 2)
            a = as_array(angles, "angles", ndim=1)
            if len(o) not in (1, len(a)):
                raise ValueError(f"origins: expected one origin or one per angle ({len(a)}), got {len(o)}")
            rmax = math.inf if max_range == math.inf else as_positive(max_range, "max_range")
        else:
            o, a, rmax = np.reshape(origins, (-1, 2)), angles, max_range
        d = np.stack([np.cos(a), np.sin(a)], axis=1)                    # ray directions, (K, 2)
        c, sn = d[:, :1], d[:, 1:]
        best = np.full(len(a), float(rmax))
        edges, par = self._edges, self._parallel
        circles, boxes = self.circles, self.boxes
        if rmax < math.inf:  # only what can be within rmax of some origin (bounding boxes overlap)
            near = np.all((self._high >= o.min(axis=0) - rmax) & (self._low <= o.max(axis=0) + rmax), axis=1)
            ne, nc = self._split
            edges, par, circles, boxes = edges[:, near[:ne]], par[near[:ne]], circles[near[ne:nc]], boxes[near[nc:]]
        if edges.shape[1]:
            px, py, ex, ey = edges
            wx, wy = px - o[:, :1], py - o[:, 1:]                       # a = p - o, (K or 1, S)
            denom = c * ey - sn * ex                                    # d x e, (K, S)
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (wx * ey - wy * ex) / denom                         # t = (a x e) / (d x e)
                s = (wx * sn - wy * c) / denom                          # s = (a x d) / (d x e)
            hit = np.abs(denom) > par                                   # not parallel
            hit &= t >= 0
            hit &= s >= 0
            hit &= s <= 1
            best = np.minimum(best, np.where(hit, t, np.inf).min(axis=1))
        if len(circles):
            oc = np.broadcast_to(circles[None, :, :2] - o[:, None, :], (len(d), len(circles), 2))  # c - o
            tca = np.einsum("knj,kj->kn", oc, d)                         # (c - o) . d
            oc2 = np.einsum("knj,knj->kn", oc, oc)
            d2 = oc2 - tca ** 2                                         # squared distance centre - ray line
            r2 = circles[None, :, 2] ** 2
            with np.errstate(invalid="ignore"):
                t0 = tca - np.sqrt(r2 - d2)                             # first root of |o + t d - c| = r
            t = np.where(oc2 <= r2, 0.0, np.where((d2 <= r2) & (t0 >= 0), t0, np.inf))
            best = np.minimum(best, t.min(axis=1))
        if len(boxes):
            best = np.where(_inside_boxes(np.broadcast_to(o, (len(a), 2)), boxes), 0.0, best)
        return best

    def contains(self, points: Any) -> np.ndarray:
        """Which points lie inside (or on the boundary of) a circle or a box.

        Parameters
        ----------
        points : array_like, shape (K, 2) or (2,)

        Returns
        -------
        numpy.ndarray of bool, shape (K,)
            Walls have no inside and never contain a point.

        Notes
        -----
        Point in disc and point in oriented box (Ericson 2005, Sec. 5.1.4).

        Examples
        --------
        >>> Layout(boxes=[[0.0, 0.0, 2.0, 1.0, 0.0]]).contains([[0.9, 0.4], [0.0, 0.6]]).tolist()
        [True, False]
        """
        pts = as_points(points, "points", 2)
        inside = _inside_boxes(pts, self.boxes)
        if len(self.circles):
            dist = np.hypot(pts[:, None, 0] - self.circles[:, 0], pts[:, None, 1] - self.circles[:, 1])
            inside |= np.any(dist <= self.circles[:, 2], axis=1)
        return inside

    def clearance(self, points: Any) -> np.ndarray:
        """Distance from each point to the nearest obstacle (0 inside a circle or box).

        Parameters
        ----------
        points : array_like, shape (K, 2) or (2,)

        Returns
        -------
        numpy.ndarray, shape (K,)
            ``inf`` for an empty layout.

        Notes
        -----
        Point-segment, point-circle and point-oriented-box distances (Ericson 2005,
        Secs. 5.1.2-5.1.4).

        Examples
        --------
        >>> lay = Layout(segments=[[[0.0, 3.0], [4.0, 3.0]]], circles=[[10.0, 0.0, 1.0]])
        >>> lay.clearance([[0.0, 0.0], [10.0, 0.0]]).tolist()
        [3.0, 0.0]
        """
        pts = as_points(points, "points", 2)
        out = np.full(len(pts), np.inf)
        if len(self.segments):
            a, e = self.segments[:, 0], self.segments[:, 1] - self.segments[:, 0]
            rel = pts[:, None, :] - a[None]
            with np.errstate(invalid="ignore", divide="ignore"):   # a zero-length wall is a point
                u = np.nan_to_num(np.einsum("kmj,mj->km", rel, e) / np.einsum("mj,mj->m", e, e))
            gap = rel - np.clip(u, 0.0, 1.0)[..., None] * e[None]       # to the closest point a + u e
            out = np.minimum(out, np.hypot(gap[..., 0], gap[..., 1]).min(axis=1))
        if len(self.circles):
            dist = np.hypot(*(pts[:, None, :] - self.circles[None, :, :2]).transpose(2, 0, 1)) - self.circles[:, 2]
            out = np.minimum(out, np.maximum(dist, 0).min(axis=1))
        if len(self.boxes):
            lx, ly = _box_frame(pts, self.boxes)
            lx, ly = np.abs(lx) - self.boxes[:, 2] / 2, np.abs(ly) - self.boxes[:, 3] / 2
            out = np.minimum(out, np.hypot(np.maximum(lx, 0), np.maximum(ly, 0)).min(axis=1))
        return out

    def collides(self, pose: Any, length: float, width: float) -> bool:
        """Whether a ``length`` x ``width`` rectangle centred at ``pose = [x, y, theta]`` touches an obstacle.

        Parameters
        ----------
        pose : array_like, shape (3,)
        length, width : float
            Along and across the heading ``theta`` (metres).

        Returns
        -------
        bool
            Touching counts (closed sets, as in :meth:`raycast`).

        Notes
        -----
        Circle-rectangle test by the closest point of the rectangle, rectangle-rectangle and
        rectangle-segment tests by separating axes (Ericson 2005, Secs. 5.2.1 and 4.4.1).

        Examples
        --------
        >>> lay = Layout(circles=[[1.0, 0.0, 0.5]])
        >>> lay.collides([0.0, 0.0, 0.0], 1.0, 0.5), lay.collides([0.0, 0.0, np.pi / 2], 0.9, 0.5)
        (True, False)
        """
        x, y, th = as_array(pose, "pose", shape=(3,))
        L, W = as_positive(length, "length") / 2, as_positive(width, "width") / 2
        c, s = np.cos(th), np.sin(th)
        reach = math.hypot(L, W)
        circles = self.circles[np.abs(self.circles[:, :2] - [x, y]).max(axis=1) <= self.circles[:, 2] + reach] \
            if len(self.circles) else self.circles
        if len(circles):
            rel = circles[:, :2] - [x, y]
            lx = np.clip(rel[:, 0] * c + rel[:, 1] * s, -L, L)        # closest point, rectangle frame
            ly = np.clip(-rel[:, 0] * s + rel[:, 1] * c, -W, W)
            closest = np.stack([x + c * lx - s * ly, y + s * lx + c * ly], axis=1)
            if np.any(np.hypot(*(closest - circles[:, :2]).T) <= circles[:, 2]):
                return True
        others = []
        if len(self.boxes):
            near = np.hypot(*(self.boxes[:, :2] - [x, y]).T) <= self.box_radius + reach
            others += list(self.corners[near])
        if len(self.segments):
            walls = np.all((self.segments.max(axis=1) >= [x - reach, y - reach])
                           & (self.segments.min(axis=1) <= [x + reach, y + reach]), axis=1)
            others += [seg[[0, 1, 1, 0]] for seg in self.segments[walls]]        # a wall: a flat box
        if not others:
            return False
        mine = box_corners([[x, y, 2 * L, 2 * W, th]])[0]
        return any(_convex_overlap(mine, poly) for poly in others)


def _box_frame(pts: np.ndarray, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coordinates ``(K, P)`` of points in each box's own frame (``R(yaw)^T (p - c)``)."""
    rel = pts[:, None, :] - boxes[None, :, :2]
    c, s = np.cos(boxes[:, 4]), np.sin(boxes[:, 4])
    return rel[..., 0] * c + rel[..., 1] * s, -rel[..., 0] * s + rel[..., 1] * c


def _inside_boxes(pts: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    if not len(boxes):
        return np.zeros(len(pts), dtype=bool)
    lx, ly = _box_frame(pts, boxes)
    return np.any((np.abs(lx) <= boxes[:, 2] / 2) & (np.abs(ly) <= boxes[:, 3] / 2), axis=1)


def _convex_overlap(a: np.ndarray, b: np.ndarray) -> bool:
    """Separating-axis test of two convex quadrilaterals (a flat one is a segment)."""
    for poly in (a, b):
        for i in range(2):
            edge = poly[i + 1] - poly[i]
            axis = np.array([-edge[1], edge[0]])
            pa, pb = a @ axis, b @ axis
            if pa.max() < pb.min() or pb.max() < pa.min():
                return False
    return True
