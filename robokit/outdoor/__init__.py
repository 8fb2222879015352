"""Outdoor navigation (lesson 05): NMEA 0183, geodesy, sonar, a skid-steer truck and its navigator.

Follows Hamid, Adom, Rahim and Rahiman, "Navigation of mobile robot using Global Positioning
System (GPS) and obstacle avoidance system with commanded loop daisy chaining application method"
(CSPA 2009; question 3 of the course's assignment): an RC truck that drives GPS waypoints read from NMEA sentences
($GPRMC, $GPRMB, $GPGGA, $HCHDG) and avoids obstacles with four LV-MaxSonar-EZ sensors fired in a
commanded daisy-chain loop.

Submodules
----------
nmea        checksum, typed records, a resynchronising stream reader (fields and record builders
            in nmea_fields, record types in nmea_records)
nmea_write  sentence builders (what a receiver model emits)
geodesy     haversine, tangent-plane projection, WGS84 inverse problem
sonar       LV-MaxSonar-EZ model, chained versus free-running firing, the paper's layout
field       the field: a :class:`robokit.sim.Layout` of obstacles with a size and a geodetic
            origin, and seeded courses
truck       the paper's truck on :mod:`robokit.sim.vehicle`'s skid-steer kinematics, with motor lag
gps         1 Hz GPS receiver and compass models that emit NMEA text
navigator   waypoint following plus the sonar obstacle-avoidance state machine
mission     the simulated experiment: courses, runs, summaries

The heading loop (designed with python-control) lives in :mod:`robokit.controllers`; its names
are re-exported here (``from robokit.outdoor import loop_metrics``).
"""
from ..controllers import (HeadingController, design_heading_gains, heading_closed_loop, heading_frequency_response,
                           heading_loop_gain, heading_plant, heading_step_response, loop_metrics)
from .field import Course, Field, random_course
from .geodesy import (EARTH_MEAN_RADIUS, LocalTangentPlane, distance_bearing, haversine_distance,
                      haversine_distance_bearing, initial_bearing, osculating_radius, vincenty_inverse)
from .gps import Compass, GPSReceiver, compass_to_heading, heading_to_compass
from .mission import RunResult, run_courses, simulate, summarize_runs
from .navigator import Navigator, avoidance_decision
from .nmea import (GGA, HDG, RMB, RMC, BadFields, BadSentence, NMEAChecksumError, NMEAError, NMEAFieldError,
                   NMEAFormatError, NMEAReader, Sentence, fix_position, nmea_checksum, parse_sentence, read_nmea)
from .nmea_write import format_sentence, gga_sentence, hdg_sentence, random_sentences, rmb_sentence, rmc_sentence
from .sonar import (PAPER_LAYOUT, LVMaxSonarEZ, firing_schedule, pulse_width_to_cm_inches, pulse_width_to_range,
                    read_sensors, sensor_poses, true_ranges)
from .truck import PAPER_TRUCK, SkidSteerTruck, TruckState

__all__ = [
    "HeadingController", "design_heading_gains", "heading_closed_loop", "heading_frequency_response",
    "heading_loop_gain", "heading_plant", "heading_step_response", "loop_metrics",
    "Course", "Field", "random_course",
    "EARTH_MEAN_RADIUS", "LocalTangentPlane", "distance_bearing", "haversine_distance",
    "haversine_distance_bearing", "initial_bearing", "osculating_radius", "vincenty_inverse",
    "Compass", "GPSReceiver", "compass_to_heading", "heading_to_compass",
    "RunResult", "run_courses", "simulate", "summarize_runs", "Navigator", "avoidance_decision",
    "GGA", "HDG", "RMB", "RMC", "BadFields", "BadSentence", "NMEAChecksumError", "NMEAError", "NMEAFieldError",
    "NMEAFormatError", "NMEAReader",
    "Sentence", "fix_position", "nmea_checksum", "parse_sentence", "read_nmea",
    "format_sentence", "gga_sentence", "hdg_sentence", "random_sentences", "rmb_sentence", "rmc_sentence",
    "PAPER_LAYOUT", "LVMaxSonarEZ", "firing_schedule", "pulse_width_to_cm_inches", "pulse_width_to_range",
    "read_sensors", "sensor_poses", "true_ranges", "PAPER_TRUCK", "SkidSteerTruck", "TruckState",
]
