"""Comparisons between an expected output and a student's (both already plain data).

A comparison is a callable ``compare(expected, got) -> str | None``: ``None`` means the answer is
accepted, a string says why not. Build them with :func:`close`, :func:`exact` and
:func:`unordered_rows`; they are plain functions of plain data, so a student's return value can
never influence them beyond its numbers.

Containers: where an exercise asks for an array, a (nested) list with the same shape and values is
the same answer, and the other way round, in every comparison; an answer is judged by its numbers,
and a mismatch names how many values differ and the worst of them.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from robocourse.exercises.plain import numeric_array, summarize

__all__ = ["Comparison", "close", "exact", "unordered_rows"]

Comparison = Callable[[Any, Any], "str | None"]


def _numeric(x: Any) -> np.ndarray | None:
    """A number, or an array/list of numbers (not booleans, not strings), as a float array."""
    if type(x) in (int, float):
        return np.asarray(float(x))
    arr = numeric_array(x)
    return None if arr is None or arr.dtype.kind == "b" else arr.astype(float)


def close(rtol: float = 1e-6, atol: float = 1e-9, *, shape: bool = True) -> Comparison:
    """Accept numbers/arrays equal within ``|got - expected| <= atol + rtol * |expected|``.

    Nested lists and dicts are compared element by element with the same tolerance; strings,
    booleans and ``None`` must be equal. With ``shape=True`` array shapes must match exactly.

    Examples
    --------
    >>> close(rtol=0, atol=1e-9)([1.0, 2.0], [1.0, 2.1])
    'result: 1 of 2 values differ (tolerance 1e-09 + 0*|expected|); at index (1,): expected 2, got 2.1'

    A list is as good as an array with the same shape and values (and an array as a list): the
    comparison judges the numbers, not the container.
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
            if e.size == 0 and g.size == 0:          # "nothing" as [], an empty array or shape (0, k)
                return None
            if shape and e.shape != g.shape:
                return f"{where or 'result'}: expected shape {e.shape}, got shape {g.shape}"
            try:
                ok = np.isclose(g, e, rtol=rtol, atol=atol, equal_nan=False)
            except ValueError:
                return f"{where or 'result'}: shapes {e.shape} and {g.shape} do not match"
            if not np.all(ok):
                return f"{where or 'result'}: " + _worst_differences(e, g, ok, rtol, atol)
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


def _worst_differences(e: np.ndarray, g: np.ndarray, ok: np.ndarray, rtol: float, atol: float,
                       show: int = 3) -> str:
    """Say how many of the values in ``g`` miss ``e`` and which are the worst (by how far past the
    tolerance), e.g. ``"3 of 12 values differ (tolerance ...); worst at index (2,): ..."``."""
    if e.ndim == 0:
        return f"expected {float(e):.6g}, got {float(g):.6g} (tolerance {atol:g} + {rtol:g}*|expected|)"
    excess = np.abs(g - e) - (atol + rtol * np.abs(e))
    excess = np.where(np.isnan(excess), np.inf, excess)          # a NaN is the worst miss of all
    bad = np.argwhere(~ok)
    worst = bad[np.argsort(-excess[tuple(bad.T)], kind="stable")[:show]]
    where = "; ".join(f"at index {tuple(int(i) for i in idx)}: expected {e[tuple(idx)]:.6g}, "
                      f"got {g[tuple(idx)]:.6g}" for idx in worst)
    head = "worst " if len(bad) > 1 else ""
    return (f"{len(bad)} of {e.size} values differ (tolerance {atol:g} + {rtol:g}*|expected|); "
            f"{head}{where}")


def exact() -> Comparison:
    """Accept only the same value: equal strings and booleans, equal numbers, equal arrays or lists.

    Numbers are judged by value (``17.0`` is ``17``, as in :func:`close`), but a boolean is not a
    number and a string is not either; an array and a list with the same shape and values are the
    same answer, and every empty answer is the same.

    Examples
    --------
    >>> exact()("2A", "2a")
    "expected '2A', got '2a'"
    >>> exact()(np.array([2, 0, 1]), [2, 0, 1]) is None, exact()(17, 17.0) is None
    (True, True)
    >>> exact()(17, "17")
    "expected the integer 17, got the string '17'"
    """

    def compare(expected: Any, got: Any) -> str | None:
        if isinstance(expected, (np.ndarray, list)) or isinstance(got, (np.ndarray, list)):
            e, g = numeric_array(expected), numeric_array(got)
            if e is not None and g is not None:
                return _exact_arrays(e, g)
        elif _is_number(expected) and _is_number(got):
            return None if expected == got else f"expected {summarize(expected)}, got {summarize(got)}"
        if type(expected) is not type(got):
            return f"expected {_kind(expected)} {summarize(expected)}, got {_kind(got)} {summarize(got)}"
        if expected != got:
            return f"expected {summarize(expected)}, got {summarize(got)}"
        return None

    return compare


def _is_number(x: Any) -> bool:
    return type(x) in (int, float)


def _kind(x: Any) -> str:
    """``'the integer'``, ``'the string'``, ... for a feedback message."""
    names = {bool: "the boolean", int: "the integer", float: "the float", str: "the string",
             list: "the list", dict: "the dict", np.ndarray: "the array"}
    return names.get(type(x), "the value")


def _exact_arrays(e: np.ndarray, g: np.ndarray) -> str | None:
    """Exact comparison of two numeric/boolean arrays (numbers by value, booleans apart)."""
    if e.size == 0 and g.size == 0:
        return None
    if g.shape != e.shape:
        return f"expected shape {e.shape}, got shape {g.shape}: {summarize(g)}"
    if (e.dtype.kind == "b") != (g.dtype.kind == "b"):
        want, have = ("booleans" if a.dtype.kind == "b" else "numbers" for a in (e, g))
        return f"expected {want}, got {have}: {summarize(g)}"
    bad = np.argwhere(g != e)
    if len(bad):
        idx = tuple(int(i) for i in bad[0])
        return (f"{len(bad)} of {e.size} values differ; first at index {idx}: expected "
                f"{e[idx].item()!r}, got {g[idx].item()!r}")
    return None


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
        if e is not None and g is not None and e.size == 0 and g.size == 0:
            return None
        if g is None or e is None or e.ndim != 2 or g.shape != e.shape:
            return f"expected an array of shape {None if e is None else e.shape}, got {summarize(got)}"
        order_e = np.lexsort(np.round(e, 6).T[::-1])
        order_g = np.lexsort(np.round(g, 6).T[::-1])
        msg = inner(e[order_e], g[order_g])
        return None if msg is None else "rows sorted by value (their order is free): " + msg.split(": ", 1)[1]

    return compare
