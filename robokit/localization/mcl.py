"""Monte-Carlo localization in an occupancy grid: MCL, ROS's AMCL and Ge et al. (2023)'s improved start.

One filter step (:func:`mcl_step`, Thrun et al. 2005, Table 8.2) moves every particle by the
odometry motion model (:func:`robokit.sim.sample_motion_model_odometry`, Table 5.6), weighs it by
the likelihood field (:func:`robokit.localization.beam_models.likelihood_field_log_weights`,
Table 6.3) and resamples (low variance, Table 4.4). :class:`MonteCarloLocalizer` adds what makes
it ROS's adaptive MCL: an update only after enough motion, resampling every
``resample_interval`` updates, KLD-sampling (Table 8.4) and the random-pose injection of
augmented MCL (Table 8.3), with the defaults of :data:`AMCL_DEFAULTS`; and Ge et al.'s
initialization inside an ellipse around a retrieved keyframe pose (Eq. (19), Algorithm 1).

ROS amcl's parameters (``amcl_node.cpp`` and ``cfg/AMCL.cfg`` of the ROS 1 navigation stack) and
how they map here:

==========================  =========  ==================================================
parameter                   default    here
==========================  =========  ==================================================
min_particles               100        ``KLDConfig.min_particles``
max_particles               5000       ``KLDConfig.max_particles``
kld_err                     0.01       ``KLDConfig.epsilon`` (Fox's epsilon)
kld_z                       0.99       ``KLDConfig.z``: used by ``pf_resample_limit`` as
                                       the normal quantile z itself (see
                                       :func:`~robokit.localization.particle_filter.kld_sample_count`)
update_min_d                0.2 m      ``update_min_d`` (``|dx|`` or ``|dy|``, per axis)
update_min_a                pi/6       ``update_min_a``
resample_interval           2          ``resample_interval``
recovery_alpha_slow         0.0        ``alpha_slow`` (0 disables recovery; the cfg help
                                       suggests 0.001; ``amcl_node.cpp``'s own fallback
                                       is 0.001)
recovery_alpha_fast         0.0        ``alpha_fast`` (suggested 0.1; fallback 0.1)
laser_max_beams             30         ``max_beams``
laser_z_hit, laser_z_rand   0.95, 0.05 ``z_hit``, ``z_rand``
laser_sigma_hit             0.2 m      ``sigma_hit``
laser_likelihood_max_dist   2.0 m      ``max_distance`` of the likelihood field
odom_alpha1..4              0.2 each   ``alphas``
==========================  =========  ==================================================

``odom_alpha1..4`` are in Table 5.6's order: alpha1 the rotation noise from rotation, alpha2 the
rotation noise from translation, alpha3 the translation noise from translation, alpha4 the
translation noise from rotation. ROS's default ``diff`` model passes each of Table 5.6's
expressions to its Gaussian sampler as a standard deviation; its ``diff-corrected`` model (and
robokit, like the book's ``sample(b^2)``) as a variance, so ROS's 0.2 is a larger noise here.

Departures from ROS, each on purpose: weights multiply across updates until a resampling (Table
8.2's importance weights; ROS's motion model resets them to ``1/N`` at every update, so with
``resample_interval = 2`` every other scan only feeds ``w_slow``/``w_fast``); the estimate is
the weighted mean of all particles (ROS publishes the mean of the heaviest cluster); low-variance
resampling when KLD is off (ROS always draws independently).

:func:`mcl_step` is that step in one call on plain arrays, for the lesson and for the localizer;
:func:`uniform_free_poses` draws poses uniformly over a map's free cells (global initialization
and augmented MCL's random poses).

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] D. Fox, "Adapting the sample size in particle filters through KLD-sampling",
   *International Journal of Robotics Research* 22(12), 2003, pp. 985-1003.
.. [3] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering* 24(6), 2023,
   doi:10.1631/FITEE.2200208.
.. [4] ROS ``amcl`` (ROS 1 navigation stack: ``amcl_node.cpp``, ``cfg/AMCL.cfg``,
   ``pf/pf.c``, ``sensors/amcl_odom.cpp``, ``sensors/amcl_laser.cpp``).
.. [5] ROS ``amcl`` (ROS 1 navigation stack: ``amcl_node.cpp``, ``uniformPoseGenerator``).
"""
from __future__ import annotations

