"""NMEA 0183 parser: agreement with pynmea2 field by field, and bad input that never stops a stream."""
from __future__ import annotations

import datetime as dt
import io

import numpy as np
import pytest

pynmea2 = pytest.importorskip("pynmea2")

from robokit.outdoor.nmea import (GGA, HDG, RMB, RMC, BadFields, NMEAChecksumError, NMEAError, NMEAFieldError,
                                  NMEAFormatError, NMEAReader, Sentence, nmea_checksum, parse_date, parse_latitude,
                                  parse_longitude, parse_sentence, parse_time, read_nmea)
from robokit.outdoor.nmea_fields import RECORD_PARSERS
from robokit.outdoor.nmea_write import (format_latitude, format_longitude, format_sentence, gga_sentence,
                                        hdg_sentence, random_sentences, rmb_sentence, rmc_sentence)


def _f(x):
    return None if x in (None, "") else float(x)


def _signed(value, direction, neg):
    v = _f(value)
    return None if v is None else (-v if direction == neg else v)


def _lat(msg, value, hemi):
    # pynmea2's own latitude conversion for RMC/GGA; RMB's destination uses the same rule
    if not value:
        return None
    deg = float(value[:2]) + float(value[2:]) / 60
    return -deg if hemi == "S" else deg


def _lon(msg, value, hemi):
    if not value:
        return None
    deg = float(value[:3]) + float(value[3:]) / 60
    return -deg if hemi == "W" else deg


def _time(t):
    return None if t is None else (t.hour, t.minute, t.second, t.microsecond)


def pynmea2_view(msg):
    """What pynmea2 says about each of our record's fields (in our units and sign conventions)."""
    kind = msg.sentence_type
    if kind == "RMC":
        return {"time": _time(msg.timestamp), "status": msg.status or None,
                "latitude": msg.latitude if msg.lat else None, "longitude": msg.longitude if msg.lon else None,
                "speed_knots": msg.spd_over_grnd, "course_deg": msg.true_course, "date": msg.datestamp,
                "magnetic_variation_deg": _signed(msg.mag_variation, msg.mag_var_dir, "W"),
                "mode": msg.mode_indicator or None}
    if kind == "GGA":
        return {"time": _time(msg.timestamp), "latitude": msg.latitude if msg.lat else None,
                "longitude": msg.longitude if msg.lon else None, "quality": msg.gps_qual,
                "satellites": int(msg.num_sats) if msg.num_sats else None, "hdop": _f(msg.horizontal_dil),
                "altitude_m": msg.altitude, "geoid_separation_m": _f(msg.geo_sep),
                "dgps_age_s": _f(msg.age_gps_data), "dgps_station": msg.ref_station_id or None}
    if kind == "HDG":
        return {"heading_deg": _f(msg.heading), "deviation_deg": _signed(msg.deviation, msg.dev_dir, "W"),
                "variation_deg": _signed(msg.variation, msg.var_dir, "W")}
    if kind == "RMB":
        return {"status": msg.status or None, "cross_track_nm": _f(msg.cross_track_error),
                "steer": msg.cte_correction_dir or None, "origin_id": msg.origin_waypoint_id or None,
                "destination_id": msg.dest_waypoint_id or None,
                "destination_latitude": _lat(msg, msg.dest_lat, msg.dest_lat_dir),
                "destination_longitude": _lon(msg, msg.dest_lon, msg.dest_lon_dir),
                "range_nm": _f(msg.dest_range), "bearing_deg": _f(msg.dest_true_bearing),
                "closing_velocity_knots": _f(msg.dest_velocity), "arrival": msg.arrival_alarm or None}
    return {"fields": tuple(msg.data)}


def ours_view(rec, keys):
    out = {}
    for k in keys:
        v = getattr(rec, k)
        out[k] = _time(v) if k == "time" else v
    return out


HAND_WRITTEN = [
    "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A",
    "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47",
    "$HCHDG,101.1,,,7.1,W*3C",
    "$GPRMB,A,0.66,L,003,004,4917.24,N,12309.57,W,001.3,052.5,000.5,V*20",
    "$GNRMC,,V,,,,,,,,,,N*4D",
    "$GNGGA,,,,,,0,00,99.99,,,,,,*56",
]


