"""Gait schedules, swing trajectories and walking plans: checked on the plan, against the model's facts."""
from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest

from robokit.legged.gait import GaitSchedule, crawl_gait, stance_pattern, swing_trajectory, trot_gait, walking_plan
from robokit.legged.support import stability_margin

LEGS = ("FL", "FR", "HL", "HR")
# The model's facts (tests/BRIEF): hip roll axes in the body frame, the hip-pitch axis 0.0236 m further
# out (0.0207 m on the hind-right leg, as the MIT model gives it).
HIPS = np.array([[0.101, 0.03625, 0.0], [0.101, -0.03625, 0.0], [-0.101, 0.03625, 0.0], [-0.101, -0.03625, 0.0]])
PITCH_POINTS = HIPS + np.array([[0, 1, 0], [0, -1, 0], [0, 1, 0], [0, -1, 0]]) * np.array([[0.0236], [0.0236], [0.0236],
                                                                                     [0.0207]])
REACH = 0.17
FOOT_Z = 0.01


@functools.cache
def crawl_plan():
    return walking_plan(crawl_gait(), 1.0)


@functools.cache
def trot_plan():
    return walking_plan(trot_gait(), 1.0)


def lift_offs(stance):
    """(sample, leg) of every lift-off: in stance at n - 1, in the air at n."""
    return np.argwhere(stance[:-1] & ~stance[1:]) + [1, 0]


def touchdowns(stance):
    return np.argwhere(~stance[:-1] & stance[1:]) + [1, 0]


# --- schedules ---------------------------------------------------------------------------------

def test_schedule_is_frozen_and_validated():
    g = crawl_gait()
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.period = 1.0
    with pytest.raises(ValueError):
        g.phase_offsets[0] = 0.5                       # read-only
    with pytest.raises(ValueError, match="duty_factor"):
        GaitSchedule("x", 1.0, 1.0, [0, 0.25, 0.5, 0.75], 0.05, 0.02)
    with pytest.raises(ValueError, match="phase_offsets"):
        GaitSchedule("x", 1.0, 0.8, [0, 0.25, 0.5, 1.0], 0.05, 0.02)
    with pytest.raises(ValueError, match="phase_offsets"):
        GaitSchedule("x", 1.0, 0.8, [0, 0.25, 0.5], 0.05, 0.02)
    with pytest.raises(ValueError, match="step_height"):
        GaitSchedule("x", 1.0, 0.8, [0, 0.25, 0.5, 0.75], 0.05, -0.01)
    with pytest.raises(ValueError, match="duty_factor: expected >= 0.75"):
        crawl_gait(duty_factor=0.7)
    with pytest.raises(ValueError, match="duty_factor: expected >= 0.5"):
        trot_gait(duty_factor=0.4)


def test_crawl_lifts_one_leg_at_a_time_hind_left_front_left_hind_right_front_right():
    g = crawl_gait()
    t = np.arange(0.0, 2 * g.period, 0.001)
    stance = stance_pattern(g, t)
    assert (~stance).sum(axis=1).max() == 1 and g.max_swinging == 1
    lifts = lift_offs(stance)
    order = [LEGS[leg] for _, leg in lifts[np.argsort(lifts[:, 0], kind="stable")]]
    assert order[:4] == ["FL", "HR", "FR", "HL"]       # starting after HL's lift at t = 0
    assert order[3:] == ["HL", "FL", "HR", "FR"]
    np.testing.assert_allclose(stance.mean(axis=0), g.duty_factor, atol=0.001)


def test_trot_swings_exactly_the_diagonals():
    g = trot_gait()
    stance = stance_pattern(g, np.arange(0.0, 3 * g.period, 0.0007))
    fl, fr, hl, hr = stance.T
    assert np.array_equal(fl, hr) and np.array_equal(fr, hl) and np.array_equal(fl, ~fr)
    assert g.max_swinging == 2
    np.testing.assert_allclose(stance.mean(axis=0), 0.5, atol=0.002)


def test_stance_pattern_shapes():
    assert stance_pattern(crawl_gait(), 0.0).shape == (1, 4)
    assert stance_pattern(crawl_gait(), 0.0).tolist() == [[True, True, False, True]]     # HL lifts at 0
    with pytest.raises(TypeError, match="schedule"):
        stance_pattern("crawl", [0.0])
    with pytest.raises(ValueError, match="t: expected"):
        stance_pattern(crawl_gait(), np.zeros((2, 2)))


# --- swing trajectory ----------------------------------------------------------------------------

