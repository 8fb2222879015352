"""Build NMEA 0183 sentences: what the simulated GPS receiver and compass emit.

The simulation talks to the navigator in the same text a Garmin eTrex sends over its serial port
(Hamid et al. 2009), so the whole stack runs through :mod:`robokit.outdoor.nmea`.
Formats follow NMEA 0183 v4.11, Sec. 5.3 (framing) and 6.3 (RMC, RMB, GGA, HDG).

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

from ..validation import as_rng, as_finite_scalar, as_int, as_positive, as_text, describe
from .nmea import NMEAFormatError, nmea_checksum
from .nmea_records import KNOT

__all__ = ["format_sentence", "format_latitude", "format_longitude", "format_time", "format_date",
           "rmc_sentence", "gga_sentence", "hdg_sentence", "rmb_sentence",
           "random_sentences"]


def format_sentence(address: str, fields: list) -> str:
    """Frame an address and fields as ``$ADDRESS,f1,f2,...*hh`` (no line ending).

    Parameters
    ----------
    address : str
        Talker and type, e.g. ``"GPRMC"`` (upper-case letters and digits).
    fields : list
        Field values; ``None`` becomes an empty field, everything else ``str(value)``.

    Returns
    -------
    str
        The sentence with its checksum.

    Raises
    ------
    NMEAFormatError
        If the address is malformed or a field contains ``$``, ``*``, ``,`` or a line break.

    Notes
    -----
    NMEA 0183 v4.11, Sec. 5.3 (sentence framing and checksum).
    """
    if not isinstance(address, str) or len(address) < 2 or not address.isalnum() or address != address.upper():
        raise NMEAFormatError(f"address: expected upper-case letters/digits like 'GPRMC', got {address!r}")
    texts = ["" if f is None else str(f) for f in fields]
    for i, t in enumerate(texts):
        if any(c in t for c in "$*,\r\n!"):
            raise NMEAFormatError(f"fields[{i}]: expected no reserved characters ($ * , ! CR LF), got {t!r}")
    body = ",".join([address] + texts)
    return f"${body}*{nmea_checksum(body)}"


def _angle(deg: float | None, name: str, width: int, limit: float, pos: str, neg: str, decimals: int) -> tuple[str, str]:
    if deg is None:
        return "", ""
    x = as_finite_scalar(deg, name)
    if abs(x) > limit:
        raise ValueError(f"{name}: expected degrees in [-{limit:g}, {limit:g}], got {x}")
    a = abs(x)
    d = int(a)
    m = round((a - d) * 60.0, decimals)
    if m >= 60.0:
        d, m = d + 1, 0.0
    return f"{d:0{width}d}{m:0{3 + decimals}.{decimals}f}", neg if x < 0 else pos


def format_latitude(deg: float | None, decimals: int = 4, *, name: str = "deg") -> tuple[str, str]:
    """Return ``(ddmm.mmmm, "N"|"S")`` for signed degrees (``("", "")`` for ``None``).

    Raises
    ------
    ValueError
        If ``deg`` is outside [-90, 90] or not finite.

    Notes
    -----
    NMEA 0183 v4.11, Sec. 6.2 (latitude field). Four decimals of a minute are about 0.2 m.
    """
    return _angle(deg, name, 2, 90.0, "N", "S", as_int(decimals, "decimals", minimum=0, maximum=8))


def format_longitude(deg: float | None, decimals: int = 4, *, name: str = "deg") -> tuple[str, str]:
    """Return ``(dddmm.mmmm, "E"|"W")`` for signed degrees (``("", "")`` for ``None``).

    Raises
    ------
    ValueError
        If ``deg`` is outside [-180, 180] or not finite.

    Notes
    -----
    NMEA 0183 v4.11, Sec. 6.2 (longitude field).
    """
    return _angle(deg, name, 3, 180.0, "E", "W", as_int(decimals, "decimals", minimum=0, maximum=8))


def format_time(t: _dt.time | None, *, name: str = "t") -> str:
    """Return ``hhmmss.ss`` for a ``datetime.time`` (``""`` for ``None``); NMEA 0183 Sec. 6.2.

    ``name`` is the argument named in the error (the caller's own argument).
    """
    if t is None:
        return ""
    if not isinstance(t, _dt.time):
        raise TypeError(f"{name}: expected a datetime.time, got {describe(t)}")
    return f"{t.hour:02d}{t.minute:02d}{t.second:02d}.{t.microsecond // 10000:02d}"


def format_date(d: _dt.date | None) -> str:
    """Return ``ddmmyy`` for a ``datetime.date`` (``""`` for ``None``); NMEA 0183 Sec. 6.3 (RMC)."""
    if d is None:
        return ""
    if not isinstance(d, _dt.date):
        raise TypeError(f"d: expected a datetime.date, got {describe(d)}")
    return f"{d.day:02d}{d.month:02d}{d.year % 100:02d}"


def _num(x: float | None, name: str, fmt: str) -> str:
    return "" if x is None else format(as_finite_scalar(x, name), fmt)


def _talker(talker: str) -> str:
    if not (isinstance(talker, str) and len(talker) == 2 and talker.isalnum() and talker.isupper()):
        raise (ValueError if isinstance(talker, str) else TypeError)(
            f"talker: expected two upper-case letters like 'GP', got {describe(talker)}")
    return talker


def rmc_sentence(when: _dt.datetime, latitude: float | None, longitude: float | None, *,
                 speed_mps: float | None = None, course_deg: float | None = None, valid: bool = True,
                 magnetic_variation_deg: float | None = None, talker: str = "GP") -> str:
    """Build a ``$--RMC`` sentence (NMEA 0183 v4.11 Sec. 6.3) from SI values.

    Parameters
    ----------
    when : datetime.datetime
        UTC date and time of the fix.
    latitude, longitude : float or None
        Signed decimal degrees.
    speed_mps : float, optional
        Speed over ground in m/s (written in knots).
    course_deg : float, optional
        Course over ground, degrees clockwise from north, written modulo 360.
    valid : bool, default True
        Status ``A`` (valid) or ``V`` (warning).
    magnetic_variation_deg : float, optional
        Signed, east positive.
    talker : str, default "GP"
        Two upper-case letters (GP, GN, GL, ...).

    Returns
    -------
    str

    Raises
    ------
    TypeError, ValueError
        For a non-datetime ``when`` or out-of-range values.
    Notes
    -----
    RMC field layout, NMEA 0183 v4.11 Sec. 6.3 (the fix sentence of Hamid et al. 2009).

    Examples
    --------
    >>> import datetime as dt
    >>> rmc_sentence(dt.datetime(2012, 6, 4, 2, 30, 15), 6.4590, 100.3505, speed_mps=0.7, course_deg=37.5)
    '$GPRMC,023015.00,A,0627.5400,N,10021.0300,E,1.36,37.5,040612,,,A*5C'
    """
    if not isinstance(when, _dt.datetime):
        raise TypeError(f"when: expected a datetime.datetime, got {describe(when)}")
    talker = _talker(talker)
    lat, ns = format_latitude(latitude, name="latitude")
    lon, ew = format_longitude(longitude, name="longitude")
    speed = None if speed_mps is None else as_positive(speed_mps, "speed_mps", allow_zero=True) / KNOT
    course = None if course_deg is None else round(as_finite_scalar(course_deg, "course_deg"), 1) % 360.0
    var = None if magnetic_variation_deg is None else as_finite_scalar(magnetic_variation_deg, "magnetic_variation_deg")
    return format_sentence(talker + "RMC", [
        format_time(when.time()), "A" if valid else "V", lat, ns, lon, ew,
        _num(speed, "speed_mps", ".2f"), _num(course, "course_deg", ".1f"), format_date(when.date()),
        "" if var is None else f"{abs(var):.1f}", "" if var is None else ("W" if var < 0 else "E"),
        "A" if valid else "N"])


def gga_sentence(when: _dt.time, latitude: float | None, longitude: float | None, *, quality: int = 1,
                 satellites: int = 8, hdop: float = 1.0, altitude_m: float = 0.0,
                 geoid_separation_m: float | None = None, talker: str = "GP") -> str:
    """Build a ``$--GGA`` sentence (NMEA 0183 v4.11 Sec. 6.3).

    Parameters
    ----------
    when : datetime.time or None
        UTC time of the fix (``None`` leaves the field empty).
    latitude, longitude : float or None
        Signed decimal degrees.
    quality : int, default 1
        Fix quality (0 invalid, 1 GPS, 2 DGPS, ...).
    satellites : int, default 8
    hdop : float, default 1.0
    altitude_m : float or None, default 0.0
        ``None`` leaves the field empty.
    geoid_separation_m : float, optional
    talker : str, default "GP"
        Two upper-case letters (GP, GN, GL, ...).

    Returns
    -------
    str
    Notes
    -----
    GGA field layout, NMEA 0183 v4.11 Sec. 6.3.

    Examples
    --------
    >>> import datetime as dt
    >>> gga_sentence(dt.time(2, 30, 15), 6.4590, 100.3505, satellites=8, hdop=1.2, altitude_m=12.0)
    '$GPGGA,023015.00,0627.5400,N,10021.0300,E,1,08,1.2,12.0,M,,M,,*4C'
    """
    talker = _talker(talker)
    when_text = format_time(when, name="when")
    lat, ns = format_latitude(latitude, name="latitude")
    lon, ew = format_longitude(longitude, name="longitude")
    q = as_int(quality, "quality", minimum=0, maximum=9)
    n = as_int(satellites, "satellites", minimum=0, maximum=99)
    return format_sentence(talker + "GGA", [
        when_text, lat, ns, lon, ew, q, f"{n:02d}", _num(as_positive(hdop, "hdop"), "hdop", ".1f"),
        _num(altitude_m, "altitude_m", ".1f"), "M", _num(geoid_separation_m, "geoid_separation_m", ".1f"), "M", "", ""])


def hdg_sentence(heading_deg: float, *, deviation_deg: float | None = None,
                 variation_deg: float | None = None, talker: str = "HC") -> str:
    """Build a ``$--HDG`` compass sentence (NMEA 0183 v4.11 Sec. 6.3; ``$HCHDG`` in Hamid et al.).

    Parameters
    ----------
    heading_deg : float
        Magnetic heading, degrees clockwise from north (written modulo 360).
    deviation_deg, variation_deg : float, optional
        Signed, east positive.
    talker : str, default "HC"
        Two upper-case letters (HC: magnetic compass).

    Returns
    -------
    str
    Notes
    -----
    HDG field layout, NMEA 0183 v4.11 Sec. 6.3 (``$HCHDG``, the compass of Hamid et al. 2009).

    Examples
    --------
    >>> hdg_sentence(36.8, deviation_deg=0.0, variation_deg=-0.3)
    '$HCHDG,36.8,0.0,E,0.3,W*6E'
    """
    talker = _talker(talker)
    h = round(as_finite_scalar(heading_deg, "heading_deg"), 1) % 360.0

    def signed(x, name):
        if x is None:
            return ["", ""]
        v = as_finite_scalar(x, name)
        return [f"{abs(v):.1f}", "W" if v < 0 else "E"]

    return format_sentence(talker + "HDG", [f"{h:.1f}"] + signed(deviation_deg, "deviation_deg")
                           + signed(variation_deg, "variation_deg"))


def rmb_sentence(destination_latitude: float, destination_longitude: float, range_m: float, bearing_deg: float,
                 *, cross_track_m: float = 0.0, origin_id: str = "000", destination_id: str = "001",
                 closing_velocity_mps: float = 0.0, arrived: bool = False, talker: str = "GP") -> str:
    """Build a ``$--RMB`` navigation sentence (NMEA 0183 v4.11 Sec. 6.3).

    Parameters
    ----------
    destination_latitude, destination_longitude : float or None
        Signed decimal degrees of the active waypoint (``None`` leaves the fields empty).
    range_m : float
        Range to it in metres (written in nautical miles).
    bearing_deg : float
        True bearing to it, degrees clockwise from north.
    cross_track_m : float, default 0
        Signed cross-track error (positive: steer left).
    origin_id, destination_id : str
    closing_velocity_mps : float, default 0
    arrived : bool, default False
    talker : str, default "GP"
        Two upper-case letters (GP, GN, GL, ...).

    Returns
    -------
    str
    Notes
    -----
    RMB field layout, NMEA 0183 v4.11 Sec. 6.3 (range and bearing to the destination waypoint).

    Examples
    --------
    >>> rmb_sentence(6.4594, 100.3509, range_m=65.0, bearing_deg=44.0, destination_id="002")
    '$GPRMB,A,0.000,L,000,002,0627.5640,N,10021.0540,E,0.035,44.0,0.0,V,A*58'
    """
    talker = _talker(talker)
    lat, ns = format_latitude(destination_latitude, name="destination_latitude")
    lon, ew = format_longitude(destination_longitude, name="destination_longitude")
    origin_id, destination_id = as_text(origin_id, "origin_id"), as_text(destination_id, "destination_id")
    xte = as_finite_scalar(cross_track_m, "cross_track_m") / 1852.0
    rng = as_positive(range_m, "range_m", allow_zero=True) / 1852.0
    brg = round(as_finite_scalar(bearing_deg, "bearing_deg"), 1) % 360.0
    vel = as_finite_scalar(closing_velocity_mps, "closing_velocity_mps") / KNOT
    return format_sentence(talker + "RMB", [
        "A", f"{abs(xte):.3f}", "L" if xte >= 0 else "R", origin_id, destination_id, lat, ns, lon, ew,
        f"{rng:.3f}", f"{brg:.1f}", f"{vel:.1f}", "A" if arrived else "V", "A"])


def random_sentences(count: int, rng=None, *, empty_fraction: float = 0.1) -> list[str]:
    """Return ``count`` varied, valid NMEA sentences for tests, benchmarks and the lesson.

    The mix cycles through RMC, GGA, HDG, RMB and two generic types (GSA, VTG) with talkers GP,
    GN, GL and HC, positions in all four hemispheres, and a fraction of sentences with optional
    fields left empty.

    Parameters
    ----------
    count : int
        Number of sentences (>= 0).
    rng : numpy.random.Generator or int, optional
        Source of randomness (see :func:`robokit.validation.as_rng`).
    empty_fraction : float, default 0.1
        Probability that a sentence leaves its optional fields empty.

    Returns
    -------
    list of str

    Notes
    -----
    Field layouts as in NMEA 0183 v4.11, Sec. 6.3.
    Examples
    --------
    >>> random_sentences(3, rng=5)[2]
    '$HCHDG,97.7,,,,*7B'
    """
    n = as_int(count, "count", minimum=0)
    p = as_positive(empty_fraction, "empty_fraction", allow_zero=True)
    if p > 1:
        raise ValueError(f"empty_fraction: expected a probability in [0, 1], got {p}")
    g = as_rng(rng)
    out = []
    base = _dt.datetime(2001, 1, 1, tzinfo=None)
    for i in range(n):
        lat = float(g.uniform(-89.9, 89.9))
        lon = float(g.uniform(-179.9, 179.9))
        when = base + _dt.timedelta(seconds=float(g.uniform(0, 25 * 365 * 86400)))
        when = when.replace(microsecond=(when.microsecond // 10000) * 10000)
        empty = bool(g.random() < p)
        talker = ("GP", "GN", "GL")[int(g.integers(3))]
        kind = i % 6
        if kind == 0:
            out.append(rmc_sentence(when, None if empty else lat, None if empty else lon,
                                    speed_mps=None if empty else float(g.uniform(0, 30)),
                                    course_deg=None if empty else float(g.uniform(0, 360)),
                                    valid=not empty,
                                    magnetic_variation_deg=None if empty else float(g.uniform(-20, 20)),
                                    talker=talker))
        elif kind == 1:
            out.append(gga_sentence(when.time(), None if empty else lat, None if empty else lon,
                                    quality=0 if empty else int(g.integers(1, 3)),
                                    satellites=int(g.integers(0, 13)), hdop=float(g.uniform(0.5, 9)),
                                    altitude_m=float(g.uniform(-50, 3000)),
                                    geoid_separation_m=None if empty else float(g.uniform(-90, 80)),
                                    talker=talker))
        elif kind == 2:
            out.append(hdg_sentence(float(g.uniform(0, 360)),
                                    deviation_deg=None if empty else float(g.uniform(-5, 5)),
                                    variation_deg=None if empty else float(g.uniform(-20, 20))))
        elif kind == 3:
            out.append(rmb_sentence(lat, lon, float(g.uniform(0, 20000)), float(g.uniform(0, 360)),
                                    cross_track_m=float(g.uniform(-500, 500)),
                                    destination_id=f"{int(g.integers(1000)):03d}",
                                    closing_velocity_mps=float(g.uniform(0, 5)), talker=talker))
        elif kind == 4:
            out.append(format_sentence(talker + "GSA", ["A", "3"] + [f"{int(s):02d}" for s in g.integers(1, 33, 6)]
                                       + [""] * 6 + ["1.8", "1.0", "1.5"]))
        else:
            out.append(format_sentence(talker + "VTG", [f"{g.uniform(0, 360):.1f}", "T", "", "M",
                                                        f"{g.uniform(0, 20):.2f}", "N", f"{g.uniform(0, 37):.2f}",
                                                        "K", "A"]))
    return out
