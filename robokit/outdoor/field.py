"""An outdoor field with obstacles: ray casting for the sonars and collision checks for the truck.

Hamid et al. (seed 000 Q3, Sec. 1) test their truck on a football field with obstacles placed
between GPS waypoints. :func:`random_course` builds such a course in a ~100 m x 60 m field from a
seed: obstacles are circles (poles, bins, people) and rotated boxes (crates, benches), some placed on
the straight lines between waypoints so that the truck has to avoid them. Frame: x east, y north,
metres, origin at the south-west corner; the field's geodetic origin places it on the Earth for GPS.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..sim.field import field_world, scatter_obstacles
from ..validation import as_array, as_points, as_rng, check_int, check_positive

__all__ = ["Field", "open_field", "random_course", "Course", "UNIMAP_ORIGIN"]

#: Geodetic origin (radians) of the simulated field: a sports field in Perlis, Malaysia, near the
#: authors' university (UniMAP); chosen for realism only.
UNIMAP_ORIGIN = (np.radians(6.4590), np.radians(100.3505))


@dataclasses.dataclass(frozen=True, eq=False)
class Field:
    """A rectangular field with circular and box obstacles.

    Parameters
    ----------
    size : (float, float)
        Width (east) and height (north) in metres.
    circles : array_like, shape (N, 3)
        ``[x, y, radius]`` per circular obstacle.
    boxes : array_like, shape (M, 5)
        ``[cx, cy, length, width, yaw]`` per box (yaw in radians, counter-clockwise from east).
    origin : (float, float)
        Geodetic latitude and longitude (radians) of the field's (0, 0) corner.
    """

    size: tuple[float, float] = (100.0, 60.0)
    circles: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros((0, 3)))
    boxes: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros((0, 5)))
    origin: tuple[float, float] = UNIMAP_ORIGIN

    def __post_init__(self):
        w = check_positive(self.size[0], "size[0]")
        h = check_positive(self.size[1], "size[1]")
        circles = as_array(self.circles, "circles").reshape(-1, 3) if np.size(self.circles) else np.zeros((0, 3))
        boxes = as_array(self.boxes, "boxes").reshape(-1, 5) if np.size(self.boxes) else np.zeros((0, 5))
        if np.any(circles[:, 2] <= 0):
            raise ValueError("circles: expected positive radii in column 2")
        if np.any(boxes[:, 2:4] <= 0):
            raise ValueError("boxes: expected positive length and width in columns 2 and 3")
        object.__setattr__(self, "size", (w, h))
        object.__setattr__(self, "circles", circles)
        object.__setattr__(self, "boxes", boxes)
        corners = _box_corners(boxes)
        object.__setattr__(self, "_corners", corners)
        # box edges as segments p -> p + e, and every obstacle's centre and bounding radius
        object.__setattr__(self, "_seg_p", corners.reshape(-1, 2))
        object.__setattr__(self, "_seg_e", (np.roll(corners, -1, axis=1) - corners).reshape(-1, 2))
        object.__setattr__(self, "_box_r", np.hypot(boxes[:, 2], boxes[:, 3]) / 2)

    @property
    def n_obstacles(self) -> int:
        """Number of obstacles (circles plus boxes)."""
        return len(self.circles) + len(self.boxes)

    def world(self, seed: int = 0, border: float = 3.0) -> Any:
        """The same field as a textured 3D :class:`robokit.sim.World` (cameras, LiDAR, meshcat).

        Parameters
        ----------
        seed : int, default 0
            Seeds textures and obstacle heights (the layout is this field's).
        border : float, default 3.0
            Run-off between the field's edge and the surrounding hedge (metres).

        Returns
        -------
        robokit.sim.World
            Boxes are exact; each circle becomes a 12-sided prism with its corners on the circle.

        Raises
        ------
        ValueError
            If an obstacle reaches the hedge.

        Notes
        -----
        :func:`robokit.sim.field_world`; Hamid et al. (seed 000 Q3, Sec. 1) test on a football field.
        """
        return field_world(self.size, self.circles, self.boxes, seed=seed, border=border)

    def box_corners(self) -> np.ndarray:
        """Corners of every box, shape ``(M, 4, 2)``, counter-clockwise (Ericson 2005, Sec. 4.4)."""
        return self._corners.copy()

    def raycast(self, origins: Any, angles: Any, max_range: float) -> np.ndarray:
        """Distance along rays to the first obstacle surface (``max_range`` if none is nearer).

        Parameters
        ----------
        origins : array_like, shape (K, 2)
            Ray starts in metres.
        angles : array_like, shape (K,)
            Ray directions in radians (counter-clockwise from east).
        max_range : float
            Returned where nothing is hit.

        Returns
        -------
        numpy.ndarray, shape (K,)

        Notes
        -----
        Ray-circle and ray-segment intersection (e.g. Ericson, *Real-Time Collision Detection*,
        2005, Secs. 5.3.2 and 5.1.9); a ray starting inside an obstacle returns 0.
        """
        o = as_points(origins, "origins", 2)
        a = as_array(angles, "angles", shape=(o.shape[0],))
        return self._raycast(o, a, check_positive(max_range, "max_range"))

    def _raycast(self, o: np.ndarray, a: np.ndarray, rmax: float) -> np.ndarray:
        # unvalidated core of raycast(); only obstacles that can be within rmax of a ray start count
        d = np.stack([np.cos(a), np.sin(a)], axis=1)
        best = np.full(len(o), rmax)
        lo, hi = o.min(axis=0) - rmax, o.max(axis=0) + rmax
        circles = self.circles
        if len(circles):
            near = np.all((circles[:, :2] + circles[:, 2:3] >= lo) & (circles[:, :2] - circles[:, 2:3] <= hi), axis=1)
            circles = circles[near]
        if len(circles):
            oc = circles[None, :, :2] - o[:, None, :]            # (K, N, 2)
            tca = np.einsum("knj,kj->kn", oc, d)
            oc2 = np.einsum("knj,knj->kn", oc, oc)
            d2 = oc2 - tca ** 2
            r2 = circles[None, :, 2] ** 2
            with np.errstate(invalid="ignore"):
                t0 = tca - np.sqrt(r2 - d2)
            t = np.where(oc2 <= r2, 0.0, np.where((d2 <= r2) & (t0 >= 0), t0, np.inf))
            best = np.minimum(best, t.min(axis=1))
        if len(self.boxes):
            near = np.all((self.boxes[:, :2] + self._box_r[:, None] >= lo)
                          & (self.boxes[:, :2] - self._box_r[:, None] <= hi), axis=1)
            if np.any(near):
                sel = np.repeat(near, 4)
                p, e = self._seg_p[sel], self._seg_e[sel]
                w = p[None] - o[:, None]                                    # (K, S, 2)
                denom = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]
                with np.errstate(divide="ignore", invalid="ignore"):
                    t = (w[..., 0] * e[None, :, 1] - w[..., 1] * e[None, :, 0]) / denom
                    u = (w[..., 0] * d[:, None, 1] - w[..., 1] * d[:, None, 0]) / denom
                hit = (np.abs(denom) > 1e-12) & (t >= 0) & (u >= 0) & (u <= 1)
                best = np.minimum(best, np.where(hit, t, np.inf).min(axis=1))
                best = np.where(self._inside_box(o, self.boxes[near]), 0.0, best)
        return best

    def inside_box(self, points: Any) -> np.ndarray:
        """Boolean ``(K,)``: which points lie inside any box (point in oriented box, Ericson 2005, Sec. 5.1.3)."""
        return self._inside_box(as_points(points, "points", 2), self.boxes)

    @staticmethod
    def _inside_box(pts: np.ndarray, boxes: np.ndarray) -> np.ndarray:
        if not len(boxes):
            return np.zeros(len(pts), dtype=bool)
        rel = pts[:, None, :] - boxes[None, :, :2]
        c, s = np.cos(boxes[:, 4]), np.sin(boxes[:, 4])
        lx = rel[..., 0] * c + rel[..., 1] * s
        ly = -rel[..., 0] * s + rel[..., 1] * c
        return np.any((np.abs(lx) <= boxes[:, 2] / 2) & (np.abs(ly) <= boxes[:, 3] / 2), axis=1)

    def collides(self, pose: Any, length: float, width: float) -> bool:
        """Whether a ``length`` x ``width`` rectangle at ``pose = [x, y, theta]`` touches an obstacle.

        Notes
        -----
        Circle-rectangle test by the closest point of the rectangle, rectangle-rectangle test by
        separating axes (Ericson 2005, Secs. 5.2.1 and 4.4.1).
        """
        x, y, th = as_array(pose, "pose", shape=(3,))
        L, W = check_positive(length, "length") / 2, check_positive(width, "width") / 2
        c, s = np.cos(th), np.sin(th)
        reach = math.hypot(L, W)
        circles = self.circles[np.abs(self.circles[:, :2] - [x, y]).max(axis=1) <= self.circles[:, 2] + reach] \
            if len(self.circles) else self.circles
        if len(circles):
            rel = circles[:, :2] - [x, y]
            lx = np.clip(rel[:, 0] * c + rel[:, 1] * s, -L, L)
            ly = np.clip(-rel[:, 0] * s + rel[:, 1] * c, -W, W)
            closest = np.stack([x + c * lx - s * ly, y + s * lx + c * ly], axis=1)
            if np.any(np.hypot(*(closest - circles[:, :2]).T) <= circles[:, 2]):
                return True
        if len(self.boxes):
            near = np.hypot(*(self.boxes[:, :2] - [x, y]).T) <= self._box_r + reach
            mine = _box_corners(np.array([[x, y, 2 * L, 2 * W, th]]))[0] if np.any(near) else None
            for corners in self._corners[near]:
                if _rectangles_overlap(mine, corners):
                    return True
        return False

    def clearance(self, points: Any) -> np.ndarray:
        """Distance from each point to the nearest obstacle (0 inside one).

        Notes
        -----
        Point-circle and point-oriented-box distances (Ericson 2005, Secs. 5.1.3-5.1.4).
        """
        pts = as_points(points, "points", 2)
        out = np.full(len(pts), np.inf)
        if len(self.circles):
            dist = np.hypot(*(pts[:, None, :] - self.circles[None, :, :2]).transpose(2, 0, 1)) - self.circles[:, 2]
            out = np.minimum(out, np.maximum(dist, 0).min(axis=1))
        if len(self.boxes):
            rel = pts[:, None, :] - self.boxes[None, :, :2]
            c, s = np.cos(self.boxes[:, 4]), np.sin(self.boxes[:, 4])
            lx = np.abs(rel[..., 0] * c + rel[..., 1] * s) - self.boxes[:, 2] / 2
            ly = np.abs(-rel[..., 0] * s + rel[..., 1] * c) - self.boxes[:, 3] / 2
            out = np.minimum(out, np.hypot(np.maximum(lx, 0), np.maximum(ly, 0)).min(axis=1))
        return out


def _box_corners(boxes: np.ndarray) -> np.ndarray:
    if not len(boxes):
        return np.zeros((0, 4, 2))
    half = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]], dtype=float) / 2
    local = half[None] * boxes[:, None, 2:4]
    c, s = np.cos(boxes[:, 4])[:, None], np.sin(boxes[:, 4])[:, None]
    return np.stack([boxes[:, None, 0] + c * local[..., 0] - s * local[..., 1],
                     boxes[:, None, 1] + s * local[..., 0] + c * local[..., 1]], axis=-1)


def _rectangles_overlap(a: np.ndarray, b: np.ndarray) -> bool:
    for poly in (a, b):
        for i in range(2):
            edge = poly[i + 1] - poly[i]
            axis = np.array([-edge[1], edge[0]])
            pa, pb = a @ axis, b @ axis
            if pa.max() < pb.min() or pb.max() < pa.min():
                return False
    return True


def open_field(size: tuple[float, float] = (100.0, 60.0), circles: Any = None, boxes: Any = None) -> Field:
    """Return a field of ``size`` metres (default a 100 m x 60 m football field) with given obstacles.

    Notes
    -----
    The test ground of Hamid et al. (seed 000 Q3, Sec. 1: "semi-rugged terrain such as a football
    field").
    """
    return Field(size=(float(size[0]), float(size[1])),
                 circles=np.zeros((0, 3)) if circles is None else circles,
                 boxes=np.zeros((0, 5)) if boxes is None else boxes)


@dataclasses.dataclass(frozen=True, eq=False)
class Course:
    """A seeded navigation task: ``field``, ``waypoints`` (K, 2) in metres and the ``start`` pose."""

    field: Field
    waypoints: np.ndarray
    start: np.ndarray


def random_course(seed: Any = 0, *, n_waypoints: int = 4, n_obstacles: int = 14, on_path: float = 0.5,
                  size: tuple[float, float] = (100.0, 60.0), min_gap: float = 2.5) -> Course:
    """Generate a waypoint course with obstacles, some of them on the legs between waypoints.

    Parameters
    ----------
    seed : int or numpy.random.Generator
        Randomness (see :func:`robokit.validation.as_rng`).
    n_waypoints : int, default 4
        Waypoints after the start, at least 12 m apart.
    n_obstacles : int, default 14
        Circles (radius 0.25-0.8 m) and boxes (0.5-2.0 m sides), about half each.
    on_path : float, default 0.5
        Fraction of obstacles centred on a leg between consecutive waypoints.
    size : (float, float), default (100, 60)
        Field size in metres.
    min_gap : float, default 2.5
        Free space kept between obstacles, and (doubled) around the start and each waypoint, so that
        every course is solvable by a 25 cm wide truck.

    Returns
    -------
    Course

    Notes
    -----
    Modelled on the experiment of Hamid et al. (seed 000 Q3, Sec. 4): drive from the first to the
    last waypoint, avoiding the obstacles met on the way. The obstacles come from
    :func:`robokit.sim.field.scatter_obstacles`, the generator :func:`robokit.sim.open_field` also
    uses; ``course.field.world()`` is the course as a 3D world.
    """
    rng = as_rng(seed, "seed")
    k = check_int(n_waypoints, "n_waypoints", minimum=1, maximum=20)
    n = check_int(n_obstacles, "n_obstacles", minimum=0, maximum=200)
    frac = check_positive(on_path, "on_path", allow_zero=True)
    gap = check_positive(min_gap, "min_gap")
    w, h = check_positive(size[0], "size[0]"), check_positive(size[1], "size[1]")
    margin = 6.0
    start_xy = np.array([margin, rng.uniform(margin, h - margin)])
    points = [start_xy]
    while len(points) < k + 1:
        p = rng.uniform([margin, margin], [w - margin, h - margin])
        if np.hypot(*(p - points[-1])) >= 12.0 and all(np.hypot(*(p - q)) >= 8.0 for q in points[:-1]):
            points.append(p)
    pts = np.array(points)
    circles, boxes = scatter_obstacles(rng, n, (w, h), waypoints=pts, on_path=frac,
                                       keep_clear=[(p, 2 * gap) for p in pts], min_gap=gap)
    first = pts[1] - pts[0]
    start = np.array([pts[0, 0], pts[0, 1], float(np.arctan2(first[1], first[0]) + rng.normal(0, 0.5))])
    return Course(Field(size=(w, h), circles=circles, boxes=boxes), pts[1:].copy(), start)
