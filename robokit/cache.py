"""The cache of generated datasets: where it lives, how a file is keyed, written and read back.

Generated datasets (recorded runs, maps, experiments) are deterministic, so they are computed once
and kept under :func:`cache_dir`. A file's name holds :func:`cache_key` of everything that made it,
including :func:`code_version` of the code, so an edit never serves an old result; it is written
atomically (:func:`write_atomically`) so notebooks running side by side never read one half
written, and read back by :func:`read_arrays`, which treats a damaged, stale or foreign file as
absent (docs/DESIGN.md, "Caching"). Course conventions; not from a paper.
"""
from __future__ import annotations

import functools
import hashlib
import json
import os
import stat
import zipfile
import zlib
from pathlib import Path
from typing import Any, Callable, Sequence

__all__ = ["cache_dir", "cache_key", "source_digest", "code_version", "write_atomically", "save_npz", "read_npz",
           "NpzFileError", "write_arrays", "read_arrays", "CACHE_READ_ERRORS", "records_to_arrays", "record_names",
           "records_from_arrays"]


def cache_dir(*parts: str, create: bool = True) -> Path:
    """Return robokit's cache directory (or a sub-directory of it).

    The location is ``$ROBOKIT_CACHE`` if set, else ``$XDG_CACHE_HOME/robokit``, else
    ``~/.cache/robokit``.

    Parameters
    ----------
    *parts : str
        Sub-directory names, e.g. ``cache_dir("runs")``. Each must be a plain name (no path
        separators, not ``..``).
    create : bool, default True
        Create the directory if it does not exist.

    Returns
    -------
    pathlib.Path
        Absolute path of the directory.

    Raises
    ------
    ValueError
        If a part is empty, contains a path separator or is ``.``/``..``.

    Notes
    -----
    Course convention (DESIGN.md, "Caching"); not from a paper.
    """
    for p in parts:
        if not isinstance(p, str) or not p or p in {".", ".."} or "/" in p or os.sep in p:
            raise ValueError(f"parts: expected plain directory names, got {p!r}")
    if os.environ.get("ROBOKIT_CACHE"):
        base = Path(os.environ["ROBOKIT_CACHE"])
    elif os.environ.get("XDG_CACHE_HOME"):
        base = Path(os.environ["XDG_CACHE_HOME"]) / "robokit"
    else:
        base = Path.home() / ".cache" / "robokit"
    path = base.expanduser().resolve().joinpath(*parts)
    if create:
        path.mkdir(parents=True, exist_ok=True)
    return path


def cache_key(**params: object) -> str:
    """Return a short, stable hash of keyword parameters, for naming cached files.

    Parameters
    ----------
    **params
        JSON-serialisable values (numbers, strings, lists, dicts, ``None``, booleans).

    Returns
    -------
    str
        16 hexadecimal characters; equal parameters give equal keys across runs and machines.

    Raises
    ------
    TypeError
        If a value cannot be serialised to JSON.

    Notes
    -----
    Course convention (DESIGN.md, "Caching"); not from a paper.
    """
    try:
        text = json.dumps(params, sort_keys=True, separators=(",", ":"))
    except TypeError as exc:
        raise TypeError(f"params: expected JSON-serialisable values ({exc})") from None
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@functools.lru_cache(maxsize=None)
def source_digest(*packages: str) -> str:
    """A short hash of the source of robokit's ``packages`` (e.g. ``"sim", "geometry"``) or single modules.

    A cached dataset is keyed by it as well as by its parameters, so a change to the code that
    makes the dataset never serves an old one (DESIGN.md, "Caching").

    Parameters
    ----------
    *packages : str
        Sub-package names of robokit (at least one), ``"package.module"`` for one module (an
        experiment keys its cache by its own module, not by every module beside it), or a
        top-level module such as ``"validation"``.

    Returns
    -------
    str
        16 hexadecimal digits.

    Raises
    ------
    ValueError
        For no package or a name that is not a robokit sub-package.

    Notes
    -----
    Course convention; not from a paper.

    Examples
    --------
    >>> len(source_digest("geometry")), source_digest("geometry") == source_digest("geometry", "sim")
    (16, False)
    >>> source_digest("geometry.planar") == source_digest("geometry"), len(source_digest("validation"))
    (False, 16)
    """
    root = Path(__file__).resolve().parent
    if not packages:
        raise ValueError("packages: expected at least one robokit sub-package name, got none")
    digest = hashlib.sha256()
    for package in packages:
        parts = package.split(".") if isinstance(package, str) else [None]
        if not 1 <= len(parts) <= 2 or not all(isinstance(p, str) and p.isidentifier() for p in parts):
            raise ValueError(f"packages: expected robokit sub-package or module names, got {package!r}")
        if len(parts) == 2 and (root / parts[0] / f"{parts[1]}.py").is_file():
            sources = [root / parts[0] / f"{parts[1]}.py"]
        elif len(parts) == 1 and (root / package).is_dir():
            sources = sorted((root / package).glob("*.py"))
        elif len(parts) == 1 and (root / f"{package}.py").is_file():
            sources = [root / f"{package}.py"]
        else:
            raise ValueError(f"packages: expected robokit sub-package or module names, got {package!r}")
        for source in sources:
            digest.update(parts[0].encode() + b"/" + source.name.encode() + b"\0" + source.read_bytes())
    return digest.hexdigest()[:16]


