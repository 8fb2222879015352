"""Corridor analysis of a 2D scan (Ge et al. 2023, Sec. 3.1, Eqs. (1)-(9)) on hand-made and simulated scans."""
from __future__ import annotations

import math

import numpy as np
import pytest

from robokit.mapping import (EmptyScanError, NoWallError, corridor_axis, corridor_axis_readable, corridor_state, invalid_areas, middle_line_condition, theta_limits, theta_limits_geometric, wall_distances, width_condition)
from robokit.mapping.corridor_areas import as_scan
from robokit.mapping.corridor_scan import door_sides
from robokit.sim import Lidar, long_corridor

ANGLES = 2 * np.pi * np.arange(360) / 360
W, RMAX = 2.17, 8.0


def two_walls(d_l, d_r, axis=0.0, r_max=RMAX, angles=ANGLES):
    """Ranges to two infinite parallel walls (left at d_l, right at d_r) along ``axis``, analytically."""
    s = np.sin(angles - axis)
    with np.errstate(divide="ignore"):
        r = np.where(s > 0, d_l / s, np.where(s < 0, -d_r / s, np.inf))
    r[r > r_max] = np.inf
    return r




# --- wall distances and the axis ----------------------------------------------------------------

@pytest.mark.parametrize("d_l, d_r", [(1.085, 1.085), (0.8, 1.37), (0.3, 1.87), (1.155, 1.085)])
def test_wall_distances_of_two_parallel_walls(d_l, d_r):
    got = wall_distances(two_walls(d_l, d_r), ANGLES, heading=0.0)
    assert got == pytest.approx((d_l, d_r), abs=1e-12)     # r cos(phi - normal) is d on every beam


@pytest.mark.parametrize("axis_deg", [-60.0, -33.5, -5.0, 0.0, 12.25, 45.0, 60.0])
def test_the_axis_and_the_distances_do_not_depend_on_the_heading(axis_deg):
    axis = math.radians(axis_deg)
    r = two_walls(0.5, 1.67, axis)
    assert math.degrees(corridor_axis(r, ANGLES)) == pytest.approx(axis_deg, abs=0.05)
    d_l, d_r = wall_distances(r, ANGLES)
    # with the axis 0.05 deg off, the coordinate along the normal is off by d (1 - cos) ~ 1e-7 at most ~ 0.001 d
    assert (d_l, d_r) == pytest.approx((0.5, 1.67), rel=2e-3)


def test_the_robots_own_halves_mislabel_a_wall_when_it_is_turned():
    """Why the sides follow the axis: turned 60 deg, the robot's own left and right (+-90 deg) meet the
    walls 60 deg off their normals, at 0.3 / sin 30 deg and 1.87 / sin 30 deg: ranges, not distances."""
    r = two_walls(0.3, 1.87, math.radians(60))
    assert wall_distances(r, ANGLES, heading=math.radians(60)) == pytest.approx((0.3, 1.87), abs=1e-12)
    assert wall_distances(r, ANGLES, heading=0.0) == pytest.approx((0.6, 3.74),
                                                                   rel=1e-3)


def test_one_noisy_beam_does_not_set_the_shortest_distance():
    r = two_walls(1.0, 1.17)
    r[90] = 0.6                                       # a spurious short return on the left normal
    r[92] = np.inf                                    # and a lost one beside it
    assert wall_distances(r, ANGLES, heading=0.0)[0] == pytest.approx(1.0, abs=1e-12)


def test_a_missing_wall_is_a_named_error():
    r = two_walls(1.0, 1.17)
    r[np.sin(ANGLES) < 0] = np.inf                   # nothing on the right within r_max
    with pytest.raises(NoWallError, match="right wall's normal, got 0"):
        wall_distances(r, ANGLES, heading=0.0)


# --- Eqs. (1)-(4) -------------------------------------------------------------------------------

def test_width_conditions_1_2_3():
    assert width_condition(0.6, 1.57, W) == "corridor"                              # Eq. (1)
    assert width_condition(1.155, 1.155, W) == "facing doors"                       # Eq. (2): w + 2 d_da
    assert width_condition(1.085, 1.155, W) == "staggered doors"                    # Eq. (3): w + d_da
    assert width_condition(1.085, 1.085 + 0.029, W) == "corridor"                   # within e1 = 0.03
    assert width_condition(1.5, 1.5, W) is None
    assert width_condition(1.085, 1.085 + 0.035, W, tol=0.02) is None              # between the cases


