"""Files read within stated bounds and written atomically: the base of every robokit reader and writer.

A reader opens only a regular file (never a device, FIFO or directory, which may never end or
block), refuses one larger than its budget before reading it (:func:`open_regular`,
:func:`read_regular`), and reads ``.npz`` archives member by member, each header checked before its
data (:func:`read_npz`); a writer writes a temporary sibling and renames it over the target
(:func:`write_atomically`), so an interrupted save leaves the old file. Each reader of robokit wraps
these in its own named error (docs/DESIGN.md, "Files"). Course conventions; not from a paper.
"""
from __future__ import annotations

import os
import stat
import zipfile
import zlib
from pathlib import Path
from typing import Any, BinaryIO, Callable

from .validation import as_int, describe

__all__ = ["as_file_path", "open_regular", "read_regular", "write_atomically", "require_named_arrays", "save_npz", "read_npz",
           "NpzFileError"]


def as_file_path(value: Any, name: str = "path") -> Path:
    """A file path given as ``str`` or ``os.PathLike``, refused clearly otherwise.

    Raises
    ------
    TypeError
        For anything else (bytes, numbers, arrays), naming ``name``.
    ValueError
        For an empty path.

    Examples
    --------
    >>> as_file_path("map.yaml").name
    'map.yaml'
    >>> as_file_path(3, "yaml_path")
    Traceback (most recent call last):
    ...
    TypeError: yaml_path: expected a file path (str or pathlib.Path), got 3
    """
    if not isinstance(value, (str, os.PathLike)) or isinstance(value, bytes):
        raise TypeError(f"{name}: expected a file path (str or pathlib.Path), got {describe(value)}")
    path = os.fspath(value)
    if not isinstance(path, str) or not path or "\0" in path:
        raise ValueError(f"{name}: expected a non-empty file path without NUL characters, got {describe(value)}")
    return Path(path)


