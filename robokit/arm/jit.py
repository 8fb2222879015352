"""Compiled kernels with numba, cached on disk in robokit's cache directory.

Only the compiled kernel modules of the IK solvers import this module, and they are imported on
the first solve, never by ``import robokit``: importing robokit compiles nothing and does not load
numba. Compiled machine code is cached under ``cache_dir("numba")`` (``$ROBOKIT_CACHE/numba``)
unless ``NUMBA_CACHE_DIR`` says otherwise, so a read-only package directory is never written to. If
no cache directory can be created, the kernels are still compiled, only not cached (each new
process then pays the compile time again).
"""
from __future__ import annotations

import hashlib
import os
import sys
import warnings
from pathlib import Path

import numba
from numba.core import config as _numba_config

from ..config import cache_dir

__all__ = ["njit", "CACHING", "compile_notice", "compiled"]


def _use_robokit_cache() -> bool:
    """Point numba's cache at ``cache_dir("numba")`` (unless ``NUMBA_CACHE_DIR`` is set); False if
    that directory cannot be created."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return True
    try:
        path = cache_dir("numba")
    except OSError:
        return False
    if not os.access(path, os.W_OK):
        return False
    _numba_config.CACHE_DIR = str(path)
    return True


#: Whether compiled kernels are cached on disk in this process.
CACHING = _use_robokit_cache()


def njit(fn):
    """``numba.njit(cache=True)`` when a cache directory is usable, plain ``numba.njit`` otherwise.

    Compilation happens on the first call, for the argument types of that call.

    Parameters
    ----------
    fn : callable
        A function written in numba's subset of Python.

    Returns
    -------
    numba dispatcher

    Examples
    --------
    >>> add = njit(lambda a, b: a + b)
    >>> add(1.5, 2.0)
    3.5
    """
    if CACHING and getattr(fn, "__name__", "") != "<lambda>":
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", numba.NumbaWarning)
                return numba.njit(cache=True)(fn)
        except (RuntimeError, OSError):          # numba found no writable cache location
            pass
    return numba.njit(fn)


#: The kernel modules whose source decides whether the cached machine code is current.
_SOURCES = ("jit.py", "chain_kernels.py", "srs_kernels.py", "numeric_kernels.py")


def _record(kernel: str) -> Path:
    """Where this machine records that ``kernel`` was compiled from the current source and numba."""
    h = hashlib.sha1(f"{numba.__version__} {sys.version_info[:2]}".encode())
    here = Path(__file__).parent
    for name in _SOURCES:
        h.update((here / name).read_bytes())
    return Path(_numba_config.CACHE_DIR or here) / f"robokit-{kernel}-{h.hexdigest()[:12]}.compiled"


def compile_notice(kernel: str, what: str) -> Path | None:
    """Say, before the first call of compiled ``kernel`` in this process, that it compiles now.

    One line on standard error, only when this machine's cache has no record that ``kernel`` was
    compiled from the current source (a cache hit stays quiet). Call :func:`compiled` with the
    returned record after the call.

    Parameters
    ----------
    kernel : str
        A name for the compiled entry point, e.g. ``"srs_solve"``.
    what : str
        What the student is waiting for, e.g. ``"the analytic IK solver"``.

    Returns
    -------
    pathlib.Path or None
        The record to write once the call has compiled; None when nothing is to be written.

    Examples
    --------
    >>> isinstance(compile_notice("doctest-never-recorded", "nothing") , Path) or not CACHING
    True
    """
    if not CACHING:
        print(f"robokit: compiling {what} for this machine (no writable cache folder, so every new "
              "process compiles it again)", file=sys.stderr)
        return None
    try:
        record = _record(kernel)
        if record.exists():
            return None
    except OSError:
        return None
    print(f"robokit: compiling {what} for this machine; this happens once, later runs load it from the "
          f"cache ({record.parent})", file=sys.stderr)
    return record


def compiled(record: Path | None) -> None:
    """Record that the kernel of :func:`compile_notice` is compiled and cached (nothing if ``None``).

    Parameters
    ----------
    record : pathlib.Path or None
        What :func:`compile_notice` returned.

    Examples
    --------
    >>> compiled(None)
    """
    if record is not None:
        try:
            record.parent.mkdir(parents=True, exist_ok=True)
            record.touch()
        except OSError:
            pass
