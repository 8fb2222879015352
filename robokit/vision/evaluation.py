"""Recall vs 1-precision of feature matching with ground-truth homographies.

Lin et al. Sec. 2.iii compare PLOT and SIFT with the protocol of Mikolajczyk & Schmid (2005):
``recall = #correct matches / #correspondences`` and
``1 - precision = #false matches / (#correct matches + #false matches)``, sweeping the matching
threshold (0.15 .. 0.7 for the nearest-neighbour ratio). Image pairs are related by a known
homography, so a match is correct when the warped keypoint lands within a tolerance of its partner.
:func:`matching_score` rates detector and descriptor together in one number per pair
(Mikolajczyk et al. 2005): correct matches over the keypoints the two images can share.

References
----------
.. [1] K. Mikolajczyk and C. Schmid, "A performance evaluation of local descriptors", IEEE Trans.
   Pattern Analysis and Machine Intelligence 27(10), 1615-1630, 2005.
.. [2] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [3] K. Mikolajczyk, T. Tuytelaars, C. Schmid, A. Zisserman, J. Matas, F. Schaffalitzky, T. Kadir
   and L. Van Gool, "A comparison of affine region detectors", International Journal of Computer
   Vision 65(1-2), 43-72, 2005.
.. [4] R. Hartley and A. Zisserman, *Multiple View Geometry in Computer Vision*, 2nd ed., Cambridge
   University Press, 2004.
"""
from __future__ import annotations

import cv2
import numpy as np
from scipy.spatial import cKDTree

from ..validation import as_array, as_points, as_finite_scalar, as_positive
from .features import Features
from .matching import two_nearest
from .matching import distance_ratio

__all__ = ["apply_homography", "warp_image", "similarity_homography", "recall_precision", "matching_score"]


def _homography(h) -> np.ndarray:
    arr = as_array(h, "homography", shape=(3, 3))
    if abs(np.linalg.det(arr)) < 1e-12:
        raise ValueError("homography: expected an invertible 3 x 3 matrix, got a singular one")
    return arr


def apply_homography(homography, points) -> np.ndarray:
    """Map pixel points ``(x, y)`` through a 3 x 3 homography.

    Parameters
    ----------
    homography : array_like, shape (3, 3)
    points : array_like, shape (N, 2)

    Returns
    -------
    numpy.ndarray, shape (N, 2)

    Raises
    ------
    ValueError
        For a singular homography or a point mapped to infinity.

    Notes
    -----
    Hartley & Zisserman 2004, Sec. 2.3 (projective transformation of the plane).
    """
    h = _homography(homography)
    pts = as_points(points, "points", 2)
    hom = np.column_stack([pts, np.ones(len(pts))]) @ h.T
    if np.any(np.abs(hom[:, 2]) < 1e-12):
        raise ValueError("points: a point maps to infinity under the homography")
    return hom[:, :2] / hom[:, 2:]


_MAX_SIDE = 32767   # far above any image of the course; a larger side would only exhaust memory


