"""Assignment 03: registration, check() rejecting wrong answers, an open exercise that is fair, helpers."""
from __future__ import annotations

import numpy as np
import pytest

from robocourse.lessons.corridor_localization import exercises as module
from robocourse.grading import check
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes
from robokit.vision import hamming_distances

EXERCISES = {ex.id: ex for ex in module.EXERCISES}


def test_assignment_is_registered():
    assert module.ASSIGNMENT == "03_corridor_localization"
    assert [e.id for e in exercises_for("03_corridor_localization")] == list(EXERCISES)
    assert 7 <= len(EXERCISES) <= 8 and len(module.WRITTEN) >= 2


def test_cases_differ_between_seeds():
    for ex in EXERCISES.values():
        assert ex.make_cases(1) != ex.make_cases(2), ex.id


def _wrong_width(d_l, d_r, width, recess=0.07, tol=0.03):   # swaps Eqs. (2) and (3)
    if d_l < 0 or d_r < 0:
        raise ValueError("d_l")
    err = np.abs(d_l + d_r - np.array([width, width + recess, width + 2 * recess]))
    k = int(np.argmin(err))
    return ("corridor", "facing doors", "staggered doors")[k] if err[k] <= tol else None


def _wrong_areas(ranges, angles):   # no wrap-around: a run across the last beam counts twice
    r, a = np.asarray(ranges, float), np.asarray(angles, float)
    if np.isnan(r).any():
        raise ValueError("ranges")
    bad = ~np.isfinite(r)
    out, k = [], 0
    while k < len(r):
        if bad[k]:
            j = k
            while j + 1 < len(r) and bad[j + 1]:
                j += 1
            out.append([a[k], a[j], a[j] - a[k]])
            k = j + 1
        else:
            k += 1
    return np.array(out).reshape(-1, 3)


def _wrong_log_odds(probabilities, prior=0.5):   # adds the log odds without subtracting the prior's
    p = np.asarray(probabilities, float)
    if np.any((p <= 0) | (p >= 1)):
        raise ValueError("probabilities")
    return float(np.sum(np.log(p / (1 - p)))) + np.log(prior / (1 - prior))


def _wrong_bow(words_a, words_b, idf):   # forgets the IDF (plain term frequencies)
    idf = np.asarray(idf, float)
    if max(list(words_a) + list(words_b) + [0]) >= len(idf):
        raise ValueError("words")
    va = np.bincount(words_a, minlength=len(idf)) / max(len(words_a), 1)
    vb = np.bincount(words_b, minlength=len(idf)) / max(len(words_b), 1)
    return float(np.minimum(va, vb).sum())


def _wrong_resample(weights, r):   # multinomial-style pointers r + m (not r + m / M)
    w = np.asarray(weights, float)
    if np.any(w < 0) or not 0 <= r < 1 / len(w):
        raise ValueError("weights")
    c = np.cumsum(w / w.sum())
    return np.minimum(np.searchsorted(c, (r + np.arange(len(w)) / len(w)) ** 2), len(w) - 1).tolist()


def _wrong_field(pose, ranges, angles, distance, resolution, origin, sigma_hit=0.2, z_hit=0.95, z_rand=0.05,
                 r_max=8.0, max_distance=2.0):   # an unnormalised Gaussian (ROS's), not Table 6.3's density
    r = np.asarray(ranges, float)
    if np.isnan(r).any():
        raise ValueError("ranges")
    d = np.asarray(distance, float)
    total = 0.0
    for z, a in zip(r, angles):
        if not np.isfinite(z) or z >= r_max:
            continue
        x = pose[0] + z * np.cos(pose[2] + a)
        y = pose[1] + z * np.sin(pose[2] + a)
        j, i = int(np.floor((x - origin[0]) / resolution)), int(np.floor((y - origin[1]) / resolution))
        dist = d[i, j] if 0 <= i < d.shape[0] and 0 <= j < d.shape[1] else max_distance
        total += np.log(z_hit * np.exp(-dist ** 2 / (2 * sigma_hit ** 2)) + z_rand / r_max)
    return float(total)


def _wrong_ellipse(points, centre, sigma_x, sigma_y):   # drops the normalising constant
    if sigma_x <= 0 or sigma_y <= 0:
        raise ValueError("sigma")
    p, c = np.asarray(points, float), np.asarray(centre, float)
    return np.exp(-((p[:, 0] - c[0]) ** 2 / (2 * sigma_x ** 2) + (p[:, 1] - c[1]) ** 2 / (2 * sigma_y ** 2)))


def _exact_equality(query, keyframes):   # a tempting shortcut: count identical descriptors
    if not keyframes:
        raise ValueError("keyframes")
    q = {bytes(np.asarray(row, np.uint8)) for row in query}
    return int(np.argmax([sum(bytes(np.asarray(row, np.uint8)) in q for row in kf) for kf in keyframes]))


WRONG = {"03.width_case": _wrong_width, "03.invalid_areas": _wrong_areas, "03.cell_log_odds": _wrong_log_odds,
         "03.bow_similarity": _wrong_bow, "03.resample_indices": _wrong_resample,
         "03.likelihood_field_weight": _wrong_field, "03.ellipse_start_weights": _wrong_ellipse,
         "03.recognise_keyframe": _exact_equality}


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_fails_a_wrong_implementation(exercise_id, capsys):
    with pytest.raises(AssertionError, match=exercise_id) as failed:
        check(exercise_id, WRONG[exercise_id])
    assert "FAIL" in str(failed.value)          # the failed cases, in the message students see


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_passes_the_reference(exercise_id, capsys):
    assert_check_passes(exercise_id, EXERCISES[exercise_id].answer, len(EXERCISES[exercise_id].make_cases(2024)))


@pytest.mark.parametrize("seed", range(12))
def test_the_open_exercise_is_fair(seed):
    """The expected keyframe is the one holding the most near-copies (within 24 bits) of the query's
    descriptors, by an exhaustive count, with a clear margin; counting identical descriptors fails."""
    fooled = 0
    for case in EXERCISES["03.recognise_keyframe"].make_cases(seed):
        if case.raises:
            continue
        query, keyframes = case.args
        near = [int((hamming_distances(np.array(query, np.uint8), np.array(kf, np.uint8)).min(axis=1) <= 24).sum())
                for kf in keyframes]
        answer = module.recognise_keyframe(*case.args)
        assert answer == int(np.argmax(near)) and np.sort(near)[-1] >= 1.5 * np.sort(near)[-2]
        fooled += _exact_equality(*case.args) != answer
    assert fooled >= 1


def test_the_aliasing_helper_shows_a_look_alike():
    """The written question's data: the scan fits the look-alike place almost as well as the true one, and
    both far better than an ordinary place."""
    from robocourse.lessons.corridor_localization.aliasing import aliasing_example
    data = aliasing_example()
    weight = {k: module.likelihood_field_weight(data[k], data["ranges"], data["angles"], data["distance"],
                                                data["resolution"], data["origin"])
              for k in ("true", "look_alike", "elsewhere")}
    assert weight["true"] > weight["look_alike"] > weight["elsewhere"]
    assert weight["true"] - weight["look_alike"] < weight["true"] - weight["elsewhere"]
