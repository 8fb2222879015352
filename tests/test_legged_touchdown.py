"""Touchdown detection: the vectorised hysteresis + debounce against a plain sample-by-sample state
machine, its delay, events, and precision/recall against a brute-force maximum matching."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from robokit.legged.touchdown import contact_events, event_precision_recall, score_events
from robokit.legged.touchdown import detect_contacts


def reference_detector(force, on, off, debounce):
    """The textbook loop: a Schmitt trigger, then a counter that accepts a new state after
    `debounce` consecutive samples of it; the first sample sets the state."""
    out = np.zeros(len(force), bool)
    h = False
    state, run_value, run = False, None, 0
    for k, f in enumerate(force):
        if f > on:
            h = True
        elif f < off:
            h = False
        if k == 0:
            state, run_value, run = h, h, 1
        else:
            run = run + 1 if h == run_value else 1
            run_value = h
            if h != state and run >= debounce:
                state = h
        out[k] = state
    return out


def gait_forces(n_steps=20, rate=100, seed=0, noise=0.3, bounce=True):
    """Force on one foot: a 1 Hz gait, 60 % stance at about 7 N, noise, and a damped bounce at each
    touchdown (the foot hits, rebounds, settles). Returns force and true contact."""
    rng = np.random.default_rng(seed)
    n = n_steps * rate
    k = np.arange(n)
    phase = (k % rate) / rate
    truth = phase < 0.6
    truth[:rate // 2] = False                                      # the trial starts in the air
    force = np.where(truth, 7.0, 0.0)
    starts = np.flatnonzero(truth[1:] & ~truth[:-1]) + 1
    if bounce:
        for s in starts:                                           # a rebound 2-4 samples after impact
            force[s + 2:s + 4] = rng.uniform(0.0, 1.5)
            force[s:s + 2] = 11.0                                  # impact overshoot
    force += rng.normal(scale=noise, size=n)
    return force, truth


@pytest.mark.parametrize("debounce", [1, 2, 3, 5])
def test_vectorised_detector_equals_the_loop(debounce):
    rng = np.random.default_rng(debounce)
    for _ in range(20):
        f = np.cumsum(rng.normal(size=300)) + rng.normal(scale=2.0, size=300)
        got = detect_contacts(f, 1.0, -1.0, debounce)
        assert np.array_equal(got, reference_detector(f, 1.0, -1.0, debounce))
    legs = np.column_stack([gait_forces(seed=s)[0] for s in range(4)])
    got = detect_contacts(legs, 3.0, 1.5, debounce)
    for j in range(4):
        assert np.array_equal(got[:, j], reference_detector(legs[:, j], 3.0, 1.5, debounce))


@pytest.mark.parametrize("debounce", [1, 2, 4])
def test_a_clean_step_is_reported_debounce_minus_one_samples_late(debounce):
    f = np.r_[np.zeros(10), np.full(20, 7.0), np.zeros(10)]
    c = detect_contacts(f, 3.0, 1.0, debounce)
    assert contact_events(c).tolist() == [10 + debounce - 1]
    assert np.flatnonzero(c[:-1] & ~c[1:]).tolist() == [29 + debounce - 1]     # lift-off, same delay


def test_a_bounce_shorter_than_the_debounce_is_ignored_and_hysteresis_holds_between_thresholds():
    f = np.r_[np.zeros(5), np.full(5, 7.0), [0.5, 0.5], np.full(5, 7.0), np.zeros(5)]
    assert len(contact_events(detect_contacts(f, 3.0, 1.0, 1))) == 2
    assert len(contact_events(detect_contacts(f, 3.0, 1.0, 3))) == 1
    g = np.r_[0.0, 4.0, 2.0, 2.0, 2.0, 0.5, 2.0]                 # 2 N is between the thresholds
    assert detect_contacts(g, 3.0, 1.0).astype(int).tolist() == [0, 1, 1, 1, 1, 0, 0]
    assert detect_contacts([5.0, 5.0], 3.0, 1.0).tolist() == [True, True]        # starts in contact
    with pytest.raises(ValueError, match="threshold_off"):
        detect_contacts(g, 3.0, 3.0)
    with pytest.raises(ValueError, match="debounce"):
        detect_contacts(g, 3.0, 1.0, 0)


def test_events_per_leg():
    c = np.array([[0, 1], [1, 1], [1, 0], [0, 1], [1, 1]], bool)
    assert [e.tolist() for e in contact_events(c)] == [[1, 4], [3]]
    assert contact_events(c[:, 0]).tolist() == [1, 4]


def brute_force_matches(det, tru, tol):
    """Maximum matching by the Hungarian algorithm on 0/1 costs (no greed involved)."""
    if not len(det) or not len(tru):
        return 0
    feasible = np.abs(det[:, None] - tru[None, :]) <= tol
    rows, cols = linear_sum_assignment(-feasible.astype(float))
    return int(feasible[rows, cols].sum())


def events_to_contacts(events, n):
    c = np.zeros(n, bool)
    c[events] = True                                          # one-sample contacts: rising edge at each
    return c


def test_matching_has_maximum_size():
    rng = np.random.default_rng(3)
    for _ in range(300):
        n = 200
        tru = np.sort(rng.choice(np.arange(1, n, 2), rng.integers(0, 15), replace=False))
        det = np.sort(rng.choice(np.arange(2, n, 2), rng.integers(0, 15), replace=False))   # never adjacent
        tol = int(rng.integers(0, 12))
        score = event_precision_recall(events_to_contacts(det, n), events_to_contacts(tru, n), tol)
        m = brute_force_matches(det, tru, tol)
        assert score.precision == (m / len(det) if len(det) else 1.0)
        assert score.recall == (m / len(tru) if len(tru) else 1.0)


def test_score_events_on_indices_is_the_same_maximum_matching():
    # indices in any order, repeats allowed (a detector that reports a touchdown twice): the score
    # of the sorted indices, against the Hungarian algorithm's maximum matching
    rng = np.random.default_rng(4)
    for _ in range(300):
        tru = rng.choice(200, rng.integers(0, 15), replace=False)
        det = rng.integers(0, 200, rng.integers(0, 15))
        tol = int(rng.integers(0, 12))
        score = score_events(det.tolist(), tru, tol)
        m = brute_force_matches(np.sort(det), np.sort(tru), tol)
        assert score.precision == (m / len(det) if len(det) else 1.0)
        assert score.recall == (m / len(tru) if len(tru) else 1.0)
    # the states' score is the indices' score of their rising edges
    truth = np.zeros(20, bool); truth[2:6] = True; truth[10:15] = True
    found = np.zeros(20, bool); found[4:6] = True; found[7:8] = True; found[11:15] = True
    assert score_events(contact_events(found), contact_events(truth), 2) == event_precision_recall(found, truth, 2)
    assert score_events([9, 3.0], [2], 2) == (0.5, 1.0, 1.0)               # whole floats are indices
    for bad, match in (([1.5], "detected"), ([-1], "detected"), ([[1, 2]], "detected"), ([float("nan")], "detected")):
        with pytest.raises(ValueError, match=match):
            score_events(bad, [2], 2)
    with pytest.raises(ValueError, match="tolerance"):
        score_events([1], [2], -1)


def test_hand_worked_score_and_empty_conventions():
    truth = np.zeros(20, bool); truth[2:6] = True; truth[10:15] = True
    found = np.zeros(20, bool); found[4:6] = True; found[7:8] = True; found[11:15] = True; found[18:19] = True
    s = event_precision_recall(found, truth, 2)
    # true 2 <- detected 4 (+2); true 10 <- detected 7? no (|7 - 10| = 3 > 2) <- 11 (+1); 7 and 18 unmatched
    assert s.precision == 2 / 4 and s.recall == 1.0 and s.mean_delay_samples == 1.5
    none = np.zeros(20, bool)
    assert tuple(event_precision_recall(none, truth, 2)) == (1.0, 0.0, 0.0)
    assert tuple(event_precision_recall(found, none, 2)) == (0.0, 1.0, 0.0)
    with pytest.raises(ValueError, match="truth"):
        event_precision_recall(found, truth[:-1], 2)


def test_hysteresis_and_debounce_fix_the_chatter_of_a_plain_threshold_on_a_gait():
    # four legs, 20 strides each: an impact of 2 samples at 11 N, a rebound of 2 samples at 0-1.5 N,
    # then stance at 7 N; 0.3 N noise throughout
    pairs = [gait_forces(seed=s) for s in range(4)]
    force = np.column_stack([p[0] for p in pairs])
    truth = np.column_stack([p[1] for p in pairs])
    naive = event_precision_recall(detect_contacts(force, 3.0, 2.999, 1), truth, 10)
    hysteresis = event_precision_recall(detect_contacts(force, 3.0, 1.0, 1), truth, 10)
    tuned = event_precision_recall(detect_contacts(force, 3.0, 1.0, 3), truth, 10)
    assert naive.recall == 1.0 and naive.precision == 0.5                # every rebound is a touchdown
    assert hysteresis.recall == 1.0 and 0.5 < hysteresis.precision < 0.7  # rebounds above 1 N no longer count
    assert tuned.precision == 1.0 and tuned.recall == 1.0
    # the delay by hand: the first rebound sample below threshold_off restarts the debounce after
    # the rebound (touchdown + 4 + 2 samples), otherwise the impact itself is accepted (+ 2)
    starts = [contact_events(truth[:, j]) for j in range(4)]
    want = [6 if force[k + 2, j] < 1.0 else 2 for j in range(4) for k in starts[j]]
    assert tuned.mean_delay_samples == pytest.approx(np.mean(want), abs=1e-12)
    assert 2.0 < tuned.mean_delay_samples < 6.0
    # a tolerance below the delay turns correct detections into misses and false alarms
    assert event_precision_recall(detect_contacts(force, 3.0, 1.0, 3), truth, 5).recall < 0.5


def test_gate_touchdowns_keeps_the_first_detection_near_each_planned_one():
    from robokit.legged.touchdown import gate_touchdowns
    assert gate_touchdowns([3, 40, 52, 95], [50, 100], 10).tolist() == [40, 95]
    assert gate_touchdowns([45, 48, 52], [50], 5).tolist() == [45]          # one per planned touchdown
    assert gate_touchdowns([45, 48], [50, 52], 5).tolist() == [45, 48]      # a detection is used once
    assert gate_touchdowns([], [10, 20], 3).tolist() == []
    assert gate_touchdowns([10, 20], [], 3).tolist() == []
    # brute force on random cases: the same as scanning the detections in order
    rng = np.random.default_rng(0)
    for _ in range(200):
        det = np.sort(rng.choice(300, rng.integers(0, 20), replace=False))
        exp = np.sort(rng.choice(300, rng.integers(0, 10), replace=False))
        w = int(rng.integers(0, 15))
        want, used = [], set()
        for p in exp:
            for d in det:
                if abs(d - p) <= w and d not in used and (not want or d > want[-1]):
                    want.append(int(d))
                    used.add(d)
                    break
        assert gate_touchdowns(det, exp, w).tolist() == want
    assert gate_touchdowns([5, 3], [4], 2).tolist() == [3]                   # any order: sorted first
    with pytest.raises(ValueError, match="detected"):
        gate_touchdowns([-5, 3], [4], 2)
    with pytest.raises(ValueError, match="window"):
        gate_touchdowns([5], [4], -1)
