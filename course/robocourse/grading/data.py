"""The data an assignment's notebook works on: plain data shipped with robocourse, one JSON file each.

A lesson whose assignment needs data (the model's constants, force traces, MoCap frames, a scan
and its map) defines ``assignment_data()`` in its ``exercises`` module; ``robocourse assign``
writes what it returns to ``robocourse/data/<slug>.json`` beside the generated notebook, and a
notebook reads it back with :func:`assignment_data`. So the student's functions run on data the
lesson made, in JupyterLab and in the grading worker alike: this module imports nothing of
robokit, and the worker's kit carries the file. The data are numbers, strings, lists and dicts
(arrays as nested lists), never a model or a function that could answer an exercise.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

__all__ = ["assignment_data", "data_file", "encode_data", "MAX_DATA_BYTES"]

#: The largest data file :func:`assignment_data` reads.
MAX_DATA_BYTES = 20_000_000
_SLUG = re.compile(r"^\d\d_[a-z][a-z0-9_]*$")


def data_file(slug: str) -> Path:
    """Where the data of assignment ``slug`` lives (it may not exist)."""
    if not isinstance(slug, str) or not _SLUG.match(slug):
        raise ValueError(f"slug: expected an assignment name like '04_littledog', got {slug!r}")
    return Path(__file__).resolve().parents[1] / "data" / f"{slug}.json"


def _no_nan(value: Any) -> None:
    if isinstance(value, float) and math.isnan(value):
        raise ValueError("data: NaN has no place in assignment data (use inf for a LiDAR's no-return)")
    for item in (value.values() if isinstance(value, dict) else value if isinstance(value, list) else ()):
        _no_nan(item)


def encode_data(data: Any) -> str:
    """The file's text for ``data``: JSON in the dicts' own order, exact floats, ``Infinity`` for inf.

    Deterministic for deterministic ``data``; the order is kept so that a notebook prints the data
    as the lesson made them.

    Raises
    ------
    ValueError
        For NaN anywhere in ``data``.
    TypeError
        For anything JSON cannot hold (arrays must be given as lists).
    """
    _no_nan(data)
    return json.dumps(data, separators=(",", ":")) + "\n"


def _no_nan_token(name: str) -> Any:
    if name == "NaN":
        raise ValueError("assignment data hold NaN, which they never should")
    return float(name.replace("Infinity", "inf"))


def assignment_data(slug: str) -> dict:
    """Return the data of assignment ``slug`` (e.g. ``"04_littledog"``).

    Parameters
    ----------
    slug : str
        The assignment's notebook name without ``.ipynb``.

    Returns
    -------
    dict
        What the lesson's ``assignment_data()`` returned when ``robocourse assign`` last ran:
        numbers, strings, lists (arrays become nested lists: ``np.asarray`` them) and dicts.

    Raises
    ------
    ValueError
        For a malformed slug or an assignment without data, or a file larger than
        :data:`MAX_DATA_BYTES` or not a JSON object.

    Notes
    -----
    Grading design (DESIGN.md, "Grading"); not from a paper.

    Examples
    --------
    >>> facts = assignment_data("04_littledog")["model_facts"]
    >>> facts["LEGS"], facts["UPPER_LEG"]
    (['FL', 'FR', 'HL', 'HR'], 0.0751)
    """
    path = data_file(slug)
    if not path.is_file():
        have = sorted(f.stem for f in path.parent.glob("*.json"))
        raise ValueError(f"slug: expected an assignment with data ({', '.join(have) or 'none'}), got {slug!r}")
    with open(path, "rb") as f:
        raw = f.read(MAX_DATA_BYTES + 1)
    if len(raw) > MAX_DATA_BYTES:
        raise ValueError(f"{path.name}: larger than {MAX_DATA_BYTES} bytes")
    data = json.loads(raw.decode("utf-8"), parse_constant=_no_nan_token)
    if not isinstance(data, dict):
        raise ValueError(f"{path.name}: expected a JSON object, got {type(data).__name__}")
    return data
