"""Localization: RANSAC ego-motion and Hough-transform global localization (Lin et al.; Se et al.).

Modules: :mod:`.egomotion` (Lin et al. Sec. 4-7) and :mod:`.hough` (Se et al. Sec. 5). Depends on
:mod:`robokit.vision` and :mod:`robokit.mapping`, never on ``viz`` or ``sim``.
"""
from .egomotion import (DegenerateCorrespondenceError, EgomotionResult, InsufficientMatchesError,
                        continuation_matches, fit_pose, pose_from_two, ransac_pose, ransac_sample_count, track)
from .hough import Hypothesis, candidate_matches, global_localize, hough_accumulator

__all__ = ["DegenerateCorrespondenceError", "EgomotionResult", "InsufficientMatchesError", "continuation_matches",
           "fit_pose", "pose_from_two", "ransac_pose", "ransac_sample_count", "track", "Hypothesis",
           "candidate_matches", "global_localize", "hough_accumulator"]
