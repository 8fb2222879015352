"""Particle-filter machinery: weights, resampling, KLD sample counts and the paper's ellipse start.

The pieces of Monte-Carlo localization that do not know about maps or sensors (the filter itself
is :class:`robokit.localization.mcl.MonteCarloLocalizer`):

* :func:`normalise_log_weights` turns log-likelihoods into weights that sum to one and is never
  NaN: when every weight is zero (all ``-inf``) it falls back to uniform weights and says so;
* :func:`low_variance_resample` is Thrun et al.'s low-variance (systematic) sampler (Table 4.4):
  one random number, ``M`` evenly spaced pointers; each particle is drawn ``floor(M w)`` or
  ``ceil(M w)`` times, unbiased and with far less variance than drawing ``M`` times at random;
* :func:`kld_sample_count` is the number of particles that KLD-sampling (Fox 2003; Thrun et al.
  Table 8.4, line 15) asks for once the samples occupy ``k`` histogram bins, and
  :func:`kld_resample` the whole adaptive resampling step (vectorised: it draws the maximum
  number of candidates and keeps the shortest prefix that satisfies the bound, which is exactly
  where the sequential loop of Table 8.4 stops);
* :func:`weighted_pose_mean` is the estimate (a circular mean for the heading);
* :func:`sample_ellipse_poses` and :func:`ellipse_weights` are Ge et al. (2023)'s start of the
  fine localization: poses spread uniformly inside an ellipse around the pose of the retrieved
  keyframe, weighted by the Gaussian of Eq. (19) (Sec. 3.4, Fig. 10, Algorithm 1 lines 2-3).

Poses are robokit's ``[x, y, theta]``; the paper writes ``(x, z, theta)`` for the corridor's
floor plane and ``(x, y)`` in Eq. (19).

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] D. Fox, "Adapting the sample size in particle filters through KLD-sampling",
   *International Journal of Robotics Research* 22(12), 2003, pp. 985-1003.
.. [3] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering* 24(6), 2023,
   doi:10.1631/FITEE.2200208.
.. [4] ROS ``amcl`` (navigation stack, ``amcl/src/amcl/pf/pf.c``: ``pf_resample_limit``,
   ``pf_update_resample``; ``pf_kdtree.c``: the histogram bins).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from scipy.special import logsumexp

from ..geometry import wrap_angle
from ..geometry.planar import as_planar
from ..validation import (as_array, as_callable, as_finite_scalar, as_int, as_positive,
                          as_rng, describe, require_angles, require_finite_result, require_sample_count)

__all__ = ["NormalisedWeights", "normalise_log_weights", "low_variance_resample", "kld_sample_count",
           "kld_resample", "pose_bins", "weighted_pose_mean", "sample_ellipse_poses", "ellipse_weights",
           "KLD_Z_99", "ROS_KLD_BIN_SIZE"]

#: Upper 0.99 quantile of the standard normal, ``z_{1-delta}`` for ``delta = 0.01`` (Fox 2003):
#: ``scipy.stats.norm.ppf(0.99)`` written out (a test holds them equal), so importing robokit does
#: not import scipy.stats (half a second).
KLD_Z_99 = 2.3263478740408408

#: Most histogram bins :func:`kld_sample_count` accepts (far beyond any particle count).
MAX_BINS = 10 ** 9

#: ROS amcl's KLD histogram bins (``pf_kdtree.c``): 0.5 m in x and y, 10 degrees in heading.
ROS_KLD_BIN_SIZE = (0.5, 0.5, float(np.deg2rad(10.0)))


class NormalisedWeights(NamedTuple):
    """Weights that sum to one, with what the normalisation learned on the way.

    ``weights`` (N,); ``log_mean`` the log of the mean of the exponentiated inputs
    (``log((1/N) sum exp(log_w))``, ``-inf`` when all are zero): augmented MCL's ``w_avg``;
    ``degenerate`` True when every input weight was zero and uniform weights were returned.

    Examples
    --------
    >>> NormalisedWeights(np.array([1.0]), 0.0, False).degenerate
    False
    """

    weights: np.ndarray
    log_mean: float
    degenerate: bool


def normalise_log_weights(log_w: Any) -> NormalisedWeights:
    """Normalise log-weights to weights summing to one, never NaN.

    Parameters
    ----------
    log_w : array_like, shape (N,)
        Natural logs of unnormalised weights; ``-inf`` (a zero weight) is allowed, NaN and
        ``+inf`` are not.

    Returns
    -------
    NormalisedWeights
        ``weights = exp(log_w - logsumexp(log_w))`` (scaled by the largest, so no overflow or
        underflow of the sum). Recovery: if every weight is zero the particles carry no
        information, and the weights become uniform ``1/N`` with ``degenerate=True`` (ROS amcl's
        ``pf_update_sensor`` does the same on a zero total).

    Raises
    ------
    ValueError
        For NaN or ``+inf`` entries, or an empty or non-1-D array.

    Notes
    -----
    Thrun et al. (2005), Table 4.3 line 8 (the weights are normalised by the resampling) and
    Table 8.3 (its ``w_avg``).

    Examples
    --------
    >>> out = normalise_log_weights([0.0, np.log(3.0)])
    >>> out.weights.round(6).tolist(), round(out.log_mean, 6), out.degenerate   # log of the mean, log 2
    ([0.25, 0.75], 0.693147, False)
    >>> normalise_log_weights([-np.inf, -np.inf]).weights.tolist()    # all zero: the recovery
    [0.5, 0.5]
    """
    lw = as_array(log_w, "log_w", ndim=1, finite=False, min_size=1)
    if np.any(np.isnan(lw)) or np.any(lw == np.inf):
        raise ValueError("log_w: expected finite log-weights or -inf (a zero weight), got NaN or +inf")
    n = lw.size
    if np.all(lw == -np.inf):
        return NormalisedWeights(np.full(n, 1.0 / n), -np.inf, True)
    total = logsumexp(lw)
    w = np.exp(lw - total)
    w /= w.sum()   # exact unit sum after rounding
    return NormalisedWeights(w, float(total - np.log(n)), False)


def _weights(weights: Any, name: str = "weights") -> np.ndarray:
    w = as_array(weights, name, ndim=1, min_size=1)
    if np.any(w < 0):
        raise ValueError(f"{name}: expected non-negative weights, got a minimum of {w.min()}")
    total = w.sum()
    if not total > 0 or not np.isfinite(total):
        raise ValueError(f"{name}: expected weights with a positive finite sum, got {total}")
    return w / total


def low_variance_resample(weights: Any, rng: Any = None, count: int | None = None, *, start: float | None = None
                          ) -> np.ndarray:
    """Indices of the particles drawn by the low-variance (systematic) sampler.

    Parameters
    ----------
    weights : array_like, shape (N,)
        Non-negative importance weights (normalised here).
    rng : Generator or int, optional
    count : int, optional
        Number of draws ``M`` (default ``N``).
    start : float, optional
        The one random number ``r`` of Table 4.4, in ``[0, 1/M)``; default drawn from ``rng`` (give
        it to replay a draw, as the lesson's exercise does).

    Returns
    -------
    numpy.ndarray of int, shape (M,)
        Non-decreasing indices; particle ``i`` appears ``floor(M w_i)`` or ``ceil(M w_i)`` times,
        and exactly ``M w_i`` times on average.

    Raises
    ------
    ValueError
        For negative weights, a zero or non-finite sum, or a non-positive count.

    Notes
    -----
    Thrun et al. (2005), Table 4.4: one random ``r ~ U(0, 1/M)``; pointer ``U = r + (m-1)/M``
    for ``m = 1..M``; the drawn particle is the first ``i`` whose cumulative weight reaches ``U``.
    Vectorised with ``searchsorted`` over the cumulative weights.

    Examples
    --------
    >>> low_variance_resample([0.5, 0.25, 0.25], rng=0, count=4).tolist()
    [0, 0, 1, 2]
    >>> low_variance_resample([0.5, 0.25, 0.25], start=0.3).tolist()
    [0, 1, 2]
    """
    w = _weights(weights)
    m = w.size if count is None else as_int(count, "count", minimum=1)
    require_sample_count(m, "count")
    g = as_rng(rng)                                                 # checked even when start is given
    if start is None:
        r = g.uniform(0.0, 1.0 / m)                                 # Table 4.4, line 3
    else:
        r = as_finite_scalar(start, "start")
        if not 0.0 <= r < 1.0 / m:
            raise ValueError(f"start: expected r in [0, 1/M) = [0, {1.0 / m:.6g}), got {r}")
    pointers = r + np.arange(m) / m                                 # line 7
    cumulative = np.cumsum(w)
    cumulative /= cumulative[-1]
    idx = np.searchsorted(cumulative, pointers, side="left")        # lines 8-11: first c_i >= U
    return np.minimum(idx, w.size - 1)


def kld_sample_count(k: Any, *, epsilon: float = 0.01, z: float = KLD_Z_99) -> Any:
    """Number of particles KLD-sampling needs once the samples occupy ``k`` bins.

    Parameters
    ----------
    k : int or array_like of int
        Number of non-empty histogram bins (``1 <= k <= MAX_BINS``).
    epsilon : float, default 0.01
        Bound on the Kullback-Leibler divergence between the sample-based and the true posterior
        (ROS amcl's ``kld_err``).
    z : float, default ``KLD_Z_99`` (2.326)
        The upper ``1 - delta`` quantile of the standard normal, ``z_{1-delta}``: with probability
        ``1 - delta`` the error stays below ``epsilon``. ROS amcl's ``kld_z`` (default 0.99) is
        passed to ``pf_resample_limit`` as this ``z`` itself, not as ``1 - delta``: the ROS
        default therefore means ``z = 0.99`` (``1 - delta = Phi(0.99) = 0.84``), not 2.326.

    Returns
    -------
    int or numpy.ndarray of int
        ``ceil((k-1)/(2 epsilon) * (1 - 2/(9(k-1)) + sqrt(2/(9(k-1))) z)^3)``; 0 for ``k = 1``
        (one bin needs no more samples; the filter's minimum count applies).

    Raises
    ------
    ValueError
        For ``k`` out of range or fractional, a non-positive ``epsilon``, a non-finite ``z``, or a
        count beyond int64.

    Notes
    -----
    Fox (2003), Eq. (11) (the chi-square quantile ``chi^2_{k-1,1-delta}/(2 epsilon)`` by the
    Wilson-Hilferty approximation); Thrun et al. (2005), Table 8.4, line 15. ROS amcl computes the
    same in ``pf_resample_limit`` and clamps it to ``[min_particles, max_particles]``; it returns
    ``max_particles`` for ``k <= 1``.

    Examples
    --------
    >>> int(kld_sample_count(2)), int(kld_sample_count(100)), int(kld_sample_count(100, z=0.99))
    (330, 6733, 5644)
    """
    kk = as_array(k, "k")
    if kk.ndim > 1:
        raise ValueError(f"k: expected a bin count or a 1-D array of them, got shape {kk.shape}")
    if not np.all(kk == np.round(kk)):
        raise ValueError(f"k: expected whole bin counts, got {describe(k)}")
    if np.any(kk < 1) or np.any(kk > MAX_BINS):
        raise ValueError(f"k: expected bin counts in [1, {MAX_BINS}], got values in [{kk.min()}, {kk.max()}]")
    eps = as_positive(epsilon, "epsilon")
    zz = float(as_array(z, "z", shape=()))
    km1 = np.maximum(kk.astype(float) - 1.0, 1.0)
    a = 2.0 / (9.0 * km1)
    n = np.ceil(km1 / (2.0 * eps) * (1.0 - a + np.sqrt(a) * zz) ** 3)   # Table 8.4, line 15
    if not np.all(n < 2.0 ** 62):
        raise ValueError(f"epsilon, z: expected values whose sample count fits an int64, got epsilon = {eps}, z = {zz}")
    out = np.where(kk > 1, n, 0.0).astype(np.int64)
    return int(out) if out.ndim == 0 else out


def pose_bins(particles: Any, bin_size: Any = ROS_KLD_BIN_SIZE) -> np.ndarray:
    """Histogram bin of each pose, ``floor(pose / bin_size)`` per axis (as ROS's ``pf_kdtree``).

    Parameters
    ----------
    particles : array_like, shape (N, 3)
    bin_size : array_like, shape (3,), default ``ROS_KLD_BIN_SIZE`` (0.5 m, 0.5 m, 10 degrees)

    Returns
    -------
    numpy.ndarray of int64, shape (N, 3)

    Raises
    ------
    ValueError
        For bad particles or bin sizes, or a pose 2**62 bins or more from the origin (its bin would
        not be an int64).

    Notes
    -----
    Fox (2003), Sec. 3: the multi-dimensional histogram whose occupied bins ``k`` set the count.

    Examples
    --------
    >>> pose_bins([[0.2, 0.7, 0.0], [0.3, 0.6, 0.1]]).tolist()
    [[0, 1, 0], [0, 1, 0]]
    """
    P = as_planar(particles, "particles", shape=(None, 3))
    size = as_array(bin_size, "bin_size", shape=(3,))
    if np.any(size <= 0):
        raise ValueError(f"bin_size: expected three positive sizes, got {size.tolist()}")
    scaled = P / size
    if len(scaled) and np.abs(scaled).max() >= 2.0 ** 62:
        raise ValueError(f"particles: expected poses within 2**62 bins of the origin (bin_size {size.tolist()}), "
                         f"got one {np.abs(scaled).max():.3g} bins away")
    return np.floor(scaled).astype(np.int64)


def _first_in_bin(keys: np.ndarray) -> np.ndarray:
    """Indices of the first row of each distinct row of the integer ``keys`` (N, 3).

    The same indices as ``np.unique(keys, axis=0, return_index=True)[1]``, from one integer per row
    (the bins counted from the smallest in each axis) when those fit in 62 bits: a sort of N
    integers instead of N rows.
    """
    lo = keys.min(axis=0)
    if np.prod(keys.max(axis=0).astype(float) - lo.astype(float) + 1) >= 2.0 ** 62:   # before any int64 sum
        return np.unique(keys, axis=0, return_index=True)[1]
    span = keys.max(axis=0) - lo + 1
    flat = ((keys[:, 0] - lo[0]) * span[1] + (keys[:, 1] - lo[1])) * span[2] + (keys[:, 2] - lo[2])
    return np.unique(flat, return_index=True)[1]


def kld_resample(particles: Any, weights: Any, rng: Any = None, *, min_count: int = 100,
                 max_count: int = 5000, epsilon: float = 0.01, z: float = KLD_Z_99,
                 bin_size: Any = ROS_KLD_BIN_SIZE, random_pose: Any = None,
                 inject_probability: float = 0.0) -> np.ndarray:
    """KLD-sampling: resample until the sample count bounds the KL error (Table 8.4).

    Parameters
    ----------
    particles : array_like, shape (N, 3)
    weights : array_like, shape (N,)
        Non-negative weights (normalised here).
    rng : Generator or int, optional
    min_count, max_count : int, default 100, 5000
        Bounds on the new count (ROS amcl's ``min_particles``/``max_particles``).
    epsilon, z : float
        As :func:`kld_sample_count`.
    bin_size : array_like, shape (3,)
        Histogram bins (:func:`pose_bins`).
    random_pose : callable, optional
        ``random_pose(n, rng) -> (n, 3)``: poses injected by augmented MCL (Table 8.3).
    inject_probability : float, default 0
        Probability that a draw is a random pose instead of a resampled particle (Table 8.3 line
        13, ``max(0, 1 - w_fast / w_slow)``).

    Returns
    -------
    numpy.ndarray, shape (M, 3)
        The new particles (their weights are uniform), ``min_count <= M <= max_count``.

    Notes
    -----
    Thrun et al. (2005), Table 8.4: draw a particle with probability proportional to its weight,
    count a new bin when it lands in an empty one, and stop at the first ``M`` with
    ``M >= kld_sample_count(k)`` and ``M >= min_count``. Here all ``max_count`` candidates are
    drawn at once, the number of distinct bins after each draw is a cumulative sum of
    first-occurrence flags, and the stop is the first index that satisfies the same test: the
    same sample set as the loop. Like ROS amcl (whose comment says the low-variance sampler does
    not combine easily with KLD), the draws are independent (multinomial).

    Examples
    --------
    >>> P = np.zeros((10, 3))                     # one bin: the filter shrinks to min_count
    >>> kld_resample(P, np.ones(10), rng=0, min_count=20, max_count=200).shape
    (20, 3)
    """
    P = as_planar(particles, "particles", shape=(None, 3), min_count=1)
    w = _weights(weights)
    if w.size != len(P):
        raise ValueError(f"weights: expected {len(P)} weights (one per particle), got {w.size}")
    lo = as_int(min_count, "min_count", minimum=1)
    hi = as_int(max_count, "max_count", minimum=lo)
    require_sample_count(hi, "max_count")
    p_inj = as_positive(inject_probability, "inject_probability", allow_zero=True)
    if p_inj > 1:
        raise ValueError(f"inject_probability: expected a probability in [0, 1], got {p_inj}")
    as_callable(random_pose, "random_pose")
    if p_inj > 0 and random_pose is None:
        raise ValueError("random_pose: expected a callable random_pose(n, rng) when inject_probability > 0")
    g = as_rng(rng)
    cumulative = np.cumsum(w)
    cumulative /= cumulative[-1]
    idx = np.minimum(np.searchsorted(cumulative, g.random(hi), side="right"), w.size - 1)
    cand = P[idx]
    injected = g.random(hi) < p_inj                                  # Table 8.3, max(0, 1 - w_fast / w_slow)
    if injected.any():
        cand[injected] = as_planar(random_pose(int(injected.sum()), g), "random_pose(n, rng)", shape=(None, 3))
    new_bin = np.zeros(hi, dtype=bool)
    new_bin[_first_in_bin(pose_bins(cand, bin_size))] = True
    k = np.cumsum(new_bin)                                           # Table 8.4, lines 11-13
    m = np.arange(1, hi + 1)
    needed = kld_sample_count(k, epsilon=epsilon, z=z)               # line 15
    ok = (m >= needed) & (m >= lo)                                   # line 19: the loop's stop
    stop = int(np.argmax(ok)) + 1 if ok.any() else hi
    return cand[:stop]


def weighted_pose_mean(particles: Any, weights: Any = None) -> np.ndarray:
    """Weighted mean pose: arithmetic in ``x, y``, circular in ``theta``.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
    weights : array_like, shape (N,), optional
        Non-negative weights (normalised here); uniform when omitted.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``[sum w x, sum w y, atan2(sum w sin(theta), sum w cos(theta))]``.

    Notes
    -----
    Thrun et al. (2005), Sec. 4.3.4 (extracting an estimate from particles); ROS amcl's
    ``pf_cluster_stats`` averages the heading the same way.

    Examples
    --------
    >>> weighted_pose_mean([[0.0, 0.0, 3.0], [2.0, 0.0, -3.0]]).round(4).tolist()  # across +-pi
    [1.0, 0.0, 3.1416]
    """
    P = as_planar(particles, "particles", shape=(None, 3), min_count=1)
    w = np.full(len(P), 1.0 / len(P)) if weights is None else _weights(weights)
    if w.size != len(P):
        raise ValueError(f"weights: expected {len(P)} weights (one per particle), got {w.size}")
    heading = np.arctan2(w @ np.sin(P[:, 2]), w @ np.cos(P[:, 2]))
    return np.array([w @ P[:, 0], w @ P[:, 1], heading])


def _ellipse_args(pose: Any, sigma_x: Any, sigma_y: Any) -> tuple[np.ndarray, float, float]:
    return (as_planar(pose, "pose", shape=(3,)), as_positive(sigma_x, "sigma_x"),
            as_positive(sigma_y, "sigma_y"))


def sample_ellipse_poses(pose: Any, sigma_x: float, sigma_y: float, n: int = 50, *, nsigma: float = 2.0,
                         sigma_theta: float = 0.05, rng: Any = None) -> np.ndarray:
    """Poses spread uniformly inside an ellipse around a retrieved keyframe pose (Ge et al. Fig. 10).

    Parameters
    ----------
    pose : array_like, shape (3,)
        The keyframe's pose ``(x_k, y_k, theta_k)``.
    sigma_x, sigma_y : float
        Standard deviations along and across the keyframe's heading (m).
    n : int, default 50
        Number of poses (the paper's Table 2 uses 50 particles).
    nsigma : float, default 2
        The ellipse's semi-axes are ``nsigma * sigma_x`` and ``nsigma * sigma_y``.
    sigma_theta : float, default 0.05
        Standard deviation of the headings about ``theta_k`` (rad): the moving strategy of Sec.
        3.1 leaves the robot's direction "consistent and with less uncertainty".
    rng : Generator or int, optional

    Returns
    -------
    numpy.ndarray, shape (n, 3)

    Notes
    -----
    Ge et al. (2023), Sec. 3.4, Fig. 10 and Algorithm 1 line 2 ("Uniformly sample poses according
    to a keyframe retrieval"): uniform over the ellipse's area (radius ``sqrt(u)``). The axes lie
    along and across ``theta_k``; in the paper's corridor the robot faces along the corridor, and
    the ellipse is the axis-aligned one of Fig. 10.

    Examples
    --------
    >>> P = sample_ellipse_poses([5.0, 0.0, 0.0], 0.5, 0.1, n=4, rng=0)
    >>> bool(np.all(((P[:, 0] - 5.0) / 1.0) ** 2 + (P[:, 1] / 0.2) ** 2 <= 1.0))
    True
    """
    c, sx, sy = _ellipse_args(pose, sigma_x, sigma_y)
    count = as_int(n, "n", minimum=1)
    require_sample_count(count, "n")
    k = as_positive(nsigma, "nsigma")
    st = as_positive(sigma_theta, "sigma_theta", allow_zero=True)
    require_angles(st, "sigma_theta", "a heading spread")
    g = as_rng(rng)
    radius = np.sqrt(g.random(count))
    phi = g.uniform(-np.pi, np.pi, count)
    along, across = k * sx * radius * np.cos(phi), k * sy * radius * np.sin(phi)
    ct, stt = np.cos(c[2]), np.sin(c[2])
    return np.column_stack([c[0] + ct * along - stt * across, c[1] + stt * along + ct * across,
                            wrap_angle(c[2] + st * g.standard_normal(count))])


def ellipse_weights(particles: Any, pose: Any, sigma_x: float, sigma_y: float, *, normalise: bool = True) -> np.ndarray:
    """Initial particle weights of Ge et al. (2023), Eq. (19): a Gaussian about the keyframe pose.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
    pose : array_like, shape (3,)
        The keyframe's pose ``(x_k, y_k, theta_k)``.
    sigma_x, sigma_y : float
        Standard deviations along and across ``theta_k`` (m). The paper calls them "the
        variances in the x and y directions" but uses them as standard deviations.
    normalise : bool, default True
        Scale the weights to sum to one; ``False`` returns Eq. (19)'s density values.

    Returns
    -------
    numpy.ndarray, shape (N,)

    Notes
    -----
    ``w = 1/(2 pi sigma_x sigma_y) exp(-(dx^2/(2 sigma_x^2) + dy^2/(2 sigma_y^2)))`` with ``dx,
    dy`` the offset from ``(x_k, y_k)`` along and across ``theta_k`` (for ``theta_k = 0``
    exactly the paper's world ``x`` and ``y``). The heading does not enter Eq. (19).

    Examples
    --------
    >>> w = ellipse_weights([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [0.0, 0.0, 0.0], 1.0, 1.0, normalise=False)
    >>> np.round(w, 6).tolist()                        # 1/(2 pi) and exp(-1/2)/(2 pi)
    [0.159155, 0.096532]
    """
    P = as_planar(particles, "particles", shape=(None, 3), min_count=1)
    c, sx, sy = _ellipse_args(pose, sigma_x, sigma_y)
    dx, dy = P[:, 0] - c[0], P[:, 1] - c[1]
    ct, st = np.cos(c[2]), np.sin(c[2])
    along, across = ct * dx + st * dy, -st * dx + ct * dy
    sx, sy = np.float64(sx), np.float64(sy)                  # an overflow is inf, not an OverflowError
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        log_w = -(along ** 2 / (2 * sx ** 2) + across ** 2 / (2 * sy ** 2)) - np.log(2 * np.pi * sx * sy)  # Eq. (19)
    require_finite_result("particles, pose, sigma_x, sigma_y", log_w)
    if not normalise:
        return np.exp(log_w)
    return normalise_log_weights(log_w).weights
