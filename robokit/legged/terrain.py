"""Rough terrain for the LittleDog: step boards on the floor, their height map, located by MoCap markers.

The LittleDog was built to study locomotion over rough terrain (LittleDog User Guide, Sec. 1), and
its motion-capture system reports where the terrain is as well as where the robot is: the Vicon
cameras track retro-reflective markers placed on the robot and on the terrain (Sec. 1). Here a
terrain is a set of boards, each an axis-aligned box standing on the floor in the terrain's own
frame, plus the markers fixed on them; the terrain frame lies on the floor at a planar pose
``[x, y, yaw]`` in the world (:class:`Terrain`).

* :func:`height_at` and :func:`edge_distance` read the map: the surface height under a point, and
  how far the point is from the nearest board edge (a foothold there would catch the edge);
* :func:`step_terrain` draws a course of boards across the walk, for seeded trials;
* :func:`locate_terrain` is what the MoCap does for the host: it fits the terrain's pose to the
  markers it sees, by the same least-squares rigid fit that gives the robot's body pose
  (:func:`robokit.legged.mocap.fit_marker_pose`), and returns the map placed there.

The boards' sizes are ours (the guide gives none): 1-4 cm tall, 12-30 cm long, across a 60 cm
lane, a third of the robot's 12 cm ground clearance at most (Sec. 3).

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Secs. 1 and 3).
.. [2] K. S. Arun, T. S. Huang and S. D. Blostein, "Least-squares fitting of two 3-D point sets",
   IEEE Trans. Pattern Analysis and Machine Intelligence 9(5), 698-700, 1987.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..geometry import se2_to_se3, se3_to_se2
from ..geometry.planar import as_planar
from ..validation import as_array, as_positive, as_rng, require_sample_count
from .mocap import fit_marker_pose

__all__ = ["Terrain", "MAX_EXTENT", "height_at", "edge_distance", "step_terrain", "locate_terrain", "terrain_transform"]

MAX_EXTENT = 100.0
"""Largest coordinate (m) of a board or marker in the terrain's frame, and of its pose: a bound no
arena comes near."""


def _rows(value: Any, name: str, width: int) -> np.ndarray:
    """``value`` as an (N, width) float array; an empty sequence is no rows."""
    if isinstance(value, (tuple, list)) and len(value) == 0:
        return np.zeros((0, width))
    arr = as_array(value, name, shape=(None, width))
    if np.any(np.abs(arr) > MAX_EXTENT):
        raise ValueError(f"{name}: expected coordinates within {MAX_EXTENT:g} m, got up to {np.abs(arr).max():.3g}")
    return arr


def _as_tuples(arr: np.ndarray) -> tuple:
    return tuple(tuple(float(v) for v in row) for row in arr)


@dataclass(frozen=True)
class Terrain:
    """A terrain of boards on the floor and the MoCap markers on them; immutable and hashable.

    Parameters
    ----------
    blocks : array_like, shape (B, 5)
        One board per row, ``(x_min, x_max, y_min, y_max, height)`` in the terrain frame (m): a box
        from the floor (z = 0) up to ``height`` (> 0). Boards may overlap; the surface is the
        highest. Empty: a flat floor.
    markers : array_like, shape (M, 3), optional
        The MoCap markers fixed on the terrain, in its frame (m). :func:`locate_terrain` needs
        three or more, not on one line.
    pose : array_like, shape (3,), default (0, 0, 0)
        ``[x, y, yaw]`` of the terrain frame in the world (m, m, rad); the frame lies on the floor.

    Raises
    ------
    ValueError, TypeError
        For shapes other than these, NaN or infinity, a board with ``x_min >= x_max``,
        ``y_min >= y_max`` or ``height <= 0``, coordinates beyond :data:`MAX_EXTENT`, or a yaw
        beyond ``robokit.validation.MAX_ANGLE``.

    Notes
    -----
    The fields are kept as tuples of floats, so a terrain can key a cache
    (:func:`robokit.legged.littledog.littledog_model` compiles one model per terrain). The boards
    are the "terrain" the guide's MoCap locates (LittleDog User Guide, Sec. 1); their shapes are ours.

    Examples
    --------
    >>> terrain = Terrain([[0.3, 0.5, -0.3, 0.3, 0.02]], markers=[[0.3, 0.3, 0.02], [0.5, 0.3, 0.02],
    ...                                                          [0.3, -0.3, 0.02]])
    >>> terrain.blocks, terrain.pose, hash(terrain) == hash(Terrain(terrain.blocks, terrain.markers))
    (((0.3, 0.5, -0.3, 0.3, 0.02),), (0.0, 0.0, 0.0), True)
    """

    blocks: Any = ()
    markers: Any = ()
    pose: Any = (0.0, 0.0, 0.0)

    def __post_init__(self):
        blocks = _rows(self.blocks, "blocks", 5)
        bad = ~((blocks[:, 0] < blocks[:, 1]) & (blocks[:, 2] < blocks[:, 3]) & (blocks[:, 4] > 0))
        if bad.any():
            raise ValueError(f"blocks: expected rows (x_min, x_max, y_min, y_max, height) with x_min < x_max, "
                             f"y_min < y_max and height > 0, got {blocks[bad][0].tolist()}")
        markers = _rows(self.markers, "markers", 3)
        pose = as_planar(self.pose, "pose", shape=(3,))
        if np.any(np.abs(pose[:2]) > MAX_EXTENT):
            raise ValueError(f"pose: expected x and y within {MAX_EXTENT:g} m, got {pose[:2].tolist()}")
        object.__setattr__(self, "blocks", _as_tuples(blocks))
        object.__setattr__(self, "markers", _as_tuples(markers))
        object.__setattr__(self, "pose", tuple(float(v) for v in pose))


def _terrain(value: Any) -> Terrain:
    if not isinstance(value, Terrain):
        raise TypeError(f"terrain: expected a robokit.legged.Terrain, got {type(value).__name__}")
    return value


def _local(terrain: Terrain, xy: Any) -> np.ndarray:
    """The validated world points (..., 2) in the terrain frame."""
    p = as_array(xy, "xy")
    if p.ndim == 0 or p.shape[-1] != 2:
        raise ValueError(f"xy: expected points of shape (2,) or (..., 2), got shape {p.shape}")
    require_sample_count(p.size * max(len(terrain.blocks), 1), "xy, terrain")
    x, y, yaw = terrain.pose
    c, s = np.cos(yaw), np.sin(yaw)
    d = p - [x, y]
    return np.stack([c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]], axis=-1)


def height_at(terrain: Terrain, xy: Any) -> np.ndarray:
    """The terrain's surface height (m) under world points: the tallest board there, else the floor (0).

    Parameters
    ----------
    terrain : Terrain
    xy : array_like, shape (..., 2)
        World points (m).

    Returns
    -------
    numpy.ndarray, shape (...)
        Heights (m); a point on a board's edge counts as on the board.

    Raises
    ------
    TypeError, ValueError
        For a ``terrain`` that is not a :class:`Terrain`, or points not of shape (..., 2), not
        finite or too many.

    Examples
    --------
    >>> terrain = Terrain([[0.3, 0.5, -0.3, 0.3, 0.02], [0.4, 0.6, -0.3, 0.3, 0.03]])
    >>> height_at(terrain, [[0.0, 0.0], [0.35, 0.1], [0.45, 0.1], [0.55, 0.0]]).tolist()
    [0.0, 0.02, 0.03, 0.03]
    """
    terrain = _terrain(terrain)
    q = _local(terrain, xy)
    if not terrain.blocks:
        return np.zeros(q.shape[:-1])
    b = np.array(terrain.blocks)
    x, y = q[..., 0, None], q[..., 1, None]
    inside = (x >= b[:, 0]) & (x <= b[:, 1]) & (y >= b[:, 2]) & (y <= b[:, 3])
    return np.max(np.where(inside, b[:, 4], 0.0), axis=-1)


def edge_distance(terrain: Terrain, xy: Any) -> np.ndarray:
    """Horizontal distance (m) from world points to the nearest board edge.

    A foot centred this far from every edge stands on flat ground as long as its contact patch
    (and the error in placing it) is smaller: the foothold test of the terrain-aware walking plan.

    Parameters
    ----------
    terrain, xy
        As :func:`height_at`.

    Returns
    -------
    numpy.ndarray, shape (...)
        Distance to the nearest side of any board's rectangle, inside or outside it; ``inf``
        without boards.

    Raises
    ------
    TypeError, ValueError
        As :func:`height_at`.

    Notes
    -----
    Every side counts, even one hidden under a taller overlapping board, so the distance is never
    more than the true distance to a step (conservative). Distances do not change under the
    terrain's rigid placement, so they are computed in its frame.

    Examples
    --------
    >>> terrain = Terrain([[0.3, 0.5, -0.3, 0.3, 0.02]])
    >>> edge_distance(terrain, [[0.0, 0.0], [0.32, 0.0], [0.4, 0.0]]).round(6).tolist()
    [0.3, 0.02, 0.1]
    """
    terrain = _terrain(terrain)
    q = _local(terrain, xy)
    if not terrain.blocks:
        return np.full(q.shape[:-1], np.inf)
    b = np.array(terrain.blocks)
    x, y = q[..., 0, None], q[..., 1, None]
    dx = np.maximum(b[:, 0] - x, x - b[:, 1])          # > 0 outside the board's x range
    dy = np.maximum(b[:, 2] - y, y - b[:, 3])
    outside = np.hypot(np.maximum(dx, 0.0), np.maximum(dy, 0.0))
    inside = -np.maximum(dx, dy)                         # to the nearest side, from within
    return np.min(np.where((dx <= 0) & (dy <= 0), inside, outside), axis=-1)


def _pair(value: Any, name: str, lowest: float) -> tuple[float, float]:
    lo, hi = as_array(value, name, shape=(2,))
    if not lowest <= lo <= hi <= 1.0:
        raise ValueError(f"{name}: expected (low, high) with {lowest:g} <= low <= high <= 1 m, got {[lo, hi]}")
    return float(lo), float(hi)


#: Board lengths along the walk, and floor gaps between boards (m): drawn uniformly from these.
BOARD_LENGTHS = (0.12, 0.30)
GAP_LENGTHS = (0.08, 0.20)


def step_terrain(rng: Any = None, *, start: float = 0.3, length: float = 1.0, heights: Any = (0.01, 0.04),
                 width: float = 0.6) -> Terrain:
    """A random course of step boards across a straight walk along +x, with four MoCap markers.

    Boards and floor gaps alternate from ``x = start`` for ``length`` metres: each board
    :data:`BOARD_LENGTHS` long and ``heights`` tall (uniform), each gap :data:`GAP_LENGTHS` long,
    every board spanning the lane ``|y| <= width / 2``. So every board edge is a step up or down of
    1-4 cm (with the default ``heights``).

    Parameters
    ----------
    rng : numpy.random.Generator or int, optional
    start : float, default 0.3
        Where the first board begins (m, >= 0); LittleDog's front feet stand at x = 0.16.
    length : float, default 1.0
        How far the course runs (m, > 0); its last board may end up to one board later.
    heights : (float, float), default (0.01, 0.04)
        Lowest and tallest board (m), 0 < low <= high <= 1.
    width : float, default 0.6
        The lane's width (m, > 0; the robot's feet are 0.16 m apart).

    Returns
    -------
    Terrain
        At pose (0, 0, 0); markers at the outer corners of its first and last boards, on their tops.

    Raises
    ------
    ValueError, TypeError
        For values outside the ranges above, or an ``rng`` that is neither a Generator nor a seed.

    Notes
    -----
    Our course, not one of the LittleDog program's terrain boards (the guide describes none); it
    keeps within the ground clearance of the guide's Sec. 3.

    Examples
    --------
    >>> terrain = step_terrain(0)
    >>> len(terrain.blocks), len(terrain.markers), terrain.blocks[0][0]
    (3, 4, 0.3)
    >>> all(0.01 <= b[4] <= 0.04 for b in terrain.blocks)
    True
    """
    start = as_positive(start, "start", allow_zero=True)
    length = as_positive(length, "length")
    low, high = _pair(heights, "heights", 1e-9)
    width = as_positive(width, "width")
    for name, value in (("start", start), ("length", length), ("width", width)):
        if value > MAX_EXTENT / 2:
            raise ValueError(f"{name}: expected at most {MAX_EXTENT / 2:g} m, got {value:g}")
    gen = as_rng(rng)
    blocks, x = [], start
    while x < start + length:
        x1 = x + gen.uniform(*BOARD_LENGTHS)
        blocks.append((x, x1, -width / 2, width / 2, gen.uniform(low, high)))
        x = x1 + gen.uniform(*GAP_LENGTHS)
    first, last = blocks[0], blocks[-1]
    markers = [(first[0], first[2], first[4]), (first[0], first[3], first[4]),
               (last[1], last[2], last[4]), (last[1], last[3], last[4])]
    return Terrain(blocks, markers)


def locate_terrain(terrain: Terrain, observed: Any, visible: Any = None) -> Terrain:
    """The terrain map placed where the MoCap sees its markers: a least-squares rigid fit.

    Parameters
    ----------
    terrain : Terrain
        The map: its boards and markers in its own frame (its ``pose`` is not used).
    observed : array_like, shape (M, 3) or (N, M, 3)
        Where the MoCap saw the markers, in the world (m): one frame or N frames of a still terrain
        (:func:`robokit.legged.mocap.simulate_mocap` makes them); ignored where not visible.
    visible : array_like of bool, shape (M,) or (N, M), optional
        Which markers each frame saw (default: all).

    Returns
    -------
    Terrain
        ``terrain`` with ``pose`` set to the fitted ``[x, y, yaw]``.

    Raises
    ------
    TooFewMarkersError
        (A ``ValueError``) if fewer than three markers were seen in all.
    DegenerateFitError
        (A ``ValueError``) if the seen markers lie on one line.
    TypeError, ValueError
        For a ``terrain`` that is not a :class:`Terrain`, or shapes that do not agree with its
        markers.

    Notes
    -----
    All frames' visible markers enter one fit, :func:`robokit.legged.mocap.fit_marker_pose` (Arun
    et al. 1987, with Umeyama's reflection guard), so N frames of a still terrain average the
    marker noise down by about ``sqrt(N)``. The boards lie on the floor, so only the fit's planar
    part is kept: its translation's x and y and its rotation's yaw (LittleDog User Guide, Sec. 1:
    the MoCap system locates the terrain by its markers).

    Examples
    --------
    >>> from robokit.geometry import se2_to_se3, transform_points
    >>> board = step_terrain(0)
    >>> seen = transform_points(se2_to_se3([0.02, -0.01, 0.05]), np.array(board.markers))
    >>> np.round(locate_terrain(board, seen).pose, 6).tolist()
    [0.02, -0.01, 0.05]
    """
    terrain = _terrain(terrain)
    m = np.array(terrain.markers).reshape(-1, 3)
    if len(m) < 3:
        raise ValueError(f"terrain: expected a map with at least 3 markers to locate it by, got {len(m)}")
    obs = as_array(observed, "observed", finite=False)
    if obs.ndim not in (2, 3) or obs.shape[-2:] != m.shape:
        raise ValueError(f"observed: expected shape ({len(m)}, 3) or (N, {len(m)}, 3) for the terrain's "
                         f"{len(m)} markers, got shape {obs.shape}")
    vis = np.ones(obs.shape[:-1], bool) if visible is None else as_array(visible, "visible", shape=obs.shape[:-1],
                                                                          dtype=bool)
    frames = obs.reshape(-1, len(m), 3)
    require_sample_count(frames.size, "observed")
    T = fit_marker_pose(np.tile(m, (len(frames), 1)), frames.reshape(-1, 3), vis.reshape(-1))
    return replace(terrain, pose=tuple(float(v) for v in se3_to_se2(T)))


def terrain_transform(terrain: Terrain) -> np.ndarray:
    """``T_world_terrain`` (4, 4): the terrain frame's pose on the floor, for MoCap simulation.

    Examples
    --------
    >>> terrain_transform(Terrain(pose=(1.0, 0.0, 0.0)))[:3, 3].tolist()
    [1.0, 0.0, 0.0]
    """
    return se2_to_se3(np.array(_terrain(terrain).pose))