def corpus():
    return HAND_WRITTEN + random_sentences(600, np.random.default_rng(5), empty_fraction=0.25)


def test_corpus_covers_talkers_hemispheres_and_empty_fields():
    recs = [parse_sentence(s) for s in corpus()]
    talkers = {r.talker for r in recs}
    assert {"GP", "GN", "GL", "HC"} <= talkers
    lats = [r.latitude for r in recs if isinstance(r, (RMC, GGA)) and r.latitude is not None]
    lons = [r.longitude for r in recs if isinstance(r, (RMC, GGA)) and r.longitude is not None]
    assert min(lats) < 0 < max(lats) and min(lons) < 0 < max(lons)
    assert any(isinstance(r, RMC) and r.latitude is None for r in recs)
    assert any(isinstance(r, GGA) and r.geoid_separation_m is None for r in recs)
    assert {type(r) for r in recs} == {RMC, GGA, HDG, RMB, Sentence}


@pytest.mark.parametrize("text", corpus())
def test_fields_agree_with_pynmea2(text):
    theirs = pynmea2_view(pynmea2.parse(text, check=True))
    rec = parse_sentence(text)
    if isinstance(rec, Sentence):
        assert rec.fields == theirs["fields"]
        return
    ours = ours_view(rec, theirs)
    for key, want in theirs.items():
        got = ours[key]
        if isinstance(want, float):
            assert got == pytest.approx(want, rel=1e-12, abs=1e-12), key
        else:
            assert got == want, key


def test_checksum_matches_pynmea2_and_known_value():
    for s in corpus()[:50]:
        body = s[1:s.index("*")]
        assert nmea_checksum(s) == s[-2:]
        assert int(nmea_checksum(body), 16) == pynmea2.NMEASentence.checksum(body)
    assert nmea_checksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,") == "47"


@pytest.mark.parametrize("bad, err", [
    ("", NMEAFormatError), ("*47", NMEAFormatError), ("GPGGA,\u00e9", NMEAFormatError),
])
def test_checksum_bad_input(bad, err):
    with pytest.raises(err):
        nmea_checksum(bad)
    with pytest.raises(TypeError, match="sentence"):
        nmea_checksum(b"GPGGA")


def test_error_hierarchy_is_valueerror():
    assert issubclass(NMEAChecksumError, NMEAError) and issubclass(NMEAFormatError, NMEAError)
    assert issubclass(NMEAError, ValueError)


@pytest.mark.parametrize("text, err, words", [
    ("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6B", NMEAChecksumError, "6A"),
    ("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W", NMEAChecksumError, "truncated"),
    ("$GPRMC,123519,A,4807.0", NMEAChecksumError, "truncated"),
    ("$GPRMC,123519,A*3Z", NMEAChecksumError, "hex"),
    ("GPRMC,123519", NMEAFormatError, "start with"),
    ("$GPRMC,123519,A,9107.038,N,01131.000,E,022.4,084.4,230394,003.1,W", NMEAFormatError, "90"),
    ("$GPRMC,123519,A,4807.038,N,18131.000,E,022.4,084.4,230394,003.1,W", NMEAFormatError, "180"),
    ("$GPRMC,123519,A,4867.038,N,01131.000,E,022.4,084.4,230394,003.1,W", NMEAFormatError, "minutes"),
    ("$GPRMC,123519,A,4807.038,X,01131.000,E,022.4,084.4,230394,003.1,W", NMEAFormatError, "hemisphere"),
    ("$GPRMC,123519,A,4807.038,,01131.000,E,022.4,084.4,230394,003.1,W", NMEAFormatError, "hemisphere"),
    ("$GPRMC,123519,A,4807.038,N", NMEAFormatError, "RMC"),
    ("$HCHDG,400.0,,,7.1,W", NMEAFormatError, "heading"),
    ("$HCHDG,nan,,,7.1,W", NMEAFieldError, "heading_deg: expected a finite number"),
    ("$GPGGA,123519,48nan,N,01131.000,E,1,08,0.9,545.4,M", NMEAFieldError, "GGA latitude"),
    ("$GPRMB,A,0.66,L,003,004,4917.24,N,inf,W,001.3,052.5,000.5,V", NMEAFieldError, "destination_longitude"),
    ("$GPRMB,A,0.66,L,003", NMEAFormatError, "RMB"),
    ("$g?,1,2", NMEAFormatError, "address"),
])
def test_bad_sentences_raise_clear_errors(text, err, words):
    with pytest.raises(err, match=words):
        parse_sentence(text, require_checksum=err is NMEAChecksumError)


