"""Moving plain data between the grader and its worker: JSON plus an ``.npz`` of arrays.

Arrays are stored in the ``.npz`` and referenced from the JSON by name, so nothing crosses the
boundary but numbers, strings and arrays.

The reading side trusts nothing: the files were written by untrusted code, which may also have
replaced them by links, FIFOs, directories or garbage, and may still be changing them.
:func:`read_untrusted` is the one way such a file is opened: without following a symbolic link
(``O_NOFOLLOW``) or blocking on a FIFO (``O_NONBLOCK``), only if ``fstat`` says it is a regular
file with a single link, and never reading more than a fixed bound. :func:`read_plain` then parses
the bytes it got, not the file: JSON with bounded nesting, and an ``.npz`` whose zip members and
``.npy`` headers are checked before any array is allocated (numeric and boolean dtypes only, no
pickles). Every problem is a :class:`TransportError`.
"""
from __future__ import annotations

import errno
import io
import json
import math
import os
import stat
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from robocourse.exercises.plain import NotPlainData, to_plain

__all__ = ["write_plain", "read_plain", "read_untrusted", "open_directory", "TransportError", "NotWritten",
           "SymlinkRefused",
           "TooLarge", "MAX_JSON_BYTES", "MAX_NPZ_BYTES"]

MAX_JSON_BYTES = 20_000_000
#: The worker cannot write a file larger than its ``RLIMIT_FSIZE`` (64 MiB by default) anyway.
MAX_NPZ_BYTES = 64 * 1024**2
MAX_ARRAYS = 10_000
MAX_DEPTH = 40
_ARRAY_KEY = "__robokit_array__"
_FLOAT_KEY = "__robokit_float__"
_OPEN_FLAGS = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC
_ARRAY_KINDS = "biuf"


class TransportError(ValueError):
    """A file written by untrusted code is missing, unsafe, too large or malformed."""


class NotWritten(TransportError):
    """The file does not exist."""


class SymlinkRefused(TransportError):
    """The file is a symbolic link, which is never followed."""


class TooLarge(TransportError):
    """The file is larger than the bound its reader allows."""


# -- writing (the worker's side) ------------------------------------------------------------------

def _encode(value: Any, arrays: dict[str, np.ndarray]) -> Any:
    if isinstance(value, np.ndarray):
        name = f"a{len(arrays)}"
        arrays[name] = value
        return {_ARRAY_KEY: name}
    if isinstance(value, list):
        return [_encode(v, arrays) for v in value]
    if isinstance(value, dict):
        if _ARRAY_KEY in value or _FLOAT_KEY in value:
            raise NotPlainData(f"dict keys {_ARRAY_KEY!r} and {_FLOAT_KEY!r} are reserved")
        return {k: _encode(v, arrays) for k, v in value.items()}
    if isinstance(value, float) and not math.isfinite(value):
        return {_FLOAT_KEY: repr(value)}
    return value


def write_plain(value: Any, stem: str | Path) -> None:
    """Write plain data to ``stem.json`` (+ ``stem.npz`` when it holds arrays)."""
    stem = Path(stem)
    arrays: dict[str, np.ndarray] = {}
    doc = _encode(to_plain(value), arrays)
    if arrays:
        np.savez(stem.with_suffix(".npz"), **arrays)
    stem.with_suffix(".json").write_text(json.dumps(doc, allow_nan=False))


# -- reading (the grader's side) ------------------------------------------------------------------

def open_directory(path: str | Path) -> int:
    """Open the directory ``path`` for :func:`read_untrusted`'s ``dir_fd``, never through a link
    in its last component; the caller closes the descriptor (``OSError`` as from :func:`os.open`)."""
    return os.open(path, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC)


