"""Corridor analysis from one 2D scan: wall distances, width and middle-line conditions, invalid areas.

Ge et al. (2023), Sec. 3.1, Eqs. (1)-(9): a robot in a long corridor measures the shortest
distances ``d_L``, ``d_R`` to the left and right walls (Eq. (1): they add up to the width; Eqs. (2),
(3): beside facing or staggered door recesses they add up to more), is on the middle line when
``|d_L - d_R| <= e4`` (Eq. (4)), and knows it is in a corridor when the angle ``theta_null`` of an
invalid area of the scan (beams without a return within ``r_max``, Eq. (9)) lies between
``theta_min`` and ``theta_max`` (Eqs. (6)-(8)); exactly one such area means the end of the corridor.

Frames: the scan is in the robot (sensor) frame, x forward, y left, beam angles counter-clockwise
from forward (as :attr:`robokit.sim.Lidar.angles`); an invalid return is ``inf`` (data, not an
error); NaN and negative ranges are errors. The corridor *axis* is an angle in that frame, taken
modulo pi in ``[-pi/2, pi/2)`` (the corridor direction nearer the robot's forward axis); "left" is
the side of the axis at ``axis + pi/2``. Robokit writes poses ``[x, y, theta]`` where the paper
writes ``(x, z, theta)``.

The invalid areas and Eqs. (6)-(7) (and where the printed bounds disagree with the geometry of
our corridor) are in :mod:`robokit.mapping.corridor_areas`; :func:`corridor_state` reports the
measured ``theta_null`` of every area beside the bounds it used.

References
----------
.. [1] Ge, Zhang, Wang, Hu, Wang and Jiang, "Visual-feature-assisted mobile robot localization in
   a long corridor environment", *Frontiers of Information Technology & Electronic Engineering*
   24(6), 2023, doi:10.1631/FITEE.2200208.
.. [2] R. O. Duda and P. E. Hart, "Use of the Hough transformation to detect lines and curves in
   pictures", *Communications of the ACM* 15(1), 11-15, 1972.
.. [3] G. H. Golub and C. F. Van Loan, "An analysis of the total least squares problem", *SIAM
   Journal on Numerical Analysis* 17(6), 883-893, 1980.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..geometry import wrap_angle
from ..validation import as_choice, as_finite_scalar, as_positive
from .corridor_areas import EmptyScanError, as_scan, invalid_areas, theta_limits, theta_limits_geometric

__all__ = ["NoWallError", "CorridorState", "corridor_axis", "corridor_axis_readable", "wall_distances", "door_sides", "width_condition",
           "middle_line_condition", "corridor_state", "EmptyScanError", "as_scan", "invalid_areas", "theta_limits",
           "theta_limits_geometric"]

WIDTH_CASES = ("corridor", "facing doors", "staggered doors")
_FOOT = 7                 # beams nearest a wall's normal that measure its distance
_FOOT_CONE = np.deg2rad(15.0)   # ... if within this angle of the normal (a sparse scan's are not)
_BIN = 0.02               # Hough bin (m) of the lateral coordinate
_VOTE_RANGE = 100.0       # only returns this near (m) vote for the axis: the tables stay under 10,000 bins
_BAND = 0.05              # half-width (m) of a wall's inlier band for the line fit
_CANDIDATES = np.deg2rad(np.arange(-90.0, 90.0, 1.0))      # the exhaustive vote's directions, 1 deg apart
_COARSE = np.deg2rad(np.arange(-90.0, 90.0, 5.0))          # the vote's first pass: every 5 deg ...
_FINE = np.deg2rad(np.arange(-4.0, 5.0, 1.0))              # ... then 1 deg apart around the best ...
_KEEP = 3                                                  # ... three of them


class NoWallError(ValueError):
    """No valid return within 45 deg of a wall's normal: that wall is farther than ``r_max``."""


