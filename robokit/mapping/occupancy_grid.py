"""Occupancy grids in log-odds form, and the likelihood field a range-finder model looks up.

A grid cell ``[i, j]`` covers ``x in origin[0] + [j, j + 1) * resolution`` and
``y in origin[1] + [i, i + 1) * resolution``: row 0 is the lowest ``y``, so ``origin`` is the
map's lower-left corner, as in ROS's map_server and :func:`robokit.viz.plot_occupancy`. A cell
stores the log odds ``l = log(p / (1 - p))`` of being occupied (Thrun et al. 2005, Sec. 9.2), so
0 is "unknown" (p = 0.5) and a measurement update is an addition (Table 9.1). A cell is read as
free below P = 0.196 and occupied above 0.65, map_server's default thresholds.

The likelihood field (Thrun et al. 2005, Table 6.3) precomputes, for each cell, the distance from
its centre to the nearest occupied cell centre, so a Monte-Carlo localizer scores a scan endpoint
with one array lookup. Ge et al. (2023, Sec. 3.4) build their grid map of the corridor with a 2D
LiDAR and localize in it with AMCL; this module is that map's data structure.

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering* 24(6), 2023,
   doi:10.1631/FITEE.2200208.
.. [3] A. Hornung, K. M. Wurm, M. Bennewitz, C. Stachniss and W. Burgard, "OctoMap: an efficient
   probabilistic 3D mapping framework based on octrees", *Autonomous Robots* 34(3), 189-206, 2013.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from scipy import ndimage, special

from ..validation import as_array, as_finite_scalar, as_positive, require_sample_count, describe
from .topological import EmptyMapError

__all__ = ["FREE_THRESHOLD", "OCCUPIED_THRESHOLD", "LOG_ODDS_MIN", "LOG_ODDS_MAX", "EmptyMapError", "log_odds",
           "probability", "OccupancyGrid", "LikelihoodField", "likelihood_field"]

#: map_server's defaults: P(occupied) below FREE_THRESHOLD is free, above OCCUPIED_THRESHOLD occupied.
FREE_THRESHOLD, OCCUPIED_THRESHOLD = 0.196, 0.65
#: Clamping bounds of a cell's log odds (OctoMap's defaults, P = 0.12 and 0.97; Hornung et al. 2013,
#: Sec. 3.3): a cell seen free a thousand times can still turn occupied after a few hits.
LOG_ODDS_MIN, LOG_ODDS_MAX = -2.0, 3.5


def _probability_in(value: Any, name: str, *, closed: bool = False) -> float:
    p = as_finite_scalar(value, name)
    if not (0.0 <= p <= 1.0 if closed else 0.0 < p < 1.0):
        raise ValueError(f"{name}: expected a probability in {'[0, 1]' if closed else '(0, 1)'}, got {p}")
    return p


def log_odds(p: Any) -> Any:
    """Log odds ``log(p / (1 - p))`` of a probability (Thrun et al. 2005, Sec. 9.2).

    Parameters
    ----------
    p : float or array_like
        Probabilities strictly inside (0, 1) (0 and 1 have infinite log odds).

    Returns
    -------
    float or numpy.ndarray
        A float for a scalar, else an array of ``p``'s shape.

    Raises
    ------
    ValueError
        If a value is NaN, infinite or outside (0, 1).

    Examples
    --------
    >>> round(log_odds(0.7), 6), log_odds(0.5)
    (0.847298, 0.0)
    >>> np.round(log_odds([0.4, 0.9]), 4)
    array([-0.4055,  2.1972])
    """
    arr = as_array(p, "p")
    if np.any((arr <= 0) | (arr >= 1)):
        raise ValueError(f"p: expected probabilities strictly inside (0, 1), got {arr[(arr <= 0) | (arr >= 1)].flat[0]}")
    out = np.log(arr / (1.0 - arr))                       # the log odds ratio, Sec. 9.2
    return float(out) if out.ndim == 0 else out


def probability(l: Any) -> Any:  # noqa: E741  (the book's name for log odds)
    """Probability ``1 - 1 / (1 + exp(l))`` of log odds ``l``, the inverse of :func:`log_odds`.

    Parameters
    ----------
    l : float or array_like
        Finite log odds.

    Returns
    -------
    float or numpy.ndarray
        A float for a scalar, else an array of ``l``'s shape, in [0, 1].

    Raises
    ------
    ValueError
        If a value is NaN or infinite.

    Notes
    -----
    Thrun et al. (2005), Sec. 9.2 (recovering the belief from log odds); evaluated as the logistic
    function ``scipy.special.expit``, which neither overflows nor loses precision for large ``|l|``.

    Examples
    --------
    >>> probability(0.0), round(probability(log_odds(0.7)), 12)
    (0.5, 0.7)
    >>> np.round(probability([-2.0, 3.5]), 4)            # the clamping bounds
    array([0.1192, 0.9707])
    """
    arr = as_array(l, "l")
    out = special.expit(arr)                              # 1 - 1 / (1 + exp(l)), Sec. 9.2
    return float(out) if out.ndim == 0 else out


class OccupancyGrid:
    """A 2-D occupancy grid map: log odds of occupancy per cell.

    Parameters
    ----------
    log_odds : array_like, shape (H, W)
        Finite log odds; cell ``[i, j]`` covers ``origin + ([j, j + 1), [i, i + 1)) * resolution``
        (row 0 is the lowest ``y``).
    resolution : float
        Cell size in metres.
    origin : array_like, shape (2,), default (0, 0)
        World ``(x, y)`` of the lower-left corner of cell ``[0, 0]``.

    Raises
    ------
    ValueError
        For an empty or non-2-D grid, a non-finite log odds, a non-positive resolution or a bad
        origin.

    Notes
    -----
    The map ``m = {m_i}`` of Thrun et al. (2005), Sec. 9.2, each cell an independent binary
    variable in log-odds form. ``log_odds`` is stored as a copy; :attr:`probability` derives from it.

    Examples
    --------
    >>> grid = OccupancyGrid(np.zeros((2, 3)), 0.5, origin=(1.0, -0.5))
    >>> grid.shape, grid.bounds
    ((2, 3), (1.0, -0.5, 2.5, 0.5))
    >>> grid.probability[0, 0], int(grid.unknown_mask().sum())
    (np.float64(0.5), 6)
    """

    def __init__(self, log_odds: Any, resolution: float, origin: Any = (0.0, 0.0)) -> None:
        arr = as_array(log_odds, "log_odds", ndim=2)
        if arr.size == 0:
            raise ValueError(f"log_odds: expected a grid with at least one cell, got shape {arr.shape}")
        self.log_odds = np.array(arr, dtype=float)
        self.resolution = as_positive(resolution, "resolution")
        self.origin = np.array(as_array(origin, "origin", shape=(2,)), dtype=float)

    def __repr__(self) -> str:
        return (f"OccupancyGrid(shape={self.shape}, resolution={self.resolution}, "
                f"origin=({self.origin[0]}, {self.origin[1]}))")

    @property
    def shape(self) -> tuple[int, int]:
        """``(H, W)``: rows (along y) and columns (along x)."""
        return self.log_odds.shape

    @property
    def probability(self) -> np.ndarray:
        """P(occupied) of every cell, shape ``(H, W)``."""
        return special.expit(self.log_odds)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(x0, y0, x1, y1)``: the world rectangle the grid covers."""
        h, w = self.shape
        x0, y0 = float(self.origin[0]), float(self.origin[1])
        return x0, y0, x0 + w * self.resolution, y0 + h * self.resolution

    @classmethod
    def empty(cls, bounds: Any, resolution: float) -> "OccupancyGrid":
        """An all-unknown grid (log odds 0) covering ``bounds = (x0, y0, x1, y1)``.

        The grid has ``ceil((x1 - x0) / resolution)`` columns and ``ceil((y1 - y0) / resolution)``
        rows, so it covers at least ``bounds``; its origin is ``(x0, y0)``.

        Raises
        ------
        ValueError
            If ``x1 <= x0`` or ``y1 <= y0``, the resolution is not positive, or the grid would have
            more than 10 000 000 cells.

        Examples
        --------
        >>> OccupancyGrid.empty((0.0, -1.2, 36.1, 1.2), 0.05)
        OccupancyGrid(shape=(48, 722), resolution=0.05, origin=(0.0, -1.2))
        """
        b = as_array(bounds, "bounds", shape=(4,))
        r = as_positive(resolution, "resolution")
        if not (b[2] > b[0] and b[3] > b[1]):
            raise ValueError(f"bounds: expected (x0, y0, x1, y1) with x1 > x0 and y1 > y0, got {b.tolist()}")
        nx, ny = (b[2] - b[0]) / r, (b[3] - b[1]) / r
        require_sample_count(nx * ny, "bounds, resolution")
        # a tolerance so that (36.1 - 0) / 0.05 = 722.0000000000001 is 722 columns, not 723
        w, h = (max(1, int(np.ceil(n - 1e-9))) for n in (nx, ny))
        return cls(np.zeros((h, w)), r, b[:2])

    @classmethod
    def from_probability(cls, P: Any, resolution: float, origin: Any = (0.0, 0.0)) -> "OccupancyGrid":
        """A grid from P(occupied) per cell (0.5 for unknown).

        Probabilities 0 and 1 (infinite log odds) are clamped to ``[LOG_ODDS_MIN, LOG_ODDS_MAX]``
        (P = 0.12 and 0.97), so they stay free and occupied under the default thresholds.

        Raises
        ------
        ValueError
            If ``P`` is not 2-D, is empty, or holds NaN, an infinity or a value outside [0, 1].

        Examples
        --------
        >>> grid = OccupancyGrid.from_probability([[0.0, 0.5], [1.0, 0.3]], 0.1)
        >>> grid.free_mask().astype(int).tolist(), grid.occupied_mask().astype(int).tolist()
        ([[1, 0], [0, 0]], [[0, 0], [1, 0]])
        """
        p = as_array(P, "P", ndim=2)
        if np.any((p < 0) | (p > 1)):
            raise ValueError(f"P: expected probabilities in [0, 1], got {p[(p < 0) | (p > 1)].flat[0]}")
        with np.errstate(divide="ignore"):
            lo = np.log(p) - np.log1p(-p)                 # log odds, Sec. 9.2 (+-inf at 1 and 0)
        return cls(np.clip(lo, LOG_ODDS_MIN, LOG_ODDS_MAX), resolution, origin)

    def crop(self, bounds: Any) -> "OccupancyGrid":
        """The cells inside ``bounds = (x0, y0, x1, y1)``: a part of the map as a map of its own.

        Parameters
        ----------
        bounds : array_like, shape (4,)
            A world rectangle inside :attr:`bounds`; its corners are rounded to the nearest cell
            edge.

        Returns
        -------
        OccupancyGrid
            The same cells (a copy), the origin moved to the rectangle's lower-left cell edge.

        Raises
        ------
        ValueError
            For a rectangle with ``x1 <= x0`` or ``y1 <= y0``, one that reaches outside the grid, or one
            that holds no whole cell.

        Notes
        -----
        A sub-map of the grid of Thrun et al. (2005), Sec. 9.2 (cells are independent, so a part of
        the map is a map).

        Examples
        --------
        >>> grid = OccupancyGrid(np.arange(12.0).reshape(3, 4), 0.5)
        >>> part = grid.crop((0.5, 0.5, 1.5, 1.5))
        >>> part.log_odds.tolist(), part.origin.tolist()
        ([[5.0, 6.0], [9.0, 10.0]], [0.5, 0.5])
        """
        b = as_array(bounds, "bounds", shape=(4,))
        x0, y0, x1, y1 = self.bounds
        tol = 1e-9 * self.resolution
        if not (b[2] > b[0] and b[3] > b[1]):
            raise ValueError(f"bounds: expected (x0, y0, x1, y1) with x1 > x0 and y1 > y0, got {b.tolist()}")
        if b[0] < x0 - tol or b[1] < y0 - tol or b[2] > x1 + tol or b[3] > y1 + tol:
            raise ValueError(f"bounds: expected a rectangle inside the grid's {[x0, y0, x1, y1]}, got {b.tolist()}")
        c0, r0, c1, r1 = np.rint((b - np.tile(self.origin, 2)) / self.resolution).astype(int)
        if c1 <= c0 or r1 <= r0:
            raise ValueError(f"bounds: expected a rectangle holding at least one whole cell, got {b.tolist()}")
        return OccupancyGrid(self.log_odds[r0:r1, c0:c1], self.resolution, self.origin + np.array([c0, r0]) * self.resolution)

    def cell_of(self, xy: Any) -> tuple[np.ndarray, np.ndarray]:
        """Cell indices ``[i, j]`` (row, column) of world points, and whether each is on the map.

        Parameters
        ----------
        xy : array_like, shape (N, 2) or (2,)

        Returns
        -------
        ij : numpy.ndarray of int, shape (N, 2)
            ``i = floor((y - y0) / resolution)``, ``j = floor((x - x0) / resolution)``; outside
            the map these are clipped to one past the edge (-1 or H / W).
        inside : numpy.ndarray of bool, shape (N,)

        Examples
        --------
        >>> grid = OccupancyGrid(np.zeros((2, 3)), 0.5)
        >>> ij, inside = grid.cell_of([[0.1, 0.9], [1.49, 0.0], [-0.1, 0.2]])
        >>> ij.tolist(), inside.tolist()
        ([[1, 0], [0, 2], [0, -1]], [True, True, False])
        """
        pts = as_array(xy, "xy")
        if pts.ndim == 1 and pts.shape == (2,):
            pts = pts[None, :]
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise ValueError(f"xy: expected shape (N, 2), got shape {pts.shape}")
        h, w = self.shape
        f = np.floor((pts - self.origin) / self.resolution)[:, ::-1]
        ij = np.clip(f, -1, [h, w]).astype(np.int64)
        inside = (ij[:, 0] >= 0) & (ij[:, 0] < h) & (ij[:, 1] >= 0) & (ij[:, 1] < w)
        return ij, inside

    def cell_centres(self, ij: Any) -> np.ndarray:
        """World ``(x, y)`` of the centres of cells ``[i, j]``, shape ``(N, 2)``.

        Examples
        --------
        >>> OccupancyGrid(np.zeros((2, 3)), 0.5, origin=(1.0, 0.0)).cell_centres([[1, 2]]).tolist()
        [[2.25, 0.75]]
        """
        idx = as_array(ij, "ij", dtype=np.int64)
        if idx.ndim == 1 and idx.shape == (2,):
            idx = idx[None, :]
        if idx.ndim != 2 or idx.shape[1] != 2:
            raise ValueError(f"ij: expected shape (N, 2), got shape {idx.shape}")
        return self.origin + (idx[:, ::-1] + 0.5) * self.resolution

    def free_mask(self, free_threshold: float = FREE_THRESHOLD) -> np.ndarray:
        """Cells with P(occupied) below ``free_threshold`` (map_server's free_thresh), shape ``(H, W)``.

        Examples
        --------
        >>> OccupancyGrid([[-3.0, 0.0, 3.0]], 1.0).free_mask().tolist()
        [[True, False, False]]
        """
        t = _probability_in(free_threshold, "free_threshold", closed=True)
        return self.probability < t

    def occupied_mask(self, occupied_threshold: float = OCCUPIED_THRESHOLD) -> np.ndarray:
        """Cells with P(occupied) above ``occupied_threshold`` (map_server's occupied_thresh), shape ``(H, W)``.

        Examples
        --------
        >>> OccupancyGrid([[-3.0, 0.0, 3.0]], 1.0).occupied_mask().tolist()
        [[False, False, True]]
        """
        t = _probability_in(occupied_threshold, "occupied_threshold", closed=True)
        return self.probability > t

    def unknown_mask(self, free_threshold: float = FREE_THRESHOLD,
                     occupied_threshold: float = OCCUPIED_THRESHOLD) -> np.ndarray:
        """Cells neither free nor occupied, shape ``(H, W)``.

        Raises
        ------
        ValueError
            If ``free_threshold > occupied_threshold``.

        Examples
        --------
        >>> OccupancyGrid([[-3.0, 0.0, 3.0]], 1.0).unknown_mask().tolist()
        [[False, True, False]]
        """
        f = _probability_in(free_threshold, "free_threshold", closed=True)
        o = _probability_in(occupied_threshold, "occupied_threshold", closed=True)
        if f > o:
            raise ValueError(f"free_threshold: expected at most occupied_threshold = {o}, got {f}")
        return ~(self.free_mask(f) | self.occupied_mask(o))

    def free_cells(self, free_threshold: float = FREE_THRESHOLD) -> np.ndarray:
        """Centres of the free cells, shape ``(M, 2)``, in row-major cell order (where particles may be drawn).

        Raises
        ------
        EmptyMapError
            If no cell is free: a localizer must never sample poses from nothing.

        Examples
        --------
        >>> OccupancyGrid([[-3.0, 0.0], [3.0, -3.0]], 1.0).free_cells().tolist()
        [[0.5, 0.5], [1.5, 1.5]]
        >>> OccupancyGrid([[0.0]], 1.0).free_cells()
        Traceback (most recent call last):
        ...
        robokit.mapping.topological.EmptyMapError: grid: no free cell (P(occupied) < 0.196) in a map of shape (1, 1)
        """
        mask = self.free_mask(free_threshold)
        if not mask.any():
            raise EmptyMapError(f"grid: no free cell (P(occupied) < {free_threshold}) in a map of shape {self.shape}")
        return self.cell_centres(np.argwhere(mask))


