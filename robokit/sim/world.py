"""A simulated world: textured planar rectangles plus the 2D footprint the LiDAR sees.

A :class:`Surface` is a rectangle in 3D with a texture glued to it: the texture's top-left pixel
corner sits at ``corner``, its columns run along ``u`` and its rows along ``v`` (so ``u`` and ``v``
are the rectangle's edge vectors, in metres). A :class:`World` holds the surfaces, the name of the
place and a point known to be inside it. The footprint (wall segments) is the slice of the solid,
vertical surfaces by a horizontal plane, so what the LiDAR measures and what the cameras see come
from the same geometry and cannot disagree.

World frame: right-handed, z up, the floor at z = 0 (see :mod:`robokit.geometry`).

References
----------
.. [1] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering*, 2023,
   doi:10.1631/FITEE.2200208.
.. [2] P. F. Felzenszwalb and D. P. Huttenlocher, "Distance transforms of sampled functions",
   *Theory of Computing* 8, 2012, pp. 415-428.
"""
from __future__ import annotations

import dataclasses
import functools
from typing import Any, Sequence

import cv2
import numpy as np

from ..validation import as_array, as_points, as_finite_scalar, as_positive
from .layout import Layout

__all__ = ["Surface", "World", "FreeSpace"]


@dataclasses.dataclass(frozen=True, eq=False)
class Surface:
    """A textured rectangle ``corner + a u + b v`` with ``a, b`` in [0, 1].

    Attributes
    ----------
    name : str
        Label, e.g. ``"wall/north/3"`` or ``"poster/2"``.
    corner : numpy.ndarray, shape (3,)
        World position of the texture's top-left corner (metres).
    u, v : numpy.ndarray, shape (3,)
        Edge vectors along the texture's columns and rows (metres); must be orthogonal.
    texture : numpy.ndarray, shape (H, W, 3), uint8
        RGB image.
    solid : bool
        Whether the surface blocks the LiDAR (walls, furniture) or is decoration (posters).
    """

    name: str
    corner: np.ndarray
    u: np.ndarray
    v: np.ndarray
    texture: np.ndarray
    solid: bool = True

    def __post_init__(self) -> None:
        for field in ("corner", "u", "v"):
            object.__setattr__(self, field, as_array(getattr(self, field), field, shape=(3,)))
        lu, lv = np.linalg.norm(self.u), np.linalg.norm(self.v)
        if lu <= 0 or lv <= 0:
            raise ValueError(f"u, v: expected non-zero edge vectors, got |u| = {lu}, |v| = {lv}")
        if abs(self.u @ self.v) > 1e-9 * lu * lv:
            raise ValueError(f"u, v: expected orthogonal edges of a rectangle, got u.v = {self.u @ self.v}")
        tex = np.ascontiguousarray(self.texture)
        if tex.dtype != np.uint8 or tex.ndim != 3 or tex.shape[2] != 3 or min(tex.shape[:2]) < 2:
            raise TypeError(f"texture: expected a uint8 RGB image (H, W, 3), got {tex.dtype} {tex.shape}")
        object.__setattr__(self, "texture", tex)

    @property
    def normal(self) -> np.ndarray:
        """Unit normal of the front side, ``v x u / |v x u|`` (the side the texture reads correctly from)."""
        n = np.cross(self.v, self.u)
        return n / np.linalg.norm(n)

    @property
    def corners(self) -> np.ndarray:
        """The four corners ``(4, 3)`` in order corner, +u, +u+v, +v."""
        c = self.corner
        return np.array([c, c + self.u, c + self.u + self.v, c + self.v])

    def point(self, a: Any, b: Any) -> np.ndarray:
        """World point at fractional texture coordinates ``(a, b)`` (0..1 along u and v)."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        return self.corner + a[..., None] * self.u + b[..., None] * self.v

    @functools.cached_property
    def pyramid(self) -> list[np.ndarray]:
        """Texture mip-map levels (Gaussian pyramid), used against aliasing when far away."""
        levels = [self.texture]
        while min(levels[-1].shape[:2]) >= _MIP_MIN:
            levels.append(cv2.pyrDown(levels[-1]))
        return levels


#: A texture is halved into another mip-map level while both its sides are at least this long.
_MIP_MIN = 8


def _mip_sizes(width: int, height: int) -> list[tuple[int, int]]:
    """(width, height) of each :attr:`Surface.pyramid` level, without building it (``cv2.pyrDown``
    halves a side of n pixels to ``(n + 1) // 2``)."""
    sizes = [(width, height)]
    while min(sizes[-1]) >= _MIP_MIN:
        sizes.append(((sizes[-1][0] + 1) // 2, (sizes[-1][1] + 1) // 2))
    return sizes


@dataclasses.dataclass(frozen=True)
class FreeSpace:
    """Boolean grid of the free (reachable) floor area of a world.

    Attributes
    ----------
    free : numpy.ndarray of bool, shape (rows, cols)
        ``free[i, j]`` is the cell whose centre is ``origin + (j + 0.5, i + 0.5) * resolution``.
    origin : numpy.ndarray, shape (2,)
        World (x, y) of the grid's lower-left corner.
    resolution : float
        Cell size in metres.
    clearance : numpy.ndarray of float
        Distance (metres) from each free cell to the nearest wall (distance transform).
    """

    free: np.ndarray
    origin: np.ndarray
    resolution: float
    clearance: np.ndarray

    def cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Row and column indices of points ``xy`` (N, 2) and whether they fall inside the grid."""
        ij = np.floor((xy - self.origin) / self.resolution).astype(int)
        inside = (ij[:, 0] >= 0) & (ij[:, 1] >= 0) & (ij[:, 0] < self.free.shape[1]) & (ij[:, 1] < self.free.shape[0])
        return np.clip(ij[:, 1], 0, self.free.shape[0] - 1), np.clip(ij[:, 0], 0, self.free.shape[1] - 1), inside


class World:
    """Textured planar surfaces plus the footprint, with a known interior point.

    Parameters
    ----------
    surfaces : sequence of Surface
        At least one solid surface.
    name : str
        Name of the place (e.g. ``"lab_room"``).
    interior : array_like, shape (2,)
        A floor point (x, y) inside the free space; the free space is the region connected to it.
    height : float
        Ceiling height in metres (cameras must be below it).
    footprint_height : float, default 0.25
        Height of the horizontal slice that defines :attr:`segments` (a LiDAR's scan plane).
    info : dict, optional
        Builder facts (dimensions, door positions, seed), for lessons and tests.
    free_resolution : float, default 0.02
        Cell size (metres) of the free-space grid behind :meth:`is_free` and
        :meth:`as_viewpoint`; large outdoor worlds use coarser cells to keep the grid small.

    Raises
    ------
    ValueError
        If the world is empty, has no walls at ``footprint_height`` or the interior point is not free.

    Notes
    -----
    The representation (textured planes + 2D footprint) is the course's design (DESIGN.md,
    "Simulation"); the footprint is what a 2D laser scanner sees (Ge et al. 2023, Sec. 3.1).
    """

    def __init__(self, surfaces: Sequence[Surface], name: str, interior: Any, height: float,
                 footprint_height: float = 0.25, info: dict | None = None, free_resolution: float = 0.02) -> None:
        surfaces = list(surfaces)
        if not surfaces or not all(isinstance(s, Surface) for s in surfaces):
            raise ValueError(f"surfaces: expected a non-empty list of Surface, got {len(surfaces)} items")
        self.surfaces = surfaces
        self.name = str(name)
        self.height = as_positive(height, "height")
        self.footprint_height = as_positive(footprint_height, "footprint_height")
        self.interior = as_array(interior, "interior", shape=(2,))
        self.info = dict(info or {})
        self.free_resolution = as_positive(free_resolution, "free_resolution")
        self.segments = self.slice(self.footprint_height)
        if len(self.segments) == 0:
            raise ValueError(f"surfaces: expected walls crossing footprint_height={self.footprint_height} m, got none")
        lo = self.segments.reshape(-1, 2).min(axis=0)
        hi = self.segments.reshape(-1, 2).max(axis=0)
        self.bounds = np.array([lo[0], lo[1], hi[0], hi[1]])
        if not self.is_free(self.interior, clearance=0.0)[0]:
            raise ValueError(f"interior: expected a free point inside the walls, got {self.interior.tolist()}")

    def __repr__(self) -> str:
        x0, y0, x1, y1 = self.bounds
        return (f"World({self.name!r}, {len(self.surfaces)} surfaces, {len(self.segments)} wall segments, "
                f"{x1 - x0:.2f} m x {y1 - y0:.2f} m)")

    @functools.cached_property
    def corner_array(self) -> np.ndarray:
        """All surface corners, shape ``(N, 4, 3)`` (used by the renderer's culling)."""
        return np.stack([s.corners for s in self.surfaces])

    @functools.cached_property
    def surface_arrays(self) -> dict[str, np.ndarray]:
        """The surfaces as arrays, for the renderer to treat every surface of a frame at once.

        Keys: ``u``, ``v``, ``normal`` (N, 3) (as :attr:`Surface.u`, :attr:`Surface.v`,
        :attr:`Surface.normal`), ``u_length`` (N,) metres, and ``mip_sizes`` (N, L, 2): width and
        height of each :attr:`Surface.pyramid` level (``mip_levels`` (N,) of them; the last repeats
        beyond).
        """
        levels = [_mip_sizes(s.texture.shape[1], s.texture.shape[0]) for s in self.surfaces]
        depth = max(len(sizes) for sizes in levels)
        return {"u": np.stack([s.u for s in self.surfaces]), "v": np.stack([s.v for s in self.surfaces]),
                "normal": np.stack([s.normal for s in self.surfaces]),
                "u_length": np.array([np.linalg.norm(s.u) for s in self.surfaces]),
                "mip_levels": np.array([len(sizes) for sizes in levels]),
                "mip_sizes": np.array([sizes + sizes[-1:] * (depth - len(sizes)) for sizes in levels], float)}

    @functools.lru_cache(maxsize=8)
    def slice(self, z: float) -> np.ndarray:
        """Wall segments ``(M, 2, 2)`` where solid surfaces cross the horizontal plane at height ``z``.

        Parameters
        ----------
        z : float
            Height of the plane (metres).

        Returns
        -------
        numpy.ndarray, shape (M, 2, 2)
            Segment end points ``[[x0, y0], [x1, y1]]``.

        Notes
        -----
        Plane-polygon intersection: each rectangle edge crossing the plane contributes its crossing
        point (linear interpolation); a convex polygon crosses a plane in one segment.
        """
        z = as_finite_scalar(z, "z")
        segs = []
        for s in self.surfaces:
            if not s.solid or abs(s.normal[2]) > 1e-9:
                continue
            c = s.corners
            pts = []
            for a, b in zip(c, np.roll(c, -1, axis=0)):
                if (a[2] - z) * (b[2] - z) < 0 or (a[2] == z and b[2] != z):
                    t = (z - a[2]) / (b[2] - a[2])
                    pts.append((a + t * (b - a))[:2])
            if len(pts) >= 2 and np.linalg.norm(pts[0] - pts[1]) > 1e-12:
                segs.append(pts[:2])
        return np.array(segs, float).reshape(-1, 2, 2)

    @functools.lru_cache(maxsize=8)
    def layout(self, z: float) -> Layout:
        """The walls at height ``z`` as a :class:`~robokit.sim.layout.Layout` (cached per height).

        Parameters
        ----------
        z : float
            Height of the plane (metres), e.g. a LiDAR's scan height.

        Returns
        -------
        Layout
            ``Layout(segments=self.slice(z))``: what a 2D scanner at that height casts over.

        Notes
        -----
        Cached so a scan pays only for its rays (DESIGN.md, "Speed").

        Examples
        --------
        >>> from robokit.sim import box_room
        >>> box_room().layout(0.25).raycast([1.0, 1.0], [np.pi]).tolist()   # the west wall at x = 0
        [1.0]
        """
        return Layout(segments=self.slice(z))

    @functools.lru_cache(maxsize=4)
    def free_space(self, resolution: float | None = None) -> FreeSpace:
        """Rasterise the footprint and flood-fill the free floor area from :attr:`interior`.

        Parameters
        ----------
        resolution : float, optional
            Cell size in metres; default :attr:`free_resolution` (0.02 m unless the builder chose).

        Returns
        -------
        FreeSpace

        Notes
        -----
        Scan-line flood fill (``cv2.floodFill``) and Euclidean distance transform (Felzenszwalb &
        Huttenlocher 2012) for the clearance.
        """
        res = as_positive(self.free_resolution if resolution is None else resolution, "resolution")
        origin = self.segments.reshape(-1, 2).min(axis=0) - 4 * res
        size = np.ceil((self.segments.reshape(-1, 2).max(axis=0) + 4 * res - origin) / res).astype(int)
        walls = np.zeros((size[1], size[0]), np.uint8)
        pix = (self.segments - origin) / res
        for (a, b) in pix:
            cv2.line(walls, tuple(np.floor(a).astype(int)), tuple(np.floor(b).astype(int)), 255, 1)
        mask = np.zeros((size[1] + 2, size[0] + 2), np.uint8)
        start = np.floor((self.interior - origin) / res).astype(int)      # the flood fill's start cell
        if not (0 <= start[0] < size[0] and 0 <= start[1] < size[1]) or walls[start[1], start[0]]:
            raise ValueError(f"interior: expected a point inside the walls of {self.name!r}, got "
                             f"{self.interior.tolist()}")
        fill = walls.copy()
        cv2.floodFill(fill, mask, (int(start[0]), int(start[1])), 128, flags=4)
        free = fill == 128
        if free[0, :].any() or free[-1, :].any() or free[:, 0].any() or free[:, -1].any():
            raise ValueError(f"surfaces: the walls do not enclose the interior point of {self.name!r}")
        clearance = cv2.distanceTransform((walls == 0).astype(np.uint8), cv2.DIST_L2, 5) * res
        return FreeSpace(free, origin, res, clearance)

    def is_free(self, xy: Any, clearance: float = 0.05) -> np.ndarray:
        """Whether floor points are inside the world and at least ``clearance`` metres from walls.

        Parameters
        ----------
        xy : array_like, shape (N, 2) or (2,)
        clearance : float, default 0.05

        Returns
        -------
        numpy.ndarray of bool, shape (N,)

        Notes
        -----
        Looks up :meth:`free_space` (cells of :attr:`free_resolution`, 2 cm by default), so the
        answer is exact to about one cell.
        """
        pts = as_points(xy, "xy", 2)
        c = as_positive(clearance, "clearance", allow_zero=True)
        fs = self.free_space()
        rows, cols, inside = fs.cells(pts)
        return inside & fs.free[rows, cols] & (fs.clearance[rows, cols] >= c)

    def as_viewpoint(self, position: Any, name: str = "pose", clearance: float = 0.05) -> np.ndarray:
        """Raise ``ValueError`` unless a sensor at ``position`` (3,) is inside the free space.

        Parameters
        ----------
        position : array_like, shape (3,)
            Sensor position (metres).
        name : str
            Argument name for the error message.
        clearance : float, default 0.05
            Minimum distance to any wall.

        Returns
        -------
        numpy.ndarray, shape (3,)
            The validated position.

        Notes
        -----
        Rendering from inside a wall or outside the world would return a plausible-looking but
        meaningless image; the issue asks for a clear exception instead.
        """
        p = as_array(position, name, shape=(3,))
        if not 0 < p[2] < self.height:
            raise ValueError(f"{name}: expected a height between the floor and the ceiling "
                             f"(0, {self.height}) m, got z = {p[2]:.3f} m")
        if not self.is_free(p[:2], clearance)[0]:
            raise ValueError(f"{name}: expected a position inside {self.name!r} at least {clearance} m from "
                             f"walls, got ({p[0]:.3f}, {p[1]:.3f}) m (inside a wall or outside the world)")
        return p