def corridor_axis(ranges: Any, angles: Any) -> float:
    """Direction of the corridor in the robot frame, from the wall points of a scan (modulo pi).

    Parameters
    ----------
    ranges, angles : array_like, shape (B,)
        Ranges (m; ``inf`` = no return) and beam angles (rad); see :func:`as_scan`.

    Returns
    -------
    float
        Axis angle in ``[-pi/2, pi/2)``; the robot's heading error from the corridor direction
        nearer its forward axis is ``-axis``.

    Raises
    ------
    EmptyScanError
        For fewer than 3 valid returns.

    Notes
    -----
    Ge et al. (2023) assume the robot can align with the corridor (Sec. 3.1, unnumbered) without
    saying how; this is ours. A Hough vote (Duda & Hart 1972), coarse to fine (36 directions 5 deg
    apart, then 9 directions 1 deg apart around each of the best three;
    :func:`corridor_axis_readable` votes over all 180),
    scores each direction by how sharply the points' coordinates across it pile up (the sum of the
    squared counts of 2 cm bins): two parallel walls give two sharp piles. Only returns within
    100 m vote (farther ones, sentinel values included, cannot help place a 2 cm bin and would
    size its table by their distance). Then a total-least-squares
    fit (Golub & Van Loan 1980) of the points within 5 cm of the strongest pile on each side, with
    a common direction and one offset per wall (the largest eigenvector of the pooled scatter).
    Door recesses (7 cm behind the wall) fall outside the bands. Close to an end wall its pile
    competes with the side walls' (on ``robokit.sim.long_corridor()`` it lost in every check, down to
    0.3 m from the end at 40 deg off the axis, where the estimate was within 0.02 deg).

    Examples
    --------
    >>> ang = 2 * np.pi * np.arange(360) / 360
    >>> rel = ang - np.deg2rad(10)                    # a corridor 10 deg left of forward
    >>> r = np.where(np.sin(rel) > 0, 1.0 / np.abs(np.sin(rel) + 1e-300), 1.2 / np.abs(np.sin(rel) + 1e-300))
    >>> r[r > 8] = np.inf
    >>> round(float(np.rad2deg(corridor_axis(r, ang))), 3)
    10.0
    """
    r, a = as_scan(ranges, angles)
    return _axis(r, a)


def _vote(pts: np.ndarray, candidates: np.ndarray) -> np.ndarray:
    """Hough score of each candidate direction: the sum of squared counts of its 2 cm lateral bins."""
    s = pts @ np.stack([-np.sin(candidates), np.cos(candidates)])     # (N, C) lateral coordinates
    lo = np.floor(s.min() / _BIN)
    bins = (np.floor(s / _BIN) - lo).astype(np.int64)
    nb = int(bins.max()) + 1
    counts = np.bincount((bins + nb * np.arange(len(candidates))).ravel(), minlength=nb * len(candidates))
    counts = counts.reshape(len(candidates), nb)
    return np.einsum("ij,ij->i", counts, counts)


def _wall_points(r: np.ndarray, a: np.ndarray) -> np.ndarray:
    ok = r <= _VOTE_RANGE                 # farther returns (sentinels too) would only widen the tables
    if np.count_nonzero(ok) < 3:
        raise EmptyScanError(f"ranges: expected at least 3 valid returns within {_VOTE_RANGE:g} m to find the "
                             f"corridor axis, got {ok.sum()}")
    return r[ok, None] * np.column_stack([np.cos(a[ok]), np.sin(a[ok])])


