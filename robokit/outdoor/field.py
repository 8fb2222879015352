"""Lesson 05's field: an obstacle layout with a size and a place on the Earth, and seeded courses.

Hamid et al. (2009) test their truck on a football field with obstacles placed between GPS
waypoints. A :class:`Field` is a :class:`robokit.sim.Layout` of circles (poles, bins, people) and
rotated boxes (crates, benches), so the sonars cast their rays and the truck checks collisions
with the course's one ray caster and collision test; it adds the field's size and the geodetic
origin that places it on the Earth for GPS. :func:`random_course` builds a course in a
~100 m x 60 m field from a seed, some obstacles on the straight lines between waypoints so that
the truck has to avoid them. Frame: x east, y north, metres, origin at the south-west corner.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] J. Feder, "Random sequential adsorption", *Journal of Theoretical Biology* 87(2), 1980.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..sim.worlds_outdoor import field_world, scatter_obstacles
from ..sim.layout import Layout
from ..validation import as_array, as_int, as_positive

__all__ = ["Field", "random_course", "Course", "UNIMAP_ORIGIN"]

#: Geodetic origin (radians) of the simulated field: a sports field in Perlis, Malaysia, near the
#: authors' university (UniMAP); chosen for realism only.
UNIMAP_ORIGIN = (np.radians(6.4590), np.radians(100.3505))


class Field(Layout):
    """A rectangular field with circular and box obstacles, placed on the Earth.

    A :class:`~robokit.sim.Layout` (so :meth:`raycast`, :meth:`collides`, :meth:`clearance`,
    :meth:`contains` and :meth:`box_corners` are the course's one implementation) plus its size
    and geodetic origin. Subclassed rather than composed: every function that takes a layout
    (the sonars, collision checks) takes a field as it is.

    Parameters
    ----------
    size : (float, float), default (100, 60)
        Width (east) and height (north) in metres.
    circles : array_like, shape (N, 3), optional
        ``[x, y, radius]`` per circular obstacle.
    boxes : array_like, shape (M, 5), optional
        ``[cx, cy, length, width, yaw]`` per box (yaw in radians, counter-clockwise from east).
    origin : (float, float), default :data:`UNIMAP_ORIGIN`
        Geodetic latitude and longitude (radians) of the field's (0, 0) corner.

    Raises
    ------
    ValueError
        For a non-positive size, badly shaped obstacle arrays or non-positive obstacle sizes.

    Notes
    -----
    The test ground of Hamid et al. (2009: "semi-rugged terrain such as a football
    field").

    Examples
    --------
    >>> field = Field(circles=[[2.5, 0.0, 0.3]], boxes=[[10.0, 5.0, 2.0, 1.0, 0.0]])
    >>> field.size, field.n_obstacles
    ((100.0, 60.0), 2)
    >>> field.raycast([[0.0, 0.0]], [0.0], max_range=6.45).tolist()      # a sonar ray along +x
    [2.2]
    >>> field.collides([9.0, 5.0, 0.0], 0.5, 0.25)
    True
    """

    def __init__(self, size: Any = (100.0, 60.0), circles: Any = None, boxes: Any = None,
                 origin: Any = UNIMAP_ORIGIN) -> None:
        sz = as_array(size, "size", shape=(2,))
        super().__init__(circles=circles, boxes=boxes)
        self.size = (as_positive(sz[0], "size[0]"), as_positive(sz[1], "size[1]"))
        lat, lon = as_array(origin, "origin", shape=(2,))
        self.origin = (float(lat), float(lon))

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
        :func:`robokit.sim.field_world`; Hamid et al. (2009) test on a football field.

        Examples
        --------
        >>> Field((20.0, 12.0), boxes=[[8.0, 6.0, 2.0, 1.0, 0.4]]).world().info["hedge"]
        (-3.0, -3.0, 23.0, 15.0)
        """
        return field_world(self.size, self.circles, self.boxes, seed=seed, border=border)


@dataclasses.dataclass(frozen=True, eq=False)
class Course:
    """A seeded navigation task: ``field``, ``waypoints`` (K, 2) in metres and the ``start`` pose ``[x, y, theta]``."""

    field: Field
    waypoints: np.ndarray
    start: np.ndarray


def random_course(seed: int = 0, *, n_waypoints: int = 4, n_obstacles: int = 14, on_path: float = 0.5,
                  size: tuple[float, float] = (100.0, 60.0), min_gap: float = 2.5) -> Course:
    """Generate a waypoint course with obstacles, some of them on the legs between waypoints.

    Parameters
    ----------
    seed : int, default 0
        Non-negative integer that seeds the layout: course ``seed`` is always the same course.
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

    Raises
    ------
    ValueError, TypeError
        For counts, fractions, gaps or sizes out of range.

    Notes
    -----
    Modelled on the experiment of Hamid et al. (2009): drive from the first to the last
    waypoint, avoiding the obstacles met on the way. The obstacles come from
    :func:`robokit.sim.worlds_outdoor.scatter_obstacles` (random sequential adsorption, Feder 1980), the generator
    :func:`robokit.sim.open_field` also uses; ``course.field.world()`` is the course as a 3D world.

    Examples
    --------
    >>> course = random_course(4, n_waypoints=2)
    >>> course.waypoints.shape, course.field.n_obstacles
    ((2, 2), 14)
    >>> bool(np.all(course.field.clearance(course.waypoints) >= 2 * 2.5))   # waypoints kept clear
    True
    """
    rng = np.random.default_rng(as_int(seed, "seed", minimum=0))
    k = as_int(n_waypoints, "n_waypoints", minimum=1, maximum=20)
    n = as_int(n_obstacles, "n_obstacles", minimum=0, maximum=200)
    frac = as_positive(on_path, "on_path", allow_zero=True)
    gap = as_positive(min_gap, "min_gap")
    sz = as_array(size, "size", shape=(2,))
    w, h = as_positive(sz[0], "size[0]"), as_positive(sz[1], "size[1]")
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
