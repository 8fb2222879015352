"""Exercises of assignment 01 (stereo visual SLAM with PLOT and SIFT features).

From one formula of Lin et al.'s PLOT detector to the stereo front end's loop over a stretch of
the lesson's lab lap. Inputs are plain data generated from the seed; the answers are robokit's
library functions (thin wrappers below only turn robokit objects into plain data and back). The
derivations (triangulation, fusion, the Hough vote's centre and spread) are judged with feedback
that names the wrong part: their cases carry their inputs in ``Case.expected`` so that the
comparison can reproject or re-derive the usual slips. The loop's cases are runs of
:mod:`.odometry` and carry the simulator's true poses.

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (question 1 of the course's assignment; our copy gives no venue or year).
.. [2] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002.
"""
from __future__ import annotations

import numpy as np

from robokit.geometry import pqt_robot_to_world, wrap_angle
from robokit.localization.egomotion import pose_from_two, ransac_sample_count
from robokit.mapping.landmarks import kalman_fuse
from robokit.vision.matching import ratio_match
from robokit.vision.plot_detector import junction_strength
from robokit.vision.stereo import StereoCalibration, disparity_to_point, triangulate_svd
from robokit.validation import as_array, as_rng
from robocourse.exercises.compare import close, exact, unordered_rows
from robocourse.exercises.plain import summarize
from robocourse.lessons.visual_slam.odometry_loop import (LOOP_SHORTCUTS, odometry_cases, on_track, robust_pose,
                                                          stereo_odometry)
from robocourse.exercises.plain import numeric_array
from robocourse.exercises.spec import Case, Exercise

ASSIGNMENT = "01_visual_slam"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"01.reduced_descriptor": 2, "01.depth_uncertainty": 2, "01.overconfident_fusion": 2}


def match_ratio(query, train, ratio: float = 0.65) -> np.ndarray:
    """Nearest-neighbour ratio matches as an (M, 2) integer array of ``[query_row, train_row]``.

    Plain-data wrapper of :func:`robokit.vision.ratio_match` (Lin et al. Sec. 3; Lowe 2004,
    Sec. 7.1).

    Raises
    ------
    ValueError
        For a ratio outside (0, 1] or descriptors of different lengths.
    """
    m = ratio_match(query, train, ratio=ratio)
    return np.column_stack([m.query, m.train]).astype(int).reshape(-1, 2)


def stereo_point(c, r, d, focal, c0, r0, baseline) -> tuple[np.ndarray, np.ndarray]:
    """3-D points ``(N, 3)`` and covariances ``(N, 3, 3)`` from pixels and disparities (1 px sigmas).

    Plain-data wrapper of :func:`robokit.vision.disparity_to_point` with a
    :class:`robokit.vision.StereoCalibration` built from ``focal, c0, r0, baseline`` (Se et al. Sec. 3.1).

    Raises
    ------
    ValueError
        For non-positive disparities, focal length or baseline, or arrays of different lengths.
    """
    return disparity_to_point(c, r, d, StereoCalibration(focal=focal, c0=c0, r0=r0, baseline=baseline))


def hough_candidates(robot_xz, robot_cov_xz, world_xz, world_cov_xz, thetas) -> tuple[np.ndarray, np.ndarray]:
    """The robot positions each potential match votes for, one per heading, with their covariances.

    For heading ``theta`` the pose model ``(X, Z) = R(theta) (X', Z') + (p, q)`` puts the robot at
    ``(p, q) = (X, Z) - R(theta) (X', Z')``; with independent errors of covariance ``S`` (feature)
    and ``W`` (landmark), to first order ``cov(p, q) = W + R(theta) S R(theta)^T`` (Se et al. Sec. 5,
    steps 2-3: the centre and the extent of each vote of the Hough transform).

    Parameters
    ----------
    robot_xz, world_xz : array_like, shape (M, 2)
        Feature ``(X', Z')`` in the robot frame and landmark ``(X, Z)`` in the world.
    robot_cov_xz, world_cov_xz : array_like, shape (M, 2, 2)
        Their covariances.
    thetas : array_like, shape (T,)
        Headings (radians).

    Returns
    -------
    positions : numpy.ndarray, shape (T, M, 2)
    covariances : numpy.ndarray, shape (T, M, 2, 2)

    Raises
    ------
    ValueError
        For arrays whose shapes do not fit together, or non-finite values.

    Examples
    --------
    >>> pos, cov = hough_candidates([[0.0, 1.0]], [np.eye(2) * 0.01], [[2.0, 3.0]], [np.eye(2) * 0.04],
    ...                             [0.0, np.pi / 2])
    >>> print(pos.round(6).tolist(), cov[1, 0].round(6).tolist())
    [[[2.0, 2.0]], [[3.0, 3.0]]] [[0.05, 0.0], [0.0, 0.05]]
    """
    r = as_array(robot_xz, "robot_xz", shape=(None, 2))
    m = r.shape[0]
    rc = as_array(robot_cov_xz, "robot_cov_xz", shape=(m, 2, 2))
    w = as_array(world_xz, "world_xz", shape=(m, 2))
    wc = as_array(world_cov_xz, "world_cov_xz", shape=(m, 2, 2))
    t = as_array(thetas, "thetas", ndim=1)
    c, s_ = np.cos(t), np.sin(t)
    rot = np.stack([np.stack([c, -s_], -1), np.stack([s_, c], -1)], -2)           # (T, 2, 2)
    positions = w[None] - np.einsum("tij,mj->tmi", rot, r)
    covariances = wc[None] + np.einsum("tij,mjk,tlk->tmil", rot, rc, rot)
    return positions, covariances