@dataclasses.dataclass(eq=False)
class LikelihoodField:
    """Distances from every cell centre to the nearest occupied cell centre (plain data).

    Attributes
    ----------
    distance : numpy.ndarray, shape (H, W)
        Metres, clipped at ``max_distance``; the grid's cell convention.
    resolution : float
    origin : numpy.ndarray, shape (2,)
    max_distance : float
        The clip, also returned for points off the map.

    Notes
    -----
    The precomputed table of Thrun et al. (2005), Table 6.3 (``likelihood_field_range_finder_model``,
    its ``dist`` term); see :func:`likelihood_field`.
    """

    distance: np.ndarray
    resolution: float
    origin: np.ndarray
    max_distance: float

    def lookup(self, xy: Any, *, validate: bool = True) -> np.ndarray:
        """Distance to the nearest obstacle at world points (``max_distance`` off the map).

        Parameters
        ----------
        xy : array_like, shape (..., 2)
            World points, e.g. ``(N, 2)`` scan endpoints or ``(particles, beams, 2)``.
        validate : bool, default True
            Validate ``xy``; ``False`` skips it (a float array; NaN points read as off the map),
            the fast path of a particle filter's inner loop.

        Returns
        -------
        numpy.ndarray, shape (...)
            The distance of the cell that holds each point (nearest-cell lookup, no interpolation).

        Examples
        --------
        >>> field = likelihood_field(OccupancyGrid([[3.0, 0.0, 0.0, 0.0]], 1.0), max_distance=2.5)
        >>> field.lookup([[0.5, 0.5], [2.9, 0.1], [9.0, 0.0]]).tolist()
        [0.0, 2.0, 2.5]
        """
        if validate:
            pts = as_array(xy, "xy")
            if pts.ndim < 1 or pts.shape[-1] != 2:
                raise ValueError(f"xy: expected shape (..., 2), got shape {pts.shape}")
        else:
            pts = np.asarray(xy, dtype=float)
        # The table framed by one ring of max_distance cells: index 0 and W + 1 (H + 1) are "off the map",
        # so every point needs one clip instead of four comparisons and a masked copy. Cell j of the
        # table is column j + 1 of the frame, j = floor((x - x0) / resolution) as in OccupancyGrid.cell_of;
        # anything outside (and NaN or inf, whatever integer they cast to) clips to the frame.
        framed = self._framed()
        h, w = framed.shape
        index = []
        for axis in (0, 1):
            u = np.subtract(pts[..., axis], self.origin[axis])
            u /= self.resolution
            np.floor(u, out=u)
            with np.errstate(invalid="ignore"):
                k = u.astype(np.intp)
            k += 1
            index.append(k)
        ix, iy = index
        np.clip(ix, 0, w - 1, out=ix)
        np.clip(iy, 0, h - 1, out=iy)
        iy *= w
        iy += ix
        return framed.ravel().take(iy)

    def _framed(self) -> np.ndarray:
        """The framed table, rebuilt whenever ``distance`` or ``max_distance`` changed (also in place)."""
        d = np.asarray(self.distance, float)
        key = (id(self.distance), float(self.max_distance), d.shape, hash(d.tobytes()))
        cached = self.__dict__.get("_framed_table")
        if cached is None or cached[0] != key:
            cached = (key, np.pad(d, 1, constant_values=self.max_distance))
            self.__dict__["_framed_table"] = cached
        return cached[1]


