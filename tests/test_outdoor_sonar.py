"""LV-MaxSonar-EZ model, the paper's layout, chained vs free-running firing, and the field geometry."""
from __future__ import annotations

import numpy as np
import pytest

from robokit.outdoor.field import Field, random_course
from robokit.outdoor.sonar import (INCH, PAPER_LAYOUT, SPEED_OF_SOUND, LVMaxSonarEZ, SonarMount, firing_schedule,
                                   pulse_width_to_cm_inches, pulse_width_to_range, range_to_pulse_width,
                                   read_sensors, sensor_poses, true_ranges)


def test_pulse_width_scale_matches_datasheet_and_sound_speed():
    assert pulse_width_to_range(147e-6) == pytest.approx(INCH)
    assert pulse_width_to_cm_inches(147 * 100) == pytest.approx({"inches": 100.0, "cm": 254.0})
    d = np.linspace(0.2, 6.0, 7)
    np.testing.assert_allclose(pulse_width_to_range(range_to_pulse_width(d)), d)
    # 147 us/inch is (within 1 %) the round trip of sound over one inch
    assert 2 * INCH / SPEED_OF_SOUND == pytest.approx(147e-6, rel=0.01)


@pytest.mark.parametrize("bad", [-1.0, float("nan"), 70000.0])
def test_pulse_width_bad_input(bad):
    with pytest.raises(ValueError, match="pulse_width_us"):
        pulse_width_to_cm_inches(bad)
    if bad != 70000.0:
        with pytest.raises(ValueError, match="pulse_width"):
            pulse_width_to_range(bad)


def test_sensor_limits_and_resolution():
    s = LVMaxSonarEZ()
    assert s.quantize(0.01) == pytest.approx(6 * INCH)
    assert s.quantize(np.inf) == pytest.approx(254 * INCH)
    assert s.quantize(1.0) == pytest.approx(round(1.0 / INCH) * INCH)
    assert s.listen_time < s.cycle  # an echo from max range returns within one cycle
    with pytest.raises(ValueError, match="NaN"):
        s.quantize(float("nan"))


def test_paper_layout_geometry():
    outer_l, mid_l, mid_r, outer_r = PAPER_LAYOUT
    assert outer_l.y - outer_r.y == pytest.approx(0.20) and mid_l.y - mid_r.y == pytest.approx(0.10)
    assert np.degrees(outer_l.yaw) == pytest.approx(45) and np.degrees(outer_r.yaw) == pytest.approx(-45)
    assert mid_l.yaw == mid_r.yaw == 0.0
    poses = sensor_poses([1.0, 2.0, np.pi / 2])
    np.testing.assert_allclose(poses[0], [1.0 - 0.10, 2.25, np.pi / 2 + np.pi / 4])
    # facing west, the left sensor's heading wraps past pi (it did not when sonar composed by hand)
    west = sensor_poses([1.0, 2.0, 0.9 * np.pi])
    assert np.all((-np.pi <= west[:, 2]) & (west[:, 2] < np.pi))
    np.testing.assert_allclose(west[0, 2], 0.9 * np.pi + np.pi / 4 - 2 * np.pi)


def test_schedules():
    chained = firing_schedule(4, 1.0)
    starts = np.sort(np.concatenate(chained))
    assert np.diff(starts).min() == pytest.approx(0.049)  # never two pings at once
    assert np.diff(chained[0]) == pytest.approx(4 * 0.049)
    free = firing_schedule(4, 1.0, "free", rng=3)
    assert all(np.allclose(np.diff(t), 0.049) for t in free)
    assert np.diff(np.sort(np.concatenate(free))).min() < 0.049
    with pytest.raises(ValueError, match="mode"):
        firing_schedule(4, 1.0, "random")


def test_true_ranges_sees_obstacles_in_cone_only():
    field = Field(circles=[[3.0, 0.0, 0.4]])
    r, hits = true_ranges(field, [0.0, 0.0, 0.0])
    assert r[1] == pytest.approx(3.0 - 0.4 - 0.25, abs=0.05) and r[2] == pytest.approx(r[1], abs=0.01)
    assert np.isinf(r[3]) and np.isnan(hits[3]).all()
    r2, _ = true_ranges(field, [0.0, 0.0, np.pi])
    assert np.isinf(r2).all()


def test_chained_has_no_crosstalk_free_running_does():
    field = Field(circles=[[2.5, 0.0, 0.3], [1.2, 1.2, 0.3]])
    pose = [0.0, 0.0, 0.0]
    truth = LVMaxSonarEZ().quantize(true_ranges(field, pose)[0])
    chained = read_sensors(field, pose, [0, 1, 2, 3], [0.0, 0.049, 0.098, 0.147], noise=0.0)
    np.testing.assert_allclose(chained, truth)
    rng = np.random.default_rng(0)
    wrong = 0
    for _ in range(200):
        t = rng.uniform(0, 0.049, 4)
        free = read_sensors(field, pose, [0, 1, 2, 3], t, others=dict(enumerate(t)), noise=0.0)
        wrong += np.any(np.abs(free - truth) > INCH)
    assert wrong > 20


