"""Moving plain data between the grader and its worker: JSON plus an ``.npz`` of arrays.

Arrays are stored in the ``.npz`` (read with ``allow_pickle=False``) and referenced from the JSON
by name, so nothing crosses the boundary but numbers, strings and arrays; the reader enforces size
and nesting limits, because the worker's files are written by untrusted code.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..exercises.plain import NotPlainData, to_plain

__all__ = ["write_plain", "read_plain", "was_written", "TransportError"]

MAX_JSON_BYTES = 20_000_000
MAX_NPZ_BYTES = 200_000_000
_ARRAY_KEY = "__robokit_array__"


class TransportError(ValueError):
    """A transport file is missing, too large or malformed."""


def _encode(value: Any, arrays: dict[str, np.ndarray]) -> Any:
    if isinstance(value, np.ndarray):
        name = f"a{len(arrays)}"
        arrays[name] = value
        return {_ARRAY_KEY: name}
    if isinstance(value, list):
        return [_encode(v, arrays) for v in value]
    if isinstance(value, dict):
        if _ARRAY_KEY in value:
            raise NotPlainData(f"dict key {_ARRAY_KEY!r} is reserved")
        return {k: _encode(v, arrays) for k, v in value.items()}
    if isinstance(value, float) and not math.isfinite(value):
        return {"__robokit_float__": repr(value)}
    return value


def write_plain(value: Any, stem: str | Path) -> None:
    """Write plain data to ``stem.json`` (+ ``stem.npz`` when it holds arrays)."""
    stem = Path(stem)
    arrays: dict[str, np.ndarray] = {}
    doc = _encode(to_plain(value), arrays)
    if arrays:
        np.savez(stem.with_suffix(".npz"), **arrays)
    stem.with_suffix(".json").write_text(json.dumps(doc, allow_nan=False))


def was_written(stem: str | Path) -> bool:
    """Whether :func:`write_plain` wrote ``stem`` (its JSON, which it writes last, exists)."""
    return Path(stem).with_suffix(".json").exists()


def _decode(value: Any, arrays: Any, depth: int = 0) -> Any:
    if depth > 40:
        raise TransportError("data nested too deeply")
    if isinstance(value, dict):
        if set(value) == {_ARRAY_KEY}:
            name = value[_ARRAY_KEY]
            if arrays is None or not isinstance(name, str) or name not in arrays.files:
                raise TransportError(f"array {name!r} is missing")
            return to_plain(arrays[name])
        if set(value) == {"__robokit_float__"}:
            text = value["__robokit_float__"]
            if text not in ("nan", "inf", "-inf"):
                raise TransportError("malformed special float")
            return float(text)
        return {str(k): _decode(v, arrays, depth + 1) for k, v in value.items()}
    if isinstance(value, list):
        return [_decode(v, arrays, depth + 1) for v in value]
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    raise TransportError(f"unexpected JSON value of type {type(value).__name__}")


def read_plain(stem: str | Path) -> Any:
    """Read plain data written by :func:`write_plain`; raise :class:`TransportError` if unsafe."""
    stem = Path(stem)
    js, npz = stem.with_suffix(".json"), stem.with_suffix(".npz")
    try:
        if js.stat().st_size > MAX_JSON_BYTES:
            raise TransportError(f"{js.name} is larger than {MAX_JSON_BYTES} bytes")
        doc = json.loads(js.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise TransportError(f"{js.name} is missing") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise TransportError(f"{js.name} is unreadable ({type(exc).__name__})") from None
    arrays = None
    if npz.exists():
        if npz.stat().st_size > MAX_NPZ_BYTES:
            raise TransportError(f"{npz.name} is larger than {MAX_NPZ_BYTES} bytes")
        try:
            arrays = np.load(npz, allow_pickle=False)
        except Exception as exc:  # malformed archive written by untrusted code
            raise TransportError(f"{npz.name} is unreadable ({type(exc).__name__})") from None
    try:
        return _decode(doc, arrays)
    except NotPlainData as exc:
        raise TransportError(str(exc)) from None
    except ValueError as exc:  # e.g. pickled object arrays refused by allow_pickle=False
        raise TransportError(f"unsafe array data ({exc})") from None
    finally:
        if arrays is not None:
            arrays.close()