def read_untrusted(path: str | Path, limit: int, *, dir_fd: int | None = None, keep: str = "all",
                   links_ok: bool = False) -> bytes:
    """Return the content of the regular file ``path``, of at most ``limit`` bytes.

    ``path`` is relative to the open directory ``dir_fd`` when given. The last component is never
    followed if it is a symbolic link, a FIFO is never waited on, and no more than ``limit + 1``
    bytes are ever read, even from a file that is still growing. With ``keep="head"`` (or
    ``"tail"``) a larger file is not an error: its first (or last) ``limit`` bytes are returned.
    A file with several hard links is refused unless ``links_ok``: the worker never writes one,
    and it could name a file the worker may not read.

    Raises
    ------
    NotWritten
        If there is no such file.
    SymlinkRefused
        If it is a symbolic link.
    TooLarge
        If it holds more than ``limit`` bytes.
    TransportError
        If it is not a regular file (a FIFO, a device, a directory), has other hard links (unless
        ``links_ok``), or cannot be read.
    """
    name = os.fspath(path)
    try:
        fd = os.open(name, _OPEN_FLAGS, dir_fd=dir_fd)
    except FileNotFoundError:
        raise NotWritten(f"{Path(name).name} is missing") from None
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise SymlinkRefused(f"{Path(name).name} is a symbolic link") from None
        raise TransportError(f"{Path(name).name} could not be opened ({exc.strerror})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise TransportError(f"{Path(name).name} is not a regular file")
        if info.st_nlink != 1 and not links_ok:
            raise TransportError(f"{Path(name).name} is a hard link to another file")
        if info.st_size > limit and keep == "all":
            raise TooLarge(f"{Path(name).name} is larger than {limit} bytes")
        if keep == "tail":
            os.lseek(fd, max(0, info.st_size - limit), os.SEEK_SET)
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit and keep == "all":
            raise TooLarge(f"{Path(name).name} is larger than {limit} bytes")
        return b"".join(chunks)[:limit]
    except OSError as exc:
        raise TransportError(f"{Path(name).name} could not be read ({exc.strerror})") from None
    finally:
        os.close(fd)


def _parse_json(data: bytes, name: str) -> Any:
    """JSON from bytes; invalid UTF-8, syntax, nesting or over-long integers are TransportErrors."""
    try:
        return json.loads(data.decode("utf-8"))
    except (ValueError, RecursionError) as exc:  # UnicodeDecodeError, JSONDecodeError, int digit limit
        raise TransportError(f"{name} is not valid JSON ({type(exc).__name__})") from None


def _read_npy(raw: bytes, name: str) -> np.ndarray:
    """One ``.npy`` member, checked before anything is allocated: a numeric or boolean dtype and a
    shape whose size is exactly the data that follows the header."""
    f = io.BytesIO(raw)
    version = np.lib.format.read_magic(f)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
    elif version == (2, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
    else:
        raise TransportError(f"{name}: unsupported .npy version {version}")
    if dtype.hasobject or dtype.fields is not None or dtype.subdtype is not None or dtype.kind not in _ARRAY_KINDS:
        raise TransportError(f"{name}: arrays must be numeric or boolean, got dtype {dtype}")
    count = math.prod(shape)
    body = raw[f.tell():]
    if count * dtype.itemsize != len(body):
        raise TransportError(f"{name}: shape {shape} does not match the {len(body)} bytes of data")
    return np.frombuffer(body, dtype=dtype, count=count).reshape(shape, order="F" if fortran else "C")


def _require_directory_end(data: bytes, name: str) -> None:
    """Check an ``.npz``'s layout before :mod:`zipfile` parses it: what :func:`numpy.savez` writes
    and nothing else.

    The end-of-directory record (no comment) bounds the member count; every member must be stored
    (not compressed, so its size on disk is its size), named once, and lie between the previous
    member and the central directory, so that no byte is read twice (overlapping members would make
    a small file cost a large read per member).
    """
    end = data[-22:]
    if len(data) < 22 or end[:4] != b"PK\x05\x06":
        raise TransportError(f"{name} is not an archive written by numpy.savez")
    count = int.from_bytes(end[10:12], "little")
    if count > MAX_ARRAYS:
        raise TooLarge(f"{name} holds more than {MAX_ARRAYS} arrays")


def _require_zip_layout(members: list[zipfile.ZipInfo], data: bytes, name: str) -> None:
    """Members stored, named once, in order and not overlapping (see :func:`_require_directory_end`)."""
    seen: set[str] = set()
    position = 0
    for member in sorted(members, key=lambda m: m.header_offset):
        if member.compress_type != zipfile.ZIP_STORED or member.compress_size != member.file_size:
            raise TransportError(f"{name}: member {member.filename[:40]!r} is compressed or its sizes disagree")
        if member.filename in seen:
            raise TransportError(f"{name}: member {member.filename[:40]!r} appears twice")
        seen.add(member.filename)
        start = member.header_offset
        header = data[start:start + 30]
        if start < position or len(header) < 30 or header[:4] != b"PK\x03\x04":
            raise TransportError(f"{name}: members overlap or are misplaced")
        position = (start + 30 + int.from_bytes(header[26:28], "little") + int.from_bytes(header[28:30], "little")
                    + member.compress_size)
    if position > len(data):
        raise TransportError(f"{name}: a member runs past the end of the file")


def _parse_npz(data: bytes, name: str) -> dict[str, np.ndarray]:
    """The arrays of an ``.npz`` held in memory; its layout and members' sizes are checked before reading."""
    _require_directory_end(data, name)
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            members = archive.infolist()
            if len(members) > MAX_ARRAYS:
                raise TooLarge(f"{name} holds more than {MAX_ARRAYS} arrays")
            _require_zip_layout(members, data, name)
            arrays = {}
            for member in members:
                if not member.filename.endswith(".npy"):
                    raise TransportError(f"{name}: unexpected member {member.filename[:40]!r}")
                arrays[member.filename[:-4]] = _read_npy(archive.read(member), name)
            return arrays
    except TransportError:
        raise
    except Exception as exc:  # a malformed archive (BadZipFile, zlib.error, EOFError, ...) written by untrusted code
        raise TransportError(f"{name} is unreadable ({type(exc).__name__})") from None


def _decode(value: Any, arrays: dict[str, np.ndarray], used: set[str], depth: int = 0) -> Any:
    """Rebuild plain data from the JSON ``value``; each array of ``arrays`` may be named once, so
    the decoded data is at most the (bounded) archive widened to 8-byte numbers."""
    if depth > MAX_DEPTH:
        raise TransportError("data nested too deeply")
    if isinstance(value, dict):
        if set(value) == {_ARRAY_KEY}:
            name = value[_ARRAY_KEY]
            if not isinstance(name, str) or name not in arrays:
                raise TransportError("an array is missing")
            if name in used:
                raise TransportError(f"array {name[:40]!r} is referenced twice")
            used.add(name)
            return to_plain(arrays[name])
        if set(value) == {_FLOAT_KEY}:
            text = value[_FLOAT_KEY]
            if text not in ("nan", "inf", "-inf"):
                raise TransportError("malformed special float")
            return float(text)
        return {k: _decode(v, arrays, used, depth + 1) for k, v in value.items()}
    if isinstance(value, list):
        return [_decode(v, arrays, used, depth + 1) for v in value]
    return value  # JSON gives only None, bool, int, float and str here


def read_plain(stem: str | Path, *, dir_fd: int | None = None) -> Any:
    """Read plain data written by :func:`write_plain` (``stem.json`` and, if present, ``stem.npz``).

    ``stem`` is relative to the open directory ``dir_fd`` when given. Both files are read with
    :func:`read_untrusted`.

    Raises
    ------
    NotWritten
        If ``stem.json`` does not exist.
    TransportError
        If either file is unsafe, too large or malformed.
    """
    stem = os.fspath(stem)
    label = Path(stem).name
    doc = _parse_json(read_untrusted(f"{stem}.json", MAX_JSON_BYTES, dir_fd=dir_fd), f"{label}.json")
    try:
        arrays = _parse_npz(read_untrusted(f"{stem}.npz", MAX_NPZ_BYTES, dir_fd=dir_fd), f"{label}.npz")
    except NotWritten:
        arrays = {}
    try:
        return _decode(doc, arrays, set())
    except NotPlainData as exc:
        raise TransportError(str(exc)) from None
