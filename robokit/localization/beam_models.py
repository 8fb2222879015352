"""The likelihood-field range-finder model: how well a laser scan fits each particle's pose.

Each beam's end point is projected from the particle's sensor pose; its distance ``d`` to the
nearest occupied cell (a :class:`robokit.mapping.LikelihoodField`, precomputed once per map)
scores the beam ``p = z_hit * g(d) + z_rand / r_max``, and the beams are combined per particle
(Thrun et al. 2005, Table 6.3, Sec. 6.4). Max-range returns (``inf`` or ``>= r_max``) say nothing
about where the obstacles are and are skipped (Table 6.3 line 4; ROS amcl's
``LikelihoodFieldModel`` too). A NaN range is a broken scan and raises.

Two ways of combining the beams (``combine``):

* ``"product"``: Table 6.3 exactly, ``q = prod_k (z_hit * prob(d_k, sigma_hit) + z_rand / r_max)``
  with ``prob`` the normalised zero-mean Gaussian density; the log-weight is the sum of the logs;
* ``"ros"``: ROS amcl's ``AMCLLaser::LikelihoodFieldModel``: the Gaussian is left unnormalised
  (``g(d) = exp(-d^2 / (2 sigma_hit^2))``, so each ``p`` is at most ``z_hit + z_rand / r_max``),
  and instead of a product the particle's factor is ``1 + sum_k p_k^3``, an ad-hoc rule (the
  source says it "works well, though") that keeps one bad beam from zeroing a particle. Its
  weights are much flatter than the product's, which is why AMCL survives unmodelled obstacles.
  The end point's distance is ``max_distance`` off the map, as in ROS.

Beams are subsampled to ``max_beams`` as ROS does: every ``step = (B - 1) // (max_beams - 1)``-th
beam from the first (:func:`subsample_beams`; ROS's ``laser_max_beams`` defaults to 30).

:func:`likelihood_field_log_weights` is the vectorised model (particles x beams in one array);
:func:`likelihood_field_log_weight_readable` the same for one pose written as the table's loop,
the readable version it is tested against.

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] ROS ``amcl`` (navigation stack, ``amcl/src/amcl/sensors/amcl_laser.cpp``:
   ``LikelihoodFieldModel``; ``amcl_node.cpp``: the beam step and the max-range handling).
.. [3] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering* 24(6), 2023,
   doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..geometry import se2_compose
from ..geometry.planar import as_planar
from ..validation import as_array, as_choice, as_int, as_positive, describe, require_angles

__all__ = ["COMBINE_RULES", "subsample_beams", "valid_beams", "likelihood_field_log_weights",
           "likelihood_field_log_weight_readable"]

#: The ways of combining per-beam likelihoods: Table 6.3's product, ROS amcl's ``1 + sum p^3``.
COMBINE_RULES = ("product", "ros")


def subsample_beams(count: int, max_beams: int | None = None) -> np.ndarray:
    """Indices of the beams ROS amcl uses out of ``count``: every ``step``-th from the first.

    Parameters
    ----------
    count : int
        Beams in the scan (>= 1).
    max_beams : int, optional
        ROS's ``laser_max_beams`` (>= 2); ``None`` keeps every beam.

    Returns
    -------
    numpy.ndarray of int
        ``0, step, 2 step, ... < count`` with ``step = max(1, (count - 1) // (max_beams - 1))``:
        about ``max_beams`` beams (exactly 30 of 360 with the default).

    Notes
    -----
    ROS amcl, ``LikelihoodFieldModel`` (Thrun et al. 2005, Sec. 6.4 leave the choice open).

    Examples
    --------
    >>> len(subsample_beams(360, 30)), subsample_beams(360, 30)[:3].tolist()
    (30, [0, 12, 24])
    """
    n = as_int(count, "count", minimum=1)
    if max_beams is None:
        return np.arange(n)
    m = as_int(max_beams, "max_beams", minimum=2)
    step = max(1, (n - 1) // (m - 1))
    return np.arange(0, n, step)


def valid_beams(ranges: Any, angles: Any, r_max: float, max_beams: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The subsampled beams that count: finite returns below ``r_max``.

    Parameters
    ----------
    ranges : array_like, shape (B,)
        Ranges (m); ``inf`` marks a max-range return, NaN is refused.
    angles : array_like, shape (B,)
        Beam angles in the sensor frame (rad).
    r_max : float
        Maximum range; returns at or beyond it are skipped.
    max_beams : int, optional
        As :func:`subsample_beams`.

    Returns
    -------
    ranges, angles : numpy.ndarray
        The beams kept.

    Raises
    ------
    ValueError
        For NaN or negative ranges, non-finite angles, or mismatched lengths.

    Notes
    -----
    Thrun et al. (2005), Table 6.3 line 4 ("if z_t^k != z_max").

    Examples
    --------
    >>> r, a = valid_beams([1.0, np.inf, 9.0, 2.0], [0.0, 1.0, 2.0, 3.0], 8.0)
    >>> r.tolist(), a.tolist()
    ([1.0, 2.0], [0.0, 3.0])
    """
    r = as_array(ranges, "ranges", ndim=1, finite=False, min_size=1)
    if np.any(np.isnan(r)):
        raise ValueError("ranges: expected ranges or inf (a max-range return), got NaN")
    if np.any(r < 0):
        raise ValueError(f"ranges: expected non-negative ranges, got a minimum of {r.min()}")
    a = as_array(angles, "angles", ndim=1)
    require_angles(a, "angles")
    if a.shape != r.shape:
        raise ValueError(f"angles: expected one angle per range ({r.size}), got {a.size}")
    rm = as_positive(r_max, "r_max")
    keep = subsample_beams(r.size, max_beams)
    keep = keep[r[keep] < rm]
    return r[keep], a[keep]


def _as_field(field: Any) -> Any:
    if not (callable(getattr(field, "lookup", None)) and hasattr(field, "max_distance")):
        raise TypeError(f"field: expected a robokit.mapping.LikelihoodField (with lookup() and max_distance), "
                        f"got {describe(field)}")
    return field


def _model_args(sensor_offset: Any, sigma_hit: float, z_hit: float, z_rand: float, combine: str) -> tuple:
    offset = as_planar(sensor_offset, "sensor_offset", shape=(3,))
    s = as_positive(sigma_hit, "sigma_hit")
    zh = as_positive(z_hit, "z_hit", allow_zero=True)
    zr = as_positive(z_rand, "z_rand", allow_zero=True)
    if zh + zr == 0:
        raise ValueError("z_hit, z_rand: expected mixture weights with a positive sum, got 0 and 0")
    return offset, s, zh, zr, as_choice(combine, "combine", COMBINE_RULES)


def likelihood_field_log_weights(particles: Any, ranges: Any, angles: Any, field: Any, *,
                                 sensor_offset: Any = (0.0, 0.0, 0.0), sigma_hit: float = 0.2, z_hit: float = 0.95,
                                 z_rand: float = 0.05, r_max: float = 8.0, max_beams: int | None = None,
                                 combine: str = "product") -> np.ndarray:
    """Log-likelihood of a scan for every particle under the likelihood-field model (vectorised).

    Parameters
    ----------
    particles : array_like, shape (N, 3)
        Robot poses ``[x, y, theta]``.
    ranges, angles : array_like, shape (B,)
        The scan: ranges (``inf`` = max range, skipped) and beam angles in the sensor frame.
    field : robokit.mapping.LikelihoodField
        Distance to the nearest occupied cell (``max_distance`` off the map).
    sensor_offset : array_like, shape (3,), default (0, 0, 0)
        The sensor's mount ``[x, y, theta]`` in the robot frame.
    sigma_hit : float, default 0.2
        Standard deviation of a hit around the nearest obstacle (m) (ROS ``laser_sigma_hit``).
    z_hit, z_rand : float, default 0.95, 0.05
        Mixture weights (ROS ``laser_z_hit``, ``laser_z_rand``).
    r_max : float, default 8.0
        Maximum range (m): returns at or beyond it are skipped, and ``z_rand / r_max`` is the
        uniform density of a random return.
    max_beams : int, optional
        Use about this many evenly spaced beams (:func:`subsample_beams`); all by default.
    combine : {"product", "ros"}, default "product"
        Table 6.3's product of beam likelihoods, or ROS amcl's ``1 + sum p^3`` (module docstring).

    Returns
    -------
    numpy.ndarray, shape (N,)
        Natural-log weights (0 for every particle when no beam is valid: the scan says nothing).

    Raises
    ------
    ValueError
        For NaN or negative ranges, bad shapes, non-positive ``sigma_hit`` or ``r_max``.
    TypeError
        If ``field`` is not a likelihood field.

    Notes
    -----
    Thrun et al. (2005), Table 6.3 (``likelihood_field_range_finder_model``): the end point
    ``x + x_sens cos(theta) - y_sens sin(theta) + z cos(theta + theta_sens)`` (line 5, and y
    likewise on line 6), ``dist`` its distance to the nearest obstacle (line 7) and ``q = q *
    (z_hit prob(dist, sigma_hit) + z_random / z_max)`` (line 8).

    Examples
    --------
    >>> from robokit.mapping import OccupancyGrid, likelihood_field
    >>> prob = np.zeros((20, 20)); prob[:, 15] = 1.0                 # a wall at x = 1.5 m
    >>> field = likelihood_field(OccupancyGrid.from_probability(prob, 0.1, (0.0, 0.0)))
    >>> P = [[0.55, 1.0, 0.0], [0.25, 1.0, 0.0]]     # the 1 m beam ends on the wall, or 0.3 m short
    >>> np.round(likelihood_field_log_weights(P, [1.0], [0.0], field), 3).tolist()
    [0.642, -0.476]
    """
    P = as_planar(particles, "particles", shape=(None, 3), min_count=1)
    _as_field(field)
    offset, s, zh, zr, rule = _model_args(sensor_offset, sigma_hit, z_hit, z_rand, combine)
    r, a = valid_beams(ranges, angles, r_max, max_beams)
    if r.size == 0:
        return np.zeros(len(P))
    sensor = se2_compose(P, offset, validate=False)
    c, sn = np.cos(sensor[:, 2:3]), np.sin(sensor[:, 2:3])
    bx, by = r * np.cos(a), r * np.sin(a)                           # the end point in the sensor frame
    ends = np.empty((len(P), r.size, 2))                            # written in place: one pass each
    ex, ey, tmp = ends[..., 0], ends[..., 1], np.empty((len(P), r.size))
    np.add(np.multiply(c, bx, out=ex), sensor[:, 0:1], out=ex)
    ex -= np.multiply(sn, by, out=tmp)                              # Table 6.3, line 5
    np.add(np.multiply(sn, bx, out=ey), sensor[:, 1:2], out=ey)
    ey += np.multiply(c, by, out=tmp)                               # line 6
    d = field.lookup(ends, validate=False)                             # line 7
    g = np.exp(np.multiply(d, d, out=d) * (-0.5 / (s * s)), out=d)
    if rule == "product":
        g *= zh / math.sqrt(2.0 * math.pi * s * s)
        g += zr / float(r_max)                                      # line 8
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):   # log 0 = -inf is a zero weight
            return _finite_or_zero_weight(np.log(g, out=g).sum(axis=1))
    g *= zh                                                         # ROS: an unnormalised Gaussian
    g += zr / float(r_max)
    return _finite_or_zero_weight(np.log1p(np.einsum("ij,ij,ij->i", g, g, g)))   # ROS: p = 1 + sum pz^3


