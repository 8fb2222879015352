"""Plain data: the only values that cross from student code to the grader.

Student functions may return anything; before anything is compared it is converted here into
plain data (``None``, ``bool``, ``int``, ``float``, ``complex``-free numbers, ``str``, lists,
string-keyed dicts and numeric/bool numpy arrays). Converting *first* means a returned object
whose ``__eq__``, ``__bool__`` or ``__array__`` lies never takes part in a comparison: only its
converted value does, and an object that is not plain data is rejected with a message.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["to_plain", "NotPlainData", "summarize", "numeric_array"]

_MAX_DEPTH = 20
_MAX_ITEMS = 1_000_000


class NotPlainData(TypeError):
    """Raised when a value is not plain data (numbers, strings, lists, dicts, numeric arrays)."""


def to_plain(value: Any, *, _depth: int = 0) -> Any:
    """Return ``value`` converted to plain data, or raise :class:`NotPlainData`.

    Only exact built-in types and numpy scalars/arrays are accepted; subclasses (which could
    override comparison) are rejected. Tuples become lists; numpy scalars become Python numbers;
    numpy arrays are copied into fresh arrays of a standard dtype.

    Raises ``NotPlainData`` for anything else, non-string dict keys, nesting deeper than 20 or a
    list longer than a million items.

    Notes
    -----
    Grader design (DESIGN.md, "Grading"); not from a paper.

    Examples
    --------
    >>> to_plain((np.float32(1.5), [np.int64(2)]))
    [1.5, [2]]
    """
    if _depth > _MAX_DEPTH:
        raise NotPlainData("value is nested too deeply")
    t = type(value)
    if value is None or t in (bool, str):
        return value
    if t is int:
        return value
    if t is float:
        return value
    if t in (list, tuple):
        if len(value) > _MAX_ITEMS:
            raise NotPlainData("list is too long")
        return [to_plain(v, _depth=_depth + 1) for v in value]
    if t is dict:
        out = {}
        for k, v in value.items():
            if type(k) is not str:
                raise NotPlainData(f"dict keys must be strings, got {type(k).__name__}")
            out[k] = to_plain(v, _depth=_depth + 1)
        return out
    if t is np.ndarray:
        if value.dtype.kind == "b":
            return np.array(value, dtype=bool)
        if value.dtype.kind in "iu":
            return np.array(value, dtype=np.int64)
        if value.dtype.kind == "f":
            return np.array(value, dtype=np.float64)
        raise NotPlainData(f"arrays must be numeric or boolean, got dtype {value.dtype}")
    if isinstance(value, np.generic) and t.__module__ == "numpy":
        if value.dtype.kind == "b":
            return bool(value)
        if value.dtype.kind in "iu":
            return int(value)
        if value.dtype.kind == "f":
            return float(value)
    raise NotPlainData(f"expected plain data (numbers, strings, lists, dicts, numpy arrays), "
                       f"got an object of type {t.__module__}.{t.__qualname__}")


def summarize(value: Any, limit: int = 160) -> str:
    """Return a short human-readable summary of a plain value for feedback messages.

    Examples
    --------
    >>> summarize(np.arange(20.0))
    'array(20,) [ 0., 1., ..., 18., 19.]'
    """
    if isinstance(value, np.ndarray):
        with np.printoptions(precision=4, suppress=True, threshold=12, edgeitems=2):
            text = f"array{value.shape} {np.array2string(value, separator=', ')}"
    elif isinstance(value, float):
        text = f"{value:.6g}" if math.isfinite(value) else repr(value)
    else:
        text = repr(value)
    text = " ".join(text.split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def numeric_array(value: Any) -> np.ndarray | None:
    """``value`` as an array if it is a numeric/boolean array or a (nested, rectangular) list of
    numbers or booleans, else ``None``: the one rule by which a list counts as an array.

    Examples
    --------
    >>> numeric_array([[1, 2], [3, 4]]).shape, numeric_array(["a"]), numeric_array([1, [2]])
    ((2, 2), None, None)
    """
    if isinstance(value, np.ndarray):
        return value if value.dtype.kind in "biuf" else None
    if not isinstance(value, list):
        return None
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        return None
    return arr if arr.dtype.kind in "biuf" else None
