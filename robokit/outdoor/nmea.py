"""NMEA 0183 sentences: checksum, typed records and a stream reader that never stops on bad input.

A sentence looks like ``$GPRMC,123519,A,4807.038,N,...*6A\\r\\n``: a ``$``, an address (a two-letter
talker such as ``GP``, ``GN``, ``GL`` or ``HC``, then a three-letter sentence type), comma separated
fields, ``*`` and a two-hex-digit checksum (NMEA 0183 v4.11, Sec. 5.2-5.3). Hamid et al. (2009)
drive their truck from ``$GPRMC``, ``$GPRMB``, ``$GPGGA`` and ``$HCHDG``; those four get
typed records (:class:`RMC`, :class:`RMB`, :class:`GGA`, :class:`HDG`) for any talker, and every
other type is returned as a :class:`Sentence` (never an error).

Conventions: empty fields become ``None``; latitude and longitude are signed decimal degrees (north
and east positive) as the fields carry them; the records keep NMEA's own units (knots, degrees) in
their field names and offer SI properties (``speed_mps``, ``course_rad``, ...).

A sentence with a good checksum and a corrupt field is still read when the record can do without
that field (a speed of ``X.138`` or ``nan``): the field becomes ``None`` and the record names it in
``bad_fields``; a corrupt essential field (the position of RMC/GGA, the destination of RMB, the
heading of HDG) rejects the sentence (:func:`~robokit.outdoor.nmea_fields.salvage_record`). Numbers
must be finite: ``nan`` and ``inf`` are corrupt.

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

import io
import os
from functools import reduce
from operator import xor
from typing import Any, BinaryIO, Callable, Iterator, NamedTuple

from ..validation import as_callable, as_int, describe
from .nmea_fields import (RECORD_PARSERS, NMEAChecksumError, NMEAError, NMEAFieldError, NMEAFormatError, parse_date,
                          parse_latitude, parse_longitude, parse_time, salvage_record)
from .nmea_records import GGA, HDG, RMB, RMC, Sentence

__all__ = [
    "NMEAError", "NMEAChecksumError", "NMEAFormatError", "NMEAFieldError",
    "RMC", "RMB", "GGA", "HDG", "Sentence",
    "nmea_checksum", "parse_sentence", "fix_position", "parse_latitude", "parse_longitude", "parse_time", "parse_date",
    "BadSentence", "BadFields", "NMEAReader", "read_nmea",
]


# every spelling of a two-hex-digit checksum -> its value (one dict lookup per sentence)
_HEX2 = {**{f"{i:02X}": i for i in range(256)}, **{f"{i:02x}": i for i in range(256)},
         **{f"{i:02x}"[0] + f"{i:02X}"[1]: i for i in range(256)}, **{f"{i:02X}"[0] + f"{i:02x}"[1]: i for i in range(256)}}


def _xor(data: bytes) -> int:
    return reduce(xor, data, 0)


def nmea_checksum(sentence: str) -> str:
    """Return the NMEA checksum of a sentence as two upper-case hex digits.

    Parameters
    ----------
    sentence : str
        Either the body between ``$`` and ``*`` (``"GPGGA,..."``) or a full sentence; a leading
        ``$`` and anything from ``*`` on are ignored.

    Returns
    -------
    str
        ``"%02X"`` of the XOR of the ASCII codes of the body's characters.

    Raises
    ------
    TypeError
        If ``sentence`` is not a string.
    NMEAFormatError
        If the body is empty or contains non-ASCII characters.

    Notes
    -----
    NMEA 0183 v4.11, Sec. 5.2.1 (checksum field); the example in Hamid et al. (2009)
    reads the receiver's ASCII output in exactly this form.

    Examples
    --------
    >>> nmea_checksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,")
    '47'
    """
    if not isinstance(sentence, str):
        raise TypeError(f"sentence: expected a str, got {describe(sentence)}")
    body = sentence[1:] if sentence[:1] in ("$", "!") else sentence
    star = body.find("*")
    if star >= 0:
        body = body[:star]
    if not body:
        raise NMEAFormatError(f"sentence: expected characters between '$' and '*', got {sentence!r}")
    try:
        data = body.encode("ascii")
    except UnicodeEncodeError:
        raise NMEAFormatError(f"sentence: expected ASCII characters only, got {sentence!r}") from None
    return "%02X" % _xor(data)


def parse_sentence(sentence: str | bytes, *, require_checksum: bool = True) -> RMC | RMB | GGA | HDG | Sentence:
    """Parse one NMEA sentence into a typed record.

    Parameters
    ----------
    sentence : str or bytes
        ``$<address>,<fields>*hh`` with optional trailing ``\\r\\n``; bytes must be ASCII.
    require_checksum : bool, default True
        Reject sentences without ``*hh`` (a truncated line loses its checksum first). A checksum
        that is present is always verified.

    Returns
    -------
    RMC, RMB, GGA, HDG or Sentence
        A typed record for those four types (any talker), otherwise a generic :class:`Sentence`.
        A corrupt field the record can do without (not a number, NaN, infinite, out of range, an
        unknown letter, an invalid date, ...) is ``None`` and named in the record's ``bad_fields``.

    Raises
    ------
    TypeError
        If ``sentence`` is neither str nor bytes.
    NMEAChecksumError
        Missing (when required), malformed or wrong checksum.
    NMEAFormatError
        No leading ``$``, non-ASCII characters, a bad address or too few fields.
    NMEAFieldError
        A corrupt essential field: the position of RMC/GGA (e.g. latitude > 90 degrees), the
        destination of RMB, the heading of HDG (an ``NMEAFormatError``).

    Notes
    -----
    Framing and checksum: NMEA 0183 v4.11, Sec. 5.2-5.3; field layouts: Sec. 6.3 (RMC, RMB, GGA,
    HDG), the four sentences Hamid et al. (2009) read.

    Examples
    --------
    >>> rec = parse_sentence("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A")
    >>> rec.talker, rec.status, rec.latitude, round(rec.longitude, 6), rec.speed_knots
    ('GP', 'A', 48.1173, 11.516667, 22.4)
    >>> parse_sentence("$GPZDA,201530.00,04,07,2002,00,00*60").kind         # any other type: generic
    'ZDA'
    >>> rec = parse_sentence("$GPRMC,123519,A,4807.038,N,01131.000,E,X.138,084.4,230394,003.1,W*0C")
    >>> rec.latitude, rec.speed_knots, rec.bad_fields                      # a corrupt speed is emptied
    (48.1173, None, ('speed_knots',))
    """
    if type(sentence) is not str:
        if isinstance(sentence, (bytes, bytearray)):
            try:
                sentence = bytes(sentence).decode("ascii")
            except UnicodeDecodeError as exc:
                raise NMEAFormatError(f"sentence: expected ASCII bytes, got byte 0x{sentence[exc.start]:02X} "
                                      f"at position {exc.start}") from None
        elif isinstance(sentence, str):
            sentence = str(sentence)
        else:
            raise TypeError(f"sentence: expected a str or bytes, got {describe(sentence)}")
    text = sentence.rstrip("\r\n") if sentence[-1:] in ("\n", "\r") else sentence
    if text[:1] != "$":
        raise NMEAFormatError(f"sentence: expected it to start with '$', got {text[:20]!r}")
    star = text.find("*", 1)
    if star >= 0:
        body = text[1:star]
        want = _HEX2.get(text[star + 1:])
        if want is None:
            raise NMEAChecksumError(f"checksum: expected two hex digits after '*', got {text[star + 1:]!r}")
        try:
            got = _xor(body.encode("ascii"))
        except UnicodeEncodeError:
            raise NMEAFormatError(f"sentence: expected ASCII characters only, got {text[:40]!r}") from None
        if got != want:
            raise NMEAChecksumError(f"checksum: expected {got:02X} for the body, got {text[star + 1:]} "
                                    f"in {text[:40]!r}")
    else:
        if require_checksum:
            raise NMEAChecksumError(f"checksum: expected '*hh' at the end (truncated sentence?), got {text[:40]!r}")
        body = text[1:]
        if not body.isascii():
            raise NMEAFormatError(f"sentence: expected ASCII characters only, got {text[:40]!r}")
    fields = body.split(",")
    address = fields[0]
    if not (address.isalnum() and address.isupper()) or len(address) < 2:
        raise NMEAFormatError(f"address: expected a talker and type like 'GPRMC', got {address!r}")
    if address[0] == "P":
        talker, kind = "P", address[1:]
    else:
        talker, kind = address[:2], address[2:]
    parser = RECORD_PARSERS.get(kind)
    if parser is None or len(address) != 5:
        return Sentence(talker, kind, tuple(fields[1:]))
    try:
        return parser(talker, fields[1:])
    except NMEAFieldError:
        pass   # rebuilt outside the handler, so that an essential field's error is not chained to this one
    return salvage_record(kind, talker, fields[1:])


def fix_position(sentence: str) -> list[float]:
    """Latitude and longitude in decimal degrees from a ``$--RMC`` or ``$--GGA`` sentence.

    Parameters
    ----------
    sentence : str
        A complete sentence with checksum, any talker.

    Returns
    -------
    list of float
        ``[latitude, longitude]``, north and east positive.

    Raises
    ------
    NMEAChecksumError, NMEAFormatError
        As :func:`parse_sentence`; also when the sentence is not RMC/GGA or carries no position
        (a receiver without a fix sends empty fields).

    Notes
    -----
    ``ddmm.mmmm`` -> ``dd + mm.mmmm / 60`` (NMEA 0183 v4.11, Sec. 6.2); the position the truck of
    Hamid et al. (2009) reads from $GPRMC/$GPGGA.

    Examples
    --------
    >>> [round(x, 6) for x in fix_position("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A")]
    [48.1173, 11.516667]
    """
    rec = parse_sentence(sentence)
    if not isinstance(rec, (RMC, GGA)):
        raise NMEAFormatError(f"sentence: expected an RMC or GGA sentence, got type {rec.kind!r}")
    if rec.latitude is None or rec.longitude is None:
        raise NMEAFormatError(f"sentence: expected a position, got empty latitude/longitude (no fix) in {sentence[:30]!r}")
    return [rec.latitude, rec.longitude]


# --- streams ------------------------------------------------------------------------------------

class BadSentence(NamedTuple):
    """A sentence the reader rejected: ``line`` (1-based), the raw ``text`` and the ``error``."""

    line: int
    text: bytes
    error: NMEAError


class BadFields(NamedTuple):
    """A sentence the reader kept with corrupt fields emptied: ``line`` (1-based), the raw ``text``
    and the names of the emptied ``fields`` (the record's ``bad_fields``)."""

    line: int
    text: bytes
    fields: tuple


class NMEAReader:
    """Read NMEA sentences from a byte stream, skipping junk and reporting bad sentences.

    Iterating yields parsed records in order. Bytes before a ``$`` (binary junk, the tail of a
    partial line) are skipped and counted in :attr:`junk_bytes`; every candidate sentence that fails
    to parse is appended to :attr:`errors` as a :class:`BadSentence` with its line number (and passed
    to ``on_error`` if given), and reading continues with the next ``$``. A sentence read with
    corrupt fields emptied (see :func:`parse_sentence`) is yielded and also logged in
    :attr:`field_errors` as a :class:`BadFields`; :attr:`lines` counts the lines read.

    Parameters
    ----------
    source : bytes, str path, os.PathLike or binary file-like
        A path is opened (and closed at the end); a file-like must have ``read(n)`` returning bytes
        (a serial port works the same way).
    require_checksum : bool, default True
        See :func:`parse_sentence`.
    on_error : callable, optional
        ``on_error(bad: BadSentence)`` called for every rejected sentence.
    chunk_size : int, default 65536
        Bytes read per call to ``read``.
    max_line : int, default 4096
        A run of bytes longer than this without a newline is cut at its last ``$`` so that a
        newline-free binary stream cannot grow the buffer without bound (NMEA sentences are at most
        82 characters, NMEA 0183 v4.11 Sec. 5.3).

    Raises
    ------
    TypeError
        If ``source`` is not bytes, a path or a binary file-like.

    Notes
    -----
    Resynchronising on ``$`` is how a receiver's listener recovers after noise or a lost
    character (NMEA 0183 v4.11, Sec. 5.3: ``$`` only ever starts a sentence).

    Examples
    --------
    >>> reader = NMEAReader(b"junk$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\\r\\n$GPGGA,12*00\\r\\n")
    >>> [rec.kind for rec in reader], reader.junk_bytes, [type(bad.error).__name__ for bad in reader.errors]
    (['RMC'], 4, ['NMEAChecksumError'])
    """

    def __init__(self, source: Any, *, require_checksum: bool = True,
                 on_error: Callable[[BadSentence], Any] | None = None,
                 chunk_size: int = 65536, max_line: int = 4096) -> None:
        self._close = False
        if isinstance(source, (bytes, bytearray, memoryview)):
            self._stream: BinaryIO = io.BytesIO(bytes(source))
        elif isinstance(source, (str, os.PathLike)):
            self._stream = open(source, "rb")
            self._close = True
        elif hasattr(source, "read"):
            self._stream = source
        else:
            raise TypeError(f"source: expected bytes, a path or a binary file-like, got {describe(source)}")
        self.require_checksum = bool(require_checksum)
        self.on_error = as_callable(on_error, "on_error")
        self.chunk_size = as_int(chunk_size, "chunk_size", minimum=1)
        self.max_line = as_int(max_line, "max_line", minimum=82)
        self.errors: list[BadSentence] = []
        self.field_errors: list[BadFields] = []
        self.junk_bytes = 0
        self.lines = 0

    def _bad(self, line: int, text: bytes, error: NMEAError) -> None:
        bad = BadSentence(line, text, error)
        self.errors.append(bad)
        if self.on_error is not None:
            self.on_error(bad)

    def _line(self, raw: bytes, number: int) -> Iterator[Any]:
        start = raw.find(b"$")
        if start < 0:
            self.junk_bytes += len(raw.strip())
            return
        self.junk_bytes += len(raw[:start].strip())
        pieces = raw[start:].split(b"$")
        for piece in pieces[1:]:
            text = b"$" + piece.rstrip(b"\r\n \t\x00")
            try:
                rec = parse_sentence(text.decode("ascii"), require_checksum=self.require_checksum)
            except UnicodeDecodeError as exc:
                self._bad(number, text, NMEAFormatError(
                    f"sentence: expected ASCII bytes, got byte 0x{text[exc.start]:02X} at position {exc.start}"))
            except NMEAError as exc:
                self._bad(number, text, exc)
            else:
                if rec.bad_fields:
                    self.field_errors.append(BadFields(number, text, rec.bad_fields))
                yield rec

    def __iter__(self) -> Iterator[RMC | RMB | GGA | HDG | Sentence]:
        rest = b""
        number = 0
        try:
            while True:
                chunk = self._stream.read(self.chunk_size)
                if chunk is None:  # non-blocking stream with nothing yet
                    continue
                if not isinstance(chunk, (bytes, bytearray)):
                    raise TypeError(f"source: expected read() to return bytes, got {describe(chunk)}")
                if not chunk:
                    break
                lines = (rest + chunk).split(b"\n")
                rest = lines.pop()
                for raw in lines:
                    number += 1
                    yield from self._line(raw, number)
                if len(rest) > self.max_line:
                    cut = rest.rfind(b"$")
                    cut = cut if 0 < cut and len(rest) - cut <= self.max_line else len(rest)
                    yield from self._line(rest[:cut], number + 1)
                    rest = rest[cut:]
            if rest:
                number += 1
                yield from self._line(rest, number)
        finally:
            self.lines = number
            if self._close:
                self._stream.close()


def read_nmea(source: Any, *, require_checksum: bool = True) -> tuple[list, list[BadSentence]]:
    """Read a whole NMEA log and return ``(records, bad_sentences)``.

    Parameters
    ----------
    source : bytes, path or binary file-like
        See :class:`NMEAReader`.
    require_checksum : bool, default True
        See :func:`parse_sentence`.

    Returns
    -------
    records : list
        Every sentence that parsed, in order.
    bad_sentences : list of BadSentence
        Every rejected sentence with its 1-based line number and the reason.

    Notes
    -----
    A convenience over :class:`NMEAReader` (NMEA 0183 v4.11, Sec. 5.3 framing).
    """
    reader = NMEAReader(source, require_checksum=require_checksum)
    return list(reader), reader.errors

