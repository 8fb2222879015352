"""Input validation shared by every public robokit function.

Each helper raises a ``ValueError`` or ``TypeError`` whose message names the argument, says what
was expected and shows what came, as DESIGN.md asks ("Errors"). Topic modules call these at their
boundary instead of writing their own checks.
"""
from __future__ import annotations

import numbers
from typing import Any, Sequence

import numpy as np

__all__ = [
    "as_array",
    "as_points",
    "check_finite_scalar",
    "check_positive",
    "check_int",
    "check_choice",
    "as_rng",
    "describe",
]


def describe(value: Any) -> str:
    """Return a short description of ``value`` for error messages (type, shape, dtype)."""
    if isinstance(value, np.ndarray):
        return f"array of shape {value.shape} and dtype {value.dtype}"
    if isinstance(value, (list, tuple)):
        return f"{type(value).__name__} of length {len(value)}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def as_array(
    value: Any,
    name: str,
    *,
    shape: Sequence[int | None] | None = None,
    ndim: int | None = None,
    dtype: Any = float,
    finite: bool = True,
    min_size: int = 0,
) -> np.ndarray:
    """Convert ``value`` to a numpy array and check its shape and values.

    Parameters
    ----------
    value : array_like
        The input.
    name : str
        Argument name used in error messages.
    shape : sequence of int or None, optional
        Required shape; ``None`` entries match any length.
    ndim : int, optional
        Required number of dimensions (ignored when ``shape`` is given).
    dtype : numpy dtype, default float
        Target dtype; ``None`` keeps the input dtype.
    finite : bool, default True
        Reject NaN and infinities (only for inexact dtypes).
    min_size : int, default 0
        Minimum number of elements.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    TypeError
        If the value cannot be converted to ``dtype``.
    ValueError
        If the shape, size or finiteness is wrong.
    """
    try:
        arr = np.asarray(value, dtype=dtype)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected an array of {np.dtype(dtype).name if dtype else 'numbers'}, "
                        f"got {describe(value)}") from None
    if arr.dtype == object:
        raise TypeError(f"{name}: expected a numeric array, got {describe(value)}")
    if shape is not None:
        ok = arr.ndim == len(shape) and all(s is None or s == a for s, a in zip(shape, arr.shape))
        if not ok:
            want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
            raise ValueError(f"{name}: expected shape {want}, got shape {arr.shape}")
    elif ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name}: expected a {ndim}-D array, got {arr.ndim}-D with shape {arr.shape}")
    if arr.size < min_size:
        raise ValueError(f"{name}: expected at least {min_size} elements, got {arr.size}")
    if finite and np.issubdtype(arr.dtype, np.inexact) and not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected finite values, got NaN or infinity")
    return arr


def as_points(value: Any, name: str, dim: int, *, min_count: int = 0) -> np.ndarray:
    """Return ``value`` as a finite float array of shape ``(N, dim)``.

    A single point of shape ``(dim,)`` is accepted and returned as ``(1, dim)``.

    Raises
    ------
    ValueError
        If the array does not have ``dim`` columns or has fewer than ``min_count`` rows.
    """
    arr = as_array(value, name)
    if arr.ndim == 1 and arr.shape[0] == dim:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != dim:
        raise ValueError(f"{name}: expected shape (N, {dim}), got shape {arr.shape}")
    if arr.shape[0] < min_count:
        raise ValueError(f"{name}: expected at least {min_count} points, got {arr.shape[0]}")
    return arr


def check_finite_scalar(value: Any, name: str) -> float:
    """Return ``value`` as a finite float.

    Raises
    ------
    TypeError
        If it is not a real number (booleans are rejected).
    ValueError
        If it is NaN or infinite.
    """
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        if not (isinstance(value, np.ndarray) and value.ndim == 0):
            raise TypeError(f"{name}: expected a real number, got {describe(value)}")
    out = float(value)
    if not np.isfinite(out):
        raise ValueError(f"{name}: expected a finite number, got {out}")
    return out


def check_positive(value: Any, name: str, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a finite float that is > 0 (or >= 0 with ``allow_zero``).

    Raises
    ------
    ValueError
        If the number is not positive.
    """
    out = check_finite_scalar(value, name)
    if out < 0 or (out == 0 and not allow_zero):
        raise ValueError(f"{name}: expected a {'non-negative' if allow_zero else 'positive'} number, got {out}")
    return out


def check_int(value: Any, name: str, *, minimum: int | None = None, maximum: int | None = None) -> int:
    """Return ``value`` as an int within ``[minimum, maximum]``.

    Raises
    ------
    TypeError
        If it is not an integer (booleans and floats are rejected).
    ValueError
        If it is out of range.
    """
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)):
        raise TypeError(f"{name}: expected an integer, got {describe(value)}")
    out = int(value)
    if minimum is not None and out < minimum:
        raise ValueError(f"{name}: expected an integer >= {minimum}, got {out}")
    if maximum is not None and out > maximum:
        raise ValueError(f"{name}: expected an integer <= {maximum}, got {out}")
    return out


def check_choice(value: Any, name: str, choices: Sequence[Any]) -> Any:
    """Return ``value`` if it is one of ``choices``.

    Raises
    ------
    ValueError
        Otherwise, listing the choices.
    """
    if value not in choices:
        raise ValueError(f"{name}: expected one of {list(choices)}, got {value!r}")
    return value


def as_rng(rng: Any = None, name: str = "rng") -> np.random.Generator:
    """Return a ``numpy.random.Generator`` from a Generator, an integer seed or ``None``.

    ``None`` gives a fixed default seed (0) so that results stay reproducible; DESIGN.md asks that
    no function uses global random state.

    Raises
    ------
    TypeError
        For anything else (e.g. the legacy ``RandomState``).
    """
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None:
        return np.random.default_rng(0)
    if isinstance(rng, (numbers.Integral, np.integer)) and not isinstance(rng, bool) and int(rng) >= 0:
        return np.random.default_rng(int(rng))
    raise TypeError(f"{name}: expected a numpy Generator or a non-negative integer seed, got {describe(rng)}")
