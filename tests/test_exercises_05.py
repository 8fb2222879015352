"""Assignment 05: registration and check() rejecting wrong answers (references: test_exercises_references.py)."""
from __future__ import annotations

import numpy as np
import pytest

from robokit.exercises import gps_sonar_truck as module
from robokit.grading import check, exercises_for
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


def _wrong_haversine(lat1, lon1, lat2, lon2):  # flat Earth, bearing counter-clockwise from east
    dy, dx = lat2 - lat1, (lon2 - lon1) * np.cos(lat1)
    return np.array([6371008.8 * np.hypot(dx, dy), np.arctan2(dy, dx) % (2 * np.pi)])


def _wrong_pulse(pulse_width_us):
    inches = pulse_width_us / 148.0
    return {"inches": inches, "cm": inches * 2.54}


def _always_forward(ranges, front=1.2, side=0.8, prefer="left"):
    return "forward"


def _wrong_gains(tau, overshoot, settling_time):
    return np.array([1.0, 0.1])


def _first_to_last(fixes, compass_deg):   # a tempting shortcut: course from two fixes, plain mean of degrees
    p = np.asarray(fixes, dtype=float)
    if len(p) < 2 or len(compass_deg) != len(p):
        raise ValueError("fixes")
    course = np.degrees(np.arctan2(*(p[-1] - p[0])))
    return float((np.mean(compass_deg) - course + 180) % 360 - 180)


WRONG = {"05.compass_bias": _first_to_last, "05.nmea_checksum": _wrong_checksum, "05.fix_position": _wrong_position,
         "05.haversine": _wrong_haversine, "05.pulse_to_distance": _wrong_pulse,
         "05.avoidance_decision": _always_forward, "05.heading_gains": _wrong_gains}


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_fails_a_wrong_implementation(exercise_id, capsys):
    with pytest.raises(AssertionError, match=exercise_id) as failed:
        check(exercise_id, WRONG[exercise_id])
    assert "FAIL" in str(failed.value)          # the failed cases, in the message students see


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_passes_the_reference(exercise_id, capsys):
    assert_check_passes(exercise_id, EXERCISES[exercise_id].reference, len(EXERCISES[exercise_id].make_cases(2024)))


@pytest.mark.parametrize("seed", range(10))
def test_the_open_exercise_is_fair(seed):
    """The reference's estimate is within 0.6 degree of the compass's true bias on every kind of drive (so
    any sound estimate passes the 1-degree tolerance), and the two-fix shortcut fails some cases."""
    rng = np.random.default_rng(seed)
    fooled = 0
    for kwargs in ({}, {}, {"heading": 359.6, "bias": 0.8}, {"poor_start": 4.0}):
        fixes, compass, bias = module._calibration_drive(rng, **kwargs)
        estimate = module.compass_bias(fixes, compass)
        assert abs(estimate - bias) < 0.6, (kwargs, estimate, bias)
        fooled += abs(_first_to_last(fixes, compass) - estimate) > 1.0
    assert fooled >= 1
    cases = EXERCISES["05.compass_bias"].make_cases(seed)
    assert sum(not _close_enough(_first_to_last, c) for c in cases if not c.raises) >= 1


def _close_enough(fn, case):
    return abs(fn(*case.args) - module.compass_bias(*case.args)) <= 1.0