def _spd(rng, n, scale):
    a = rng.normal(size=(n, 3, 3)) * scale
    return a @ np.swapaxes(a, 1, 2) + np.eye(3) * scale ** 2


def _junction_cases(rng: np.random.Generator) -> list[Case]:
    a = rng.normal(size=(4, 5, 2, 2))
    field = a @ np.swapaxes(a, -1, -2)
    return [
        Case(([[1.0, 0.0], [0.0, 1.0]],), label="isotropic tensor: a perfect junction"),
        Case(([[4.0, 0.0], [0.0, 0.0]],), label="an ideal edge: no junction strength"),
        Case((field.tolist(),), label="a 4 x 5 field of random symmetric tensors"),
        Case(([[1.0, 2.0, 3.0]],), raises="ValueError", label="not 2 x 2"),
    ]


def _ratio_cases(rng: np.random.Generator) -> list[Case]:
    train = rng.normal(size=(12, 8))
    query = train[rng.choice(12, 4, replace=False)] + rng.normal(scale=0.05, size=(4, 8))
    query = np.vstack([query, rng.normal(size=(3, 8))])[rng.permutation(7)]    # true matches anywhere
    return [
        Case((query.tolist(), train.tolist()), label="four true matches among seven queries"),
        Case((query.tolist(), train.tolist(), 0.9), label="looser ratio 0.9"),
        Case((query[:2].tolist(), train[:1].tolist()), label="one train row: no ratio, no matches"),
        Case((query.tolist(), train[:, :4].tolist()), raises="ValueError", label="descriptor lengths differ"),
        Case((query.tolist(), train.tolist(), 1.5), raises="ValueError", label="ratio above 1"),
    ]


def _rig_projections(focal, c0, r0, baseline):
    return StereoCalibration(focal=focal, c0=c0, r0=r0, baseline=baseline).projection_matrices()


def _camera_matrix(focal, c0, r0, yaw, centre):
    """``K [R | -R C]`` of a camera at ``centre`` (robot frame: X right, Y down in the image, Z
    forward) turned by ``yaw`` about the vertical axis; image rows grow downwards, so ``v = r0 - f Y / Z``."""
    k = np.array([[focal, 0.0, c0], [0.0, -focal, r0], [0.0, 0.0, 1.0]])
    c, s = np.cos(yaw), np.sin(yaw)
    rot = np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])
    return k @ np.hstack([rot, -rot @ np.reshape(centre, (3, 1))])


def _project(p, pts):
    hom = np.column_stack([pts, np.ones(len(pts))]) @ np.asarray(p, float).T
    with np.errstate(divide="ignore", invalid="ignore"):
        return hom[:, :2] / hom[:, 2:]


#: The pixels' noise (px) of the noisy triangulation cases, and how much worse (px, RMS over the
#: four coordinates) than the reference's least-squares point a student's point may reproject.
TRIANGULATION = {"pixel_noise": 0.5, "slack_px": 0.02}


def _triangulation_case(pl, pr, pts, rng, noise, label) -> Case:
    ul, ur = _project(pl, pts), _project(pr, pts)
    if noise:
        ul, ur = ul + rng.normal(0.0, noise, ul.shape), ur + rng.normal(0.0, noise, ur.shape)
    ul, ur = ul.round(4), ur.round(4)
    args = (np.round(pl, 9).tolist(), np.round(pr, 9).tolist(), ul.tolist(), ur.tolist())
    return Case(args, label=label, expected={"points": triangulate_svd(*args).tolist(), "p_left": args[0],
                                             "p_right": args[1], "uv_left": args[2], "uv_right": args[3]})


