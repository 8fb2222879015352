"""Assignment 04: registration, check() rejecting wrong answers, an open exercise and a loop, both fair, helpers."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from robocourse.lessons.littledog import exercises as module
from robokit.geometry import so3_log
from robocourse.grading import check
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes
from robokit.legged import littledog
from robokit.legged.touchdown import contact_events, detect_contacts, gate_touchdowns, score_leg_events
from robocourse.lessons.littledog.data import crawl_touchdowns, model_facts, mocap_frames
from robokit.legged.mocap import fit_marker_pose

EXERCISES = {ex.id: ex for ex in module.EXERCISES}


def test_assignment_is_registered():
    assert module.ASSIGNMENT == "04_littledog"
    assert [e.id for e in exercises_for("04_littledog")] == list(EXERCISES)
    assert 7 <= len(EXERCISES) <= 8 and len(module.WRITTEN) >= 3
    assert sum(e.points for e in EXERCISES.values()) == 10


def test_cases_differ_between_seeds():
    for ex in EXERCISES.values():
        assert ex.make_cases(1) != ex.make_cases(2), ex.id


def _wrong_fk(q_leg, leg):   # forgets that the right legs' pitch axis sits outwards to the right (-y)
    q = np.asarray(q_leg, float)
    if q.shape != (3,) or leg not in littledog.LEGS:
        raise ValueError("q_leg, leg")
    c, s = np.cos(q[0]), np.sin(q[0])
    x = -littledog.UPPER_LEG * np.sin(q[1]) - littledog.LOWER_LEG * np.sin(q[1] + q[2])
    z = -littledog.UPPER_LEG * np.cos(q[1]) - littledog.LOWER_LEG * np.cos(q[1] + q[2])
    y = littledog.HIP_OFFSETS[littledog.LEGS.index(leg)]
    return (littledog.HIP_POSITIONS[littledog.LEGS.index(leg)] + [x, c * y - s * z, s * y + c * z]).tolist()


def _wrong_ik(p_foot, leg, branch):   # ignores the branch: every knee bends backwards
    from robokit.legged.leg_kinematics import leg_ik
    if branch not in (-1, 1):
        raise ValueError("branch")
    return leg_ik(p_foot, leg, -1).tolist()


def _wrong_margin(feet_xy, com_xy):   # unsigned: a robot about to tip over looks stable
    from robokit.legged.support import stability_margin
    return abs(stability_margin(feet_xy, com_xy))


def _wrong_servo(q_ref, q, q_prev, kp, kd, dt, voltage_max):   # no saturation
    r, q, p = (np.asarray(v, float) for v in (q_ref, q, q_prev))
    if np.isnan(r).any():
        raise ValueError("q_ref")
    return (np.asarray(kp) * (r - q) - np.asarray(kd) * (q - p) / dt).tolist()


def _ignores_visibility(markers_body, observed, visible):   # fits the hidden markers' zeros too
    if sum(bool(v) for v in visible) < 3:
        raise ValueError("visible")
    return fit_marker_pose(markers_body, observed).tolist()


def _plain_threshold(force, planned_stance, dt):   # the tempting shortcut: each leg's rises through 2 N
    f = np.asarray(force, float)
    if f.ndim != 2 or f.shape[1] != 4 or not np.isfinite(f).all() or np.shape(planned_stance) != f.shape \
            or not dt > 0:
        raise ValueError("force, planned_stance, dt")
    return [(np.flatnonzero(np.diff((leg > 2.0).astype(int)) == 1) + 1).tolist() for leg in f.T]


def _wrong_endurance(capacity_ah, voltage, mean_power_w):   # watt-hours over watts: hours, not minutes
    if min(capacity_ah, voltage, mean_power_w) <= 0:
        raise ValueError("capacity_ah")
    return capacity_ah * voltage / mean_power_w


WRONG = {"04.leg_fk": _wrong_fk, "04.leg_ik": _wrong_ik, "04.stability_margin": _wrong_margin,
         "04.pd_servo_step": _wrong_servo, "04.marker_fit": _ignores_visibility,
         "04.detect_touchdowns": _plain_threshold, "04.battery_endurance": _wrong_endurance}


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_fails_a_wrong_implementation(exercise_id, capsys):
    with pytest.raises(AssertionError, match=exercise_id) as failed:
        check(exercise_id, WRONG[exercise_id])
    assert "FAIL" in str(failed.value)          # the failed cases, in the message students see


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_passes_the_reference(exercise_id, capsys):
    assert_check_passes(exercise_id, EXERCISES[exercise_id].answer, len(EXERCISES[exercise_id].make_cases(2024)))


def test_the_fk_cases_match_a_chain_of_homogeneous_transforms():
    """The reference against the brief's formula written as a product of 4x4 transforms (by hand)."""
    def rot(axis, a):
        return Rotation.from_rotvec(np.eye(3)[axis] * a).as_matrix()

    def tf(R=np.eye(3), p=(0, 0, 0)):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, p
        return T
    for case in EXERCISES["04.leg_fk"].make_cases(5):
        if case.raises:
            continue
        q, leg = case.args
        i = littledog.LEGS.index(leg)
        side = 1.0 if leg.endswith("L") else -1.0
        T = (tf(p=littledog.HIP_POSITIONS[i]) @ tf(rot(0, q[0])) @ tf(p=(0, side * littledog.HIP_OFFSETS[i], 0))
             @ tf(rot(1, q[1])) @ tf(p=(0, 0, -littledog.UPPER_LEG)) @ tf(rot(1, q[2])))
        foot = T @ [0, 0, -littledog.LOWER_LEG, 1]
        assert np.allclose(EXERCISES["04.leg_fk"].answer(q, leg), foot[:3], atol=1e-12)


