"""Assignment 01 exercises: registration and check() catching wrong answers (answers: test_exercises_references.py)."""
import numpy as np
import pytest

from robocourse.lessons.visual_slam import exercises as visual_slam
from robocourse.grading import check
from robocourse.grading.judge import expected_output
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes

EXERCISES = exercises_for("01_visual_slam")


def test_assignment_is_registered():
    assert visual_slam.ASSIGNMENT == "01_visual_slam"
    assert set(visual_slam.WRITTEN) == {"01.reduced_descriptor", "01.depth_uncertainty", "01.overconfident_fusion"}
    assert {e.id for e in EXERCISES} == {"01.junction_strength", "01.match_ratio", "01.triangulate_svd",
                                         "01.stereo_point", "01.ransac_sample_count", "01.pose_from_two",
                                         "01.kalman_fuse", "01.hough_candidates", "01.robust_pose",
                                         "01.stereo_odometry"}
    assert sum(e.points for e in EXERCISES) + sum(visual_slam.WRITTEN.values()) == 24


@pytest.mark.parametrize("exercise", EXERCISES, ids=lambda e: e.id)
def test_cases_depend_on_the_seed(exercise):
    assert exercise.make_cases(1) != exercise.make_cases(2)


def _exercise(ex_id):
    return next(e for e in EXERCISES if e.id == ex_id)


def _shift(value):
    """A small but real mistake in every number of the answer."""
    if isinstance(value, (tuple, list)):
        return type(value)(_shift(v) for v in value)
    arr = np.asarray(value)
    return arr + 1 if arr.dtype.kind in "iu" else arr.astype(float) + 1e-3


def _wrong(reference):
    return lambda *args, **kwargs: _shift(reference(*args, **kwargs))


def _least_squares_pose(robot_points, world_points):
    """The tempting shortcut for the open exercise: one least-squares fit to every match, wrong ones too."""
    r, w = np.asarray(robot_points, float)[:, [0, 2]], np.asarray(world_points, float)[:, [0, 2]]
    if r.shape != w.shape or len(r) < 2:
        raise ValueError("robot_points, world_points: expected equal (N, 3) arrays with N >= 2")
    rc, wc = r - r.mean(0), w - w.mean(0)
    theta = np.arctan2(np.sum(rc[:, 0] * wc[:, 1] - rc[:, 1] * wc[:, 0]), np.sum(rc * wc))
    c, s = np.cos(theta), np.sin(theta)
    p, q = w.mean(0) - np.array([[c, -s], [s, c]]) @ r.mean(0)
    return np.array([p, q, theta])


def _chain_least_squares(features, matches, start_pose):
    """A loop without robustness: one least-squares fit to every match of each step, chained."""
    return visual_slam.LOOP_SHORTCUTS["least squares on every match, chained"](features, matches, start_pose)


def _shifted_points(*args):
    """Triangulated points a centimetre off: reprojects several pixels off at a few metres."""
    return np.asarray(visual_slam.triangulate_svd(*args)) + [0.01, 0.0, 0.0]


#: Wrong answers that a small shift would not expose (the open exercise accepts 2 cm, the loop
#: decimetres, the triangulation judges by reprojection).
WRONG = {"01.robust_pose": _least_squares_pose, "01.stereo_odometry": _chain_least_squares,
         "01.triangulate_svd": _shifted_points}


@pytest.mark.parametrize("exercise", EXERCISES, ids=lambda e: e.id)
def test_check_fails_a_wrong_implementation(exercise, capsys):
    with pytest.raises(AssertionError):
        check(exercise.id, WRONG.get(exercise.id, _wrong(exercise.answer)))
    assert_check_passes(exercise.id, exercise.answer, len(exercise.make_cases(2024)))


def test_check_fails_an_implementation_without_validation():
    def sample_count(contamination, sample_size=2, confidence=0.99):
        good = (1 - contamination) ** sample_size
        return 1 if good >= 1 else max(1, int(np.ceil(np.log(1 - confidence) / np.log(1 - good))))
    with np.errstate(divide="ignore"), pytest.raises((AssertionError, ZeroDivisionError, ValueError)):
        check("01.ransac_sample_count", sample_count)