def _triangulate_cases(rng: np.random.Generator) -> list[Case]:
    pl, pr = _rig_projections(500.0, 320.0, 240.0, 0.12)
    pts = rng.uniform([-1.0, -0.5, 1.0], [1.0, 0.5, 6.0], size=(5, 3))
    verged_l = _camera_matrix(620.0, 330.0, 250.0, 0.05, [0.0, 0.0, 0.0])
    verged_r = _camera_matrix(580.0, 310.0, 235.0, -0.05, [0.3, 0.02, 0.0])
    top = _camera_matrix(500.0, 320.0, 240.0, 0.0, [0.0, 0.12, 0.0])          # the Triclops' vertical pair
    noise = TRIANGULATION["pixel_noise"]
    return [
        _triangulation_case(pl, pr, pts, rng, 0.0, "the lesson's rig, exact projections of five points"),
        _triangulation_case(pl, pr, pts, rng, noise, f"the lesson's rig, {noise} px noise in all four coordinates"),
        _triangulation_case(verged_l, verged_r, pts[:3], rng, noise,
                            "two cameras turned towards each other, different focal lengths, noisy"),
        _triangulation_case(pl, top, pts, rng, noise, "a vertical baseline (the Triclops' left and top cameras), noisy"),
        _triangulation_case(pl, pr, pts[:1], rng, 0.0, "a single point"),
        Case((pl[:2].tolist(), pr.tolist(), [[1.0, 2.0]], [[1.0, 2.0]]), raises="ValueError",
             label="2 x 4 projection matrix"),
        Case((pl.tolist(), pr.tolist(), [[1.0, 2.0], [3.0, 4.0]], [[1.0, 2.0]]), raises="ValueError",
             label="two left pixels, one right"),
    ]


def _disparity_shortcut(p_left, p_right, uv_left, uv_right):
    """Exercise 4's formulas with f, c0, r0 and the baseline read off the matrices, as if the pair were
    rectified and horizontal: right on the lesson's rig, wrong on a verged or a vertical pair."""
    pl, pr = np.asarray(p_left, float), np.asarray(p_right, float)
    ul, ur = np.asarray(uv_left, float), np.asarray(uv_right, float)
    focal, c0, r0, base = pl[0, 0], pl[0, 2], pl[1, 2], -pr[0, 3] / pr[0, 0]
    d = ul[:, 0] - ur[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):       # a vertical pair has no horizontal disparity
        return np.column_stack([(ul[:, 0] - c0) * base / d, (r0 - ul[:, 1]) * base / d, focal * base / d])


#: Ways to pass triangulation cases without deriving the method, by name.
TRIANGULATION_SHORTCUTS = {"Exercise 4's disparity formulas (a rectified horizontal pair assumed)": _disparity_shortcut}


_COORDINATES = ("the left camera's u", "the left camera's v", "the right camera's u", "the right camera's v")


def _reprojects(expected, got) -> str | None:
    """Accept points that reproject into both cameras as well as the least-squares (reference)
    points, within ``TRIANGULATION["slack_px"]``; say which point and which coordinate is off."""
    g = numeric_array(got)
    ref = np.asarray(expected["points"], float)
    if g is None or g.dtype.kind not in "iuf":
        return f"expected an (N, 3) array of numbers, got {summarize(got)}"
    if g.shape == (len(ref), 4):
        return "expected (N, 3) Euclidean points, got (N, 4): divide by the homogeneous coordinate"
    if g.shape != ref.shape:
        return f"expected shape {ref.shape}, got {g.shape}"
    g = g.astype(float)
    if not np.all(np.isfinite(g)):
        return "expected finite points, got NaN or inf"
    pl, pr = np.asarray(expected["p_left"], float), np.asarray(expected["p_right"], float)
    seen = np.hstack([expected["uv_left"], expected["uv_right"]])

    def residuals(pts):
        return np.hstack([_project(pl, pts), _project(pr, pts)]) - seen

    ours, yours = residuals(ref), residuals(g)
    depth = np.column_stack([np.column_stack([g, np.ones(len(g))]) @ p[2] for p in (pl, pr)])
    if np.any(depth <= 0):
        i = int(np.argmax(np.any(depth <= 0, axis=1)))
        return (f"point {i} ({g[i].round(4).tolist()}) lies behind a camera (P^3 x <= 0 there), but both "
                "cameras saw it: a point that reprojects onto its pixels must lie in front of both")
    rms_ref, rms = np.sqrt((ours ** 2).mean(1)), np.sqrt((yours ** 2).mean(1))
    bad = rms > rms_ref + TRIANGULATION["slack_px"] + 1e-6 * rms_ref
    if not bad.any():
        return None
    i = int(np.argmax(rms - rms_ref))
    k = int(np.argmax(np.abs(yours[i])))
    return (f"{int(bad.sum())} of {len(g)} points reproject worse than the least-squares point: point {i} "
            f"({g[i].round(4).tolist()}) lands {np.abs(yours[i]).max():.3g} px off in {_COORDINATES[k]} "
            f"(residuals left u, v, right u, v: {yours[i].round(3).tolist()}; the best point's: "
            f"{ours[i].round(3).tolist()})")