@pytest.mark.parametrize("text, words, bad", [
    ("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,310294,003.1,W", "date", ("date",)),
    ("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,2303,003.1,W", "ddmmyy", ("date",)),
    ("$GPRMC,256019,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W", "hours", ("time",)),
    ("$GPRMC,123519,A,4807.038,N,01131.000,E,fast,084.4,230394,003.1,W", "speed_knots", ("speed_knots",)),
    ("$GPRMC,123519,A,4807.038,N,01131.000,E,X.138,nan,230394,003.1,W", "speed_knots", ("speed_knots", "course_deg")),
    ("$GPGGA,123519,4807.038,N,01131.000,E,x,08,0.9,545.4,M", "quality", ("quality",)),
])
def test_a_corrupt_optional_field_is_emptied_and_named_not_fatal(text, words, bad):
    rec = parse_sentence(text, require_checksum=False)
    assert rec.bad_fields == bad and all(getattr(rec, name) is None for name in bad)
    assert rec.latitude == pytest.approx(48.1173)        # the position survives
    with pytest.raises(NMEAFieldError, match=words) as info:  # the field on its own says why
        RECORD_PARSERS[rec.kind](rec.talker, text.split(",")[1:])
    assert info.value.field == bad[0]


# --- every field corrupted on its own: emptied and named, or (essential) the sentence rejected ------

FULL = [rmc_sentence(dt.datetime(2012, 6, 4, 2, 30, 5, 250000), 6.45, 100.35, speed_mps=1.2, course_deg=45.0,
                     magnetic_variation_deg=-0.5),
        format_sentence("GNGGA", "023005.00,0627.0000,S,10021.0000,W,2,08,0.9,12.5,M,-3.2,M,1.5,0120".split(",")),
        hdg_sentence(120.0, deviation_deg=1.5, variation_deg=-0.5),
        rmb_sentence(6.46, 100.36, 120.0, 45.0, cross_track_m=-3.0, closing_velocity_mps=1.0)]
#: What the records exist to carry: a corrupt one rejects the sentence.
ESSENTIAL = {"latitude", "longitude", "destination_latitude", "destination_longitude", "heading_deg"}
#: Not numbers: what a sentence's text may hold, ``nan`` included, and what a fuzz of any field tries.
CORRUPTIONS = ["nan", "NaN", "-nan", "inf", "-inf", "+Infinity", "1e999", "X.138", "1.2.3", "?"]


def _corrupted():
    for full in FULL:
        address, fields = full[1:full.index("*")].split(",", 1)
        fields = fields.split(",")
        for i in range(len(fields)):
            for bad in CORRUPTIONS:
                yield pytest.param(full, format_sentence(address, fields[:i] + [bad] + fields[i + 1:]), bad,
                                   id=f"{address}-field{i + 1}-{bad}")


def _numeric_attributes(rec):
    return {k for k, v in rec._asdict().items() if isinstance(v, float)}


@pytest.mark.parametrize("full, text, bad", list(_corrupted()))
def test_every_field_corrupted_on_its_own_is_emptied_and_named_or_rejects_the_sentence(full, text, bad):
    intact = parse_sentence(full)
    try:
        rec = parse_sentence(text)
    except NMEAFieldError as exc:
        assert exc.field in ESSENTIAL and exc.field in str(exc) and repr(bad) in str(exc)
        return
    assert not any(isinstance(v, float) and not np.isfinite(v) for v in rec), rec     # no NaN, no inf
    changed = [k for k in rec._fields if k != "bad_fields" and getattr(rec, k) != getattr(intact, k)]
    if rec.bad_fields:   # the corrupt field, and nothing else, emptied and named
        assert changed == list(rec.bad_fields) and all(getattr(rec, k) is None for k in changed)
        assert not ESSENTIAL & set(changed)
    else:                # free text (waypoint ids, mode, station) or a field the record does not read (units)
        assert all(getattr(rec, k) == bad for k in changed) and len(changed) <= 1


