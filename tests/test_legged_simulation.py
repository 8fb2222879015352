"""LittleDog walking in MuJoCo with the servo and host loops (robokit.legged.simulation)."""
import numpy as np
import pytest

from robokit.controllers import LITTLEDOG_MOTOR, motor_current
from robokit.legged import crawl_gait, load_trial, save_trial, stability_margins, trot_gait, walking_plan
from robokit.legged.simulation import LoopSettings, SensorSettings, simulate_walk


@pytest.fixture(scope="module")
def crawl():
    plan = walking_plan(crawl_gait(period=2.0, step_height=0.04), 0.3)
    return plan, simulate_walk(plan, rng=1)


def test_crawl_keeps_a_positive_margin_over_the_true_contacts(crawl):
    plan, out = crawl
    log = out.log
    assert not out.fell and len(log) == len(plan.t)
    assert out.distance == pytest.approx(0.3, abs=0.03)
    margin = stability_margins(log.feet[:, :, :2], log.contact, log.com[:, :2])   # MuJoCo's truth, not the plan
    assert margin.min() > 0.005
    assert (plan.stance == log.contact).mean() > 0.9          # the feet touch down about when planned


def test_log_holds_what_the_host_saw_and_survives_a_file(crawl, tmp_path):
    _, out = crawl
    log = out.log
    assert log.meta["gait"] == "crawl" and log.meta["servo_rate"] == 500.0
    # the servo's set-point is what the host sent one cycle before (no latency)
    np.testing.assert_allclose(log.q_ref[2:], log.q_cmd[1:-1])
    # standing still, the IMU reads gravity (plus its bias); the feet carry the robot
    assert log.imu_acc[25:50, 2].mean() == pytest.approx(9.81 + 0.08, abs=0.05)
    assert log.foot_force[25:50].sum(axis=1).mean() > 10
    seen = log.mocap_visible.any(axis=1)                       # frames outside the whole-trunk bursts
    assert log.mocap_visible[seen].mean() == pytest.approx(0.95, abs=0.02)   # 5 % of markers occluded
    assert 0.02 < 1 - seen.mean() < 0.25                      # bursts: 0.005 per frame x 20 frames
    back = load_trial(save_trial(tmp_path / "crawl.npz", log))
    for name in ("q", "mocap", "contact", "t"):
        np.testing.assert_array_equal(getattr(back, name), getattr(log, name))


def test_energy_standing_still_is_the_copper_loss_of_the_holding_currents():
    """Standing, each joint holds a constant voltage at zero speed: the motors draw sum V^2 / R."""
    stand = walking_plan(crawl_gait(), 0.3)._replace(gait="stand")
    n = 201
    plan = stand._replace(t=stand.t[:n], T_world_body=np.repeat(stand.T_world_body[:1], n, 0),
                          feet_world=np.repeat(stand.feet_world[:1], n, 0), stance=stand.stance[:n],
                          margin=stand.margin[:n])
    out = simulate_walk(plan)
    v = out.log.voltage[-1]
    assert np.abs(out.log.qd[-1]).max() < 1e-3
    steady = float((v ** 2).sum() / LITTLEDOG_MOTOR.resistance)
    assert steady > 1.0                                        # a few watts just to stand
    # the first 0.5 s include settling onto the feet; after that the draw is steady
    late = simulate_walk(plan._replace(t=plan.t[:101], T_world_body=plan.T_world_body[:101],
                                       feet_world=plan.feet_world[:101], stance=plan.stance[:101],
                                       margin=plan.margin[:101]))
    assert (out.energy - late.energy) == pytest.approx(steady * 1.0, rel=0.02)
    assert np.allclose(motor_current(v, 0.0, LITTLEDOG_MOTOR), v / LITTLEDOG_MOTOR.resistance)


def test_latency_and_a_slow_servo_hurt_tracking():
    plan = walking_plan(trot_gait(step_height=0.04), 0.15)
    base = simulate_walk(plan)
    late = simulate_walk(plan, LoopSettings(latency=0.03))
    assert late.tracking_rms > 1.5 * base.tracking_rms
    lossy = simulate_walk(plan, LoopSettings(loss=0.3), rng=4)
    assert 0.2 < lossy.link["lost"] / lossy.link["sent"] < 0.4