def _stereo_cases(rng: np.random.Generator) -> list[Case]:
    c, r = rng.uniform(0, 640, 4), rng.uniform(0, 480, 4)
    d = rng.uniform(5, 60, 4)
    return [
        Case(([320.0], [240.0], [10.0], 500.0, 320.0, 240.0, 0.1), label="on the optical axis, Z = 5 m"),
        Case((c.tolist(), r.tolist(), d.tolist(), 500.0, 320.0, 240.0, 0.12), label="four random features"),
        Case(([100.0], [50.0], [0.0], 500.0, 320.0, 240.0, 0.12), raises="ValueError", label="zero disparity"),
        Case(([100.0, 2.0], [50.0], [4.0], 500.0, 320.0, 240.0, 0.12), raises="ValueError",
             label="arrays of different lengths"),
    ]


def _sample_count_cases(rng: np.random.Generator) -> list[Case]:
    eps = rng.uniform(0.1, 0.8, 2)
    return [
        Case((0.5,), label="half the matches wrong, pairs, P = 0.99"),
        Case((0.0,), label="no outliers: one sample"),
        Case((float(eps[0]), 2, 0.999), label="random contamination, P = 0.999"),
        Case((float(eps[1]), 3, 0.95), label="random contamination, triples"),
        Case((1.0,), raises="ValueError", label="every match wrong"),
        Case((0.3, 2, 1.0), raises="ValueError", label="confidence 1"),
    ]


def _two_point_cases(rng: np.random.Generator) -> list[Case]:
    out = []
    for _ in range(3):
        pose = rng.uniform([-3, -3, -np.pi], [3, 3, np.pi])
        r = rng.uniform([-2, -0.5, 1], [2, 0.5, 6], size=(2, 3))
        c, s = np.cos(pose[2]), np.sin(pose[2])
        w = r.copy()
        w[:, 0] = c * r[:, 0] - s * r[:, 2] + pose[0]
        w[:, 2] = s * r[:, 0] + c * r[:, 2] + pose[1]
        out.append(Case((r.tolist(), w.tolist()), label="two exact correspondences"))
    same = [[1.0, 0.0, 2.0], [1.0, 0.5, 2.0]]
    return [
        Case(([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0]], [[2.0, 0.0, 3.0], [3.0, 0.0, 3.0]]), label="pure translation"),
        *out,
        Case((same, [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0]]), raises="ValueError",
             label="robot points coincide on the ground plane"),
        Case(([[0.0, 0.0, 1.0]], [[2.0, 0.0, 3.0]]), raises="ValueError", label="only one correspondence"),
    ]


def _fuse_case(args, label) -> Case:
    mean, cov = kalman_fuse(*args)
    return Case(args, label=label, expected={"fused": [mean.tolist(), cov.tolist()], "s": args[0], "sigma": args[1],
                                             "r_new": args[2], "sigma_new": args[3]})


def _fuse_cases(rng: np.random.Generator) -> list[Case]:
    s, r = rng.normal(size=(2, 3)), rng.normal(size=(2, 3))
    cov, cov_new = _spd(rng, 2, 0.1), _spd(rng, 2, 0.2)
    ray = np.diag([0.01, 0.01, 0.3]) ** 2                     # a far landmark: long along the line of sight
    across = np.diag([0.3, 0.01, 0.01]) ** 2                  # seen from the side: long across
    return [
        _fuse_case(([0.0, 0.0, 1.0], np.eye(3).tolist(), [0.0, 0.0, 3.0], np.eye(3).tolist()),
                   "equal covariances"),
        _fuse_case((s[0].tolist(), cov[0].tolist(), r[0].tolist(), cov_new[0].tolist()), "one random landmark"),
        _fuse_case((s.tolist(), cov.tolist(), r.tolist(), cov_new.tolist()), "two landmarks at once"),
        _fuse_case(([0.0, 0.0, 4.0], ray.tolist(), [0.2, 0.0, 4.2], across.tolist()),
                   "two elongated ellipses at right angles: each fixes what the other cannot"),
        _fuse_case((s[1].tolist(), (cov[1] * 100).tolist(), r[1].tolist(), cov_new[1].tolist()),
                   "an old estimate far less certain than the new one"),
        Case(([0.0, 0.0, 1.0], [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]], [0.0, 0.0, 2.0],
              np.eye(3).tolist()), raises="ValueError", label="covariance not positive definite"),
    ]


