"""Hamid et al.'s outdoor field as a textured 3D world, and the obstacle layout it shares with lesson 05.

Hamid et al. (2009) test their GPS + sonar skid-steer truck on "semi-rugged terrain such a
football field" (description of the truck) and let it avoid obstacles met between GPS waypoints
(their obstacle-avoidance tests; the text numbers no sections).

* :func:`scatter_obstacles` draws such a layout in the plane: circles (posts, bins, trunks) and
  rotated boxes (bales, crates), kept ``min_gap`` apart. It is the one obstacle generator of the
  course: :func:`open_field` uses it here and :func:`robokit.outdoor.random_course` (lesson 05's
  2D field) uses it with the legs between its waypoints.
* :func:`field_world` turns any 2D layout into a :class:`~robokit.sim.world.World`; lesson 05's
  ``Field.world()`` calls it, so the truck's 2D field and the 3D world have the same obstacles.
* :func:`open_field` is the seeded builder, like :func:`~robokit.sim.worlds.lab_room`.

The world: grass over the field and a run-off ``border``; circles as upright regular prisms
(``SIDES`` faces, corners on the circle: tree trunks for radii >= 0.45 m, else painted posts);
boxes as hay bales or crates, and any box with a side of at least 2.5 m as a shed with a door; a
2.5 m hedge all round (so the footprint is closed, free space is defined and a camera always sees
something); and a skybox far outside the hedge (a sky band, a sky ceiling and far grass), not
solid, so the LiDAR ignores it while every camera pixel gets a colour and a finite depth.
Frame: x east, y north, metres, origin at the field's south-west corner (as in lesson 05).

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] J. Feder, "Random sequential adsorption", *Journal of Theoretical Biology* 87(2), 1980,
   pp. 237-254.
.. [3] N. Greene, "Environment mapping and other applications of world projections", *IEEE
   Computer Graphics and Applications* 6(11), 1986, pp. 21-29.
"""
from __future__ import annotations

import functools
from typing import Any, Sequence

import numpy as np

from ..validation import as_array, as_rng, as_int, as_positive
from . import textures as tx
from . import textures_outdoor as tox
from .build import Builder
from .layout import obstacle_array
from .world import World

__all__ = ["scatter_obstacles", "field_world", "open_field", "SIDES"]

#: Faces of the prism that stands for a circular obstacle (its corners lie on the circle, so the
#: 3D footprint is inside the 2D circle by at most ``r (1 - cos(pi / SIDES))``, 2.7 cm at r = 0.8 m).
SIDES = 12
HEDGE_HEIGHT = 2.5
SHED_SIDE = 2.5     # a box with a side at least this long is a shed
SKY_DISTANCE = 100.0  # skybox walls this far outside the hedge
SKY_HEIGHT = 60.0     # skybox ceiling; the world's height (cameras must be below it)


def _size(size: Any) -> tuple[float, float]:
    s = as_array(size, "size", shape=(2,))
    return as_positive(s[0], "size[0]"), as_positive(s[1], "size[1]")