def test_middle_line_condition_removes_the_door_recess():
    assert middle_line_condition(1.085, 1.085) == (True, 0.0, "none")               # Eq. (4)
    assert middle_line_condition(1.105, 1.065, tol=0.04) == (True, -0.02, "none")
    assert middle_line_condition(1.11, 1.06, tol=0.04)[0] is False
    # centred beside a door on the right: raw Eq. (4) sees the 7 cm recess, the rule removes it
    assert middle_line_condition(1.085, 1.155, tol=0.04)[0] is False
    assert middle_line_condition(1.085, 1.155, tol=0.04, width=W) == (True, 0.0, "right")
    assert middle_line_condition(1.155, 1.155, width=W) == (True, 0.0, "both")
    # 0.06 m left of the line beside a left door: d_L = 1.085 - 0.06 + 0.07, d_R = 1.085 + 0.06
    d_l, d_r = 1.095, 1.145
    assert middle_line_condition(d_l, d_r, width=W)[1:] == pytest.approx((-0.01, "right"))   # the guess errs by d_da
    assert middle_line_condition(d_l, d_r, width=W, door="left")[1:] == pytest.approx((0.06, "left"))


def test_door_sides_from_simulated_scans():
    corridor, lidar = long_corridor(), Lidar(noise=0.01)
    assert door_sides(lidar.scan(corridor, [25.5, 0.06, 0.0], 1), lidar.angles) == (True, False)   # 2.25 m north door
    assert door_sides(lidar.scan(corridor, [12.0, 0.0, 0.4], 1), lidar.angles) == (True, True)     # facing doors
    assert door_sides(lidar.scan(corridor, [14.5, -0.3, -0.5], 1), lidar.angles) == (False, False)
    assert door_sides(lidar.scan(corridor, [23.25, 0.0, math.pi], 1), lidar.angles) == (True, False)  # south door, facing -x


# --- Eqs. (6)-(9) -------------------------------------------------------------------------------

def test_theta_limits_as_printed_and_from_the_geometry():
    lo, hi = theta_limits(W, RMAX)
    assert lo == pytest.approx(math.asin(2.17 / 16)) and hi == pytest.approx(math.asin(2.17 / 8))
    assert (math.degrees(lo), math.degrees(hi)) == pytest.approx((7.7948, 15.7387), abs=1e-4)
    # brute force: the invalid cone's width over lateral positions, from 0.0001-deg beams
    beta = np.radians(np.arange(-20, 20, 1e-4))
    cones = []
    for a in np.linspace(0.0, W, 21):
        with np.errstate(divide="ignore"):
            r = np.where(beta > 0, (W - a) / np.sin(beta), np.where(beta < 0, -a / np.sin(beta), np.inf))
        cones.append(np.count_nonzero(r > RMAX) * 1e-4)
    g_lo, g_hi = theta_limits_geometric(W, RMAX)
    assert math.degrees(g_lo) == pytest.approx(min(cones), abs=2e-4) and min(cones) == pytest.approx(cones[10], abs=2e-4)
    assert math.degrees(g_hi) == pytest.approx(max(cones), abs=2e-4) == pytest.approx(cones[0], abs=2e-4)
    assert g_lo == pytest.approx(2 * lo) and g_hi == pytest.approx(hi)     # Eq. (7) is the half-angle
    assert math.degrees(theta_limits_geometric(W, RMAX, 0.07)[1]) == pytest.approx(
        math.degrees(math.asin(0.07 / 8) + math.asin(2.24 / 8)))


def test_invalid_areas_of_a_hand_made_corridor_scan():
    areas = invalid_areas(two_walls(1.085, 1.085), ANGLES)       # beams within 7.795 deg of the axis
    assert np.degrees(areas).round(9).tolist() == [[173.0, 187.0, 14.0], [353.0, 7.0, 14.0]]   # wraps at 2 pi
    # 0.1 m from the left wall the forward cone runs from -14.99 deg (asin(2.07/8), the right wall) to
    # +0.716 deg (asin(0.1/8)): beams -14..0, 15 of them; the backward one beams 180..194. Eq. (9)
    # gives the 14 deg from the first to the last of each
    near = invalid_areas(two_walls(0.1, 2.07), ANGLES)
    assert np.degrees(near).round(9).tolist() == [[180.0, 194.0, 14.0], [346.0, 0.0, 14.0]]