def corridor_axis_readable(ranges: Any, angles: Any) -> float:
    """The readable reference of :func:`corridor_axis`: the Hough vote over all 180 directions.

    Parameters
    ----------
    ranges, angles : array_like, shape (B,)
        As :func:`corridor_axis`.

    Returns
    -------
    float
        Axis angle in ``[-pi/2, pi/2)``, found as :func:`corridor_axis` finds it but voting over every
        direction 1 deg apart in one pass instead of coarse to fine (same fit afterwards).

    Raises
    ------
    EmptyScanError
        For fewer than 3 valid returns.

    Notes
    -----
    Ge et al. (2023), Sec. 3.1 (the robot aligns with the corridor; how is ours); the vote of Duda &
    Hart (1972) and the total-least-squares fit of Golub & Van Loan (1980) as in :func:`corridor_axis`.

    Examples
    --------
    >>> ang = 2 * np.pi * np.arange(360) / 360
    >>> rel = ang - np.deg2rad(10)
    >>> r = np.where(np.sin(rel) > 0, 1.0 / np.abs(np.sin(rel) + 1e-300), 1.2 / np.abs(np.sin(rel) + 1e-300))
    >>> r[r > 8] = np.inf
    >>> round(float(np.rad2deg(corridor_axis_readable(r, ang))), 3)
    10.0
    """
    r, a = as_scan(ranges, angles)
    pts = _wall_points(r, a)
    return _fit_axis(pts, float(_CANDIDATES[np.argmax(_vote(pts, _CANDIDATES))]))


def _axis(r: np.ndarray, a: np.ndarray) -> float:
    """:func:`corridor_axis` of a scan :func:`as_scan` has checked: the vote coarse to fine, then the fit."""
    pts = _wall_points(r, a)
    coarse = _COARSE[np.argsort(-_vote(pts, _COARSE), kind="stable")[:_KEEP]]
    fine = (coarse[:, None] + _FINE).ravel()            # a wall 2.5 deg off the 5 deg grid can rank low
    return _fit_axis(pts, float(fine[np.argmax(_vote(pts, fine))]))


def _fit_axis(pts: np.ndarray, axis: float) -> float:
    """Total least squares of the two walls' inliers around the voted ``axis`` (twice), modulo pi."""
    for _ in range(2):                                                           # TLS refinement
        s = pts @ np.array([-np.sin(axis), np.cos(axis)])
        scatter = np.zeros((2, 2))
        for side in (s > 0, s < 0):
            if np.count_nonzero(side) < 3:
                continue
            across = s[side]
            b = np.floor(across / _BIN).astype(np.int64)
            first = b.min()
            peak = (np.argmax(np.bincount(b - first)) + first + 0.5) * _BIN      # the fullest bin (lowest on a tie)
            inl = pts[side][np.abs(across - peak) < _BAND]
            if len(inl) >= 2:
                c = inl - inl.mean(axis=0)
                scatter += c.T @ c
        if not scatter.any():
            break
        u = np.linalg.eigh(scatter)[1][:, -1]
        axis = float(np.arctan2(u[1], u[0]))
    return float(wrap_angle(2 * axis, validate=False) / 2)        # modulo pi, in [-pi/2, pi/2)


def _as_heading(heading: Any) -> float:
    """A given corridor axis (rad), within +-2 pi: a larger one is degrees by mistake, or so large
    that the beams' angles to the wall normals lose their precision."""
    value = as_finite_scalar(heading, "heading")
    if abs(value) > 2 * np.pi:
        raise ValueError(f"heading: expected the corridor axis in radians, within [-2 pi, 2 pi], got {value:g}")
    return value


