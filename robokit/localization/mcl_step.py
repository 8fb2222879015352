"""One Monte-Carlo localization step on plain arrays, and AMCL's uniform pose generator.

:func:`mcl_step` is Thrun et al. (2005)'s Table 8.2 (``MCL``) in one call, for the lesson and for
:class:`robokit.localization.mcl.MonteCarloLocalizer`: every particle moves by the odometry motion
model (:func:`robokit.sim.sample_motion_model_odometry`, Table 5.6), is weighed by the likelihood
field (:func:`robokit.localization.beam_models.likelihood_field_log_weights`, Table 6.3) and the
set is resampled by the low-variance sampler (Table 4.4). :func:`uniform_free_poses` draws poses
uniformly over a map's free cells (global initialization and augmented MCL's random poses).

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering* 24(6), 2023,
   doi:10.1631/FITEE.2200208.
.. [3] ROS ``amcl`` (ROS 1 navigation stack: ``amcl_node.cpp``, ``uniformPoseGenerator``).
"""
from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..mapping import LikelihoodField
from ..sim import sample_motion_model_odometry
from ..validation import as_array, as_points, as_rng, as_int, as_positive, describe
from .beam_models import likelihood_field_log_weights
from .particle_filter import low_variance_resample, normalise_log_weights

__all__ = ["MCLStep", "mcl_step", "uniform_free_poses"]


class MCLStep(NamedTuple):
    """One filter step's result: ``particles`` (N, 3), ``weights`` (N,), ``degenerate`` (every
    weight was zero and the recovery made them uniform) and ``log_evidence``, the log of the
    weighted mean likelihood ``sum_i w_i p(z | x_i)`` (augmented MCL's ``w_avg``; ``-inf`` when
    degenerate).

    Examples
    --------
    >>> MCLStep(np.zeros((1, 3)), np.ones(1), False, 0.0).weights.tolist()
    [1.0]
    """

    particles: np.ndarray
    weights: np.ndarray
    degenerate: bool
    log_evidence: float


def mcl_step(particles: Any, weights: Any, odom_prev: Any, odom_now: Any, ranges: Any, angles: Any,
             field: LikelihoodField, *, alphas: Any = (0.2, 0.2, 0.2, 0.2), resample: bool = True, rng: Any = None,
             **model: Any) -> MCLStep:
    """One MCL step on plain arrays: motion, likelihood-field weights, low-variance resampling.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
    weights : array_like, shape (N,)
        Their current weights (non-negative).
    odom_prev, odom_now : array_like, shape (3,)
        Consecutive odometry poses (the control ``u_t``).
    ranges, angles : array_like, shape (B,)
        The scan (``inf`` = max range).
    field : robokit.mapping.LikelihoodField
    alphas : array_like, shape (4,), default ROS's (0.2, 0.2, 0.2, 0.2)
        Odometry noise of Table 5.6.
    resample : bool, default True
        Resample (low variance) after weighing; ``False`` returns the weighted particles.
    rng : Generator or int, optional
    **model
        Keyword arguments of :func:`~robokit.localization.beam_models.likelihood_field_log_weights`
        (``sigma_hit``, ``z_hit``, ``z_rand``, ``r_max``, ``max_beams``, ``combine``, ``sensor_offset``).

    Returns
    -------
    MCLStep

    Notes
    -----
    Thrun et al. (2005), Table 8.2 (``MCL``): line 4 ``sample_motion_model``, line 5
    ``measurement_model`` (times the prior weight: importance weights accumulate until a
    resampling), lines 8-11 resampling (Table 4.4). Ge et al. (2023), Algorithm 1 lines 5-13.

    Examples
    --------
    >>> from robokit.mapping import OccupancyGrid, likelihood_field
    >>> prob = np.zeros((20, 40)); prob[:, 35] = 1.0                # a wall at x = 3.5 m
    >>> field = likelihood_field(OccupancyGrid.from_probability(prob, 0.1))
    >>> P = np.array([[1.0, 1.0, 0.0], [1.5, 1.0, 0.0]])             # the robot is at the second
    >>> out = mcl_step(P, [0.5, 0.5], [0, 0, 0], [0.5, 0, 0], [1.5], [0.0], field, alphas=[0, 0, 0, 0], rng=0)
    >>> out.particles[:, 0].tolist()                                 # both copies of the one that fits
    [2.0, 2.0]
    """
    P = as_points(particles, "particles", 3, min_count=1)
    w = as_array(weights, "weights", shape=(len(P),))
    if np.any(w < 0) or not w.sum() > 0:
        raise ValueError(f"weights: expected non-negative weights with a positive sum, got {describe(weights)}")
    u = (as_array(odom_prev, "odom_prev", shape=(3,)), as_array(odom_now, "odom_now", shape=(3,)))
    g = as_rng(rng)
    moved = sample_motion_model_odometry(*u, P, alphas, g)                            # Table 8.2, line 4
    log_lik = likelihood_field_log_weights(moved, ranges, angles, field, **model)    # line 5
    with np.errstate(divide="ignore"):
        out = normalise_log_weights(np.log(w / w.sum()) + log_lik)
    evidence = out.log_mean + math.log(len(P))
    if not resample:
        return MCLStep(moved, out.weights, out.degenerate, evidence)
    idx = low_variance_resample(out.weights, g)                                       # lines 8-11
    return MCLStep(moved[idx], np.full(len(P), 1.0 / len(P)), out.degenerate, evidence)


def uniform_free_poses(free_cells: Any, resolution: float, n: int, rng: Any = None) -> np.ndarray:
    """Poses uniform over the free area of a map, headings uniform: AMCL's global initialization.

    Parameters
    ----------
    free_cells : array_like, shape (M, 2)
        Centres of the free cells (:meth:`robokit.mapping.OccupancyGrid.free_cells`).
    resolution : float
        Cell size (m): each pose is uniform inside its cell.
    n : int
        Number of poses.
    rng : Generator or int, optional

    Returns
    -------
    numpy.ndarray, shape (n, 3)

    Notes
    -----
    ROS amcl's ``uniformPoseGenerator`` (a free cell at random, heading uniform in ``[-pi,
    pi)``), used by its ``global_localization`` service and by the random poses of augmented MCL
    (Thrun et al. 2005, Table 8.3, line 13).

    Examples
    --------
    >>> uniform_free_poses([[0.5, 0.5]], 1.0, 3, rng=0)[:, :2].round(2).tolist()
    [[0.64, 0.27], [0.04, 0.02], [0.81, 0.91]]
    """
    cells = as_array(free_cells, "free_cells", shape=(None, 2), min_size=2)
    res = as_positive(resolution, "resolution")
    count = as_int(n, "n", minimum=0)
    g = as_rng(rng)
    xy = cells[g.integers(0, len(cells), count)] + g.uniform(-res / 2, res / 2, (count, 2))
    return np.column_stack([xy, g.uniform(-np.pi, np.pi, count)])