def write_atomically(target: str | Path, write: Callable[[Path], Any]) -> Path:
    """Write a cache file so that no reader ever sees it half written.

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
    Course convention (DESIGN.md, "Caching"); a rename within one directory is atomic on POSIX.

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



@functools.lru_cache(maxsize=None)
def code_version(*packages: str) -> dict:
    """What decides a cached dataset besides its parameters: the code that makes it.

    A hash of the source of robokit's ``packages`` (:func:`source_digest`) and the numpy, scipy
    and OpenCV versions (their numerics changed results before; scipy's KD-trees and least squares
    sit under matching and mapping). It enters every cache key and is
    stored in the cache file, so a dataset made by other code is never served.

    Parameters
    ----------
    *packages : str
        As for :func:`source_digest`.

    Returns
    -------
    dict
        ``{"robokit": digest, "numpy": version, "scipy": version, "opencv": version}``.

    Raises
    ------
    ValueError
        As :func:`source_digest`.

    Notes
    -----
    Course convention (DESIGN.md, "Caching"); not from a paper.

    Examples
    --------
    >>> v = code_version("geometry")
    >>> sorted(v), v["robokit"] == source_digest("geometry")
    (['numpy', 'opencv', 'robokit', 'scipy'], True)
    """
    import cv2
    import numpy as np
    import scipy

    return {"robokit": source_digest(*packages), "numpy": np.__version__, "scipy": scipy.__version__,
            "opencv": cv2.__version__}


#: What reading a damaged, truncated or foreign cache file can raise; every cache reader catches
#: exactly these and rebuilds (``zlib.error`` is a damaged compressed member; it is not an OSError).
CACHE_READ_ERRORS: tuple = (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile, zlib.error)

#: The largest cache file :func:`read_arrays` serves (bytes; also its bound on values per array).
MAX_CACHE_BYTES = 4 * 1024**3
#: The entry of a cache file (:func:`write_arrays`) that holds the parameters it was made with.
_META = "cache_meta"


def _meta_text(meta: dict) -> str:
    try:
        return json.dumps(meta, sort_keys=True, separators=(",", ":"))
    except TypeError as exc:
        raise TypeError(f"meta: expected a JSON-serialisable dict of parameters ({exc})") from None


def _require_named_arrays(arrays: Any) -> None:
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

    _require_named_arrays(arrays)
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
    robokit.cache.NpzFileError: path: a.npz: array 'a' declares 3 values, more than this reader's 2
    """
    path = Path(path)
    info = os.stat(path)
    if not stat.S_ISREG(info.st_mode):
        raise NpzFileError(f"path: {path.name}: expected a regular file, got a device, FIFO or directory")
    if info.st_size > max_bytes:
        raise NpzFileError(f"path: {path.name}: {info.st_size} bytes, more than this reader's {max_bytes}")
    try:
        with zipfile.ZipFile(path) as archive:
            members = archive.infolist()
            if len(members) > max_arrays:
                raise NpzFileError(f"path: {path.name}: {len(members)} members, more than this reader's {max_arrays}")
            return {m.filename[:-4]: _read_member(archive, m, path.name, max_bytes, max_values) for m in members}
    except NpzFileError:
        raise
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error) as err:
        raise NpzFileError(f"path: {path.name}: not a readable .npz archive (truncated or corrupt: {err})") from None


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
        except NpzFileError:
            raise
        except Exception as err:  # numpy parses the header as a Python literal: a damaged one fails in many ways
            raise NpzFileError(f"path: {label}: array {name[:-4]!r} has a damaged header ({type(err).__name__})") from None
        count = int(np.prod(shape, dtype=object))
        if dtype.hasobject:
            raise NpzFileError(f"path: {label}: array {name[:-4]!r} holds Python objects, which are never read")
        if count > max_values:
            raise NpzFileError(f"path: {label}: array {name[:-4]!r} declares {count} values, more than this "
                               f"reader's {max_values}")
        data = fh.read(count * dtype.itemsize)
        if len(data) != count * dtype.itemsize:
            raise NpzFileError(f"path: {label}: array {name[:-4]!r} is truncated")
        arr = np.frombuffer(data, dtype=dtype, count=count).copy()
        return arr.reshape(shape[::-1]).T if fortran else arr.reshape(shape)


