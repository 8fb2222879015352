"""Assignment 05: registration and check() rejecting wrong answers (references: test_exercises_references.py)."""
from __future__ import annotations

import numpy as np
import pytest

from robocourse.lessons.gps_sonar_truck import exercises as module
from robocourse.grading import check
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes

EXERCISES = {ex.id: ex for ex in module.EXERCISES}


def test_assignment_is_registered():
    assert module.ASSIGNMENT == "05_gps_sonar_truck"
    assert [e.id for e in exercises_for("05_gps_sonar_truck")] == list(EXERCISES)
    assert len(EXERCISES) >= 7 and set(module.WRITTEN) == {"05.calibration_drive", "05.bearing_near_waypoint",
                                                           "05.gps_accuracy"}


def test_cases_differ_between_seeds():
    ex = EXERCISES["05.fix_position"]
    assert ex.make_cases(1)[0].args != ex.make_cases(2)[0].args


def _wrong_checksum(sentence):
    return "00"


def _wrong_position(sentence):  # forgets that the minutes are minutes
    fields = sentence.split(",")
    i = 3 if "RMC" in fields[0] else 2
    return [float(fields[i]) / 100, float(fields[i + 2]) / 100]


def _wrong_offset(origin, point):  # forgets that a parallel is a smaller circle than a meridian
    if len(origin) != 2 or len(point) != 2 or abs(origin[0]) > 90 or abs(point[0]) > 90:
        raise ValueError("origin, point")
    return [6371008.8 * np.radians((point[1] - origin[1] + 180) % 360 - 180), 6371008.8 * np.radians(point[0] - origin[0])]


def _wrong_pulse(pulse_width_us):
    inches = pulse_width_us / 148.0
    return {"inches": inches, "cm": inches * 2.54}


def _stand_still(course):
    if not course["waypoints"]:
        raise ValueError("course")
    return [[0.0, 0.0]] * 100


def _wrong_gains(tau, overshoot, settling_time):
    return np.array([1.0, 0.1])


def _first_to_last(fixes, compass_deg):   # a tempting shortcut: course from two fixes, plain mean of degrees
    p = np.asarray(fixes, dtype=float)
    if len(p) < 2 or len(compass_deg) != len(p):
        raise ValueError("fixes")
    course = np.degrees(np.arctan2(*(p[-1] - p[0])))
    return float((np.mean(compass_deg) - course + 180) % 360 - 180)


WRONG = {"05.compass_bias": _first_to_last, "05.nmea_checksum": _wrong_checksum, "05.fix_position": _wrong_position,
         "05.local_offset": _wrong_offset, "05.pulse_to_distance": _wrong_pulse,
         "05.drive_course": _stand_still, "05.heading_gains": _wrong_gains}


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_fails_a_wrong_implementation(exercise_id, capsys):
    with pytest.raises(AssertionError, match=exercise_id) as failed:
        check(exercise_id, WRONG[exercise_id])
    assert "FAIL" in str(failed.value)          # the failed cases, in the message students see


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_passes_the_reference(exercise_id, capsys):
    assert_check_passes(exercise_id, EXERCISES[exercise_id].answer, len(EXERCISES[exercise_id].make_cases(2024)))


def _hemisphere_ignored(sentence):
    return [abs(v) for v in module.fix_position(sentence)]


def _minutes_as_hundredths(sentence):
    lat, lon = module.fix_position(sentence)
    def read(x):
        d = np.floor(abs(x))
        return np.sign(x) * (d + (abs(x) - d) * 60 / 100)
    return [read(lat), read(lon)]


def _other_field(sentence):                     # GGA's places used for RMC too: time and status read
    fields = sentence.split(",")
    return [float(fields[2][:2]) + float(fields[2][2:]) / 60 if fields[2][:1].isdigit() else 0.0,
            float(fields[4][:3]) + float(fields[4][3:]) / 60 if fields[4][:1].isdigit() else 0.0]


@pytest.mark.parametrize("wrong, words", [(_hemisphere_ignored, ["wrong sign", "hemisphere letter"]),
                                          (_minutes_as_hundredths, ["hundredths of a degree"]),
                                          (_other_field, ["latitude", "longitude"])])
