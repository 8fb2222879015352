"""NMEA 0183 fields: conversions, the builders of the typed records, and the error hierarchy.

Latitude/longitude ``ddmm.mmmm``/``dddmm.mmmm`` with hemisphere, UTC time ``hhmmss.ss``, date
``ddmmyy``, signed values with E/W direction, single-letter flags; empty fields become ``None``
(NMEA 0183 v4.11, Secs. 6.2-6.3). :data:`RECORD_PARSERS` turns the fields of an RMC, RMB, GGA or
HDG sentence into its record (:mod:`robokit.outdoor.nmea_records`); :func:`robokit.outdoor.nmea.parse_sentence`
frames and checks a sentence and hands its fields over.

A number must be finite: ``nan``, ``inf`` and ``infinity`` (which Python's ``float`` reads) are as
corrupt as ``X.138``. A corrupt field raises :class:`NMEAFieldError`. When it is a field the record
can do without, :func:`salvage_record` builds the record again with that field empty (``None``) and
its name in the record's ``bad_fields``, so a good position survives a corrupt speed (as pynmea2
keeps such a sentence). The fields a record exists to carry - the position of RMC and GGA, the
destination of RMB, the heading of HDG - are essential: a corrupt one rejects the sentence.

References
----------
.. [1] National Marine Electronics Association, *NMEA 0183 Standard for Interfacing Marine
   Electronic Devices*, version 4.11, 2018.
"""
from __future__ import annotations

import datetime as _dt
from typing import Any, Callable

from .nmea_records import GGA, HDG, RMB, RMC

__all__ = ["NMEAError", "NMEAChecksumError", "NMEAFormatError", "NMEAFieldError",
           "parse_latitude", "parse_longitude", "parse_time", "parse_date", "RECORD_PARSERS", "salvage_record"]


class NMEAError(ValueError):
    """Base class of every NMEA problem (a ``ValueError``, so callers may catch either)."""


class NMEAChecksumError(NMEAError):
    """The checksum is missing (when required), not two hex digits, or does not match."""


class NMEAFormatError(NMEAError):
    """The sentence is malformed: framing, address, too few fields, or a field out of range."""


class NMEAFieldError(NMEAFormatError):
    """One field is corrupt: not a number, not finite, out of range or not one of its letters.

    ``field`` is the name of the record attribute it fills (``"speed_knots"``).
    """

    def __init__(self, name: str, message: str) -> None:
        super().__init__(f"{name}: {message}")
        self.field = name.rpartition(" ")[2]   # "RMC speed_knots" -> "speed_knots"


def _float(text: str, name: str) -> float | None:
    if not text:
        return None
    try:
        x = float(text)
    except ValueError:
        raise NMEAFieldError(name, f"expected a number, got {text!r}") from None
    if x - x != 0.0:   # NaN or infinity: float() reads "nan" and "inf", NMEA has neither
        raise NMEAFieldError(name, f"expected a finite number, got {text!r}")
    return x


def _int(text: str, name: str) -> int | None:
    if not text:
        return None
    if not text.isdigit():
        raise NMEAFieldError(name, f"expected a non-negative integer, got {text!r}")
    return int(text)


def _angle(value: str, hemi: str, name: str, max_deg: int, pos: str, neg: str) -> float | None:
    if not value and not hemi:
        return None
    if not value or hemi not in (pos, neg):
        raise NMEAFieldError(name, f"expected a value with hemisphere {pos}/{neg}, got {value!r},{hemi!r}")
    dot = value.find(".")
    whole = value if dot < 0 else value[:dot]
    if len(whole) < 3 or not whole.isdigit():
        raise NMEAFieldError(name, f"expected {'dd' if max_deg == 90 else 'ddd'}mm.mmmm, got {value!r}")
    try:
        minutes = float(value[len(whole) - 2:])
    except ValueError:
        raise NMEAFieldError(name, f"expected {'dd' if max_deg == 90 else 'ddd'}mm.mmmm, got {value!r}") from None
    degrees = float(whole[:-2]) + minutes / 60.0
    if minutes >= 60.0 or degrees > max_deg:
        raise NMEAFieldError(name, f"expected at most {max_deg} degrees with minutes < 60, got {value!r}")
    return -degrees if hemi == neg else degrees


def parse_latitude(value: str, hemisphere: str) -> float | None:
    """Convert an NMEA latitude ``ddmm.mmmm`` and ``N``/``S`` to signed decimal degrees.

    Parameters
    ----------
    value : str
        Degrees (two digits) and decimal minutes, e.g. ``"4807.038"``.
    hemisphere : str
        ``"N"`` or ``"S"``.

    Returns
    -------
    float or None
        Degrees in [-90, 90], north positive; ``None`` when both fields are empty.

    Raises
    ------
    NMEAFormatError
        Malformed value, missing or wrong hemisphere, minutes >= 60 or more than 90 degrees.

    Notes
    -----
    NMEA 0183 v4.11, Sec. 6.2 (field type "latitude").
    """
    return _angle(str(value), str(hemisphere), "latitude", 90, "N", "S")


