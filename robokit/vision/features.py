"""Containers shared by every detector and descriptor: grey images, keypoints, features.

Image convention: ``image[row, col]``; keypoint positions are ``(x, y) = (col, row)`` in pixels,
orientations are ``atan2(dy, dx)`` in image axes (x right, y down), in ``[0, 2 pi)``, and the scale
of a keypoint is the standard deviation (pixels) of the Gaussian it was found at. PLOT (Lin et al.)
and OpenCV's SIFT (Lowe 2004; Se, Lowe & Little 2002) both produce :class:`Features`, so every
pipeline accepts either.

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [2] D. G. Lowe, "Distinctive image features from scale-invariant keypoints", International Journal
   of Computer Vision 60(2), 91-110, 2004.
.. [3] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..validation import as_array, describe

__all__ = ["as_gray_image", "Keypoints", "Features"]


def _pixel_scale(raw: np.ndarray, name: str) -> float:
    """What the image's values are divided by to lie in [0, 1]: 255 for 8-bit data (``uint8``, or
    any other integer type holding 0..255, as ``img.astype(int)`` makes), 65535 for ``uint16``, 1
    for floats in [0, 1]. Values that fit no such reading are refused (they would give a blank or
    saturated image, and no features, without a word)."""
    if raw.dtype == np.uint16:
        return 65535.0
    finite = raw[np.isfinite(raw)] if raw.dtype.kind == "f" else raw
    low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 0.0)
    if raw.dtype.kind in "iu":
        if raw.dtype != np.uint8 and (low < 0 or high > 255):
            raise ValueError(f"{name}: expected 8-bit pixel values 0..255 in a {raw.dtype} image (or uint8/uint16), "
                             f"got values from {low:g} to {high:g}")
        return 255.0
    if low < -0.5 or high > 1.5:         # noise may stray a little outside [0, 1]; 0..255 floats do not fit
        raise ValueError(f"{name}: expected float pixel values in [0, 1], got values from {low:g} to {high:g} "
                         "(divide an 8-bit image by 255, or pass it as uint8)")
    return 1.0


def as_gray_image(image, name: str = "image") -> np.ndarray:
    """Return ``image`` as a float32 grey image with values in [0, 1] (for integer input).

    Parameters
    ----------
    image : array_like, shape (H, W) or (H, W, 3|4)
        Grey or RGB(A) image (the alpha channel is ignored). ``uint16`` images are divided by
        65535 and every other integer image by 255 (its values must be 0..255: 8-bit data, as
        ``img.astype(int)`` makes); float images are kept as they are, in [0, 1] (values beyond
        [-0.5, 1.5], as a 0..255 float image has, are refused). Boolean and
        complex images are refused: convert a mask on purpose (``mask.astype(np.uint8) * 255``).
    name : str
        Argument name for error messages.

    Returns
    -------
    numpy.ndarray, shape (H, W), float32

    Raises
    ------
    TypeError
        If the input is not an array of real numbers (strings, booleans, complex, ragged lists).
    ValueError
        If it is empty, smaller than 3 x 3, has the wrong number of dimensions or channels, holds
        NaN/infinity, or holds values outside what its dtype reads as (above).

    Notes
    -----
    Course convention (DESIGN.md "Errors"); the luminance weights are ITU-R BT.601, as in OpenCV.
    """
    raw = as_array(image, name, dtype=None, finite=False)
    if raw.size == 0:
        raise ValueError(f"{name}: expected a non-empty image, got shape {raw.shape}")
    scale = _pixel_scale(raw, name)
    if raw.ndim == 3 and raw.shape[2] in (3, 4):
        rgb = raw[..., :3].astype(np.float32) / np.float32(scale)
        gray = rgb @ np.array([0.299, 0.587, 0.114], dtype=np.float32)
    elif raw.ndim == 2:
        gray = raw.astype(np.float32) / np.float32(scale)
    else:
        raise ValueError(f"{name}: expected shape (H, W), (H, W, 3) or (H, W, 4), got shape {raw.shape}")
    if min(gray.shape) < 3:
        raise ValueError(f"{name}: expected an image of at least 3 x 3 pixels, got shape {gray.shape}")
    if not np.all(np.isfinite(gray)):
        raise ValueError(f"{name}: expected finite pixel values, got NaN or infinity")
    return np.ascontiguousarray(gray)


@dataclass(frozen=True)
class Keypoints:
    """Image keypoints (Lin et al. Sec. 2.i: position, scale, response; Sec. 2.ii: orientation).

    Attributes
    ----------
    xy : numpy.ndarray, shape (N, 2)
        Sub-pixel positions ``(col, row)`` in pixels.
    scale : numpy.ndarray, shape (N,)
        Gaussian scale sigma in pixels.
    response : numpy.ndarray, shape (N,)
        Detector strength (PLOT: junction strength lambda_2; SIFT: the absolute difference-of-Gaussians response).
    orientation : numpy.ndarray, shape (N,)
        Dominant gradient orientation in radians, ``[0, 2 pi)``; zeros before assignment.
    """

    xy: np.ndarray
    scale: np.ndarray
    response: np.ndarray
    orientation: np.ndarray

    def __post_init__(self):
        xy = as_array(self.xy, "xy")
        xy = as_array(xy.reshape(0, 2) if xy.size == 0 else xy, "xy", shape=(None, 2))
        n = xy.shape[0]
        object.__setattr__(self, "xy", xy)
        for field in ("scale", "response", "orientation"):
            arr = as_array(getattr(self, field), field, shape=(n,)) if n else np.zeros(0)
            object.__setattr__(self, field, arr)
        if n and np.any(self.scale <= 0):
            raise ValueError("scale: expected positive keypoint scales, got a value <= 0")

    def __len__(self) -> int:
        return self.xy.shape[0]

    @classmethod
    def empty(cls) -> "Keypoints":
        """Return zero keypoints (the documented result for a textureless image)."""
        return cls(np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros(0))

    def subset(self, index) -> "Keypoints":
        """Return the keypoints selected by a boolean mask or an index array."""
        return Keypoints(self.xy[index], self.scale[index], self.response[index], self.orientation[index])


@dataclass(frozen=True)
class Features:
    """Keypoints with one descriptor row each (what every matcher in ``robokit.vision`` consumes).

    Attributes
    ----------
    keypoints : Keypoints
    descriptors : numpy.ndarray, shape (N, D), float32 or uint8
        D = 128 for the SIFT-style descriptor, 16 for Se et al.'s reduced vector (Sec. 4). Binary
        descriptors (ORB's 256 bits packed in D = 32 bytes, :mod:`.orb`) stay uint8: their
        distance is the Hamming distance (:mod:`.hamming`), and a float copy would hide that.
    """

    keypoints: Keypoints
    descriptors: np.ndarray

    def __post_init__(self):
        if not isinstance(self.keypoints, Keypoints):
            raise TypeError(f"keypoints: expected Keypoints, got {describe(self.keypoints)}")
        d = np.asarray(self.descriptors)
        d = d if d.dtype == np.uint8 else d.astype(np.float32)   # binary descriptors stay bytes
        if d.ndim != 2 or d.shape[0] != len(self.keypoints):
            raise ValueError(f"descriptors: expected shape ({len(self.keypoints)}, D), got shape {d.shape}")
        object.__setattr__(self, "descriptors", d)

    def __len__(self) -> int:
        return len(self.keypoints)

    def subset(self, index) -> "Features":
        """Return the features selected by a boolean mask or an index array."""
        return Features(self.keypoints.subset(index), self.descriptors[index])
