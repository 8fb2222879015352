"""Localization: RANSAC ego-motion and Hough-transform global localization (Lin et al.; Se et al.).

Modules: :mod:`.egomotion` (Lin et al. Sec. 4-7), :mod:`.hough` (Se et al. Sec. 5),
:mod:`.visual_slam` (the whole pipeline over a stereo sequence) and :mod:`.hierarchical` (lesson 02:
coarse-to-fine localization in a topological map). They depend on :mod:`robokit.vision`
and :mod:`robokit.mapping`, never on ``viz``; :mod:`.hierarchical` uses its omni camera model (rays, mount), never its renderer, and
:mod:`.pose_ekf` (lesson 02's EKF over ``(x, y, theta, v, omega)``, imported on demand:
``from robokit.localization.pose_ekf import UnicycleEKF``) takes the one unicycle model,
:func:`robokit.sim.unicycle_step`, for its prediction.

Monte-Carlo localization (lesson 03, Ge et al. 2023 and Thrun et al. 2005): :mod:`.particle_filter`
(weights, low-variance and KLD resampling, the paper's ellipse start of Eq. (19)),
:mod:`.beam_models` (the likelihood-field laser model, Table 6.3 and ROS amcl's variant) and
:mod:`.mcl_step` (one MCL step on arrays) and :mod:`.mcl` (:class:`MonteCarloLocalizer`: ROS amcl's
adaptive MCL with the paper's Algorithm 1). They use :mod:`robokit.mapping`'s occupancy grid and likelihood field and
:mod:`robokit.sim`'s odometry motion model.
"""
from .egomotion import (DegenerateCorrespondenceError, EgomotionResult, InsufficientMatchesError,
                        continuation_matches, fit_pose, pose_from_two, ransac_pose, ransac_sample_count, track)
from .hierarchical import MODES, HierarchicalLocalizer, Localization
from .hough import Hypothesis, candidate_matches, global_localize, hough_accumulator
from .visual_slam import FrameReport, VisualSLAM
from .beam_models import (COMBINE_RULES, likelihood_field_log_weight_readable, likelihood_field_log_weights,
                          subsample_beams, valid_beams)
from .mcl import AMCL_DEFAULTS, KLDConfig, MonteCarloLocalizer
from .mcl import MCLStep, mcl_step, uniform_free_poses
from .particle_clusters import largest_cluster_mean, largest_cluster_share, pose_clusters
from .particle_filter import (KLD_Z_99, ROS_KLD_BIN_SIZE, NormalisedWeights, ellipse_weights, kld_resample,
                              kld_sample_count, low_variance_resample, normalise_log_weights, pose_bins,
                              sample_ellipse_poses, weighted_pose_mean)

__all__ = ["DegenerateCorrespondenceError", "EgomotionResult", "InsufficientMatchesError", "continuation_matches",
           "fit_pose", "pose_from_two", "ransac_pose", "ransac_sample_count", "track", "Hypothesis",
           "candidate_matches", "global_localize", "hough_accumulator", "FrameReport", "VisualSLAM",
           "MODES", "HierarchicalLocalizer", "Localization",
           "COMBINE_RULES", "likelihood_field_log_weight_readable", "likelihood_field_log_weights", "subsample_beams",
           "valid_beams", "AMCL_DEFAULTS", "KLDConfig", "MCLStep", "MonteCarloLocalizer", "mcl_step",
           "uniform_free_poses", "KLD_Z_99", "ROS_KLD_BIN_SIZE", "NormalisedWeights", "ellipse_weights",
           "kld_resample", "kld_sample_count", "low_variance_resample", "normalise_log_weights", "pose_bins",
           "sample_ellipse_poses", "weighted_pose_mean", "pose_clusters", "largest_cluster_share", "largest_cluster_mean"]