def parse_longitude(value: str, hemisphere: str) -> float | None:
    """Convert an NMEA longitude ``dddmm.mmmm`` and ``E``/``W`` to signed decimal degrees.

    Parameters
    ----------
    value : str
        Degrees (three digits) and decimal minutes, e.g. ``"01131.000"``.
    hemisphere : str
        ``"E"`` or ``"W"``.

    Returns
    -------
    float or None
        Degrees in [-180, 180], east positive; ``None`` when both fields are empty.

    Raises
    ------
    NMEAFormatError
        Malformed value, missing or wrong hemisphere, minutes >= 60 or more than 180 degrees.

    Notes
    -----
    NMEA 0183 v4.11, Sec. 6.2 (field type "longitude").
    """
    return _angle(str(value), str(hemisphere), "longitude", 180, "E", "W")


def parse_time(value: str) -> _dt.time | None:
    """Convert an NMEA UTC time ``hhmmss.ss`` to a ``datetime.time`` (``None`` when empty).

    Raises
    ------
    NMEAFormatError
        If the field is not ``hhmmss[.s...]`` or hours/minutes/seconds are out of range.

    Notes
    -----
    NMEA 0183 v4.11, Sec. 6.2 (field type "time").
    """
    return _time(value, "time")


def _time(value: str, name: str) -> _dt.time | None:
    if not value:
        return None
    head = value[:6]
    frac = value[6:]
    if len(head) < 6 or not head.isdigit() or (frac and (frac[0] != "." or not (frac[1:].isdigit() or frac == "."))):
        raise NMEAFieldError(name, f"expected hhmmss.ss, got {value!r}")
    h, m, s = int(head[:2]), int(head[2:4]), int(head[4:6])
    if h > 23 or m > 59 or s > 59:
        raise NMEAFieldError(name, f"expected hours < 24, minutes < 60, seconds < 60, got {value!r}")
    us = int(round(float("0" + frac) * 1e6)) if len(frac) > 1 else 0
    return _dt.time(h, m, s, min(us, 999999))


def parse_date(value: str) -> _dt.date | None:
    """Convert an NMEA date ``ddmmyy`` to a ``datetime.date`` (``None`` when empty).

    Two-digit years 69-99 are 1969-1999 and 00-68 are 2000-2068 (the POSIX ``%y`` rule, as
    ``time.strptime`` and pynmea2 use).

    Raises
    ------
    NMEAFormatError
        If the field is not six digits or is not a calendar date (e.g. 310299).

    Notes
    -----
    NMEA 0183 v4.11, Sec. 6.3 (RMC field 9, "date: ddmmyy").
    """
    return _date(value, "date")


def _date(value: str, name: str) -> _dt.date | None:
    if not value:
        return None
    if len(value) != 6 or not value.isdigit():
        raise NMEAFieldError(name, f"expected ddmmyy, got {value!r}")
    yy = int(value[4:])
    try:
        return _dt.date(1900 + yy if yy >= 69 else 2000 + yy, int(value[2:4]), int(value[:2]))
    except ValueError:
        raise NMEAFieldError(name, f"expected a calendar date ddmmyy, got {value!r}") from None


def _signed(value: str, direction: str, name: str, pos: str, neg: str) -> float | None:
    x = _float(value, name)
    if x is None:
        return None
    if direction == neg:
        return -x
    if direction == pos or not direction:
        return x
    raise NMEAFieldError(name, f"expected direction {pos}/{neg}, got {direction!r}")


def _flag(value: str, name: str, allowed: str) -> str | None:
    if not value:
        return None
    if len(value) != 1 or value not in allowed:
        raise NMEAFieldError(name, f"expected one of {list(allowed)}, got {value!r}")
    return value


def _need(f: list, n: int, kind: str) -> None:
    if len(f) < n:
        raise NMEAFormatError(f"{kind}: expected at least {n} fields, got {len(f)}")


# The builders take the parsers of the fields a record can do without as keyword arguments, so that
# salvage_record can rebuild a record with lenient ones; essential fields (position, destination,
# heading) always use the strict parsers and reject the sentence. ``bad`` becomes ``bad_fields``.

def _rmc(talker: str, f: list, *, num=_float, flag=_flag, time=_time, date=_date, signed=_signed, bad=(), **_unused) -> RMC:
    _need(f, 9, "RMC")
    f = f + [""] * (13 - len(f)) if len(f) < 13 else f
    return RMC(talker, time(f[0], "RMC time"), flag(f[1], "RMC status", "AV"),
               _angle(f[2], f[3], "RMC latitude", 90, "N", "S"),
               _angle(f[4], f[5], "RMC longitude", 180, "E", "W"),
               num(f[6], "RMC speed_knots"), num(f[7], "RMC course_deg"), date(f[8], "RMC date"),
               signed(f[9], f[10], "RMC magnetic_variation_deg", "E", "W"), f[11] or None, tuple(bad))