def warp_image(image, homography, shape=None) -> np.ndarray:
    """Warp an image by a homography (image B of a test pair, pixels outside filled with 0).

    Parameters
    ----------
    image : numpy.ndarray, shape (H, W), (H, W, 3) or (H, W, 4), uint8 or float32
    homography : array_like, shape (3, 3)
        Maps pixels ``(x, y)`` of ``image`` to the output.
    shape : tuple (H', W'), optional
        Output size, integers between 1 and 32767; default the input's.

    Returns
    -------
    numpy.ndarray
        Same dtype and channels as ``image``.

    Raises
    ------
    ValueError
        For an empty image, a singular homography or a bad shape.

    Notes
    -----
    Builds the pairs of Mikolajczyk & Schmid's protocol (Lin et al. Sec. 2.iii) with OpenCV's
    bilinear ``warpPerspective``.

    Examples
    --------
    >>> from robokit.vision import similarity_homography, warp_image
    >>> import numpy as np
    >>> image = np.zeros((60, 80), np.uint8)
    >>> image[25:35, 50:70] = 255                        # a bright bar right of the centre
    >>> turned = warp_image(image, similarity_homography(image.shape, angle=np.pi / 2))
    >>> rows, cols = np.nonzero(turned > 127)
    >>> turned.shape, bool(np.ptp(rows) > np.ptp(cols))   # the horizontal bar now stands upright
    ((60, 80), True)
    """
    img = as_array(image, "image", dtype=None)
    if img.ndim not in (2, 3) or img.shape[0] == 0 or img.shape[1] == 0 or img.ndim == 3 and img.shape[2] not in (3, 4):
        raise ValueError(f"image: expected a non-empty (H, W), (H, W, 3) or (H, W, 4) array, got shape {img.shape}")
    h = _homography(homography)
    out = img.shape[:2] if shape is None else tuple(int(v) for v in as_array(shape, "shape", shape=(2,), dtype=int))
    if min(out) < 1 or max(out) > _MAX_SIDE:
        raise ValueError(f"shape: expected (H, W) between 1 and {_MAX_SIDE}, got {out}")
    if img.dtype not in (np.uint8, np.float32):
        img = img.astype(np.float32)
        if not np.all(np.isfinite(img)):
            raise ValueError("image: expected values that fit float32 (|x| < 3.4e38), got larger ones")
    return cv2.warpPerspective(np.ascontiguousarray(img), h, (out[1], out[0]), flags=cv2.INTER_LINEAR)


def similarity_homography(shape, zoom: float = 1.0, angle: float = 0.0) -> np.ndarray:
    """Homography that zooms by ``zoom`` and rotates by ``angle`` about the image centre.

    Parameters
    ----------
    shape : tuple (H, W)
        Image shape (an image's full ``shape`` will do: its first two entries are used).
    zoom : float, default 1
        Scale factor (> 0).
    angle : float, default 0
        Rotation in radians (counter-clockwise on screen, i.e. from +x towards -y).

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        Use with ``cv2.warpPerspective(image, H, (W, H))`` to build a "Boat"-like pair.

    Notes
    -----
    The zoom + rotation change of Lin et al.'s "Boat" pair (Sec. 2.iii).

    Examples
    --------
    >>> from robokit.vision import similarity_homography
    >>> from robokit.vision.evaluation import apply_homography
    >>> H = similarity_homography((480, 640), zoom=2.0)          # zoom about the image centre
    >>> apply_homography(H, [[319.5, 239.5], [329.5, 239.5]]).round(2).tolist()
    [[319.5, 239.5], [339.5, 239.5]]
    """
    dims = as_array(shape, "shape")
    if dims.ndim != 1 or dims.size < 2 or np.any(dims[:2] < 1):
        raise ValueError(f"shape: expected (H, W) with positive sizes, got {shape!r}")
    zoom = as_positive(zoom, "zoom")
    angle = as_finite_scalar(angle, "angle")
    cx, cy = (dims[1] - 1) / 2, (dims[0] - 1) / 2
    c, s = zoom * np.cos(angle), zoom * np.sin(angle)
    # y points down, so a counter-clockwise on-screen rotation is [[c, s], [-s, c]]
    return np.array([[c, s, cx - c * cx - s * cy], [-s, c, cy + s * cx - c * cy], [0.0, 0.0, 1.0]])


def _require_features(*features):
    for name, f in zip(("features_a", "features_b"), features):
        if not isinstance(f, Features):
            raise TypeError(f"{name}: expected Features, got {type(f).__name__}")


def _shape(value, name: str) -> np.ndarray:
    shape = as_array(value, name)
    if shape.ndim != 1 or shape.size < 2 or np.any(shape[:2] < 1):
        raise ValueError(f"{name}: expected (H, W) with positive sizes, got {value!r}")
    return shape


def _inside(xy: np.ndarray, shape: np.ndarray) -> np.ndarray:
    """Points that fall on an image of ``shape`` (H, W)."""
    return (xy[:, 0] >= 0) & (xy[:, 0] <= shape[1] - 1) & (xy[:, 1] >= 0) & (xy[:, 1] <= shape[0] - 1)