def likelihood_field(grid: OccupancyGrid, *, occupied_threshold: float = OCCUPIED_THRESHOLD,
                     max_distance: float = 2.0) -> LikelihoodField:
    """Precompute the distance from every cell to the nearest occupied cell (Thrun et al. 2005, Table 6.3).

    Parameters
    ----------
    grid : OccupancyGrid
    occupied_threshold : float, default 0.65
        Cells with P(occupied) above it are obstacles.
    max_distance : float, default 2.0
        Clip (metres): ROS amcl's ``laser_likelihood_max_dist`` default.

    Returns
    -------
    LikelihoodField
        A grid with no occupied cell gives ``max_distance`` everywhere (there is no obstacle
        within reach), as amcl does; a localizer then sees a uniform likelihood.

    Raises
    ------
    TypeError
        If ``grid`` is not an OccupancyGrid.
    ValueError
        For a threshold outside [0, 1] or a non-positive ``max_distance``.

    Notes
    -----
    The exact Euclidean distance transform between cell centres,
    ``scipy.ndimage.distance_transform_edt`` with ``sampling=resolution``; ``dist`` of
    Table 6.3 (Ge et al. 2023 localize with AMCL, Sec. 3.4, whose laser model is this one).

    Examples
    --------
    >>> grid = OccupancyGrid.from_probability([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]], 0.5)
    >>> likelihood_field(grid).distance.round(4).tolist()
    [[0.0, 0.5, 1.0], [0.5, 0.7071, 1.118]]
    """
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(f"grid: expected an OccupancyGrid, got {describe(grid)}")
    occupied = grid.occupied_mask(occupied_threshold)
    d_max = as_positive(max_distance, "max_distance")
    if occupied.any():
        dist = ndimage.distance_transform_edt(~occupied, sampling=grid.resolution)  # dist of Table 6.3
        dist = np.minimum(dist, d_max)
    else:
        dist = np.full(grid.shape, d_max)
    return LikelihoodField(dist, grid.resolution, grid.origin.copy(), d_max)
