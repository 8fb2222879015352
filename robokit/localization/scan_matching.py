"""Correlative scan matching: the pose near a guess whose scan fits the likelihood field best.

A particle filter's estimate is only as fine as its particles are dense; a scan matcher refines it
by searching a small window of poses around it for the one under which the scan's end points lie
closest to the map's walls. Olson (2009) scores a grid of poses exhaustively (and finds the grid's
best with a multi-resolution bound); here each level searches a grid around the previous level's
best, a greedy coarse-to-fine refinement that can miss a better pose far from the guess. Each
candidate is scored with the likelihood-field model (Thrun et al. 2005, Table 6.3,
:func:`~robokit.localization.beam_models.likelihood_field_log_weights`, with every beam and the
product of their likelihoods). A window of zero on an axis keeps that coordinate, so a matcher can
refine the heading and the sideways position but leave a coordinate the scan cannot pin down (the
position along a corridor) to the filter.

References
----------
.. [1] E. Olson, "Real-time correlative scan matching", *IEEE International Conference on Robotics
   and Automation* (ICRA), 2009, pp. 4387-4393.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..geometry import wrap_angle
from ..geometry.planar import as_planar
from ..mapping import LikelihoodField
from ..validation import as_array, as_int, as_positive
from .beam_models import likelihood_field_log_weights

__all__ = ["ScanMatch", "match_scan"]


class ScanMatch(NamedTuple):
    """A scan matcher's answer: the best ``pose`` found and its scan's ``log_likelihood``.

    Examples
    --------
    >>> ScanMatch(np.zeros(3), -1.0).log_likelihood
    -1.0
    """

    pose: np.ndarray
    log_likelihood: float


def match_scan(pose: Any, ranges: Any, angles: Any, field: LikelihoodField, *,
               window: Any = (0.15, 0.15, math.radians(3.0)), steps: int = 11, levels: int = 3,
               sensor_offset: Any = (0.0, 0.0, 0.0), sigma_hit: float = 0.05, r_max: float = 8.0) -> ScanMatch:
    """Refine ``pose`` by a coarse-to-fine grid search of the scan's fit to the likelihood field.

    Parameters
    ----------
    pose : array_like, shape (3,)
        The guess ``[x, y, theta]`` (e.g. a particle filter's estimate).
    ranges, angles : array_like, shape (B,)
        The scan taken at the true pose: ranges (``inf`` where nothing returned) and beam angles
        in the sensor frame.
    field : robokit.mapping.LikelihoodField
        The map's distance field.
    window : array_like, shape (3,), default (0.15 m, 0.15 m, 3 degrees)
        Half-widths of the first search in ``x``, ``y`` (m) and ``theta`` (rad); 0 keeps that
        coordinate. At most 10 m and pi rad.
    steps : int, default 11
        Candidates per searched axis and level (odd, 3 to 41): the grid includes the centre.
    levels : int, default 3
        Searches, each around the previous best with a window ``(steps - 1) / 2`` times smaller
        (1 to 6).
    sensor_offset : array_like, shape (3,), default (0, 0, 0)
        The sensor's mount in the robot frame.
    sigma_hit : float, default 0.05
        The likelihood field's hit spread (m); sharper than amcl's 0.2 m, since the matcher wants
        the best fit, not a tolerant weight.
    r_max : float, default 8.0
        Maximum range (m): returns at or beyond it are skipped.

    Returns
    -------
    ScanMatch
        The best candidate of the last level (heading wrapped to [-pi, pi)) and its log-likelihood (the product model over every
        beam). The guess itself is a candidate of the first level, so the answer never fits worse.

    Raises
    ------
    ValueError, TypeError
        For a bad pose, scan, field, window or count.

    Notes
    -----
    After Olson (2009), Sec. III (search of a pose window for the best-scoring pose), but greedy:
    each level re-centres on the previous best, so it refines a guess rather than guaranteeing the
    window's optimum. The score is Thrun et al. (2005), Table 6.3 (likelihood field, product of beams).

    Examples
    --------
    >>> from robokit.mapping import OccupancyGrid, likelihood_field
    >>> P = np.zeros((60, 60)); P[:, 0] = P[:, -1] = P[0, :] = P[-1, :] = 1.0    # a 3 m x 3 m box
    >>> field = likelihood_field(OccupancyGrid.from_probability(P, 0.05))
    >>> angles = np.linspace(0, 2 * np.pi, 72, endpoint=False) + 0.01     # no beam exactly along an axis
    >>> d = np.stack([np.cos(angles), np.sin(angles)], 1)
    >>> ranges = np.min((np.where(d > 0, 2.95, 0.05) - 1.5) / d, axis=1)       # seen from (1.5, 1.5)
    >>> best = match_scan([1.55, 1.47, 0.04], ranges, angles, field).pose
    >>> np.round(best, 2).tolist()
    [1.5, 1.5, 0.0]
    """
    guess = as_planar(pose, "pose", shape=(3,))
    if not isinstance(field, LikelihoodField):
        raise TypeError(f"field: expected a robokit.mapping.LikelihoodField, got {type(field).__name__}")
    win = as_array(window, "window", shape=(3,))
    if np.any(win < 0) or np.any(win > [10.0, 10.0, math.pi]):
        raise ValueError(f"window: expected half-widths in [0, 10] m, [0, 10] m and [0, pi] rad, got {win.tolist()}")
    steps = as_int(steps, "steps", minimum=3, maximum=41)
    if steps % 2 == 0:
        raise ValueError(f"steps: expected an odd number (the grid's centre is a candidate), got {steps}")
    levels = as_int(levels, "levels", minimum=1, maximum=6)
    sigma_hit = as_positive(sigma_hit, "sigma_hit")
    r_max = as_positive(r_max, "r_max")
    model = dict(sensor_offset=sensor_offset, sigma_hit=sigma_hit, r_max=r_max, combine="product")
    score = likelihood_field_log_weights(guess[None], ranges, angles, field, **model)   # validates the scan
    best, best_score = guess, float(score[0])
    grid = np.linspace(-1.0, 1.0, steps)
    for _ in range(levels):
        axes = [grid * w if w > 0 else np.zeros(1) for w in win]
        offsets = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        scores = likelihood_field_log_weights(best + offsets, ranges, angles, field, **model)
        k = int(np.argmax(scores))
        if scores[k] > best_score:
            best, best_score = best + offsets[k], float(scores[k])
        win = win * 2.0 / (steps - 1)
    best = best.copy()
    best[2] = wrap_angle(best[2])
    return ScanMatch(best, best_score)