def open_regular(path: Any, max_bytes: int, refuse: Callable[[str], Exception]) -> BinaryIO:
    """Open ``path`` for binary reading if it is a regular file of at most ``max_bytes``.

    The file is opened without blocking (a FIFO would otherwise wait for a writer) and checked on
    the opened descriptor, so a symbolic link swapped after a check cannot lead elsewhere.

    Parameters
    ----------
    path : str or os.PathLike
    max_bytes : int
        The reader's budget.
    refuse : callable ``(reason) -> Exception``
        Makes the reader's own named error from a phrase such as ``"is not a regular file (...)"``.

    Returns
    -------
    binary file object
        Open at the start; the caller closes it.

    Raises
    ------
    FileNotFoundError
        If there is no such file (or a symbolic link leads nowhere).
    Exception
        ``refuse(reason)`` for a device, FIFO, directory, a file over ``max_bytes``, or one that
        cannot be opened (permissions, a loop of symbolic links).

    Notes
    -----
    Course convention for file readers (DESIGN.md, "Files").

    Examples
    --------
    >>> open_regular("/dev/zero", 10, ValueError)
    Traceback (most recent call last):
    ...
    ValueError: is not a regular file (a device, FIFO or directory)
    """
    try:
        fd = os.open(os.fspath(path), os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        raise
    except OSError as exc:
        raise refuse(f"cannot be opened ({exc.strerror})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise refuse("is not a regular file (a device, FIFO or directory)")
        if info.st_size > max_bytes:
            raise refuse(f"has {info.st_size} bytes, more than the {max_bytes} this reader reads")
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(path: Any, max_bytes: int, refuse: Callable[[str], Exception]) -> bytes:
    """The bytes of a regular file of at most ``max_bytes`` (:func:`open_regular`), read once.

    Only the bytes the file holds are asked for (a small file costs little memory, whatever the
    budget); a file that grows while it is read is refused.

    Returns
    -------
    bytes

    Raises
    ------
    FileNotFoundError
        If there is no such file.
    Exception
        ``refuse(reason)``, as :func:`open_regular`, or if reading fails.

    Examples
    --------
    >>> import tempfile
    >>> target = Path(tempfile.mkdtemp()) / "a.txt"
    >>> _ = target.write_bytes(b"12345")
    >>> read_regular(target, 5, ValueError)
    b'12345'
    >>> read_regular(target, 4, ValueError)
    Traceback (most recent call last):
    ...
    ValueError: has 5 bytes, more than the 4 this reader reads
    """
    with open_regular(path, max_bytes, refuse) as fh:
        try:   # as many bytes as it holds (no memory set aside for the whole budget), and one to see growth
            size = os.fstat(fh.fileno()).st_size
            data = fh.read(size + 1)
        except OSError as exc:
            raise refuse(f"cannot be read ({exc.strerror})") from None
    if len(data) > size:
        raise refuse("changed while it was read")
    return data


def write_atomically(target: str | Path, write: Callable[[Path], Any]) -> Path:
    """Write a file so that no reader ever sees it half written.

    ``write(tmp)`` writes a temporary sibling of ``target`` (same suffix, named after this process);
    it is then renamed over ``target`` in one step. Notebooks run in parallel (the course build, the
    tests) and share the cache: each either finds the old file, the complete new one, or none.

    Parameters
    ----------
    target : str or Path
    write : callable ``(path) -> Any``
        Writes the file at the path it is given.

    Returns
    -------
    Path
        ``target``.

    Raises
    ------
    TypeError
        For a non-callable ``write``. Whatever ``write`` raises propagates; its temporary file is
        removed.

    Notes
    -----
    Course convention (DESIGN.md, "Files"); a rename within one directory is atomic on POSIX.

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> write_atomically(folder / "a.json", lambda p: p.write_text("{}")).read_text()
    '{}'
    >>> sorted(f.name for f in folder.iterdir())
    ['a.json']
    """
    if not callable(write):
        raise TypeError(f"write: expected a callable that writes a path, got {type(write).__name__}")
    target = Path(target)
    tmp = target.with_name(f"{target.stem}.{os.getpid()}.tmp{target.suffix}")
    try:
        write(tmp)
        tmp.replace(target)
    finally:
        tmp.unlink(missing_ok=True)
    return target




def require_named_arrays(arrays: Any) -> None:
    """Refuse ``arrays`` unless it is a dict of non-empty names (the ``.npz`` writers' input).

    Examples
    --------
    >>> require_named_arrays({"a": [1]})
    >>> require_named_arrays([1])
    Traceback (most recent call last):
    ...
    TypeError: arrays: expected a dict of array names to arrays, got list
    """
    if not isinstance(arrays, dict) or not all(isinstance(k, str) and k for k in arrays):
        raise TypeError(f"arrays: expected a dict of array names to arrays, got {type(arrays).__name__}")



def save_npz(target: Any, arrays: dict) -> Any:
    """Write named arrays as an ``.npz`` that ``numpy.load`` reads, compressed for speed over size.

    The layout of ``numpy.savez_compressed`` (a zip of ``.npy`` files, never pickles) with zlib's
    fastest level, 1: rendered images and depths compress hardly better at numpy's default level 6,
    which takes about 1.5 times as long to write.

    Parameters
    ----------
    target : str, Path or binary file object
    arrays : dict of str to array_like

    Returns
    -------
    The ``target`` it was given.

    Raises
    ------
    TypeError
        For ``arrays`` that is not a dict of names, or an array of Python objects.

    Examples
    --------
    >>> import io
    >>> import numpy as np
    >>> buffer = save_npz(io.BytesIO(), {"a": np.arange(3)})
    >>> np.load(io.BytesIO(buffer.getvalue()))["a"].tolist()
    [0, 1, 2]
    """
    import numpy as np

    require_named_arrays(arrays)
    with zipfile.ZipFile(target, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=1, allowZip64=True) as zf:
        for name, value in arrays.items():
            arr = np.asanyarray(value)
            if arr.dtype.hasobject:
                raise TypeError(f"arrays: expected numeric or text arrays, got Python objects under {name!r}")
            with zf.open(f"{name}.npy", "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, arr, allow_pickle=False)
    return target



class NpzFileError(ValueError):
    """A file that :func:`read_npz` will not read: not a regular file, too large, not an ``.npz`` of
    plain arrays, truncated, or declaring more values than its reader allows."""


def read_npz(path: Any, *, max_bytes: int = 1 << 30, max_arrays: int = 10_000,
             max_values: int = 1 << 28) -> dict:
    """Read every array of an ``.npz`` file within stated bounds, checked before memory is spent.

    The file must be a regular file (not a device, FIFO or directory) of at most ``max_bytes``,
    hold at most ``max_arrays`` ``.npy`` members, each of at most ``max_bytes`` uncompressed, of a
    plain dtype (never Python objects: nothing is unpickled) and declaring at most ``max_values``
    elements in its header, which is read before its data.

    Parameters
    ----------
    path : str or Path
    max_bytes, max_arrays, max_values : int
        The reader's budget; each file reader of robokit states its own.

    Returns
    -------
    dict of str to numpy.ndarray

    Raises
    ------
    TypeError, ValueError
        For a ``path`` that is not a path, or bounds that are not non-negative integers.
    NpzFileError
        (a ``ValueError``) For a file outside the bounds or not such an archive; the message names
        ``path`` and what was found.
    FileNotFoundError
        If there is no such file.

    Notes
    -----
    Course convention for file readers (DESIGN.md, "Conventions", Files); the twin of :func:`save_npz`.

    Examples
    --------
    >>> import tempfile
    >>> import numpy as np
    >>> target = Path(tempfile.mkdtemp()) / "a.npz"
    >>> read_npz(save_npz(target, {"a": np.arange(3)}))["a"].tolist()
    [0, 1, 2]
    >>> read_npz(target, max_values=2)
    Traceback (most recent call last):
    ...
    robokit.files.NpzFileError: path: a.npz: array 'a' declares 3 values, more than this reader's 2
    """
    path = as_file_path(path, "path")
    max_bytes = as_int(max_bytes, "max_bytes", minimum=0)
    max_arrays = as_int(max_arrays, "max_arrays", minimum=0)
    max_values = as_int(max_values, "max_values", minimum=0)

    def refuse(reason: str) -> NpzFileError:
        return NpzFileError(f"path: {path.name}: {reason}")

    try:
        with open_regular(path, max_bytes, refuse) as fh, zipfile.ZipFile(fh) as archive:
            members = archive.infolist()
            if len(members) > max_arrays:
                raise refuse(f"{len(members)} members, more than this reader's {max_arrays}")
            return {m.filename[:-4]: _read_member(archive, m, path.name, max_bytes, max_values) for m in members}
    except (NpzFileError, FileNotFoundError):
        raise
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error) as err:
        raise NpzFileError(f"path: {path.name}: not a readable .npz archive (truncated or corrupt: {err})") from None


#: How much of an ``.npy`` member :func:`read_npz` reads at a time.
_CHUNK_BYTES = 1 << 24


def _read_member(archive: zipfile.ZipFile, member: zipfile.ZipInfo, label: str, max_bytes: int, max_values: int):
    """One ``.npy`` member, its header checked against the budget before its data are read."""
    import numpy as np

    name = member.filename
    if not name.endswith(".npy") or member.file_size > max_bytes:
        raise NpzFileError(f"path: {label}: member {name[:60]!r} is not an .npy array within {max_bytes} bytes")
    with archive.open(member) as fh:
        try:
            version = np.lib.format.read_magic(fh)
            header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, fortran, dtype = header(fh, max_header_size=10_000)
        except Exception as err:  # numpy parses the header as a Python literal: a damaged one fails in many ways
            raise NpzFileError(f"path: {label}: array {name[:-4]!r} has a damaged header ({type(err).__name__})") from None
        count = int(np.prod(shape, dtype=object))
        if dtype.hasobject:
            raise NpzFileError(f"path: {label}: array {name[:-4]!r} holds Python objects, which are never read")
        if count > max_values:
            raise NpzFileError(f"path: {label}: array {name[:-4]!r} declares {count} values, more than this "
                               f"reader's {max_values}")
        arr = np.empty(count, dtype=dtype)
        raw, done = arr.view(np.uint8) if arr.nbytes else np.empty(0, np.uint8), 0
        while done < raw.size:                  # in chunks, into the array: memory for one copy, not two
            chunk = fh.read(min(raw.size - done, _CHUNK_BYTES))
            if not chunk:
                raise NpzFileError(f"path: {label}: array {name[:-4]!r} is truncated")
            raw[done:done + len(chunk)] = np.frombuffer(chunk, np.uint8)
            done += len(chunk)
        return arr.reshape(shape[::-1]).T if fortran else arr.reshape(shape)
