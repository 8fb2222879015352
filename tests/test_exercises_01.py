"""Assignment 01 exercises: registration and check() catching wrong answers (answers: test_exercises_references.py)."""
import numpy as np
import pytest

from robocourse.lessons.visual_slam import exercises as visual_slam
from robocourse.grading import check
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes

EXERCISES = exercises_for("01_visual_slam")


def test_assignment_is_registered():
    assert visual_slam.ASSIGNMENT == "01_visual_slam"
    assert set(visual_slam.WRITTEN) == {"01.reduced_descriptor", "01.depth_uncertainty", "01.overconfident_fusion"}
    assert {e.id for e in EXERCISES} == {"01.junction_strength", "01.match_ratio", "01.triangulate_svd",
                                         "01.stereo_point", "01.ransac_sample_count", "01.pose_from_two",
                                         "01.kalman_fuse", "01.hough_votes", "01.robust_pose"}


@pytest.mark.parametrize("exercise", EXERCISES, ids=lambda e: e.id)
def test_cases_depend_on_the_seed(exercise):
    assert exercise.make_cases(1) != exercise.make_cases(2)


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


#: Wrong answers that a small shift would not expose (the open exercise accepts 2 cm).
WRONG = {"01.robust_pose": _least_squares_pose}


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


def test_hough_votes_peak_at_the_true_pose():
    rng = np.random.default_rng(0)
    args = list(visual_slam.hough_cases(rng)[1].args)
    args[-1] = float(np.deg2rad(2.0))                      # 2 degree bins as in Se et al.
    acc = visual_slam.hough_votes(*args)
    assert acc.max() == 3                                   # all three matches agree somewhere
    t = int(np.floor((0.3 + np.pi) / np.deg2rad(2.0)))      # the bin holding the true heading
    assert acc[t, int(0.2 / 0.04), int(0.2 / 0.04)] == 3    # ... and the true position
    assert acc[(t + 45) % acc.shape[0]].max() < 3           # 90 degrees off, they disagree


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