def test_the_ik_cases_are_inverted_on_the_branch_asked_for_with_the_foot_below_the_hip():
    for case in EXERCISES["04.leg_ik"].make_cases(6):
        if case.raises:
            continue
        p, leg, branch = case.args
        q = EXERCISES["04.leg_ik"].answer(p, leg, branch)
        assert np.allclose(EXERCISES["04.leg_fk"].answer(q, leg), p, atol=1e-9)
        assert np.sign(q[2]) == branch and np.all(np.abs(q) < np.pi - 0.1)
        # below the hip: in the rolled frame the foot's z is negative
        v = np.asarray(p) - littledog.HIP_POSITIONS[littledog.LEGS.index(leg)]
        assert -np.sin(q[0]) * v[1] + np.cos(q[0]) * v[2] < 0


# --- the open exercise and the loop --------------------------------------------------------------

def _hysteresis(force, planned_stance, dt):   # the lesson's best detector without the plan (3 / 1 N, debounce 2)
    return [e.tolist() for e in contact_events(detect_contacts(np.asarray(force), 3.0, 1.0, 2))]


def _lesson_gate(force, planned_stance, dt):   # the lesson's gate: the first rise within 100 ms of the plan
    found = contact_events(detect_contacts(np.asarray(force), 3.0, 1.0, 2))
    return [gate_touchdowns(d, p, 10).tolist() for d, p in zip(found, contact_events(np.asarray(planned_stance)))]


@pytest.mark.parametrize("seed", [0, 1, "instructor-secret"])
def test_the_touchdown_loop_is_fair(seed):
    """The cases are crawls simulated in MuJoCo, graded against its true touchdowns: the reference
    (hysteresis gated by the plan) passes every one; the force alone (a threshold, the lesson's
    hysteresis) fails every one; the plan alone, shifted by any fixed delay, fails at least one; the
    lesson's +-100 ms gate fails the slow link."""
    exercise = EXERCISES["04.detect_touchdowns"]
    cases = [c for c in exercise.make_cases(seed) if not c.raises]
    assert len(cases) == len(module.TOUCHDOWN_LINKS) == 3
    for case in cases:
        force, stance, dt = case.args
        assert np.shape(force) == np.shape(stance) and np.shape(force)[1] == 4 and dt == 0.01
        assert sum(map(len, case.expected)) >= 12, case.label                 # touchdowns enough for 0.9 to mean much
        assert exercise.compare(case.expected, exercise.answer(*case.args)) is None, case.label
        for blind in (_plain_threshold, _hysteresis):
            assert score_leg_events(blind(*case.args), case.expected, 5).precision < 0.4, (blind, case.label)
    assert exercise.compare(cases[2].expected, _lesson_gate(*cases[2].args)) is not None
    for name, shortcut in exercise.shortcuts.items():
        assert any(exercise.compare(c.expected, shortcut(*c.args)) is not None for c in cases), name
    assert exercise.compare(cases[0].expected, exercise.shortcuts["the plan's touchdowns"](*cases[0].args)) is None