def recall_precision(features_a: Features, features_b: Features, homography, image_shape_b,
                     thresholds=None, *, tolerance: float = 2.5, method: str = "kdtree") -> dict:
    """Recall and 1-precision of nearest-neighbour ratio matching for a range of thresholds.

    Parameters
    ----------
    features_a, features_b : Features
        Features of the reference image and of the transformed image.
    homography : array_like, shape (3, 3)
        Ground truth mapping pixels of image A to image B.
    image_shape_b : tuple (H, W)
        Shape of image B (an image's full ``shape`` will do: its first two entries are used);
        keypoints of A that map outside it have no possible correspondence.
    thresholds : array_like, optional
        Ratio thresholds; default ``numpy.linspace(0.15, 0.7, 12)`` (Lin et al. Sec. 2.iii).
    tolerance : float, default 2.5
        A pair corresponds when the warped keypoint of A is within this many pixels of B's.
    method : {"kdtree", "opencv"}
        Neighbour search (see :func:`robokit.vision.matching.two_nearest`).

    Returns
    -------
    dict
        ``thresholds``, ``recall``, ``one_minus_precision`` (arrays), ``n_correct``, ``n_false``
        (int arrays) and ``n_correspondences`` (int). With no correspondences, recall is 0; with no
        matches at a threshold, 1-precision is 0 (documented empty results, never NaN).

    Notes
    -----
    Mikolajczyk & Schmid 2005, Sec. 4.1, as used by Lin et al. Sec. 2.iii. The overlap-error
    criterion of the original is replaced by a position tolerance (simpler, and the same for
    both detectors).

    Examples
    --------
    Match PLOT features of an image against a copy turned by 10 degrees:

    >>> from robokit.vision import detect_plot_features, recall_precision, similarity_homography, warp_image
    >>> import cv2, numpy as np
    >>> noise = np.random.default_rng(1).uniform(0, 255, (160, 200))
    >>> image = cv2.GaussianBlur(noise, (0, 0), 2.0).astype(np.uint8)
    >>> H = similarity_homography(image.shape, angle=np.deg2rad(10))
    >>> turned = warp_image(image, H)
    >>> r = recall_precision(detect_plot_features(image), detect_plot_features(turned), H, turned.shape,
    ...                      thresholds=[0.65])
    >>> round(float(r["recall"][0]), 2), int(r["n_correct"][0]), int(r["n_false"][0])
    (0.72, 472, 0)
    """
    _require_features(features_a, features_b)
    h = _homography(homography)
    tol = as_positive(tolerance, "tolerance")
    ts = np.linspace(0.15, 0.7, 12) if thresholds is None else as_array(thresholds, "thresholds", ndim=1, min_size=1)
    shape = _shape(image_shape_b, "image_shape_b")
    nt = ts.size
    empty = {"thresholds": ts, "recall": np.zeros(nt), "one_minus_precision": np.zeros(nt),
             "n_correct": np.zeros(nt, int), "n_false": np.zeros(nt, int), "n_correspondences": 0}
    if len(features_a) == 0 or len(features_b) < 2:
        return empty
    warped = apply_homography(h, features_a.keypoints.xy)
    inside = _inside(warped, shape)
    near, _ = cKDTree(features_b.keypoints.xy).query(warped, k=1)
    n_corr = int(np.sum(inside & (near <= tol)))
    dist, index = two_nearest(features_a.descriptors, features_b.descriptors, method=method)
    r = distance_ratio(dist[:, 0], dist[:, 1])
    correct = np.linalg.norm(warped - features_b.keypoints.xy[index[:, 0]], axis=1) <= tol
    matched = (r[None, :] < ts[:, None]) & inside[None, :]
    n_correct = np.sum(matched & correct[None, :], axis=1)
    n_false = np.sum(matched & ~correct[None, :], axis=1)
    total = n_correct + n_false
    return {"thresholds": ts,
            "recall": n_correct / n_corr if n_corr else np.zeros(nt),
            "one_minus_precision": np.divide(n_false, total, out=np.zeros(nt), where=total > 0),
            "n_correct": n_correct, "n_false": n_false, "n_correspondences": n_corr}