def _fusion_mistakes(e) -> tuple[dict, dict]:
    """Wrong means and covariances a fusion is often derived as, by name (from a case's inputs)."""
    s, r = np.asarray(e["s"], float), np.asarray(e["r_new"], float)
    a, b = np.asarray(e["sigma"], float), np.asarray(e["sigma_new"], float)
    ia, ib = np.linalg.inv(a), np.linalg.inv(b)
    fused = np.linalg.inv(ia + ib)
    means = {"the plain average of the two estimates (each must be weighted by its information)": (s + r) / 2,
             "the weights swapped (each estimate weighted by the other's information: the less certain one "
             "pulls harder)": (fused @ (ib @ s[..., None] + ia @ r[..., None]))[..., 0],
             "the new observation alone": r, "the old estimate alone": s}
    covs = {"the sum of the covariances (that is the covariance of a difference, not of the fused "
            "estimate)": a + b,
            "the average of the covariances": (a + b) / 2,
            "the information Sigma^-1 + Sigma_new^-1 itself, not its inverse": ia + ib,
            "the product of the covariances": a @ b}
    return means, covs


def _numeric_pair(got, names: str) -> tuple | str:
    """A student's pair of arrays as two float arrays, or what is wrong with it (``names`` says what
    the pair holds, for the message)."""
    if not isinstance(got, (tuple, list)) or len(got) != 2:
        return f"expected a pair {names}, got {summarize(got)}"
    parts = [numeric_array(v) for v in got]
    if any(v is None or v.dtype.kind not in "iuf" for v in parts):
        return f"expected a pair of arrays of numbers {names}, got {summarize(got)}"
    return tuple(v.astype(float) for v in parts)


def _fused(expected, got) -> str | None:
    """Accept ``(s', Sigma')`` within 1e-6 relative; otherwise say which of the two is wrong and,
    where it matches a known slip, which."""
    want_mean, want_cov = (np.asarray(v, float) for v in expected["fused"])
    pair = _numeric_pair(got, "(s_fused, sigma_fused)")
    if isinstance(pair, str):
        return pair
    mean, cov = pair
    if mean.shape != want_mean.shape or cov.shape != want_cov.shape:
        return (f"expected s_fused of shape {want_mean.shape} and sigma_fused of shape {want_cov.shape}, got "
                f"{mean.shape} and {cov.shape}")
    same = lambda x, y: bool(np.allclose(x, y, rtol=1e-6, atol=1e-9))     # noqa: E731
    mean_ok, cov_ok = same(mean, want_mean), same(cov, want_cov)
    if mean_ok and cov_ok:
        return None
    means, covs = _fusion_mistakes(expected)
    notes = []
    if not cov_ok:
        slip = next((name for name, v in covs.items() if same(cov, v)), None)
        notes.append("the covariance Sigma' is wrong" + (f": it is {slip}" if slip else
                     f" (expected {summarize(want_cov.round(6).tolist())}, got {summarize(cov.round(6).tolist())})"))
    if not mean_ok:
        slip = next((name for name, v in means.items() if same(mean, v)), None)
        notes.append("the mean s' is wrong" + (f": it is {slip}" if slip else
                     f" (expected {want_mean.round(6).tolist()}, got {mean.round(6).tolist()})"))
    right = "the mean is right; " if mean_ok else "the covariance is right; " if cov_ok else ""
    return right + "; ".join(notes)


def _hough_case(args, label) -> Case:
    pos, cov = hough_candidates(*args)
    return Case(args, label=label, expected={"candidates": [pos.tolist(), cov.tolist()], "robot_xz": args[0],
                                             "robot_cov_xz": args[1], "world_xz": args[2], "world_cov_xz": args[3],
                                             "thetas": args[4]})


def hough_cases(rng: np.random.Generator) -> list[Case]:
    """Cases of ``01.hough_candidates``: matches that agree on one pose, and bad input."""
    robot = rng.uniform([-1, 1], [1, 3], size=(3, 2))
    pose = np.array([0.2, 0.2, 0.3])
    c, s = np.cos(pose[2]), np.sin(pose[2])
    world = robot @ np.array([[c, -s], [s, c]]).T + pose[:2]
    rcov = np.stack([np.diag([rng.uniform(0.01, 0.03), rng.uniform(0.05, 0.2)]) ** 2 for _ in range(3)])
    rcov[:, 0, 1] = rcov[:, 1, 0] = 0.3 * np.sqrt(rcov[:, 0, 0] * rcov[:, 1, 1])     # tilted ellipses
    wcov = np.stack([np.diag(rng.uniform(0.005, 0.02, 2)) ** 2 for _ in range(3)])
    thetas = (-np.pi + (np.arange(12) + 0.5) * 2 * np.pi / 12).round(9)
    return [
        _hough_case(([[0.0, 1.0]], [(np.eye(2) * 1e-4).tolist()], [[0.2, 1.2]], [(np.eye(2) * 1e-4).tolist()],
                     [0.0]), "one match, heading 0, round covariances"),
        _hough_case((robot.round(4).tolist(), rcov.tolist(), world.round(4).tolist(), wcov.tolist(),
                     [float(pose[2])]), "three matches at their true heading: one position"),
        _hough_case((robot.round(4).tolist(), rcov.tolist(), world.round(4).tolist(), wcov.tolist(),
                     thetas.tolist()), "three matches, twelve headings, elongated tilted feature ellipses"),
        Case((robot.tolist(), rcov.tolist(), world[:2].tolist(), wcov[:2].tolist(), [0.0]), raises="ValueError",
             label="three features but two landmarks"),
        Case((robot.tolist(), rcov[:, :1].tolist(), world.tolist(), wcov.tolist(), [0.0]), raises="ValueError",
             label="feature covariances not 2 x 2"),
    ]


