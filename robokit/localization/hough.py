"""Global localization by Hough-transform set matching (Se, Lowe & Little, Sec. 5).

Given the current stereo features (robot frame) and the landmark database (world frame), every
potential feature-landmark match votes, for every discretised heading ``theta``, for the robot
position ``(X, Z)`` that would align them; votes are spread over +-2.8 sigma in X and Z (a 95 %
region). The top N bins are pose hypotheses, each refined by iterated least squares over the
matches it explains; the winner has the most matches and the lowest residual.

Variable-size rectangular votes are added in O(1) each with a 2-D difference array (four corner
increments) that OpenCV's integral image turns into the accumulator.

References
----------
.. [1] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002.
"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ..geometry.paper_frames import pqt_rotate_xz, pqt_transform_xz
from ..mapping.landmarks import LandmarkMap
from ..vision.matching import k_nearest
from ..validation import as_array, as_choice, as_int, as_positive
from .egomotion import InsufficientMatchesError, fit_pose

__all__ = ["Hypothesis", "candidate_matches", "hough_accumulator", "global_localize"]

_BLOCK = 256  # matches voted at once: small (matches, headings) arrays stay in cache


@dataclass(frozen=True)
class Hypothesis:
    """A refined pose hypothesis.

    Attributes
    ----------
    pqt : numpy.ndarray, shape (3,)
        ``[p, q, theta]`` (metres, metres, radians).
    covariance : numpy.ndarray, shape (3, 3)
    votes : int
        Votes of the Hough bin it started from.
    feature_index, landmark_row : numpy.ndarray of int
        The matches it explains after refinement.
    rms : float
        Root-mean-square ground-plane residual of those matches (metres).
    """

    pqt: np.ndarray
    covariance: np.ndarray
    votes: int
    feature_index: np.ndarray
    landmark_row: np.ndarray
    rms: float

    @property
    def n_matches(self) -> int:
        """Number of matches explained by the pose."""
        return int(self.feature_index.size)


def candidate_matches(points, descriptors, landmarks: LandmarkMap, *, k: int = 3, max_distance: float = 0.5,
                      height_tol: float = 0.2, method: str = "auto") -> tuple[np.ndarray, np.ndarray]:
    """Potential matches: the ``k`` nearest landmark descriptors that also agree in height.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Features in the robot frame (Y is the height above the camera, as in the world frame).
    descriptors : array_like, shape (N, D)
    landmarks : LandmarkMap
    k : int, default 3
        Candidates per feature.
    max_distance : float, default 0.5
        Maximum descriptor distance (unit-length descriptors).
    height_tol : float, default 0.2
        Maximum height difference in metres.
    method : {"auto", "kdtree", "bruteforce"}, default "auto"
        Exact neighbour search by scipy's KD-tree or by blocked matrix products; ``"auto"`` takes
        the KD-tree for short descriptors (16 elements) and brute force for long ones (128), where a
        KD-tree degenerates into a slower exhaustive search.

    Returns
    -------
    feature_index, landmark_row : numpy.ndarray of int

    Notes
    -----
    Se et al. Sec. 5, step 1: "using the local image vector and the height as the preliminary
    constraints".
    """
    pts = as_array(points, "points", shape=(None, 3))
    desc = as_array(descriptors, "descriptors", shape=(pts.shape[0], landmarks.descriptor_size), dtype=np.float32)
    k = as_int(k, "k", minimum=1)
    max_distance = as_positive(max_distance, "max_distance")
    height_tol = as_positive(height_tol, "height_tol")
    if pts.shape[0] == 0 or len(landmarks) == 0:
        return np.zeros(0, int), np.zeros(0, int)
    method = as_choice(method, "method", ("auto", "kdtree", "bruteforce"))
    if method == "auto":
        method = "kdtree" if landmarks.descriptor_size <= 32 else "bruteforce"
    k = min(k, len(landmarks))
    dist, idx = k_nearest(desc, landmarks.descriptors, k, method=method, max_distance=max_distance)
    fi = np.repeat(np.arange(pts.shape[0]), k)
    li = idx.ravel()
    ok = np.isfinite(dist.ravel())
    fi, li = fi[ok], li[ok]
    ok = np.abs(pts[fi, 1] - landmarks.positions[li, 1]) <= height_tol
    return fi[ok], li[ok]


def hough_accumulator(robot_xz, robot_cov_xz, world_xz, world_cov_xz, bounds, *, bin_size: float = 0.04,
                      angle_bin: float = np.deg2rad(2.0), spread: float = 2.8) -> tuple[np.ndarray, np.ndarray]:
    """Vote over ``(theta, X, Z)`` for every potential match.

    Parameters
    ----------
    robot_xz : array_like, shape (M, 2)
        Feature ground-plane position ``(X', Z')`` in the robot frame.
    robot_cov_xz : array_like, shape (M, 2, 2)
        Its covariance.
    world_xz : array_like, shape (M, 2)
        Landmark ``(X, Z)`` in the world.
    world_cov_xz : array_like, shape (M, 2, 2)
    bounds : array_like, shape (4,)
        ``(x_min, x_max, z_min, z_max)`` of the search space in metres.
    bin_size : float, default 0.04
        Position bin (Se et al. used 4 cm).
    angle_bin : float, default 2 degrees
        Heading bin (radians).
    spread : float, default 2.8
        Votes cover +-spread sigma in X and Z.

    Returns
    -------
    accumulator : numpy.ndarray of int, shape (T, NX, NZ)
    thetas : numpy.ndarray, shape (T,)
        Bin-centre headings.

    Notes
    -----
    Se et al. Sec. 5, steps 2-3. For heading ``theta`` the pose aligning a match is
    ``(p, q) = (X, Z) - R(theta) (X', Z')``; its covariance is
    ``Sigma_landmark + R Sigma_feature R^T``, and the vote fills the rectangle covering
    +-2.8 sigma in X and Z.
    """
    r = as_array(robot_xz, "robot_xz", shape=(None, 2))
    m = r.shape[0]
    rc = as_array(robot_cov_xz, "robot_cov_xz", shape=(m, 2, 2))
    w = as_array(world_xz, "world_xz", shape=(m, 2))
    wc = as_array(world_cov_xz, "world_cov_xz", shape=(m, 2, 2))
    b = as_array(bounds, "bounds", shape=(4,))
    if b[1] <= b[0] or b[3] <= b[2]:
        raise ValueError(f"bounds: expected x_min < x_max and z_min < z_max, got {b.tolist()}")
    size = as_positive(bin_size, "bin_size")
    dth = as_positive(angle_bin, "angle_bin")
    spread = as_positive(spread, "spread")
    nt = int(round(2 * np.pi / dth))
    # sizes rounded up to multiples of 4 bins: the peak search works on 4 x 4 blocks without copying
    nx, nz = 4 * int(np.ceil((b[1] - b[0]) / size / 4)), 4 * int(np.ceil((b[3] - b[2]) / size / 4))
    if nt * nx * nz > 60_000_000:
        raise ValueError(f"bounds: the Hough space would have {nt * nx * nz} bins; enlarge bin_size or shrink bounds")
    thetas = -np.pi + (np.arange(nt) + 0.5) * 2 * np.pi / nt
    # float32 holds vote counts exactly (< 2^24) and lets OpenCV's integral image do the sums
    diff = np.zeros((nt, nx + 1, nz + 1), np.float32)
    c, s = np.cos(thetas)[None, :], np.sin(thetas)[None, :]
    flat = lambda ti, xi, zi: (ti * (nx + 1) + xi) * (nz + 1) + zi  # noqa: E731
    for k in range(0, m, _BLOCK):  # blocks of matches keep the (matches, headings) arrays small
        r_, w_, rc_, wc_ = r[k:k + _BLOCK], w[k:k + _BLOCK], rc[k:k + _BLOCK], wc[k:k + _BLOCK]
        rr = pqt_rotate_xz(thetas, r_[:, None, :], validate=False)          # (matches, headings, 2)
        px, pz = w_[:, :1] - rr[..., 0], w_[:, 1:] - rr[..., 1]          # (p, q) aligning each match
        sxx, sxz, szz = rc_[:, 0, 0, None], rc_[:, 0, 1, None], rc_[:, 1, 1, None]
        var_x = wc_[:, 0, 0, None] + c * c * sxx - 2 * c * s * sxz + s * s * szz
        var_z = wc_[:, 1, 1, None] + s * s * sxx + 2 * c * s * sxz + c * c * szz
        hx, hz = spread * np.sqrt(var_x), spread * np.sqrt(var_z)
        x0 = np.clip(np.floor((px - hx - b[0]) / size), 0, nx).astype(int)
        x1 = np.clip(np.floor((px + hx - b[0]) / size) + 1, 0, nx).astype(int)
        z0 = np.clip(np.floor((pz - hz - b[2]) / size), 0, nz).astype(int)
        z1 = np.clip(np.floor((pz + hz - b[2]) / size) + 1, 0, nz).astype(int)
        t = np.broadcast_to(np.arange(nt)[None, :], x0.shape)
        ok = (x1 > x0) & (z1 > z0)
        t, x0, x1, z0, z1 = t[ok], x0[ok], x1[ok], z0[ok], z1[ok]
        idx = np.concatenate([flat(t, x0, z0), flat(t, x1, z1), flat(t, x0, z1), flat(t, x1, z0)])
        val = np.concatenate([np.ones(2 * t.size, np.float32), -np.ones(2 * t.size, np.float32)])
        np.add.at(diff.ravel(), idx, val)
    acc = np.empty((nt, nx, nz), np.int32)
    for i in range(nt):  # summed-area table of the difference array = rectangle votes
        acc[i] = cv2.integral(diff[i], sdepth=cv2.CV_32F)[1:nx + 1, 1:nz + 1]
    return acc, thetas


def _peaks(acc, n, radius=(2, 3, 3), block=(2, 4, 4)):
    """Top ``n`` bins of the accumulator, greedily suppressing neighbours (heading wraps).

    The maxima of small blocks are ranked first, so only a small array is partially sorted.
    """
    shape = [int(np.ceil(a / k)) * k for a, k in zip(acc.shape, block)]
    padded = acc
    if list(acc.shape) != shape:
        padded = np.zeros(shape, acc.dtype)
        padded[: acc.shape[0], : acc.shape[1], : acc.shape[2]] = acc
    # block maxima as element-wise maxima of strided views (numpy reduces tiny axes slowly)
    best = padded
    for axis, k in enumerate(block):
        views = [best[tuple(slice(i, None, k) if a == axis else slice(None) for a in range(3))] for i in range(k)]
        best = np.maximum.reduce(views)
    flat = best.ravel()
    top = min(flat.size, 20 * n)
    cand = np.argpartition(-flat, top - 1)[:top]
    cand = cand[np.argsort(-flat[cand], kind="stable")]
    cand = cand[flat[cand] > 0]
    bt, bx, bz = np.unravel_index(cand, best.shape)
    t, x, z = np.empty(cand.size, int), np.empty(cand.size, int), np.empty(cand.size, int)
    for i in range(cand.size):
        t0, x0, z0 = bt[i] * block[0], bx[i] * block[1], bz[i] * block[2]
        cell = padded[t0:t0 + block[0], x0:x0 + block[1], z0:z0 + block[2]]
        dt, dx, dz = np.unravel_index(int(cell.argmax()), cell.shape)
        t[i], x[i], z[i] = t0 + dt, x0 + dx, z0 + dz
    chosen: list[int] = []
    for i in range(cand.size):
        close = False
        for j in chosen:
            dt = abs(t[i] - t[j])
            dt = min(dt, acc.shape[0] - dt)
            if dt <= radius[0] and abs(x[i] - x[j]) <= radius[1] and abs(z[i] - z[j]) <= radius[2]:
                close = True
                break
        if not close:
            chosen.append(i)
            if len(chosen) == n:
                break
    return t[chosen], x[chosen], z[chosen], flat[cand[chosen]]


def _refine(pqt, pts, world, fi, li, gates, pts_cov, world_cov):
    """Iterated least squares: keep each feature's best match within the gate, refit (weighted)."""
    h = None
    for gate in gates:
        e = world[li][:, ::2] - pqt_transform_xz(pqt, pts[fi][:, ::2], validate=False)
        d = np.hypot(e[:, 0], e[:, 1])
        order = np.lexsort((d, fi))
        first = order[np.r_[True, fi[order][1:] != fi[order][:-1]]]
        keep = first[d[first] <= gate]
        if keep.size < 2 or np.ptp(pts[fi[keep]][:, [0, 2]], axis=0).max() < 1e-3:
            return h
        pqt, cov, rms = fit_pose(pts[fi[keep]], world[li[keep]], pts_cov[fi[keep]], world_cov[li[keep]])
        h = (pqt, cov, fi[keep], li[keep], rms)
    return h