def matching_score(features_a: Features, features_b: Features, homography, image_shape_a, image_shape_b, *,
                   ratio: float = 0.8, tolerance: float = 2.5, method: str = "kdtree") -> dict:
    """Matching score: correct ratio-test matches over the keypoints both images can share.

    Parameters
    ----------
    features_a, features_b : Features
        Features of the reference image A and of the transformed image B.
    homography : array_like, shape (3, 3)
        Ground truth mapping pixels of A to B.
    image_shape_a, image_shape_b : tuple (H, W)
        Shapes of A and B (an image's full ``shape`` will do).
    ratio : float, default 0.8
        Nearest-neighbour distance-ratio threshold (Lowe 2004, Sec. 7.1); in (0, 1].
    tolerance : float, default 2.5
        A match is correct when A's keypoint, mapped by the homography, lands within this many
        pixels of its partner in B.
    method : {"kdtree", "opencv"}
        Neighbour search (see :func:`robokit.vision.matching.two_nearest`).

    Returns
    -------
    dict
        ``score`` (float in [0, 1]), ``n_correct`` (B keypoints that are the correct partner of at
        least one of A's: each counts once, so repeated keypoints in A cannot inflate the score),
        ``n_matches`` (ratio-test matches of A's
        keypoints that map into B) and ``n_overlap`` (the smaller of A's keypoints that map into
        B and B's that map back into A). No overlap or fewer than two features in B gives score 0
        (documented empty result, never NaN).

    Raises
    ------
    TypeError, ValueError
        For features of the wrong type, a singular homography, bad shapes or a bad ``ratio``.

    Notes
    -----
    The matching score of Mikolajczyk et al. (2005, "A comparison of affine region
    detectors"), with a position tolerance instead of their region-overlap criterion (as in
    :func:`recall_precision`). It rates detector and descriptor together, so it is the number to
    compare PLOT with SIFT on under a known transformation.

    Examples
    --------
    >>> from robokit.vision import detect_sift_features, matching_score, similarity_homography, warp_image
    >>> import cv2, numpy as np
    >>> noise = np.random.default_rng(1).uniform(0, 255, (160, 200))
    >>> image = cv2.GaussianBlur(noise, (0, 0), 2.0).astype(np.uint8)
    >>> H = similarity_homography(image.shape, angle=np.deg2rad(10))
    >>> turned = warp_image(image, H)
    >>> m = matching_score(detect_sift_features(image), detect_sift_features(turned), H, image.shape, turned.shape)
    >>> bool(0.3 < m["score"] <= 1), m["n_correct"] <= m["n_matches"]
    (True, True)
    """
    _require_features(features_a, features_b)
    h = _homography(homography)
    shape_a, shape_b = _shape(image_shape_a, "image_shape_a"), _shape(image_shape_b, "image_shape_b")
    t = as_positive(ratio, "ratio")
    if t > 1:
        raise ValueError(f"ratio: expected a threshold in (0, 1], got {t}")
    tol = as_positive(tolerance, "tolerance")
    if len(features_a) == 0 or len(features_b) < 2:
        return {"score": 0.0, "n_correct": 0, "n_matches": 0, "n_overlap": 0}
    warped = apply_homography(h, features_a.keypoints.xy)
    inside_a = _inside(warped, shape_b)
    inside_b = _inside(apply_homography(np.linalg.inv(h), features_b.keypoints.xy), shape_a)
    overlap = int(min(inside_a.sum(), inside_b.sum()))
    dist, index = two_nearest(features_a.descriptors, features_b.descriptors, method=method)
    matched = inside_a & (distance_ratio(dist[:, 0], dist[:, 1]) < t)
    correct = matched & (np.linalg.norm(warped - features_b.keypoints.xy[index[:, 0]], axis=1) <= tol)
    n_correct = int(np.unique(index[correct, 0]).size)        # one-to-one: each B keypoint counts once
    return {"score": n_correct / overlap if overlap else 0.0, "n_correct": n_correct, "n_matches": int(matched.sum()),
            "n_overlap": overlap}