def _hough_mistakes(e) -> tuple[dict, dict]:
    """Wrong vote centres and covariances, by name (from a case's inputs)."""
    r, w = np.asarray(e["robot_xz"], float), np.asarray(e["world_xz"], float)
    rc, wc = np.asarray(e["robot_cov_xz"], float), np.asarray(e["world_cov_xz"], float)
    t = np.asarray(e["thetas"], float)
    c, s = np.cos(t), np.sin(t)
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
    back = np.swapaxes(rot, 1, 2)
    turn = lambda m: np.einsum("tij,mj->tmi", m, r)                            # noqa: E731
    spread = lambda m: np.einsum("tij,mjk,tlk->tmil", m, rc, m)               # noqa: E731
    centres = {"R(theta) applied the wrong way round (R^T)": w[None] - turn(back),
               "the rotated feature added instead of subtracted": w[None] + turn(rot),
               "the sign of the whole vector flipped ((p, q) = R (X', Z') - (X, Z))": turn(rot) - w[None],
               "the feature not rotated at all": np.broadcast_to(w - r, (len(t),) + r.shape)}
    spreads = {"the landmark's covariance W missing": spread(rot),
               "the feature's covariance S missing": np.broadcast_to(wc, (len(t),) + wc.shape),
               "S added without rotating it (R S R^T is the covariance of R (X', Z'))":
                   np.broadcast_to(wc + rc, (len(t),) + wc.shape),
               "S rotated the wrong way (R^T S R)": wc[None] + spread(back),
               "S rotated once (R S) instead of on both sides": wc[None] + np.einsum("tij,mjk->tmik", rot, rc)}
    return centres, spreads


def _same_candidates(expected, got) -> str | None:
    """Accept the vote centres and covariances within 1e-6 relative; else name the part that is wrong."""
    want_pos, want_cov = (np.asarray(v, float) for v in expected["candidates"])
    pair = _numeric_pair(got, "(positions, covariances)")
    if isinstance(pair, str):
        return pair
    pos, cov = pair
    if pos.shape != want_pos.shape or cov.shape != want_cov.shape:
        return (f"expected positions of shape {want_pos.shape} (T, M, 2) and covariances of shape "
                f"{want_cov.shape} (T, M, 2, 2), got {pos.shape} and {cov.shape}")
    same = lambda x, y: bool(np.allclose(x, y, rtol=1e-6, atol=1e-9))     # noqa: E731
    pos_ok, cov_ok = same(pos, want_pos), same(cov, want_cov)
    if pos_ok and cov_ok:
        return None
    centres, spreads = _hough_mistakes(expected)
    notes = []
    if not pos_ok:
        slip = next((n for n, v in centres.items() if same(pos, v)), None)
        t, m = np.unravel_index(int(np.argmax(np.abs(pos - want_pos).max(-1))), pos.shape[:2])
        notes.append("the positions (p, q) are wrong" + (f": {slip}" if slip else
                     f" (heading {t}, match {m}: expected {want_pos[t, m].round(6).tolist()}, got "
                     f"{pos[t, m].round(6).tolist()})"))
    if not cov_ok:
        slip = next((n for n, v in spreads.items() if same(cov, v)), None)
        t, m = np.unravel_index(int(np.argmax(np.abs(cov - want_cov).max((-1, -2)))), cov.shape[:2])
        notes.append("the covariances are wrong" + (f": {slip}" if slip else
                     f" (heading {t}, match {m}: expected {want_cov[t, m].round(8).tolist()}, got "
                     f"{cov[t, m].round(8).tolist()})"))
    right = "the positions are right; " if pos_ok else "the covariances are right; " if cov_ok else ""
    return right + "; ".join(notes)


