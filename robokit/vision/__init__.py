"""Vision: PLOT, SIFT and ORB features, descriptor matching, stereo, colour, bags of words.

Vision needs only :mod:`robokit.geometry` (never the simulator or ``viz``).

features       Keypoints and Features (keypoints with descriptors), the grey-image check
plot_detector  PLOT keypoints (Lin et al. Sec. 2.i) and the search for maxima in scale space
plot_readable  the PLOT detector as a plain full-resolution loop, which the tests compare it with
descriptors    SIFT-like and Se et al.'s 16-element descriptors, orientations, OpenCV's SIFT
matching       the distance-ratio test (Lin et al. Sec. 3) and the neighbour searches behind it:
               KD-tree, blocked products, OpenCV brute force and FLANN, a DescriptorIndex per node
evaluation     recall vs 1-precision, the matching score, homographies for warped test images
stereo         rectified stereo: calibration, matching along rows, disparity to 3D points, SVD
               triangulation (Lin et al. Sec. 3; Se et al. Secs. 2.2, 3.1)
colour         HSI colour and hue histograms (lesson 02's coarse stage, Eqs. (4)-(5))
omni_features  SIFT inside an omnidirectional image's annulus (lesson 02's fine stage)
ransac         the RANSAC sample count and a planar RANSAC fit
spherical      the essential matrix of omni bearings, its decomposition and RANSAC, floor points
orb            OpenCV ORB features (Ge et al. 2023, Sec. 3.2)
hamming        Hamming distances of binary descriptors and ORB-SLAM-style matching
keyframes      lesson 03's keyframe conditions (Eq. (15) and conditions (1)-(4)) and an ORB-SLAM-like rule
bag_of_words   a vocabulary tree of binary words, TF-IDF vectors and their L1 score (Eqs. (16)-(17))
bow_database   the inverted index of a bag-of-words database (Fig. 7, as DBoW2)
"""
from .features import Features, Keypoints
from .plot_detector import PlotParams, detect_plot, junction_strength, plot_scales
from .descriptors import detect_and_describe, detect_plot_features, detect_sift_features
from .matching import DescriptorIndex, Matches, ratio_match
from .evaluation import matching_score, recall_precision, similarity_homography, warp_image
from .stereo import (NotRectifiedError, StereoCalibration, StereoObservations, disparity_to_point, match_stereo,
                     observe_stereo, triangulate_svd)
from .colour import (histogram_distance, histogram_intersection, hue_histogram, hue_histogram_opencv, hue_mask,
                     rgb_to_hsi)
from .omni_features import ImageSizeError, omni_sift
from .ransac import PlanarFit, ransac_sample_count, ransac_se2
from .spherical import EssentialFit, essential_from_bearings, ransac_essential
from .orb import detect_orb_features
from .hamming import as_binary_descriptors, hamming_distance, hamming_distances, hamming_match
from .keyframes import (TRACK_DISTANCE, TRACK_WINDOW, KeyframeConditions, KeyframeSelector, feature_threshold,
                        matched_points, select_keyframes, select_keyframes_orbslam, shared_fraction, tracked_fraction,
                        tracked_matches)
from .bag_of_words import BowVector, TooFewDescriptorsError, Vocabulary, VocabularyFileError, l1_score, tf_idf
from .bow_database import BowDatabase, DatabaseFileError, QueryResult

__all__ = ["Features", "Keypoints", "PlotParams", "detect_plot", "junction_strength", "plot_scales",
           "detect_and_describe", "detect_plot_features", "detect_sift_features", "DescriptorIndex", "Matches",
           "ratio_match", "matching_score", "recall_precision", "similarity_homography", "warp_image",
           "NotRectifiedError", "StereoCalibration", "StereoObservations", "disparity_to_point", "match_stereo",
           "observe_stereo", "triangulate_svd", "histogram_distance", "histogram_intersection", "hue_histogram",
           "hue_histogram_opencv", "hue_mask", "rgb_to_hsi", "ImageSizeError", "omni_sift", "PlanarFit",
           "ransac_sample_count", "ransac_se2", "EssentialFit", "essential_from_bearings", "ransac_essential",
           "detect_orb_features", "as_binary_descriptors", "hamming_distance", "hamming_distances", "hamming_match",
           "KeyframeConditions", "KeyframeSelector", "feature_threshold", "select_keyframes",
           "select_keyframes_orbslam", "shared_fraction", "tracked_fraction", "tracked_matches", "matched_points",
           "TRACK_WINDOW", "TRACK_DISTANCE", "BowVector", "TooFewDescriptorsError", "Vocabulary", "VocabularyFileError",
           "l1_score", "tf_idf", "BowDatabase", "DatabaseFileError", "QueryResult"]
