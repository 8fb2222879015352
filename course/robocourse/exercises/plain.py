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

__all__ = ["to_plain", "NotPlainData", "summarize", "numeric_array", "count_values", "MAX_ANSWER_VALUES"]

_MAX_DEPTH = 20
_MAX_ITEMS = 1_000_000
#: The most numbers (or other leaves) an answer may hold: 190 times the largest expected answer
#: of any exercise (01.hough_votes, 5,184); a larger one is judged wrong before it is compared.
MAX_ANSWER_VALUES = 1_000_000


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

    The list's structure and the type of every item are checked before numpy sees it, so that a
    list of a million numbers ending in a long string costs a walk over the list, never an array of
    strings (numpy would widen every number to that string's length). A list of more than
    :data:`MAX_ANSWER_VALUES` numbers is not an array either.

    Examples
    --------
    >>> numeric_array([[1, 2], [3, 4]]).shape, numeric_array(["a"]), numeric_array([1, [2]])
    ((2, 2), None, None)
    """
    if isinstance(value, np.ndarray):
        return value if value.dtype.kind in "biuf" else None
    if not isinstance(value, list) or _rectangular_numbers(value) is None:
        return None
    arr = np.asarray(value)
    return arr if arr.dtype.kind in "biuf" else None     # e.g. an int beyond 64 bits is not numeric


def _rectangular_numbers(value: list) -> tuple[int, ...] | None:
    """The shape of a nested list whose items are all ``int``, ``float`` or ``bool`` (exact types)
    at one depth, with equal lengths at each depth and at most ``MAX_ANSWER_VALUES`` of them;
    ``None`` for any other list. One pass, level by level, without recursion."""
    shape: list[int] = []
    level: list = [value]
    while level and type(level[0]) is list:
        if len(shape) == 32:                  # numpy's own limit is 64 dimensions; no answer has 32
            return None
        n = len(level[0])
        if any(type(x) is not list or len(x) != n for x in level):
            return None
        shape.append(n)
        if len(level) * n > MAX_ANSWER_VALUES:
            return None
        level = [y for x in level for y in x]
    if any(type(x) not in (int, float, bool) for x in level):
        return None
    return tuple(shape)


def count_values(value: Any, limit: int = MAX_ANSWER_VALUES) -> int:
    """How many numbers, strings and other leaves ``value`` holds (arrays count their elements),
    counting no further than ``limit + 1``: the size of an answer, known before it is compared.

    Examples
    --------
    >>> count_values([1.0, [2, 3], {"a": np.zeros((2, 3))}]), count_values(list(range(50)), limit=10)
    (9, 11)
    """
    total, stack = 0, [value]
    while stack and total <= limit:
        item = stack.pop()
        if isinstance(item, np.ndarray):
            total += item.size
        elif isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, dict):
            stack.extend(item.values())
        else:
            total += 1
    return total
