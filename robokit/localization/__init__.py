"""Localization: ego-motion, global localization, visual SLAM, hierarchical and Monte-Carlo localization.

egomotion          Lin et al.'s RANSAC ego-motion from 3D matches (Secs. 4-7) and frame-to-map tracking
hough              Se et al.'s Hough-transform global localization (Sec. 5)
visual_slam        the whole stereo pipeline over a sequence: VisualSLAM
hierarchical       lesson 02's coarse-to-fine localization in a topological map
appearance_mcl     lesson 02's Monte-Carlo check: image-based MCL over a short drive decides between places
pose_ekf           lesson 02's EKF over (x, y, theta, v, omega) on the unicycle model
particle_filter    normalised weights, low-variance and KLD resampling, Ge et al.'s ellipse start (Eq. (19))
particle_clusters  ROS amcl's clusters of particles and the largest one's share
beam_models        the likelihood-field laser model (Thrun et al. Table 6.3, and amcl's rule)
scan_matching      correlative scan matching (Olson 2009) on the likelihood field
mcl                one MCL step on arrays, and MonteCarloLocalizer: amcl's adaptive MCL, augmented MCL,
                   Ge et al.'s Algorithm 1
"""
from .egomotion import (DegenerateCorrespondenceError, EgomotionResult, InsufficientMatchesError, fit_pose,
                        pose_from_two, ransac_pose, track)
from .hough import Hypothesis, global_localize, hough_accumulator
from .visual_slam import FrameReport, VisualSLAM
from .hierarchical import HierarchicalLocalizer, Localization, MODES, TOP_K
from .particle_filter import (ellipse_weights, kld_resample, low_variance_resample, normalise_log_weights,
                              sample_ellipse_poses, weighted_pose_mean)
from .beam_models import likelihood_field_log_weight_readable, likelihood_field_log_weights
from .mcl import AMCL_DEFAULTS, KLDConfig, MCLStep, MonteCarloLocalizer, mcl_step, uniform_free_poses
from .particle_clusters import largest_cluster_mean, largest_cluster_share, pose_clusters
from .scan_matching import ScanMatch, match_scan

__all__ = ["DegenerateCorrespondenceError", "EgomotionResult", "InsufficientMatchesError", "fit_pose",
           "pose_from_two", "ransac_pose", "track", "Hypothesis", "global_localize", "hough_accumulator",
           "FrameReport", "VisualSLAM", "HierarchicalLocalizer", "Localization", "MODES", "TOP_K", "ellipse_weights",
           "kld_resample", "low_variance_resample", "normalise_log_weights", "sample_ellipse_poses",
           "weighted_pose_mean", "likelihood_field_log_weight_readable", "likelihood_field_log_weights",
           "AMCL_DEFAULTS", "KLDConfig", "MCLStep", "MonteCarloLocalizer", "mcl_step", "uniform_free_poses",
           "largest_cluster_mean", "largest_cluster_share", "pose_clusters", "ScanMatch", "match_scan"]
