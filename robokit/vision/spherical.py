"""Two-view geometry on the unit sphere: the essential matrix of omnidirectional bearings.

An omnidirectional camera gives each feature a *bearing*, a unit vector ``b`` from the single
viewpoint (:meth:`robokit.sim.OmniCamera.rays`), not a pixel on an image plane; rays that point
sideways or backwards are as good as forward ones. Two views of the same point ``X`` related by
``X_2 = R X_1 + t`` satisfy the epipolar constraint ``b_2^T E b_1 = 0`` with ``E = [t]_x R``
(Longuet-Higgins 1981), whatever direction the rays point. This module estimates ``E`` from
bearings (the eight-point algorithm, Hartley 1997), robustly (RANSAC with the Sampson error
measured as an angle on the sphere), and splits it into ``R`` and the direction of ``t`` with the
cheirality test done on the rays themselves (both depths positive), which a pinhole test on the
sign of ``z`` would get wrong for rays behind the image plane. Lesson 02's paper verifies an
ambiguous recognition with "epipolar geometry constraints" (Sec. "Hierarchical localization").

A camera looking down at a level floor from a known height also fixes scale: a bearing below the
horizon meets the floor at one point, :func:`floor_points`, which lifts matched features to metric
points of the robot's frame.

References
----------
.. [1] H. C. Longuet-Higgins, "A computer algorithm for reconstructing a scene from two
   projections", Nature 293, 133-135, 1981.
.. [2] R. I. Hartley, "In defense of the eight-point algorithm", IEEE Trans. Pattern Analysis and
   Machine Intelligence 19(6), 580-593, 1997.
.. [3] R. Hartley and A. Zisserman, *Multiple View Geometry in Computer Vision*, 2nd ed., Cambridge
   University Press, 2004 (Sec. 9.6, 11.4.3).
.. [4] M. A. Fischler and R. C. Bolles, "Random sample consensus: a paradigm for model fitting with
   applications to image analysis and automated cartography", Communications of the ACM 24(6),
   381-395, 1981.
.. [5] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..geometry import as_se3
from ..validation import as_array, as_rng, as_int, as_positive
from .ransac import ransac_sample_count

__all__ = ["as_bearings", "essential_from_bearings", "epipolar_error", "EssentialFit", "ransac_essential",
           "decompose_essential", "floor_points"]

_W = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def as_bearings(value: Any, name: str, *, count: int | None = None) -> np.ndarray:
    """Validate viewing directions (N, 3) and return them scaled to unit length.

    Raises
    ------
    ValueError
        For a shape other than (N, 3) (or ``count`` rows when given), NaN/inf or a zero vector.

    Notes
    -----
    Validation only (DESIGN.md, "Errors"); bearings as in Longuet-Higgins (1981).

    Examples
    --------
    >>> print(as_bearings([[0.0, 0.0, 2.0], [3.0, 4.0, 0.0]], "b"))
    [[0.  0.  1. ]
     [0.6 0.8 0. ]]
    """
    b = as_array(value, name, shape=(count, 3))
    scale = np.max(np.abs(b), axis=1, initial=0.0)      # divided out first: a 1e300 component cannot overflow
    if np.any(scale < 1e-12):
        raise ValueError(f"{name}: expected non-zero viewing directions, got a zero vector at row "
                         f"{int(np.argmax(scale < 1e-12))}")
    b = b / scale[:, None]
    return b / np.linalg.norm(b, axis=1)[:, None]


def _eight_point(b1: np.ndarray, b2: np.ndarray) -> np.ndarray:
    """Unchecked, batched: least-squares ``E`` of unit bearings (..., N, 3), N >= 8, singular values (1, 1, 0)."""
    A = (b2[..., :, :, None] * b1[..., :, None, :]).reshape(*b1.shape[:-1], 9)   # rows of b2^T E b1 = 0
    if A.shape[-2] < 9:                                       # a zero row keeps the thin SVD's V square
        A = np.concatenate([A, np.zeros((*A.shape[:-2], 9 - A.shape[-2], 9))], axis=-2)
    e = np.linalg.svd(A, full_matrices=False)[2][..., -1, :]  # null vector (least squares for N > 8)
    U, _, Vt = np.linalg.svd(e.reshape(*e.shape[:-1], 3, 3))
    return U @ (np.array([1.0, 1.0, 0.0])[:, None] * Vt)     # closest essential matrix (Hartley & Zisserman 9.6)


def essential_from_bearings(b1: Any, b2: Any) -> np.ndarray:
    """Essential matrix from N >= 8 pairs of bearings (the eight-point algorithm on the sphere).

    Parameters
    ----------
    b1, b2 : array_like, shape (N, 3)
        Viewing directions of the same points from camera 1 and camera 2 (any length, not zero).

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        ``E`` with ``b2^T E b1 ~ 0``, singular values ``(1, 1, 0)`` (unit Frobenius norm over
        ``sqrt(2)``; the sign is arbitrary). ``E = [t]_x R`` for ``X_2 = R X_1 + t``, OpenCV's
        convention.

    Raises
    ------
    ValueError
        For fewer than eight pairs, shapes that differ, NaN/inf or zero vectors.

    Notes
    -----
    Longuet-Higgins (1981); Hartley (1997) normalises pixel coordinates so that the linear system
    is well conditioned: unit bearings already have coordinates of order one, so the sphere *is*
    that normalisation. The rank-2 constraint is imposed by setting the singular values to
    ``(1, 1, 0)`` (Hartley & Zisserman 2004, Sec. 9.6.1; lesson 02's paper, Sec. "Hierarchical
    localization", verifies recognition with epipolar geometry).

    Examples
    --------
    A camera turned 0.3 rad about z and moved along x sees eight points:

    >>> rng = np.random.default_rng(0)
    >>> X1 = rng.uniform(-3, 3, (8, 3))
    >>> c, s = np.cos(0.3), np.sin(0.3)
    >>> R, t = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]), np.array([1.0, 0.0, 0.0])
    >>> E = essential_from_bearings(X1, X1 @ R.T + t)
    >>> from robokit.geometry import skew
    >>> E_true = skew(t) @ R / np.linalg.norm(skew(t) @ R)        # [t]x R at unit norm
    >>> print(np.round(E * np.sign(np.sum(E * E_true)) / np.linalg.norm(E), 6) + 0.0)
    [[ 0.        0.        0.      ]
     [ 0.        0.       -0.707107]
     [ 0.208964  0.675525  0.      ]]
    >>> bool(np.allclose(E * np.sign(np.sum(E * E_true)) / np.linalg.norm(E), E_true))
    True
    """
    p = as_bearings(b1, "b1")
    q = as_bearings(b2, "b2", count=len(p))
    if len(p) < 8:
        raise ValueError(f"b1: expected at least 8 pairs of bearings for the eight-point algorithm, got {len(p)}")
    return _eight_point(p, q)


def epipolar_error(E: Any, b1: Any, b2: Any) -> np.ndarray:
    """Sampson distance of bearing pairs to the epipolar constraint, as an angle on the sphere.

    Parameters
    ----------
    E : array_like, shape (3, 3) or (K, 3, 3)
        Essential matrices (one per hypothesis).
    b1, b2 : array_like, shape (N, 3)
        Unit bearings.

    Returns
    -------
    numpy.ndarray, shape (N,) or (K, N)
        ``|b2^T E b1| / sqrt(|P1 E^T b2|^2 + |P2 E b1|^2)`` in radians, with ``P = I - b b^T`` the
        projection onto the sphere's tangent plane at ``b``.

    Raises
    ------
    ValueError
        For bad shapes, NaN/inf or zero vectors.

    Notes
    -----
    The Sampson (first-order geometric) error, Hartley & Zisserman (2004), Sec. 11.4.3, with the
    image-plane Jacobian replaced by the tangent plane of the sphere, so that it measures how far
    (in radians) the two rays must turn to meet.

    Examples
    --------
    >>> E = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])   # [t]x with t = x, R = I
    >>> print(np.round(epipolar_error(E, [[0.0, 0.6, 0.8]], [[0.0, 0.6, 0.8]]), 6))
    [0.]
    >>> # b2 leaves the epipolar plane by 0.0997 rad; Sampson turns each ray about half of that
    >>> print(np.round(epipolar_error(E, [[0.0, 0.0, 1.0]], [[0.0, 0.1, 1.0]]), 4))
    [0.0707]
    """
    E = as_array(E, "E")
    if E.shape[-2:] != (3, 3) or E.ndim > 3:
        raise ValueError(f"E: expected shape (3, 3) or (K, 3, 3), got shape {E.shape}")
    scale = np.max(np.abs(E), axis=(-2, -1), keepdims=True)    # the error is scale-free: divide out first,
    E = E / np.where(scale > 0, scale, 1.0)                    # so 1e300 entries cannot overflow
    b1 = as_bearings(b1, "b1")
    return _epipolar_error(E, b1, as_bearings(b2, "b2", count=len(b1)))


def _epipolar_error(E: np.ndarray, b1: np.ndarray, b2: np.ndarray) -> np.ndarray:
    """Unchecked :func:`epipolar_error` (unit float bearings, float ``E``)."""
    Eb1 = np.einsum("...ij,nj->...ni", E, b1)                  # E b1, (..., N, 3)
    Etb2 = np.einsum("...ji,nj->...ni", E, b2)                 # E^T b2
    algebraic = (b2 * Eb1).sum(-1)
    g1 = Etb2 - (Etb2 * b1).sum(-1, keepdims=True) * b1       # tangent parts of the gradient
    g2 = Eb1 - (Eb1 * b2).sum(-1, keepdims=True) * b2
    denom = np.sqrt((g1 ** 2).sum(-1) + (g2 ** 2).sum(-1))
    return np.abs(algebraic) / np.maximum(denom, 1e-12)


@dataclass(frozen=True)
class EssentialFit:
    """Outcome of :func:`ransac_essential`.

    Attributes
    ----------
    E : numpy.ndarray, shape (3, 3)
        Best essential matrix, refitted on its inliers (zeros when ``ok`` is False).
    inliers : numpy.ndarray of bool, shape (N,)
    errors : numpy.ndarray, shape (N,)
        Angular Sampson error of every pair under ``E`` (radians; ``inf`` when ``ok`` is False).
    iterations : int
        Hypotheses drawn.
    ok : bool
        Whether at least ``min_inliers`` pairs support ``E``.
    """

    E: np.ndarray
    inliers: np.ndarray
    errors: np.ndarray
    iterations: int
    ok: bool

    @property
    def n_inliers(self) -> int:
        """Number of supporting pairs."""
        return int(np.count_nonzero(self.inliers))


def ransac_essential(b1: Any, b2: Any, *, threshold: float = 0.01, confidence: float = 0.99,
                     min_inliers: int = 12, max_iterations: int = 1000, rng: Any = None) -> EssentialFit:
    """Essential matrix from bearing pairs with false matches among them (eight-point RANSAC).

    Parameters
    ----------
    b1, b2 : array_like, shape (N, 3)
        Tentative matches: bearings in camera 1 and camera 2.
    threshold : float, default 0.01
        Inlier bound on the angular Sampson error (radians; 0.01 rad is about 1.4 pixels of the
        640 x 480 omni image at the horizon).
    confidence : float, default 0.99
        ``P`` of the sample count :func:`robokit.vision.ransac.ransac_sample_count` (8 pairs per
        sample), the contamination re-estimated from the best support so far.
    min_inliers : int, default 12
        Fewer supporting pairs and the fit is reported as failed (``ok=False``), not raised.
    max_iterations : int, default 1000
    rng : numpy.random.Generator or int, optional

    Returns
    -------
    EssentialFit

    Raises
    ------
    ValueError
        For bad shapes, NaN/inf, zero vectors or a non-positive threshold.

    Notes
    -----
    Fischler & Bolles (1981) around :func:`essential_from_bearings`; hypotheses are fitted and
    scored in vectorised batches; the winner is refitted on its support (least squares over all
    inliers). Lesson 02's paper, Sec. "Hierarchical localization": "epipolar geometry constraints
    ... are employed to verify the result".

    Examples
    --------
    Forty points seen from two poses, a quarter of the matches shuffled:

    >>> rng = np.random.default_rng(2)
    >>> X1 = rng.uniform(-4, 4, (40, 3))
    >>> R, t = np.eye(3), np.array([0.3, 0.1, 0.0])
    >>> b2 = X1 @ R.T + t
    >>> b2[:10] = b2[rng.permutation(10)]
    >>> fit = ransac_essential(X1, b2, rng=0)
    >>> fit.ok, fit.n_inliers >= 30, bool(fit.inliers[10:].all())
    (True, True, True)
    """
    p = as_bearings(b1, "b1")
    q = as_bearings(b2, "b2", count=len(p))
    thr = as_positive(threshold, "threshold")
    min_inliers = as_int(min_inliers, "min_inliers", minimum=8)
    max_iterations = as_int(max_iterations, "max_iterations", minimum=1)
    gen = as_rng(rng)
    n = len(p)
    needed, drawn = ransac_sample_count(0.5, 8, confidence), 0
    failed = EssentialFit(np.zeros((3, 3)), np.zeros(n, bool), np.full(n, np.inf), 0, False)
    if n < max(8, min_inliers):
        return failed
    best, best_count, best_cost = None, -1, np.inf
    while drawn < min(needed, max_iterations):
        k = min(64, max_iterations - drawn)
        sample = np.argsort(gen.random((k, n)), axis=1)[:, :8]   # eight distinct pairs per hypothesis
        drawn += k
        E = _eight_point(p[sample], q[sample])
        err = _epipolar_error(E, p, q)
        support = err < thr
        count = support.sum(1)
        cost = np.where(support, err, thr).sum(1)                   # MSAC tie-break
        h = int(np.lexsort((cost, -count))[0])
        if count[h] > best_count or (count[h] == best_count and cost[h] < best_cost):
            best, best_count, best_cost = E[h], int(count[h]), float(cost[h])
            needed = ransac_sample_count(min(1 - best_count / n, 0.9), 8, confidence)   # 0.9: ~4.6e8, the cap rules
    E = best
    for _ in range(2):                                              # refit on the support
        inliers = _epipolar_error(E, p, q) < thr
        if inliers.sum() < 8:
            break
        E = _eight_point(p[inliers], q[inliers])
    errors = _epipolar_error(E, p, q)
    inliers = errors < thr
    if inliers.sum() < min_inliers:
        return EssentialFit(failed.E, inliers, errors, drawn, False)
    return EssentialFit(E, inliers, errors, drawn, True)


def _depths(R: np.ndarray, t: np.ndarray, b1: np.ndarray, b2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares depths ``l1, l2`` with ``l2 b2 ~ R (l1 b1) + t`` (midpoint triangulation), per pair."""
    a = b1 @ R.T                                                   # R b1
    # normal equations of [a, -b2] [l1, l2]^T = -t
    aa, ab, bb = (a * a).sum(1), -(a * b2).sum(1), (b2 * b2).sum(1)
    ra, rb = -(a @ t), (b2 @ t)
    det = aa * bb - ab * ab
    ok = det > 1e-12
    det = np.where(ok, det, 1.0)
    l1 = np.where(ok, (ra * bb - ab * rb) / det, 0.0)
    l2 = np.where(ok, (aa * rb - ab * ra) / det, 0.0)
    return l1, l2