def _finite_or_zero_weight(log_w: Any) -> Any:
    """Refuse NaN and +inf log-weights (model parameters so large that the sum overflows); -inf is a zero weight."""
    if np.any(np.isnan(log_w)) or np.any(np.asarray(log_w) == np.inf):
        raise ValueError("sigma_hit, z_hit, z_rand, r_max: expected model parameters whose likelihood is finite, "
                         "got an overflow (values too large?)")
    return log_w


def likelihood_field_log_weight_readable(pose: Any, ranges: Any, angles: Any, field: Any, *,
                                          sensor_offset: Any = (0.0, 0.0, 0.0), sigma_hit: float = 0.2,
                                          z_hit: float = 0.95, z_rand: float = 0.05, r_max: float = 8.0,
                                          max_beams: int | None = None, combine: str = "product") -> float:
    """Table 6.3 for one pose, beam by beam: the readable version of :func:`likelihood_field_log_weights`.

    Parameters
    ----------
    pose : array_like, shape (3,)
        One robot pose.
    ranges : array_like, shape (B,)
        Ranges; ``inf`` (a max-range return) is skipped, NaN raises.
    angles, field, sensor_offset, sigma_hit, z_hit, z_rand, r_max, max_beams, combine
        As :func:`likelihood_field_log_weights`.

    Returns
    -------
    float
        The natural-log weight of the pose.

    Notes
    -----
    Thrun et al. (2005), Table 6.3, line by line; ROS amcl's ``LikelihoodFieldModel`` for
    ``combine="ros"``.

    Examples
    --------
    >>> from robokit.mapping import OccupancyGrid, likelihood_field
    >>> prob = np.zeros((20, 20)); prob[:, 15] = 1.0
    >>> field = likelihood_field(OccupancyGrid.from_probability(prob, 0.1, (0.0, 0.0)))
    >>> round(likelihood_field_log_weight_readable([0.55, 1.0, 0.0], [1.0], [0.0], field), 3)
    0.642
    """
    x, y, theta = as_planar(pose, "pose", shape=(3,))
    _as_field(field)
    (xs, ys, ts), s, zh, zr, rule = _model_args(sensor_offset, sigma_hit, z_hit, z_rand, combine)
    r, a = valid_beams(ranges, angles, r_max, max_beams)
    log_q, ros_sum = 0.0, 0.0
    s2 = np.float64(s) ** 2                                          # numpy floats: an overflow is inf, not a crash
    for z, theta_sens in zip(r, a):                                  # Table 6.3, line 3: for all k
        ex = x + xs * math.cos(theta) - ys * math.sin(theta) + z * math.cos(theta + ts + theta_sens)  # line 5
        ey = y + xs * math.sin(theta) + ys * math.cos(theta) + z * math.sin(theta + ts + theta_sens)  # line 6
        dist = float(field.lookup(np.array([[ex, ey]]))[0])          # line 7
        with np.errstate(all="ignore"):
            if rule == "product":
                prob = np.exp(-dist ** 2 / (2 * s2)) / np.sqrt(2 * np.pi * s2)
                log_q += np.log(zh * prob + zr / r_max)              # line 8, in logs (log 0 = -inf)
            else:
                pz = zh * np.exp(-dist ** 2 / (2 * s2)) + zr / r_max
                ros_sum += pz ** 3
    with np.errstate(all="ignore"):
        return float(_finite_or_zero_weight(log_q if rule == "product" else np.log1p(ros_sum)))