import math
import types
from typing import Any, NamedTuple

import numpy as np

from ..geometry import wrap_angle
from ..mapping import LikelihoodField, OccupancyGrid, likelihood_field
from ..sim import sample_motion_model_odometry
from ..geometry.planar import as_planar
from ..validation import as_array, as_covariance, as_int, as_positive, as_rng, describe
from .beam_models import likelihood_field_log_weights
from .particle_filter import (ROS_KLD_BIN_SIZE, ellipse_weights, kld_resample, low_variance_resample, normalise_log_weights, sample_ellipse_poses, weighted_pose_mean)

__all__ = ["AMCL_DEFAULTS", "KLDConfig", "MonteCarloLocalizer", "MCLStep", "mcl_step", "uniform_free_poses"]


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
    P = as_planar(particles, "particles", shape=(None, 3), min_count=1)
    w = as_array(weights, "weights", shape=(len(P),))
    if np.any(w < 0) or not w.sum() > 0:
        raise ValueError(f"weights: expected non-negative weights with a positive sum, got {describe(weights)}")
    u = (as_planar(odom_prev, "odom_prev", shape=(3,)), as_planar(odom_now, "odom_now", shape=(3,)))
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


#: ROS 1 amcl's defaults (module docstring): name -> value, read-only.
AMCL_DEFAULTS = types.MappingProxyType({
    "min_particles": 100, "max_particles": 5000, "kld_err": 0.01, "kld_z": 0.99,
    "update_min_d": 0.2, "update_min_a": math.pi / 6, "resample_interval": 2,
    "recovery_alpha_slow": 0.0, "recovery_alpha_fast": 0.0, "laser_max_beams": 30,
    "laser_z_hit": 0.95, "laser_z_rand": 0.05, "laser_sigma_hit": 0.2, "laser_likelihood_max_dist": 2.0,
    "odom_alpha1": 0.2, "odom_alpha2": 0.2, "odom_alpha3": 0.2, "odom_alpha4": 0.2,
})


class KLDConfig(NamedTuple):
    """KLD-sampling settings (Table 8.4); the defaults are ROS amcl's (``kld_z`` = 0.99 used as z).

    Examples
    --------
    >>> KLDConfig().max_particles, KLDConfig(z=2.326).z
    (5000, 2.326)
    """

    min_particles: int = 100
    max_particles: int = 5000
    epsilon: float = 0.01
    z: float = 0.99
    bin_size: tuple = ROS_KLD_BIN_SIZE


