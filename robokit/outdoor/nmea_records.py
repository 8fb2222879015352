"""Typed NMEA 0183 records returned by :mod:`robokit.outdoor.nmea`.

Immutable named tuples (cheap to build, compare and print). Field names carry NMEA's own units
(``speed_knots``, ``course_deg``); SI properties convert them (DESIGN.md: SI units in APIs).
Layouts follow NMEA 0183 v4.11, Sec. 6.3, for the sentences Hamid et al. (2009) read.

References
----------
.. [1] National Marine Electronics Association, *NMEA 0183 Standard for Interfacing Marine
   Electronic Devices*, version 4.11, 2018.
.. [2] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
"""
from __future__ import annotations

import datetime as _dt
import math
from typing import NamedTuple

__all__ = ["RMC", "RMB", "GGA", "HDG", "Sentence", "KNOT", "NAUTICAL_MILE"]

def _repr(record: tuple) -> str:
    """The named tuple's usual repr, without ``bad_fields`` when it is empty (an intact sentence)."""
    items = [(k, v) for k, v in zip(record._fields, record) if k != "bad_fields" or v]
    return f"{type(record).__name__}(" + ", ".join(f"{k}={v!r}" for k, v in items) + ")"


#: One knot in metres per second (1852 m per hour).
KNOT = 1852.0 / 3600.0
#: One international nautical mile in metres.
NAUTICAL_MILE = 1852.0


class RMC(NamedTuple):
    """Recommended minimum specific GNSS data (``$--RMC``), NMEA 0183 v4.11 Sec. 6.3.

    Attributes
    ----------
    talker : str
        Talker id (``"GP"``, ``"GN"``, ...).
    time : datetime.time or None
        UTC time of the fix.
    status : {"A", "V"} or None
        ``A`` valid, ``V`` navigation receiver warning.
    latitude, longitude : float or None
        Signed decimal degrees (north, east positive).
    speed_knots : float or None
        Speed over ground.
    course_deg : float or None
        Course over ground, degrees clockwise from true north.
    date : datetime.date or None
        UTC date.
    magnetic_variation_deg : float or None
        Signed, east positive.
    mode : str or None
        Mode indicator (NMEA 2.3+): ``A`` autonomous, ``D`` differential, ``N`` not valid, ...
    bad_fields : tuple of str
        Attributes whose field was corrupt (not a number, NaN, infinite, out of range) and is
        therefore ``None``; empty for an intact sentence, and then left out of the repr (see
        :func:`~robokit.outdoor.nmea_fields.salvage_record`).
    """

    talker: str
    time: _dt.time | None
    status: str | None
    latitude: float | None
    longitude: float | None
    speed_knots: float | None
    course_deg: float | None
    date: _dt.date | None
    magnetic_variation_deg: float | None
    mode: str | None
    bad_fields: tuple = ()

    __repr__ = _repr

    @property
    def kind(self) -> str:
        """The sentence type, ``"RMC"``."""
        return "RMC"

    @property
    def valid(self) -> bool:
        """True when the receiver flags the fix as valid (status ``A``)."""
        return self.status == "A"

    @property
    def speed_mps(self) -> float | None:
        """Speed over ground in m/s."""
        return None if self.speed_knots is None else self.speed_knots * KNOT

    @property
    def course_rad(self) -> float | None:
        """Course over ground in radians clockwise from true north."""
        return None if self.course_deg is None else math.radians(self.course_deg)

    @property
    def datetime(self) -> _dt.datetime | None:
        """UTC date and time combined (``None`` unless both are present)."""
        if self.date is None or self.time is None:
            return None
        return _dt.datetime.combine(self.date, self.time, tzinfo=_dt.timezone.utc)


