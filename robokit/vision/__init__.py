"""Vision: PLOT and SIFT features, descriptor matching, evaluation, rectified stereo, colour.

Modules: :mod:`.features` (containers), :mod:`.plot_detector` (Lin et al. Sec. 2.i; its plain
reference :mod:`.plot_readable`),
:mod:`.descriptors` (Lin et al. Sec. 2.ii, Se et al. Sec. 4, OpenCV SIFT), :mod:`.ratio` (the
distance-ratio test, Lin et al. Sec. 3), :mod:`.matching` (the neighbour searches behind it), :mod:`.evaluation` (recall vs 1-precision, matching score), :mod:`.stereo` (Lin et al. Sec. 3,
Se et al. Sec. 2.2 and 3.1), :mod:`.colour` (HSI hue histograms, lesson 02's paper, Sec. "Global
image features"), :mod:`.omni_features` (SIFT in an omni image's annulus, Sec. "Local image
features"; its KD-tree per map node is :class:`.matching.DescriptorIndex`), :mod:`.ransac` (the
sample count and a planar RANSAC), :mod:`.spherical` (the essential matrix of omni bearings, floor
points below the horizon). Vision depends only on :mod:`robokit.validation` and
:mod:`robokit.geometry` (never on ``viz`` or ``sim``). Lesson 03 (Ge et al. 2023) adds :mod:`.orb`
(OpenCV ORB as :class:`Features`), :mod:`.hamming` (the one Hamming distance for binary
descriptors), :mod:`.keyframes` (Sec. 3.2's keyframe conditions and an ORB-SLAM-like rule),
:mod:`.bag_of_words` (the vocabulary tree, Sec. 3.3), :mod:`.bag_of_words` (TF-IDF and the L1
score, Eqs. (16)-(17)) and :mod:`.bow_database` (the inverted index, Fig. 7).
"""
from .bag_of_words import TooFewDescriptorsError, Vocabulary, VocabularyFileError
from .bow_database import BowDatabase, DatabaseFileError, QueryResult
from .bag_of_words import BowVector, as_bow_vector, l1_score, tf_idf
from .colour import (histogram_distance, histogram_intersection, hue_histogram, hue_histogram_opencv, hue_mask,
                     rgb_to_hsi)
from .descriptors import (assign_orientations, detect_and_describe, gradient_histogram_descriptor,
                          detect_plot_features, reduced_descriptor, sift_descriptor, detect_sift_features)
from .evaluation import apply_homography, matching_score, recall_precision, similarity_homography, warp_image
from .features import Features, Keypoints, as_gray_image
from .hamming import as_binary_descriptors, hamming_distance, hamming_distances, hamming_match
from .keyframes import (KeyframeConditions, KeyframeSelector, feature_threshold, select_keyframes,
                        select_keyframes_orbslam, shared_fraction)
from .matching import DescriptorIndex, Matches, k_nearest, ratio_match, ratio_test, two_nearest
from .plot_detector import scale_space_maxima
from .orb import detect_orb_features
from .omni_features import ImageSizeError, annulus_mask, omni_sift, radial_orientation
from .ransac import PlanarFit, ransac_sample_count, ransac_se2
from .spherical import (EssentialFit, as_bearings, decompose_essential, epipolar_error, essential_from_bearings,
                        floor_points, ransac_essential)
from .plot_detector import (PlotParams, ScaleSpace, detect_plot, detect_plot_levels, edge_strength, junction_strength,
                   orientation_tensor, plot_scales, polynomial_expansion, tensor_eigenvalues)
from .stereo import (NotRectifiedError, StereoMatches, StereoObservations, StereoCalibration, disparity_to_point,
                     match_stereo, observe_stereo, triangulate_svd)

__all__ = ["assign_orientations", "detect_and_describe", "gradient_histogram_descriptor", "detect_plot_features",
           "reduced_descriptor", "sift_descriptor", "detect_sift_features", "apply_homography", "matching_score", "recall_precision", "warp_image",
           "similarity_homography", "Features", "Keypoints", "as_gray_image", "Matches", "ratio_match",
           "two_nearest", "k_nearest", "PlotParams", "ScaleSpace", "detect_plot", "detect_plot_levels", "edge_strength",
           "junction_strength", "orientation_tensor", "plot_scales", "polynomial_expansion",
           "tensor_eigenvalues", "NotRectifiedError", "StereoMatches", "StereoCalibration", "disparity_to_point",
           "match_stereo", "triangulate_svd", "StereoObservations", "observe_stereo",
           "rgb_to_hsi", "hue_mask", "hue_histogram", "hue_histogram_opencv", "histogram_distance",
           "histogram_intersection", "DescriptorIndex", "ratio_test", "scale_space_maxima", "ImageSizeError",
           "annulus_mask", "omni_sift",
           "radial_orientation", "PlanarFit", "ransac_sample_count", "ransac_se2", "EssentialFit", "as_bearings",
           "decompose_essential", "epipolar_error", "essential_from_bearings", "floor_points", "ransac_essential",
           "detect_orb_features", "as_binary_descriptors", "hamming_distance", "hamming_distances", "hamming_match",
           "KeyframeConditions", "KeyframeSelector", "feature_threshold", "select_keyframes",
           "select_keyframes_orbslam", "shared_fraction", "BowVector", "TooFewDescriptorsError", "Vocabulary",
           "VocabularyFileError", "as_bow_vector", "l1_score", "tf_idf", "BowDatabase", "DatabaseFileError",
           "QueryResult"]