def test_field_raycast_and_collision():
    field = Field(circles=[[10.0, 0.0, 1.0]], boxes=[[20.0, 0.0, 2.0, 2.0, 0.0]])
    d = field.raycast([[0.0, 0.0], [15.0, 0.0], [0.0, 5.0], [20.0, 0.0]], [0.0, 0.0, 0.0, 0.0], 30.0)
    np.testing.assert_allclose(d, [9.0, 4.0, 30.0, 0.0])
    assert field.collides([8.8, 0.0, 0.0], 0.5, 0.25) and not field.collides([8.7, 0.0, 0.0], 0.5, 0.25)
    assert field.collides([18.8, 0.0, 0.0], 0.5, 0.25) and not field.collides([18.7, 0.0, 0.0], 0.5, 0.25)
    assert field.collides([18.9, 0.9, np.pi / 4], 0.5, 0.25) and not field.collides([18.9, 1.1, np.pi / 4], 0.5, 0.25)
    np.testing.assert_allclose(field.clearance([[0.0, 0.0], [20.0, 3.0]]), [9.0, 2.0])


def test_random_course_is_seeded_and_keeps_waypoints_clear():
    a, b = random_course(7), random_course(7)
    np.testing.assert_array_equal(a.waypoints, b.waypoints)
    np.testing.assert_array_equal(a.field.circles, b.field.circles)
    assert a.field.n_obstacles == 14
    assert np.all(a.field.clearance(np.vstack([a.waypoints, a.start[:2]])) >= 2.0)
    assert not np.array_equal(random_course(8).waypoints, a.waypoints)


@pytest.mark.parametrize("call, words", [
    (lambda: Field(size=(0, 10)), "size"),
    (lambda: Field(circles=[[1, 1, -1]]), "radii"),
    (lambda: Field(origin=(0.1,)), "origin"),
    (lambda: Field().raycast([[0, 0], [1, 1]], [0, 1, 2], 5.0), "origins"),
    (lambda: random_course(0, n_waypoints=0), "n_waypoints"),
    (lambda: sensor_poses([0, 0]), "pose"),
])
def test_bad_input(call, words):
    with pytest.raises((ValueError, TypeError), match=words):
        call()


def test_true_ranges_needs_a_field():
    with pytest.raises(TypeError, match="field"):
        true_ranges("a field", [0.0, 0.0, 0.0])


@pytest.mark.parametrize("kwargs, match", [
    ({"max_range": -1.0}, r"max_range: expected a positive number, got -1"),
    ({"max_range": 0.1}, r"max_range: expected a value above min_range"),
    ({"min_range": float("nan")}, r"min_range: expected a finite number"),
    ({"cycle": 0.0}, r"cycle: expected a positive number"),
    ({"resolution": float("inf")}, r"resolution: expected a finite number"),
    ({"half_angle": float("nan")}, r"half_angle: expected a finite number"),
    ({"half_angle": 2.0}, r"half_angle: expected radians in \[0, pi/2\)"),
    ({"half_angle": "wide"}, r"half_angle: expected a real number"),
])
def test_sensor_parameters_are_checked_when_made(kwargs, match):
    # true_ranges casts with validate=False using max_range: a bad sensor must not get that far
    with pytest.raises((ValueError, TypeError), match=match):
        LVMaxSonarEZ(**kwargs)


@pytest.mark.parametrize("args, match", [
    (("left", 0.25, 0.1, float("nan")), r"yaw: expected a finite number"),
    (("left", "front", 0.1, 0.0), r"x: expected a real number"),
    ((3, 0.25, 0.1, 0.0), r"name: expected a string"),
])
def test_mounts_are_checked_when_made(args, match):
    with pytest.raises((ValueError, TypeError), match=match):
        SonarMount(*args)


@pytest.mark.parametrize("kwargs, match", [
    ({"mounts": ()}, r"mounts: expected a non-empty sequence of SonarMount"),
    ({"mounts": PAPER_LAYOUT[0]}, r"mounts: expected a non-empty sequence"),
    ({"mounts": [PAPER_LAYOUT[0], (0.25, 0.0, 0.0)]}, r"mounts\[1\]: expected a SonarMount, got tuple"),
    ({"sensor": "EZ1"}, r"sensor: expected an LVMaxSonarEZ, got str"),
    ({"rays": 0}, r"rays: expected an integer >= 1"),
])
def test_true_ranges_names_bad_sensors_and_mounts(kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        true_ranges(Field(circles=[[2.5, 0.0, 0.3]]), [0.0, 0.0, 0.0], **kwargs)


@pytest.mark.parametrize("kwargs, match", [
    ({"others": {7: 0.0}}, r"others key: expected an integer <= 3, got 7"),
    ({"others": {0: float("nan")}}, r"others\[0\]: expected a finite number"),
    ({"others": [(0, 0.0)]}, r"others: expected a dict"),
    ({"mounts": ()}, r"mounts: expected a non-empty sequence"),
    ({"sensor": None}, r"sensor: expected an LVMaxSonarEZ"),
])
def test_read_sensors_names_bad_input(kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        read_sensors(Field(circles=[[2.5, 0.0, 0.3]]), [0.0, 0.0, 0.0], [1], [0.0], **kwargs)


def test_a_shorter_sensor_and_custom_mounts_are_honoured():
    post = Field(circles=[[2.5, 0.0, 0.3]])
    r, _ = true_ranges(post, [0.0, 0.0, 0.0], sensor=LVMaxSonarEZ(max_range=1.5))
    assert np.isinf(r).all()                                   # the post is 1.95 m from the sensors
    ahead = (SonarMount("nose", 0.5, 0.0, 0.0),)
    r, hits = true_ranges(post, [0.0, 0.0, 0.0], mounts=ahead, rays=1)   # one ray: the axis, not the cone's edge
    assert r.tolist() == pytest.approx([2.5 - 0.3 - 0.5]) and hits[0] == pytest.approx([2.2, 0.0])