def test_fix_position_feedback_names_the_coordinate_and_the_misreading(wrong, words):
    ex = EXERCISES["05.fix_position"]
    messages = [ex.compare(ex.answer(*c.args), wrong(*c.args)) for c in ex.make_cases(3) if not c.raises]
    failed = [m for m in messages if m]
    assert failed and all(all(w in m for w in words) for m in failed[:1]), failed[:2]


def test_local_offset_feedback_names_the_term():
    ex = EXERCISES["05.local_offset"]
    far_north = next(c for c in ex.make_cases(4) if c.label.startswith("far north"))
    message = ex.compare(ex.answer(*far_north.args), _wrong_offset(*far_north.args))
    assert message.startswith("east:") and "longitude term" in message and "north" not in message.split(";")[0][:6]
    swapped = ex.compare(ex.answer(*far_north.args), ex.answer(*far_north.args)[::-1])
    assert "swapped" in swapped


def _equidistant(origin, point):                # another sound local map: haversine distance and bearing
    from robokit.outdoor import haversine_distance_bearing
    d, b = haversine_distance_bearing(*np.radians([*origin, *point]))
    return [d * np.sin(b), d * np.cos(b)]


@pytest.mark.parametrize("seed", range(5))
def test_local_offset_accepts_another_sound_local_map(seed):
    ex = EXERCISES["05.local_offset"]
    for c in ex.make_cases(seed):
        if not c.raises:
            assert ex.compare(ex.answer(*c.args), _equidistant(*c.args)) is None, c.label


def _course_from(fixes, compass_deg, a, b):   # course from fix a to fix b, circular mean of the readings
    p = np.asarray(fixes, dtype=float)
    if len(p) < 2 or len(compass_deg) != len(p):
        raise ValueError("fixes")
    r = np.radians(compass_deg)
    mean = np.degrees(np.arctan2(np.sin(r).mean(), np.cos(r).mean()))
    return float((mean - np.degrees(np.arctan2(*(p[b] - p[a]))) + 180) % 360 - 180)


SHORTCUTS = {"no bias at all": lambda f, c: 0.0 if len(f) >= 2 and len(c) == len(f) else _course_from(f, c, 0, 0),
             "first fix to last": lambda f, c: _course_from(f, c, 0, -1),
             "fourth fix to last": lambda f, c: _course_from(f, c, 3, -1)}


@pytest.mark.parametrize("seed", range(10))
def test_the_reference_is_the_truth(seed):
    """On every kind of drive in the cases the reference is within 0.6 degree of the compass's true bias,
    so any sound estimate passes the 1-degree tolerance."""
    rng = np.random.default_rng(seed)
    for label, kwargs in module.BIAS_DRIVES:
        kw = dict(kwargs, poor=int(rng.integers(2, 9)) if kwargs.get("poor") else 0)
        fixes, compass, bias = module.calibration_drive(rng, **kw)
        assert 1.5 <= abs(bias) <= 5.0
        assert abs(module.compass_bias(fixes, compass) - bias) < 0.6, (label, kw)


@pytest.mark.parametrize("name", list(SHORTCUTS))
def test_shortcuts_score_little(name):
    """Scored as the grader does (the bad-input cases count only once a value case passes), each shortcut
    gets at most about a third of the points on average over 40 seeds, and never full marks."""
    fn, scores = SHORTCUTS[name], []
    for seed in range(40):
        cases = EXERCISES["05.compass_bias"].make_cases(seed)
        values = [c for c in cases if not c.raises]
        ok = sum(_close_enough(fn, c) for c in values)
        scores.append((ok + (len(cases) - len(values)) * (ok > 0)) / len(cases))
    assert max(scores) < 1 and np.mean(scores) <= 0.42, (name, np.mean(scores))


def test_the_cases_vary_the_bias_sign_and_the_poor_fixes():
    biases, counts = [], set()
    for seed in range(30):
        poor = int(np.random.default_rng(seed).integers(2, 9))
        fixes, compass, bias = module.calibration_drive(np.random.default_rng(seed), poor=poor)
        clean = module.calibration_drive(np.random.default_rng(seed), poor=0)[0]
        biases.append(bias)
        counts.add(int(np.sum(np.hypot(*(fixes - clean).T) > 1.0)))
    assert min(biases) < -1.5 and max(biases) > 1.5 and len(counts) >= 3


def _close_enough(fn, case):
    return abs(fn(*case.args) - module.compass_bias(*case.args)) <= 1.0
