"""The cache of generated datasets: where it lives, how a file is keyed, written and read back.

Generated datasets (recorded runs, maps, experiments) are deterministic, so they are computed once
and kept under :func:`cache_dir`. A file's name holds :func:`cache_key` of everything that made it,
including :func:`code_version` of the code, so an edit never serves an old result; it is written
by :func:`write_arrays` (atomically, through :func:`robokit.files.write_atomically`) so notebooks
running side by side never read one half written, and read back by :func:`read_arrays`, which treats
a damaged, stale or foreign file as absent (docs/DESIGN.md, "Caching"). Course conventions; not from
a paper.
"""
from __future__ import annotations

import functools
import hashlib
import json
import os
import zipfile
import zlib
from pathlib import Path
from typing import Sequence

from .files import read_npz, require_named_arrays, save_npz, write_atomically

__all__ = ["cache_dir", "cache_key", "source_digest", "code_version", "write_arrays", "read_arrays",
           "CACHE_READ_ERRORS", "records_to_arrays", "record_names", "records_from_arrays"]


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

    require_named_arrays(arrays)
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
