"""Invalid areas of a 2D scan and the corridor bounds on their angle (Ge et al. 2023, Eqs. (5)-(9)).

A beam without a return within ``r_max`` is invalid (``inf``, as :class:`robokit.sim.Lidar`
reports it: data, not an error; NaN is an error). In a long corridor the invalid beams form a cone
along the corridor in each open direction; Eq. (8) bounds its angle ``theta_null`` (Eq. (9)) by
``theta_min`` and ``theta_max`` (Eqs. (6)-(7)). :mod:`robokit.mapping.corridor_scan` uses them.

Eqs. (6)-(7) checked against the geometry (width ``w``, range ``r_max``, robot at distance ``a``
from one wall): the invalid cone along the corridor spans ``arcsin(a / r_max) + arcsin((w - a) /
r_max)``. At a wall (``a -> 0``) that is ``arcsin(w / r_max)``, the paper's Eq. (6); on the middle
line it is ``2 arcsin(w / (2 r_max))``, twice the paper's Eq. (7), which is the half-angle of the cone.
For our corridor (``w`` = 2.17 m, ``r_max`` = 8 m): Eq. (7) printed gives 7.80 deg, the cone on
the middle line is 15.59 deg, and Eq. (6) 15.74 deg: the geometric range of ``theta_null`` is only
0.15 deg wide, narrower than one 1-deg beam, so Eq. (8) with geometric bounds cannot be tested on
Eq. (9)'s first-to-last beam angle (which is ``(n - 1)`` beam steps for ``n`` invalid beams) without
a resolution allowance. Door recesses also widen the cone: a 7 cm recess where a beam crosses
``r_max`` gives up to 16.76 deg, above Eq. (6). In ``robokit.sim.long_corridor()`` with the 360-beam
``robokit.sim.Lidar`` Eq. (9) measures 14 or 15 deg on the middle line (inside the printed bounds),
but 16 deg for one area at ``[15, -0.7, -60 deg]`` (0.385 m from a wall) and at ``[14.5, 0.935,
0]`` (0.15 m from a wall): the printed Eq. (8) fails there and the end rule calls it an end.
Closer than ``r_min`` (0.15 m) the near wall itself becomes a wide invalid area. :func:`theta_limits` gives the printed bounds,
:func:`theta_limits_geometric` the cone's with recesses.

References
----------
.. [1] Ge, Zhang, Wang, Hu, Wang and Jiang, "Visual-feature-assisted mobile robot localization in
   a long corridor environment", *Frontiers of Information Technology & Electronic Engineering*
   24(6), 2023, doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, as_positive

__all__ = ["EmptyScanError", "as_scan", "invalid_areas", "theta_limits", "theta_limits_geometric", "MAX_RANGE"]

#: Largest finite range a scan may hold (m): beyond it a number is a fault, not a distance.
MAX_RANGE = 1e6


class EmptyScanError(ValueError):
    """A scan without beams, or without any valid return where one is needed."""


def as_scan(ranges: Any, angles: Any) -> tuple[np.ndarray, np.ndarray]:
    """Validate a scan: ranges (``inf`` = no return) and strictly increasing beam angles spanning < 2 pi.

    Parameters
    ----------
    ranges, angles : array_like, shape (B,)
        Ranges in metres, ``inf`` where a beam has no return within the sensor's range (below
        ``MAX_RANGE`` = 1e6 m otherwise), and beam angles in radians. A range of exactly 0 is
        read as no return too (many LiDAR drivers code it so) and returned as ``inf``.

    Returns
    -------
    (ranges, angles) : numpy.ndarray, numpy.ndarray

    Raises
    ------
    EmptyScanError
        For ``B = 0``.
    ValueError
        For NaN, negative, ``-inf`` or absurd (``>= MAX_RANGE``, finite) ranges, non-finite or non-increasing angles, a span of 2 pi or
        more, or lengths that differ.

    Notes
    -----
    The raw data of Ge et al. (2023), Definition 1, Eq. (5): ``R = {(r_i, phi_i)}``.

    Examples
    --------
    >>> r, a = as_scan([1.0, np.inf], [0.0, np.pi])
    >>> r.tolist(), a.tolist()
    ([1.0, inf], [0.0, 3.141592653589793])
    """
    r = as_array(ranges, "ranges", ndim=1, finite=False)
    a = as_array(angles, "angles", ndim=1)
    if r.size == 0:
        raise EmptyScanError("ranges: expected a scan with at least one beam, got an empty array")
    if len(a) != len(r):
        raise ValueError(f"angles: expected {len(r)} angles to match ranges, got {len(a)}")
    bad = np.isnan(r) | (r < 0) | (np.isfinite(r) & (r >= MAX_RANGE))
    if bad.any():
        raise ValueError(f"ranges: expected non-negative ranges below {MAX_RANGE:g} m or inf (no return), got {r[bad][0]}")
    if np.any(r == 0):                    # many drivers code "no return" as 0: read it as inf
        r = np.where(r == 0, np.inf, r)
    if np.any(np.diff(a) <= 0) or a[-1] - a[0] >= 2 * np.pi:
        raise ValueError(f"angles: expected strictly increasing angles spanning less than 2 pi, "
                         f"got {a[0]} ... {a[-1]} (B = {len(a)})")
    return r, a


def invalid_areas(ranges: Any, angles: Any, *, validate: bool = True) -> np.ndarray:
    """The contiguous runs of invalid returns of a scan and their angles ``theta_null`` (Eq. (9)).

    Parameters
    ----------
    ranges, angles : array_like, shape (B,)
        Ranges (m; ``inf`` = an invalid return) and beam angles (rad); see :func:`as_scan`.
    validate : bool, default True
        Check the scan; ``False`` is the fast path for callers that pass it as :func:`as_scan`
        returns it.

    Returns
    -------
    numpy.ndarray, shape (K, 3)
        One row per run: ``(start_angle, end_angle, theta_null)``, the first and last invalid beam
        angles and ``theta_null = |phi_i - phi_j|`` counted counter-clockwise from start to end.
        A run crossing the end of a full-turn scan (beam ``B - 1`` to beam 0) is one area; a scan
        short of a full turn never joins its last and first beams.

    Notes
    -----
    Ge et al. (2023), Eq. (9). ``theta_null`` is the angle from the first to the last invalid
    beam, so a run of ``n`` beams gives ``(n - 1)`` beam steps: about one step less than the cone.
    An all-invalid scan is one area from the first to the last beam.

    Examples
    --------
    >>> ang = np.deg2rad(np.arange(0.0, 360.0, 45.0))
    >>> r = np.array([np.inf, 1, 1, 1, np.inf, 1, np.inf, np.inf])
    >>> np.round(np.rad2deg(invalid_areas(r, ang)), 3).tolist()
    [[180.0, 180.0, 0.0], [270.0, 0.0, 90.0]]
    """
    r, a = as_scan(ranges, angles) if validate else (ranges, angles)
    bad = ~np.isfinite(r)
    if bad.all():
        return np.array([[a[0], a[-1], a[-1] - a[0]]])
    if not bad.any():
        return np.zeros((0, 3))
    step = np.median(np.diff(a)) if len(a) > 1 else 2 * np.pi
    full_turn = abs(a[0] + 2 * np.pi - a[-1] - step) < 0.5 * step     # the last beam's neighbour is the first
    # walk from a valid beam, so no run wraps in that order; a scan short of a full turn has a blind
    # sector between its last and first beams, so a run never continues across it
    shift = int(np.argmin(bad)) if full_turn else 0
    b = np.roll(bad, -shift).astype(np.int8)
    edges = np.diff(np.concatenate([[0], b, [0]]))
    starts = (np.flatnonzero(edges == 1) + shift) % len(r)
    ends = (np.flatnonzero(edges == -1) - 1 + shift) % len(r)
    order = np.argsort(starts)
    starts, ends = starts[order], ends[order]
    theta = np.mod(a[ends] - a[starts], 2 * np.pi)  # Eq. (9)
    return np.column_stack([a[starts], a[ends], theta])


def theta_limits(width: float, r_max: float) -> tuple[float, float]:
    """``(theta_min, theta_max)`` of the invalid-area angle as printed, Eqs. (7) and (6).

    Parameters
    ----------
    width, r_max : float
        Corridor width and the LiDAR's maximum range (m), ``width <= r_max``.

    Returns
    -------
    (theta_min, theta_max) : float, float
        ``arcsin(w / (2 r_max))`` and ``arcsin(w / r_max)`` (radians).

    Notes
    -----
    Ge et al. (2023), Definition 2, Eqs. (6)-(7) as printed. Eq. (7) is the half-angle of the
    invalid cone on the middle line (see the module notes and :func:`theta_limits_geometric`).

    Examples
    --------
    >>> [round(float(np.rad2deg(t)), 3) for t in theta_limits(2.17, 8.0)]
    [7.795, 15.739]
    """
    w, rm = as_positive(width, "width"), as_positive(r_max, "r_max")
    if w > rm:
        raise ValueError(f"width: expected a width no larger than r_max = {rm}, got {w}")
    return float(np.arcsin(w / (2 * rm))), float(np.arcsin(w / rm))  # Eqs. (7), (6)


def theta_limits_geometric(width: float, r_max: float, recess: float = 0.0) -> tuple[float, float]:
    """``(theta_min, theta_max)`` of the invalid cone in a corridor of parallel walls (ours).

    Parameters
    ----------
    width, r_max : float
        Corridor width and the LiDAR's maximum range (m), ``width + 2 recess <= r_max``.
    recess : float, default 0
        Door-frame depth ``d_da`` (m): a recess where a beam leaves ``r_max`` widens the cone.

    Returns
    -------
    (theta_min, theta_max) : float, float
        ``2 arcsin(w / (2 r_max))`` on the middle line and ``arcsin(d_da / r_max) + arcsin((w +
        d_da) / r_max)`` at a wall (``arcsin(w / r_max)`` without recesses).

    Notes
    -----
    At distance ``a`` from one wall the beams with no return within ``r_max`` span
    ``arcsin(a / r_max) + arcsin((w - a) / r_max)`` (convex in ``a``: least on the middle line,
    most at a wall). The maximum without recesses equals Ge et al. (2023), Eq. (6); the minimum is
    twice their Eq. (7). A recess on both walls at the ``r_max`` crossings adds ``d_da`` to both
    terms.

    Examples
    --------
    >>> [round(float(np.rad2deg(t)), 3) for t in theta_limits_geometric(2.17, 8.0)]
    [15.59, 15.739]
    >>> [round(float(np.rad2deg(t)), 3) for t in theta_limits_geometric(2.17, 8.0, recess=0.07)]
    [15.59, 16.762]
    """
    lo, _ = theta_limits(width, r_max)
    w, rm = width, r_max
    dda = as_positive(recess, "recess", allow_zero=True)
    if w + 2 * dda > rm:
        raise ValueError(f"recess: expected width + 2 recess <= r_max = {rm}, got {dda}")
    return 2 * lo, float(np.arcsin(dda / rm) + np.arcsin((w + dda) / rm))
