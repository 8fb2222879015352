"""Rectified stereo: constrained feature matching, triangulation and its uncertainty.

Frames: the camera (= robot) frame has X to the right (sideways), Y up and Z forward (the
convention of Se et al. and Lin et al.); an image pixel is ``(c, r) = (col, row)`` with rows growing downwards. The right camera
sits ``I`` metres to the right of the left one and both share the focal length ``f`` (pixels) and
the image centre ``(c0, r0)``, so a point's disparity is ``d = c_left - c_right = f I / Z``.

Lin et al. Sec. 3 (matching constraints, SVD triangulation) and Se, Lowe & Little Sec. 2.2
(ambiguity rejection) and 3.1 (disparity formulas and first-order error propagation).

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [2] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002.
.. [3] R. Hartley and A. Zisserman, *Multiple View Geometry in Computer Vision*, 2nd ed., Cambridge
   University Press, 2004.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import wrap_angle
from ..validation import as_array, require_finite_result, as_finite_scalar, as_positive
from .features import Features
from .matching import gated_ratio_match, ratio_match

__all__ = ["NotRectifiedError", "StereoCalibration", "StereoMatches", "StereoObservations", "disparity_to_point",
           "triangulate_svd", "match_stereo", "observe_stereo"]


class NotRectifiedError(ValueError):
    """Raised when stereo input is not a rectified pair (epipolar lines are not image rows)."""


@dataclass(frozen=True)
class StereoCalibration:
    """The calibration of a rectified stereo pair: what triangulation needs (Se et al. Sec. 3.1).

    Not to be confused with :class:`robokit.sim.StereoRig`, the simulated rig that renders images;
    :func:`robocourse.lessons.visual_slam.experiment.calibrated_rig` reads one off the other.

    Attributes
    ----------
    focal : float
        Focal length ``f`` in pixels.
    c0, r0 : float
        Image centre column and row in pixels.
    baseline : float
        Interocular distance ``I`` in metres (right camera to the right of the left one).
    """

    focal: float
    c0: float
    r0: float
    baseline: float

    def __post_init__(self):
        as_positive(self.focal, "focal")
        as_finite_scalar(self.c0, "c0")
        as_finite_scalar(self.r0, "r0")
        as_positive(self.baseline, "baseline")

    def projection_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Return the 3 x 4 projection matrices ``(P_L, P_R)`` in the camera frame (X right, Y up).

        Notes
        -----
        Pinhole model of Se et al. Sec. 3.1 written as matrices for Lin et al.'s triangulation.
        """
        f, c0, r0, b = self.focal, self.c0, self.r0, self.baseline
        left = np.array([[f, 0.0, c0, 0.0], [0.0, -f, r0, 0.0], [0.0, 0.0, 1.0, 0.0]])
        right = left.copy()
        right[0, 3] = -f * b
        return left, right

    def project(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Project camera-frame points (N, 3) with Z > 0 to left and right pixels ``(c, r)``.

        Raises
        ------
        ValueError
            If a point is not in front of the cameras.

        Notes
        -----
        Inverse of Se et al. Sec. 3.1: ``c = c0 + f X / Z``, ``r = r0 - f Y / Z``, and the right
        column is ``f I / Z`` smaller.
        """
        pts = as_array(points, "points", shape=(None, 3))
        if np.any(pts[:, 2] <= 0):
            raise ValueError("points: expected Z > 0 (in front of the cameras), got Z <= 0")
        left, right = self.projection_matrices()
        hom = np.column_stack([pts, np.ones(len(pts))])
        pl, pr = hom @ left.T, hom @ right.T
        return pl[:, :2] / pl[:, 2:], pr[:, :2] / pr[:, 2:]

    @classmethod
    def from_projections(cls, p_left, p_right, *, tol: float = 1e-6) -> "StereoCalibration":
        """Recover the rig from projection matrices, refusing a pair that is not rectified.

        Parameters
        ----------
        p_left, p_right : array_like, shape (3, 4)
            Projection matrices in the left camera's frame (X right, Y up, Z forward).
        tol : float
            Relative tolerance of the rectification checks.

        Returns
        -------
        StereoCalibration

        Raises
        ------
        NotRectifiedError
            If the cameras differ by more than a sideways translation, or the left one is not
            the canonical ``[K | 0]``.
        """
        pl = as_array(p_left, "p_left", shape=(3, 4))
        pr = as_array(p_right, "p_right", shape=(3, 4))
        pl, pr = pl / np.linalg.norm(pl[2, :3]), pr / np.linalg.norm(pr[2, :3])
        scale = max(1.0, float(np.abs(pl).max()))
        same = np.allclose(pl[1:], pr[1:], atol=tol * scale) and np.allclose(pl[0, :3], pr[0, :3], atol=tol * scale)
        canonical = (np.allclose(pl[:, 3], 0, atol=tol * scale) and np.allclose(pl[2, :3], [0, 0, 1], atol=tol)
                     and abs(pl[0, 1]) <= tol * scale and abs(pl[1, 0]) <= tol * scale
                     and pl[0, 0] > 0 and np.isclose(pl[1, 1], -pl[0, 0], atol=tol * scale))
        if not (same and canonical):
            raise NotRectifiedError("p_left, p_right: expected a rectified pair [K | 0], [K | -K (I, 0, 0)^T] "
                                    "with K = [[f, 0, c0], [0, -f, r0], [0, 0, 1]]; got another pair")
        f = pl[0, 0]
        return cls(float(f), float(pl[0, 2]), float(pl[1, 2]), float(-pr[0, 3] / f))


@dataclass(frozen=True)
class StereoMatches:
    """Accepted left-right correspondences: indices, disparity (pixels) and descriptor distance."""

    left: np.ndarray
    right: np.ndarray
    disparity: np.ndarray
    distance: np.ndarray

    def __len__(self) -> int:
        return int(self.left.size)


@dataclass(frozen=True)
class StereoObservations:
    """3-D features of one stereo frame in the robot (left camera) frame.

    Attributes
    ----------
    points : numpy.ndarray, shape (M, 3)
    covariances : numpy.ndarray, shape (M, 3, 3)
    features : Features
        The left-image features of the matches (keypoints and descriptors).
    matches : StereoMatches
    """

    points: np.ndarray
    covariances: np.ndarray
    features: Features
    matches: StereoMatches

    def __len__(self) -> int:
        return int(self.points.shape[0])


def disparity_to_point(c, r, d, rig: StereoCalibration, *, sigma_c: float = 1.0, sigma_r: float = 1.0,
                       sigma_d: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """3-D position from image coordinates and disparity, with first-order covariance.

    Parameters
    ----------
    c, r : array_like, shape (N,)
        Column and row in the left image (pixels).
    d : array_like, shape (N,)
        Disparity in pixels (> 0).
    rig : StereoCalibration
    sigma_c, sigma_r, sigma_d : float, default 1
        Standard deviations of column, row and disparity in pixels (Se et al. measured 1, 1 and
        ``sigma_d^2 = 1`` for their trinocular average).

    Returns
    -------
    points : numpy.ndarray, shape (N, 3)
        ``X = (c - c0) I / d``, ``Y = (r0 - r) I / d``, ``Z = f I / d`` in metres.
    covariance : numpy.ndarray, shape (N, 3, 3)
        ``J diag(sigma_c^2, sigma_r^2, sigma_d^2) J^T`` with ``J = d(X, Y, Z) / d(c, r, d)``.

    Raises
    ------
    ValueError
        If the arrays differ in length, a disparity is not positive, or a sigma is negative.

    Notes
    -----
    Se, Lowe & Little, Sec. 3.1 (the pinhole formulas and first-order error propagation).
    """
    if not isinstance(rig, StereoCalibration):
        raise TypeError(f"rig: expected StereoCalibration, got {type(rig).__name__}")
    c = as_array(c, "c", ndim=1)
    r = as_array(r, "r", shape=(c.size,))
    d = as_array(d, "d", shape=(c.size,))
    if np.any(d <= 0):
        raise ValueError("d: expected positive disparities (points in front of the rig), got d <= 0")
    var = np.square([as_positive(sigma_c, "sigma_c", allow_zero=True),
                     as_positive(sigma_r, "sigma_r", allow_zero=True),
                     as_positive(sigma_d, "sigma_d", allow_zero=True)])
    ib = rig.baseline / d
    pts = np.column_stack([(c - rig.c0) * ib, (rig.r0 - r) * ib, rig.focal * ib])
    jac = np.zeros((c.size, 3, 3))
    jac[:, 0, 0] = ib
    jac[:, 1, 1] = -ib
    jac[:, :, 2] = -pts / d[:, None]          # d(X, Y, Z)/dd = -(X, Y, Z)/d
    cov = np.einsum("nij,j,nkj->nik", jac, var, jac)
    require_finite_result("c, r, d, rig (focal, c0, r0, baseline), sigma_c, sigma_r, sigma_d", pts, cov)
    return pts, cov


def triangulate_svd(p_left, p_right, uv_left, uv_right) -> np.ndarray:
    """Triangulate matches by the SVD of the 4 x 4 homogeneous system ``A x = 0``.

    Parameters
    ----------
    p_left, p_right : array_like, shape (3, 4)
        Projection matrices.
    uv_left, uv_right : array_like, shape (N, 2)
        Pixel coordinates ``(u, v) = (col, row)`` of the matches.

    Returns
    -------
    numpy.ndarray, shape (N, 3)

    Raises
    ------
    ValueError
        For mismatched shapes, or zero disparity: two cameras with the same centre (no baseline,
        every match), a match whose rays are parallel (a point at infinity) or coincide (a point
        on the baseline); none has one finite position.

    Notes
    -----
    Lin et al. Sec. 3: rows ``u P^3 - P^1`` and ``v P^3 - P^2`` for each camera; the solution is
    the right singular vector of the smallest singular value (last column of ``V``), normalised by
    its last element (Hartley & Zisserman 2004, Sec. 12.2). Two solutions (a second zero singular
    value) mean the rays coincide; the camera centres are the null vectors of ``P`` (Sec. 6.2.4).

    Examples
    --------
    >>> K = np.array([[100.0, 0.0, 80.0], [0.0, 100.0, 60.0], [0.0, 0.0, 1.0]])
    >>> p_left, p_right = K @ np.eye(3, 4), K @ np.hstack([np.eye(3), [[-0.12], [0.0], [0.0]]])
    >>> triangulate_svd(p_left, p_right, [[80.0, 60.0]], [[70.0, 60.0]]).round(6).tolist()
    [[0.0, 0.0, 1.2]]
    >>> triangulate_svd(p_left, p_left, [[80.0, 60.0]], [[70.0, 60.0]])
    Traceback (most recent call last):
    ...
    ValueError: p_left, p_right: expected two camera centres (a baseline), got one centre: every match has zero disparity
    """
    pl = as_array(p_left, "p_left", shape=(3, 4))
    pr = as_array(p_right, "p_right", shape=(3, 4))
    ul = as_array(uv_left, "uv_left", shape=(None, 2))
    ur = as_array(uv_right, "uv_right", shape=(ul.shape[0], 2))
    cl, cr = np.linalg.svd(pl)[2][-1], np.linalg.svd(pr)[2][-1]    # the centres, homogeneous, unit length
    wedge = np.outer(cl, cr)
    if np.linalg.norm(wedge - wedge.T) < 1e-12:
        raise ValueError("p_left, p_right: expected two camera centres (a baseline), got one centre: "
                         "every match has zero disparity")
    a = np.stack([ul[:, :1] * pl[2] - pl[0], ul[:, 1:] * pl[2] - pl[1],
                  ur[:, :1] * pr[2] - pr[0], ur[:, 1:] * pr[2] - pr[1]], axis=1)
    # condition each row so the smallest singular vector is not dominated by pixel magnitudes
    a /= np.linalg.norm(a, axis=2, keepdims=True)
    _, sv, vt = np.linalg.svd(a)
    x = vt[:, -1, :]
    w = x[:, 3]
    if np.any(sv[:, 2] < 1e-12 * sv[:, 0]):
        raise ValueError("uv_left, uv_right: a match has zero disparity (its rays through p_left and p_right coincide: "
                         "a point on the baseline)")
    if np.any(np.abs(w) < 1e-12 * np.abs(x[:, :3]).max(axis=1, initial=1.0)):
        raise ValueError("uv_left, uv_right: a match has zero disparity (its rays through p_left and p_right are "
                         "parallel: a point at infinity)")
    return x[:, :3] / w[:, None]


def match_stereo(left: Features, right: Features, *, epipolar_tol: float = 1.5,
                 min_disparity: float = 0.5, max_disparity: float = 200.0,
                 max_orientation_diff: float = np.deg2rad(20.0), max_scale_ratio: float = 1.5,
                 ratio: float = 0.65, max_distance: float = 0.8, require_rectified: bool = True) -> StereoMatches:
    """Match features of a rectified pair under the epipolar, disparity, orientation and scale constraints.

    Parameters
    ----------
    left, right : Features
        Features of the left and right images.
    epipolar_tol : float, default 1.5
        Maximum row difference in pixels (rectified: epipolar lines are rows).
    min_disparity, max_disparity : float
        Allowed disparity ``c_left - c_right`` in pixels.
    max_orientation_diff : float, default 20 degrees
        Maximum difference of the keypoint orientations (radians).
    max_scale_ratio : float, default 1.5
        Maximum ratio of the keypoint scales.
    ratio : float, default 0.65
        Nearest / second-nearest descriptor distance among the candidates allowed by the
        constraints; above it the feature is ambiguous and discarded.
    max_distance : float, default 0.8
        Maximum descriptor distance (unit-length descriptors) of an accepted match.
    require_rectified : bool, default True
        Refuse input whose unconstrained descriptor matches lie far off the image rows.

    Returns
    -------
    StereoMatches
        Empty when either side has no features.

    Raises
    ------
    NotRectifiedError
        If ``require_rectified`` and at least 12 confident descriptor matches have a median row
        difference above ``3 * epipolar_tol``.
    ValueError, TypeError
        For invalid arguments.

    Notes
    -----
    Lin et al. Sec. 3 (nearest-neighbour ratio t = 0.65; epipolar and disparity, orientation and
    scale constraints) and Se et al. Sec. 2.2 (a feature with more than one acceptable match is
    ambiguous and discarded; a right feature claimed twice is discarded too).
    """
    for name, f in (("left", left), ("right", right)):
        if not isinstance(f, Features):
            raise TypeError(f"{name}: expected Features, got {type(f).__name__}")
    tol = as_positive(epipolar_tol, "epipolar_tol")
    dmin = as_finite_scalar(min_disparity, "min_disparity")
    dmax = as_finite_scalar(max_disparity, "max_disparity")
    if dmax <= dmin:
        raise ValueError(f"max_disparity: expected a value > min_disparity={dmin}, got {dmax}")
    dori = as_positive(max_orientation_diff, "max_orientation_diff")
    srat = as_positive(max_scale_ratio, "max_scale_ratio")
    if srat < 1:
        raise ValueError(f"max_scale_ratio: expected a value >= 1, got {srat}")
    ratio = as_positive(ratio, "ratio")
    max_distance = as_positive(max_distance, "max_distance")
    empty = StereoMatches(np.zeros(0, int), np.zeros(0, int), np.zeros(0), np.zeros(0))
    if len(left) == 0 or len(right) == 0:
        return empty
    if left.descriptors.shape[1] != right.descriptors.shape[1]:
        raise ValueError(f"right: expected descriptors of length {left.descriptors.shape[1]}, "
                         f"got {right.descriptors.shape[1]}")
    kl, kr = left.keypoints, right.keypoints
    if require_rectified:
        # exact search either way; OpenCV's brute force is faster than a KD-tree for long descriptors
        method = "kdtree" if left.descriptors.shape[1] <= 32 else "opencv"
        m = ratio_match(left.descriptors, right.descriptors, ratio=0.6, method=method)
        if len(m) >= 12:
            dy = np.median(np.abs(kl.xy[m.query, 1] - kr.xy[m.train, 1]))
            if dy > 3 * tol:
                raise NotRectifiedError(f"left, right: expected a rectified pair (matches on the same rows), "
                                        f"got a median row difference of {dy:.1f} px")
    li, ri = _row_candidates(kl.xy[:, 1], kr.xy[:, 1], tol)
    disp = kl.xy[li, 0] - kr.xy[ri, 0]
    ok = (np.abs(kl.xy[li, 1] - kr.xy[ri, 1]) <= tol) & (disp >= dmin) & (disp <= dmax)
    dtheta = np.abs(wrap_angle(kl.orientation[li] - kr.orientation[ri], validate=False))
    ok &= dtheta <= dori
    sr = kl.scale[li] / kr.scale[ri]
    ok &= (sr <= srat) & (sr >= 1 / srat)
    li, ri = li[ok], ri[ok]
    m = gated_ratio_match(left.descriptors, right.descriptors, li, ri, ratio=ratio, max_distance=max_distance)
    unique = np.bincount(m.train, minlength=len(kr))[m.train] == 1   # one left feature per right one
    li, ri = m.query[unique], m.train[unique]
    return StereoMatches(li, ri, kl.xy[li, 0] - kr.xy[ri, 0], m.distance[unique])


def _row_candidates(y_left: np.ndarray, y_right: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Every pair (left, right), in row-major order, whose rows may lie within ``tol`` of each other.

    A superset of ``|y_left - y_right| <= tol`` (the window is widened by a rounding margin; the
    caller applies the exact test), found by sorting the right rows instead of comparing all pairs.
    """
    order = np.argsort(y_right, kind="stable")
    ys = y_right[order]
    margin = tol + 1e-9 * (1.0 + np.abs(y_left).max(initial=0.0))
    lo = np.searchsorted(ys, y_left - margin, side="left")
    count = np.searchsorted(ys, y_left + margin, side="right") - lo
    li = np.repeat(np.arange(len(y_left)), count)
    ri = order[np.arange(count.sum()) - np.repeat(np.cumsum(count) - count - lo, count)]
    pairs = np.lexsort((ri, li))          # row-major, as numpy.nonzero of the all-pairs test gives them
    return li[pairs], ri[pairs]


def observe_stereo(left: Features, right: Features, rig: StereoCalibration, *, sigma_c: float = 1.0,
                   sigma_r: float = 1.0, sigma_d: float = 1.0, **match_options) -> StereoObservations:
    """Match a rectified pair and turn the matches into 3-D points with covariances.

    Parameters
    ----------
    left, right : Features
    rig : StereoCalibration
    sigma_c, sigma_r, sigma_d : float
        Image noise (pixels) for :func:`disparity_to_point`.
    **match_options
        Passed to :func:`match_stereo` (the disparity range defaults to the rig's 0.3 m .. infinity
        when not given).

    Returns
    -------
    StereoObservations
        Empty (zero rows) when nothing matches.

    Notes
    -----
    Lin et al. Sec. 3 (matching, then "the 3D positions of matches relative to the mobile robot")
    and Se et al. Sec. 2.2 and 3.1.

    Examples
    --------
    A right image that is the left one shifted 8 px to the left: every point lies at
    ``Z = f I / d = 400 * 0.12 / 8 = 6`` m.

    >>> from robokit.vision import StereoCalibration, detect_plot_features, observe_stereo
    >>> import cv2, numpy as np
    >>> noise = np.random.default_rng(1).uniform(0, 255, (160, 208))
    >>> scene = cv2.GaussianBlur(noise, (0, 0), 2.0).astype(np.uint8)
    >>> left, right = scene[:, :200], scene[:, 8:]
    >>> cal = StereoCalibration(focal=400.0, c0=99.5, r0=79.5, baseline=0.12)
    >>> obs = observe_stereo(detect_plot_features(left), detect_plot_features(right), cal)
    >>> len(obs.points) > 50, float(np.median(obs.points[:, 2]).round(2))
    (True, 6.0)
    """
    if not isinstance(rig, StereoCalibration):
        raise TypeError(f"rig: expected StereoCalibration, got {type(rig).__name__}")
    for name, sigma in (("sigma_c", sigma_c), ("sigma_r", sigma_r), ("sigma_d", sigma_d)):
        as_positive(sigma, name, allow_zero=True)      # now, not only when there are matches
    match_options.setdefault("max_disparity", rig.focal * rig.baseline / 0.3)
    m = match_stereo(left, right, **match_options)
    if len(m) == 0:
        return StereoObservations(np.zeros((0, 3)), np.zeros((0, 3, 3)), left.subset(m.left), m)
    xy = left.keypoints.xy[m.left]
    pts, cov = disparity_to_point(xy[:, 0], xy[:, 1], m.disparity, rig, sigma_c=sigma_c, sigma_r=sigma_r,
                                  sigma_d=sigma_d)
    return StereoObservations(pts, cov, left.subset(m.left), m)