def scatter_obstacles(rng: Any, n_obstacles: int, size: Any = (100.0, 60.0), *, waypoints: Any = None,
                      on_path: float = 0.5, keep_clear: Sequence = (), min_gap: float = 2.5,
                      boxes: Any = None, tries: int = 5000) -> tuple[np.ndarray, np.ndarray]:
    """Scatter circular and box obstacles over a field, some on the legs between waypoints.

    Parameters
    ----------
    rng : numpy.random.Generator or int
        Randomness (consumed in a fixed order, so a seed gives one layout).
    n_obstacles : int
        Obstacles to add: about half circles (radius 0.25-0.8 m), half boxes (0.5-2.0 m x 0.5-1.2 m).
    size : (float, float), default (100, 60)
        Field width (east) and height (north) in metres; centres stay 2 m inside it.
    waypoints : array_like, shape (K + 1, 2), optional
        A fraction ``on_path`` of the obstacles is centred on the legs between consecutive
        waypoints (25-75 % along the leg, 0.4 m sideways scatter).
    on_path : float, default 0.5
        See ``waypoints``; ignored without waypoints.
    keep_clear : sequence of (point (2,), radius)
        Discs no obstacle may reach into (start, waypoints, a camera spot).
    min_gap : float, default 2.5
        Free space kept between obstacles' bounding circles.
    boxes : array_like, shape (M, 5), optional
        Boxes ``[cx, cy, length, width, yaw]`` already placed (e.g. a shed): kept first in the
        output and respected by the gap test.
    tries : int, default 5000
        Candidate draws before giving up.

    Returns
    -------
    circles : numpy.ndarray, shape (N, 3)
        ``[x, y, radius]``.
    boxes : numpy.ndarray, shape (M, 5)
        ``[cx, cy, length, width, yaw]``, pre-placed boxes first.
        Fewer than ``n_obstacles`` new obstacles come back when ``tries`` run out; callers decide
        whether that is an error (:func:`open_field` raises).

    Raises
    ------
    ValueError, TypeError
        For bad sizes, counts, gaps or array shapes.

    Notes
    -----
    Rejection sampling of non-overlapping discs (random sequential adsorption, Feder 1980) around
    the experiment of Hamid et al. (2009, the obstacle-avoidance tests): obstacles lie on the way between waypoints so
    the truck must avoid them.

    Examples
    --------
    >>> circles, boxes = scatter_obstacles(0, 4, (30.0, 20.0))
    >>> circles.shape, boxes.shape
    ((3, 3), (1, 5))
    """
    rng = as_rng(rng, "rng")
    n = as_int(n_obstacles, "n_obstacles", minimum=0)
    w, h = _size(size)
    frac = as_positive(on_path, "on_path", allow_zero=True)
    gap = as_positive(min_gap, "min_gap")
    tries = as_int(tries, "tries", minimum=1)
    pts = np.zeros((0, 2)) if waypoints is None else as_array(waypoints, "waypoints", shape=(None, 2))
    k = len(pts) - 1
    clear = [(as_array(p, "keep_clear point", shape=(2,)), as_positive(r, "keep_clear radius", allow_zero=True))
             for p, r in keep_clear]
    pre = obstacle_array(boxes, "boxes")
    shapes: list[tuple[str, np.ndarray, float]] = [("box", q, float(np.hypot(q[2], q[3]) / 2)) for q in pre]
    added = 0
    while added < n and tries > 0:
        tries -= 1
        if rng.random() < frac and k > 0:
            leg = int(rng.integers(k))
            a, b = pts[leg], pts[leg + 1]
            centre = a + rng.uniform(0.25, 0.75) * (b - a) + rng.normal(0, 0.4, 2)
        else:
            centre = rng.uniform([2, 2], [w - 2, h - 2])
        if rng.random() < 0.5:
            params = np.array([*centre, rng.uniform(0.25, 0.8)])
            kind, radius = "circle", params[2]
        else:
            params = np.array([*centre, rng.uniform(0.5, 2.0), rng.uniform(0.5, 1.2), rng.uniform(0, np.pi)])
            kind, radius = "box", float(np.hypot(params[2], params[3]) / 2)
        if any(np.hypot(*(centre - p)) < radius + r for p, r in clear):
            continue
        if any(np.hypot(*(centre - q[:2])) < radius + rq + gap for _, q, rq in shapes):
            continue
        shapes.append((kind, params, radius))
        added += 1
    circles = np.array([p for kind, p, _ in shapes if kind == "circle"]).reshape(-1, 3)
    out_boxes = np.array([p for kind, p, _ in shapes if kind == "box"]).reshape(-1, 5)
    return circles, out_boxes


def _inside_hedge(arr: np.ndarray, reach: np.ndarray, name: str, lo: float, hi: tuple) -> None:
    """Raise unless every obstacle (centre +- reach) stays strictly inside the hedge."""
    bad = (arr[:, 0] - reach <= lo) | (arr[:, 1] - reach <= lo) | (arr[:, 0] + reach >= hi[0]) \
        | (arr[:, 1] + reach >= hi[1])
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}: expected obstacles inside the hedge [{lo:g}, {hi[0]:g}] x [{lo:g}, {hi[1]:g}] m, "
                         f"got one at ({arr[i, 0]:.2f}, {arr[i, 1]:.2f}) reaching {reach[i]:.2f} m")


