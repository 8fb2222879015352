"""The reactive host: integral feedback of the trunk pose (robokit.legged.posture) and its walks."""
import numpy as np
import pytest

from robokit import legged
from robokit.geometry import rot_x, se3_from_rt
from robokit.legged import PostureFeedback, delay_gain_limit
from robocourse.lessons.littledog import experiment


def _decays(a: float, d: int, steps: int = 3000) -> bool:
    """Does e[k+1] = e[k] - a e[k-d] die out from a unit error?"""
    e = np.zeros(steps + d + 1)
    e[: d + 1] = 1.0
    for k in range(d, steps + d):
        e[k + 1] = e[k] - a * e[k - d]
    return abs(e[-1]) < 1e-3


@pytest.mark.parametrize("d", [0, 1, 2, 3, 5, 8])
def test_delay_gain_limit_separates_decaying_from_growing_loops(d):
    limit = delay_gain_limit(d)
    assert _decays(0.95 * limit, d, steps=20000)
    assert not _decays(1.05 * limit, d)


def test_delay_gain_limit_refuses_a_negative_delay():
    with pytest.raises(ValueError, match="delay_cycles"):
        delay_gain_limit(-1)


@pytest.mark.parametrize("kwargs, name", [({"gain": 0.0}, "gain"), ({"gain": float("nan")}, "gain"),
                                          ({"axes": ("z", "z")}, "axes"), ({"axes": ()}, "axes"),
                                          ({"axes": ["z"]}, "axes"), ({"limit": (0.03,)}, "limit"),
                                          ({"limit": (0.03, -1.0)}, "limit")])
def test_posture_feedback_refuses_bad_settings_by_name(kwargs, name):
    with pytest.raises((ValueError, TypeError), match=name):
        PostureFeedback(**kwargs)


def test_a_trunk_too_high_is_commanded_lower_by_gain_dt_of_the_error_each_cycle():
    loop = PostureFeedback(gain=20.0).start(0.01)
    plan = se3_from_rt(np.eye(3), [0.1, 0.0, 0.13])
    seen = se3_from_rt(np.eye(3), [0.1, 0.0, 0.14])       # 1 cm above the plan
    first = loop.command(plan, seen)
    second = loop.command(plan, seen)
    assert first[2, 3] == pytest.approx(0.13 - 0.2 * 0.01)
    assert second[2, 3] == pytest.approx(0.13 - 0.4 * 0.01)
    assert np.allclose(first[:2, 3], plan[:2, 3]) and np.allclose(first[:3, :3], np.eye(3))
    held = loop.command(plan, None)                      # no MoCap pose: the correction stays
    assert held[2, 3] == pytest.approx(second[2, 3])


def test_a_rolled_trunk_is_commanded_rolled_the_other_way_and_unlisted_axes_stay():
    loop = PostureFeedback(gain=50.0, axes=("roll",)).start(0.01)
    plan = se3_from_rt(np.eye(3), [0.0, 0.0, 0.13])
    seen = se3_from_rt(rot_x(0.1), [0.02, 0.0, 0.15])
    T = loop.command(plan, seen)
    assert np.allclose(T[:3, :3], rot_x(-0.05), atol=1e-12)
    assert np.allclose(T[:3, 3], plan[:3, 3])            # position errors are not corrected


def test_the_correction_is_bounded():
    loop = PostureFeedback(gain=100.0, limit=(0.01, 0.05)).start(0.01)
    plan = se3_from_rt(np.eye(3), [0.0, 0.0, 0.13])
    for _ in range(50):
        T = loop.command(plan, se3_from_rt(rot_x(0.5), [0.0, 0.0, 0.2]))
    assert T[2, 3] == pytest.approx(0.12)
    assert np.allclose(T[:3, :3], rot_x(-0.05), atol=1e-12)


@pytest.fixture(scope="module")
def crawl():
    return experiment.lesson_plans(0.2)["crawl"]


def test_a_reactive_host_removes_the_sag_a_plan_playing_host_leaves(crawl):
    fixed = legged.simulate_walk(crawl, rng=0)
    reactive = legged.simulate_walk(crawl, host=PostureFeedback(gain=20.0), rng=0)
    _, sag_fixed = experiment.posture_errors(fixed.log, crawl)
    _, sag_reactive = experiment.posture_errors(reactive.log, crawl)
    assert not fixed.fell and not reactive.fell
    assert sag_fixed > 2.0 and sag_reactive < 0.5 * sag_fixed