def wall_distances(ranges: Any, angles: Any, *, heading: Any = None) -> tuple[float, float]:
    """Shortest distances ``(d_L, d_R)`` from the sensor to the left and right walls (Eq. (1)).

    Parameters
    ----------
    ranges, angles : array_like, shape (B,)
        Ranges (m; ``inf`` = no return) and beam angles (rad); see :func:`as_scan`.
    heading : float, optional
        Corridor axis in the robot frame (radians, see :func:`corridor_axis`); ``None`` estimates
        it from the scan. ``0.0`` takes the robot's own left and right, as the paper does for a
        robot aligned with the corridor.

    Returns
    -------
    (d_L, d_R) : float, float
        Metres.

    Raises
    ------
    NoWallError
        If fewer than 4 of the 7 beams nearest a wall's normal have a return within 15 deg of it
        (a sparse scan's nearest beams may point away from the wall: they never give a distance).
    ValueError
        For a bad scan (:func:`as_scan`) or a ``heading`` that is not finite or beyond +-2 pi.

    Notes
    -----
    Ge et al. (2023), Eq. (1): "the shortest distance between the left wall and the center of the
    laser sensor". Ours: the distance to a wall is its perpendicular distance, measured at the foot
    of the perpendicular: the median, over the 7 beams nearest the wall's normal (``axis +- pi/2``),
    of each return's coordinate along that normal, ``r cos(phi - normal)``. On a plain wall every
    one of them equals the perpendicular distance (the nearest point of a line, whatever the
    heading); beside a door it is the recessed distance, as Eqs. (2)-(3) expect; the median keeps
    one spurious or noisy beam from setting it; and neither the far wall seen at a slant, nor an
    end wall, nor a door frame's corner near the foot (which the minimum range would pick, neither
    wall nor recess) enters it.

    Examples
    --------
    >>> ang = 2 * np.pi * np.arange(360) / 360
    >>> r = np.where(np.sin(ang) > 0, 0.8 / np.abs(np.sin(ang) + 1e-300), 1.37 / np.abs(np.sin(ang) + 1e-300))
    >>> r[r > 8] = np.inf
    >>> tuple(round(d, 9) for d in wall_distances(r, ang))
    (0.8, 1.37)
    """
    r, a = as_scan(ranges, angles)
    axis = _axis(r, a) if heading is None else _as_heading(heading)
    return _wall_distances(r, a, axis)


def _wall_distances(r: np.ndarray, a: np.ndarray, axis: float) -> tuple[float, float]:
    """:func:`wall_distances` of a checked scan and axis."""
    out = []
    for name, normal in (("left", axis + np.pi / 2), ("right", axis - np.pi / 2)):
        off = wrap_angle(a - normal, validate=False)
        foot = np.argsort(np.abs(off), kind="stable")[:_FOOT]
        along = np.where(np.abs(off[foot]) <= _FOOT_CONE, r[foot] * np.cos(off[foot]), np.inf)
        if np.count_nonzero(np.isfinite(along)) < (_FOOT + 2) // 2:
            raise NoWallError(f"ranges: expected returns on most of the {_FOOT} beams nearest the {name} wall's "
                              f"normal, got {np.count_nonzero(np.isfinite(along))} within {np.rad2deg(_FOOT_CONE):g} "
                              "deg of it")
        out.append(float(np.median(along)))
    return out[0], out[1]


def door_sides(ranges: Any, angles: Any, *, heading: Any = None, recess: float = 0.07) -> tuple[bool, bool]:
    """Whether the robot is beside a door recess on its left and on its right, from the scan.

    Parameters
    ----------
    ranges, angles : array_like, shape (B,)
        Ranges (m; ``inf`` = no return) and beam angles (rad); see :func:`as_scan`.
    heading : float, optional
        Corridor axis in the robot frame (see :func:`wall_distances`); ``None`` estimates it.
    recess : float, default 0.07
        Door-frame depth ``d_da`` (m).

    Returns
    -------
    (left, right) : bool, bool

    Raises
    ------
    NoWallError, ValueError
        As :func:`wall_distances`.

    Notes
    -----
    Ours; it settles the case Ge et al. (2023) leave open after Eq. (4): when Eq. (3) holds, which
    side is at the door. A side is at a door when its shortest distance (:func:`wall_distances`)
    exceeds the plain wall's distance by more than ``recess / 2``. The plain wall is the nearest
    line on that side: the 10th percentile of the returns' distances along the wall normal within
    60 deg of it (a door seen from its middle leaves the plain wall on both sides of it in that
    sector; an end wall farther than ~1.9 m stays out of it).

    Examples
    --------
    >>> from robokit.sim import Lidar, long_corridor
    >>> lidar = Lidar()
    >>> door_sides(lidar.scan(long_corridor(), [25.5, 0.06, 0.0]), lidar.angles)   # a 2.25 m door, left
    (True, False)
    """
    r, a = as_scan(ranges, angles)
    axis = _axis(r, a) if heading is None else _as_heading(heading)
    dda = as_positive(recess, "recess", allow_zero=True)
    return _door_sides(r, a, axis, dda, _wall_distances(r, a, axis))


