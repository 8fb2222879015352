"""SIFT on omnidirectional images: keypoints in the mirror's annulus, oriented about its centre.

Lesson 02's paper (Sec. "Local image features") extracts SIFT features from the omni images with
a "modified" SIFT: the omni camera "make[s] a motion constraint for rotational invariance" and
allows "eliminating of the rotational normalization and rotational part of the descriptor". Our
reading: a robot on a floor turns only about the vertical axis, which rotates the omni image
about its centre; giving every keypoint the polar angle of its position about that centre
(``orientation="radial"``, the local "up" of an unwrapped panorama) makes descriptors invariant
to that rotation without estimating a gradient orientation per keypoint (Lowe 2004, Sec. 5).
``"gradient"`` is plain SIFT (the reference); ``"upright"`` fixes every angle to 0, right only
when the robot never turns.

What we measured on rendered ``office_floor()`` views (tests/test_vision_omni_features.py,
benchmarks/bench_omni_features.py; Lowe's ratio 0.8, 3 px ground-truth tolerance): under a pure
turn, radial and gradient SIFT match alike (94 % of the ratio-test matches correct) and upright
SIFT finds no correct match; when the robot also moves 0.1-0.5 m (20 random pairs), gradient SIFT
keeps a few more matches and a slightly higher accurate rate (0.889 pooled, worst pair 0.821)
than radial SIFT (0.873, worst 0.750, in the corridor): a floor or ceiling patch turns relative
to the radial direction as its bearing changes, which the gradient orientation follows and the
radial one does not. Radial SIFT also costs a second pass over the pyramid (OpenCV detects, then
describes at the given angles): about 1.3 x plain SIFT's time.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011, Sec. "Local image features".
.. [2] D. G. Lowe, "Distinctive image features from scale-invariant keypoints", International Journal
   of Computer Vision 60(2), 91-110, 2004.
"""
from __future__ import annotations

import numpy as np

from ..validation import as_array, as_points, as_choice
from .descriptors import detect_sift_features
from .features import Features, as_gray_image

__all__ = ["ImageSizeError", "ORIENTATIONS", "annulus_mask", "radial_orientation", "omni_sift"]

#: Keypoint orientations :func:`omni_sift` offers.
ORIENTATIONS = ("radial", "gradient", "upright")


class ImageSizeError(ValueError):
    """An image too small for the omni annulus it should hold (e.g. a query of another camera)."""


def _annulus(centre, radii) -> tuple[np.ndarray, float, float]:
    c = as_array(centre, "centre", shape=(2,))
    r_in, r_out = as_array(radii, "radii", shape=(2,))
    if not 0 <= r_in < r_out:
        raise ValueError(f"radii: expected 0 <= r_in < r_out, got ({r_in}, {r_out})")
    return c, float(r_in), float(r_out)


def _require_holds(shape: tuple[int, int], c: np.ndarray, r_out: float, name: str) -> None:
    h, w = shape
    # one pixel of slack: the default camera's rim touches the image's top and bottom rows
    if c[0] - r_out < -1 or c[0] + r_out > w or c[1] - r_out < -1 or c[1] + r_out > h:
        raise ImageSizeError(
            f"{name}: expected an image that holds the annulus of centre ({c[0]:g}, {c[1]:g}) and radii (outer "
            f"{r_out:g}): at least {np.ceil(c[0] + r_out):.6g} x {np.ceil(c[1] + r_out):.6g} pixels (width x height), got shape {shape}")


def annulus_mask(shape, centre, radii) -> np.ndarray:
    """Pixels of an omni image between the inner and the outer radius of the mirror's annulus.

    Parameters
    ----------
    shape : (int, int)
        Image ``(height, width)``.
    centre : array_like, shape (2,)
        Image centre ``(x, y) = (col, row)`` in pixels (``OmniCamera().cx, .cy``).
    radii : array_like, shape (2,)
        ``(r_in, r_out)`` in pixels, ``0 <= r_in < r_out`` (``OmniCamera().radii``).

    Returns
    -------
    numpy.ndarray of bool, shape (height, width)
        True where ``r_in <= |(x, y) - centre| <= r_out``.

    Raises
    ------
    TypeError, ValueError
        For a malformed shape, centre or radii; :class:`ImageSizeError` if the annulus does not
        fit in ``shape``.

    Notes
    -----
    The imaged band of elevations of a catadioptric camera (Sec. "Implementation for
    omnidirectional vision", unnumbered): the robot hides the centre, the mirror's rim bounds
    the outside.

    Examples
    --------
    >>> annulus_mask((5, 5), (2, 2), (1, 2)).astype(int)
    array([[0, 0, 1, 0, 0],
           [0, 1, 1, 1, 0],
           [1, 1, 0, 1, 1],
           [0, 1, 1, 1, 0],
           [0, 0, 1, 0, 0]])
    """
    hw = as_array(shape, "shape", shape=(2,), dtype=int)
    if hw.min() < 1 or hw.max() > 1 << 15:
        raise ValueError(f"shape: expected (height, width) between 1 and 32768, got {tuple(hw)}")
    c, r_in, r_out = _annulus(centre, radii)
    _require_holds((int(hw[0]), int(hw[1])), c, r_out, "shape")
    y, x = np.ogrid[:hw[0], :hw[1]]
    r2 = (x - c[0]) ** 2 + (y - c[1]) ** 2
    return (r2 >= r_in ** 2) & (r2 <= r_out ** 2)