def test_swing_starts_and_ends_at_rest_on_its_footholds():
    a, b, h = np.array([0.1, 0.08, FOOT_Z]), np.array([0.18, 0.08, FOOT_Z]), 0.03
    u = np.linspace(0.0, 1.0, 2001)
    p = swing_trajectory(a, b, u, h)
    np.testing.assert_allclose(p[0], a, atol=1e-15)
    np.testing.assert_allclose(p[-1], b, atol=1e-15)
    assert p[1000, 2] == pytest.approx(FOOT_Z + h)                   # peak at mid-swing
    assert p[:, 2].max() == pytest.approx(FOOT_Z + h)
    assert np.all(np.diff(p[:, 0]) >= 0) and np.all(p[:, 2] >= FOOT_Z)
    du = u[1] - u[0]
    v = np.gradient(p, du, axis=0)
    acc = np.gradient(v, du, axis=0)
    assert np.abs(v[[0, -1]]).max() < 1e-5                            # zero velocity at both ends
    assert np.abs(acc[[1, -2]]).max() < 0.01 * np.abs(acc).max()      # and (nearly) zero acceleration
    # the quintic's peak speed: 15/8 of the mean
    assert np.abs(v[:, 0]).max() == pytest.approx(15 / 8 * 0.08, rel=1e-4)


def test_swing_broadcasts_and_refuses_bad_phases():
    a = np.zeros((5, 3))
    b = np.ones((5, 3))
    assert swing_trajectory(a, b, np.linspace(0, 1, 5), 0.0).shape == (5, 3)
    assert swing_trajectory([0, 0, 0], [1, 0, 0], 0.5, 0.1).tolist() == [0.5, 0.0, 0.1]
    with pytest.raises(ValueError, match="phase"):
        swing_trajectory(a, b, [0.0, 1.5], 0.0)
    with pytest.raises(ValueError, match="phase, p_start, p_end"):
        swing_trajectory(a, b, np.linspace(0, 1, 4), 0.0)


# --- walking plans ---------------------------------------------------------------------------------