def robust_pose_problems(rng: np.random.Generator) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, float]]:
    """The open exercise's scenes: ``(robot_points, world_points, true_pqt, contamination)`` each.

    40 to 80 features 1-6 m ahead of the robot, their landmarks placed by the true pose (any
    heading in ``[-pi, pi)``) with 5 mm noise, then a share (20 to 60 %) of the matches made wrong
    by pointing them at landmarks of another part of the lab: other landmarks of the scene, moved
    2-4 m in one direction (a look-alike corner across the room, as a wrong descriptor match
    finds), plus 0.5 m of scatter. Every scene has wrong matches, and they pull one least-squares
    fit to all matches decimetres away, so that shortcut fails every scene.

    Parameters
    ----------
    rng : numpy.random.Generator

    Returns
    -------
    list of tuple
        Four scenes, contamination 0.2, 0.4, 0.5 and 0.6: robot points ``(N, 3)``, world points
        ``(N, 3)`` (both rounded to micrometres, as the cases hand them out), the true ``[p, q, theta]``
        and the share of wrong matches.

    Examples
    --------
    >>> r, w, truth, eps = robust_pose_problems(np.random.default_rng(0))[2]
    >>> r.shape == w.shape, eps
    (True, 0.5)
    """
    rng = as_rng(rng)
    out = []
    for eps in (0.2, 0.4, 0.5, 0.6):
        n = int(rng.integers(40, 81))
        truth = rng.uniform([0.0, 0.0, -np.pi], [10.0, 10.0, np.pi])
        robot = rng.uniform([-3.0, -1.0, 1.0], [3.0, 1.0, 6.0], (n, 3))
        world = pqt_robot_to_world(robot, truth) + rng.normal(0.0, 0.005, (n, 3))
        wrong = rng.choice(n, int(round(eps * n)), replace=False)
        heading = rng.uniform(-np.pi, np.pi)
        elsewhere = rng.uniform(2.0, 4.0) * np.array([np.cos(heading), 0.0, np.sin(heading)])
        world[wrong] = world[np.roll(wrong, 1)] + elsewhere + rng.normal(0.0, 0.5, (len(wrong), 3))
        out.append((robot.round(6), world.round(6), truth, eps))
    return out


def _same_pose(expected, got) -> str | None:
    """:func:`close` within 2 cm and 0.02 rad, the heading compared modulo 2 pi (the answer is a heading)."""
    g, e = numeric_array(got), numeric_array(expected)      # the one rule for what counts as numbers
    note = ""
    if g is not None and e is not None and g.dtype.kind in "iuf" and g.shape == (3,) == e.shape \
            and np.all(np.isfinite(g)):
        g, e = g.astype(float), e.astype(float)
        turned = e[2] + wrap_angle(g[2] - e[2])
        if turned != g[2]:
            note = f" (your heading {g[2]:.6g} read as {turned:.6g}: headings are compared modulo 2 pi)"
        g[2] = turned
        got = g.tolist() if isinstance(got, list) else g
    message = close(rtol=0, atol=0.02)(expected, got)
    return message and message + note


def _robust_pose_cases(rng: np.random.Generator) -> list[Case]:
    cases = [Case((r.tolist(), w.tolist()), label=f"{len(r)} matches, {eps:.0%} of them wrong")
             for r, w, _, eps in robust_pose_problems(rng)]
    return cases + [
        Case(([[0.0, 0.0, 1.0]], [[1.0, 0.0, 2.0]]), raises="ValueError", label="a single match"),
        Case(([[0.0, 0.0, 1.0], [1.0, 0.0, 2.0]], [[1.0, 0.0, 2.0]]), raises="ValueError",
             label="two features but one landmark"),
    ]