def test_corruption_reaches_every_numeric_field_of_every_record():
    """The generated cases above do cover each float field (read off the records, not listed)."""
    emptied = {}
    for param in _corrupted():
        full, text, _ = param.values
        try:
            rec = parse_sentence(text)
        except NMEAFieldError as exc:
            emptied.setdefault(full, set()).add(exc.field)
            continue
        emptied.setdefault(full, set()).update(rec.bad_fields)
    for full in FULL:
        assert _numeric_attributes(parse_sentence(full)) <= emptied[full], full


def test_the_reader_keeps_a_sentence_with_a_corrupt_field_and_counts_it():
    speed = format_sentence("GPRMC", ["123519", "A", "4807.038", "N", "01131.000", "E", "X.138", "84.4", "230394", "", ""])
    position = format_sentence("GPRMC", ["123519", "A", "4807.038", "N", "nan", "E", "22.4", "84.4", "230394", "", ""])
    data = "\r\n".join([HAND_WRITTEN[0], speed, position, HAND_WRITTEN[2].replace("7.1", "inf")]).encode()
    seen = []
    reader = NMEAReader(data, on_error=seen.append)
    records = list(reader)
    assert [r.kind for r in records] == ["RMC", "RMC"]      # the position fix survives its speed
    assert records[1].latitude == pytest.approx(48.1173) and records[1].speed_knots is None
    assert [(b.line, b.fields) for b in reader.field_errors] == [(2, ("speed_knots",))]
    assert isinstance(reader.field_errors[0], BadFields) and reader.field_errors[0].text == speed.encode()
    assert [b.line for b in reader.errors] == [3, 4] and seen == reader.errors   # rejected: still counted
    assert "longitude" in str(reader.errors[0].error) and isinstance(reader.errors[1].error, NMEAChecksumError)
    records, bad = read_nmea(data)
    assert len(records) == 2 and len(bad) == 2


def test_checksum_optional_when_asked():
    rec = parse_sentence("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,", require_checksum=False)
    assert rec.latitude == pytest.approx(48.1173)
    with pytest.raises(NMEAChecksumError):  # a present checksum is still verified
        parse_sentence("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*48", require_checksum=False)


def test_parse_sentence_types_and_bytes():
    assert isinstance(parse_sentence(HAND_WRITTEN[0].encode()), RMC)
    with pytest.raises(NMEAFormatError, match="0xFF"):
        parse_sentence(b"$GPGGA,\xff*00")
    with pytest.raises(TypeError, match="sentence"):
        parse_sentence(42)


def test_proprietary_and_unknown_types_are_generic():
    rec = parse_sentence(format_sentence("PGRME", ["15.0", "M", "45.0", "M", "25.0", "M"]))
    assert rec == Sentence("P", "GRME", ("15.0", "M", "45.0", "M", "25.0", "M"))
    assert parse_sentence(format_sentence("GPZDA", ["1", "2"])).kind == "ZDA"


def test_field_helpers():
    assert parse_latitude("4807.038", "S") == pytest.approx(-48.1173)
    assert parse_longitude("00000.600", "W") == pytest.approx(-0.01)
    assert parse_latitude("", "") is None and parse_time("") is None and parse_date("") is None
    assert parse_time("235959.999") == dt.time(23, 59, 59, 999000)
    assert parse_date("290224") == dt.date(2024, 2, 29) and parse_date("010199") == dt.date(1999, 1, 1)
    with pytest.raises(NMEAFormatError):
        parse_date("290223")
    with pytest.raises(NMEAFormatError):
        parse_latitude("9000.001", "N")
    assert parse_latitude("9000.000", "N") == 90.0