def write_arrays(target: str | Path, arrays: dict, meta: dict | None = None) -> Path:
    """Write named arrays as a compressed ``.npz`` cache file (:func:`save_npz`), with the parameters that made them.

    Parameters
    ----------
    target : str or Path
    arrays : dict of str to array_like
    meta : dict, optional
        The parameters and code version (:func:`code_version`) the arrays were made with; stored
        in the file, and :func:`read_arrays` serves the file only to a caller asking with equal ones.

    Returns
    -------
    Path
        ``target``, written through :func:`write_atomically`.

    Raises
    ------
    TypeError
        For a ``meta`` that is not JSON-serialisable or ``arrays`` that is not a dict of names.
    ValueError
        If ``arrays`` uses the reserved name ``"cache_meta"``.

    Notes
    -----
    Course convention (DESIGN.md, "Caching"); not from a paper.

    Examples
    --------
    >>> import tempfile
    >>> import numpy as np
    >>> target = Path(tempfile.mkdtemp()) / "c.npz"
    >>> _ = write_arrays(target, {"a": np.arange(3)}, {"n": 3})
    >>> read_arrays(target, ["a"], {"n": 3})["a"].tolist(), read_arrays(target, ["a"], {"n": 4})
    ([0, 1, 2], None)
    """
    import numpy as np

    _require_named_arrays(arrays)
    if _META in arrays:
        raise ValueError(f"arrays: expected names other than the reserved {_META!r}, got {sorted(arrays)}")
    stored = dict(arrays)
    if meta is not None:
        stored[_META] = np.array(_meta_text(meta))
    return write_atomically(target, lambda path: save_npz(path, stored))


