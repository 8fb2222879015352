"""Skid-steer truck (on robokit.sim.vehicle), the heading loop driving it, GPS and compass models."""
from __future__ import annotations

import math

import numpy as np
import pytest

from robokit.controllers import HeadingController, design_heading_gains
from robokit.outdoor.field import UNIMAP_ORIGIN
from robokit.outdoor.geodesy import LocalTangentPlane
from robokit.outdoor.gps import Compass, GPSReceiver, compass_to_heading, heading_to_compass
from robokit.outdoor.nmea import GGA, HDG, RMC, parse_sentence
from robokit.outdoor.truck import PAPER_TRUCK, SkidSteerTruck, TruckState
from robokit.sim.vehicle import skid_steer_velocities, skid_steer_wheel_speeds


def test_paper_truck_dimensions():
    assert (PAPER_TRUCK.length, PAPER_TRUCK.width, PAPER_TRUCK.height) == (0.50, 0.25, 0.15)


def test_straight_line_and_turn_in_place():
    truck = SkidSteerTruck(slip=0.1, icr_factor=1.5)
    s = TruckState(np.zeros(3))
    for _ in range(200):
        s = truck.step(s, [0.5, 0.5], 0.05)
    assert s.pose[1] == pytest.approx(0.0, abs=1e-12) and s.pose[2] == 0.0
    assert s.v == pytest.approx(0.45, rel=1e-3)          # slip: 10 % slower than the wheels
    s = TruckState(np.zeros(3))
    for _ in range(400):
        s = truck.step(s, [-0.3, 0.3], 0.01)
    assert np.hypot(*s.pose[:2]) < 1e-9                   # turns on the spot
    assert s.omega == pytest.approx(0.9 * 0.6 / (1.5 * 0.21), rel=1e-3)


def test_wheel_commands_invert_the_model_and_keep_the_turn():
    truck = PAPER_TRUCK
    v, om = truck.body_velocity(truck.wheel_commands(0.4, 0.8))
    assert (v, om) == pytest.approx((0.4, 0.8))
    w = truck.wheel_commands(5.0, 2.0)                    # too fast: forward speed gives way
    assert np.abs(w).max() == pytest.approx(truck.max_wheel_speed)
    assert truck.body_velocity(w)[1] == pytest.approx(2.0)


def test_truck_uses_the_vehicle_kinematics():
    truck = SkidSteerTruck(slip=0.08, icr_factor=1.7)
    v, om = truck.body_velocity([0.2, 0.6])
    assert (v, om) == skid_steer_velocities(0.2, 0.6, truck.track, 1.7, 0.08)
    assert truck.max_turn_rate == pytest.approx(skid_steer_velocities(-1.0, 1.0, truck.track, 1.7, 0.08)[1])
    np.testing.assert_array_equal(truck.wheel_commands(0.3, 0.5),
                                  skid_steer_wheel_speeds(0.3, 0.5, truck.track, 1.0, 1.7, 0.08))


def test_arc_is_exact_for_constant_velocity():
    truck = SkidSteerTruck(motor_tau=1e-6)
    s = TruckState(np.zeros(3), wheels=np.array([0.2, 0.4]))
    v, om = truck.body_velocity([0.2, 0.4])
    s = truck.step(s, [0.2, 0.4], 1.0)
    r = v / om
    assert s.pose[:2] == pytest.approx([r * math.sin(om), r * (1 - math.cos(om))])


@pytest.mark.parametrize("kwargs, words", [({"slip": 0.6}, "slip"), ({"icr_factor": 0.5}, "icr_factor"),
                                           ({"length": -1}, "length"), ({"slip": float("nan")}, "slip"),
                                           ({"icr_factor": "wide"}, "icr_factor: expected a real number")])
def test_truck_validation(kwargs, words):
    with pytest.raises((ValueError, TypeError), match=words):
        SkidSteerTruck(**kwargs)


@pytest.mark.parametrize("call, words", [
    (lambda: PAPER_TRUCK.wheel_commands(float("nan"), 0.0), r"v: expected finite values"),
    (lambda: PAPER_TRUCK.wheel_commands(0.3, math.inf), r"omega: expected finite values"),
    (lambda: PAPER_TRUCK.wheel_commands("fast", 0.0), r"v: expected real numbers, got a string \('fast'\)"),
    (lambda: PAPER_TRUCK.step(np.zeros(3), [0.1, 0.1], 0.1), r"state: expected a TruckState, got ndarray"),
    (lambda: PAPER_TRUCK.step(TruckState(np.zeros(2)), [0.1, 0.1], 0.1), r"state.pose: expected shape \(3\), got shape \(2,\)"),
    (lambda: PAPER_TRUCK.step(TruckState(np.zeros(3), [0.0, np.nan]), [0.1, 0.1], 0.1), r"state.wheels: expected finite"),
    (lambda: PAPER_TRUCK.step(TruckState(np.zeros(3)), [0.1, np.nan], 0.1), r"command: expected finite"),
    (lambda: PAPER_TRUCK.step(TruckState(np.zeros(3)), [0.1, 0.1], 0.0), r"dt: expected a positive number"),
])
def test_truck_methods_name_bad_input(call, words):
    # both methods pass their values on with validate=False: bad input must stop at the boundary
    with pytest.raises((ValueError, TypeError), match=words):
        call()


