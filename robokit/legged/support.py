"""Static stability of a legged robot: the support polygon and the stability margin.

A robot standing still (or moving slowly enough that inertia does not matter) does not tip over
while the vertical projection of its centre of mass lies inside the *support polygon*, the convex
hull of the feet in contact with the ground. McGhee & Frank (1968) measure how far it is from
tipping by the *stability margin*: the shortest distance from that projection to the polygon's
boundary. Robokit signs it: positive inside, zero on an edge, negative (minus the distance to the
polygon) outside, so one number says both "stable?" and "by how much?".

* :func:`support_polygon` - the convex hull of three or more stance feet, counter-clockwise.
* :func:`stability_margin` - the signed margin of one support polygon, edge by edge (the lesson's
  exercise: read it).
* :func:`stability_margins` - the same over a whole plan at once (N instants, K feet, a stance
  mask), without a Python loop over time; ``-inf`` where fewer than three feet are down.

Frames: any horizontal frame (world x, y); feet and centre of mass in the same one, metres.

References
----------
.. [1] R. B. McGhee and A. A. Frank, "On the stability properties of quadruped creeping gaits",
   *Mathematical Biosciences* 3, 331-351, 1968.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from ..validation import as_array

__all__ = ["SupportPolygonError", "MAX_COORDINATE", "support_polygon", "stability_margin", "stability_margins",
           "nearest_boundary_point"]

#: Largest coordinate (m) a foot or centre of mass may have: beyond it a number is a fault (a unit
#: error), not a place a robot stands, and squares of it stay far from overflow.
MAX_COORDINATE = 1e6
#: Stance feet whose spread across their best line is below this fraction of their spread along it
#: are collinear: they span a line (or a point), not a polygon.
FLATNESS = 1e-6


class SupportPolygonError(ValueError):
    """Fewer than three stance feet, or feet on one line: there is no support polygon."""


def _as_xy(value: Any, name: str, shape: tuple) -> np.ndarray:
    arr = as_array(value, name, shape=shape)
    if arr.size and np.max(np.abs(arr)) > MAX_COORDINATE:
        raise ValueError(f"{name}: expected coordinates within +-{MAX_COORDINATE:g} m, got {np.max(np.abs(arr)):.3g}")
    return arr


def support_polygon(feet_xy: Any) -> np.ndarray:
    """The support polygon: the convex hull of the stance feet, counter-clockwise.

    Parameters
    ----------
    feet_xy : array_like, shape (k, 2)
        Horizontal positions (m) of the feet on the ground, k >= 3, in any order.

    Returns
    -------
    numpy.ndarray, shape (m, 2)
        The hull's vertices (3 <= m <= k) counter-clockwise; feet inside the hull or on one of its
        edges are not vertices.

    Raises
    ------
    SupportPolygonError
        For fewer than three feet, or feet that are collinear or coincide (their spread across
        their best-fit line is below ``FLATNESS`` = 1e-6 times their spread along it): a line
        supports no robot statically.
    ValueError, TypeError
        For a wrong shape, non-finite values or coordinates beyond ``MAX_COORDINATE``.

    Notes
    -----
    McGhee & Frank (1968), the support pattern (unnumbered): the convex hull of the points of
    support. The hull is ``scipy.spatial.ConvexHull`` (Qhull), whose 2-D vertices come
    counter-clockwise.

    Examples
    --------
    >>> support_polygon([[0, 0], [1, 1], [1, 0], [0, 1], [0.5, 0.5]]).tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    >>> support_polygon([[0, 0], [1, 0]])
    Traceback (most recent call last):
    ...
    robokit.legged.support.SupportPolygonError: feet_xy: expected at least three stance feet for a support polygon, got 2
    """
    feet = _as_xy(feet_xy, "feet_xy", (None, 2))
    if len(feet) < 3:
        raise SupportPolygonError(f"feet_xy: expected at least three stance feet for a support polygon, got {len(feet)}")
    spread = np.linalg.svd(feet - feet.mean(axis=0), compute_uv=False)
    if not spread[1] > FLATNESS * spread[0]:
        raise SupportPolygonError(f"feet_xy: the {len(feet)} feet are collinear (or coincide): they span a line, "
                                  "not a support polygon")
    try:
        hull = ConvexHull(feet)
    except QhullError:      # nearly flat beyond FLATNESS for Qhull's own tolerance
        raise SupportPolygonError(f"feet_xy: the {len(feet)} feet are nearly collinear: no support polygon") from None
    vertices = hull.vertices
    start = np.lexsort((feet[vertices, 1], feet[vertices, 0]))[0]    # lowest x (then y) first: a fixed order
    return feet[np.roll(vertices, -start)]


def stability_margin(feet_xy: Any, com_xy: Any) -> float:
    """Signed static stability margin: the distance from the centre-of-mass projection to the
    support polygon's boundary, positive inside and negative outside.

    Parameters
    ----------
    feet_xy : array_like, shape (k, 2)
        Horizontal positions (m) of the stance feet, k >= 3 (see :func:`support_polygon`).
    com_xy : array_like, shape (2,)
        Vertical projection of the centre of mass (m), in the same frame.

    Returns
    -------
    float
        Metres: the shortest distance to an edge when the point is inside (or on) the polygon,
        minus the distance to the polygon when it is outside.

    Raises
    ------
    SupportPolygonError
        For fewer than three feet or collinear feet (no support polygon).
    ValueError, TypeError
        For wrong shapes or non-finite values.

    Notes
    -----
    McGhee & Frank (1968), the stability margin (unnumbered): the shortest distance from the
    projection of the centre of gravity to the boundary of the support pattern. Walking the
    counter-clockwise polygon, an edge from ``a`` to ``b`` has the polygon on its left, so the
    point ``p`` is inside when every cross product ``(b - a) x (p - a) >= 0``; its distance to the
    segment is ``|p - a - t (b - a)|`` with ``t = clip((p - a).(b - a) / |b - a|^2, 0, 1)``, the
    nearest point of the segment. The margin is the smallest of these distances, with the sign of
    "inside".

    Examples
    --------
    >>> square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    >>> stability_margin(square, [0.5, 0.5]), stability_margin(square, [0.5, 0.2])
    (0.5, 0.2)
    >>> stability_margin(square, [2.0, 0.5]), stability_margin(square, [1.0, 0.5])
    (-1.0, 0.0)
    """
    polygon = support_polygon(feet_xy)
    return nearest_boundary_point(polygon, _as_xy(com_xy, "com_xy", (2,)), validate=False)[1]


def nearest_boundary_point(polygon: Any, point: Any, *, validate: bool = True) -> tuple[np.ndarray, float]:
    """The point of a convex polygon's boundary nearest to ``point``, and the signed distance to it.

    Parameters
    ----------
    polygon : array_like, shape (k, 2)
        Vertices of a convex polygon, k >= 3, in either order (a clockwise one is reversed), open
        or closed (a last vertex equal to the first is dropped).
    point : array_like, shape (2,)
    validate : bool, default True
        Validate the inputs; ``False`` is the fast path for callers that built the polygon
        (counter-clockwise and open, as :func:`support_polygon` gives).

    Returns
    -------
    nearest : numpy.ndarray, shape (2,)
    distance : float
        Positive inside the polygon, negative outside, 0 on an edge: McGhee & Frank's margin when
        ``point`` is the centre of mass's projection.

    Raises
    ------
    SupportPolygonError
        For fewer than 3 distinct vertices or collinear ones (no inside).
    TypeError, ValueError
        For arrays of the wrong shape or with NaN or infinity.

    Examples
    --------
    >>> near, d = nearest_boundary_point([[0, 0], [1, 0], [1, 1], [0, 1]], [0.5, 0.2])
    >>> near.tolist(), d
    ([0.5, 0.0], 0.2)
    """
    if validate:
        polygon = _as_xy(polygon, "polygon", (None, 2))
        if len(polygon) > 3 and np.array_equal(polygon[0], polygon[-1]):
            polygon = polygon[:-1]                  # a closed ring (GeoJSON's convention): one vertex twice
        if len(polygon) < 3:
            raise SupportPolygonError(f"polygon: expected at least 3 vertices, got {len(polygon)}")
        x, y = polygon[:, 0], polygon[:, 1]
        area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        if area == 0.0:
            raise SupportPolygonError("polygon: expected a polygon with an area, got collinear vertices")
        if area < 0:                                # clockwise: the inside is on the other side
            polygon = polygon[::-1]
        point = _as_xy(point, "point", (2,))
    a, b = polygon, np.roll(polygon, -1, axis=0)           # edge i runs from a[i] to b[i]
    edge, rel = b - a, point - a
    cross = edge[:, 0] * rel[:, 1] - edge[:, 1] * rel[:, 0]   # > 0: point left of the edge, the inside
    t = np.clip(np.sum(rel * edge, axis=1) / np.sum(edge * edge, axis=1), 0.0, 1.0)
    foot = a + t[:, None] * edge                               # nearest point of each edge
    dist = np.linalg.norm(point - foot, axis=1)
    k = int(np.argmin(dist))
    return foot[k], float(dist[k] if np.all(cross >= 0) else -dist[k])


def stability_margins(feet_xy: Any, stance: Any, com_xy: Any) -> np.ndarray:
    """Signed stability margins over time: :func:`stability_margin` for every instant of a plan.

    Parameters
    ----------
    feet_xy : array_like, shape (N, K, 2)
        Horizontal foot positions (m) at N instants (K = 4 for a quadruped).
    stance : array_like of bool, shape (N, K)
        Which feet are on the ground at each instant.
    com_xy : array_like, shape (N, 2)
        Centre-of-mass projections (m).

    Returns
    -------
    numpy.ndarray, shape (N,)
        The margin at each instant (m), and ``-inf`` where fewer than three feet are in stance or
        the stance feet are collinear: there is no support polygon, so the robot is not statically
        stable (a trot's two-foot phases; it balances dynamically, if at all).

    Raises
    ------
    ValueError, TypeError
        For shapes that disagree, non-finite positions, a non-boolean stance or coordinates beyond
        ``MAX_COORDINATE``.

    Notes
    -----
    The same margin as :func:`stability_margin` (McGhee & Frank 1968, unnumbered) without building
    each hull. An ordered pair of stance feet ``(i, j)`` is an edge of the counter-clockwise hull
    when every other stance foot lies on its left or on its line; the centre of mass is inside when
    it is left of every such edge, and the margin is its distance to the nearest one. All K (K - 1)
    ordered pairs are tested for all N instants at once (arrays of N x K (K - 1) x K values, no loop
    over time). Where a foot lies on an edge, the edge's parts count as edges too, which changes no
    distance. Collinear stance feet are detected as in :func:`support_polygon`.

    Examples
    --------
    >>> feet = np.array([[[0, 0], [1, 0], [1, 1], [0, 1]]] * 3, float)
    >>> stance = [[True] * 4, [True, True, True, False], [True, False, True, False]]
    >>> stability_margins(feet, stance, [[0.5, 0.5], [0.6, 0.5], [0.5, 0.5]])
    array([0.5       , 0.07071068,       -inf])
    """
    feet = _as_xy(feet_xy, "feet_xy", (None, None, 2))
    n, k = feet.shape[:2]
    mask = as_array(stance, "stance", dtype=bool)
    if mask.shape != (n, k):
        raise ValueError(f"stance: expected shape {(n, k)} (one flag per foot of feet_xy), got shape {mask.shape}")
    com = _as_xy(com_xy, "com_xy", (None, 2))
    if len(com) != n:
        raise ValueError(f"com_xy: expected shape {(n, 2)} (one point per instant of feet_xy), got shape {com.shape}")
    count = mask.sum(axis=1)

    # collinear stance feet: the scatter matrix's smaller eigenvalue is ~0 (support_polygon's test)
    w = mask[..., None].astype(float)
    mean = (feet * w).sum(axis=1) / np.maximum(count, 1)[:, None]
    d = (feet - mean[:, None, :]) * w
    sxx, syy, sxy = (d[..., 0] ** 2).sum(1), (d[..., 1] ** 2).sum(1), (d[..., 0] * d[..., 1]).sum(1)
    half_trace, root = (sxx + syy) / 2, np.hypot((sxx - syy) / 2, sxy)
    flat = ~(half_trace - root > FLATNESS ** 2 * (half_trace + root))

    # every ordered pair (i, j) as a candidate edge: its vector e, and every foot seen from foot i
    x, y = feet[..., 0], feet[..., 1]                              # (N, K) each
    i, j = np.nonzero(~np.eye(k, dtype=bool))                      # the K (K - 1) ordered pairs
    ex, ey = x[:, j] - x[:, i], y[:, j] - y[:, i]                  # (N, P)
    dx, dy = x[:, None, :] - x[:, i, None], y[:, None, :] - y[:, i, None]      # (N, P, K)
    cross = ex[..., None] * dy - ey[..., None] * dx
    length2 = ex * ex + ey * ey
    # each foot left of the edge, on its line (|sin| <= FLATNESS), or in the air
    left = (cross >= 0) | (cross * cross <= FLATNESS ** 2 * length2[..., None] * (dx * dx + dy * dy))
    is_edge = mask[:, i] & mask[:, j] & (length2 > 0) & (left | ~mask[:, None, :]).all(axis=-1)

    rx, ry = com[:, 0, None] - x[:, i], com[:, 1, None] - y[:, i]  # (N, P): the centre of mass seen from i
    inside = (ex * ry - ey * rx >= 0) | ~is_edge
    t = np.clip((rx * ex + ry * ey) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    distance = np.hypot(rx - t * ex, ry - t * ey)                  # to the nearest point of the segment
    nearest = np.where(is_edge, distance, np.inf).min(axis=1)
    margin = np.where(inside.all(axis=1), nearest, -nearest)
    return np.where((count < 3) | flat, -np.inf, margin)
