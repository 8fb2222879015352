"""Assignment 03: registration, check() rejecting wrong answers, an open exercise that is fair, helpers."""
from __future__ import annotations

import numpy as np
import pytest

from robocourse.lessons.corridor_localization import exercises as module
from robocourse.exercises.plain import to_plain
from robocourse.grading import check
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes
from robokit.vision import hamming_distances

EXERCISES = {ex.id: ex for ex in module.EXERCISES}


def test_assignment_is_registered():
    assert module.ASSIGNMENT == "03_corridor_localization"
    assert [e.id for e in exercises_for("03_corridor_localization")] == list(EXERCISES)
    assert 7 <= len(EXERCISES) <= 9 and len(module.WRITTEN) >= 2


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


def _wrong_bow(words_a, words_b, idf):   # maps the L1 distance to 1 - d (not 1 - d / 2)
    idf = np.asarray(idf, float)
    if max(list(words_a) + list(words_b) + [0]) >= len(idf):
        raise ValueError("words")
    va = np.bincount(words_a, minlength=len(idf)) * idf
    vb = np.bincount(words_b, minlength=len(idf)) * idf
    va, vb = (v / v.sum() if v.sum() > 0 else v for v in (va, vb))
    return {"a": va, "b": vb, "score": float(1 - np.abs(va - vb).sum()) if va.sum() and vb.sum() else 0.0}


def _wrong_resample(weights, r):   # multinomial-style pointers r + m (not r + m / M)
    w = np.asarray(weights, float)
    if np.any(w < 0) or not 0 <= r < 1 / len(w):
        raise ValueError("weights")
    c = np.cumsum(w / w.sum())
    return np.minimum(np.searchsorted(c, (r + np.arange(len(w)) / len(w)) ** 2), len(w) - 1).tolist()


def _wrong_field(pose, ranges, angles, distance, resolution, origin, sigma_hit=0.2, z_hit=0.95, z_rand=0.05,
                 r_max=8.0, max_distance=2.0):   # an unnormalised Gaussian (ROS's), not the normal density
    r = np.asarray(ranges, float)
    if np.isnan(r).any():
        raise ValueError("ranges")
    d = np.asarray(distance, float)
    dists = []
    for z, a in zip(r, angles):
        if not np.isfinite(z) or z >= r_max:
            continue
        x = pose[0] + z * np.cos(pose[2] + a)
        y = pose[1] + z * np.sin(pose[2] + a)
        j, i = int(np.floor((x - origin[0]) / resolution)), int(np.floor((y - origin[1]) / resolution))
        dists.append(d[i, j] if 0 <= i < d.shape[0] and 0 <= j < d.shape[1] else max_distance)
    hit = z_hit * np.exp(-np.array(dists) ** 2 / (2 * sigma_hit ** 2))
    return {"distance": dists, "hit": hit, "rand": z_rand / r_max, "log_q": float(np.log(hit + z_rand / r_max).sum())}


def _uniform_rand_field(*args, **kwargs):   # the random-return term without its 1 / r_max
    out = module.likelihood_field_weight(*args, **kwargs)
    rand = kwargs.get("z_rand", 0.05)
    return dict(out, rand=rand, log_q=float(np.log(np.asarray(out["hit"]) + rand).sum()))


def _no_resampling(run):   # importance weights multiplied up, never resampled: the cloud degenerates
    P = np.asarray(run["particles"], float)
    if len(run["scans"]) != len(run["odometry"]) or any(not 0 <= r < 1 / len(P) for r in run["uniforms"]):
        raise ValueError("run")
    log_w, out = np.zeros(len(P)), []
    for t, u in enumerate(np.asarray(run["odometry"], float)):
        du = u + np.asarray(run["noise"][t]) * run["motion_std"]
        c, s = np.cos(P[:, 2]), np.sin(P[:, 2])
        P = np.column_stack([P[:, 0] + c * du[:, 0] - s * du[:, 1], P[:, 1] + s * du[:, 0] + c * du[:, 1],
                             P[:, 2] + du[:, 2]])
        log_w += [module.likelihood_field_weight(p, run["scans"][t], run["angles"], run["distance"], run["resolution"],
                                                 run["origin"])["log_q"] for p in P]
        w = np.exp(log_w - log_w.max())
        w /= w.sum()
        out.append([w @ P[:, 0], w @ P[:, 1], np.arctan2(w @ np.sin(P[:, 2]), w @ np.cos(P[:, 2]))])
    return out


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
         "03.recognise_keyframe": _exact_equality, "03.mcl_track": _no_resampling}


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
                                                data["resolution"], data["origin"])["log_q"]
              for k in ("true", "look_alike", "elsewhere")}
    assert weight["true"] > weight["look_alike"] > weight["elsewhere"]
    assert weight["true"] - weight["look_alike"] < weight["true"] - weight["elsewhere"]


