"""Comparisons between a reference output and a student's (both already plain data).

A comparison is a callable ``compare(expected, got) -> str | None``: ``None`` means the answer is
accepted, a string says why not. Build them with :func:`close`, :func:`exact` and
:func:`unordered_rows`; they are plain functions of plain data, so a student's return value can
never influence them beyond its numbers.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from .plain import summarize

__all__ = ["Comparison", "close", "exact", "unordered_rows"]

Comparison = Callable[[Any, Any], "str | None"]


def _numeric(x: Any) -> np.ndarray | None:
    if isinstance(x, bool):
        return None
    if isinstance(x, (int, float)):
        return np.asarray(float(x))
    if isinstance(x, np.ndarray) and x.dtype.kind in "iuf":
        return x.astype(float)
    if isinstance(x, list):
        try:
            arr = np.asarray(x, dtype=float)
        except (TypeError, ValueError):
            return None
        return arr
    return None


def close(rtol: float = 1e-6, atol: float = 1e-9, *, shape: bool = True) -> Comparison:
    """Accept numbers/arrays equal within ``|got - expected| <= atol + rtol * |expected|``.

    Nested lists and dicts are compared element by element with the same tolerance; strings,
    booleans and ``None`` must be equal. With ``shape=True`` array shapes must match exactly.

    Examples
    --------
    >>> close(rtol=0, atol=1e-9)([1.0, 2.0], [1.0, 2.1])
    'result: values differ at index (1,): expected 2, got 2.1 (tolerance 1e-09 + 0*|expected|)'
    """

    def compare(expected: Any, got: Any, where: str = "") -> str | None:
        if isinstance(expected, dict):
            if not isinstance(got, dict):
                return f"{where or 'result'}: expected a dict, got {summarize(got)}"
            missing = sorted(set(expected) - set(got))
            if missing:
                return f"{where or 'result'}: missing keys {missing}"
            for k in expected:
                msg = compare(expected[k], got[k], f"{where}[{k!r}]")
                if msg:
                    return msg
            return None
        e = _numeric(expected)
        if e is not None:
            g = _numeric(got)
            if g is None:
                return f"{where or 'result'}: expected a number/array like {summarize(expected)}, got {summarize(got)}"
            if shape and e.shape != g.shape:
                return f"{where or 'result'}: expected shape {e.shape}, got shape {g.shape}"
            try:
                ok = np.isclose(g, e, rtol=rtol, atol=atol, equal_nan=False)
            except ValueError:
                return f"{where or 'result'}: shapes {e.shape} and {g.shape} do not match"
            if not np.all(ok):
                bad = np.argwhere(~np.atleast_1d(ok))[0]
                ge, gg = np.atleast_1d(e)[tuple(bad)], np.atleast_1d(g)[tuple(bad)]
                at = "" if e.ndim == 0 else f" at index {tuple(int(i) for i in bad)}"
                return (f"{where or 'result'}: values differ{at}: expected {ge:.6g}, got {gg:.6g} "
                        f"(tolerance {atol:g} + {rtol:g}*|expected|)")
            return None
        if isinstance(expected, list):
            if not isinstance(got, list) or len(got) != len(expected):
                return f"{where or 'result'}: expected a list of length {len(expected)}, got {summarize(got)}"
            for i, (a, b) in enumerate(zip(expected, got)):
                msg = compare(a, b, f"{where}[{i}]")
                if msg:
                    return msg
            return None
        if type(expected) is not type(got) or expected != got:
            return f"{where or 'result'}: expected {summarize(expected)}, got {summarize(got)}"
        return None

    return lambda expected, got: compare(expected, got)


def exact() -> Comparison:
    """Accept only an identical value (strings, integers, booleans, lists of them).

    Examples
    --------
    >>> exact()("2A", "2a")
    "expected '2A', got '2a'"
    """

    def compare(expected: Any, got: Any) -> str | None:
        if isinstance(expected, np.ndarray):
            if not isinstance(got, np.ndarray) or got.shape != expected.shape or not np.array_equal(got, expected):
                return f"expected {summarize(expected)}, got {summarize(got)}"
            return None
        if type(expected) is not type(got) or expected != got:
            return f"expected {summarize(expected)}, got {summarize(got)}"
        return None

    return compare


def unordered_rows(rtol: float = 1e-6, atol: float = 1e-9) -> Comparison:
    """Accept an (N, k) array whose rows equal the expected rows in any order (within tolerance).

    Examples
    --------
    >>> rows = [[0.0, 1.0], [2.0, 3.0]]
    >>> unordered_rows()(rows, rows[::-1]) is None
    True
    """
    inner = close(rtol, atol)

    def compare(expected: Any, got: Any) -> str | None:
        e, g = _numeric(expected), _numeric(got)
        if g is None or e is None or e.ndim != 2 or g.shape != e.shape:
            return f"expected an array of shape {None if e is None else e.shape}, got {summarize(got)}"
        order_e = np.lexsort(np.round(e, 6).T[::-1])
        order_g = np.lexsort(np.round(g, 6).T[::-1])
        return inner(e[order_e], g[order_g])

    return compare
