"""The heading loop of robokit.controllers, designed by pole placement and checked with python-control."""
from __future__ import annotations

import math

import control
import numpy as np
import pytest

from robokit.controllers import (design_heading_gains, heading_closed_loop, heading_frequency_response,
                                 heading_loop_gain, heading_plant, heading_step_response, loop_metrics)
from robokit.controllers import loop_metrics as outdoor_loop_metrics


def test_outdoor_re_exports_the_loop_design():
    assert outdoor_loop_metrics is loop_metrics   # lesson 05 and its assignment import it from robokit.outdoor


@pytest.mark.parametrize("overshoot, settling", [(0.05, 1.5), (0.10, 1.0), (0.02, 2.0)])
def test_designed_gains_meet_the_spec_in_python_control(overshoot, settling):
    kp, kd = design_heading_gains(0.3, overshoot, settling)
    T = heading_closed_loop(kp, kd, 0.3)
    info = control.step_info(T)
    assert info["Overshoot"] / 100 == pytest.approx(overshoot, rel=0.02)
    # 4 / (zeta omega_n) is the decay-envelope estimate: the true 2 % settling time is near it
    # (within 5 % above; the oscillation can enter the band earlier than the envelope does)
    assert 0.7 * settling < info["SettlingTime"] < 1.05 * settling
    wn, zeta, _ = control.damp(T, doprint=False)
    assert zeta[0] == pytest.approx(-math.log(overshoot) / math.hypot(math.pi, math.log(overshoot)))
    # the criterion is 2 % (Nise Sec. 4.6: 4 / (zeta omega_n)), not Franklin et al.'s 1 % (4.6 / (zeta omega_n)):
    # at the asked-for time the decay envelope exp(-zeta omega_n t) is inside 2 % but not yet inside 1 %
    envelope = math.exp(-zeta[0] * wn[0] * settling)
    assert 0.01 < envelope <= 0.02
    assert control.step_info(T, SettlingTimeThreshold=0.01)["SettlingTime"] > info["SettlingTime"]


def test_rate_feedback_turns_negative_beyond_eight_motor_time_constants():
    # kd = (8 tau / settling_time - 1) / gain, whatever the overshoot (the docstring's bound)
    for overshoot in (0.02, 0.2):
        assert design_heading_gains(0.3, overshoot, 2.39)[1] == pytest.approx(8 * 0.3 / 2.39 - 1)
        with pytest.raises(ValueError, match="settling_time"):
            design_heading_gains(0.3, overshoot, 2.41)


def test_margins_and_delay():
    kp, kd = design_heading_gains(0.3, 0.05, 1.5)
    m = loop_metrics(kp, kd, 0.3)
    assert m["gain_margin"] == math.inf and 60 < m["phase_margin_deg"] < 80
    gm, pm, *_ = control.stability_margins(heading_loop_gain(kp, kd, 0.3))
    assert pm == pytest.approx(m["phase_margin_deg"])
    slow = loop_metrics(kp, kd, 0.3, delay=0.05)   # half of the 10 Hz compass period
    assert slow["phase_margin_deg"] < m["phase_margin_deg"] and slow["overshoot"] > m["overshoot"]
    assert np.isfinite(slow["gain_margin"])
    assert heading_plant(0.3).poles().tolist() == pytest.approx([0.0, -1 / 0.3]) or \
        sorted(heading_plant(0.3).poles().real) == pytest.approx([-1 / 0.3, 0.0])


@pytest.mark.parametrize("args, words", [((0.3, 1.2, 1.0), "overshoot"), ((0.3, 0.05, -1.0), "settling_time"),
                                         ((0.3, 0.05, 30.0), "settling_time"), ((0.0, 0.05, 1.0), "tau")])
def test_design_bad_input(args, words):
    with pytest.raises(ValueError, match=words):
        design_heading_gains(*args)


def test_step_and_frequency_response_helpers():
    kp, kd = design_heading_gains(0.3, 0.05, 1.5)
    t, y = heading_step_response(kp, kd, 0.3)
    assert y.max() == pytest.approx(1.05, abs=1e-3) and y[-1] == pytest.approx(1.0, abs=1e-3)
    m = loop_metrics(kp, kd, 0.3)
    assert abs(heading_frequency_response(kp, kd, 0.3, [m["crossover"]])[0]) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="omega"):
        heading_frequency_response(kp, kd, 0.3, [0.0])