@pytest.mark.parametrize("exercise_id, wrong, term", [
    ("03.likelihood_field_weight", _wrong_field, "'hit'"),
    ("03.likelihood_field_weight", _uniform_rand_field, "'rand'"),
    ("03.bow_similarity", _wrong_bow, "'score'"),
])
def test_derivation_feedback_names_the_wrong_term(exercise_id, wrong, term, capsys):
    """A derivation checked term by term: the feedback names the wrong term and no other upstream one
    (log q follows a wrong term), and says when every value is off by one factor (a normalisation)."""
    ex = EXERCISES[exercise_id]
    messages = [ex.compare(to_plain(ex.answer(*c.args, **c.kwargs)), to_plain(wrong(*c.args, **c.kwargs)))
                for c in ex.make_cases(2024) if not c.raises]
    failed = [m for m in messages if m]
    right = {"03.likelihood_field_weight": ["'distance'", "'hit'", "'rand'"], "03.bow_similarity": ["'a'", "'b'"]}
    assert failed and all(f"{term} (" in m for m in failed)
    assert not any(f"{other} (" in m for m in failed for other in right[exercise_id] if other != term)
    if term == "'hit'":                             # every hit off by 1 / (sqrt(2 pi) sigma_hit)
        assert all("same factor" in m for m in failed)


def test_field_terms_add_up_to_the_lessons_weight():
    """log_q is the log of the product of hit + rand over the used beams, and equals the lesson's
    likelihood field (robokit) on the public cases."""
    from robokit.localization import likelihood_field_log_weights
    from robokit.mapping import LikelihoodField
    for c in EXERCISES["03.likelihood_field_weight"].make_cases(7):
        if c.raises:
            continue
        out = module.likelihood_field_weight(*c.args)
        pose, ranges, angles, distance, resolution, origin = c.args
        field = LikelihoodField(np.asarray(distance), resolution, np.asarray(origin), 2.0)
        assert out["log_q"] == pytest.approx(float(np.log(np.asarray(out["hit"]) + out["rand"]).sum()), abs=1e-9)
        assert out["log_q"] == pytest.approx(float(likelihood_field_log_weights([pose], ranges, angles, field)[0]),
                                             abs=1e-9)


def test_loop_cases_are_fair_and_shortcuts_fail():
    """The loop's runs: the reference converges on every run, every registered shortcut (dead
    reckoning, the held start, the laser-blind filter, one look) fails every run, and the feedback of
    a failed run shows the error at a few updates."""
    ex = EXERCISES["03.mcl_track"]
    runs = [c for c in ex.make_cases(5) if not c.raises]
    assert len(runs) == 3
    for c in runs:
        assert ex.compare(c.expected, np.asarray(ex.answer(*c.args)).tolist()) is None
        for name, shortcut in ex.shortcuts.items():
            message = ex.compare(c.expected, np.asarray(shortcut(*c.args)).tolist())
            assert message and "did not converge" in message and "Error at update 1:" in message, name


def test_loop_truth_is_hidden_from_the_inputs():
    """The truth travels only in Case.expected: no input holds the true poses."""
    from robocourse.lessons.corridor_localization.mcl_runs import corridor_distance
    whole, origin = corridor_distance()
    for c in EXERCISES["03.mcl_track"].make_cases(9):
        if c.raises:
            continue
        run = c.args[0]
        assert set(run) == {"particles", "odometry", "motion_std", "noise", "scans", "angles", "distance",
                            "resolution", "origin", "uniforms"}
        truth = np.asarray(c.expected)
        start = np.mean(np.asarray(run["particles"])[:, :2], axis=0)
        assert np.hypot(*(start - truth[0, :2])) > 0.3
        # the grid is the whole corridor's, whatever the drive: its extent says nothing of where it went
        # (a grid cropped to the drive +- 8.5 m once gave its x away to 0.1 m)
        assert np.shape(run["distance"]) == whole.shape and run["origin"] == origin.tolist()
        uniforms = np.asarray(run["uniforms"])
        assert np.all((uniforms >= 0) & (uniforms < 1 / len(run["particles"])))