def test_fusion_of_equal_covariances_is_the_midpoint():
    s, cov = visual_slam.kalman_fuse([0.0, 0.0, 1.0], np.eye(3), [0.0, 0.0, 3.0], np.eye(3))
    assert np.allclose(s, [0, 0, 2]) and np.allclose(cov, np.eye(3) / 2)


def test_hough_candidates_agree_at_the_true_heading_only():
    rng = np.random.default_rng(0)
    case = visual_slam.hough_cases(rng)[1]                  # three matches of the pose [0.2, 0.2, 0.3]
    positions, _ = visual_slam.hough_candidates(*case.args)
    assert np.allclose(positions, [0.2, 0.2], atol=1e-3)
    args = list(case.args)
    args[-1] = [0.3 + np.pi / 2]
    positions, _ = visual_slam.hough_candidates(*args)
    assert np.ptp(positions[0], axis=0).max() > 0.5         # 90 degrees off, they disagree


def test_hough_candidates_match_the_libraries_votes():
    """The derived centre and covariance are what robokit's accumulator votes with: a match votes
    at a heading exactly in the bins of the +-2.8 sigma box around its candidate."""
    from robokit.localization import hough_accumulator

    case = visual_slam.hough_cases(np.random.default_rng(1))[2]
    robot, rcov, world, wcov, _ = case.args
    bounds, size = [-2.0, 2.0, -2.0, 2.0], 0.04
    acc, thetas = hough_accumulator(robot[:1], rcov[:1], world[:1], wcov[:1], bounds, bin_size=size,
                                    angle_bin=np.deg2rad(30.0))
    pos, cov = visual_slam.hough_candidates(robot[:1], rcov[:1], world[:1], wcov[:1], thetas)
    for t in range(len(thetas)):
        half = 2.8 * np.sqrt(np.diag(cov[t, 0]))
        x0, z0 = np.floor((pos[t, 0] - half - bounds[::2]) / size).astype(int)
        x1, z1 = np.floor((pos[t, 0] + half - bounds[::2]) / size).astype(int) + 1
        box = np.zeros(acc.shape[1:], int)
        box[max(x0, 0):max(x1, 0), max(z0, 0):max(z1, 0)] = 1
        assert np.array_equal(acc[t], box), t


def _feedback(ex_id, fn, seed=2024):
    """The messages of the valid cases ``fn`` fails."""
    ex = _exercise(ex_id)
    return [ex.compare(expected_output(ex, c), fn(*c.args)) for c in ex.make_cases(seed) if not c.raises]


def test_triangulation_feedback_names_the_camera_and_coordinate():
    def right_camera_ignored(p_left, p_right, uv_left, uv_right):     # the left camera's equations twice
        return visual_slam.triangulate_svd(p_left, p_right, uv_left, np.asarray(uv_right) + [3.0, 0.0])
    msgs = [m for m in _feedback("01.triangulate_svd", right_camera_ignored) if m]
    assert msgs and all("px off in the" in m for m in msgs)
    assert any("the right camera's u" in m or "the left camera's u" in m for m in msgs)


def test_any_least_squares_triangulation_passes():
    """The check asks for the least-squares point, not our recipe: the unscaled rows and the inhomogeneous
    least squares (W = 1) pass too."""
    def unscaled(p_left, p_right, uv_left, uv_right):
        pl, pr, ul, ur = (np.asarray(a, float) for a in (p_left, p_right, uv_left, uv_right))
        out = []
        for a, b in zip(ul, ur):
            m = np.array([a[0] * pl[2] - pl[0], a[1] * pl[2] - pl[1], b[0] * pr[2] - pr[0], b[1] * pr[2] - pr[1]])
            out.append(np.linalg.lstsq(m[:, :3], -m[:, 3], rcond=None)[0])
        return np.array(out)
    for seed in range(5):
        assert not any(_feedback("01.triangulate_svd", unscaled, seed))


