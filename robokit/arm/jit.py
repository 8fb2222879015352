"""Compiled kernels with numba, cached on disk in robokit's cache directory.

Only the compiled kernel modules of the IK solvers import this module, and they are imported on
the first solve, never by ``import robokit``: importing robokit compiles nothing and does not load
numba. Compiled machine code is cached under ``cache_dir("numba")`` (``$ROBOKIT_CACHE/numba``)
unless ``NUMBA_CACHE_DIR`` says otherwise, so a read-only package directory is never written to. If
no cache directory can be created, the kernels are still compiled, only not cached (each new
process then pays the compile time again).
"""
from __future__ import annotations

import os
import warnings

import numba
from numba.core import config as _numba_config

from ..config import cache_dir

__all__ = ["njit", "CACHING"]


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
