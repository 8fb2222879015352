"""ORB features (oriented FAST keypoints, rotated BRIEF descriptors) through OpenCV.

Ge et al. (2023), Sec. 3.2, select keyframes and build their bag of words (Sec. 3.3) on ORB
features (Rublee et al. 2011): FAST corners on an image pyramid, each oriented by the intensity
centroid of its patch (the moments of Eq. (10), the centroid of Eq. (11), the angle of Eq. (12)),
and described by 256 binary intensity tests (Eq. (13)) packed into a number (Eq. (14)): 32 bytes
compared by Hamming distance (:mod:`.hamming`). OpenCV's ``cv2.ORB_create`` computes all of it.

References
----------
.. [1] E. Rublee, V. Rabaud, K. Konolige and G. Bradski, "ORB: an efficient alternative to SIFT or
   SURF", Proc. IEEE Int. Conf. on Computer Vision (ICCV), 2564-2571, 2011.
.. [2] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang (Ge et al.), "Visual-feature-assisted
   mobile robot localization in a long corridor environment", Frontiers of Information Technology
   & Electronic Engineering 24(6), 2023, doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import cv2
import numpy as np

from ..validation import as_array, as_finite_scalar, as_int
from .features import Features, Keypoints, as_gray_image
from .hamming import ORB_BYTES

__all__ = ["ORB_FEATURES", "ORB_SCALE_FACTOR", "detect_orb_features"]

#: OpenCV's default number of ORB features.
ORB_FEATURES = 500
#: OpenCV's default step between ORB's pyramid levels (a keypoint's scale is this to the power of its level).
ORB_SCALE_FACTOR = 1.2


def detect_orb_features(image, n_features: int = ORB_FEATURES, *, scale_factor: float = ORB_SCALE_FACTOR, n_levels: int = 8,
                        fast_threshold: int = 20, mask=None) -> Features:
    """Detect ORB keypoints and compute their binary descriptors (OpenCV ``cv2.ORB_create``).

    Parameters
    ----------
    image : array_like, shape (H, W) or (H, W, 3|4)
        Grey or RGB(A) image, uint8 (or any :func:`.features.as_gray_image` accepts; floats are
        taken in [0, 1] and quantised to 8 bits, as OpenCV's ORB needs).
    n_features : int, default 500
        Most features kept (by FAST/Harris response), >= 1.
    scale_factor : float, default 1.2
        Pyramid decimation ratio, in (1, 2].
    n_levels : int, default 8
        Pyramid levels, in [1, 32].
    fast_threshold : int, default 20
        FAST intensity threshold (grey levels), in [1, 255].
    mask : array_like of bool, shape (H, W), optional
        Detect only where true.

    Returns
    -------
    Features
        Keypoints (``xy`` in pixels; ``scale`` = ``scale_factor ** octave``, the pyramid level's
        size in pixels of the full image; ``orientation`` = Eq. (12)'s angle in radians, image
        axes; ``response`` = the Harris score) and ``descriptors`` of shape (N, 32), uint8. An
        image without keypoints (a blank wall) gives ``N = 0`` with the same shapes and dtypes.

    Raises
    ------
    TypeError, ValueError
        For images :func:`.features.as_gray_image` refuses, parameters out of range or a mask of
        another shape.

    Notes
    -----
    Ge et al. (2023), Sec. 3.2, Eqs. (10)-(14) (oFAST orientation by the intensity centroid, the
    rBRIEF binary tests); Rublee et al. (2011).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> image = (rng.random((120, 160)) > 0.5).astype(np.uint8) * 255
    >>> f = detect_orb_features(image, 100)
    >>> 0 < len(f) <= 100, f.descriptors.shape[1], f.descriptors.dtype.name
    (True, 32, 'uint8')
    >>> blank = detect_orb_features(np.zeros((120, 160), np.uint8))
    >>> len(blank), blank.descriptors.shape, blank.keypoints.xy.shape
    (0, (0, 32), (0, 2))
    """
    n_features = as_int(n_features, "n_features", minimum=1, maximum=1 << 20)
    scale_factor = as_finite_scalar(scale_factor, "scale_factor")
    if not 1.0 < scale_factor <= 2.0:
        raise ValueError(f"scale_factor: expected a value in (1, 2], got {scale_factor}")
    n_levels = as_int(n_levels, "n_levels", minimum=1, maximum=32)
    fast_threshold = as_int(fast_threshold, "fast_threshold", minimum=1, maximum=255)
    raw = np.asarray(image) if isinstance(image, np.ndarray) else None
    if raw is not None and raw.dtype == np.uint8 and raw.ndim == 2 and min(raw.shape) >= 3:
        grey = np.ascontiguousarray(raw)           # no round trip through floats for 8-bit grey input
    else:
        grey = np.clip(np.rint(as_gray_image(image) * 255.0), 0, 255).astype(np.uint8)
    cv_mask = None
    if mask is not None:
        m = as_array(mask, "mask", dtype=bool)
        if m.shape != grey.shape:
            raise ValueError(f"mask: expected shape {grey.shape} like the image, got {m.shape}")
        cv_mask = m.astype(np.uint8) * 255
    orb = cv2.ORB_create(nfeatures=n_features, scaleFactor=scale_factor, nlevels=n_levels,
                         fastThreshold=fast_threshold)
    kps, desc = orb.detectAndCompute(grey, cv_mask)
    if desc is None or len(kps) == 0:
        return Features(Keypoints.empty(), np.zeros((0, ORB_BYTES), np.uint8))
    xy = np.array([k.pt for k in kps], float)
    octave = np.array([k.octave & 0xFF for k in kps], float)   # OpenCV packs the layer in the low byte
    keypoints = Keypoints(xy, scale_factor ** octave, np.array([k.response for k in kps], float),
                          np.deg2rad(np.array([k.angle for k in kps], float)) % (2 * np.pi))  # Eq. (12)
    return Features(keypoints, np.ascontiguousarray(desc, np.uint8))