def decompose_essential(E: Any, b1: Any, b2: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rotation and translation direction of an essential matrix, chosen by cheirality on bearings.

    Parameters
    ----------
    E : array_like, shape (3, 3)
        Essential matrix with ``b2^T E b1 = 0`` (e.g. from :func:`ransac_essential`).
    b1, b2 : array_like, shape (N, 3)
        Bearing pairs (inliers) that decide among the four solutions.

    Returns
    -------
    R : numpy.ndarray, shape (3, 3)
    t : numpy.ndarray, shape (3,)
        Unit vector; ``X_2 = R X_1 + s t`` for an unknown scale ``s > 0``.
    in_front : numpy.ndarray of bool, shape (N,)
        Pairs whose triangulated point lies ahead along both rays (positive depths).

    Raises
    ------
    ValueError
        For bad shapes, NaN/inf, zero bearings, or a matrix that is not essential (its two
        largest singular values must agree within 10 % and the third be near zero).

    Notes
    -----
    The four solutions ``(U W V^T | U W^T V^T, +-u_3)`` of Hartley & Zisserman (2004), Sec. 9.6.2;
    the one with most points at positive depth along *both rays* wins. This is the cheirality
    test for bearings: an omnidirectional camera sees points behind it, where the pinhole test
    ``z > 0`` fails.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> X1 = rng.uniform(-3, 3, (20, 3))
    >>> c, s = np.cos(0.3), np.sin(0.3)
    >>> R, t = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]), np.array([0.6, 0.8, 0.0])
    >>> b2 = X1 @ R.T + 0.5 * t
    >>> R_est, t_est, front = decompose_essential(essential_from_bearings(X1, b2), X1, b2)
    >>> print(np.round(R_est, 6) + 0.0, np.round(t_est, 6) + 0.0, front.all())
    [[ 0.955336 -0.29552   0.      ]
     [ 0.29552   0.955336  0.      ]
     [ 0.        0.        1.      ]] [0.6 0.8 0. ] True
    """
    E = as_array(E, "E", shape=(3, 3))
    p = as_bearings(b1, "b1")
    q = as_bearings(b2, "b2", count=len(p))
    U, S, Vt = np.linalg.svd(E)
    if not (S[0] > 0 and S[1] >= 0.9 * S[0] and S[2] <= 0.1 * S[0]):
        raise ValueError(f"E: expected an essential matrix (singular values s, s, 0), got {np.round(S, 6).tolist()}")
    U = U * np.sign(np.linalg.det(U))                               # proper rotations
    Vt = Vt * np.sign(np.linalg.det(Vt))
    best = None
    for R in (U @ _W @ Vt, U @ _W.T @ Vt):
        for t in (U[:, 2], -U[:, 2]):
            l1, l2 = _depths(R, t, p, q)
            front = (l1 > 0) & (l2 > 0)
            score = (int(front.sum()), float(np.minimum(l1, l2).clip(max=0).sum()))
            if best is None or score > best[0]:
                best = (score, R, t, front)
    _, R, t, front = best
    return R, t / np.linalg.norm(t), front


def floor_points(bearings: Any, T_body_camera: Any, *, min_depression: float = 0.35) -> tuple[np.ndarray, np.ndarray]:
    """Where viewing rays meet a level floor: metric points of the robot frame from bearings.

    Parameters
    ----------
    bearings : array_like, shape (N, 3)
        Viewing directions in the camera frame (e.g. :meth:`robokit.sim.OmniCamera.rays`).
    T_body_camera : array_like, shape (4, 4)
        The camera's mount on the robot (body frame: x forward, y left, z up, floor at ``z = 0``;
        e.g. :func:`robokit.sim.omni.omni_mount`).
    min_depression : float, default 0.35
        Rays less than this angle (radians, about 20 deg) below the horizon are not lifted: their
        floor point would be far and its range error large (it grows like ``h / sin^2`` of the
        depression).

    Returns
    -------
    points : numpy.ndarray, shape (N, 2)
        Floor points ``(x, y)`` in the body frame (zeros where not ``valid``).
    valid : numpy.ndarray of bool, shape (N,)
        Rays at least ``min_depression`` below the horizon.

    Raises
    ------
    ValueError
        For bad bearings, a transform that is not rigid, a camera not above the floor, or a
        ``min_depression`` outside (0, pi/2).

    Notes
    -----
    A ray ``c + l d`` from the viewpoint ``c`` (height ``h = c_z``) meets the floor at
    ``l = h / (-d_z)``. Features that are not on the floor (a wall's foot, a table's leg) lift to
    wrong points; a robust fit between two views rejects them (:func:`robokit.vision.ransac.ransac_se2`).
    In the paper (Sec. "Implementation for omnidirectional vision") a CCD camera looks *up* at a
    spherical mirror and no height is given; the 1.0 m viewpoint height of our simulated robot and
    the floor lifting are this course's choices, for a metric pose relative to a node.

    Examples
    --------
    A camera 1 m up, mounted z down (the omni frame); a ray 45 deg below the horizon, straight ahead:

    >>> T = np.diag([1.0, -1.0, -1.0, 1.0]); T[2, 3] = 1.0
    >>> pts, ok = floor_points([[1.0, 0.0, 1.0], [1.0, 0.0, -0.1]], T)
    >>> print(np.round(pts, 6) + 0.0, ok)
    [[1. 0.]
     [0. 0.]] [ True False]
    """
    d = as_bearings(bearings, "bearings")
    T = as_se3(T_body_camera, "T_body_camera")
    dep = as_positive(min_depression, "min_depression")
    if dep >= np.pi / 2:
        raise ValueError(f"min_depression: expected an angle in (0, pi/2), got {dep}")
    h = T[2, 3]
    if not h > 0:
        raise ValueError(f"T_body_camera: expected a camera above the floor (z > 0), got z = {h}")
    ray = d @ T[:3, :3].T                                          # body-frame directions
    valid = -ray[:, 2] >= np.sin(dep)
    scale = np.where(valid, h / np.where(valid, -ray[:, 2], 1.0), 0.0)
    pts = T[:2, 3] + scale[:, None] * ray[:, :2]
    pts[~valid] = 0.0
    return pts, valid
