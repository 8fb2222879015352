"""Lesson 04's experiment tables (robocourse.lessons.littledog.experiment): inputs refused by name, before any trial."""
import numpy as np
import pytest

from robokit.legged import trot_gait, walking_plan
from robocourse.lessons.littledog.experiment import TOUCHDOWN_DETECTORS, loop_table, touchdown_table
from tests.legged_logs import synthetic_log


@pytest.fixture(scope="module")
def log():
    return synthetic_log(30)


@pytest.mark.parametrize("detectors, error", [
    (42, TypeError), ("hysteresis", TypeError), (np.zeros(3), TypeError), ([("only a label",)], ValueError),
    ([], ValueError), ([("bad threshold", np.nan, 1.0, 1)], ValueError)])
def test_touchdown_table_names_bad_detectors(log, detectors, error):
    # found by the fuzz: 42 gave "'int' object is not iterable", a string "not enough values to unpack"
    with pytest.raises(error, match=r"^detectors(\[0\])?: "):
        touchdown_table(log, detectors)


def test_touchdown_table_names_a_bad_gate_and_tolerance(log):
    # found by the fuzz: gate=1.5 was refused as "window: expected an integer", the name inside gate_touchdowns
    plan = walking_plan(trot_gait(), 0.05)
    with pytest.raises(TypeError, match="^gate: "):
        touchdown_table(log, plan=plan, gate=1.5)
    with pytest.raises(ValueError, match="^tolerance: "):
        touchdown_table(log, tolerance=-1)


def test_touchdown_table_scores_each_detector_given(log):
    rows = touchdown_table(log, [TOUCHDOWN_DETECTORS[1]])
    assert [r["label"] for r in rows] == [TOUCHDOWN_DETECTORS[1][0]]
    rising = np.diff(np.asarray(log.contact).astype(int), axis=0) == 1     # a touchdown: swing -> stance
    assert rows[0]["true_touchdowns"] == int(rising.sum())


@pytest.mark.parametrize("kwargs, name", [
    ({"progress": 42}, "progress"), ({"servo_rates": (300.0,)}, "servo_rates"), ({"latencies": (-0.01,)}, "latencies"),
    ({"bandwidths": (0.0,)}, "bandwidths")])
def test_loop_table_refuses_bad_settings_before_the_first_trial(kwargs, name):
    # found by the fuzz: progress=42 ran a whole trial, then failed with "'int' object is not callable";
    # a servo rate of 300 Hz was refused as "servo_rate", a bandwidth of 0 as "bandwidth_hz"
    calls = []
    with pytest.raises((TypeError, ValueError), match=rf"^{name}: "):
        loop_table(walking_plan(trot_gait(), 0.02), **{"progress": lambda *a: calls.append(a), **kwargs})
    assert not calls