def radial_orientation(xy, centre) -> np.ndarray:
    """Polar angle of image points about the omni image's centre, as keypoint orientations.

    Parameters
    ----------
    xy : array_like, shape (N, 2)
        Pixel positions ``(col, row)``.
    centre : array_like, shape (2,)

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``atan2(y - cy, x - cx)`` in ``[0, 2 pi)`` (image axes, y down: the convention of
        :class:`robokit.vision.Keypoints`); 0 at the centre itself.

    Raises
    ------
    TypeError, ValueError
        For malformed points or centre.

    Notes
    -----
    Our reading of the paper's "eliminating of the rotational normalization" (Sec. "Local image
    features"): a turn of the robot rotates every point and every patch of the omni image by the
    same angle about the centre, so this angle turns with the patch.

    Examples
    --------
    >>> np.rad2deg(radial_orientation([[3, 1], [1, 3], [-1, 1]], (1, 1))).tolist()
    [0.0, 90.0, 180.0]
    """
    p = as_points(xy, "xy", 2)
    c = as_array(centre, "centre", shape=(2,))
    return np.mod(np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0]), 2 * np.pi)


def omni_sift(image, centre, radii, *, orientation: str = "radial", n_features: int = 0, mask=None) -> Features:
    """OpenCV SIFT on an omni image: keypoints in the annulus, orientation radial, gradient or upright.

    Parameters
    ----------
    image : array_like, shape (H, W), (H, W, 3) or (H, W, 4)
        The omni image (colour is converted to grey).
    centre : array_like, shape (2,)
        Image centre ``(cx, cy)`` in pixels.
    radii : array_like, shape (2,)
        ``(r_in, r_out)``: only keypoints whose centre lies in this annulus are kept.
    orientation : {"radial", "gradient", "upright"}, default "radial"
        Keypoint angle: the polar angle about ``centre`` (:func:`radial_orientation`), SIFT's
        dominant gradient orientation (plain SIFT), or 0.
    n_features : int, default 0
        Keep the best ``n_features`` in the annulus (0 keeps all), as OpenCV's ``nfeatures``.
    mask : array_like of bool, shape (H, W), optional
        Further pixels to leave out (False), e.g. a robot part in view.

    Returns
    -------
    Features
        128-element unit descriptors; empty for an image without texture in the annulus.

    Raises
    ------
    ImageSizeError
        If the image cannot hold the annulus (a query image of another size than the map's).
    TypeError, ValueError
        For a malformed image, centre, radii, mask or an unknown orientation.

    Notes
    -----
    Sec. "Local image features" (the modified SIFT; our reading is in the module docstring),
    with OpenCV's SIFT (Lowe 2004) through :func:`robokit.vision.detect_sift_features`.

    Examples
    --------
    A textured disc and the same disc turned by 40 degrees about its centre: with radial
    orientations every match lands where the turn moved its keypoint.

    >>> import cv2, numpy as np
    >>> from robokit.vision import DescriptorIndex
    >>> noise = np.random.default_rng(2).uniform(0, 255, (241, 241)).astype(np.float32)
    >>> disc = cv2.GaussianBlur(noise, (0, 0), 2.0).astype(np.uint8)
    >>> turn = cv2.getRotationMatrix2D((120, 120), 40, 1.0)
    >>> a = omni_sift(disc, (120, 120), (20, 100))
    >>> b = omni_sift(cv2.warpAffine(disc, turn, (241, 241)), (120, 120), (20, 100))
    >>> m = DescriptorIndex(a.descriptors).match(b.descriptors)
    >>> moved = a.keypoints.xy[m.train] @ turn[:, :2].T + turn[:, 2]
    >>> len(m) > 40, bool(np.all(np.hypot(*(moved - b.keypoints.xy[m.query]).T) < 2))
    (True, True)
    """
    orientation = as_choice(orientation, "orientation", ORIENTATIONS)
    img = as_gray_image(image)
    c, r_in, r_out = _annulus(centre, radii)
    _require_holds(img.shape, c, r_out, "image")
    where = annulus_mask(img.shape, c, (r_in, r_out))
    if mask is not None:
        where &= as_array(mask, "mask", shape=img.shape, dtype=bool)
    given = {"radial": lambda xy: radial_orientation(xy, c), "upright": lambda xy: np.zeros(len(xy)),
             "gradient": None}[orientation]
    f = detect_sift_features(img, n_features=n_features, mask=where, orientation=given)
    r = np.hypot(*(f.keypoints.xy - c).T) if len(f) else np.zeros(0)
    return f.subset((r >= r_in) & (r <= r_out))            # refinement may move a keypoint off the mask
