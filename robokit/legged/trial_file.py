"""A LittleDog trial log as one file: :func:`save_trial`, :func:`load_trial`, :func:`describe_layout`.

The file is a numpy ``.npz`` (a zip of ``.npy`` arrays, readable without robokit): one array per
stream of :class:`~robokit.legged.trial_log.TrialLog`, named as in
:data:`~robokit.legged.trial_log.LOG_LAYOUT`, plus two JSON strings, ``__meta__`` (the metadata,
with ``format`` = :data:`~robokit.legged.trial_log.LOG_FORMAT` and ``version`` =
:data:`~robokit.legged.trial_log.LOG_VERSION`) and ``__layout__`` (the layout: shape, dtype, unit,
description of every stream). It loads with ``allow_pickle=False``, so a log file can never run
code. A file that is truncated or corrupt, of another format or version, or that lacks a stream or
holds one of the wrong shape raises :class:`~robokit.legged.trial_log.TrialLogError`.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Sec. 2 (the host computer's
   log of every trial).
"""
from __future__ import annotations

import json
import os
import zipfile
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from ..cache import save_npz, write_atomically
from ..validation import describe
from .trial_log import LOG_FORMAT, LOG_LAYOUT, LOG_VERSION, META_KEYS, TrialLog, TrialLogError

__all__ = ["save_trial", "load_trial", "describe_layout"]


def _as_path(path: Any) -> Path:
    if not isinstance(path, (str, os.PathLike)) or isinstance(path, bytes):
        raise TypeError(f"path: expected a file path (str or pathlib.Path), got {describe(path)}")
    if not str(path):
        raise ValueError("path: expected a file path, got ''")
    return Path(path)


def _layout_json() -> str:
    return json.dumps({k: {"shape": list(s.shape), "dtype": s.dtype, "unit": s.unit, "description": s.description}
                       for k, s in LOG_LAYOUT.items()})


def save_trial(path: Any, log: TrialLog) -> Path:
    """Write a trial log to one compressed ``.npz``, atomically.

    Parameters
    ----------
    path : str or pathlib.Path
        The file (written as given; ``.npz`` is the usual suffix).
    log : TrialLog

    Returns
    -------
    pathlib.Path

    Raises
    ------
    TypeError, TrialLogError
        If ``log`` is not a TrialLog or ``path`` not a path; if the log's arrays were changed into
        an invalid state since it was built.

    Notes
    -----
    :func:`robokit.cache.save_npz` through :func:`robokit.cache.write_atomically`: a reader finds the
    old file, the complete new one or none, never half of one. The layout is in the module docstring.

    Examples
    --------
    >>> import tempfile
    >>> from robokit.legged import empty_streams, trial_meta
    >>> target = Path(tempfile.mkdtemp()) / "trial.npz"
    >>> save_trial(target, TrialLog(empty_streams(5), trial_meta())).name
    'trial.npz'
    >>> len(load_trial(target))
    5
    """
    target = _as_path(path)
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a TrialLog, got {describe(log)}")
    log.validate()
    arrays = dict(log.streams)
    arrays["__meta__"] = np.array(json.dumps(dict(log.meta)))
    arrays["__layout__"] = np.array(_layout_json())

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            save_npz(fh, arrays)

    return write_atomically(target, write)


def load_trial(path: Any) -> TrialLog:
    """Read a trial log written by :func:`save_trial`.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    TrialLog

    Raises
    ------
    TrialLogError
        For a truncated or corrupt file, a file of another format or of another version (the
        message says which version it is and which this code reads), a missing or unexpected
        stream, or one of the wrong shape, dtype or length.
    FileNotFoundError, TypeError
        If there is no such file; if ``path`` is not a path.

    Notes
    -----
    ``numpy.load(..., allow_pickle=False)``: a log file can never run code.

    Examples
    --------
    >>> import tempfile
    >>> target = Path(tempfile.mkdtemp()) / "cut.npz"
    >>> _ = target.write_bytes(b"PK\\x03\\x04 truncated")
    >>> load_trial(target)
    Traceback (most recent call last):
    ...
    robokit.legged.trial_log.TrialLogError: ...cut.npz: not a readable trial log (truncated or corrupt: ...)
    """
    source = _as_path(path)
    try:
        data = np.load(source, allow_pickle=False)
        if not isinstance(data, np.lib.npyio.NpzFile):      # a lone .npy array
            raise TrialLogError(f"{source}: not a {LOG_FORMAT} file (one .npy array, not an .npz archive)")
        with data:
            names = list(data.files)
            if "__meta__" not in names:
                raise TrialLogError(f"{source}: not a {LOG_FORMAT} file (it has no __meta__ record; arrays "
                                    f"{names[:6]})")
            arrays = {name: data[name] for name in names}
    except FileNotFoundError:
        raise
    except TrialLogError:
        raise
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error) as err:
        raise TrialLogError(f"{source}: not a readable trial log (truncated or corrupt: {err})") from None
    try:
        meta = json.loads(str(arrays.pop("__meta__")[()]))
    except (ValueError, TypeError, IndexError) as err:
        raise TrialLogError(f"{source}: its __meta__ record is not JSON ({err})") from None
    if not isinstance(meta, dict) or meta.get("format") != LOG_FORMAT:
        got = meta.get("format") if isinstance(meta, dict) else describe(meta)
        raise TrialLogError(f"{source}: a file of format {got!r}, not a {LOG_FORMAT!r} trial log")
    if meta.get("version") != LOG_VERSION:
        raise TrialLogError(f"{source}: a {LOG_FORMAT} file of version {meta.get('version')!r}; this code reads "
                            f"version {LOG_VERSION} only (convert the file, or read it with the robokit that wrote it)")
    arrays.pop("__layout__", None)
    missing = [k for k in LOG_LAYOUT if k not in arrays]
    if missing:
        raise TrialLogError(f"{source}: stream(s) {missing} missing (version {LOG_VERSION} has {list(LOG_LAYOUT)})")
    try:
        return TrialLog(arrays, meta)
    except (ValueError, TypeError) as err:
        raise TrialLogError(f"{source}: {err}") from None


def describe_layout() -> str:
    """The log's layout as a text table: each stream's name, shape, dtype, unit and description,
    then the metadata keys (a str).

    Examples
    --------
    >>> print(describe_layout().splitlines()[0])
    stream         shape     dtype    unit        description
    >>> print(describe_layout().splitlines()[2])
    q              (N, 12)   float64  rad         measured joint angles (encoders), leg-major FL, FR, HL, HR
    """
    rows = [f"{'stream':<14} {'shape':<9} {'dtype':<8} {'unit':<11} description"]
    for name, spec in LOG_LAYOUT.items():
        shape = "(" + ", ".join(["N"] + [str(s) for s in spec.shape]) + ")"
        rows.append(f"{name:<14} {shape:<9} {spec.dtype:<8} {spec.unit:<11} {spec.description}")
    rows += ["", f"one row per host cycle; file: {LOG_FORMAT} version {LOG_VERSION} (.npz, metadata as JSON):"]
    rows += [f"  {key:<17} {what}" for key, what in META_KEYS.items()]
    return "\n".join(rows)
