"""Building blocks for world builders: walls, floors, boxes and things hung on walls.

A :class:`Builder` collects :class:`~robokit.sim.world.Surface` objects. Long walls, floors and
ceilings are cut into tiles of at most ``tile`` metres, each with its own seeded texture, so that
no texture gets huge and no two stretches of wall look exactly alike.

References
----------
.. [1] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering*, 2023,
   doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..validation import as_array, as_rng, as_positive
from . import textures as tx
from .world import Surface, World

__all__ = ["Builder", "wall_with_doors", "random_decoration"]

TextureFn = Callable[[int, int, np.random.Generator], np.ndarray]

#: Offset (metres) of decorations in front of their wall, so depth tests never tie.
DECAL_OFFSET = 0.005


class Builder:
    """Accumulate textured surfaces for a world.

    Parameters
    ----------
    rng : numpy.random.Generator or int
        Seeds every texture.
    density : float, default 120
        Texture resolution of walls, floors and ceilings in pixels per metre (decorations use
        twice that).
    tile : float, default 2.0
        Longest side of a wall/floor tile in metres.

    Notes
    -----
    Course design (DESIGN.md, "Simulation"), no paper.
    """

    def __init__(self, rng: Any = None, density: float = 120.0, tile: float = 2.0) -> None:
        self.rng = as_rng(rng)
        self.density = as_positive(density, "density")
        self.tile = as_positive(tile, "tile")
        self.surfaces: list[Surface] = []

    def _pixels(self, length: float, density: float) -> int:
        return max(8, int(round(length * density)))

    def _add(self, name: str, corner, u, v, texture_fn: TextureFn, density: float, solid: bool) -> Surface:
        w = self._pixels(np.linalg.norm(u), density)
        h = self._pixels(np.linalg.norm(v), density)
        s = Surface(name, corner, u, v, texture_fn(w, h, self.rng), solid)
        self.surfaces.append(s)
        return s

    def wall(self, name: str, a: Any, b: Any, z0: float = 0.0, z1: float = 2.8,
             texture_fn: TextureFn = tx.plaster, solid: bool = True, *, density: float | None = None,
             tile: float | None = None) -> None:
        """Add a vertical wall from floor point ``a`` to ``b`` spanning heights ``z0..z1``, tiled.

        The texture reads correctly from the side to the right of the direction ``a -> b`` (walk
        a room clockwise to face its walls inwards). ``density`` and ``tile`` override the
        builder's (e.g. coarse, large tiles for a far skybox).
        """
        a = as_array(a, "a", shape=(2,))
        b = as_array(b, "b", shape=(2,))
        length = float(np.linalg.norm(b - a))
        if length <= 0 or z1 <= z0:
            raise ValueError(f"a, b, z0, z1: expected a wall of positive size, got {length} m x {z1 - z0} m")
        n = int(np.ceil(length / (tile or self.tile) - 1e-9))
        step = (b - a) / n
        for i in range(n):
            p = a + i * step
            self._add(f"{name}/{i}", [p[0], p[1], z1], [step[0], step[1], 0.0], [0.0, 0.0, z0 - z1],
                      texture_fn, density or self.density, solid)

    def horizontal(self, name: str, x0: float, y0: float, x1: float, y1: float, z: float, up: bool,
                   texture_fn: TextureFn, solid: bool = False, *, density: float | None = None,
                   tile: float | None = None) -> None:
        """Add a horizontal rectangle (floor if ``up`` else ceiling) over ``[x0, x1] x [y0, y1]``, tiled.

        The texture reads correctly from above (``up``) or from below (ceiling); ``density`` and
        ``tile`` override the builder's.
        """
        nx = int(np.ceil((x1 - x0) / (tile or self.tile) - 1e-9))
        ny = int(np.ceil((y1 - y0) / (tile or self.tile) - 1e-9))
        dx, dy = (x1 - x0) / nx, (y1 - y0) / ny
        for i in range(nx):
            for j in range(ny):
                if up:  # front normal v x u = +z
                    corner, u, v = [x0 + i * dx, y0 + (j + 1) * dy, z], [dx, 0, 0], [0, -dy, 0]
                else:
                    corner, u, v = [x0 + i * dx, y0 + j * dy, z], [dx, 0, 0], [0, dy, 0]
                self._add(f"{name}/{i}-{j}", corner, u, v, texture_fn, density or self.density, solid)

    def box(self, name: str, centre: Any, size: Any, yaw: float = 0.0,
            texture_fn: TextureFn = tx.wood) -> None:
        """Add a furniture-like box standing on the floor: four outward-facing sides and a top.

        Parameters
        ----------
        centre : (x, y) of the footprint centre; size : (length, width, height); yaw : heading.
        """
        c = as_array(centre, "centre", shape=(2,))
        L, W, H = as_array(size, "size", shape=(3,))
        if min(L, W, H) <= 0:
            raise ValueError(f"size: expected three positive extents, got {[L, W, H]}")
        R = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]])
        quad = (np.array([[-L, -W], [L, -W], [L, W], [-L, W]]) / 2) @ R.T + c  # counter-clockwise
        self.prism(name, quad, H, texture_fn, lid=quad)

    def prism(self, name: str, polygon: Any, height: float, texture_fn: TextureFn = tx.wood,
              lid: Any = None) -> None:
        """Add an upright prism standing on the floor: outward-facing sides ``{name}/side{k}`` and a lid.

        Parameters
        ----------
        polygon : array_like, shape (N, 2)
            Footprint corners in counter-clockwise order (N >= 3).
        height : float
            Height of the sides (metres).
        lid : array_like, shape (4, 2), optional
            A counter-clockwise rectangle laid on top as ``{name}/top`` (surfaces are rectangles,
            so a box's lid is its footprint and a round post's lid is a square inside it).

        Notes
        -----
        Walking a counter-clockwise polygon, the right side of each edge is the outside
        (O'Rourke, *Computational Geometry in C*, 2nd ed., Sec. 1.3).
        """
        poly = as_array(polygon, "polygon", shape=(None, 2))
        if len(poly) < 3:
            raise ValueError(f"polygon: expected at least 3 corners, got {len(poly)}")
        h = as_positive(height, "height")
        for k in range(len(poly)):
            self.wall(f"{name}/side{k}", poly[k], poly[(k + 1) % len(poly)], 0.0, h, texture_fn)
        if lid is not None:
            q = as_array(lid, "lid", shape=(4, 2))
            d, e = q[1] - q[0], q[0] - q[3]  # seen from above: u along the first edge, v back along the last
            self._add(f"{name}/top", [q[3][0], q[3][1], h], [d[0], d[1], 0], [e[0], e[1], 0],
                      texture_fn, self.density, True)

    def decal(self, name: str, a: Any, b: Any, z_top: float, height: float, texture_fn: TextureFn,
              solid: bool = False) -> None:
        """Hang a flat decoration (poster, plate, board) on the wall from ``a`` to ``b``.

        ``a``, ``b`` are floor points on the wall line, ordered as the wall (the decoration faces
        the wall's visible side, offset by :data:`DECAL_OFFSET`).
        """
        a = as_array(a, "a", shape=(2,))
        b = as_array(b, "b", shape=(2,))
        t = (b - a) / np.linalg.norm(b - a)
        n = np.array([t[1], -t[0]]) * DECAL_OFFSET  # right of a -> b, the wall's visible side
        p = a + n
        d = b - a
        self._add(name, [p[0], p[1], z_top], [d[0], d[1], 0], [0, 0, -height], texture_fn, 2 * self.density, solid)

    def world(self, name: str, interior: Any, height: float, info: dict | None = None, **kwargs: Any) -> World:
        """Return the :class:`World` made of the collected surfaces (see :class:`World` for the arguments)."""
        return World(self.surfaces, name, interior, height, info=info, **kwargs)


def random_decoration(rng: np.random.Generator) -> TextureFn:
    """Pick a poster (with a photo) or a notice board at random."""
    if rng.random() < 0.6:
        return tx.poster
    return tx.notice_board


def _door_leaf(w: int, h: int, rng: np.random.Generator) -> np.ndarray:
    return tx.door(w, h, rng)


def wall_with_doors(builder: Builder, name: str, a: Any, b: Any, doors: list, *, height: float,
                    depth: float = 0.0, door_height: float = 2.1, leaf: bool = True,
                    texture_fn: TextureFn = tx.plaster) -> None:
    """Add a wall from ``a`` to ``b`` with door openings, recessed ``depth`` metres away from the room.

    Parameters
    ----------
    builder : Builder
    name : str
    a, b : array_like, shape (2,)
        Wall end points, ordered so that the room is on the right of ``a -> b``.
    doors : list of (float, float)
        Openings as distances ``(s0, s1)`` from ``a`` along the wall.
    height : float
        Wall height (ceiling).
    depth : float, default 0
        Recess depth of the door frame (Ge et al. 2023, Sec. 4.1: 0.07 m); 0 for a plain opening.
    door_height : float, default 2.1
        Height of the opening (a lintel fills the wall above it).
    leaf : bool, default True
        Close the opening with a door leaf at the back of the recess (else a walk-through doorway).

    Notes
    -----
    Door-frame recess geometry of Ge et al. (2023), Fig. 3a and Eqs. (1)-(3).
    """
    a = as_array(a, "a", shape=(2,))
    b = as_array(b, "b", shape=(2,))
    length = float(np.linalg.norm(b - a))
    t = (b - a) / length
    away = np.array([-t[1], t[0]])  # left of a -> b: away from the room
    pos = 0.0
    for k, (s0, s1) in enumerate(sorted(doors)):
        if not (pos <= s0 < s1 <= length):
            raise ValueError(f"doors: expected non-overlapping openings within the wall's {length:.2f} m, got {doors}")
        if s0 > pos:
            builder.wall(f"{name}/seg{k}", a + pos * t, a + s0 * t, 0.0, height, texture_fn)
        p0, p1 = a + s0 * t, a + s1 * t
        q0, q1 = p0 + depth * away, p1 + depth * away
        if depth > 0:
            builder.wall(f"{name}/door{k}/jamb0", p0, q0, 0.0, door_height, texture_fn)
            builder.wall(f"{name}/door{k}/jamb1", q1, p1, 0.0, door_height, texture_fn)
            lo, hi = np.minimum(p0, q1), np.maximum(p0, q1)
            builder.horizontal(f"{name}/door{k}/soffit", lo[0], lo[1], hi[0], hi[1], door_height, False,
                               texture_fn)
        if leaf:
            builder.wall(f"{name}/door{k}/leaf", q0, q1, 0.0, door_height, _door_leaf)
        builder.wall(f"{name}/door{k}/lintel", p0, p1, door_height, height, texture_fn)
        pos = s1
    if pos < length:
        builder.wall(f"{name}/seg{len(doors)}", a + pos * t, b, 0.0, height, texture_fn)
