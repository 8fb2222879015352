"""Lesson 03's checks on the rendered corridor as ORB sees it: repeatability against a real photograph, counts before the cap.

Ge et al. (2023) select keyframes by the ORB features of each image (Sec. 3.2): condition (1) compares
the image's feature count with ``F_min`` (Eq. (15)), condition (3) asks that 70-90 % of the last
keyframe's features still match. Both depend on how ORB behaves on the images, so two questions
about our renderer come before any conclusion about the paper's rule:

* :func:`motion_shares`: does ORB keep as many matches on our rendered views as on a real photograph
  when the image moves a little? Every image goes through the same small motions (:data:`MOTIONS`:
  sub-pixel and one-pixel shifts, zooms of 1-5 %, which is how the scene grows when a camera drives
  forward), and the share is :func:`robokit.vision.shared_fraction`, the measure of condition (3).
* :func:`feature_counts`: how many ORB features the views hold before ORB's cap of 500 keeps the
  strongest, and what Eq. (15) gives with those counts.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
.. [2] E. Rublee, V. Rabaud, K. Konolige and G. Bradski, "ORB: an efficient alternative to SIFT or
   SURF", Proc. IEEE Int. Conf. on Computer Vision (ICCV), 2564-2571, 2011.
"""
from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from robocourse.lessons.corridor_localization.experiment import CALIBRATION_STRETCH, N_FEATURES, corridor_camera
from robokit.sim import long_corridor
from robokit.validation import as_array, as_choice, as_finite_scalar, as_int, describe
from robokit.vision.features import as_gray_image
from robokit.vision import detect_orb_features, feature_threshold, shared_fraction, tracked_fraction

__all__ = ["MOTIONS", "move_image", "motion_shares", "feature_counts"]

#: Small image motions, name -> (shift right, shift down in pixels, zoom about the image centre).
MOTIONS = {"0.5 px, 0.3 px": (0.5, 0.3, 1.0), "1 px": (1.0, 0.0, 1.0), "zoom 1 %": (0.0, 0.0, 1.01),
           "zoom 2 %": (0.0, 0.0, 1.02), "zoom 5 %": (0.0, 0.0, 1.05)}

#: More ORB features than any 640 x 480 view holds: a cap that never binds.
NO_CAP = 1 << 20


def move_image(image, shift_x: float = 0.0, shift_y: float = 0.0, zoom: float = 1.0) -> np.ndarray:
    """The image zoomed about its centre and shifted (bilinear resampling, borders reflected), uint8 grey.

    Parameters
    ----------
    image : array_like, shape (H, W) or (H, W, 3|4)
        Any image :func:`robokit.vision.features.as_gray_image` accepts.
    shift_x, shift_y : float, default 0
        Pixels right and down, each within +-50.
    zoom : float, default 1
        Scale about the image centre, in [0.5, 2].

    Returns
    -------
    numpy.ndarray, uint8, shape (H, W)

    Raises
    ------
    ValueError, TypeError
        For a bad image or a motion outside the ranges above.

    Notes
    -----
    A camera driving forward by ``d`` sees a point at depth ``Z`` grow by ``Z / (Z - d)`` about the
    focus of expansion: 7.3 cm (11 frames of the calibration video) is a zoom of about 8 % for a wall
    1 m ahead and 0.7 % for one 10 m ahead. Ge et al. (2023), Sec. 3.2, condition (3).

    Examples
    --------
    >>> img = np.zeros((5, 5), np.uint8); img[2, 2] = 200
    >>> move_image(img, 1.0)[2].tolist()
    [0, 0, 0, 200, 0]
    """
    grey = _grey(image, "image")
    return _moved(grey, *_motion(shift_x, shift_y, zoom))


def _motion(shift_x: Any, shift_y: Any, zoom: Any, where: str = "") -> tuple[float, float, float]:
    """The checked motion; an error names the argument, after ``where`` (e.g. ``"motions['a']: "``)."""
    shift_x, shift_y, zoom = (as_finite_scalar(v, f"{where}{n}") for v, n in ((shift_x, "shift_x"),
                                                                             (shift_y, "shift_y"), (zoom, "zoom")))
    for name, shift in (("shift_x", shift_x), ("shift_y", shift_y)):
        if abs(shift) > 50:
            raise ValueError(f"{where}{name}: expected a shift within +-50 pixels, got {shift}")
    if not 0.5 <= zoom <= 2.0:
        raise ValueError(f"{where}zoom: expected a scale in [0.5, 2], got {zoom}")
    return shift_x, shift_y, zoom


def _grey(image, name: str) -> np.ndarray:
    return np.clip(np.rint(as_gray_image(image, name) * 255.0), 0, 255).astype(np.uint8)