def test_wheel_commands_take_arrays_and_the_fast_paths_agree():
    v, om = np.array([0.2, 0.4, 5.0]), np.array([0.0, 0.5, 2.0])
    batch = PAPER_TRUCK.wheel_commands(v, om)
    assert batch.shape == (3, 2)
    np.testing.assert_array_equal(batch, [PAPER_TRUCK.wheel_commands(a, b) for a, b in zip(v, om)])
    np.testing.assert_array_equal(PAPER_TRUCK.wheel_commands(0.4, 0.8, validate=False), PAPER_TRUCK.wheel_commands(0.4, 0.8))
    s0 = TruckState(np.array([1.0, 2.0, 0.3]), np.array([0.1, 0.2]))
    a, b = PAPER_TRUCK.step(s0, [0.5, 0.7], 0.049), PAPER_TRUCK.step(s0, np.array([0.5, 0.7]), 0.049, validate=False)
    np.testing.assert_array_equal(a.pose, b.pose)
    np.testing.assert_array_equal(a.wheels, b.wheels)
    assert (a.v, a.omega) == (b.v, b.omega)


def test_heading_controller_turns_the_truck():
    truck = PAPER_TRUCK
    kp, kd = design_heading_gains(truck.motor_tau, 0.05, 1.5)
    ctl = HeadingController(kp, kd, max_rate=0.8 * truck.max_turn_rate)
    s = TruckState(np.zeros(3))
    for _ in range(100):
        ctl.measure(s.pose[2], 0.05)
        s = truck.step(s, truck.wheel_commands(0.0, ctl.command(1.0, s.pose[2])), 0.05)
    assert s.pose[2] == pytest.approx(1.0, abs=0.02)
    assert ctl.command(np.pi - 0.1, -np.pi + 0.1) < 0   # the short way round


def test_compass_convention():
    assert heading_to_compass(0.0) == 90.0 and heading_to_compass(np.pi / 2) == 0.0
    assert compass_to_heading(270.0) == pytest.approx(-np.pi) or compass_to_heading(270.0) == pytest.approx(np.pi)
    for th in np.linspace(-3, 3, 7):
        assert compass_to_heading(heading_to_compass(th)) == pytest.approx(th)
    rec = parse_sentence(Compass(noise=0.0, accuracy=0.0, resolution=math.radians(0.1), rng=1).reading(0.3))
    assert isinstance(rec, HDG) and rec.talker == "HC"
    assert compass_to_heading(rec.true_heading_deg) == pytest.approx(0.3, abs=np.radians(0.1))


def test_compass_takes_radians_and_writes_degrees():
    fine = {"accuracy": 0.0, "resolution": math.radians(0.1)}       # no bias, NMEA's 0.1 degree steps
    rec = parse_sentence(Compass(noise=0.0, variation=math.radians(2.5), **fine).reading(0.3))
    assert rec.variation_deg == pytest.approx(2.5)                  # NMEA keeps degrees
    assert compass_to_heading(rec.true_heading_deg) == pytest.approx(0.3, abs=np.radians(0.1))
    compass = Compass(noise=math.radians(2.0), rng=5, **dict(fine, accuracy=math.radians(20.0)))   # bound far out
    err = [compass_to_heading(parse_sentence(compass.reading(0.3)).true_heading_deg) - 0.3 for _ in range(2000)]
    assert np.std(err) == pytest.approx(math.radians(2.0), rel=0.1)   # a standard deviation in radians
    with pytest.raises(ValueError, match="noise: expected a non-negative number"):
        Compass(noise=-0.1)
    with pytest.raises(ValueError, match="variation: expected a finite number"):
        Compass(variation=math.nan)


def test_gps_emits_parseable_fixes_with_metre_level_error():
    plane = LocalTangentPlane(*UNIMAP_ORIGIN)
    gps = GPSReceiver(plane, rng=4)
    errors = []
    for k in range(2000):
        rmc, gga = (parse_sentence(s) for s in gps.fix(float(k), [30.0, 20.0], 0.5, 0.0))
        assert isinstance(rmc, RMC) and isinstance(gga, GGA) and rmc.valid
        fix = plane.to_local(np.radians(rmc.latitude), np.radians(rmc.longitude))
        err = fix - [30.0, 20.0]
        assert err == pytest.approx(gps.last_error, abs=0.2)   # 1e-4 arc-minute resolution
        errors.append(np.hypot(*err))
    errors = np.array(errors)
    assert 1.5 < np.median(errors) < 5.0 and errors.max() < 12.0
    assert abs(rmc.course_deg - 90.0) < 0.1 and rmc.speed_mps == pytest.approx(0.5, abs=0.01)
    with pytest.raises(TypeError, match="plane"):
        GPSReceiver("here")