def global_localize(points, covariances, descriptors, landmarks: LandmarkMap, *, bounds=None,
                    bin_size: float = 0.04, angle_bin: float = np.deg2rad(2.0), spread: float = 2.8,
                    n_hypotheses: int = 10, k: int = 3, max_distance: float = 0.5, height_tol: float = 0.2,
                    gates=(0.5, 0.25, 0.12, 0.08), min_matches: int = 5) -> tuple[Hypothesis, list[Hypothesis]]:
    """Localise the robot in the map without any prior pose (the kidnapped robot).

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Current stereo features in the robot frame.
    covariances : array_like, shape (N, 3, 3)
        Their covariances (Se et al. Sec. 3.1).
    descriptors : array_like, shape (N, D)
        Their local image vectors (Se et al. Sec. 4).
    landmarks : LandmarkMap
        The database map.
    bounds : array_like, shape (4,), optional
        Search space ``(x_min, x_max, z_min, z_max)``; default: the landmarks' extent plus 0.5 m.
    bin_size, angle_bin, spread
        Hough bins (4 cm, 2 degrees) and vote spread (2.8 sigma), Se et al. Sec. 5-6.
    n_hypotheses : int, default 10
        Top N bins refined (Se et al. use N = 10).
    k, max_distance, height_tol
        Candidate matching, see :func:`candidate_matches`.
    gates : sequence of float
        Match gates (metres) of the successive least-squares iterations; each iteration is weighted
        by the feature and landmark covariances (:func:`robokit.localization.egomotion.fit_pose`).
    min_matches : int, default 5
        The winner must explain at least this many matches.

    Returns
    -------
    best : Hypothesis
        Most matches, then lowest residual.
    hypotheses : list of Hypothesis
        All refined hypotheses, best first.

    Raises
    ------
    InsufficientMatchesError
        If there are fewer than two potential matches or no hypothesis explains ``min_matches``.

    Notes
    -----
    Se, Lowe & Little, Sec. 5 (steps 1-6).
    """
    pts = as_array(points, "points", shape=(None, 3))
    cov = as_array(covariances, "covariances", shape=(pts.shape[0], 3, 3))
    n_hypotheses = as_int(n_hypotheses, "n_hypotheses", minimum=1)
    min_matches = as_int(min_matches, "min_matches", minimum=2)
    gates = as_array(gates, "gates", ndim=1, min_size=1)
    if not isinstance(landmarks, LandmarkMap):
        raise TypeError(f"landmarks: expected LandmarkMap, got {type(landmarks).__name__}")
    fi, li = candidate_matches(pts, descriptors, landmarks, k=k, max_distance=max_distance, height_tol=height_tol)
    if fi.size < 2:
        raise InsufficientMatchesError(f"points, descriptors: only {fi.size} potential matches with the map "
                                       "(need at least 2)")
    world = landmarks.positions
    if bounds is None:
        lo, hi = world[:, [0, 2]].min(0) - 0.5, world[:, [0, 2]].max(0) + 0.5
        bounds = (lo[0], hi[0], lo[1], hi[1])
    b = as_array(bounds, "bounds", shape=(4,))
    xz = [0, 2]
    acc, thetas = hough_accumulator(pts[fi][:, xz], cov[fi][:, xz][:, :, xz], world[li][:, xz],
                                    landmarks.covariances[li][:, xz][:, :, xz], b, bin_size=bin_size,
                                    angle_bin=angle_bin, spread=spread)
    hyps = []
    for t, x, z, votes in zip(*_peaks(acc, n_hypotheses)):
        start = np.array([b[0] + (x + 0.5) * bin_size, b[2] + (z + 0.5) * bin_size, thetas[t]])
        h = _refine(start, pts, world, fi, li, gates, cov, landmarks.covariances)
        if h is not None:
            hyps.append(Hypothesis(h[0], h[1], int(votes), h[2], h[3], float(h[4])))
    hyps.sort(key=lambda h: (-h.n_matches, h.rms))
    if not hyps or hyps[0].n_matches < min_matches:
        got = hyps[0].n_matches if hyps else 0
        raise InsufficientMatchesError(f"points, descriptors: the best pose explains {got} matches "
                                       f"(need {min_matches})")
    return hyps[0], hyps
