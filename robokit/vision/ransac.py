"""RANSAC for matched features: the sample count, and a planar rigid fit robust to false matches.

Fischler & Bolles (1981): draw minimal samples of tentative matches, fit a model to each, keep the
model that most matches support, refit it on its support. The number of samples ``m`` that draws
at least one clean sample with probability ``P`` when a fraction ``eps`` of the matches is wrong
solves ``P = 1 - (1 - (1 - eps)^p)^m`` (Lin et al. Sec. 7) for samples of ``p`` matches; it is
written once here, :func:`ransac_sample_count`, and used by every RANSAC in robokit (the 3-DoF
ego-motion of :mod:`robokit.localization.egomotion`, the essential matrix of
:mod:`robokit.vision.spherical`, the planar fit :func:`ransac_se2`).

References
----------
.. [1] M. A. Fischler and R. C. Bolles, "Random sample consensus: a paradigm for model fitting with
   applications to image analysis and automated cartography", Communications of the ACM 24(6),
   381-395, 1981.
.. [2] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [3] S. Umeyama, "Least-squares estimation of transformation parameters between two point
   patterns", IEEE Trans. Pattern Analysis and Machine Intelligence 13(4), 376-380, 1991.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..geometry import fit_se2
from ..validation import as_points, as_rng, as_int, as_positive

__all__ = ["ransac_sample_count", "PlanarFit", "ransac_se2"]


def ransac_sample_count(contamination: float, sample_size: int = 2, confidence: float = 0.99) -> int:
    """Number of RANSAC samples ``m`` so that a clean sample is drawn with probability ``P``.

    Parameters
    ----------
    contamination : float
        Ratio ``eps`` of false matches, in [0, 1).
    sample_size : int, default 2
        Matches per hypothesis ``p`` (two for the 3-DoF pose).
    confidence : float, default 0.99
        Required probability ``P`` in (0, 1).

    Returns
    -------
    int
        ``ceil(log(1 - P) / log(1 - (1 - eps)^p))``, at least 1.

    Raises
    ------
    ValueError
        For ``eps`` outside [0, 1) (``eps = 1`` would need infinitely many samples) or ``P``
        outside (0, 1).

    Notes
    -----
    Lin et al. Sec. 7, ``P = 1 - (1 - (1 - eps)^p)^m`` solved for ``m`` (Fischler & Bolles 1981).

    Examples
    --------
    >>> ransac_sample_count(0.5)                 # half the matches wrong, two-match samples, P = 0.99
    17
    >>> ransac_sample_count(0.5, confidence=0.999), ransac_sample_count(0.8)
    (25, 113)
    """
    eps = as_positive(contamination, "contamination", allow_zero=True)
    if eps >= 1:
        raise ValueError(f"contamination: expected a ratio in [0, 1), got {eps}")
    p = as_int(sample_size, "sample_size", minimum=1)
    conf = as_positive(confidence, "confidence")
    if conf >= 1:
        raise ValueError(f"confidence: expected a probability in (0, 1), got {conf}")
    good = (1 - eps) ** p
    if good >= 1:
        return 1
    samples = np.log1p(-conf) / np.log1p(-good)      # log1p: a tiny clean-sample probability stays nonzero
    if not samples < 2.0 ** 63:   # a clean sample is so unlikely that no count is enough
        raise ValueError(f"sample_size: expected a sample that can be clean, got {p} matches at contamination {eps} "
                         f"(probability {good:.3g} per sample)")
    return max(1, int(np.ceil(samples)))


@dataclass(frozen=True)
class PlanarFit:
    """Outcome of :func:`ransac_se2`.

    Attributes
    ----------
    pose : numpy.ndarray, shape (3,)
        ``[x, y, theta]``: the source frame in the target frame (all zeros when ``ok`` is False).
    inliers : numpy.ndarray of bool, shape (N,)
        Matches that support the pose.
    rms : float
        Root-mean-square residual of the inliers (metres; ``inf`` when ``ok`` is False).
    iterations : int
        Hypotheses drawn.
    ok : bool
        Whether at least ``min_inliers`` matches support the pose.
    """

    pose: np.ndarray
    inliers: np.ndarray
    rms: float
    iterations: int
    ok: bool

    @property
    def n_inliers(self) -> int:
        """Number of supporting matches."""
        return int(np.count_nonzero(self.inliers))


def ransac_se2(source: Any, target: Any, *, threshold: float = 0.1, confidence: float = 0.99,
               min_inliers: int = 6, max_iterations: int = 2000, rng: Any = None) -> PlanarFit:
    """Planar rigid pose from point matches with false ones among them (two-point RANSAC).

    Parameters
    ----------
    source, target : array_like, shape (N, 2)
        Tentative matches: a point in the source frame and its match in the target frame.
    threshold : float, default 0.1
        A match supports a pose when its moved source point lies within this distance of its
        target point (same unit as the points).
    confidence : float, default 0.99
        ``P`` of the sample count; the contamination is re-estimated from the best support so far.
    min_inliers : int, default 6
        Fewer supporting matches and the fit is reported as failed (``ok=False``), not raised.
    max_iterations : int, default 2000
        Cap on hypotheses.
    rng : numpy.random.Generator or int, optional

    Returns
    -------
    PlanarFit

    Raises
    ------
    ValueError
        For shapes that do not agree, NaN/inf, or a non-positive threshold.

    Notes
    -----
    Fischler & Bolles (1981) with two-point hypotheses (Lin et al. Sec. 5) fitted in one batch by
    :func:`robokit.geometry.fit_se2` (Umeyama 1991); the winner is refitted on its support twice.

    Examples
    --------
    Thirty matches, ten of them wrong; the source frame sits at ``[1, -0.5, 0.4]`` in the target:

    >>> from robokit.geometry import se2_compose
    >>> rng = np.random.default_rng(1)
    >>> src = rng.uniform(-3.0, 3.0, (30, 2))
    >>> tgt = se2_compose([1.0, -0.5, 0.4], np.column_stack([src, np.zeros(30)]))[:, :2]
    >>> tgt[:10] = rng.uniform(-3.0, 3.0, (10, 2))
    >>> fit = ransac_se2(src, tgt, rng=0)
    >>> print(np.round(fit.pose, 6), fit.n_inliers, fit.ok)
    [ 1.  -0.5  0.4] 20 True
    """
    s = as_points(source, "source", 2)
    t = as_points(target, "target", 2)
    if len(t) != len(s):
        raise ValueError(f"target: expected {len(s)} points (one per source point), got {len(t)}")
    thr = as_positive(threshold, "threshold")
    min_inliers = as_int(min_inliers, "min_inliers", minimum=2)
    max_iterations = as_int(max_iterations, "max_iterations", minimum=1)
    gen = as_rng(rng)
    needed, drawn, n = ransac_sample_count(0.99, 2, confidence), 0, len(s)
    failed = PlanarFit(np.zeros(3), np.zeros(n, bool), np.inf, 0, False)
    if n < max(2, min_inliers):
        return failed
    best, best_count, best_cost = None, -1, np.inf
    while drawn < min(needed, max_iterations):
        k = min(128, max_iterations - drawn)
        i = gen.integers(0, n, k)
        j = (i + gen.integers(1, n, k)) % n                      # a distinct second index
        drawn += k
        ok = (np.linalg.norm(s[j] - s[i], axis=1) > 1e-9) & (np.linalg.norm(t[j] - t[i], axis=1) > 1e-9)
        if not ok.any():
            continue
        poses = fit_se2(np.stack([s[i[ok]], s[j[ok]]], 1), np.stack([t[i[ok]], t[j[ok]]], 1), validate=False)
        dist = _residuals(poses, s, t)                           # (hypotheses, matches)
        support = dist < thr
        count = support.sum(1)
        cost = np.where(support, dist, thr).sum(1)               # MSAC tie-break among equal counts
        h = int(np.lexsort((cost, -count))[0])
        if count[h] > best_count or (count[h] == best_count and cost[h] < best_cost):
            best, best_count, best_cost = poses[h], int(count[h]), float(cost[h])
            needed = ransac_sample_count(min(1 - best_count / n, 0.999), 2, confidence)
    if best is None or best_count < min_inliers:
        return PlanarFit(failed.pose, failed.inliers, np.inf, drawn, False)
    pose = best
    for _ in range(2):                                           # refit on the support, recompute it
        inliers = _residuals(pose[None], s, t)[0] < thr
        if inliers.sum() < 2:
            break
        pose = fit_se2(s[inliers], t[inliers], validate=False)
    dist = _residuals(pose[None], s, t)[0]
    inliers = dist < thr
    ok = bool(inliers.sum() >= min_inliers)
    rms = float(np.sqrt((dist[inliers] ** 2).mean())) if ok else np.inf
    return PlanarFit(pose if ok else np.zeros(3), inliers, rms, drawn, ok)


def _residuals(poses: np.ndarray, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Distances ``|R s + p - t|`` for each pose (K, 3) and match: shape (K, N)."""
    c, si = np.cos(poses[:, 2:3]), np.sin(poses[:, 2:3])
    dx = c * s[:, 0] - si * s[:, 1] + poses[:, 0:1] - t[:, 0]
    dy = si * s[:, 0] + c * s[:, 1] + poses[:, 1:2] - t[:, 1]
    return np.hypot(dx, dy)
