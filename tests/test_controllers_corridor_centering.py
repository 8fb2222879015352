"""The corridor moving strategy (Ge et al. 2023, Sec. 3.1): the law, and the closed loop on simulated scans."""
from __future__ import annotations

import math

import numpy as np
import pytest

from robokit.controllers import move_to_middle_line
from robokit.controllers.corridor_centering import centering_command
from robokit.geometry import wrap_angle
from robokit.sim import Lidar, long_corridor, unicycle_step


def test_the_law_by_hand():
    # y = 0.3 m left, facing along: aim -atan(0.3 / 0.15) = -63.43 deg; omega saturates at -0.6;
    # v = clip(0.5 * 0.3, 0.02, 0.15) * cos(63.43 deg)^2 = 0.15 * 0.2
    v, w = centering_command(0.3, 0.0)
    assert (v, w) == pytest.approx((0.15 * math.cos(math.atan(2.0)) ** 2, -0.6))
    # small errors: no saturation; aim -atan(0.01/0.15) = -3.814 deg, omega = 1.5 (aim - e)
    v, w = centering_command(0.01, 0.02)
    delta = -math.atan(0.01 / 0.15) - 0.02
    assert (v, w) == pytest.approx((0.02 * math.cos(delta) ** 2, 1.5 * delta))
    # heading more than 90 deg from the aim: turn in place, never drive away
    v, w = centering_command(-0.5, math.radians(-80))
    assert v == 0.0 and w == pytest.approx(0.6)
    # inside the deadband: turn onto the corridor direction only
    assert centering_command(0.004, -0.1, deadband=0.01) == pytest.approx((0.0, 0.15))


def test_the_law_is_mirror_symmetric():
    for y, e in [(0.3, 0.2), (-0.1, 0.5), (0.6, -1.0)]:
        v1, w1 = centering_command(y, e)
        v2, w2 = centering_command(-y, -e)
        assert v1 == pytest.approx(v2) and w1 == pytest.approx(-w2)


def test_the_law_converges_on_exact_kinematics():
    """With the true offset and heading (no LiDAR), from a grid of starts: onto the line, facing along,
    after a path a little longer than the offset."""
    for y0 in (-0.7, -0.3, 0.1, 0.5, 0.7):
        for e0 in np.radians([-60, -20, 0, 30, 60]):
            p, dist = np.array([0.0, y0, e0]), 0.0
            for _ in range(1500):
                v, w = centering_command(p[1], p[2], deadband=0.005)
                p = unicycle_step(p, v, w, 0.1)
                dist += v * 0.1
            assert abs(p[1]) <= 0.0051 and abs(p[2]) < 1e-3, (y0, e0, p)
            assert abs(y0) - 0.005 <= dist < abs(y0) + 0.45, (y0, e0, dist)


def test_bad_gains_are_named():
    with pytest.raises(ValueError, match="v_min"):
        centering_command(0.1, 0.0, v_min=0.5, v_max=0.1)
    with pytest.raises(ValueError, match="lateral_offset"):
        centering_command(np.nan, 0.0)


# --- the closed loop on the simulator -------------------------------------------------------------

def random_starts(n, seed=11):
    rng = np.random.default_rng(seed)
    x = rng.uniform(2.0, 34.0, n)
    y = rng.uniform(-0.7, 0.7, n)
    e = np.radians(rng.uniform(-60, 60, n))
    facing = np.where(np.arange(n) % 2, np.pi, 0.0)          # half the robots face -x
    return np.column_stack([x, y, wrap_angle(e + facing)]), facing


def test_reaches_the_middle_line_from_random_starts():
    starts, facing = random_starts(10)
    corridor, lidar, tol = long_corridor(), Lidar(noise=0.01), 0.04
    dists = []
    for k, (pose, f) in enumerate(zip(starts, facing)):
        res = move_to_middle_line(corridor, pose, lidar, rng=k, tol=tol)
        end = res.poses[-1]
        assert res.reached, pose
        assert abs(end[1]) < tol / 2, (pose, end)                              # Eq. (4) on the true pose
        assert abs(math.degrees(wrap_angle(end[2] - f))) < 2.0, (pose, end)   # facing along, the nearer way
        assert res.final.middle
        dists.append(res.distance_moved)
        # the path length is what the poses show
        assert res.distance_moved >= np.linalg.norm(np.diff(res.poses[:, :2], axis=0), axis=1).sum() - 1e-9
    assert max(dists) < 1.25 and np.mean(dists) < 0.9


def test_opposite_direction_turns_round():
    res = move_to_middle_line(long_corridor(), [20.0, -0.3, 0.2], Lidar(noise=0.01), direction="opposite")
    assert res.reached and abs(res.poses[-1, 1]) < 0.02
    assert abs(math.degrees(wrap_angle(res.poses[-1, 2] - np.pi))) < 2.0


def test_already_centred_barely_moves():
    res = move_to_middle_line(long_corridor(), [14.5, 0.0, 0.0], Lidar(noise=0.01))
    assert res.reached and res.distance_moved < 0.02 and len(res.poses) <= 10


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="world"):
        move_to_middle_line("corridor", [14.5, 0.0, 0.0], Lidar())
    with pytest.raises(TypeError, match="lidar"):
        move_to_middle_line(long_corridor(), [14.5, 0.0, 0.0], None)
    with pytest.raises(ValueError, match="direction"):
        move_to_middle_line(long_corridor(), [14.5, 0.0, 0.0], Lidar(), direction="north")
    with pytest.raises(ValueError, match="pose"):
        move_to_middle_line(long_corridor(), [14.5, np.nan, 0.0], Lidar())


def _public_loop(world, pose, lidar, rng, steps):
    """move_to_middle_line's loop written with the public, checked calls only (the reference)."""
    from robokit.mapping import corridor_state
    width, recess, e4 = world.info["width"], world.info["recess"], 0.04
    p, poses, e_prev, good = np.asarray(pose, float), [np.asarray(pose, float)], None, 0
    for _ in range(steps + 1):
        s = corridor_state(lidar.scan(world, p, rng), lidar.angles, width, lidar.r_max, recess=recess, tol=e4)
        if s.lateral_offset is None:
            break
        e0 = -s.axis
        e_prev = e0 if e_prev is None else e_prev
        k = int(np.round((e_prev - e0) / np.pi))
        e_prev = e = e0 + k * np.pi
        y = -s.lateral_offset if k % 2 else s.lateral_offset
        good = good + 1 if abs(y) <= e4 / 4 and abs(wrap_angle(e)) <= np.deg2rad(2.0) else 0
        if good >= 3 or len(poses) > steps:
            break
        p = unicycle_step(p, *centering_command(y, float(wrap_angle(e)), deadband=e4 / 4), 0.1)
        poses.append(p)
    return np.array(poses)


@pytest.mark.parametrize("start", [[15.0, 0.4, 0.5], [25.3, -0.6, 2.9], [4.0, 0.1, -1.2]])
def test_the_loop_drives_exactly_as_the_public_calls_would(start):
    """The loop checks each scan once and trusts it after; the poses are those of the checked calls."""
    world, lidar = long_corridor(), Lidar(noise=0.01)
    run = move_to_middle_line(world, start, lidar, rng=np.random.default_rng(7), max_steps=120)
    reference = _public_loop(world, start, lidar, np.random.default_rng(7), 120)
    assert len(run.poses) > 5 and np.array_equal(run.poses, reference)
