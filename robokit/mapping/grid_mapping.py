"""Occupancy grid mapping with known poses: the inverse range sensor model and the log-odds update.

:func:`occupancy_grid_mapping` is Thrun et al. (2005), Table 9.1, over a recorded run: every scan
adds, to each cell in its perceptual field, the log odds of the inverse range sensor model
(Table 9.2) minus the prior ``l0``. The model is cell-centred, as in the book: a cell takes the
beam nearest its bearing; it is occupied if its distance is within ``thickness / 2`` of that
beam's return, free if it is nearer, and untouched if it is farther, off the beam, or beyond
``r_max``. A max-range reading (``inf``, as :class:`robokit.sim.Lidar` reports, or any range
``>= r_max``) marks free space up to ``r_max`` and no hit.

Log odds are clamped to ``[LOG_ODDS_MIN, LOG_ODDS_MAX]`` (P = 0.12 and 0.97, OctoMap's defaults,
Hornung et al. 2013) after each scan, so a cell that was free for a long time can still turn
occupied after a few hits. The defaults ``l_occ = log_odds(0.7)`` and ``l_free = log_odds(0.4)``
are OctoMap's hit and miss probabilities.

:func:`occupancy_grid_mapping_readable` is the same algorithm written line by line from the two
tables with plain Python loops (one cell, one beam at a time): the fast version vectorises over
the cells of a scan's perceptual field and is tested equal to it.

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] A. Hornung, K. M. Wurm, M. Bennewitz, C. Stachniss and W. Burgard, "OctoMap: an efficient
   probabilistic 3D mapping framework based on octrees", *Autonomous Robots* 34(3), 189-206, 2013.
.. [3] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering* 24(6), 2023,
   doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..geometry import se2_compose, wrap_angle
from ..geometry.planar import as_planar
from ..validation import as_array, as_finite_scalar, as_positive, describe, require_angles
from .occupancy_grid import LOG_ODDS_MAX, LOG_ODDS_MIN, OccupancyGrid

__all__ = ["L_OCC", "L_FREE", "inverse_range_sensor_model", "update_log_odds", "occupancy_grid_mapping",
           "occupancy_grid_mapping_readable"]

#: Log odds a hit and a pass-through add: log_odds(0.7) and log_odds(0.4) (OctoMap's defaults).
L_OCC, L_FREE = math.log(0.7 / 0.3), math.log(0.4 / 0.6)


def _as_scan(ranges: Any, angles: Any, name: str = "ranges") -> tuple[np.ndarray, np.ndarray]:
    r = as_array(ranges, name, finite=False)
    a = as_array(angles, "angles", ndim=1)
    require_angles(a, "angles")
    if r.ndim == 0 or r.shape[-1] == 0:
        raise ValueError(f"{name}: expected at least one beam per scan (an empty scan has nothing to map), "
                         f"got shape {r.shape}")
    if a.size == 0:
        raise ValueError("angles: expected at least one beam angle, got an empty array")
    if r.shape[-1] != a.size:
        raise ValueError(f"{name}: expected {a.size} ranges per scan to match angles, got shape {r.shape}")
    bad = np.isnan(r) | (r < 0)
    if bad.any():
        where = np.argwhere(bad)[0].tolist()
        raise ValueError(f"{name}: expected non-negative ranges or inf (no return), got {r[bad].flat[0]} "
                         f"at index {where}")
    return r, a


def _model_options(r_max: Any, l_occ: Any, l_free: Any, l0: Any, thickness: Any, beam_width: Any,
                   beams: int) -> tuple:
    z_max = as_positive(r_max, "r_max")
    lo = as_finite_scalar(l_occ, "l_occ")
    lf = as_finite_scalar(l_free, "l_free")
    prior = as_finite_scalar(l0, "l0")
    alpha = as_positive(thickness, "thickness")
    beta = 2 * np.pi / beams if beam_width is None else as_positive(beam_width, "beam_width")
    return z_max, lo, lf, prior, alpha, beta


def _nearest_beam(phi: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Index of the beam whose angle is nearest each bearing ``phi`` (the argmin over beams of Table 9.2),
    by a binary search over the beams sorted around the circle."""
    wrapped = wrap_angle(angles)
    order = np.argsort(wrapped, kind="stable")
    s = wrapped[order]
    pos = np.searchsorted(s, phi)
    below, above = order[(pos - 1) % s.size], order[pos % s.size]
    closer_below = np.abs(wrap_angle(phi - angles[below])) <= np.abs(wrap_angle(phi - angles[above]))
    return np.where(closer_below, below, above)