def test_the_touchdown_cases_are_mujocos_truth():
    """A crawl's touchdowns are the rising edges of MuJoCo's contacts, whatever the sensor noise's seed."""
    from robokit.legged import crawl_gait, simulate_walk, walking_plan
    from robokit.legged.simulation import LoopSettings
    gait = {"period": 2.4, "step_length": 0.07, "step_height": 0.045, "duty_factor": 0.92}
    run = crawl_touchdowns(gait, distance=0.1, latency=0.05, seed=3)
    out = simulate_walk(walking_plan(crawl_gait(**gait), 0.1), LoopSettings(latency=0.05), rng=7)
    assert run["touchdowns"] == [e.tolist() for e in contact_events(out.log.contact)]
    other = crawl_touchdowns(gait, distance=0.1, latency=0.05, seed=4)
    assert other["touchdowns"] == run["touchdowns"] and other["force"] != run["force"]
    assert other["planned_stance"] == walking_plan(crawl_gait(**gait), 0.1).stance[:len(out.log)].tolist()


def test_the_touchdown_compare_needs_both_precision_and_recall():
    compare = EXERCISES["04.detect_touchdowns"].compare
    truth = [list(range(10 + 50 * leg, 1000, 200)) for leg in range(4)]        # 20 true touchdowns
    assert compare(truth, [[t + 5 for t in leg] for leg in truth]) is None      # 50 ms late: still a match
    assert "0 right" in compare(truth, [[t + 6 for t in leg] for leg in truth]) # 60 ms late: none matches
    assert compare(truth, [truth[0][:3], *truth[1:]]) is None                   # recall 0.9
    missed = compare(truth, [truth[0][:2], *truth[1:]])
    assert "recall 0.85" in missed and "3 missed" in missed and "FL at sample 410" in missed
    bounces = compare(truth, [sorted(truth[0] + [t + 3 for t in truth[0][:3]]), *truth[1:]])
    assert "precision 0.87" in bounces and "the first false one: FL at sample 13" in bounces
    assert compare(truth, [np.array(leg) for leg in truth]) is None
    assert compare(truth, [[float(t) for t in leg] for leg in truth]) is None
    assert compare(truth, truth[::-1]) is not None                              # each leg's own touchdowns
    for bad in ("10, 60", [[10.5], [], [], []], [[-1], [], [], []], truth[:3], [10, 20, 30, 40], None,
                np.zeros((4, 5))):
        assert compare(truth, bad) is not None


def _least_squares_fit(markers_body, observed, visible):
    """Another correct method: nonlinear least squares on a rotation vector and a translation, from the
    identity rotation, with scipy's default tolerances."""
    v = np.asarray(visible, bool)
    if v.sum() < 3:
        raise ValueError("visible: expected at least three visible markers")
    m, o = np.asarray(markers_body, float)[v], np.asarray(observed, float)[v]

    def residuals(x):
        return (m @ Rotation.from_rotvec(x[:3]).as_matrix().T + x[3:] - o).ravel()
    best = min((least_squares(residuals, np.r_[r0, o.mean(0) - m.mean(0)]) for r0 in np.eye(3) * np.pi / 2),
               key=lambda s: s.cost)                                   # a few starts: the cost is not convex
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = Rotation.from_rotvec(best.x[:3]).as_matrix(), best.x[3:]
    return T.tolist()


def _horn_quaternion_fit(markers_body, observed, visible):
    """Horn's (1987) closed form: the rotation is the eigenvector of a 4x4 symmetric matrix."""
    v = np.asarray(visible, bool)
    if v.sum() < 3:
        raise ValueError("visible: expected at least three visible markers")
    m, o = np.asarray(markers_body, float)[v], np.asarray(observed, float)[v]
    a, b = m - m.mean(0), o - o.mean(0)
    S = a.T @ b
    delta = [S[1, 2] - S[2, 1], S[2, 0] - S[0, 2], S[0, 1] - S[1, 0]]
    N = np.zeros((4, 4))
    N[0, 0], N[0, 1:], N[1:, 0] = np.trace(S), delta, delta
    N[1:, 1:] = S + S.T - np.trace(S) * np.eye(3)
    w, x, y, z = np.linalg.eigh(N)[1][:, -1]
    R = Rotation.from_quat([x, y, z, w]).as_matrix()
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, o.mean(0) - R @ m.mean(0)
    return T


