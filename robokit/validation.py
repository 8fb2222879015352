"""Input validation shared by every public robokit function.

Each helper raises a ``ValueError`` or ``TypeError`` whose message names the argument, says what
was expected and shows what came, as DESIGN.md asks ("Errors"). Topic modules call these at their
boundary instead of writing their own checks.

What counts as a number (the same rule for arrays and scalars): integers and real floats, and
Python objects that are ``numbers.Real`` (``Fraction``, a big ``int``). Refused with a
``TypeError`` naming the argument:

* strings and bytes, even numeric ones (``"1.0"``): numpy would convert them silently;
* complex values, even with a zero imaginary part: numpy would drop the imaginary part;
* booleans where numbers are expected (``True``, a boolean mask): a mask passed for coordinates or
  weights is almost always a mistake, and ``mask.astype(float)`` says it on purpose. An argument
  that is a mask asks for ``dtype=bool`` and gets booleans (or 0/1 integers);
* ragged nested lists, ``None`` and other objects.

Where integers are expected, floats are accepted only when they are whole (``2.0``, not ``2.5``).

Angles (headings, beam and joint angles) are refused beyond ``MAX_ANGLE`` radians
(:func:`require_angles`): a larger finite one is a unit mistake, and from about 1e15 rad on float64
no longer resolves a turn, so every sine, cosine and wrap of it would be an arbitrary number.
"""
from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from typing import Any, Sequence

import numpy as np

__all__ = ["as_array", "array_ndim", "broadcast_to", "as_points", "as_finite_scalar", "as_positive", "as_int",
           "as_choice", "as_text", "as_callable", "as_mapping", "require_finite_result", "require_sample_count",
           "MAX_SAMPLES", "as_rng", "describe", "as_covariance", "MAX_ANGLE", "require_angles"]


def describe(value: Any) -> str:
    """Return a short description of ``value`` for error messages (type, shape, dtype)."""
    if isinstance(value, np.ndarray):
        return f"array of shape {value.shape} and dtype {value.dtype}"
    if isinstance(value, (list, tuple)):
        return f"{type(value).__name__} of length {len(value)}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _what(kind: str) -> str:
    return {"b": "booleans", "i": "integers", "u": "integers", "c": "complex numbers"}.get(kind, "real numbers")


def _refuse(value: Any, raw: np.ndarray, name: str, want: str) -> None:
    kind = raw.dtype.kind
    got = {"U": "a string", "S": "bytes", "b": "booleans", "c": "complex numbers"}.get(kind, "a non-number")
    hint = "; convert a mask on purpose, e.g. mask.astype(float)" if kind == "b" else ""
    if kind == "O":
        bad = next((x for x in raw.flat if not _is_number(x)), None)
        got = f"an element {describe(bad)}"
    raise TypeError(f"{name}: expected {want}, got {got} ({describe(value)}){hint}")


def _is_number(x: Any) -> bool:
    return isinstance(x, (numbers.Real, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))


def _whole(raw: np.ndarray, name: str) -> None:
    ok = np.isfinite(raw) & (raw == np.round(raw)) & (np.abs(raw) < 2.0 ** 63)
    if not np.all(ok):
        raise ValueError(f"{name}: expected whole numbers, got {float(raw[~ok].flat[0])!r}")


