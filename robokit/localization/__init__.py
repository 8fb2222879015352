"""Localization: RANSAC ego-motion and Hough-transform global localization (Lin et al.; Se et al.).

Modules: :mod:`.egomotion` (Lin et al. Sec. 4-7), :mod:`.hough` (Se et al. Sec. 5),
:mod:`.visual_slam` (the whole pipeline over a stereo sequence) and :mod:`.hierarchical` (lesson 02:
coarse-to-fine localization in a topological map). They depend on :mod:`robokit.vision`
and :mod:`robokit.mapping`, never on ``viz``; only :mod:`.lab_experiment` (Se et al. Sec. 6 re-run
in the simulated lab, imported on demand) uses :mod:`robokit.sim` to render views,
:mod:`.hierarchical` uses its omni camera model (rays, mount), never its renderer, and
:mod:`.pose_ekf` (lesson 02's EKF over ``(x, y, theta, v, omega)``, imported on demand:
``from robokit.localization.pose_ekf import UnicycleEKF``) takes the one unicycle model,
:func:`robokit.sim.unicycle_step`, for its prediction.
"""
from .egomotion import (DegenerateCorrespondenceError, EgomotionResult, InsufficientMatchesError,
                        continuation_matches, fit_pose, pose_from_two, ransac_pose, ransac_sample_count, track)
from .hierarchical import MODES, HierarchicalLocalizer, Localization
from .hough import Hypothesis, candidate_matches, global_localize, hough_accumulator
from .visual_slam import FrameReport, VisualSLAM

__all__ = ["DegenerateCorrespondenceError", "EgomotionResult", "InsufficientMatchesError", "continuation_matches",
           "fit_pose", "pose_from_two", "ransac_pose", "ransac_sample_count", "track", "Hypothesis",
           "candidate_matches", "global_localize", "hough_accumulator", "FrameReport", "VisualSLAM",
           "MODES", "HierarchicalLocalizer", "Localization"]