def _free_point(w: float, h: float, circles: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """A field point far from every obstacle's bounding circle, preferring the centre."""
    centres = np.vstack([circles[:, :2], boxes[:, :2]])
    radii = np.concatenate([circles[:, 2], np.hypot(boxes[:, 2], boxes[:, 3]) / 2])
    gx, gy = np.meshgrid(np.linspace(0, w, 41), np.linspace(0, h, 25))
    p = np.column_stack([gx.ravel(), gy.ravel()])
    if not len(centres):
        return np.array([w / 2, h / 2])
    clear = (np.linalg.norm(p[:, None] - centres[None], axis=2) - radii).min(axis=1)
    score = np.minimum(clear, 2.0) - 1e-3 * np.linalg.norm(p - [w / 2, h / 2], axis=1)
    return p[int(np.argmax(score))]


def field_world(size: Any = (100.0, 60.0), circles: Any = None, boxes: Any = None, *, seed: int = 0,
                border: float = 3.0, interior: Any = None, name: str = "field") -> World:
    """Build the textured 3D world of a field with the given 2D obstacles (see the module notes).

    Parameters
    ----------
    size : (float, float), default (100, 60)
        Field width (east) and height (north) in metres; the field is ``[0, w] x [0, h]``.
    circles : array_like, shape (N, 3), optional
        ``[x, y, radius]`` per round obstacle (trunk if radius >= 0.45 m, else post).
    boxes : array_like, shape (M, 5), optional
        ``[cx, cy, length, width, yaw]`` per box (shed if a side >= 2.5 m, else bale or crate).
    seed : int, default 0
        Seeds the textures, obstacle heights and the bale/crate choice.
    border : float, default 3.0
        Run-off between the field's edge and the hedge (metres).
    interior : array_like, shape (2,), optional
        A free point; by default the field point farthest from obstacles (the centre if clear).
    name : str, default "field"

    Returns
    -------
    World
        Height (skybox ceiling) 60 m, free-space cells of 5 cm; ``info`` holds ``size``,
        ``border``, ``seed``, ``circles``, ``boxes``, ``hedge`` ``(x0, y0, x1, y1)`` and
        ``obstacles`` (one ``(surface name prefix, kind, height)`` per circle then per box).

    Raises
    ------
    ValueError, TypeError
        For non-positive sizes, NaN, badly shaped obstacle arrays, obstacles reaching the hedge or
        a field with no free point.

    Notes
    -----
    Test site of Hamid et al. (2009, description of the truck: a football field); world representation of
    the course (DESIGN.md, "Simulation"); skybox after Greene (1986).

    Examples
    --------
    >>> world = field_world((20.0, 12.0), circles=[[5.0, 5.0, 0.5]], boxes=[[12.0, 6.0, 2.0, 1.0, 0.3]])
    >>> world.info["hedge"], [kind for _, kind, _ in world.info["obstacles"]]
    ((-3.0, -3.0, 23.0, 15.0), ['tree', 'crate'])
    """
    w, h = _size(size)
    bd = as_positive(border, "border")
    rng = np.random.default_rng(as_int(seed, "seed", minimum=0))
    x0, y0, x1, y1 = -bd, -bd, w + bd, h + bd
    circles, boxes = obstacle_array(circles, "circles"), obstacle_array(boxes, "boxes")
    _inside_hedge(circles, circles[:, 2], "circles", -bd, (x1, y1))
    _inside_hedge(boxes, np.hypot(boxes[:, 2], boxes[:, 3]) / 2, "boxes", -bd, (x1, y1))
    b = Builder(rng, density=100)
    b.horizontal("ground", x0, y0, x1, y1, 0.0, True, tox.grass, density=40, tile=6.0)
    corners = [(x0, y0), (x0, y1), (x1, y1), (x1, y0)]  # clockwise: the hedge faces inwards
    for k in range(4):
        b.wall(f"hedge/{k}", corners[k], corners[(k + 1) % 4], 0.0, HEDGE_HEIGHT, tox.hedge, density=60)
    obstacles = []
    ang = 2 * np.pi * np.arange(SIDES) / SIDES
    for i, (cx, cy, r) in enumerate(circles):
        tree = r >= 0.45
        kind, height = ("tree", rng.uniform(3.0, 4.5)) if tree else ("post", rng.uniform(1.0, 1.6))
        paint = tox.PAINTS[int(rng.integers(len(tox.PAINTS)))]
        fn = tox.bark if tree else (lambda w_, h_, r_, c=paint: tox.painted_post(w_, h_, r_, paint=c))
        poly = np.column_stack([cx + r * np.cos(ang), cy + r * np.sin(ang)])
        lid = poly[::SIDES // 4]  # the square on four of the corners
        b.prism(f"{kind}/{i}", poly, height, fn, lid=lid)
        obstacles.append((f"{kind}/{i}", kind, float(height)))
    for i, (cx, cy, length, width, yaw) in enumerate(boxes):
        if max(length, width) >= SHED_SIDE:  # one stain for all its planks
            stain = tox.STAINS[int(rng.integers(len(tox.STAINS)))]
            kind, height, fn = "shed", 2.6, lambda w_, h_, r_, c=stain: tox.planks(w_, h_, r_, stain=c)
        elif rng.random() < 0.5:
            kind, height, fn = "bale", rng.uniform(0.9, 1.2), tox.straw
        else:
            kind, height, fn = "crate", rng.uniform(0.6, 1.0), tx.wood
        b.box(f"{kind}/{i}", (cx, cy), (length, width, height), yaw, fn)
        if kind == "shed":  # a door on the side facing -y in the shed's frame
            t, c = np.array([np.cos(yaw), np.sin(yaw)]), np.array([cx, cy])
            n_out = np.array([np.sin(yaw), -np.cos(yaw)]) * width / 2
            b.decal(f"shed/{i}/door", c + n_out - 0.45 * t, c + n_out + 0.45 * t, 2.0, 2.0, tx.door)
        obstacles.append((f"{kind}/{i}", kind, float(height)))
    span = x1 - x0
    for k in range(3):  # signs on the north hedge, facing south, apart from each other
        s = (0.1 + 0.3 * k + rng.uniform(0, 0.1)) * span
        b.decal(f"sign/{k}", (x0 + s, y1), (x0 + s + min(2.0, 0.1 * span), y1), 2.2, 1.2, tx.poster)
    _skybox(b, x0 - SKY_DISTANCE, y0 - SKY_DISTANCE, x1 + SKY_DISTANCE, y1 + SKY_DISTANCE, (x0, y0, x1, y1))
    point = _free_point(w, h, circles, boxes) if interior is None else interior
    info = {"size": (w, h), "border": bd, "seed": seed, "circles": circles, "boxes": boxes,
            "hedge": (x0, y0, x1, y1), "obstacles": obstacles}
    return b.world(name, point, SKY_HEIGHT, info=info, free_resolution=0.05)


def _skybox(b: Builder, X0: float, Y0: float, X1: float, Y1: float, hedge: tuple) -> None:
    """Far, non-solid backdrop: grass out to a sky band all round, and a sky ceiling."""
    x0, y0, x1, y1 = hedge
    coarse = {"density": 2.0, "tile": 400.0}  # one tile per side: no seams in the sky
    for k, (a0, b0, a1, b1) in enumerate([(X0, Y0, x0, Y1), (x1, Y0, X1, Y1), (x0, Y0, x1, y0), (x0, y1, x1, Y1)]):
        b.horizontal(f"backdrop/ground/{k}", a0, b0, a1, b1, 0.0, True, tox.grass, **coarse)
    corners = [(X0, Y0), (X0, Y1), (X1, Y1), (X1, Y0)]
    for k in range(4):
        b.wall(f"backdrop/sky/{k}", corners[k], corners[(k + 1) % 4], 0.0, SKY_HEIGHT, tox.sky, solid=False,
               **coarse)
    b.horizontal("backdrop/zenith", X0, Y0, X1, Y1, SKY_HEIGHT, False,
                 lambda w_, h_, r: tox.sky(w_, h_, r, top=1.0, bottom=1.0), density=1.0, tile=400.0)


def open_field(seed: int = 0, *, size: Any = (100.0, 60.0), n_obstacles: int = 14, shed: bool = True,
               border: float = 3.0) -> World:
    """Hamid et al.'s outdoor field: about 100 m x 60 m of grass with obstacles, a shed and a hedge.

    Parameters
    ----------
    seed : int, default 0
        Seeds the layout and the textures.
    size : (float, float), default (100, 60)
        Field width and height in metres (at least 12 m x 10 m with a shed, 6 m x 6 m without).
    n_obstacles : int, default 14
        Scattered obstacles (posts, trunks, bales, crates) as in lesson 05's courses, kept 2.5 m
        apart and 3 m clear of the field's centre (:attr:`World.interior`, a camera spot).
    shed : bool, default True
        Add a 4 m x 3 m shed near a seeded corner.
    border : float, default 3.0
        Run-off between the field's edge and the hedge (metres).

    Returns
    -------
    World
        Built by :func:`field_world`; ``world.info["circles"]`` and ``["boxes"]`` are the 2D layout
        (``robokit.outdoor.Field(size, circles, boxes)`` is the same field for lesson 05's sonars).

    Raises
    ------
    ValueError, TypeError
        For non-positive or NaN sizes, a negative seed or count, or more obstacles than fit
        (names ``n_obstacles``, the expected bound and what came).

    Notes
    -----
    Hamid et al. (2009, description of the truck): it runs on "semi-rugged terrain such a football
    field"; obstacles as in their obstacle-avoidance tests. Worlds are cached per parameter set.

    Examples
    --------
    >>> field = open_field(seed=0, size=(20.0, 12.0), n_obstacles=2)
    >>> field
    World('open_field', 99 surfaces, 68 wall segments, 26.00 m x 18.00 m)
    >>> [kind for _, kind, _ in field.info["obstacles"]], field.info["circles"].shape
    (['tree', 'shed', 'bale'], (1, 3))
    """
    w, h = _size(size)
    if not isinstance(shed, (bool, np.bool_)):
        raise TypeError(f"shed: expected True or False, got {shed!r}")
    if w < (12.0 if shed else 6.0) or h < (10.0 if shed else 6.0):
        raise ValueError(f"size: expected at least {'12 m x 10 m with a shed' if shed else '6 m x 6 m'}, "
                         f"got {w:g} m x {h:g} m")
    return _cached_field(as_int(seed, "seed", minimum=0), w, h, as_int(n_obstacles, "n_obstacles", minimum=0),
                         bool(shed), as_positive(border, "border"))


def build_open_field(seed: int, w: float, h: float, n: int, shed: bool, border: float) -> World:
    """Unchecked, uncached :func:`open_field` (its arguments as that function checks them)."""
    rng = np.random.default_rng(seed)
    centre = np.array([w / 2, h / 2])
    sheds = np.zeros((0, 5))
    if shed:
        sx = 5.0 if rng.random() < 0.5 else w - 5.0
        sy = 4.0 if rng.random() < 0.5 else h - 4.0
        sheds = np.array([[sx, sy, 4.0, 3.0, np.pi if sy < h / 2 else 0.0]])  # door towards the field
    circles, boxes = scatter_obstacles(rng, n, (w, h), keep_clear=[(centre, 3.0)], boxes=sheds)
    placed = len(circles) + len(boxes) - len(sheds)
    if placed < n:
        raise ValueError(f"n_obstacles: expected at most what fits in a {w:g} m x {h:g} m field with 2.5 m gaps, "
                         f"got {n} (only {placed} placed)")
    return field_world((w, h), circles, boxes, seed=seed, border=border, interior=centre, name="open_field")


_cached_field = functools.lru_cache(maxsize=4)(build_open_field)