def _door_sides(r: np.ndarray, a: np.ndarray, axis: float, dda: float, d: tuple[float, float]) -> tuple[bool, bool]:
    """:func:`door_sides` of a checked scan, axis and recess, given the wall distances ``d``."""
    out = []
    for dist, normal in zip(d, (axis + np.pi / 2, axis - np.pi / 2)):
        off = wrap_angle(a - normal, validate=False)
        near = (np.abs(off) <= np.pi / 3) & np.isfinite(r)
        level = np.percentile(r[near] * np.cos(off[near]), 10) if near.any() else dist
        out.append(bool(dist - level > dda / 2))
    return out[0], out[1]


def width_condition(d_l: float, d_r: float, width: float, *, recess: float = 0.07, tol: float = 0.03) -> str | None:
    """Which of Ge et al.'s width conditions, Eqs. (1), (2), (3), the distances satisfy.

    Parameters
    ----------
    d_l, d_r : float
        Shortest distances to the left and right walls (m).
    width : float
        Corridor width ``w_corridor`` (m).
    recess : float, default 0.07
        Door-frame depth ``d_da`` (m).
    tol : float, default 0.03
        The tiny errors ``e1 = e2 = e3`` (m); below ``recess / 2`` the three cases cannot overlap.

    Returns
    -------
    {"corridor", "facing doors", "staggered doors"} or None
        Eq. (1), (2) or (3); ``None`` when none holds (not in a plain stretch of the corridor).

    Notes
    -----
    Ge et al. (2023), Eqs. (1)-(3); the nearest case wins if ``tol`` lets two overlap.

    Examples
    --------
    >>> width_condition(1.085, 1.085, 2.17), width_condition(1.155, 1.085, 2.17), width_condition(1.2, 1.2, 2.17)
    ('corridor', 'staggered doors', None)
    """
    dl, dr = as_positive(d_l, "d_l"), as_positive(d_r, "d_r")
    w, dda = as_positive(width, "width"), as_positive(recess, "recess", allow_zero=True)
    return _width_case(dl, dr, w, dda, as_positive(tol, "tol", allow_zero=True))


def _width_case(dl: float, dr: float, w: float, dda: float, e: float) -> str | None:
    """:func:`width_condition` of checked distances, width, recess and tolerance."""
    err = np.abs(dl + dr - np.array([w, w + 2 * dda, w + dda]))   # Eqs. (1), (2), (3)
    k = int(np.argmin(err))
    return WIDTH_CASES[k] if err[k] <= e else None