def _moved(grey: np.ndarray, shift_x: float, shift_y: float, zoom: float) -> np.ndarray:
    h, w = grey.shape
    M = cv2.getRotationMatrix2D(((w - 1) / 2.0, (h - 1) / 2.0), 0.0, zoom)
    M[:, 2] += (shift_x, shift_y)
    return cv2.warpAffine(grey, M, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


def motion_shares(images: dict, motions: dict | None = None, *, n_features: int = N_FEATURES,
                  matching: str = "mutual") -> dict:
    """Share of each image's ORB features still matched after each small motion (condition (3)'s measure).

    Parameters
    ----------
    images : dict of str -> array_like
        Named images (grey or RGB), at least one.
    motions : dict of str -> (float, float, float), optional
        Named ``(shift_x, shift_y, zoom)`` (:func:`move_image`); default :data:`MOTIONS`.
    n_features : int, default 500
        ORB's cap (the lesson's).
    matching : {"mutual", "tracked"}, default "mutual"
        The share's reading: :func:`robokit.vision.shared_fraction` (mutual nearest neighbours within
        50 bits) or :func:`robokit.vision.tracked_fraction` (ORB-SLAM-style search windows).

    Returns
    -------
    dict of str -> dict of str -> float
        ``shares[image][motion]``: the moved image's ORB features against the image's own, over the
        original's feature count, in [0, 1].

    Raises
    ------
    ValueError, TypeError
        For an empty or non-dict ``images`` or ``motions``, keys that are equal as text, bad images
        (or an image without ORB features, whose share would read as every match lost) or motions.

    Notes
    -----
    Ge et al. (2023), Sec. 3.2, condition (3); ORB: Rublee et al. (2011).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> img = cv2.GaussianBlur((rng.random((240, 320)) * 255).astype(np.uint8), (5, 5), 1.5)
    >>> shares = motion_shares({"noise": img}, {"none": (0.0, 0.0, 1.0)})
    >>> shares["noise"]["none"]
    1.0
    """
    motions = MOTIONS if motions is None else motions
    for name, value in (("images", images), ("motions", motions)):
        if not isinstance(value, dict) or not value:
            raise TypeError(f"{name}: expected a non-empty dict, got {describe(value)}")
        if len({str(k) for k in value}) < len(value):
            raise ValueError(f"{name}: expected keys that differ as text, got {list(value)}")
    moves = {str(k): _motion(*as_array(v, f"motions[{k!r}]", shape=(3,)), where=f"motions[{k!r}]: ")
             for k, v in motions.items()}
    n_features = as_int(n_features, "n_features", minimum=1, maximum=NO_CAP)
    matching = as_choice(matching, "matching", ("mutual", "tracked"))
    out = {}
    for name, image in images.items():
        grey = _grey(image, f"images[{name!r}]")
        own = detect_orb_features(grey, n_features)
        if len(own) == 0:
            raise ValueError(f"images[{name!r}]: expected an image in which ORB finds features, got one with none")
        moved = {k: detect_orb_features(_moved(grey, *m), n_features) for k, m in moves.items()}
        out[str(name)] = {k: (tracked_fraction(f, own) if matching == "tracked"
                              else shared_fraction(f.descriptors, own.descriptors)) for k, f in moved.items()}
    return out


def feature_counts(spacing: float = 1.0, *, section=CALIBRATION_STRETCH) -> dict:
    """ORB features of the corridor's middle-line views before and after the cap, and Eq. (15) on a section.

    Parameters
    ----------
    spacing : float, default 1
        Metres between views along the middle line, facing +x, from 0.5 m to 0.5 m before the end
        wall, in [0.1, 5].
    section : (float, float), default :data:`.experiment.CALIBRATION_STRETCH`
        The calibration video's stretch (:func:`.experiment.calibration_run`'s default), at least
        two views long.

    Returns
    -------
    dict
        ``x`` (n,) the views' positions, ``uncapped`` and ``capped`` (n,) int the ORB feature counts
        with no cap and with the lesson's 500, ``f_min`` Eq. (15) over the uncapped counts of the
        views inside ``section``, ``section``.

    Raises
    ------
    ValueError, TypeError
        For a spacing or section out of range.

    Notes
    -----
    Ge et al. (2023), Sec. 3.2, condition (1) and Eq. (15): ``F_min = max(0.5 mean, I_min)`` over a
    calibration video; here over views ``spacing`` apart in the same stretch.

    Examples
    --------
    >>> counts = feature_counts(5.0)
    >>> counts["x"].tolist(), bool((counts["capped"] <= 500).all())
    ([0.5, 5.5, 10.5, 15.5, 20.5, 25.5, 30.5, 35.5], True)
    """
    spacing = as_finite_scalar(spacing, "spacing")
    if not 0.1 <= spacing <= 5.0:
        raise ValueError(f"spacing: expected 0.1 to 5 m between views, got {spacing}")
    world, camera = long_corridor(), corridor_camera()
    x = np.arange(0.5, world.info["length"] - 0.5 + 1e-9, spacing)
    lo, hi = as_array(section, "section", shape=(2,))
    inside = (x >= lo) & (x <= hi)
    if inside.sum() < 2:
        raise ValueError(f"section: expected a stretch of the corridor holding at least two views "
                         f"{spacing} m apart, got {[float(lo), float(hi)]}")
    uncapped, capped = [], []
    for xk in x:
        grey = _grey(camera.observe(world, [xk, 0.0, 0.0], rng=0).image, "image")
        uncapped.append(len(detect_orb_features(grey, NO_CAP)))
        capped.append(len(detect_orb_features(grey, N_FEATURES)))
    uncapped = np.array(uncapped, int)
    return {"x": x, "uncapped": uncapped, "capped": np.array(capped, int),
            "f_min": feature_threshold(uncapped[inside]), "section": (float(lo), float(hi))}