def test_fusion_feedback_names_the_wrong_term():
    def summed(s, sigma, r_new, sigma_new):         # covariances added, mean right
        mean, _ = visual_slam.kalman_fuse(s, sigma, r_new, sigma_new)
        return mean, np.asarray(sigma) + np.asarray(sigma_new)

    def averaged(s, sigma, r_new, sigma_new):       # plain average, covariance right
        _, cov = visual_slam.kalman_fuse(s, sigma, r_new, sigma_new)
        return (np.asarray(s) + np.asarray(r_new)) / 2, cov

    def swapped(s, sigma, r_new, sigma_new):        # each estimate weighted by the other's information
        return visual_slam.kalman_fuse(s, sigma_new, r_new, sigma)[0], visual_slam.kalman_fuse(s, sigma, r_new, sigma_new)[1]
    assert any("the mean is right" in m and "sum of the covariances" in m for m in _feedback("01.kalman_fuse", summed) if m)
    assert any("the covariance is right" in m and "plain average" in m for m in _feedback("01.kalman_fuse", averaged) if m)
    assert any("weights swapped" in m for m in _feedback("01.kalman_fuse", swapped) if m)


def test_hough_feedback_names_the_wrong_term():
    def no_landmark_term(robot_xz, robot_cov_xz, world_xz, world_cov_xz, thetas):
        pos, _ = visual_slam.hough_candidates(robot_xz, robot_cov_xz, world_xz, world_cov_xz, thetas)
        _, cov = visual_slam.hough_candidates(robot_xz, robot_cov_xz, world_xz, np.zeros_like(world_cov_xz), thetas)
        return pos, cov

    def turned_back(robot_xz, robot_cov_xz, world_xz, world_cov_xz, thetas):
        pos, cov = visual_slam.hough_candidates(robot_xz, robot_cov_xz, world_xz, world_cov_xz, -np.asarray(thetas))
        return pos, visual_slam.hough_candidates(robot_xz, robot_cov_xz, world_xz, world_cov_xz, thetas)[1]
    msgs = [m for m in _feedback("01.hough_candidates", no_landmark_term) if m]
    assert msgs and all("the positions are right" in m and "W missing" in m for m in msgs)
    msgs = [m for m in _feedback("01.hough_candidates", turned_back) if m]
    assert msgs and all("the covariances are right" in m and "wrong way round" in m for m in msgs)


@pytest.mark.parametrize("seed", range(12))
def test_the_open_exercise_is_fair(seed):
    """The reference lands within 1 cm and 0.1 degree of the pose that generated every scene, even
    with 60 % wrong matches; one least-squares fit to all matches misses every scene by far more
    than the 2 cm the cases accept."""
    for robot, world, truth, eps in visual_slam.robust_pose_problems(np.random.default_rng(seed)):
        answer = visual_slam.robust_pose(robot, world)
        assert np.all(np.abs(answer[:2] - truth[:2]) < 0.01)
        assert abs(np.angle(np.exp(1j * (answer[2] - truth[2])))) < np.deg2rad(0.1)
        assert eps >= 0.2 and np.max(np.abs(_least_squares_pose(robot, world)[:2] - truth[:2])) > 0.1


def _score(exercise, fn, seed):
    """The grader's points for ``fn`` (bad-input cases count only once a valid case passes)."""
    from robocourse.grading.judge import call_student, expected_output, judge

    cases = exercise.make_cases(seed)
    passed = {True: 0, False: 0}
    for case in cases:
        passed[bool(case.raises)] += judge(exercise, case, expected_output(exercise, case), call_student(fn, case)).passed
    total = passed[False] + (passed[True] if passed[False] else 0)
    return exercise.points * total / len(cases)


@pytest.mark.parametrize("seed", range(6))
def test_the_least_squares_shortcut_earns_at_most_a_third(seed):
    exercise = next(e for e in EXERCISES if e.id == "01.robust_pose")
    assert _score(exercise, exercise.answer, seed) == exercise.points
    assert _score(exercise, _least_squares_pose, seed) <= exercise.points / 3


