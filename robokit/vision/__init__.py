"""Vision: PLOT and SIFT features, descriptor matching, evaluation, rectified stereo, colour.

Modules: :mod:`.features` (containers), :mod:`.plot_detector` (Lin et al. Sec. 2.i),
:mod:`.descriptors` (Lin et al. Sec. 2.ii, Se et al. Sec. 4, OpenCV SIFT), :mod:`.matching`
(Lin et al. Sec. 3), :mod:`.evaluation` (recall vs 1-precision), :mod:`.stereo` (Lin et al. Sec. 3,
Se et al. Sec. 2.2 and 3.1), :mod:`.colour` (HSI hue histograms, lesson 02's paper, Sec. "Global
image features"), :mod:`.omni_features` (SIFT in an omni image's annulus, Sec. "Local image
features"; its KD-tree per map node is :class:`.matching.DescriptorIndex`). Vision depends only on :mod:`robokit.validation` (never on ``viz`` or
``sim``).
"""
from .colour import (histogram_distance, histogram_intersection, hue_histogram, hue_histogram_opencv, hue_mask,
                     rgb_to_hsi)
from .descriptors import (assign_orientations, detect_and_describe, gradient_histogram_descriptor,
                          detect_plot_features, reduced_descriptor, sift_descriptor, detect_sift_features)
from .evaluation import apply_homography, recall_precision, similarity_homography, warp_image
from .features import Features, Keypoints, as_gray_image
from .matching import DescriptorIndex, Matches, k_nearest, ratio_match, ratio_test, two_nearest
from .omni_features import ImageSizeError, annulus_mask, omni_sift, radial_orientation
from .plot_detector import (PlotParams, ScaleSpace, detect_plot, detect_plot_levels, edge_strength, junction_strength,
                   orientation_tensor, plot_scales, polynomial_expansion, tensor_eigenvalues)
from .stereo import (NotRectifiedError, StereoMatches, StereoObservations, StereoCalibration, disparity_to_point,
                     match_stereo, observe_stereo, triangulate_svd)

__all__ = ["assign_orientations", "detect_and_describe", "gradient_histogram_descriptor", "detect_plot_features",
           "reduced_descriptor", "sift_descriptor", "detect_sift_features", "apply_homography", "recall_precision", "warp_image",
           "similarity_homography", "Features", "Keypoints", "as_gray_image", "Matches", "ratio_match",
           "two_nearest", "k_nearest", "PlotParams", "ScaleSpace", "detect_plot", "detect_plot_levels", "edge_strength",
           "junction_strength", "orientation_tensor", "plot_scales", "polynomial_expansion",
           "tensor_eigenvalues", "NotRectifiedError", "StereoMatches", "StereoCalibration", "disparity_to_point",
           "match_stereo", "triangulate_svd", "StereoObservations", "observe_stereo",
           "rgb_to_hsi", "hue_mask", "hue_histogram", "hue_histogram_opencv", "histogram_distance",
           "histogram_intersection", "DescriptorIndex", "ratio_test", "ImageSizeError", "annulus_mask", "omni_sift",
           "radial_orientation"]