class RMB(NamedTuple):
    """Recommended minimum navigation information to a waypoint (``$--RMB``), NMEA 0183 Sec. 6.3.

    Attributes
    ----------
    talker : str
    status : {"A", "V"} or None
        Data valid / warning.
    cross_track_nm : float or None
        Cross-track error in nautical miles.
    steer : {"L", "R"} or None
        Direction to steer to correct the cross-track error.
    origin_id, destination_id : str or None
        Waypoint identifiers.
    destination_latitude, destination_longitude : float or None
        Signed decimal degrees.
    range_nm : float or None
        Range to the destination in nautical miles.
    bearing_deg : float or None
        True bearing to the destination, degrees clockwise from north.
    closing_velocity_knots : float or None
        Velocity towards the destination.
    arrival : {"A", "V"} or None
        ``A`` when the arrival circle was entered.
    mode : str or None
        Mode indicator (NMEA 2.3+).
    bad_fields : tuple of str
        Attributes whose field was corrupt (not a number, NaN, infinite, out of range) and is
        therefore ``None``; empty for an intact sentence, and then left out of the repr (see
        :func:`~robokit.outdoor.nmea_fields.salvage_record`).
    """

    talker: str
    status: str | None
    cross_track_nm: float | None
    steer: str | None
    origin_id: str | None
    destination_id: str | None
    destination_latitude: float | None
    destination_longitude: float | None
    range_nm: float | None
    bearing_deg: float | None
    closing_velocity_knots: float | None
    arrival: str | None
    mode: str | None
    bad_fields: tuple = ()

    __repr__ = _repr

    @property
    def kind(self) -> str:
        """The sentence type, ``"RMB"``."""
        return "RMB"

    @property
    def range_m(self) -> float | None:
        """Range to the destination in metres."""
        return None if self.range_nm is None else self.range_nm * NAUTICAL_MILE

    @property
    def bearing_rad(self) -> float | None:
        """Bearing to the destination in radians clockwise from true north."""
        return None if self.bearing_deg is None else math.radians(self.bearing_deg)


class GGA(NamedTuple):
    """Global positioning system fix data (``$--GGA``), NMEA 0183 v4.11 Sec. 6.3.

    Attributes
    ----------
    talker : str
    time : datetime.time or None
        UTC time of the fix.
    latitude, longitude : float or None
        Signed decimal degrees.
    quality : int or None
        0 invalid, 1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float, 6 dead reckoning, ...
    satellites : int or None
        Satellites in use.
    hdop : float or None
        Horizontal dilution of precision.
    altitude_m : float or None
        Antenna altitude above mean sea level (metres).
    geoid_separation_m : float or None
        Geoid height above the WGS84 ellipsoid (metres).
    dgps_age_s : float or None
        Age of differential corrections (seconds).
    dgps_station : str or None
        Differential reference station id.
    bad_fields : tuple of str
        Attributes whose field was corrupt (not a number, NaN, infinite, out of range) and is
        therefore ``None``; empty for an intact sentence, and then left out of the repr (see
        :func:`~robokit.outdoor.nmea_fields.salvage_record`).
    """

    talker: str
    time: _dt.time | None
    latitude: float | None
    longitude: float | None
    quality: int | None
    satellites: int | None
    hdop: float | None
    altitude_m: float | None
    geoid_separation_m: float | None
    dgps_age_s: float | None
    dgps_station: str | None
    bad_fields: tuple = ()

    __repr__ = _repr

    @property
    def kind(self) -> str:
        """The sentence type, ``"GGA"``."""
        return "GGA"

    @property
    def valid(self) -> bool:
        """True for a fix (quality > 0)."""
        return bool(self.quality)


class HDG(NamedTuple):
    """Heading, deviation and variation (``$--HDG``; ``$HCHDG`` from a magnetic compass).

    Attributes
    ----------
    talker : str
        ``"HC"`` for a magnetic compass.
    heading_deg : float or None
        Magnetic sensor heading, degrees clockwise.
    deviation_deg : float or None
        Magnetic deviation, signed (east positive).
    variation_deg : float or None
        Magnetic variation, signed (east positive).
    bad_fields : tuple of str
        Attributes whose field was corrupt (not a number, NaN, infinite, out of range) and is
        therefore ``None``; empty for an intact sentence, and then left out of the repr (see
        :func:`~robokit.outdoor.nmea_fields.salvage_record`).

    Notes
    -----
    NMEA 0183 v4.11 Sec. 6.3: true heading = heading + deviation + variation.
    """

    talker: str
    heading_deg: float | None
    deviation_deg: float | None
    variation_deg: float | None
    bad_fields: tuple = ()

    __repr__ = _repr

    @property
    def kind(self) -> str:
        """The sentence type, ``"HDG"``."""
        return "HDG"

    @property
    def true_heading_deg(self) -> float | None:
        """Heading corrected by deviation and variation, in [0, 360) degrees."""
        if self.heading_deg is None:
            return None
        return (self.heading_deg + (self.deviation_deg or 0.0) + (self.variation_deg or 0.0)) % 360.0


class Sentence(NamedTuple):
    """Any other sentence: ``talker`` (``"P"`` for proprietary), ``kind`` and raw ``fields``."""

    talker: str
    kind: str
    fields: tuple

    @property
    def bad_fields(self) -> tuple:
        """Always empty: the fields of a generic sentence are kept as text, never judged."""
        return ()