def inverse_range_sensor_model(xy: Any, pose: Any, ranges: Any, angles: Any, *, r_max: float, l_occ: float = L_OCC,
                               l_free: float = L_FREE, l0: float = 0.0, thickness: float = 0.1,
                               beam_width: float | None = None) -> np.ndarray:
    """Log odds that one scan gives each cell (Thrun et al. 2005, Table 9.2), vectorised over cells.

    Parameters
    ----------
    xy : array_like, shape (N, 2)
        Cell centres (world metres).
    pose : array_like, shape (3,)
        The sensor's pose ``[x, y, theta]`` (a robot pose composed with the sensor mount).
    ranges : array_like, shape (B,)
        Metres; ``inf`` (or any value ``>= r_max``) is a max-range reading: free up to ``r_max``,
        no hit.
    angles : array_like, shape (B,)
        Beam angles in the sensor frame (any order).
    r_max : float
        The sensor's maximum range ``z_max``.
    l_occ, l_free, l0 : float
        Log odds of a hit, of a pass-through, and the prior (returned outside the field).
    thickness : float, default 0.1
        ``alpha``: the depth of an obstacle (metres) around a return.
    beam_width : float, optional
        ``beta``: the opening angle of a beam; default ``2 pi / B`` (a full-turn scan's spacing).

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``l_occ``, ``l_free`` or ``l0`` per cell.

    Raises
    ------
    ValueError
        For an empty scan, a NaN or negative range, mismatched ``ranges`` / ``angles`` or bad options.

    Notes
    -----
    Table 9.2, step by step: ``r`` and ``phi`` are the cell's range and bearing in the sensor
    frame, ``k`` the nearest beam; ``l0`` if ``r > min(z_max, z_k + alpha / 2)`` or
    ``|phi - theta_k| > beta / 2``, else ``l_occ`` if ``z_k < z_max`` and ``|r - z_k| < alpha / 2``,
    else ``l_free`` if ``r <= z_k``.

    Examples
    --------
    >>> cells = [[0.5, 0.0], [1.0, 0.0], [1.5, 0.0], [0.0, 0.5]]
    >>> inverse_range_sensor_model(cells, [0, 0, 0], [1.0, np.inf, 3.0, 4.0], np.arange(4) * np.pi / 2,
    ...                            r_max=2.0, l_occ=1.0, l_free=-0.5).tolist()
    [-0.5, 1.0, 0.0, -0.5]
    """
    pts = as_array(xy, "xy")
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"xy: expected shape (N, 2), got shape {pts.shape}")
    p = as_planar(pose, "pose", shape=(3,))
    z, a = _as_scan(ranges, angles)
    if z.ndim != 1:
        raise ValueError(f"ranges: expected one scan of shape ({a.size},), got shape {z.shape}")
    return _inverse_model(pts, p, z, a, _model_options(r_max, l_occ, l_free, l0, thickness, beam_width, a.size))


def _inverse_model(pts: np.ndarray, p: np.ndarray, z: np.ndarray, a: np.ndarray, opts: tuple) -> np.ndarray:
    """Unchecked :func:`inverse_range_sensor_model`; ``opts`` as :func:`_model_options` gives them."""
    z_max, lo, lf, prior, alpha, beta = opts
    d = pts - p[:2]
    r = np.hypot(d[:, 0], d[:, 1])                                         # Table 9.2: range
    phi = wrap_angle(np.arctan2(d[:, 1], d[:, 0]) - p[2])                  # bearing
    k = _nearest_beam(phi, a)                                              # nearest beam
    zk = np.minimum(z[k], z_max)                                           # max-range readings are z_max
    outside = (r > np.minimum(z_max, zk + alpha / 2)) | (np.abs(wrap_angle(phi - a[k])) > beta / 2)   # no information
    hit = (zk < z_max) & (np.abs(r - zk) < alpha / 2)                      # a hit
    out = np.where(hit, lo, np.where(r <= zk, lf, prior))                  # Table 9.2: l_occ, l_free
    out[outside] = prior                                                   # Table 9.2: l0
    return out