def middle_line_condition(d_l: float, d_r: float, *, tol: float = 0.04, width: Any = None,
                          recess: float = 0.07, width_tol: float = 0.03,
                          door: Any = None) -> tuple[bool, float, str]:
    """Eq. (4), ``|d_L - d_R| <= e4``, after the rule that removes a door recess from its side.

    Parameters
    ----------
    d_l, d_r : float
        Shortest distances to the left and right walls (m).
    tol : float, default 0.04
        ``e4`` (m); the lateral offset is then within ``tol / 2`` of the middle line.
    width : float, optional
        Corridor width; with it, the width case (:func:`width_condition`) decides the door sides.
        Without it Eq. (4) is applied to the raw distances.
    recess, width_tol : float
        Door-frame depth ``d_da`` and ``e1 = e2 = e3`` (m).
    door : {None, "left", "right"}
        Which side is at the door when Eq. (3) holds, if known (:func:`door_sides`); ``None``
        takes the side with the longer distance.

    Returns
    -------
    (holds, lateral_offset, doors) : bool, float, str
        Whether Eq. (4) holds; the robot's offset from the middle line, positive to the left (m);
        and where the doors are: ``"none"``, ``"both"``, ``"left"`` or ``"right"``.

    Raises
    ------
    TypeError, ValueError
        For a distance, tolerance, recess or width that is not a finite non-negative number (the
        distances and the width positive), or a ``door`` other than ``None``, ``"left"`` and
        ``"right"`` (whichever case the distances fit).

    Notes
    -----
    Ge et al. (2023), Eq. (4) and the rule after it: with Eqs. (1)-(3) the robot "decides whether
    d_L or d_R equals 0.5 w_corridor or 0.5 w_corridor + d_da". Eq. (1) or (2): no door or a door on
    each side, the offset is ``(d_R - d_L) / 2``. Eq. (3): one door, on the side ``door`` names or,
    without it, on the side with the longer distance (ours: the paper does not say how; that guess
    is right whenever the robot is within ``recess / 2`` of the middle line, and farther out it errs
    by ``recess``: a robot 6 cm left of the line beside a left door would believe itself 1 cm
    right of it), and ``recess`` is removed from that side before Eq. (4).

    Examples
    --------
    >>> middle_line_condition(1.155, 1.085, width=2.17)          # a door on the left, centred
    (True, 0.0, 'left')
    >>> middle_line_condition(1.155, 1.085)                      # raw Eq. (4) sees 7 cm
    (False, -0.035, 'none')
    """
    dl, dr = as_positive(d_l, "d_l"), as_positive(d_r, "d_r")
    e4 = as_positive(tol, "tol", allow_zero=True)
    dda = as_positive(recess, "recess", allow_zero=True)
    e_w = as_positive(width_tol, "width_tol", allow_zero=True)
    w = None if width is None else as_positive(width, "width")
    side = None if door is None else as_choice(door, "door", ["left", "right"])
    return _middle_line(dl, dr, e4, w, dda, e_w, side)


def _middle_line(dl: float, dr: float, e4: float, w: float | None, dda: float, e_w: float,
                 door: str | None) -> tuple[bool, float, str]:
    """:func:`middle_line_condition` of checked arguments (``w``: the width or ``None``)."""
    doors = "none"
    if w is not None:
        case = _width_case(dl, dr, w, dda, e_w)
        if case == "facing doors":
            doors = "both"
        elif case == "staggered doors":
            doors = door or ("left" if dl > dr else "right")
            dl, dr = (dl - dda, dr) if doors == "left" else (dl, dr - dda)
    holds = bool(abs(dl - dr) <= e4 + 1e-12)                  # Eq. (4)
    return holds, round((dr - dl) / 2, 12), doors


@dataclasses.dataclass(frozen=True)
class CorridorState:
    """What one scan says about the corridor (Ge et al. 2023, Sec. 3.1).

    Attributes
    ----------
    in_corridor : bool
        At least one invalid area satisfies Eq. (8).
    at_end : bool
        Exactly one does (the paper's end-of-corridor rule).
    n_areas : int
        How many invalid areas satisfy Eq. (8).
    areas : numpy.ndarray, shape (K, 3)
        Every invalid area, ``(start, end, theta_null)`` (:func:`invalid_areas`).
    theta_bounds : (float, float)
        The bounds of Eq. (8) used.
    axis : float or None
        Corridor direction in the robot frame (:func:`corridor_axis`); ``-axis`` is the heading error.
    d_l, d_r : float
        Shortest wall distances (``inf`` when a wall was not seen).
    width_case : str or None
        :func:`width_condition`.
    middle : bool
        Eq. (4) (after the door rule).
    lateral_offset : float or None
        Offset from the middle line, positive to the left (``None`` without both walls).
    doors : str
        Door sides from the width case.
    """

    in_corridor: bool
    at_end: bool
    n_areas: int
    areas: np.ndarray
    theta_bounds: tuple
    axis: float | None
    d_l: float
    d_r: float
    width_case: str | None
    middle: bool
    lateral_offset: float | None
    doors: str