def test_invalid_areas_edge_cases():
    ang = np.radians(np.arange(0.0, 360.0, 45.0))
    r = np.array([np.inf, 1, 1, 1, np.inf, 1, np.inf, np.inf])
    assert np.degrees(invalid_areas(r, ang)).round(9).tolist() == [[180.0, 180.0, 0.0], [270.0, 0.0, 90.0]]
    assert invalid_areas(np.ones(8), ang).shape == (0, 3)
    assert np.degrees(invalid_areas(np.full(8, np.inf), ang)).round(9).tolist() == [[0.0, 315.0, 315.0]]
    r2 = np.array([1, np.inf, np.inf, 1, 1, 1, 1, np.inf])
    assert np.degrees(invalid_areas(r2, ang)).round(9).tolist() == [[45.0, 90.0, 45.0], [315.0, 315.0, 0.0]]


@pytest.mark.parametrize("bad, match", [([1.0, np.nan], "ranges"), ([1.0, -0.5], "ranges"),
                                        ([1.0, -np.inf], "ranges")])
def test_bad_ranges_are_named_errors(bad, match):
    with pytest.raises(ValueError, match=match):
        invalid_areas(bad, [0.0, 1.0])


def test_bad_scans_are_named_errors():
    with pytest.raises(EmptyScanError, match="empty"):
        as_scan([], [])
    with pytest.raises(ValueError, match="angles: expected 2"):
        as_scan([1.0, 2.0], [0.0])
    with pytest.raises(ValueError, match="increasing"):
        as_scan([1.0, 2.0], [1.0, 0.0])
    with pytest.raises(ValueError, match="2 pi"):
        as_scan([1.0, 2.0], [0.0, 7.0])
    with pytest.raises(EmptyScanError, match="at least 3 valid"):
        corridor_axis(np.full(360, np.inf), ANGLES)
    with pytest.raises(ValueError, match="width"):
        theta_limits(9.0, 8.0)


# --- one scan's state on the simulator ------------------------------------------------------------

def state(pose, bounds="paper", noise=0.01):
    lidar = Lidar(noise=noise)
    return corridor_state(lidar.scan(long_corridor(), pose, rng=3), lidar.angles, W, RMAX, bounds=bounds)


def test_in_the_middle_of_the_corridor_two_areas_satisfy_eq_8():
    s = state([14.5, 0.0, 0.0])
    assert (s.in_corridor, s.at_end, s.n_areas) == (True, False, 2)
    assert set(np.degrees(s.areas[:, 2]).round(6).tolist()) <= {14.0, 15.0}     # 15 or 16 beams
    assert s.width_case == "corridor" and s.middle and s.doors == "none"
    assert s.d_l == pytest.approx(1.085, abs=0.02) and s.d_r == pytest.approx(1.085, abs=0.02)
    assert abs(s.lateral_offset) < 0.01 and abs(math.degrees(s.axis)) < 0.3


def test_near_an_end_one_area_satisfies_eq_8():
    for pose in ([3.0, 0.0, 0.0], [33.0, 0.0, 0.0], [5.0, 0.5, 0.7]):
        s = state(pose)
        assert (s.in_corridor, s.at_end, s.n_areas) == (True, True, 1), pose


def test_near_a_wall_and_turned():
    s = state([14.5, 0.885, 0.3])                      # 0.2 m from the north wall
    assert (s.n_areas, s.at_end) == (2, False)
    assert s.lateral_offset == pytest.approx(0.885, abs=0.02)
    assert math.degrees(s.axis) == pytest.approx(-math.degrees(0.3), abs=0.3)


def test_a_recess_at_the_range_limit_breaks_the_printed_eq_8():
    """0.385 m from the south wall, turned 60 deg: one cone is 16 deg (a recess where the beams pass
    r_max), above Eq. (6)'s 15.74 deg, so the printed bounds call it an end; the geometric ones do not."""
    paper, geo = state([15.0, -0.7, -math.radians(60)]), state([15.0, -0.7, -math.radians(60)], "geometric")
    assert np.degrees(paper.areas[:, 2]).round(6).tolist() == [14.0, 16.0]
    assert (paper.n_areas, paper.at_end) == (1, True)
    assert (geo.n_areas, geo.at_end) == (2, False)


def test_beside_doors_the_width_case_and_the_offset():
    s = state([12.0, 0.1, 0.0])                                # facing doors, 0.1 m left
    assert s.width_case == "facing doors" and s.lateral_offset == pytest.approx(0.1, abs=0.01)
    s = state([25.5, 0.06, 0.0])                               # a north door only, 6 cm left
    assert s.width_case == "staggered doors" and s.doors == "left"
    assert s.lateral_offset == pytest.approx(0.06, abs=0.01)