def _update(L: np.ndarray, xs: np.ndarray, ys: np.ndarray, sensor: np.ndarray, z: np.ndarray, a: np.ndarray,
            opts: tuple, clamp: tuple) -> None:
    """Add one scan to the log odds ``L`` in place (Table 9.1, lines 2-6) over its perceptual field."""
    z_max, lo, lf, prior, alpha, beta = opts
    reach = z_max + alpha / 2
    j0, j1 = np.searchsorted(xs, [sensor[0] - reach, sensor[0] + reach])
    i0, i1 = np.searchsorted(ys, [sensor[1] - reach, sensor[1] + reach])
    if i0 >= i1 or j0 >= j1:
        return
    gx, gy = np.meshgrid(xs[j0:j1], ys[i0:i1])
    cells = np.column_stack([gx.ravel(), gy.ravel()])
    ism = _inverse_model(cells, sensor, z, a, opts)
    block = L[i0:i1, j0:j1]
    block += (ism - prior).reshape(block.shape)                            # Table 9.1, line 4
    np.clip(block, clamp[0], clamp[1], out=block)


def _as_clamp(clamp: Any) -> tuple[float, float]:
    c = as_array(clamp, "clamp", shape=(2,))
    if not c[0] < c[1]:
        raise ValueError(f"clamp: expected (low, high) with low < high, got {c.tolist()}")
    return float(c[0]), float(c[1])


def update_log_odds(grid: OccupancyGrid, pose: Any, ranges: Any, angles: Any, *, r_max: float, l_occ: float = L_OCC,
                    l_free: float = L_FREE, l0: float = 0.0, thickness: float = 0.1, beam_width: float | None = None,
                    clamp: Any = (LOG_ODDS_MIN, LOG_ODDS_MAX)) -> OccupancyGrid:
    """One scan's update of a grid: ``l_t = l_{t-1} + inverse_range_sensor_model - l0`` (Thrun et al. 2005, Table 9.1, line 4).

    Parameters
    ----------
    grid : OccupancyGrid
        Left unchanged; the updated grid is returned.
    pose : array_like, shape (3,)
        The sensor's pose ``[x, y, theta]``.
    ranges : array_like, shape (B,)
        Metres; ``inf`` (or any value ``>= r_max``) is a max-range reading: free up to ``r_max``.
    angles, r_max, l_occ, l_free, l0, thickness, beam_width
        As :func:`inverse_range_sensor_model`.
    clamp : (float, float), default (LOG_ODDS_MIN, LOG_ODDS_MAX)
        Bounds of a cell's log odds after the update (P = 0.12 and 0.97).

    Returns
    -------
    OccupancyGrid

    Raises
    ------
    TypeError
        If ``grid`` is not an OccupancyGrid.
    ValueError
        As :func:`inverse_range_sensor_model`, or for a bad ``clamp``.

    Notes
    -----
    Only cells within ``r_max + thickness / 2`` of the sensor (the perceptual field, Table 9.1,
    line 3) are evaluated; the model returns ``l0`` for every other cell anyway.

    Examples
    --------
    >>> grid = OccupancyGrid.empty((0.0, -0.5, 3.0, 0.5), 0.5)        # 2 rows x 6 columns
    >>> out = update_log_odds(grid, [0.0, 0.25, 0.0], [2.25], [0.0], r_max=4.0, thickness=0.5)
    >>> np.round(out.log_odds[1], 3).tolist()                           # along the beam: free, free, free, free, hit, unknown
    [-0.405, -0.405, -0.405, -0.405, 0.847, 0.0]
    """
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(f"grid: expected an OccupancyGrid, got {describe(grid)}")
    p = as_planar(pose, "pose", shape=(3,))
    z, a = _as_scan(ranges, angles)
    if z.ndim != 1:
        raise ValueError(f"ranges: expected one scan of shape ({a.size},), got shape {z.shape}")
    opts = _model_options(r_max, l_occ, l_free, l0, thickness, beam_width, a.size)
    bounds = _as_clamp(clamp)
    L = grid.log_odds.copy()
    xs = grid.origin[0] + (np.arange(grid.shape[1]) + 0.5) * grid.resolution
    ys = grid.origin[1] + (np.arange(grid.shape[0]) + 0.5) * grid.resolution
    _update(L, xs, ys, p, z, a, opts, bounds)
    return OccupancyGrid(L, grid.resolution, grid.origin)


