"""Run-time settings read from the environment: fast mode, headless, worker processes, the heap.

``ROBOKIT_FAST=1`` (set by the test-suite and the course build) asks for small runs: the progress
bar is quiet, and the course's experiments shrink (``robocourse.FAST``). ``ROBOKIT_HEADLESS`` and
``ROBOKIT_WORKERS`` say whether anyone is watching and how many worker processes to use.
Generated datasets are cached by :mod:`robokit.cache`. ``ROBOKIT_HEAP_PAD_MB`` says how much freed
memory the C heap keeps (:func:`pad_heap`, which ``import robokit`` calls once).
"""
from __future__ import annotations

import importlib.util
import os
import sys
import types
from collections.abc import Mapping

__all__ = ["fast_mode", "headless", "available_cpus", "worker_count", "HEAP_PAD_MB", "HEAP_ARRAY_LIMIT", "pad_heap",
           "lazy_module"]

_TRUE = {"1", "true", "yes", "on"}
_FALSE = {"", "0", "false", "no", "off"}


def _flag(environ, name: str) -> bool:
    """An on/off environment variable; a typo is an error, never silently off."""
    env = os.environ if environ is None else environ
    raw = str(env.get(name, "")).strip().lower()
    if raw in _TRUE:
        return True
    if raw in _FALSE:
        return False
    raise ValueError(f"{name}: expected one of 1/0/true/false/yes/no/on/off, got {env.get(name)!r}")


def fast_mode(environ: "os._Environ[str] | dict[str, str] | None" = None) -> bool:
    """Return whether fast mode is requested by the ``ROBOKIT_FAST`` environment variable.

    Parameters
    ----------
    environ : mapping, optional
        Environment to read; defaults to :data:`os.environ`.

    Returns
    -------
    bool
        ``True`` for ``1``/``true``/``yes``/``on`` (any case), ``False`` when unset or
        ``0``/``false``/``no``/``off``.

    Raises
    ------
    ValueError
        If the variable holds anything else, so a typo never silently runs the full experiment.

    Notes
    -----
    Course convention (DESIGN.md, "Fast mode"); not from a paper.
    """
    return _flag(environ, "ROBOKIT_FAST")


def headless(environ: "os._Environ[str] | dict[str, str] | None" = None) -> bool:
    """Return whether notebooks run without a person watching (``ROBOKIT_HEADLESS``).

    The course build and the test-suite execute notebooks with ``ROBOKIT_HEADLESS=1``: widgets
    that need a live kernel (sliders) are then replaced by their pre-computed static equivalent,
    which is what the course site shows.

    Parameters
    ----------
    environ : mapping, optional
        Environment to read; defaults to :data:`os.environ`.

    Returns
    -------
    bool

    Raises
    ------
    ValueError
        If the variable holds anything but the values :func:`fast_mode` accepts.

    Notes
    -----
    Course convention (DESIGN.md, "Visualisation"); not from a paper.

    Examples
    --------
    >>> headless({"ROBOKIT_HEADLESS": "1"}), headless({})
    (True, False)
    """
    return _flag(environ, "ROBOKIT_HEADLESS")


def available_cpus() -> int:
    """Number of CPUs this process may run on (its affinity mask where the system has one).

    Returns
    -------
    int
        At least 1.

    Notes
    -----
    Course convention (DESIGN.md, "Independent runs"); not from a paper.

    Examples
    --------
    >>> available_cpus() >= 1
    True
    """
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def worker_count(environ: "os._Environ[str] | dict[str, str] | None" = None) -> int:
    """Number of worker processes for :func:`robokit.parallel.map_runs`.

    Parameters
    ----------
    environ : mapping, optional
        Environment to read (default :data:`os.environ`).

    Returns
    -------
    int
        ``ROBOKIT_WORKERS`` when set (the course build sets it to share the cores between the
        notebooks it runs at once), else the number of CPUs this process may run on.

    Raises
    ------
    ValueError
        If ``ROBOKIT_WORKERS`` is not a whole number from 1 to 64.

    Notes
    -----
    Course convention (DESIGN.md, "Independent runs"); not from a paper.

    Examples
    --------
    >>> worker_count({"ROBOKIT_WORKERS": "1"})
    1
    """
    value = _whole_number(os.environ if environ is None else environ, "ROBOKIT_WORKERS", 1, 64)
    return min(64, available_cpus()) if value is None else value


def _whole_number(env, name: str, low: int, high: int, what: str = "a whole number") -> int | None:
    """A whole-number environment variable from ``low`` to ``high``; ``None`` when unset or blank."""
    raw = str(env.get(name, "")).strip()
    if not raw:
        return None
    try:
        value = int(raw)
    except ValueError:
        value = low - 1
    if not low <= value <= high:
        raise ValueError(f"{name}: expected {what} from {low} to {high}, got {raw!r}")
    return value