def test_the_log_holds_the_mocap_frames_the_reactive_host_saw(crawl):
    out = legged.simulate_walk(crawl, host=PostureFeedback(), rng=1)
    poses = legged.mocap_body_poses(legged.MARKERS, out.log.mocap, out.log.mocap_visible)
    truth = out.log.T_world_body()
    err = np.linalg.norm(poses.T_world_body[poses.ok, :3, 3] - truth[poses.ok, :3, 3], axis=1)
    assert poses.ok.mean() > 0.8 and np.median(err) < 0.002      # noisy markers around the true trunk
    again = legged.simulate_walk(crawl, host=PostureFeedback(), rng=1)
    assert np.array_equal(again.log.mocap, out.log.mocap) and np.array_equal(again.log.q, out.log.q)


def test_a_reactive_host_keeps_the_link_draws_of_its_seed(crawl):
    settings = legged.LoopSettings(latency=0.02, jitter=0.01, loss=0.2)
    fixed = legged.simulate_walk(crawl, settings, rng=4)
    reactive = legged.simulate_walk(crawl, settings, host=PostureFeedback(), rng=4)
    assert fixed.link == reactive.link


def test_latency_turns_a_fast_reactive_host_unstable_as_the_delay_bound_predicts(crawl):
    lag = experiment.host_lag().half_cycles
    host = PostureFeedback(gain=50.0)                  # 0.5 of the error per cycle
    assert 0.5 < delay_gain_limit(round(lag)) and 0.5 > delay_gain_limit(round(lag + 3))
    quick = legged.simulate_walk(crawl, host=host, rng=0)
    slow = legged.simulate_walk(crawl, legged.LoopSettings(latency=0.03), host=host, rng=0)
    tilt_quick, _ = experiment.posture_errors(quick.log, crawl)
    tilt_slow, _ = experiment.posture_errors(slow.log, crawl)
    assert tilt_quick < 1.0 and tilt_slow > 3 * tilt_quick


def test_host_lag_grows_by_the_link_latency():
    base = experiment.host_lag()
    late = experiment.host_lag(latency=0.03)
    assert 1.0 < base.half_cycles < 3.0
    assert late.half_cycles - base.half_cycles == pytest.approx(3.0, abs=0.5)
    assert 0.8 < base.response[-1] < 1.0          # the loaded legs settle short of the step (the sag)
    with pytest.raises(ValueError, match="step"):
        experiment.host_lag(0.5)


def test_host_table_rows_and_predictions(crawl):
    plan = experiment.lesson_plans(0.05)["crawl"]
    rows = experiment.host_table(plan, gains=(20.0, 80.0), latencies=(0.0, 0.03), losses=(0.0,))
    assert [(r["gain"], r["latency"]) for r in rows] == [(0.0, 0.0), (0.0, 0.03), (20.0, 0.0), (20.0, 0.03),
                                                         (80.0, 0.0), (80.0, 0.03)]
    for r in rows:
        if r["gain"] == 0:
            assert r["predicted_stable"] is None
        else:
            assert r["predicted_stable"] == (r["step_gain"] < delay_gain_limit(r["delay_cycles"]))
    assert rows[3]["delay_cycles"] - rows[2]["delay_cycles"] == 3
    with pytest.raises(ValueError, match="gains"):
        experiment.host_table(plan, gains=(-1.0,))
    with pytest.raises(ValueError, match="loss"):
        experiment.host_table(plan, losses=(1.5,))


def test_host_lag_refuses_what_it_cannot_measure():
    for kwargs, name in (({"step": 1e-9}, "step"), ({"latency": 0.45}, "latency"), ({"dt": 0.0105}, "dt"),
                         ({"latency": float("nan")}, "latency")):
        with pytest.raises(ValueError, match=f"^{name}: "):
            experiment.host_lag(**kwargs)


def test_a_reactive_trial_that_falls_logs_a_mocap_frame_on_its_last_row():
    plan = experiment.lesson_plans(0.05)["crawl"]
    out = legged.simulate_walk(plan, legged.LoopSettings(gains=(0.05, 0.0)), host=PostureFeedback(), rng=0)
    assert out.fell                                         # servos this weak let the trunk down
    last = out.log.mocap[-1][out.log.mocap_visible[-1]]
    truth = out.log.T_world_body()[-1]
    assert len(last) and np.all(np.abs(last[:, 2] - truth[2, 3]) < 0.1)   # markers where the trunk is
    assert out.log.meta["host"]["gain"] == PostureFeedback().gain


def test_the_reactive_host_sees_the_logged_trunk_pose():
    plan = experiment.lesson_plans(0.05)["crawl"]
    quiet = legged.SensorSettings(mocap_noise=0.0, mocap_dropout=0.0, mocap_bursts=0.0)
    out = legged.simulate_walk(plan, sensors=quiet, host=PostureFeedback(), rng=0)
    poses = legged.mocap_body_poses(legged.MARKERS, out.log.mocap, out.log.mocap_visible)
    np.testing.assert_allclose(poses.T_world_body[:, :3, 3], out.log.body_pos, atol=1e-9)
