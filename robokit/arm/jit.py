"""Compiled kernels with numba, cached on disk in robokit's cache directory.

Only the compiled kernel modules of the IK solvers import this module, and they are imported on
the first solve, never by ``import robokit``: importing robokit compiles nothing and does not load
numba. Compiled machine code is cached under ``cache_dir("numba", <digest>)``
(``$ROBOKIT_CACHE/numba/<digest>``, or ``$NUMBA_CACHE_DIR/<digest>`` if that is set), so a
read-only package directory is never written to. ``<digest>`` hashes the source of every kernel
module with the numba and Python versions: numba checks only the file of the function it compiled,
and our kernels inline functions of the other kernel modules, so an edit there must start a new
cache rather than let numba load machine code built from the old source. If no cache directory can
be created, the kernels are still compiled, only not cached (each new process then pays the
compile time again). The redirection is process-wide: a student's own ``@njit(cache=True)`` code
run after a robokit solve is cached in the same folder.
"""
from __future__ import annotations

import hashlib
import os
import sys
import warnings
from pathlib import Path

import numba
from numba.core import config as _numba_config

from ..cache import cache_dir

__all__ = ["njit", "CACHING", "compile_notice", "compiled"]


#: The kernel modules whose source decides whether the cached machine code is current.
SOURCES = ("jit.py", "chain_kernels.py", "srs_kernels.py", "numeric_kernels.py")


def source_digest() -> str:
    """Hash of every kernel module's source with the numba and Python versions."""
    h = hashlib.sha1(f"{numba.__version__} {sys.version_info[:2]}".encode())
    here = Path(__file__).parent
    for name in SOURCES:
        h.update((here / name).read_bytes())
    return h.hexdigest()[:12]


#: Names the cache folder of the compiled kernels (see the module docstring).
SOURCE_DIGEST = source_digest()


def _use_robokit_cache() -> bool:
    """Point numba's cache at a folder named by :data:`SOURCE_DIGEST`, under ``NUMBA_CACHE_DIR`` if
    set, else under ``cache_dir("numba")``; False if that folder cannot be created."""
    try:
        if os.environ.get("NUMBA_CACHE_DIR"):
            path = Path(os.environ["NUMBA_CACHE_DIR"]) / SOURCE_DIGEST
            path.mkdir(parents=True, exist_ok=True)
        else:
            path = cache_dir("numba", SOURCE_DIGEST)
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


def _record(kernel: str) -> Path:
    """Where this machine records that ``kernel`` was compiled from the current source and numba."""
    return Path(_numba_config.CACHE_DIR or Path(__file__).parent) / f"robokit-{kernel}-{SOURCE_DIGEST}.compiled"


def compile_notice(kernel: str, what: str) -> Path | None:
    """Say, before the first call of compiled ``kernel`` in this process, that it compiles now.

    One line on standard output labelled "robokit note" (information, not an error: a notebook shows
    it in a plain box, not a red one), only when this machine's cache has no record that ``kernel`` was
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
    >>> record = compile_notice("doctest-never-recorded", "nothing")   # doctest: +ELLIPSIS
    robokit note: compiling nothing for this machine...
    >>> isinstance(record, Path) or not CACHING
    True
    """
    if not CACHING:
        print(f"robokit note: compiling {what} for this machine (no writable cache folder, so every new "
              "process compiles it again)")
        return None
    try:
        record = _record(kernel)
        if record.exists():
            return None
    except OSError:
        return None
    print(f"robokit note: compiling {what} for this machine; this happens once, later runs load it from "
          f"the cache ({record.parent})")
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