def test_a_scan_without_walls_is_reported_not_raised():
    s = corridor_state(np.full(360, np.inf), ANGLES, W, RMAX)
    assert (s.in_corridor, s.lateral_offset, s.axis, s.d_l) == (False, None, None, np.inf)
    assert s.areas.shape == (1, 3)


def test_zero_ranges_are_no_returns_and_far_returns_cost_no_memory():
    # a driver that codes "no return" as 0 had stopped corridor_state with an error about an
    # internal "d_l"; a 9e5 m return had asked the axis vote for tens of GiB
    r = two_walls(1.0, 1.17)
    ok = corridor_state(r, ANGLES, W, 8.0)
    zeroed = np.where(np.isinf(r), 0.0, r)
    assert as_scan(zeroed, ANGLES)[0].tolist() == r.tolist()
    again = corridor_state(zeroed, ANGLES, W, 8.0)
    assert (again.d_l, again.d_r, again.width_case, again.n_areas) == (ok.d_l, ok.d_r, ok.width_case, ok.n_areas)
    far = np.where(np.isinf(r), 9e5, r)
    assert round(corridor_axis(far, ANGLES), 9) == round(corridor_axis(r, ANGLES), 9)
    all_zero = corridor_state(np.zeros_like(r), ANGLES, W, 8.0)
    assert all_zero.d_l == np.inf and all_zero.lateral_offset is None


def test_a_sparse_scan_gives_no_wall_rather_than_a_negative_distance():
    angles = np.deg2rad(np.arange(0, 360, 45.0)) + 0.3             # eight beams, none near a normal
    with pytest.raises(NoWallError, match="within 15 deg"):
        wall_distances(np.full(8, 1.5), angles, heading=0.0)


def test_the_coarse_to_fine_vote_finds_the_exhaustive_votes_axis():
    # the vote over 36 + 9 directions against the readable one over all 180, on simulated scans of
    # the long corridor: anywhere across it, near and far from its ends, turned up to 60 deg either way
    world, lidar = long_corridor(), Lidar(noise=0.01)
    g = np.random.default_rng(7)
    L, half = world.info["length"], world.info["width"] / 2
    for _ in range(150):
        pose = np.array([g.uniform(0.4, L - 0.4), g.uniform(-half + 0.3, half - 0.3), g.uniform(-1.05, 1.05)])
        pose[2] += np.pi * g.integers(0, 2)
        r, a = as_scan(lidar.scan(world, pose, g), lidar.angles)
        assert corridor_axis(r, a) == pytest.approx(corridor_axis_readable(r, a), abs=1e-9), pose
        # and both find the corridor: the robot's heading error is minus the axis, modulo pi
        err = math.remainder(pose[2], math.pi)
        assert math.degrees(abs(math.remainder(corridor_axis(r, a) + err, math.pi))) < 1.0, pose   # centering asks 2 deg


def test_the_unchecked_state_agrees_with_the_public_conditions():
    """corridor_state(validate=False), the moving strategy's per-scan path: the same state as the
    checked call, and its width case, door sides and Eq. (4) those of the public functions."""
    lidar, world, rng = Lidar(noise=0.01), long_corridor(), np.random.default_rng(3)
    for _ in range(40):
        pose = [rng.uniform(1.0, 35.0), rng.uniform(-0.8, 0.8), rng.uniform(-np.pi, np.pi)]
        r, a = as_scan(lidar.scan(world, pose, rng), lidar.angles)
        for bounds in ("paper", "geometric"):
            slow = corridor_state(r, a, 2.17, lidar.r_max, bounds=bounds)
            fast = corridor_state(r, a, 2.17, lidar.r_max, bounds=bounds, validate=False)
            for field in slow.__dataclass_fields__:
                assert np.array_equal(np.asarray(getattr(slow, field), dtype=object),
                                      np.asarray(getattr(fast, field), dtype=object)), field
        assert np.array_equal(invalid_areas(r, a), invalid_areas(r, a, validate=False))
        if fast.lateral_offset is None:
            continue
        sides = door_sides(r, a, heading=fast.axis)
        hint = "left" if sides == (True, False) else "right" if sides == (False, True) else None
        assert fast.width_case == width_condition(fast.d_l, fast.d_r, 2.17)
        assert (fast.middle, fast.lateral_offset, fast.doors) == middle_line_condition(fast.d_l, fast.d_r, width=2.17,
                                                                                      door=hint)


def test_a_bad_door_is_refused_whatever_the_distances():
    with pytest.raises(ValueError, match="door"):
        middle_line_condition(1.085, 1.085, width=2.17, door="up")      # Eq. (1): the door is not read