def _rmb(talker: str, f: list, *, num=_float, flag=_flag, bad=(), **_unused) -> RMB:
    _need(f, 13, "RMB")
    xte = num(f[1], "RMB cross_track_nm")
    steer = flag(f[2], "RMB steer", "LR")
    return RMB(talker, flag(f[0], "RMB status", "AV"), xte, steer, f[3] or None, f[4] or None,
               _angle(f[5], f[6], "RMB destination_latitude", 90, "N", "S"),
               _angle(f[7], f[8], "RMB destination_longitude", 180, "E", "W"),
               num(f[9], "RMB range_nm"), num(f[10], "RMB bearing_deg"),
               num(f[11], "RMB closing_velocity_knots"), flag(f[12], "RMB arrival", "AV"),
               f[13] or None if len(f) > 13 else None, tuple(bad))


def _gga(talker: str, f: list, *, num=_float, integer=_int, time=_time, bad=(), **_unused) -> GGA:
    _need(f, 9, "GGA")
    f = f + [""] * (14 - len(f)) if len(f) < 14 else f
    return GGA(talker, time(f[0], "GGA time"),
               _angle(f[1], f[2], "GGA latitude", 90, "N", "S"),
               _angle(f[3], f[4], "GGA longitude", 180, "E", "W"),
               integer(f[5], "GGA quality"), integer(f[6], "GGA satellites"), num(f[7], "GGA hdop"),
               num(f[8], "GGA altitude_m"), num(f[10], "GGA geoid_separation_m"),
               num(f[12], "GGA dgps_age_s"), f[13] or None, tuple(bad))


def _hdg(talker: str, f: list, *, signed=_signed, bad=(), **_unused) -> HDG:
    _need(f, 5, "HDG")
    heading = _float(f[0], "HDG heading_deg")
    if heading is not None and not 0.0 <= heading <= 360.0:
        raise NMEAFieldError("HDG heading_deg", f"expected degrees in [0, 360], got {f[0]!r}")
    return HDG(talker, heading, signed(f[1], f[2], "HDG deviation_deg", "E", "W"),
               signed(f[3], f[4], "HDG variation_deg", "E", "W"), tuple(bad))


#: Builders of the typed records from a sentence's fields (after the address), by sentence type.
RECORD_PARSERS: dict[str, Callable[..., Any]] = {"RMC": _rmc, "RMB": _rmb, "GGA": _gga, "HDG": _hdg}


def _lenient(parse: Callable[..., Any], bad: list[str]) -> Callable[..., Any]:
    def parse_or_empty(*args: Any) -> Any:
        try:
            return parse(*args)
        except NMEAFieldError as exc:
            bad.append(exc.field)
            return None
    return parse_or_empty


def salvage_record(kind: str, talker: str, fields: list) -> Any:
    """Build the record of a sentence with its corrupt optional fields left empty.

    Parameters
    ----------
    kind : {"RMC", "RMB", "GGA", "HDG"}
        The sentence type (a key of :data:`RECORD_PARSERS`).
    talker : str
        The talker id.
    fields : list of str
        The sentence's fields after the address.

    Returns
    -------
    RMC, RMB, GGA or HDG
        The record, each corrupt field the record can do without set to ``None`` and named (as
        the record's attribute) in ``bad_fields``, in field order.

    Raises
    ------
    NMEAFieldError
        If an essential field is corrupt: the position of RMC or GGA, the destination of RMB, the
        heading of HDG.
    NMEAFormatError
        If the sentence has too few fields.

    Notes
    -----
    NMEA 0183 v4.11, Sec. 6.3 layouts. pynmea2 converts fields lazily, so it too keeps a sentence
    whose speed is corrupt and fails only when that field is read.

    Examples
    --------
    >>> rec = salvage_record("RMC", "GP", "123519,A,4807.038,N,01131.000,E,X.138,084.4,230394,003.1,W".split(","))
    >>> rec.latitude, rec.speed_knots, rec.course_deg, rec.bad_fields
    (48.1173, None, 84.4, ('speed_knots',))
    """
    bad: list[str] = []
    rec = RECORD_PARSERS[kind](talker, fields, num=_lenient(_float, bad), flag=_lenient(_flag, bad),
                               time=_lenient(_time, bad), date=_lenient(_date, bad),
                               signed=_lenient(_signed, bad), integer=_lenient(_int, bad))
    return rec._replace(bad_fields=tuple(bad))