def corridor_state(ranges: Any, angles: Any, width: float, r_max: float, *, bounds: str = "paper",
                   recess: float = 0.07, tol: float = 0.04, width_tol: float = 0.03,
                   validate: bool = True) -> CorridorState:
    """Analyse one scan: invalid areas against Eq. (8), the end rule, wall distances and Eq. (4).

    Parameters
    ----------
    ranges, angles : array_like, shape (B,)
        Ranges (m; ``inf`` = no return) and beam angles (rad); see :func:`as_scan`.
    width, r_max : float
        Corridor width and LiDAR range (m).
    bounds : {"paper", "geometric"}, default "paper"
        Eq. (8)'s bounds: :func:`theta_limits` as printed, or :func:`theta_limits_geometric` (with
        ``recess``) widened by Eq. (9)'s quantisation: a first-to-last beam angle lies within two
        beam steps below the cone, never above.
    recess, tol, width_tol : float
        ``d_da``, ``e4`` and ``e1 = e2 = e3`` (m).
    validate : bool, default True
        Check the scan, ``recess``, ``tol`` and ``width_tol``; ``False`` is the fast path for a loop
        over scans (the moving strategy) that passes a scan as :func:`as_scan` returns it and checked
        floats (a raw scan is then read as it is: a 0 is not turned into ``inf``, a NaN is not
        refused). ``width``, ``r_max`` and ``bounds`` are checked either way.

    Returns
    -------
    CorridorState

    Notes
    -----
    Ge et al. (2023), Eqs. (1)-(4), (8), (9) and the end rule after Eq. (9); the door side of
    Eq. (3) from :func:`door_sides`. A scan where a wall
    has no return (:class:`NoWallError`) or too few points for the axis is still analysed for its
    invalid areas; its distances are ``inf`` and ``lateral_offset`` is ``None``.

    Examples
    --------
    >>> from robokit.sim import Lidar, long_corridor
    >>> lidar = Lidar()
    >>> s = corridor_state(lidar.scan(long_corridor(), [18.0, 0.0, 0.0]), lidar.angles, 2.17, 8.0)
    >>> s.in_corridor, s.at_end, s.n_areas, np.rad2deg(s.areas[:, 2]).round(3).tolist()
    (True, False, 2, [14.0, 15.0])
    """
    as_choice(bounds, "bounds", ["paper", "geometric"])
    if validate:
        r, a = as_scan(ranges, angles)
        recess = as_positive(recess, "recess", allow_zero=True)
        tol = as_positive(tol, "tol", allow_zero=True)
        width_tol = as_positive(width_tol, "width_tol", allow_zero=True)
    else:
        r, a = ranges, angles
    lo, hi = theta_limits(width, r_max) if bounds == "paper" else theta_limits_geometric(width, r_max, recess)
    if bounds == "geometric" and len(a) > 1:
        lo -= 2 * float(np.min(np.diff(a)))
    areas = invalid_areas(r, a, validate=False)
    n = int(np.sum((areas[:, 2] > lo) & (areas[:, 2] < hi)))      # Eq. (8)
    axis = None
    try:
        axis = _axis(r, a)
        d_l, d_r = _wall_distances(r, a, axis)
        at_door = _door_sides(r, a, axis, recess, (d_l, d_r))
    except (EmptyScanError, NoWallError):
        return CorridorState(n > 0, n == 1, n, areas, (lo, hi), axis, np.inf, np.inf, None, False, None, "none")
    w = float(width)                     # theta_limits checked it above, on either path
    case = _width_case(d_l, d_r, w, recess, width_tol)
    hint = "left" if at_door == (True, False) else "right" if at_door == (False, True) else None
    middle, offset, doors = _middle_line(d_l, d_r, tol, w, recess, width_tol, hint)
    return CorridorState(n > 0, n == 1, n, areas, (lo, hi), axis, d_l, d_r, case, middle, offset, doors)
