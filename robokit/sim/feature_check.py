"""Do real feature detectors work on rendered images? Matches checked against exact geometry.

The simulator knows the depth of every pixel, so a feature match between two rendered views can be
judged without any homography or hand labelling: lift the first pixel to 3D with its rendered
depth, project it into the second view, and see whether it lands on the matched pixel.

References
----------
.. [1] R. Hartley and A. Zisserman, *Multiple View Geometry in Computer Vision*, 2nd ed.,
   Cambridge University Press, 2004.
.. [2] D. G. Lowe, "Distinctive image features from scale-invariant keypoints", *International
   Journal of Computer Vision* 60(2), 2004, pp. 91-110.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from ..validation import as_array, as_points, check_positive
from ..vision.matching import ratio_match
from .camera import PinholeCamera
from .world import World

__all__ = ["ViewPairCheck", "ground_truth_inliers", "sift_view_pair"]


def ground_truth_inliers(camera: PinholeCamera, depth: Any, T1: Any, T2: Any, uv1: Any, uv2: Any,
                         tol: float = 3.0) -> np.ndarray:
    """Which correspondences ``uv1 -> uv2`` agree with the true geometry of two rendered views.

    Parameters
    ----------
    camera : PinholeCamera
        The camera that rendered both views.
    depth : array_like, shape (H, W)
        Rendered depth ``Z`` of the first view.
    T1, T2 : array_like, shape (4, 4)
        ``T_world_cam`` of the two views.
    uv1, uv2 : array_like, shape (N, 2)
        Matched pixel coordinates ``(u, v) = (col, row)`` in view 1 and view 2.
    tol : float, default 3
        Largest reprojection distance (pixels) that counts as correct.

    Returns
    -------
    numpy.ndarray, shape (N,), bool
        False also where view 1 has no finite depth (nothing to check against).

    Raises
    ------
    TypeError
        If ``camera`` is not a :class:`PinholeCamera`.
    ValueError
        For mismatched shapes, pixels outside the depth image or a non-positive ``tol``.

    Notes
    -----
    Back-projection ``X = Z K^-1 [u, v, 1]^T`` and projection ``u = K X / Z`` (Hartley & Zisserman
    2004, Eq. 6.5); the depth is read at the nearest pixel.
    """
    if not isinstance(camera, PinholeCamera):
        raise TypeError(f"camera: expected robokit.sim.PinholeCamera, got {type(camera).__name__}")
    depth = as_array(depth, "depth", shape=(camera.height, camera.width), finite=False)
    tol = check_positive(tol, "tol")
    uv1 = as_points(uv1, "uv1", 2)
    uv2 = as_points(uv2, "uv2", 2)
    if len(uv1) != len(uv2):
        raise ValueError(f"uv2: expected {len(uv1)} pixels like uv1, got {len(uv2)}")
    col, row = np.round(uv1[:, 0]).astype(int), np.round(uv1[:, 1]).astype(int)
    if np.any((col < 0) | (col >= camera.width) | (row < 0) | (row >= camera.height)):
        raise ValueError(f"uv1: expected pixels inside the {camera.width}x{camera.height} image")
    z = depth[row, col]
    known = np.isfinite(z) & (z > 0)          # pixels without a surface (no depth) cannot be judged
    ok = np.zeros(len(uv1), bool)
    if known.any():
        predicted, _ = camera.project(camera.backproject(uv1[known], z[known], T1), T2)
        ok[known] = np.linalg.norm(predicted - uv2[known], axis=1) < tol
    return ok


@dataclass(frozen=True)
class ViewPairCheck:
    """Result of :func:`sift_view_pair`: ``keypoints`` in view 1, ratio-test ``matches`` and the
    fraction of them that agree with the true geometry (``inlier_ratio``)."""

    keypoints: int
    matches: int
    inlier_ratio: float


def sift_view_pair(world: World, camera: PinholeCamera, robot_pose: Any, step: float = 0.3,
                   ratio: float = 0.8, tol: float = 3.0) -> ViewPairCheck:
    """OpenCV SIFT on two views ``step`` metres apart, matches judged by :func:`ground_truth_inliers`.

    Parameters
    ----------
    world : World
    camera : PinholeCamera
        Rendered at its mount on the robot (:meth:`PinholeCamera.transform_at`).
    robot_pose : array_like, shape (3,)
        Planar pose ``[x, y, theta]`` of the first view; the second is ``step`` metres ahead.
    step : float, default 0.3
    ratio : float, default 0.8
        Lowe's nearest/second-nearest distance ratio (Lowe 2004, Sec. 7.1), in (0, 1], applied by
        :func:`robokit.vision.ratio_match` on OpenCV's brute-force matcher.
    tol : float, default 3
        Reprojection tolerance in pixels.

    Returns
    -------
    ViewPairCheck

    Raises
    ------
    ValueError
        For bad sizes or a pose outside the world's free space (raised by the renderer).

    Notes
    -----
    The simulator's acceptance check: rendered textures must give a detector what a camera
    image would, hundreds of keypoints and mostly correct matches.
    """
    step = check_positive(step, "step")
    ratio = check_positive(ratio, "ratio")
    pose = as_array(robot_pose, "robot_pose", shape=(3,))
    T1 = camera.transform_at(pose)
    T2 = camera.transform_at(pose + [step * np.cos(pose[2]), step * np.sin(pose[2]), 0.0])
    frame1, frame2 = camera.render(world, T1), camera.render(world, T2)
    sift = cv2.SIFT_create()
    k1, d1 = sift.detectAndCompute(cv2.cvtColor(frame1.image, cv2.COLOR_RGB2GRAY), None)
    k2, d2 = sift.detectAndCompute(cv2.cvtColor(frame2.image, cv2.COLOR_RGB2GRAY), None)
    if d1 is None or d2 is None:
        return ViewPairCheck(len(k1), 0, 0.0)
    good = ratio_match(d1, d2, ratio=ratio, method="opencv")
    if not len(good):
        return ViewPairCheck(len(k1), 0, 0.0)
    uv1 = np.array([k1[i].pt for i in good.query])
    uv2 = np.array([k2[j].pt for j in good.train])
    inliers = ground_truth_inliers(camera, frame1.depth, T1, T2, uv1, uv2, tol)
    return ViewPairCheck(len(k1), len(good), float(inliers.mean()))