def test_rmc_si_properties():
    rec = parse_sentence(HAND_WRITTEN[0])
    assert rec.speed_mps == pytest.approx(22.4 * 1852 / 3600)
    assert rec.course_rad == pytest.approx(np.radians(84.4))
    assert rec.datetime == dt.datetime(1994, 3, 23, 12, 35, 19, tzinfo=dt.timezone.utc)
    assert rec.valid and parse_sentence(HAND_WRITTEN[3]).range_m == pytest.approx(1.3 * 1852)
    assert parse_sentence(HAND_WRITTEN[2]).true_heading_deg == pytest.approx(94.0)


@pytest.mark.parametrize("lat", [-89.99999, -45.5, -0.001, 0.0, 0.001, 33.3333333, 89.99999])
def test_format_then_parse_round_trip(lat):
    text, hemi = format_latitude(lat, decimals=6)
    assert parse_latitude(text, hemi) == pytest.approx(lat, abs=1e-7)
    text, hemi = format_longitude(lat * 2, decimals=6)
    assert parse_longitude(text, hemi) == pytest.approx(lat * 2, abs=1e-7)


def test_writers_validate():
    with pytest.raises(ValueError, match="deg"):
        format_latitude(91.0)
    with pytest.raises(NMEAFormatError, match="fields"):
        format_sentence("GPXXX", ["a,b"])
    with pytest.raises(TypeError, match="when"):
        rmc_sentence("now", 1.0, 2.0)
    with pytest.raises(ValueError, match="hdop"):
        gga_sentence(dt.time(1, 2, 3), 1.0, 2.0, hdop=-1)
    assert parse_sentence(hdg_sentence(359.99)).heading_deg == 0.0
    assert parse_sentence(rmb_sentence(1.0, 2.0, 1852.0, 90.0, arrived=True)).arrival == "A"


# --- streams -------------------------------------------------------------------------------------