def _convert(value: Any, name: str, target: np.dtype | None) -> np.ndarray:
    """``value`` as an array of ``target`` (``None``: its own numeric dtype), refusing what is not
    a number of that kind (see the module docstring)."""
    if type(value) is np.ndarray:     # a subclass (matrix, masked array) becomes a plain array, as before
        raw = value
    else:
        try:
            raw = np.asarray(value)
        except (TypeError, ValueError):
            raise TypeError(f"{name}: expected an array of {_what(target.kind) if target else 'numbers'} "
                            f"(nested lists of equal length), got {describe(value)}") from None
    kind = raw.dtype.kind
    want = "f" if target is None else target.kind
    if kind == want and target is not None:
        return raw if raw.dtype == target else raw.astype(target)
    if kind == "O":
        if not all(_is_number(x) for x in raw.flat):
            _refuse(value, raw, name, _what(want))
        raw = raw.astype(complex if want == "c" else float)
        kind = raw.dtype.kind
    if want == "b":          # a mask: booleans, or integers that are 0 or 1
        if kind in "iu" and np.all((raw == 0) | (raw == 1)):
            return raw.astype(bool)
        if kind != "b":
            _refuse(value, raw, name, "booleans")
        return raw
    if kind not in ("iuf" if want in "fiu" else "iufc"):
        _refuse(value, raw, name, _what(want))
    if want in "iu" and kind == "f":
        _whole(raw, name)
    if target is None:
        return raw
    try:
        return raw.astype(target, copy=False)
    except OverflowError:
        raise ValueError(f"{name}: expected {_what(want)} that fit {target.name}, got {describe(value)}") from None


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
        The input: numbers, nested lists of numbers or an array (what counts as a number: see the
        module docstring).
    name : str
        Argument name used in error messages.
    shape : sequence of int or None, optional
        Required shape; ``None`` entries match any length.
    ndim : int, optional
        Required number of dimensions (ignored when ``shape`` is given).
    dtype : numpy dtype, default float
        Target dtype; ``None`` keeps the input's numeric dtype (integer, float or boolean).
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
        If the value is not numbers of ``dtype``'s kind: strings (numeric or not), complex values,
        booleans (unless ``dtype`` is bool), ragged lists, ``None`` or other objects.
    ValueError
        If the shape, size or finiteness is wrong, or an integer dtype gets a fraction.

    Examples
    --------
    >>> as_array([1, 2.5], "x")
    array([1. , 2.5])
    >>> as_array("1.0", "x")
    Traceback (most recent call last):
    ...
    TypeError: x: expected real numbers, got a string ('1.0')
    >>> as_array(np.array([1 + 2j]), "x")
    Traceback (most recent call last):
    ...
    TypeError: x: expected real numbers, got complex numbers (array of shape (1,) and dtype complex128)
    """
    arr = _convert(value, name, None if dtype is None else np.dtype(dtype))
    if shape is not None:
        ok = arr.ndim == len(shape) and all(s is None or s == a for s, a in zip(shape, arr.shape))
        if not ok:
            want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
            raise ValueError(f"{name}: expected shape {want}, got shape {arr.shape}")
    elif ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name}: expected a {ndim}-D array, got {arr.ndim}-D with shape {arr.shape}")
    if arr.size < min_size:
        raise ValueError(f"{name}: expected at least {min_size} elements, got {arr.size}")
    if finite and arr.dtype.kind in "fc" and not np.isfinite(arr).all():   # the method: no wrapper
        raise ValueError(f"{name}: expected finite values, got NaN or infinity")
    return arr


def array_ndim(value: Any, name: str) -> int:
    """Number of dimensions of ``value`` as an array, for choosing between a single and a batch.

    Raises
    ------
    TypeError
        If ``value`` is a ragged nested list (numpy's own error would not name the argument).

    Examples
    --------
    >>> array_ndim([[1, 2], [3, 4]], "q")
    2
    """
    if isinstance(value, np.ndarray):
        return value.ndim
    try:
        return np.ndim(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected an array of numbers (nested lists of equal length), "
                        f"got {describe(value)}") from None


def broadcast_to(value: np.ndarray, shape: tuple[int, ...], name: str, what: str = "") -> np.ndarray:
    """``numpy.broadcast_to`` whose error names the argument.

    Parameters
    ----------
    value : numpy.ndarray
        The (validated) argument.
    shape : tuple of int
        The shape it must broadcast to.
    name : str
        Argument name used in error messages.
    what : str, optional
        What the shape means, for the message (``"one per pose"``).

    Raises
    ------
    ValueError
        If ``value`` does not broadcast to ``shape``.

    Examples
    --------
    >>> broadcast_to(np.array(2.0), (3,), "v").tolist()
    [2.0, 2.0, 2.0]
    """
    try:
        return np.broadcast_to(value, shape)
    except ValueError:
        extra = f" ({what})" if what else ""
        raise ValueError(f"{name}: expected a scalar or shape {tuple(shape)}{extra}, got shape {np.shape(value)}") from None


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


#: Largest angle magnitude (rad) a public function accepts: 160,000 turns, far beyond any unwrapped
#: heading of a lesson's run, where float64 still resolves 1e-10 rad.
MAX_ANGLE = 1e6


def require_angles(angles: np.ndarray, name: str, what: str = "angles") -> None:
    """Refuse angles (rad) beyond ``MAX_ANGLE``: finite, but meaningless once wrapped.

    ``what`` says which values of ``name`` are the angles (``"headings (column 2)"``).

    Raises
    ------
    ValueError
        Naming ``name``, the largest magnitude and the bound.

    Examples
    --------
    >>> require_angles(np.array([0.5, -40.0]), "q")
    >>> require_angles(np.array([1e300]), "pose", "heading (element 2)")
    Traceback (most recent call last):
    ...
    ValueError: pose: expected heading (element 2) in radians within +-1e+06, got 1e+300
    """
    a = np.abs(np.asarray(angles, dtype=float))
    if a.size and not a.max() <= MAX_ANGLE:
        raise ValueError(f"{name}: expected {what} in radians within +-{MAX_ANGLE:g}, got {a.max():.3g}")


def as_finite_scalar(value: Any, name: str) -> float:
    """Return ``value`` as a finite float.

    Raises
    ------
    TypeError
        If it is not a real number: booleans, strings (numeric or not), complex numbers and arrays
        other than a 0-d array of numbers are rejected.
    ValueError
        If it is NaN or infinite.
    """
    if not _is_number(value):
        if not (isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf"):
            raise TypeError(f"{name}: expected a real number, got {describe(value)}")
    out = float(value)
    if not math.isfinite(out):
        raise ValueError(f"{name}: expected a finite number, got {out}")
    return out


def as_positive(value: Any, name: str, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a finite float that is > 0 (or >= 0 with ``allow_zero``).

    Raises
    ------
    ValueError
        If the number is not positive.
    """
    out = as_finite_scalar(value, name)
    if out < 0 or (out == 0 and not allow_zero):
        raise ValueError(f"{name}: expected a {'non-negative' if allow_zero else 'positive'} number, got {out}")
    return out


INT64_MAX = 2 ** 63 - 1


def as_int(value: Any, name: str, *, minimum: int | None = None, maximum: int | None = INT64_MAX) -> int:
    """Return ``value`` as an int within ``[minimum, maximum]``.

    ``maximum`` defaults to the largest int64 (and ``minimum`` is at least the smallest): a count,
    size or index beyond it fits no numpy array, and numpy's own error would not name the argument.

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
    if minimum is not None and out < minimum or out < -INT64_MAX - 1:
        raise ValueError(f"{name}: expected an integer >= {-INT64_MAX - 1 if minimum is None else minimum}, got {out}")
    if maximum is not None and out > maximum:
        raise ValueError(f"{name}: expected an integer <= {maximum}, got {out}")
    return out


def as_choice(value: Any, name: str, choices: Sequence[Any]) -> Any:
    """Return ``value`` if it is one of ``choices`` (of the same type: ``1`` is not ``"1"`` and an
    array is never a choice).

    Raises
    ------
    ValueError
        Otherwise, listing the choices.
    """
    for choice in choices:
        if (isinstance(value, type(choice)) and not isinstance(value, np.ndarray)
                and isinstance(value, bool) == isinstance(choice, bool) and value == choice):
            return value
    raise ValueError(f"{name}: expected one of {list(choices)}, got {describe(value)}")


def as_text(value: Any, name: str, *, empty: bool = True) -> str:
    """Return ``value`` if it is a ``str`` (non-empty unless ``empty``).

    Raises
    ------
    TypeError
        If it is not a string (bytes, numbers and ``None`` are not converted).
    ValueError
        If it is empty and ``empty`` is false.

    Examples
    --------
    >>> as_text("GP", "talker")
    'GP'
    """
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected a str, got {describe(value)}")
    if not empty and not value:
        raise ValueError(f"{name}: expected a non-empty str, got ''")
    return value


def as_callable(value: Any, name: str, *, optional: bool = True) -> Any:
    """Return ``value`` if it is callable (or ``None`` when ``optional``).

    Raises
    ------
    TypeError
        Otherwise: a callback that is not callable would fail later, far from its cause.

    Examples
    --------
    >>> as_callable(print, "progress") is print
    True
    """
    if value is None and optional:
        return None
    if not callable(value):
        raise TypeError(f"{name}: expected a callable{' or None' if optional else ''}, got {describe(value)}")
    return value


def as_mapping(value: Any, name: str, *, optional: bool = True) -> Any:
    """Return ``value`` if it is a mapping (a dict of options; ``None`` when ``optional``).

    Raises
    ------
    TypeError
        Otherwise (a string or a list of pairs is not read as options).

    Examples
    --------
    >>> as_mapping({"n_waypoints": 1}, "course_options")
    {'n_waypoints': 1}
    """
    if value is None and optional:
        return None
    if not isinstance(value, Mapping):
        raise TypeError(f"{name}: expected a dict{' or None' if optional else ''}, got {describe(value)}")
    return value


def require_finite_result(names: str, *results: Any) -> None:
    """Refuse a result that holds NaN or infinity: finite inputs too large for the computation.

    Valid inputs that overflow an intermediate (a square, a determinant, a time step) would
    otherwise return a silent NaN or inf; the error names the inputs the result depends on.

    Raises
    ------
    ValueError
        If any result is not finite.

    Examples
    --------
    >>> require_finite_result("d_se, d_ew", np.array([1.0, 2.0]))
    >>> require_finite_result("J", np.array([np.inf]))
    Traceback (most recent call last):
    ...
    ValueError: J: expected values whose result is finite, got NaN or infinity (an overflow: values too large?)
    """
    for x in results:
        if not np.all(np.isfinite(x)):
            raise ValueError(f"{names}: expected values whose result is finite, got NaN or infinity "
                             "(an overflow: values too large?)")


#: Most samples a simulated signal may hold (80 MB of float64): a bound that no lesson comes near,
#: so that a huge rate or duration is refused before numpy tries to allocate it.
MAX_SAMPLES = 10 ** 7


def require_sample_count(count: float, names: str, maximum: int = MAX_SAMPLES) -> None:
    """Refuse a number of samples (a duration times a rate) above ``maximum``.

    Raises
    ------
    ValueError
        Naming the arguments that set the count.

    Examples
    --------
    >>> require_sample_count(784, "speed, rate")
    >>> require_sample_count(1e300, "rate")
    Traceback (most recent call last):
    ...
    ValueError: rate: expected at most 10000000 samples, got 1e+300
    """
    if not count <= maximum:
        raise ValueError(f"{names}: expected at most {maximum} samples, got {count:.3g}")


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


def as_covariance(value: Any, name: str, n: int, *, semidefinite: bool = False) -> np.ndarray:
    """Return ``value`` as a finite, symmetric, positive-definite ``(n, n)`` covariance matrix.

    Parameters
    ----------
    value : array_like, shape (n, n)
    name : str
        Argument name used in error messages.
    n : int
        Dimension.
    semidefinite : bool, default False
        Accept a positive-semidefinite matrix (a process noise with zero rows, say).

    Returns
    -------
    numpy.ndarray
        The matrix, made exactly symmetric (the mean of it and its transpose).

    Raises
    ------
    ValueError
        For a wrong shape, NaN or infinity, an asymmetry beyond rounding (1e-9 relative), or a
        negative (or, unless ``semidefinite``, zero) eigenvalue beyond rounding.

    Examples
    --------
    >>> as_covariance([[1.0, 0.1], [0.1, 2.0]], "R", 2).tolist()
    [[1.0, 0.1], [0.1, 2.0]]
    >>> as_covariance([[1.0, 2.0], [2.0, 1.0]], "R", 2)
    Traceback (most recent call last):
    ...
    ValueError: R: expected a positive-definite covariance, got an eigenvalue -1
    """
    M = as_array(value, name, shape=(n, n))
    scale = float(np.abs(M).max(initial=0.0))
    if not np.allclose(M, M.T, rtol=0.0, atol=1e-9 * scale):
        raise ValueError(f"{name}: expected a symmetric covariance, got M[i, j] != M[j, i]")
    M = 0.5 * (M + M.T)
    low = float(np.linalg.eigvalsh(M)[0]) if n else 0.0
    if low < -1e-12 * scale or (not semidefinite and low <= 1e-14 * scale):
        kind = "positive-semidefinite" if semidefinite else "positive-definite"
        raise ValueError(f"{name}: expected a {kind} covariance, got an eigenvalue {low:.3g}")
    return M