#: Megabytes of freed memory the C heap keeps at its top by default (:func:`pad_heap`).
HEAP_PAD_MB = 64
#: Arrays below this many bytes come from the heap, not from a fresh ``mmap`` (glibc's own ceiling
#: for its adaptive threshold on 64-bit systems, 32 MiB).
HEAP_ARRAY_LIMIT = 32 << 20
_M_TOP_PAD, _M_MMAP_THRESHOLD = -2, -3          # glibc's malloc.h


def pad_heap(environ: "os._Environ[str] | dict[str, str] | None" = None) -> int:
    """Let the C heap keep freed memory, up to ``ROBOKIT_HEAP_PAD_MB`` megabytes (glibc only).

    Parameters
    ----------
    environ : mapping, optional
        Environment to read (default :data:`os.environ`).

    Returns
    -------
    int
        The pad set, in bytes; 0 when nothing was changed: ``ROBOKIT_HEAP_PAD_MB=0``, the user's own
        allocator settings in ``environ`` (any ``MALLOC_*_`` variable, or ``glibc.malloc`` in
        ``GLIBC_TUNABLES``), or a C library without glibc's ``mallopt``.

    Raises
    ------
    ValueError
        If ``ROBOKIT_HEAP_PAD_MB`` is not a whole number from 0 to 1024.
    TypeError
        If ``environ`` is not a mapping.

    Notes
    -----
    Course convention (DESIGN.md, "Speed"); not from a paper. A filter update over thousands of
    particles makes and frees arrays of megabytes (2000 particles x 60 beams x 2 coordinates of
    float64 is 1.9 MB). glibc serves such an array from a fresh ``mmap``, or from its heap, whose
    freed top it gives back to the system once more than a threshold is free; either way the next
    update pays a page fault for every 4 KiB it takes again (1600 faults and about half the time of
    a 2000-particle update). Its thresholds adapt to the largest array freed so far, so how often
    that happens depends on the process's history. This fixes them with ``mallopt``: arrays below
    :data:`HEAP_ARRAY_LIMIT` come from the heap (``M_MMAP_THRESHOLD``, where glibc's adaptation
    stops anyway), and the heap keeps up to the pad free at its top (``M_TOP_PAD``, per malloc
    arena). No number computed changes. The cost: freed arrays below a live allocation stay with
    the process too (heap fragmentation), where a fresh ``mmap`` would have been unmapped;
    ``ROBOKIT_HEAP_PAD_MB=0`` leaves glibc's defaults. ``benchmarks/bench_heap.py`` measures the
    gain.

    Examples
    --------
    >>> pad_heap({"ROBOKIT_HEAP_PAD_MB": "0"})
    0
    """
    env = os.environ if environ is None else environ
    if not isinstance(env, Mapping):
        raise TypeError(f"environ: expected a mapping of environment variables, got {type(env).__name__}")
    megabytes = _whole_number(env, "ROBOKIT_HEAP_PAD_MB", 0, 1024, "a whole number of megabytes")
    megabytes = HEAP_PAD_MB if megabytes is None else megabytes
    users_own = any(k.startswith("MALLOC_") and k.endswith("_") for k in env) or \
        "glibc.malloc." in str(env.get("GLIBC_TUNABLES", ""))
    if megabytes == 0 or users_own or not sys.platform.startswith("linux"):
        return 0
    try:
        import ctypes
        mallopt = ctypes.CDLL(None).mallopt
    except (ImportError, OSError, AttributeError):      # no ctypes, or not glibc (musl has no mallopt)
        return 0
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    if mallopt(_M_MMAP_THRESHOLD, HEAP_ARRAY_LIMIT) != 1:
        return 0
    return megabytes << 20 if mallopt(_M_TOP_PAD, megabytes << 20) == 1 else 0


def lazy_module(name: str) -> types.ModuleType:
    """The module ``name``, registered now and executed on its first attribute access.

    Parameters
    ----------
    name : str
        An importable module's full name (e.g. ``"control"``).

    Returns
    -------
    module
        The module already imported, if it is; otherwise a module that :mod:`importlib`'s
        ``LazyLoader`` executes when an attribute is first read. Later ``import name`` statements
        get the same module, so a package that imports it at its top pays nothing until it is used.

    Raises
    ------
    TypeError
        For a ``name`` that is not a string.
    ModuleNotFoundError
        For a module that is not installed.

    Notes
    -----
    Not from a paper: python-control (and scipy.signal and scipy.stats under it) take about 0.75 s
    to import, which every notebook, grading worker and test process paid for robokit's
    controllers whether it designed a loop or not.

    Examples
    --------
    >>> lazy_module("json").dumps([1])
    '[1]'
    """
    if not isinstance(name, str):
        raise TypeError(f"name: expected a module name, got {type(name).__name__}")
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.find_spec(name)
    if spec is None or spec.loader is None:
        raise ModuleNotFoundError(f"name: expected an importable module, got {name!r}", name=name)
    spec.loader = importlib.util.LazyLoader(spec.loader)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module