class MonteCarloLocalizer:
    """Adaptive Monte-Carlo localization (ROS amcl's algorithm) with Ge et al.'s keyframe start.

    Parameters
    ----------
    grid : robokit.mapping.OccupancyGrid
        The map: its free cells are where global initialization and recovery draw poses.
    field : robokit.mapping.LikelihoodField, optional
        Defaults to ``likelihood_field(grid, max_distance=2.0)`` (ROS's ``laser_likelihood_max_dist``).
    n_particles : int, default 500
        Particles of a fixed-size filter and of :meth:`initialize_uniform` (ROS starts with
        ``max_particles``; the paper's Table 2 runs AMCL with 500).
    alphas : array_like, shape (4,), default (0.2, 0.2, 0.2, 0.2)
        Odometry noise (Table 5.6; ROS's ``odom_alpha1..4``, module docstring).
    sigma_hit, z_hit, z_rand, r_max, max_beams, combine, sensor_offset
        The laser model (:func:`~robokit.localization.beam_models.likelihood_field_log_weights`);
        ``combine="ros"`` (AMCL's ``1 + sum p^3``) by default, ``max_beams`` 30.
    update_min_d, update_min_a : float, default 0.2, pi/6
        A filter update runs once the odometry moved more than ``update_min_d`` in x or y or
        turned more than ``update_min_a`` since the last one.
    resample_interval : int, default 2
        Resample every this many updates.
    kld : KLDConfig, optional
        KLD-sampling (adaptive particle count) at each resampling; ``None``: a fixed count and
        low-variance resampling.
    alpha_slow, alpha_fast : float, default 0, 0
        Augmented MCL's averaging rates (Table 8.3); both positive enables random-pose injection.
    rng : Generator or int, default 0

    Notes
    -----
    :meth:`update` is Thrun et al. (2005)'s Table 8.3 (augmented MCL) with KLD-sampling
    (Table 8.4) as the resampler, run the way ROS amcl schedules it. Ge et al. (2023)'s
    Algorithm 1 ("Improved AMCL"), line by line, with robokit's calls:

    - line 1: ``chi_t = {}``: the filter's state is replaced by the next line;
    - line 2: "Uniformly sample poses according to a keyframe retrieval": :meth:`initialize_ellipse`
      at the retrieved keyframe's pose (Eq. (18) gives it; the lead's retrieval loop calls it);
    - line 3: ``w_initial`` of Eq. (19): the weights :meth:`initialize_ellipse` sets;
    - line 4: "Robot moves forward": the odometry passed to :meth:`update`;
    - lines 5-9: for each particle, ``sample_motion_model`` and ``measurement_model``: one
      :meth:`update` (:func:`mcl_step`'s motion and weights);
    - lines 10-13: draw ``N`` particles with probability proportional to their weights: the resampling
      inside :meth:`update` (every ``resample_interval`` updates);
    - lines 14-16: "if time interval equals Delta t, go to step 2": call :meth:`initialize_ellipse`
      again with a fresh retrieval (every 5 s in the paper's kidnapping test, Sec. 4.2);
    - line 17: return ``chi_t``: :attr:`particles`, :attr:`weights`, :meth:`estimate`.

    Examples
    --------
    >>> from robokit.mapping import OccupancyGrid
    >>> prob = np.ones((30, 40)); prob[1:-1, 1:-1] = 0.0              # a 4 m x 3 m box room
    >>> mcl = MonteCarloLocalizer(OccupancyGrid.from_probability(prob, 0.1), n_particles=200, rng=1)
    >>> mcl.particles.shape, mcl.n_updates
    ((200, 3), 0)
    >>> mcl.initialize_ellipse([2.0, 1.5, 0.0], 0.3, 0.1)
    >>> len(mcl.particles), bool(np.linalg.norm(mcl.estimate()[:2] - [2.0, 1.5]) < 0.1)
    (50, True)
    """

    def __init__(self, grid: OccupancyGrid, *, field: LikelihoodField | None = None, n_particles: int = 500,
                 alphas: Any = (0.2, 0.2, 0.2, 0.2), sigma_hit: float = 0.2, z_hit: float = 0.95,
                 z_rand: float = 0.05, r_max: float = 8.0, max_beams: int | None = 30, combine: str = "ros",
                 sensor_offset: Any = (0.0, 0.0, 0.0), update_min_d: float = 0.2,
                 update_min_a: float = math.pi / 6, resample_interval: int = 2, kld: KLDConfig | None = None,
                 alpha_slow: float = 0.0, alpha_fast: float = 0.0, rng: Any = 0) -> None:
        if not isinstance(grid, OccupancyGrid):
            raise TypeError(f"grid: expected a robokit.mapping.OccupancyGrid, got {describe(grid)}")
        self.grid = grid
        self.field = likelihood_field(grid) if field is None else field
        if not isinstance(self.field, LikelihoodField):
            raise TypeError(f"field: expected a robokit.mapping.LikelihoodField, got {describe(field)}")
        self._free = grid.free_cells()                  # EmptyMapError: nowhere to put a particle
        self.n_particles = as_int(n_particles, "n_particles", minimum=1, maximum=10 ** 6)
        self.alphas = as_array(alphas, "alphas", shape=(4,))
        if np.any(self.alphas < 0):
            raise ValueError(f"alphas: expected four non-negative noise parameters, got {self.alphas.tolist()}")
        self.model = dict(sigma_hit=sigma_hit, z_hit=z_hit, z_rand=z_rand, r_max=r_max, max_beams=max_beams,
                          combine=combine, sensor_offset=sensor_offset)
        likelihood_field_log_weights(np.zeros((1, 3)), [1.0], [0.0], self.field, **self.model)  # validates model
        self.update_min_d = as_positive(update_min_d, "update_min_d", allow_zero=True)
        self.update_min_a = as_positive(update_min_a, "update_min_a", allow_zero=True)
        self.resample_interval = as_int(resample_interval, "resample_interval", minimum=1)
        if kld is not None and not isinstance(kld, KLDConfig):
            raise TypeError(f"kld: expected None or a KLDConfig, got {describe(kld)}")
        if kld is not None:
            as_int(kld.min_particles, "kld.min_particles", minimum=1)
            as_int(kld.max_particles, "kld.max_particles", minimum=kld.min_particles, maximum=10 ** 6)
        self.kld = kld
        self.alpha_slow = as_positive(alpha_slow, "alpha_slow", allow_zero=True)
        self.alpha_fast = as_positive(alpha_fast, "alpha_fast", allow_zero=True)
        if self.alpha_slow > 1 or self.alpha_fast > 1:
            raise ValueError(f"alpha_slow, alpha_fast: expected rates in [0, 1], got {alpha_slow} and {alpha_fast}")
        self.rng = as_rng(rng)
        self._odom: np.ndarray | None = None
        self.n_updates = 0
        self.n_injected = 0
        self.degenerate = False
        self.initialize_uniform()

    # --- initialization (each resets the weights and the recovery averages) --------------------
    def _reset(self, particles: np.ndarray, weights: np.ndarray | None = None) -> None:
        self.particles = particles
        self.weights = np.full(len(particles), 1.0 / len(particles)) if weights is None else weights
        self._log_w_slow = self._log_w_fast = -np.inf      # w_slow = w_fast = 0 (unset) on every init
        self._since_resample = 0

    def _random_poses(self, n: int, rng: np.random.Generator) -> np.ndarray:
        return uniform_free_poses(self._free, self.grid.resolution, n, rng)

    def initialize_uniform(self, n: int | None = None) -> None:
        """Global localization: ``n`` (default ``n_particles``) poses uniform over the free cells.

        Notes
        -----
        ROS amcl's ``global_localization`` service (:func:`uniform_free_poses`); Thrun et al.
        (2005), Sec. 8.3.2.

        Examples
        --------
        >>> from robokit.mapping import OccupancyGrid
        >>> mcl = MonteCarloLocalizer(OccupancyGrid.from_probability(np.zeros((10, 10)), 0.1), n_particles=5)
        >>> mcl.initialize_uniform(20); mcl.particles.shape
        (20, 3)
        """
        count = self.n_particles if n is None else as_int(n, "n", minimum=1, maximum=10 ** 6)
        self._reset(self._random_poses(count, self.rng))

    def initialize_gaussian(self, pose: Any, cov: Any, n: int | None = None) -> None:
        """Pose tracking from a known start: ``n`` poses drawn from ``N(pose, cov)``.

        Parameters
        ----------
        pose : array_like, shape (3,)
        cov : array_like, shape (3, 3)
            Covariance of ``[x, y, theta]`` (positive semi-definite).
        n : int, optional
            Default ``n_particles``.

        Notes
        -----
        ROS amcl's ``initialpose`` (``pf_init``); Thrun et al. (2005), Sec. 8.3.

        Examples
        --------
        >>> from robokit.mapping import OccupancyGrid
        >>> mcl = MonteCarloLocalizer(OccupancyGrid.from_probability(np.zeros((10, 10)), 0.1), rng=0)
        >>> mcl.initialize_gaussian([0.5, 0.5, 0.0], np.diag([0.01, 0.01, 0.001]), n=2000)
        >>> np.abs(mcl.estimate() - [0.5, 0.5, 0.0]).max() < 0.01
        np.True_
        """
        mean = as_planar(pose, "pose", shape=(3,))
        C = as_covariance(cov, "cov", 3, semidefinite=True)
        count = self.n_particles if n is None else as_int(n, "n", minimum=1, maximum=10 ** 6)
        P = self.rng.multivariate_normal(mean, C, size=count, method="eigh")
        P[:, 2] = wrap_angle(P[:, 2])
        self._reset(P)

    def initialize_ellipse(self, pose: Any, sigma_x: float, sigma_y: float, *, sigma_theta: float = 0.05,
                           n: int = 50, nsigma: float = 2.0) -> None:
        """Ge et al. (2023)'s start: ``n`` poses inside an ellipse around a keyframe pose, Eq. (19) weights.

        Parameters
        ----------
        pose : array_like, shape (3,)
            The retrieved keyframe's pose ``(x_k, y_k, theta_k)``.
        sigma_x, sigma_y : float
            Standard deviations along and across ``theta_k`` (m).
        sigma_theta : float, default 0.05
            Spread of the headings (rad).
        n : int, default 50
            Particles (the paper's Table 2: 50).
        nsigma : float, default 2
            Semi-axes of the ellipse in standard deviations.

        Notes
        -----
        Sec. 3.4, Fig. 10, Eq. (19) and Algorithm 1 lines 1-3
        (:func:`~robokit.localization.particle_filter.sample_ellipse_poses`,
        :func:`~robokit.localization.particle_filter.ellipse_weights`). Call it again at any time
        to re-initialize (Algorithm 1, lines 14-15: the kidnapped robot).

        Examples
        --------
        >>> from robokit.mapping import OccupancyGrid
        >>> mcl = MonteCarloLocalizer(OccupancyGrid.from_probability(np.zeros((40, 40)), 0.1), rng=0)
        >>> mcl.initialize_ellipse([2.0, 2.0, 0.0], 0.5, 0.1, n=10)
        >>> len(mcl.particles), bool(mcl.weights.argmax() == np.linalg.norm(mcl.particles[:, :2] - 2, axis=1).argmin())
        (10, True)
        """
        P = sample_ellipse_poses(pose, sigma_x, sigma_y, n, nsigma=nsigma, sigma_theta=sigma_theta, rng=self.rng)
        self._reset(P, ellipse_weights(P, pose, sigma_x, sigma_y))       # Eq. (19)

    # --- the filter ----------------------------------------------------------------------------
    def due(self, odometry_pose: Any) -> bool:
        """Whether :meth:`update` with this odometry pose would run a filter update.

        True when the odometry has moved more than ``update_min_d`` along x or y, or turned more
        than ``update_min_a``, since the last update (ROS amcl's ``update_min_d`` and
        ``update_min_a``); false before the first odometry pose is known. A simulation can skip
        rendering a scan the filter would not use.

        Parameters
        ----------
        odometry_pose : array_like, shape (3,)

        Returns
        -------
        bool

        Examples
        --------
        >>> from robokit.mapping import OccupancyGrid
        >>> mcl = MonteCarloLocalizer(OccupancyGrid.from_probability(np.zeros((10, 10)), 0.1), n_particles=10)
        >>> mcl.due([0.5, 0, 0]), mcl.update([0, 0, 0], [1.0]), mcl.due([0.1, 0, 0]), mcl.due([0.3, 0, 0])
        (False, False, False, True)
        """
        return self._moved(as_planar(odometry_pose, "odometry_pose", shape=(3,)))

    def _moved(self, odom: np.ndarray) -> bool:
        """:meth:`due` for a checked odometry pose."""
        if self._odom is None:
            return False
        d = odom - self._odom
        return bool(abs(d[0]) > self.update_min_d or abs(d[1]) > self.update_min_d
                    or abs(wrap_angle(d[2])) > self.update_min_a)

    def update(self, odometry_pose: Any, ranges: Any, angles: Any = None, *, force: bool = False) -> bool:
        """Feed one odometry pose and scan; run a filter update if the robot moved enough.

        Parameters
        ----------
        odometry_pose : array_like, shape (3,)
            The odometry's pose (its own drifting frame: only increments are used).
        ranges : array_like, shape (B,)
            The scan (``inf`` = max range, skipped; NaN raises).
        angles : array_like, shape (B,), optional
            Beam angles in the sensor frame; default ``2 pi i / B`` (:class:`robokit.sim.Lidar`).
        force : bool, default False
            Update even without motion (ROS's ``force_update_after_initialpose``).

        Returns
        -------
        bool
            Whether an update ran. The first call only stores the odometry (amcl runs a sensor update
            on its first scan; ours waits for motion, or ``force``).

        Notes
        -----
        Thrun et al. (2005), Table 8.3: motion and weights, ``w_avg`` (the
        weighted mean of the likelihoods ``log_mean``, which is the table's plain mean right after
        a resampling), ``w_slow += alpha_slow (w_avg - w_slow)`` and ``w_fast`` likewise (kept
        as logs), and at a resampling each new particle is a uniform random pose with
        probability ``max(0, 1 - w_fast / w_slow)``. The averages start at the first
        ``w_avg`` (ROS; Table 8.3 starts them at 0, which holds off any recovery for about
        ``1 / alpha_slow`` updates) and are never reset (Table 8.3; ROS resets both after every
        injection and so re-seeds them at the next, possibly already low, ``w_avg``); an
        initialization resets them. All-zero weights recover as uniform (:attr:`degenerate` set).

        Examples
        --------
        >>> from robokit.mapping import OccupancyGrid
        >>> mcl = MonteCarloLocalizer(OccupancyGrid.from_probability(np.zeros((10, 10)), 0.1), n_particles=10)
        >>> mcl.update([0, 0, 0], [1.0]), mcl.update([0.1, 0, 0], [1.0]), mcl.update([0.3, 0, 0], [1.0])
        (False, False, True)
        """
        odom = as_planar(odometry_pose, "odometry_pose", shape=(3,))
        r = as_array(ranges, "ranges", ndim=1, finite=False, min_size=1)
        if np.any(np.isnan(r)):
            raise ValueError("ranges: expected ranges or inf (a max-range return), got NaN")
        a = 2 * np.pi * np.arange(r.size) / r.size if angles is None else angles
        if self._odom is None:
            self._odom = odom
            return False
        if not (force or self._moved(odom)):
            return False
        step = mcl_step(self.particles, self.weights, self._odom, odom, r, a, self.field, alphas=self.alphas,
                        resample=False, rng=self.rng, **self.model)
        self.particles, self.weights, self.degenerate, log_avg = step                 # Table 8.3: motion, weights, w_avg
        self._odom = odom
        self.n_updates += 1
        if not self.degenerate and self.alpha_slow > 0 and self.alpha_fast > 0:
            self._log_w_slow = self._average(self._log_w_slow, log_avg, self.alpha_slow)   # Table 8.3: w_slow, w_fast
            self._log_w_fast = self._average(self._log_w_fast, log_avg, self.alpha_fast)
        self._since_resample += 1
        if self._since_resample >= self.resample_interval:
            self._resample()
        return True

    @staticmethod
    def _average(log_w: float, log_avg: float, alpha: float) -> float:
        if log_w == -np.inf:
            return log_avg                                  # ROS seeds the average with the first w_avg
        return float(np.logaddexp(np.log1p(-alpha) + log_w, np.log(alpha) + log_avg)) if alpha < 1 else log_avg

    @property
    def inject_probability(self) -> float:
        """``max(0, 1 - w_fast / w_slow)``: the chance a resampled particle is random (Table 8.3)."""
        if not np.isfinite(self._log_w_slow) or not np.isfinite(self._log_w_fast):
            return 0.0
        return max(0.0, 1.0 - math.exp(min(self._log_w_fast - self._log_w_slow, 50.0)))

    def _resample(self) -> None:
        p_inj = self.inject_probability
        if self.kld is not None:
            k = self.kld
            new = kld_resample(self.particles, self.weights, self.rng, min_count=k.min_particles,
                               max_count=k.max_particles, epsilon=k.epsilon, z=k.z, bin_size=k.bin_size,
                               random_pose=self._random_poses, inject_probability=p_inj)
        else:
            n = len(self.particles)
            injected = self.rng.random(n) < p_inj                           # Table 8.3: max(0, 1 - w_fast / w_slow)
            new = np.empty((n, 3))
            new[injected] = self._random_poses(int(injected.sum()), self.rng)
            if (~injected).any():
                new[~injected] = self.particles[low_variance_resample(self.weights, self.rng, int((~injected).sum()))]
        self.n_injected = int(round(p_inj * len(new))) if p_inj > 0 else 0
        log_slow, log_fast = self._log_w_slow, self._log_w_fast
        self._reset(new)
        self._log_w_slow, self._log_w_fast = log_slow, log_fast    # Table 8.3 never resets them

    # --- results -------------------------------------------------------------------------------
    def estimate(self) -> np.ndarray:
        """The weighted mean pose of all particles (:func:`~robokit.localization.particle_filter.weighted_pose_mean`).

        Not the pose ROS amcl publishes: amcl reports the weighted mean of the heaviest particle
        cluster (:func:`~robokit.localization.particle_clusters.largest_cluster_mean`). While the cloud
        holds several clusters (after a global start, in a corridor of look-alike stretches) the
        mean of all particles lies between them, near none.

        Examples
        --------
        >>> from robokit.localization import largest_cluster_mean
        >>> from robokit.mapping import OccupancyGrid
        >>> mcl = MonteCarloLocalizer(OccupancyGrid.from_probability(np.zeros((100, 100)), 0.1), rng=0)
        >>> mcl.initialize_gaussian([0.3, 0.6, 1.0], np.zeros((3, 3)), n=3); mcl.estimate().tolist()
        [0.3, 0.6, 1.0]
        >>> mcl.particles = np.array([[1.0, 1.0, 0.0]] * 3 + [[7.0, 1.0, 0.0]] * 2)   # two clusters
        >>> mcl.weights = np.full(5, 0.2)
        >>> mcl.estimate().round(2).tolist(), largest_cluster_mean(mcl.particles, mcl.weights).round(2).tolist()
        ([3.4, 1.0, 0.0], [1.0, 1.0, 0.0])
        """
        return weighted_pose_mean(self.particles, self.weights)

    def converged(self, dist_threshold: float = 0.5) -> bool:
        """ROS amcl's ``pf_update_converged``: every particle within ``dist_threshold`` of the mean in x and in y.

        Examples
        --------
        >>> from robokit.mapping import OccupancyGrid
        >>> mcl = MonteCarloLocalizer(OccupancyGrid.from_probability(np.zeros((100, 100)), 0.1), rng=0)
        >>> mcl.converged(), (mcl.initialize_ellipse([5.0, 5.0, 0.0], 0.1, 0.1), mcl.converged())[1]
        (False, True)
        """
        t = as_positive(dist_threshold, "dist_threshold")
        mean = self.particles[:, :2].mean(axis=0)          # ROS: the unweighted mean
        return bool(np.all(np.abs(self.particles[:, :2] - mean) <= t))