@pytest.mark.parametrize("method", [_least_squares_fit, _horn_quaternion_fit])
def test_the_open_marker_fit_accepts_other_correct_methods(method, capsys):
    for seed in (2024, 3, "instructor-secret"):
        exercise = EXERCISES["04.marker_fit"]
        for case in exercise.make_cases(seed):
            if case.raises:
                with pytest.raises(ValueError):
                    method(*case.args)
                continue
            assert exercise.compare(exercise.answer(*case.args).tolist(), method(*case.args)) is None, case.label
    assert_check_passes("04.marker_fit", method, 7)


def test_the_marker_fit_compare_rejects_near_misses():
    exercise = EXERCISES["04.marker_fit"]
    case = exercise.make_cases(2024)[1]                                # four markers, 1 mm noise
    markers, seen, visible = case.args
    best = exercise.answer(*case.args)
    three = fit_marker_pose(markers, seen, [True, True, True, False])  # a good fit, but not the optimum
    assert "not the least-squares fit" in exercise.compare(best, three)
    flipped = best @ np.diag([1.0, 1.0, -1.0, 1.0])                    # a reflection
    assert "reflection" in exercise.compare(best, flipped)
    nudged = best.copy()
    nudged[:3, 3] += 3e-5                                              # 0.03 mm: within the tolerance
    assert exercise.compare(best, nudged) is None
    assert exercise.compare(best, best[:3]) is not None and exercise.compare(best, "T") is not None


# --- the written questions' helpers ---------------------------------------------------------------

def test_model_facts_are_the_models_constants():
    facts = model_facts()
    for name, value in facts.items():
        assert np.array_equal(np.asarray(value, dtype=object if name == "GUIDE" else None),
                              np.asarray(getattr(littledog, name), dtype=object if name == "GUIDE" else None)
                              ) or name == "STANCE_FEET", name
    assert np.allclose(facts["STANCE_FEET"], littledog.STANCE_FEET)


def test_the_touchdown_question_crawls_show_the_trade_off():
    """Question 2's crawls: the plain threshold finds every touchdown but counts mid-stance rises; the
    plan alone is exact over the quick link and useless over the slow one; the reference is exact on
    both."""
    crawl = {"period": 2.4, "step_length": 0.07, "step_height": 0.045, "duty_factor": 0.92}
    for latency in (0.0, 0.13):
        run = crawl_touchdowns(crawl, distance=0.5, latency=latency, force_noise=0.2, seed=1)
        args, truth = (run["force"], run["planned_stance"], run["dt"]), run["touchdowns"]
        plain = score_leg_events(_plain_threshold(*args), truth, 5)
        planned = score_leg_events(contact_events(np.array(run["planned_stance"])), truth, 5)
        ours = score_leg_events(module.detect_touchdowns(*args), truth, 5)
        assert plain.recall == 1.0 and plain.precision < 0.3
        assert ours.precision == ours.recall == 1.0
        assert (planned.precision, planned.recall) == ((1.0, 1.0) if latency == 0.0 else (0.0, 0.0))


def test_the_marker_question_frames_show_the_narrow_marker_set():
    """Rotation about the body's x axis (roll) is the worst fixed: the markers spread 0.21 m along x but
    only 0.075 m across (y) and 0.03 m in height (z); hiding the post's marker (the only one off the
    trunk's top plane) makes it worse still."""
    noisy, exact = mocap_frames(noise=0.001), mocap_frames(noise=0.0)

    def rms_errors(data, visible):
        err = [so3_log(np.asarray(T)[:3, :3].T @ fit_marker_pose(data["markers_body"], seen, visible)[:3, :3])
               for T, seen in zip(data["T_world_body"], data["observed"])]
        return np.degrees(np.sqrt(np.mean(np.square(err), axis=0)))
    assert rms_errors(exact, [True] * 4).max() < 1e-6
    four, no_post = rms_errors(noisy, [True] * 4), rms_errors(noisy, [True, True, True, False])
    assert four[0] > 2 * max(four[1], four[2]) and no_post[0] > 1.2 * four[0]
    assert 0.2 < four[0] < 2.0                                         # degrees, for 1 mm of noise
