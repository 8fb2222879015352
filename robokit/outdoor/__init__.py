"""Outdoor navigation (lesson 05): NMEA 0183, geodesy, sonar, a skid-steer truck and its navigator.

Follows Hamid, Adom, Rahim and Rahiman (CSPA 2009; question 3 of the course's assignment): an RC
truck that drives GPS waypoints read from NMEA sentences ($GPRMC, $GPRMB, $GPGGA, $HCHDG) and
avoids obstacles with four LV-MaxSonar-EZ sensors fired in a commanded daisy-chain loop. Its
heading loop is :mod:`robokit.controllers.heading`.

nmea_fields   checksums, field parsers and the NMEA errors
nmea_records  the typed records (RMC, RMB, GGA, HDG)
nmea          parse a sentence, a resynchronising stream reader, a fix's position
nmea_write    sentence builders (what a receiver model emits)
geodesy       haversine, the local tangent plane, the WGS84 inverse problem (Vincenty)
sonar         the LV-MaxSonar-EZ model, chained versus free-running firing, the paper's layout
field         the field: a sim Layout of obstacles with a size and a geodetic origin; seeded courses
truck         the paper's truck on the skid-steer kinematics, with motor lag
gps           1 Hz GPS receiver and compass models that emit NMEA text
navigator     waypoint following and the sonar obstacle-avoidance state machine
mission       one simulated mission through NMEA and sonar, and the summary of many
"""
from .nmea import (GGA, HDG, NMEAChecksumError, NMEAError, NMEAFieldError, NMEAFormatError, NMEAReader, RMB, RMC,
                   Sentence, fix_position, nmea_checksum, parse_sentence, read_nmea)
from .nmea_write import format_sentence, gga_sentence, hdg_sentence, random_sentences, rmb_sentence, rmc_sentence
from .geodesy import LocalTangentPlane, distance_bearing, haversine_distance_bearing, vincenty_inverse
from .sonar import (LVMaxSonarEZ, PAPER_LAYOUT, firing_schedule, pulse_width_to_cm_inches, read_sensors, sensor_poses,
                    true_ranges)
from .field import Course, Field, random_course
from .truck import PAPER_TRUCK, SkidSteerTruck, TruckState
from .gps import Compass, GPSReceiver, compass_to_heading
from .navigator import Navigator, avoidance_decision
from .mission import RunResult, simulate, summarize_runs

__all__ = ["GGA", "HDG", "NMEAChecksumError", "NMEAError", "NMEAFieldError", "NMEAFormatError", "NMEAReader", "RMB",
           "RMC", "Sentence", "fix_position", "nmea_checksum", "parse_sentence", "read_nmea", "format_sentence",
           "gga_sentence", "hdg_sentence", "random_sentences", "rmb_sentence", "rmc_sentence", "LocalTangentPlane",
           "distance_bearing", "haversine_distance_bearing", "vincenty_inverse", "LVMaxSonarEZ", "PAPER_LAYOUT",
           "firing_schedule", "pulse_width_to_cm_inches", "read_sensors", "sensor_poses", "true_ranges", "Course",
           "Field", "random_course", "PAPER_TRUCK", "SkidSteerTruck", "TruckState", "Compass", "GPSReceiver",
           "compass_to_heading", "Navigator", "avoidance_decision", "RunResult", "simulate",
           "summarize_runs"]