def read_arrays(target: str | Path, names: Sequence[str], meta: dict | None = None) -> dict | None:
    """The named arrays of a cache file written with ``numpy.savez``, or ``None`` to rebuild it.

    Parameters
    ----------
    target : str or Path
    names : sequence of str
        The arrays the cache must hold.
    meta : dict, optional
        The parameters the caller needs (as given to :func:`write_arrays`): a file made with any
        others, or that does not say what it was made with, is not served.

    Returns
    -------
    dict of str to numpy.ndarray, or None
        ``None`` for a missing, truncated, corrupt or foreign file, one without every name, or one
        made with other parameters or code: the caller rebuilds it, so a cache is never needed for
        correctness and never serves a stale dataset.

    Notes
    -----
    Course convention (DESIGN.md, "Caching"), the reading twin of :func:`write_atomically` and
    :func:`write_arrays`; never unpickles. Every array is read here (:func:`read_npz`, within
    :data:`MAX_CACHE_BYTES`), so a damaged or oversized member is found now rather than by the caller.

    Examples
    --------
    >>> import tempfile
    >>> import numpy as np
    >>> target = Path(tempfile.mkdtemp()) / "c.npz"
    >>> read_arrays(target, ["a"]) is None
    True
    >>> _ = write_atomically(target, lambda p: np.savez(p, a=np.arange(3)))
    >>> read_arrays(target, ["a"])["a"].tolist(), read_arrays(target, ["a", "b"])
    ([0, 1, 2], None)
    >>> read_arrays(target, ["a"], {"n": 3}) is None     # says nothing of what made it
    True
    """
    try:
        data = read_npz(target, max_bytes=MAX_CACHE_BYTES, max_values=MAX_CACHE_BYTES)
        if meta is not None and (_META not in data or str(data[_META]) != _meta_text(meta)):
            return None
        return {name: data[name] for name in names}
    except CACHE_READ_ERRORS:
        return None


#: Field annotations a cached record may have (as strings: ``from __future__ import annotations``).
_RECORD_FIELD_KINDS = ("int", "float", "bool", "list", "np.ndarray")


def _record_fields(cls) -> tuple:
    import dataclasses

    if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
        raise TypeError(f"cls: expected a dataclass, got {cls!r}")
    odd = [f"{f.name}: {f.type}" for f in dataclasses.fields(cls) if f.type not in _RECORD_FIELD_KINDS]
    if odd:
        raise TypeError(f"cls: expected fields annotated {list(_RECORD_FIELD_KINDS)}, got {odd}")
    return dataclasses.fields(cls)


def records_to_arrays(records: Sequence, cls) -> dict:
    """Named arrays ``"k/field"`` of dataclass records, for :func:`write_arrays`; read them back
    with :func:`read_arrays` ``(target,`` :func:`record_names` ``(cls, n))`` and :func:`records_from_arrays`.

    Parameters
    ----------
    records : sequence of ``cls``
    cls : dataclass type
        Fields annotated ``int``, ``float``, ``bool``, ``list`` (of str) or ``np.ndarray``.

    Returns
    -------
    dict of str to numpy.ndarray

    Raises
    ------
    TypeError
        For a ``cls`` that is not such a dataclass, or a record that is not a ``cls``.

    Notes
    -----
    Course convention (DESIGN.md, "Caching"); not from a paper.

    Examples
    --------
    >>> import dataclasses
    >>> @dataclasses.dataclass
    ... class Run:
    ...     reached: int
    ...     states: list
    >>> arrays = records_to_arrays([Run(2, ["go", "stop"])], Run)
    >>> record_names(Run, 1), records_from_arrays(arrays, Run, 1)
    (['0/reached', '0/states'], [Run(reached=2, states=['go', 'stop'])])
    """
    import numpy as np

    fields = _record_fields(cls)
    bad = [k for k, r in enumerate(records) if not isinstance(r, cls)]
    if bad:
        raise TypeError(f"records: expected {cls.__name__} records, got another kind at {bad[:5]}")
    return {f"{k}/{f.name}": np.asarray(getattr(r, f.name), str if f.type == "list" else None)
            for k, r in enumerate(records) for f in fields}


def record_names(cls, n: int) -> list:
    """The array names of ``n`` records of ``cls`` in :func:`records_to_arrays` (its Examples)."""
    return [f"{k}/{f.name}" for k in range(n) for f in _record_fields(cls)]


def records_from_arrays(data: dict, cls, n: int) -> list:
    """The ``n`` records of ``cls`` stored by :func:`records_to_arrays` (see its Examples): ``int``,
    ``float`` and ``bool`` fields as Python scalars, ``list`` fields as lists of str."""
    import numpy as np

    cast = {"int": int, "float": float, "bool": bool, "list": lambda a: [str(v) for v in a], "np.ndarray": np.asarray}
    return [cls(**{f.name: cast[f.type](data[f"{k}/{f.name}"]) for f in _record_fields(cls)}) for k in range(n)]