def test_the_open_exercise_judges_the_heading_modulo_two_pi():
    exercise = next(e for e in EXERCISES if e.id == "01.robust_pose")
    truth = [1.0, 2.0, -3.0]
    assert exercise.compare(truth, [1.0, 2.0, -3.0 + 2 * np.pi]) is None            # [0, 2 pi) is the same heading
    assert exercise.compare(truth, np.array([1.0, 2.0, 3.27])) is None                # across the seam, 0.013 rad off
    assert exercise.compare(truth, [1.0, 2.0, -2.9]) is not None
    assert "modulo 2 pi" in exercise.compare(truth, [1.0, 2.0, 3.0])
    assert exercise.compare(truth, [1.05, 2.0, -3.0]) is not None
    assert exercise.compare(truth, "a pose") is not None


def test_the_loop_runs_are_the_lessons_lab():
    """Every run is a stretch of the lesson's lap with a corner, its first truth is the start pose,
    no two runs share their poses (the start pose does not give the rest away), and the plain data
    stay small."""
    import json

    from robocourse.lessons.visual_slam.odometry import ODOMETRY_RUN

    cases = _exercise("01.stereo_odometry").make_cases(11)
    for case in (c for c in cases if not c.raises):
        features, matches, start_pose = case.args
        truth = np.asarray(case.expected)
        assert np.allclose(truth[0], start_pose) and len(truth) == len(features) == ODOMETRY_RUN["frames"]
        assert len(json.dumps([case.args, case.expected])) < 200_000
        assert np.abs(np.diff(np.unwrap(truth[:, 2]))).sum() >= ODOMETRY_RUN["min_turn"] - 0.2
    public = [np.asarray(c.expected) for c in _exercise("01.stereo_odometry").make_cases(2024) if not c.raises]
    for case in (c for c in cases if not c.raises):
        assert all(np.abs(np.asarray(case.expected) - p).max() > 0.05 for p in public)


@pytest.mark.parametrize("seed", range(4))
def test_the_loop_shortcuts_fail_and_the_reference_passes(seed):
    ex = _exercise("01.stereo_odometry")
    for case in (c for c in ex.make_cases(seed) if not c.raises):
        assert ex.compare(case.expected, ex.answer(*case.args)) is None
        for name, shortcut in ex.shortcuts.items():
            assert ex.compare(case.expected, shortcut(*case.args)) is not None, name


def test_the_loop_feedback_shows_the_run():
    ex = _exercise("01.stereo_odometry")
    case = next(c for c in ex.make_cases(3) if not c.raises)
    msg = ex.compare(case.expected, _chain_least_squares(*case.args))
    assert "error by frame: 0: 0 cm" in msg and "the worst step is" in msg
    assert "expected one pose" in ex.compare(case.expected, case.expected[:-1])


def _graded_points(exercise, fn, seed):
    """The grader's points for ``fn`` on a seed's cases, trivial answers and shortcuts discounted."""
    from robocourse.exercises.trivial import trivial_passes
    from robocourse.grading.grader import score_exercise
    from robocourse.grading.judge import call_student

    cases = exercise.make_cases(seed)
    expected = [expected_output(exercise, c) for c in cases]
    public = [(c, expected_output(exercise, c)) for c in exercise.make_cases(2024) if not c.raises]
    trivial = trivial_passes(exercise, cases, expected, public)
    return score_exercise(exercise, cases, expected, trivial, [call_student(fn, c) for c in cases])[0].points


@pytest.mark.parametrize("seed", range(3))
def test_the_disparity_shortcut_earns_nothing_on_triangulation(seed):
    """Exercise 4's formulas pass the exact cases on the lesson's rectified rig, and nothing else: as a
    registered shortcut they earn no points; the reference earns all."""
    exercise = _exercise("01.triangulate_svd")
    shortcut = exercise.shortcuts["Exercise 4's disparity formulas (a rectified horizontal pair assumed)"]
    assert _graded_points(exercise, shortcut, seed) == 0
    assert _graded_points(exercise, exercise.answer, seed) == exercise.points