@pytest.mark.parametrize("plan_of", [crawl_plan, trot_plan])
def test_plan_shapes_start_and_end(plan_of):
    plan = plan_of()
    n = len(plan.t)
    assert plan.T_world_body.shape == (n, 4, 4) and plan.feet_world.shape == (n, 4, 3)
    assert plan.stance.shape == (n, 4) and plan.stance.dtype == bool and plan.margin.shape == (n,)
    np.testing.assert_allclose(np.diff(plan.t), 0.01, atol=1e-12)
    np.testing.assert_array_equal(plan.T_world_body[:, :3, :3], np.broadcast_to(np.eye(3), (n, 3, 3)))
    np.testing.assert_allclose(plan.T_world_body[:, 2, 3], 0.1315)
    body = plan.T_world_body[:, :3, 3]
    nominal = np.array([[0.16, 0.08], [0.16, -0.08], [-0.16, 0.08], [-0.16, -0.08]])
    # starts at rest in the nominal stance, settles (0.5 s), walks, stops with four feet down, settles
    assert plan.stance[:50].all() and plan.stance[-51:].all()
    np.testing.assert_allclose(body[:51], [[0.0, 0.0, 0.1315]] * 51, atol=1e-15)
    np.testing.assert_allclose(body[-51:], [[1.0, 0.0, 0.1315]] * 51, atol=1e-12)    # the body covers 1 m
    np.testing.assert_allclose(plan.feet_world[0, :, :2], nominal, atol=1e-15)
    np.testing.assert_allclose(plan.feet_world[-1, :, :2], nominal + [1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(plan.feet_world[[0, -1], :, 2], FOOT_Z)


@pytest.mark.parametrize("plan_of", [crawl_plan, trot_plan])
def test_feet_do_not_slide_in_stance_and_swings_join_the_footholds(plan_of):
    plan = plan_of()
    feet, stance = plan.feet_world, plan.stance
    held = stance[1:] & stance[:-1]
    np.testing.assert_array_equal(feet[1:][held], feet[:-1][held])        # constant while down
    np.testing.assert_allclose(feet[..., 2][stance], FOOT_Z, atol=1e-15)   # on the ground
    for n, leg in lift_offs(stance):
        # the first airborne sample is the swing at phase 0: where the foot stood
        np.testing.assert_allclose(feet[n, leg], feet[n - 1, leg], atol=1e-12)
    for n, leg in touchdowns(stance):
        # the last airborne sample is one step short of touchdown, a few mm from the foothold at most
        assert np.linalg.norm(feet[n - 1, leg] - feet[n, leg]) < 0.005
    assert np.all(feet[..., 2] <= FOOT_Z + 0.03 + 1e-12)


@pytest.mark.parametrize("plan_of", [crawl_plan, trot_plan])
def test_feet_stay_within_reach_and_below_the_hips(plan_of):
    plan = plan_of()
    body = plan.T_world_body[:, None, :3, 3]
    rel = plan.feet_world - body                                     # level body: world axes = body axes
    assert np.linalg.norm(rel - PITCH_POINTS, axis=-1).max() < REACH
    assert rel[..., 2].max() < 0.0


def test_crawl_keeps_a_positive_margin_and_the_margin_at_lift_off():
    plan, margin = crawl_plan(), 0.02
    assert np.all(plan.margin > 0) and plan.margin.min() == pytest.approx(margin, abs=1e-8)
    lifts = lift_offs(plan.stance)
    assert len(lifts) >= 4 * (1.0 / 0.08)
    for n, leg in lifts:
        others = [i for i in range(4) if i != leg]
        com = plan.T_world_body[n, :2, 3]
        assert plan.margin[n] >= margin
        assert stability_margin(plan.feet_world[n, others, :2], com) >= margin     # recomputed independently
    assert (~plan.stance).sum(axis=1).max() == 1


def test_crawl_body_moves_smoothly_and_only_with_four_feet_down():
    plan = crawl_plan()
    x = plan.T_world_body[:, :2, 3]
    v = np.diff(x, axis=0) / 0.01
    a = np.diff(v, axis=0) / 0.01
    assert np.abs(v).max() < 0.2 and np.abs(a).max() < 1.0                # no jumps in position or velocity
    assert np.abs(np.diff(a, axis=0)).max() < 0.1                           # nor in acceleration (C2 quintics)
    swinging = ~plan.stance.all(axis=1)
    still = swinging[1:] & swinging[:-1]
    np.testing.assert_array_equal(x[1:][still], x[:-1][still])             # the body waits while a leg swings


def test_plan_swings_follow_the_schedule():
    for g, plan in ((crawl_gait(), crawl_plan()), (trot_gait(), trot_plan())):
        first = lift_offs(plan.stance)[:, 0].min()
        tau = plan.t - plan.t[first] + g.phase_offsets[~plan.stance[first]].min() * g.period   # gait time
        pattern = stance_pattern(g, tau + 1e-9)             # (sample times and lift-offs round apart)
        assert not np.any(pattern & ~plan.stance)           # every planned swing is a scheduled one
        last = touchdowns(plan.stance)[:, 0].max()
        np.testing.assert_array_equal(plan.stance[first:last], pattern[first:last])   # and none is skipped


def test_trot_moves_at_constant_speed_with_diagonal_support():
    g, plan = trot_gait(), trot_plan()
    fl, fr, hl, hr = plan.stance.T
    assert np.array_equal(fl, hr) and np.array_equal(fr, hl)
    x = plan.T_world_body[:, 0, 3]
    v = np.diff(x) / 0.01
    # the speed ramps up over the first period after the 0.5 s settle, and down over the last one
    cruise = (plan.t[:-1] > 0.5 + g.period) & (plan.t[1:] < 0.5 + 1.0 / g.speed)
    assert cruise.sum() > 700
    np.testing.assert_allclose(v[cruise], g.speed, rtol=1e-9)
    assert np.all(v >= 0) and v.max() == pytest.approx(g.speed)
    two_feet = plan.stance.sum(axis=1) == 2
    assert np.all(plan.margin[two_feet] == -np.inf) and two_feet.mean() > 0.8
    assert np.all(plan.margin[plan.stance.all(axis=1)] > 0)


def test_other_sample_periods_and_distances():
    plan = walking_plan(crawl_gait(), 0.37, dt=0.003, settle=0.0)
    assert plan.T_world_body[-1, 0, 3] == pytest.approx(0.37) and plan.t[0] == 0.0
    assert np.all(plan.margin > 0)
    wide = np.array([[0.16, 0.1, -0.1215], [0.16, -0.1, -0.1215], [-0.16, 0.1, -0.1215], [-0.16, -0.1, -0.1215]])
    plan = walking_plan(crawl_gait(step_length=0.05), 0.2, nominal_feet=wide, margin=0.03)
    assert plan.margin.min() >= 0.03 and plan.feet_world[-1, 0, 1] == 0.1


def test_walking_plan_bad_input():
    with pytest.raises(ValueError, match="schedule: a crawl shifts its body"):
        walking_plan(crawl_gait(duty_factor=0.75), 1.0)
    with pytest.raises(ValueError, match="margin: expected less than the inradius"):
        walking_plan(crawl_gait(), 1.0, margin=0.08)
    with pytest.raises(ValueError, match="distance"):
        walking_plan(crawl_gait(), 0.0)
    with pytest.raises(TypeError, match="schedule"):
        walking_plan("crawl", 1.0)
    with pytest.raises(ValueError, match="nominal_feet"):
        walking_plan(crawl_gait(), 1.0, nominal_feet=[[0.1, 0.0, -0.1], [0.0, 0.0, -0.1], [-0.1, 0.0, -0.1],
                                                      [-0.2, 0.0, -0.1]])
    with pytest.raises(ValueError, match="distance, schedule: expected at most 100000 steps"):
        walking_plan(crawl_gait(), 1e9)
    with pytest.raises(ValueError, match="distance, dt, settle, schedule: expected at most"):
        walking_plan(crawl_gait(), 1.0, dt=1e-6)