def _as_run(poses: Any, scans: Any, angles: Any, sensor_offset: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    P = as_planar(poses, "poses", shape=(None, 3), min_count=1)
    z, a = _as_scan(scans, angles, "scans")
    if z.ndim != 2 or z.shape[0] != P.shape[0]:
        raise ValueError(f"scans: expected shape ({P.shape[0]}, {a.size}), one scan per pose, got shape {z.shape}")
    offset = as_planar(sensor_offset, "sensor_offset", shape=(3,))
    return se2_compose(P, offset), z, a


def occupancy_grid_mapping(poses: Any, scans: Any, angles: Any, bounds: Any, resolution: float = 0.05, *,
                           r_max: float, sensor_offset: Any = (0.0, 0.0, 0.0), l_occ: float = L_OCC,
                           l_free: float = L_FREE, l0: float = 0.0, thickness: float = 0.1,
                           beam_width: float | None = None,
                           clamp: Any = (LOG_ODDS_MIN, LOG_ODDS_MAX)) -> OccupancyGrid:
    """Map a recorded run with known poses (Thrun et al. 2005, Table 9.1).

    Parameters
    ----------
    poses : array_like, shape (N, 3)
        Robot poses ``[x, y, theta]`` (ground truth or a localizer's), one per scan.
    scans : array_like, shape (N, B)
        Ranges in metres; ``inf`` = no return (a max-range reading).
    angles : array_like, shape (B,)
        Beam angles in the sensor frame (e.g. :attr:`robokit.sim.Lidar.angles`).
    bounds : array_like, (x0, y0, x1, y1)
        The world rectangle to map (see :meth:`OccupancyGrid.empty`).
    resolution : float, default 0.05
        Cell size (metres); Ge et al. (2023) do not state theirs, 0.05 m is gmapping's default.
    r_max : float
        The sensor's maximum range (8 m for :class:`robokit.sim.Lidar`).
    sensor_offset : array_like, shape (3,), default (0, 0, 0)
        Sensor mount ``[x, y, theta]`` in the robot frame (:attr:`robokit.sim.Lidar.offset`).
    l_occ, l_free, l0, thickness, beam_width
        As :func:`inverse_range_sensor_model`.
    clamp : (float, float), default (LOG_ODDS_MIN, LOG_ODDS_MAX)
        Bounds of a cell's log odds after each scan.

    Returns
    -------
    OccupancyGrid

    Raises
    ------
    ValueError
        For no poses, an empty scan, NaN or negative ranges (naming the scan and beam), shapes that
        disagree, or bad options.

    Notes
    -----
    Each scan updates only the cells of its perceptual field (a square of side ``2 r_max`` around
    the sensor), vectorised over those cells; equal to
    :func:`occupancy_grid_mapping_readable`.

    Examples
    --------
    >>> angles = np.arange(4) * np.pi / 2                       # 4 beams: ahead, left, behind, right
    >>> grid = occupancy_grid_mapping([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]], [[1.0, np.inf, np.inf, np.inf]] * 2,
    ...                               angles, (-0.25, -0.25, 1.25, 0.25), 0.5, r_max=3.0, thickness=0.5)
    >>> np.round(grid.log_odds, 3).tolist()                     # two scans: free, free, hit
    [[-0.811, -0.811, 1.695]]
    """
    sensors, z, a = _as_run(poses, scans, angles, sensor_offset)
    opts = _model_options(r_max, l_occ, l_free, l0, thickness, beam_width, a.size)
    lims = _as_clamp(clamp)
    grid = OccupancyGrid.empty(bounds, resolution)
    L = grid.log_odds
    xs = grid.origin[0] + (np.arange(grid.shape[1]) + 0.5) * grid.resolution
    ys = grid.origin[1] + (np.arange(grid.shape[0]) + 0.5) * grid.resolution
    for sensor, ranges in zip(sensors, z):                                 # Table 9.1: one scan at a time
        _update(L, xs, ys, sensor, ranges, a, opts, lims)
    return grid


def occupancy_grid_mapping_readable(poses: Any, scans: Any, angles: Any, bounds: Any, resolution: float = 0.05, *,
                                     r_max: float, sensor_offset: Any = (0.0, 0.0, 0.0), l_occ: float = L_OCC,
                                     l_free: float = L_FREE, l0: float = 0.0, thickness: float = 0.1,
                                     beam_width: float | None = None,
                                     clamp: Any = (LOG_ODDS_MIN, LOG_ODDS_MAX)) -> OccupancyGrid:
    """Tables 9.1 and 9.2 of Thrun et al. (2005) as written: one cell and one beam at a time (slow; the readable version).

    Parameters and result as :func:`occupancy_grid_mapping` (``inf`` in ``scans`` is a max-range
    reading), which it is tested equal to. Plain
    Python loops: about a second per 360-beam scan of the corridor; for teaching and testing only.

    Examples
    --------
    >>> angles = np.arange(4) * np.pi / 2
    >>> grid = occupancy_grid_mapping_readable([[0.0, 0.0, 0.0]], [[1.0, np.inf, np.inf, np.inf]], angles,
    ...                                         (-0.25, -0.25, 1.25, 0.25), 0.5, r_max=3.0, thickness=0.5)
    >>> np.round(grid.log_odds, 3).tolist()
    [[-0.405, -0.405, 0.847]]
    """
    sensors, z, a = _as_run(poses, scans, angles, sensor_offset)
    z_max, lo, lf, prior, alpha, beta = _model_options(r_max, l_occ, l_free, l0, thickness, beam_width, a.size)
    low, high = _as_clamp(clamp)
    grid = OccupancyGrid.empty(bounds, resolution)
    H, W = grid.shape
    beams = a.tolist()
    L = [[0.0] * W for _ in range(H)]
    for (x, y, theta), scan in zip(sensors.tolist(), z.tolist()):
        for i in range(H):
            for j in range(W):
                xi = grid.origin[0] + (j + 0.5) * grid.resolution
                yi = grid.origin[1] + (i + 0.5) * grid.resolution
                r = math.hypot(xi - x, yi - y)                             # Table 9.2: range
                if r > z_max + alpha / 2:                                  # not in the perceptual field (9.1, line 3)
                    continue
                phi = math.atan2(yi - y, xi - x) - theta                   # bearing
                # nearest beam; |remainder(d, 2 pi)| is |wrap_angle(d)|, in plain Python for speed
                k = min(range(len(beams)), key=lambda b: abs(math.remainder(phi - beams[b], math.tau)))
                zk = min(scan[k], z_max)
                if r > min(z_max, zk + alpha / 2) or abs(math.remainder(phi - beams[k], math.tau)) > beta / 2:
                    ism = prior                                            # no information
                elif zk < z_max and abs(r - zk) < alpha / 2:               # a hit
                    ism = lo
                elif r <= zk:                                              # passed through
                    ism = lf
                else:
                    ism = prior
                L[i][j] = min(high, max(low, L[i][j] + ism - prior))       # Table 9.1, line 4, clamped
    return OccupancyGrid(np.array(L), grid.resolution, grid.origin)
