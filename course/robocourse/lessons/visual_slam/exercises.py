"""Exercises of assignment 01 (stereo visual SLAM with PLOT and SIFT features).

From one formula of Lin et al.'s PLOT detector to one voting step of Se, Lowe & Little's Hough
transform. Inputs are plain data generated from the seed; the answers are robokit's library
functions (thin wrappers below only turn robokit objects into plain data and back).

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
from robokit.localization.egomotion import pose_from_two, ransac_pose, ransac_sample_count
from robokit.localization.hough import hough_accumulator
from robokit.mapping.landmarks import kalman_fuse
from robokit.vision.matching import ratio_match
from robokit.vision.plot_detector import junction_strength
from robokit.vision.stereo import StereoCalibration, disparity_to_point, triangulate_svd
from robokit.validation import as_array, as_rng
from robocourse.exercises.compare import close, exact, unordered_rows
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


def hough_votes(robot_xz, robot_cov_xz, world_xz, world_cov_xz, bounds, bin_size, angle_bin) -> np.ndarray:
    """Vote array ``(T, NX, NZ)`` of Se et al.'s Hough transform (votes over +-2.8 sigma).

    Plain-data wrapper of :func:`robokit.localization.hough_accumulator` returning only the
    accumulator (Se et al. Sec. 5, steps 2-3).

    Raises
    ------
    ValueError
        For mismatched shapes or empty bounds.
    """
    return hough_accumulator(robot_xz, robot_cov_xz, world_xz, world_cov_xz, bounds, bin_size=bin_size,
                             angle_bin=angle_bin)[0]


def robust_pose(robot_points, world_points) -> np.ndarray:
    """The robot pose ``[p, q, theta]`` from tentative matches of which many may be wrong (the open exercise).

    The expected answer: :func:`robokit.localization.ransac_pose` (two-point hypotheses, support
    within 10 cm, least-squares refit on the support; Lin et al. Sec. 5-6) with a fixed seed and
    no minimum support beyond two matches.

    Parameters
    ----------
    robot_points, world_points : array_like, shape (N, 3)
        Feature ``k`` in the robot frame (X right, Y up, Z forward) and the landmark it was matched
        to in the world frame; ``N >= 2``.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``[p, q, theta]`` with ``(X, Z)_world = R(theta) (X', Z')_robot + (p, q)`` and theta in
        ``[-pi, pi)`` (the grader compares headings modulo 2 pi).

    Raises
    ------
    ValueError
        For shapes other than two equal ``(N, 3)`` arrays, fewer than two matches or non-finite values.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> robot = rng.uniform([-2.0, -0.5, 1.0], [2.0, 0.5, 5.0], (30, 3))
    >>> world = pqt_robot_to_world(robot, [1.0, 2.0, 0.3])
    >>> world[:12] = rng.uniform(0.0, 8.0, (12, 3))          # 12 of the 30 matches are wrong
    >>> print(np.round(robust_pose(robot, world), 6))
    [1.  2.  0.3]
    """
    r = as_array(robot_points, "robot_points", shape=(None, 3))
    w = as_array(world_points, "world_points", shape=(r.shape[0], 3))
    if r.shape[0] < 2:
        raise ValueError(f"robot_points: expected at least 2 matches, got {r.shape[0]}")
    return ransac_pose(r, w, min_matches=2, rng=0).pqt


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
    query = train[[2, 5, 7, 9]] + rng.normal(scale=0.05, size=(4, 8))
    query = np.vstack([query, rng.normal(size=(3, 8))])
    return [
        Case((query.tolist(), train.tolist()), label="four true matches among seven queries"),
        Case((query.tolist(), train.tolist(), 0.9), label="looser ratio 0.9"),
        Case((query[:2].tolist(), train[:1].tolist()), label="one train row: no ratio, no matches"),
        Case((query.tolist(), train[:, :4].tolist()), raises="ValueError", label="descriptor lengths differ"),
        Case((query.tolist(), train.tolist(), 1.5), raises="ValueError", label="ratio above 1"),
    ]


def _rig_projections(focal, c0, r0, baseline):
    return StereoCalibration(focal=focal, c0=c0, r0=r0, baseline=baseline).projection_matrices()


def _triangulate_cases(rng: np.random.Generator) -> list[Case]:
    pl, pr = _rig_projections(500.0, 320.0, 240.0, 0.12)
    pts = rng.uniform([-1.0, -0.5, 1.0], [1.0, 0.5, 6.0], size=(5, 3))
    hom = np.column_stack([pts, np.ones(5)])
    ul, ur = hom @ pl.T, hom @ pr.T
    ul, ur = ul[:, :2] / ul[:, 2:], ur[:, :2] / ur[:, 2:]
    noisy = ul + rng.normal(scale=0.5, size=ul.shape)
    return [
        Case((pl.tolist(), pr.tolist(), ul.tolist(), ur.tolist()), label="exact projections of five points"),
        Case((pl.tolist(), pr.tolist(), noisy.tolist(), ur.tolist()), label="noisy left pixels"),
        Case((pl.tolist(), pr.tolist(), ul[:1].tolist(), ur[:1].tolist()), label="a single point"),
        Case((pl[:2].tolist(), pr.tolist(), ul.tolist(), ur.tolist()), raises="ValueError",
             label="2 x 4 projection matrix"),
    ]


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


def _fuse_cases(rng: np.random.Generator) -> list[Case]:
    s, r = rng.normal(size=(2, 3)), rng.normal(size=(2, 3))
    cov, cov_new = _spd(rng, 2, 0.1), _spd(rng, 2, 0.2)
    return [
        Case(([0.0, 0.0, 1.0], np.eye(3).tolist(), [0.0, 0.0, 3.0], np.eye(3).tolist()),
             label="equal covariances: the midpoint, half the covariance"),
        Case((s[0].tolist(), cov[0].tolist(), r[0].tolist(), cov_new[0].tolist()), label="one random landmark"),
        Case((s.tolist(), cov.tolist(), r.tolist(), cov_new.tolist()), label="two landmarks at once"),
        Case(([0.0, 0.0, 1.0], [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]], [0.0, 0.0, 2.0],
              np.eye(3).tolist()), raises="ValueError", label="covariance not positive definite"),
    ]


def hough_cases(rng: np.random.Generator) -> list[Case]:
    bounds = [0.0, 0.4, 0.0, 0.4]
    robot = rng.uniform([-1, 1], [1, 3], size=(3, 2))
    pose = np.array([0.2, 0.2, 0.3])
    c, s = np.cos(pose[2]), np.sin(pose[2])
    world = robot @ np.array([[c, -s], [s, c]]).T + pose[:2]
    rcov = np.tile(np.diag([0.02 ** 2, 0.05 ** 2]), (3, 1, 1))
    wcov = np.tile(np.eye(2) * 0.01 ** 2, (3, 1, 1))
    return [
        Case(([[0.0, 1.0]], [(np.eye(2) * 1e-4).tolist()], [[0.2, 1.2]], [(np.eye(2) * 1e-4).tolist()], bounds,
              0.04, float(np.deg2rad(30.0))),
             label="one match, sharp covariances"),
        Case((robot.tolist(), rcov.tolist(), world.tolist(), wcov.tolist(), bounds, 0.04, float(np.deg2rad(10.0))),
             label="three matches agreeing on one pose"),
        Case((robot.tolist(), rcov.tolist(), world.tolist(), wcov.tolist(), [0.4, 0.0, 0.0, 0.4], 0.04,
              float(np.deg2rad(10.0))), raises="ValueError", label="empty bounds (x_max < x_min)"),
    ]


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
        points=2, cases=_ratio_cases, answer=match_ratio, compare=unordered_rows(atol=0),
        kind="transcription",
        description="Pairs [query_row, train_row] whose nearest / second-nearest Euclidean distance ratio is below "
                    "`ratio` (Lin et al. Sec. 3); (0, 2) when train has fewer than two rows; ValueError for "
                    "different descriptor lengths or a ratio outside (0, 1]."),
    Exercise(
        id="01.triangulate_svd", function="triangulate_svd",
        signature="triangulate_svd(p_left: (3, 4), p_right: (3, 4), uv_left: (N, 2), uv_right: (N, 2)) -> (N, 3)",
        points=2, cases=_triangulate_cases, answer=triangulate_svd, compare=close(rtol=1e-6, atol=1e-7),
        kind="transcription",
        description="Linear triangulation: the right singular vector of the 4 x 4 system (Lin et al. Sec. 3); "
                    "ValueError for wrong shapes."),
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
        cases=_fuse_cases, answer=kalman_fuse, compare=close(rtol=1e-6, atol=1e-9),
        kind="transcription",
        description="Information-form fusion Sigma' = (Sigma^-1 + Sigma_new^-1)^-1, "
                    "s' = Sigma' (Sigma^-1 s + Sigma_new^-1 r_new) for one (3,) or N (N, 3) landmarks (Se et al. "
                    "Sec. 3.5); ValueError for covariances that are not symmetric positive definite."),
    Exercise(
        id="01.hough_votes", function="hough_votes",
        signature="hough_votes(robot_xz, robot_cov_xz, world_xz, world_cov_xz, bounds, bin_size, angle_bin) "
                  "-> numpy.ndarray (T, NX, NZ) of int",
        points=3, cases=hough_cases, answer=hough_votes, compare=close(rtol=0, atol=0),
        kind="transcription",
        description="For each heading bin centre, each match votes for every (X, Z) bin within +-2.8 sigma of the "
                    "position (X, Z) - R(theta) (X', Z') (Se et al. Sec. 5); see the notebook for the bin layout; "
                    "ValueError for empty bounds."),
    Exercise(
        id="01.robust_pose", function="robust_pose",
        signature="robust_pose(robot_points: (N, 3), world_points: (N, 3)) -> numpy.ndarray [p, q, theta]",
        points=3, cases=_robust_pose_cases, answer=robust_pose, compare=_same_pose,
        kind="open",
        description="Open: any method. The pose [p, q, theta] (theta in [-pi, pi); headings are compared modulo "
                    "2 pi) that explains the true matches, within 2 cm and 0.02 rad, when 20 to 60 % of the matches "
                    "are wrong; ValueError for fewer than two matches or unequal shapes."),
]