@pytest.mark.parametrize("rate", [250.0, 40.0])
def test_a_servo_period_that_does_not_divide_the_host_period_keeps_its_own_clock(rate):
    """The servo ticks every 1 / rate s of simulated time, not afresh in every 10 ms host period.

    The host logs the voltage the servo holds at each host cycle, so the logged voltage changes at
    cycle k exactly when a tick fell in the period before it. (A 250 Hz servo used to overrun the
    tick arrays, and a 40 Hz one ticked once every 10 ms with a 25 ms time step.)
    """
    plan = walking_plan(trot_gait(), 0.05)
    out = simulate_walk(plan, LoopSettings(servo_rate=rate), rng=3)
    servo_ms, n = round(1000 / rate), len(plan.t)
    # ms, up to the last host cycle; the tick at 0 holds 0 V (the robot starts in the plan's posture)
    ticks = np.arange(servo_ms, 10 * (n - 1), servo_ms)
    expected = np.unique(ticks // 10 + 1)                            # the first cycle to see each tick
    changed = np.nonzero(np.any(np.diff(out.log.voltage, axis=0) != 0, axis=1))[0] + 1
    np.testing.assert_array_equal(changed, expected)
    assert not out.fell and out.log.meta["servo_rate"] == rate


def test_bad_settings_are_named():
    with pytest.raises(ValueError, match="servo_rate"):
        LoopSettings(servo_rate=300)
    with pytest.raises(ValueError, match="loss"):
        LoopSettings(loss=1.0)
    with pytest.raises(ValueError, match="gains"):
        LoopSettings(gains=(1.0,))
    with pytest.raises(TypeError, match="plan"):
        simulate_walk("crawl")
    with pytest.raises(TypeError, match="sensors"):
        simulate_walk(walking_plan(trot_gait(), 0.05), sensors={})


@pytest.mark.parametrize("field, value, error", [
    ("force_noise", np.nan, ValueError), ("gyro_noise", -0.1, ValueError), ("mocap_dropout", 1.5, ValueError),
    ("mocap_burst_length", 2.5, TypeError), ("gyro_bias", (0.0, 0.0), ValueError), ("acc_bias", "abc", TypeError)])
def test_bad_sensor_settings_are_named_before_any_walk(field, value, error):
    # found by the fuzz: SensorSettings took anything, and a NaN noise or a 2-vector bias surfaced (if at all)
    # only after the whole MuJoCo walk had run, named by the sensor model's argument, not the setting
    with pytest.raises(error, match=rf"^{field}: "):
        SensorSettings(**{field: value})


def test_a_plan_with_nan_or_uneven_steps_is_refused_by_name():
    plan = walking_plan(trot_gait(), 0.05)
    feet = plan.feet_world.copy()
    feet[3, 1, 2] = np.nan
    with pytest.raises(ValueError, match="plan.feet_world"):
        simulate_walk(plan._replace(feet_world=feet))
    t = plan.t.copy()
    t[5:] += 0.003
    with pytest.raises(ValueError, match="plan.t"):
        simulate_walk(plan._replace(t=t))


def test_mujoco_actuators_apply_the_dc_motor_model():
    """With a motor, the MJCF's affine actuators give exactly controllers.joint_torque (clipped voltage too)."""
    import mujoco

    from robokit.controllers import joint_torque
    from robokit.legged import littledog_model

    model = littledog_model(motor=LITTLEDOG_MOTOR)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(3)
    for _ in range(5):
        data.qvel[6:] = rng.uniform(-10, 10, 12)
        data.ctrl[:] = rng.uniform(-20, 20, 12)          # beyond +-14.8 V: the driver saturates
        mujoco.mj_forward(model, data)
        np.testing.assert_allclose(data.actuator_force, joint_torque(data.ctrl, data.qvel[6:], LITTLEDOG_MOTOR),
                                   rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(model.dof_armature[6:], LITTLEDOG_MOTOR.rotor_inertia * LITTLEDOG_MOTOR.gear_ratio ** 2)


def test_with_perfect_sensors_the_log_integrates_to_the_truth():
    """The log's IMU rows and the estimators agree on timing: with ideal sensors, integrating the
    gyro follows the true orientation, and the fused position follows the true one."""
    from robokit.legged import SensorSettings, integrate_gyro, orientation_errors
    from robocourse.lessons.littledog.experiment import estimation_table

    perfect = SensorSettings(mocap_noise=0.0, mocap_dropout=0.0, mocap_bursts=0.0, gyro_noise=0.0, acc_noise=0.0,
                             gyro_bias=(0.0, 0.0, 0.0), acc_bias=(0.0, 0.0, 0.0), force_noise=0.0)
    out = simulate_walk(walking_plan(trot_gait(step_height=0.04), 0.2), sensors=perfect)
    T = out.log.T_world_body()
    R = integrate_gyro(T[0, :3, :3], out.log.imu_gyro, 0.01)
    assert np.degrees(orientation_errors(R, T[:, :3, :3])).max() < 0.3     # one sample late: about 1 deg
    shifted = integrate_gyro(T[0, :3, :3], np.roll(out.log.imu_gyro, 1, axis=0), 0.01)
    assert np.degrees(orientation_errors(shifted, T[:, :3, :3])).max() > 0.5
    table = estimation_table(out.log)
    assert table["mocap"]["position_mm"] < 1e-9 and table["fused"]["position_mm"] < 0.5


def test_the_imu_alone_drifts_as_its_biases_predict():
    """Tilt grows as the horizontal gyro bias times t, position as g b t^3 / 6; with no bias, neither."""
    from robocourse.lessons.littledog.experiment import imu_drift

    plan = walking_plan(crawl_gait(), 0.2)
    drift = imu_drift(simulate_walk(plan, rng=0).log)
    late = drift.t > 0.5 * drift.t[-1]
    assert np.allclose(drift.tilt_error[late], drift.tilt_rate * drift.t[late], rtol=0.05)
    assert np.allclose(drift.position_error[late], drift.from_tilt[late], rtol=0.25)
    assert np.all(drift.from_acc_bias[late] < 0.5 * drift.position_error[late])
    still = SensorSettings(gyro_bias=(0.0, 0.0, 0.0), acc_bias=(0.0, 0.0, 0.0))
    quiet = imu_drift(simulate_walk(plan, sensors=still, rng=0).log, still)
    assert quiet.tilt_rate == 0.0 and quiet.position_error[-1] < 0.1 * drift.position_error[-1]
    with pytest.raises(TypeError, match="sensors"):
        imu_drift(simulate_walk(plan, rng=0).log, {"gyro_bias": (0, 0, 0)})
