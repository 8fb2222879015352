"""What a topological map keeps of an omnidirectional image, and the relative pose of two of them.

An :class:`OmniView` is the paper's two levels of description of one image (Sec.
"Implementation for omnidirectional vision"): the global feature, a hue histogram compared by
Eq. (5), and the local features, SIFT keypoints with descriptors, plus each keypoint's bearing (its
unit viewing ray, :meth:`robokit.sim.OmniCamera.rays`). :func:`relative_pose` turns the matched
features of two views into the pose of one robot in the other's frame:

* epipolar geometry on the bearings (:func:`robokit.vision.spherical.ransac_essential`): the
  rotation and the direction of travel, and the paper's check that a recognition is not ambiguous
  (Sec. "Hierarchical localization": "epipolar geometry constraints ... are employed to verify
  the result");
* the floor: the camera looks down from a known height, so a matched feature well below the
  horizon lifts to a metric floor point in each robot's frame
  (:func:`robokit.vision.spherical.floor_points`); with the heading from the essential matrix
  each floor match proposes a translation, and the proposals that agree along the epipolar
  direction of travel give ``[dx, dy]`` in metres. Features on a wall's foot or a table's side
  lift to wrong points and are outliers. Without an essential matrix a free planar RANSAC
  (:func:`robokit.vision.ransac.ransac_se2`) is tried, and the pose is not ``verified``.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] R. Hartley and A. Zisserman, *Multiple View Geometry in Computer Vision*, 2nd ed., Cambridge
   University Press, 2004 (Sec. 9.6).
.. [3] M. A. Fischler and R. C. Bolles, "Random sample consensus: a paradigm for model fitting with
   applications to image analysis and automated cartography", Communications of the ACM 24(6),
   381-395, 1981.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..sim.omni import OmniCamera, as_omni_camera
from ..validation import as_array, as_rng, as_int, as_mapping, as_positive, as_text, describe
from ..vision.colour import hue_histogram
from ..vision.features import Features, Keypoints
from ..vision.matching import Matches
from ..vision.omni_features import ImageSizeError, omni_sift
from ..vision.ransac import ransac_se2
from ..vision.spherical import decompose_essential, floor_points, ransac_essential

__all__ = ["HISTOGRAM_STEP", "OmniView", "omni_view", "as_omni_image", "RelativePose", "relative_pose"]


def as_omni_image(image: Any, camera: OmniCamera, name: str = "image") -> np.ndarray:
    """Validate an RGB image of ``camera``'s size (uint8, or float in [0, 1]).

    Raises
    ------
    ImageSizeError
        For an image whose shape is not ``(camera.height, camera.width, 3)``
        (:class:`robokit.vision.omni_features.ImageSizeError`, a ``ValueError``).
    TypeError, ValueError
        For a camera that is not an :class:`~robokit.sim.OmniCamera`, or an image that is not
        numbers or holds NaN/inf.

    Notes
    -----
    Validation only (DESIGN.md, "Errors"); the paper's camera gives 640 x 480 colour images (Sec.
    "Implementation for omnidirectional vision").

    Examples
    --------
    >>> cam = OmniCamera(width=64, height=48)
    >>> as_omni_image(np.zeros((48, 64, 3), np.uint8), cam).shape
    (48, 64, 3)
    """
    name = as_text(name, "name", empty=False)
    as_omni_camera(camera)
    img = as_array(image, name, dtype=None)
    want = (camera.height, camera.width, 3)
    if img.shape != want:
        raise ImageSizeError(f"{name}: expected an RGB image of the camera's size {want}, got shape {img.shape}")
    return img


@dataclass(frozen=True)
class OmniView:
    """The map's description of one omnidirectional image.

    Attributes
    ----------
    histogram : numpy.ndarray, shape (B,)
        Hue histogram (sums to 1, or all zeros for an image without colour).
    features : robokit.vision.Features
        Omni SIFT keypoints (pixels) and descriptors.
    bearings : numpy.ndarray, shape (N, 3)
        Unit viewing ray of each keypoint in the camera frame.
    """

    histogram: np.ndarray
    features: Features
    bearings: np.ndarray

    def __len__(self) -> int:
        return len(self.features)


#: The hue histogram is taken over every second pixel in each direction: a quarter of the pixels,
#: four times faster, and within 0.002 (Eq. (5)) of the full histogram on office_floor() views,
#: where neighbouring key images differ by 0.02 and more.
HISTOGRAM_STEP = 2


def omni_view(image: Any, camera: OmniCamera, *, bins: int = 32, n_features: int = 500,
              features: bool = True, times: dict | None = None, histogram: Any = None) -> OmniView:
    """Describe an omni image by its hue histogram and its SIFT features with their bearings.

    Parameters
    ----------
    image : array_like, shape (camera.height, camera.width, 3)
        RGB image.
    camera : OmniCamera
        The camera that took it (its centre and annulus radii bound the features; its lifting
        gives the bearings).
    bins : int, default 32
        Hue histogram bins.
    n_features : int, default 500
        Most SIFT features kept (the strongest; 0 keeps all).
    features : bool, default True
        ``False`` skips SIFT (the view then has no features): the coarse stage needs none.
    times : dict, optional
        Receives the seconds spent on ``"histogram"`` and ``"sift"``.
    histogram : array_like, shape (bins,), optional
        This image's hue histogram, already computed (e.g. by an earlier ``features=False`` view of
        it): it is used as given instead of being computed again.

    Returns
    -------
    OmniView

    Raises
    ------
    ImageSizeError
        For an image of another size than the camera's.

    Notes
    -----
    Sec. "Global image features" (HSI hue histogram, Eq. (4), over every
    :data:`HISTOGRAM_STEP`-th pixel) and Sec. "Local image features" (SIFT without the
    rotational normalisation, which an omni camera makes unnecessary:
    :func:`robokit.vision.omni_sift` with radial orientations).

    Examples
    --------
    >>> cam = OmniCamera(width=160, height=120)
    >>> rng = np.random.default_rng(0)
    >>> view = omni_view(rng.integers(0, 255, (120, 160, 3), dtype=np.uint8), cam, n_features=50)
    >>> view.histogram.shape, len(view) == len(view.bearings), round(float(view.histogram.sum()), 6)
    ((32,), True, 1.0)
    """
    img = as_omni_image(image, camera)
    n_features = as_int(n_features, "n_features", minimum=0)
    bins = as_int(bins, "bins", minimum=1)
    times = as_mapping(times, "times")
    t0 = time.perf_counter()
    if histogram is None:
        histogram = hue_histogram(img[::HISTOGRAM_STEP, ::HISTOGRAM_STEP], bins)
    else:
        histogram = as_array(histogram, "histogram", shape=(bins,))
        if np.any(histogram < 0):
            raise ValueError(f"histogram: expected non-negative bin values, got {histogram.min()}")
    t1 = time.perf_counter()
    if features:
        found = omni_sift(img, (camera.cx, camera.cy), camera.radii, orientation="radial", n_features=n_features)
    else:
        found = Features(Keypoints.empty(), np.zeros((0, 128), np.float32))
    bearings = camera.rays(found.keypoints.xy) if len(found) else np.zeros((0, 3))
    if times is not None:
        times["histogram"] = times.get("histogram", 0.0) + t1 - t0
        times["sift"] = times.get("sift", 0.0) + time.perf_counter() - t1
    return OmniView(histogram, found, bearings)


@dataclass(frozen=True)
class RelativePose:
    """Pose of a query robot in the frame of a map node, from matched omni features.

    Attributes
    ----------
    pose : numpy.ndarray, shape (3,)
        ``[dx, dy, dtheta]`` of the query in the node's robot frame when ``metric``; otherwise
        ``[0, 0, dtheta]`` with the heading from the essential matrix when ``epipolar``, or all
        zeros.
    metric : bool
        At least ``min_floor`` floor points support the translation.
    epipolar : bool
        The essential matrix found at least ``min_epipolar`` supporting matches.
    verified : bool
        Both hold: the heading and the direction of travel of the essential matrix, the distance
        from the floor.
    n_matches, n_epipolar, n_floor : int
        Tentative matches, essential-matrix inliers, floor points supporting the translation.
    heading_epipolar : float
        ``dtheta`` from the essential matrix (0 when not ``epipolar``).
    rms : float
        Root-mean-square disagreement of the supporting floor points (metres; ``inf`` when not
        ``metric``).
    direction : numpy.ndarray, shape (2,)
        Unit direction from the node to the query in the node's frame, from the essential matrix
        (zeros when not ``epipolar``): the query lies on this ray whatever the distance.
    """

    pose: np.ndarray
    metric: bool
    epipolar: bool
    verified: bool
    n_matches: int
    n_epipolar: int
    n_floor: int
    heading_epipolar: float
    rms: float
    direction: np.ndarray


def relative_pose(query: OmniView, node: OmniView, matches: Matches, camera: OmniCamera, *,
                  threshold_epipolar: float = 0.01, threshold_floor: float = 0.08, min_epipolar: int = 12,
                  min_floor: int = 3, min_depression: float = 0.35, direction_tolerance: float = 0.35,
                  min_baseline: float = 0.1, rng: Any = 0) -> RelativePose:
    """Pose of the query robot relative to a node from their matched features (epipolar + floor).

    Parameters
    ----------
    query, node : OmniView
    matches : Matches
        ``matches.query`` index the query's features, ``matches.train`` the node's.
    camera : OmniCamera
        Both views' camera (its ``mount`` gives the height above the floor).
    threshold_epipolar : float, default 0.01
        Angular Sampson bound (radians) of the essential-matrix RANSAC.
    threshold_floor : float, default 0.08
        Metres: floor points that agree on the translation within this support it.
    min_epipolar : int, default 12
        Least support for the essential matrix to count.
    min_floor : int, default 3
        Least floor points for a metric pose (without an essential matrix the free planar fit
        needs ``max(min_floor, 8)``).
    min_depression : float, default 0.35
        Rays at least this far below the horizon (radians) are lifted to the floor.
    direction_tolerance : float, default 0.35
        Largest angle (radians) between a floor translation and the essential matrix's direction
        of travel, checked beyond ``min_baseline``.
    min_baseline : float, default 0.1
        Metres; below it the direction of travel is not checked (it is noise).
    rng : numpy.random.Generator or int, default 0
        For the RANSACs (fixed by default: a localizer's answer does not change run to run).

    Returns
    -------
    RelativePose

    Raises
    ------
    TypeError, ValueError
        For arguments of the wrong type, match indices out of range, or bad thresholds.

    Notes
    -----
    Lesson 02's paper, Sec. "Hierarchical localization": the recognised node's pose plus "epipolar
    geometry constraints" to verify; the metric step (floor points from the known camera height)
    is this course's, since the paper does not say how it turns a recognised node into the
    positions of its Fig. 9. The essential matrix relates camera frames; the mount turns it into
    robot frames (``R_body = M R M^T``, ``t_body = M t``; both cameras share the mount). Its
    heading and direction of travel are kept, and the floor supplies the one thing it lacks, the
    distance: with the heading known, every floor match proposes a translation on its own, and
    the proposal along the direction of travel that most others agree with wins. Floor features
    near the robot change much between viewpoints a metre apart, so a handful of floor matches is
    typical; three agreeing ones along the epipolar direction are hard to meet by chance.

    Examples
    --------
    >>> cam = OmniCamera(width=160, height=120)
    >>> from robokit.vision import Keypoints
    >>> empty = OmniView(np.zeros(32), Features(Keypoints.empty(), np.zeros((0, 128))), np.zeros((0, 3)))
    >>> rel = relative_pose(empty, empty, Matches.empty(), cam)
    >>> rel.metric, rel.epipolar, rel.verified, rel.pose.tolist()
    (False, False, False, [0.0, 0.0, 0.0])
    """
    for name, view in (("query", query), ("node", node)):
        if not isinstance(view, OmniView):
            raise TypeError(f"{name}: expected an OmniView, got {describe(view)}")
    if not isinstance(matches, Matches):
        raise TypeError(f"matches: expected a robokit.vision.Matches, got {describe(matches)}")
    as_omni_camera(camera)
    qi, ni = np.asarray(matches.query, int), np.asarray(matches.train, int)
    if len(qi) and (qi.min() < 0 or qi.max() >= len(query.bearings) or ni.min() < 0 or ni.max() >= len(node.bearings)):
        raise ValueError(f"matches: expected indices of the query's {len(query.bearings)} and the node's "
                         f"{len(node.bearings)} features, got up to {qi.max()} and {ni.max()}")
    threshold_epipolar = as_positive(threshold_epipolar, "threshold_epipolar")
    threshold_floor = as_positive(threshold_floor, "threshold_floor")
    min_epipolar = as_int(min_epipolar, "min_epipolar", minimum=8)
    min_floor = as_int(min_floor, "min_floor", minimum=2)
    min_depression = as_positive(min_depression, "min_depression")
    if min_depression >= np.pi / 2:
        raise ValueError(f"min_depression: expected an angle in (0, pi/2), got {min_depression}")
    direction_tolerance = as_positive(direction_tolerance, "direction_tolerance")
    min_baseline = as_positive(min_baseline, "min_baseline", allow_zero=True)
    rng = as_rng(rng)
    bq, bn = query.bearings[qi], node.bearings[ni]
    M = camera.mount[:3, :3]
    heading_e, direction_e, n_e, epipolar = 0.0, None, 0, False
    if len(qi) >= max(8, min_epipolar):
        fit = ransac_essential(bn, bq, threshold=threshold_epipolar, min_inliers=min_epipolar, rng=rng)
        if fit.ok:
            R, t, _ = decompose_essential(fit.E, bn[fit.inliers], bq[fit.inliers])
            R_body, t_body = M @ R @ M.T, M @ t               # X_query = R_body X_node + s t_body
            heading_e = float(np.arctan2(R_body[0, 1], R_body[0, 0]))
            direction_e = -R_body.T @ t_body                   # query position in the node frame, unit
            n_e, epipolar = fit.n_inliers, True
    empty = (np.zeros((0, 2)), np.zeros(0, bool))
    pq, vq = floor_points(bq, camera.mount, min_depression=min_depression) if len(qi) else empty
    pn, vn = floor_points(bn, camera.mount, min_depression=min_depression) if len(qi) else empty
    pq, pn = pq[vq & vn], pn[vq & vn]
    if epipolar:
        pose, n_floor, rms = _floor_given_heading(pq, pn, heading_e, direction_e[:2], threshold_floor,
                                                  direction_tolerance, min_baseline)
        metric = n_floor >= min_floor
    else:
        fit = ransac_se2(pq, pn, threshold=threshold_floor, min_inliers=max(min_floor, 8), rng=rng)
        pose, n_floor, rms, metric = fit.pose, fit.n_inliers, fit.rms, fit.ok
    if not metric:
        pose, rms = np.array([0.0, 0.0, heading_e]), np.inf
    verified = bool(metric and epipolar)
    direction = np.zeros(2) if direction_e is None else direction_e[:2] / max(np.linalg.norm(direction_e[:2]), 1e-12)
    return RelativePose(pose, bool(metric), bool(epipolar), verified, int(len(qi)), int(n_e), int(n_floor),
                        heading_e, float(rms), direction)


def _floor_given_heading(pq: np.ndarray, pn: np.ndarray, heading: float, direction: np.ndarray, threshold: float,
                         direction_tolerance: float, min_baseline: float) -> tuple[np.ndarray, int, float]:
    """Translation from floor points when the heading and the direction of travel are known.

    With the rotation fixed, each floor match alone proposes a translation ``t_i = p_n - R p_q``;
    the proposal most others agree with (within ``threshold``) wins, among those that point along
    the essential matrix's direction of travel (beyond ``min_baseline``). A feature above the
    floor lifts to ``k`` times its true horizontal position in both frames (``k > 1`` the same for
    both), so it proposes ``k t``: on the right line, too far, and rarely in agreement with others.
    """
    if len(pq) == 0:
        return np.array([0.0, 0.0, heading]), 0, np.inf
    c, s = np.cos(heading), np.sin(heading)
    T = pn - pq @ np.array([[c, s], [-s, c]])                     # one proposal per match
    norm = np.linalg.norm(T, axis=1)
    d = direction / max(np.linalg.norm(direction), 1e-12)
    along = (norm <= min_baseline) | (np.arccos(np.clip(T @ d / np.maximum(norm, 1e-12), -1, 1)) <= direction_tolerance)
    if not along.any():
        return np.array([0.0, 0.0, heading]), 0, np.inf
    gap = np.linalg.norm(T[along][:, None] - T[None], axis=2)      # (proposals, matches)
    support = gap < threshold
    cost = np.where(support, gap, threshold).sum(1)
    best = int(np.lexsort((cost, -support.sum(1)))[0])
    inliers = support[best]
    t = T[inliers].mean(0)
    inliers = np.linalg.norm(T - t, axis=1) < threshold             # once more about the mean
    t = T[inliers].mean(0) if inliers.any() else t
    rms = float(np.sqrt(((T[inliers] - t) ** 2).sum(1).mean())) if inliers.any() else np.inf
    return np.array([t[0], t[1], heading]), int(inliers.sum()), rms