def _dirty_stream(rng):
    """Good sentences interleaved with junk, truncations, bad checksums, non-ASCII and bad values."""
    good = random_sentences(300, rng)
    lines, expect_bad = [], 0
    for i, s in enumerate(good):
        r = i % 7
        if r == 0:
            lines.append(bytes(rng.integers(0, 256, 12, dtype=np.uint8)).replace(b"$", b"#").replace(b"\n", b" ")
                         + s.encode() + b"\r\n")                      # junk before, recovered
        elif r == 1:
            lines.append(s[: len(s) // 2].encode() + b"\r\n")        # truncated: reported
            lines.append(s.encode() + b"\r\n")
            expect_bad += 1
        elif r == 2:
            bad = s[:-1] + ("0" if s[-1] != "0" else "1")
            lines.append(bad.encode() + b"\r\n" + s.encode() + b"\r\n")  # wrong checksum: reported
            expect_bad += 1
        elif r == 3:
            lines.append(b"$GPGGA,12\xc3\xa9,4807*00\r\n" + s.encode() + b"\n")  # non-ASCII: reported
            expect_bad += 1
        elif r == 4:
            lines.append(s[:min(20, len(s) - 3)].encode() + s.encode() + b"\r\n")     # partial then full on one line
            expect_bad += 1
        else:
            lines.append(s.encode() + b"\r\n")
    bad_values = [format_sentence("GPRMC", ["123519", "A", "9107.038", "N", "01131.000", "E", "1", "2", "230394", "", ""]),
                  format_sentence("GPRMC", ["123519", "A", "4807.038", "N", "18131.000", "E", "1", "2", "230394", "", ""])]
    lines += [b.encode() + b"\r\n" for b in bad_values]
    expect_bad += 2
    return good, b"".join(lines), expect_bad


def test_stream_recovers_every_good_sentence_and_reports_every_bad_one():
    good, data, expect_bad = _dirty_stream(np.random.default_rng(3))
    for chunk in (7, 64, 65536):  # chunk borders fall inside sentences
        reader = NMEAReader(io.BytesIO(data), chunk_size=chunk)
        records = list(reader)
        assert records == [parse_sentence(s) for s in good]
        assert len(reader.errors) == expect_bad
        assert all(isinstance(b.error, NMEAError) and b.line >= 1 for b in reader.errors)
        assert reader.junk_bytes > 0


def test_stream_reports_line_numbers_and_calls_back():
    data = (HAND_WRITTEN[0] + "\r\n" + HAND_WRITTEN[1][:-1] + "0\r\n\r\n" + HAND_WRITTEN[2] + "\n"
            "$HCHDG,1\xe9\n").encode("latin-1")
    seen = []
    reader = NMEAReader(data, on_error=seen.append)
    assert [r.kind for r in reader] == ["RMC", "HDG"]
    assert [b.line for b in reader.errors] == [2, 5]
    assert isinstance(reader.errors[0].error, NMEAChecksumError)
    assert isinstance(reader.errors[1].error, NMEAFormatError) and "0xE9" in str(reader.errors[1].error)
    assert seen == reader.errors and reader.lines == 5


def test_stream_from_path_and_empty_files(tmp_path):
    path = tmp_path / "log.nmea"
    path.write_bytes(("\r\n".join(HAND_WRITTEN) + "\r\n").encode())
    records, bad = read_nmea(path)
    assert len(records) == len(HAND_WRITTEN) and bad == []
    empty = tmp_path / "empty.nmea"
    empty.write_bytes(b"")
    assert read_nmea(empty) == ([], [])
    assert read_nmea(str(empty)) == ([], [])
    assert read_nmea(b"\x00\x01\x02 no sentences here") == ([], [])


def test_stream_without_newlines_stays_bounded():
    junk = bytes(np.random.default_rng(0).integers(0, 256, 50_000, dtype=np.uint8)).replace(b"$", b"#").replace(b"\n", b"#")
    data = junk + HAND_WRITTEN[0].encode() + junk + b"\n" + HAND_WRITTEN[1].encode()
    reader = NMEAReader(data, chunk_size=1000, max_line=200)
    records = list(reader)
    assert [r.kind for r in records] == ["RMC", "GGA"] or [r.kind for r in records] == ["GGA"]
    assert records[-1] == parse_sentence(HAND_WRITTEN[1])


def test_reader_validates_its_arguments():
    with pytest.raises(TypeError, match="source"):
        NMEAReader(3.5)
    with pytest.raises(ValueError, match="chunk_size"):
        NMEAReader(b"", chunk_size=0)

    class TextStream:
        def read(self, n):
            return "text"

    with pytest.raises(TypeError, match="bytes"):
        list(NMEAReader(TextStream()))


# --- fuzzing: arbitrary input never crashes the parser or the reader -------------------------------

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings, strategies as st  # noqa: E402

_GOOD = random_sentences(30, np.random.default_rng(9))


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=200))
def test_parse_sentence_only_raises_nmea_errors_on_random_bytes(data):
    try:
        parse_sentence(b"$" + data)
    except NMEAError:
        pass


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(_GOOD), st.integers(min_value=1, max_value=80), st.characters())
def test_a_mutated_sentence_is_rejected_or_parsed_never_crashes(sentence, position, char):
    i = min(position, len(sentence) - 1)
    mutated = sentence[:i] + char + sentence[i + 1:]
    try:
        rec = parse_sentence(mutated)
    except NMEAError:
        return
    # a mutation that survives must have kept the checksum valid
    assert nmea_checksum(mutated) == mutated[-2:].upper()
    assert rec.talker


@settings(max_examples=100, deadline=None)
@given(st.lists(st.one_of(st.sampled_from(_GOOD).map(str.encode), st.binary(max_size=40)), max_size=30),
       st.integers(min_value=1, max_value=64))
def test_reader_returns_every_intact_sentence_from_a_random_mix(parts, chunk):
    data = b"\n".join(parts) + b"\n"
    reader = NMEAReader(data, chunk_size=chunk)
    records = list(reader)
    intact = sum(1 for p in parts if p.decode("latin-1") in _GOOD)
    assert len(records) >= intact
    assert all(isinstance(b.error, NMEAError) for b in reader.errors)