EXERCISES = [
    Exercise(
        id="01.junction_strength", function="junction_strength",
        signature="junction_strength(tensor: array (..., 2, 2)) -> numpy.ndarray (...)", points=1,
        cases=_junction_cases, answer=junction_strength, compare=close(rtol=1e-6, atol=1e-9),
        kind="warm-up",
        description="The smaller eigenvalue lambda_2 of each symmetric 2 x 2 tensor (Lin et al. Sec. 2.i); "
                    "ValueError unless the last two axes are 2 x 2."),
    Exercise(
        id="01.match_ratio", function="match_ratio",
        signature="match_ratio(query: (N, D), train: (M, D), ratio: float = 0.65) -> numpy.ndarray (K, 2) of int",
        points=1, cases=_ratio_cases, answer=match_ratio, compare=unordered_rows(atol=0),
        kind="warm-up",
        description="Pairs [query_row, train_row] whose nearest / second-nearest Euclidean distance ratio is below "
                    "`ratio` (Lin et al. Sec. 3); (0, 2) when train has fewer than two rows; ValueError for "
                    "different descriptor lengths or a ratio outside (0, 1]."),
    Exercise(
        id="01.triangulate_svd", function="triangulate_svd",
        signature="triangulate_svd(p_left: (3, 4), p_right: (3, 4), uv_left: (N, 2), uv_right: (N, 2)) -> (N, 3)",
        points=2, cases=_triangulate_cases, answer=triangulate_svd, compare=_reprojects,
        kind="derivation", shortcuts=TRIANGULATION_SHORTCUTS,
        description="Triangulation derived from the projection model u = P^1 x / P^3 x, v = P^2 x / P^3 x (Lin et "
                    "al. Sec. 3): points that reproject into both cameras as well as the least-squares point, on "
                    "the lesson's rig, a verged pair and a vertical baseline; ValueError for wrong shapes."),
    Exercise(
        id="01.stereo_point", function="stereo_point",
        signature="stereo_point(c, r, d, focal, c0, r0, baseline) -> (points (N, 3), covariances (N, 3, 3))",
        points=2, cases=_stereo_cases, answer=stereo_point, compare=close(rtol=1e-6, atol=1e-9),
        kind="derivation",
        description="X = (c - c0) I / d, Y = (r0 - r) I / d, Z = f I / d and the first-order covariance with "
                    "sigma_c = sigma_r = sigma_d = 1 px (Se et al. Sec. 3.1); ValueError for d <= 0 or "
                    "arrays of different lengths."),
    Exercise(
        id="01.ransac_sample_count", function="ransac_sample_count",
        signature="ransac_sample_count(contamination: float, sample_size: int = 2, confidence: float = 0.99) -> int",
        points=1, cases=_sample_count_cases, answer=ransac_sample_count, compare=exact(),
        kind="warm-up",
        description="Smallest m with 1 - (1 - (1 - eps)^p)^m >= P, at least 1 (Lin et al. Sec. 7); ValueError "
                    "for eps outside [0, 1) or P outside (0, 1)."),
    Exercise(
        id="01.pose_from_two", function="pose_from_two",
        signature="pose_from_two(robot_points: (2, 3), world_points: (2, 3)) -> numpy.ndarray [p, q, theta]",
        points=2, cases=_two_point_cases, answer=pose_from_two, compare=close(rtol=1e-6, atol=1e-9),
        kind="derivation",
        description="Heading from the direction between the two points on the ground plane (X, Z), translation "
                    "from the midpoints (Lin et al. Sec. 5); ValueError for coincident points or not 2 x 3."),
    Exercise(
        id="01.kalman_fuse", function="kalman_fuse",
        signature="kalman_fuse(s, sigma, r_new, sigma_new) -> (s_fused, sigma_fused)", points=2,
        cases=_fuse_cases, answer=kalman_fuse, compare=_fused,
        kind="derivation",
        description="The fusion of two independent Gaussian estimates of a landmark, derived from the product of "
                    "their densities (Se et al. Sec. 3.5), for one (3,) or N (N, 3) landmarks; feedback names the "
                    "wrong part (mean or covariance) and the slip; ValueError for covariances that are not "
                    "symmetric positive definite."),
    Exercise(
        id="01.hough_candidates", function="hough_candidates",
        signature="hough_candidates(robot_xz (M, 2), robot_cov_xz (M, 2, 2), world_xz (M, 2), world_cov_xz (M, 2, 2), "
                  "thetas (T,)) -> (positions (T, M, 2), covariances (T, M, 2, 2))",
        points=2, cases=hough_cases, answer=hough_candidates, compare=_same_candidates,
        kind="derivation",
        description="For each heading, the robot position each match votes for and its first-order covariance, "
                    "derived from the pose model and independent feature and landmark errors (Se et al. Sec. 5); "
                    "feedback names the wrong term; ValueError for shapes that do not fit."),
    Exercise(
        id="01.robust_pose", function="robust_pose",
        signature="robust_pose(robot_points: (N, 3), world_points: (N, 3)) -> numpy.ndarray [p, q, theta]",
        points=2, cases=_robust_pose_cases, answer=robust_pose, compare=_same_pose,
        kind="open",
        description="Open: any method. The pose [p, q, theta] (theta in [-pi, pi); headings are compared modulo "
                    "2 pi) that explains the true matches, within 2 cm and 0.02 rad, when 20 to 60 % of the matches "
                    "are wrong; ValueError for fewer than two matches or unequal shapes."),
    Exercise(
        id="01.stereo_odometry", function="stereo_odometry",
        signature="stereo_odometry(features: list of (N_k, 3), matches: list of (M_k, 2) int, start_pose: [p, q, theta]) "
                  "-> (K, 3) poses",
        points=3, cases=odometry_cases, answer=stereo_odometry, compare=on_track,
        kind="loop", shortcuts=LOOP_SHORTCUTS,
        description="Loop: the stereo front end over simulated stretches of the lesson's lab lap (stereo features "
                    "per frame, matches to the previous frame, 20-45 % wrong): chain robust frame-to-frame poses "
                    "from the start pose; every frame within 40 cm and 5 deg of the simulator's truth; ValueError "
                    "for match lists that do not fit the frames."),
]
