"""Occupancy grids as ROS map_server files: a PGM image and a YAML description beside it.

The convention of ROS's ``map_server`` / ``map_saver`` (and nav2's), so a map built here opens in
RViz, GIMP or any image viewer, and a map from a ROS robot loads here::

    image: corridor.pgm          # relative to the YAML file's folder (or absolute)
    mode: trinary
    resolution: 0.05             # metres per pixel
    origin: [-0.2, -1.4, 0.0]    # world x, y, yaw of the lower-left pixel
    negate: 0
    occupied_thresh: 0.65
    free_thresh: 0.196

The image is a binary ("P5") 8-bit PGM whose first row is the TOP of the map (the highest y),
so it is flipped against :class:`OccupancyGrid`, whose row 0 is the lowest y. A pixel value ``v``
reads as ``p = (255 - v) / 255`` (``v / 255`` with ``negate: 1``); ``p > occupied_thresh`` is
occupied, ``p < free_thresh`` free, anything else unknown. ``map_saver`` writes trinary values:
0 occupied, 254 free, 205 unknown. In ``mode: scale`` a pixel between the thresholds keeps its
probability; ``mode: raw`` (values are occupancy percentages) is not supported.

The YAML reader is strict and small (there is no PyYAML in the course environment): one
``key: value`` per line, ``#`` comments, numbers, one ``[x, y, yaw]`` list and plain or quoted
strings; other keys are ignored, as map_server does. Whatever is wrong (a missing or repeated
key, a bad number, a non-zero yaw, a missing image, a PGM that is not 8-bit binary, whose header
is malformed or whose pixel count is short or long) raises :class:`MapFileError` naming the
file and the problem.

References
----------
.. [1] ROS map_server documentation, http://wiki.ros.org/map_server (YAML format, value
   interpretation, map_saver), 2019.
.. [2] J. Poskanzer, "PGM: Netpbm grayscale image format", http://netpbm.sourceforge.net/doc/pgm.html.
.. [3] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from ..files import as_file_path, read_regular, write_atomically
from ..validation import as_choice, as_int, describe
from .occupancy_grid import FREE_THRESHOLD, OCCUPIED_THRESHOLD, OccupancyGrid

__all__ = ["MapFileError", "save_map", "load_map", "OCCUPIED_VALUE", "FREE_VALUE", "UNKNOWN_VALUE",
           "MAX_YAML_BYTES", "MAX_PGM_BYTES"]

#: The largest map description (YAML) and map image (PGM) :func:`load_map` reads, in bytes.
MAX_YAML_BYTES, MAX_PGM_BYTES = 64 * 1024, 256 * 1024**2
#: Characters that make YAML read a plain value differently: such an image name is written quoted.
_YAML_SPECIAL = set("#:[]{},'\"&*!|>%@`?")

#: map_saver's trinary pixel values (negate 0).
OCCUPIED_VALUE, FREE_VALUE, UNKNOWN_VALUE = 0, 254, 205
_REQUIRED = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")
_LINE = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*:\s*(.*)$")


class MapFileError(ValueError):
    """A map_server YAML or PGM file that cannot be read; ``path`` names the file."""

    def __init__(self, path: Any, message: str) -> None:
        super().__init__(f"{path}: {message}")
        self.path = str(path)


def _thresholds(free_thresh: Any, occupied_thresh: Any, fail) -> tuple[float, float]:
    vals = []
    for name, v in (("free_thresh", free_thresh), ("occupied_thresh", occupied_thresh)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0.0 <= v <= 1.0:
            fail(f"{name}: expected a number in [0, 1], got {describe(v)}")
        vals.append(float(v))
    if not vals[0] < vals[1]:
        fail(f"free_thresh: expected below occupied_thresh = {vals[1]}, got {vals[0]}")
    return vals[0], vals[1]


def _value_error(message: str) -> None:
    raise ValueError(message)


def save_map(grid: OccupancyGrid, stem: Any, *, occupied_thresh: float = OCCUPIED_THRESHOLD,
             free_thresh: float = FREE_THRESHOLD, negate: int = 0, mode: str = "trinary") -> tuple[Path, Path]:
    """Write ``grid`` as ``<stem>.pgm`` and ``<stem>.yaml`` in ROS map_server's format.

    Parameters
    ----------
    grid : OccupancyGrid
    stem : str or Path
        Path without suffix; its folder must exist.
    occupied_thresh, free_thresh : float, default 0.65, 0.196
        Written to the YAML and used to classify cells (map_saver's defaults).
    negate : {0, 1}, default 0
        1 writes ``255 - value`` (white = occupied), and says so in the YAML.
    mode : {"trinary", "scale"}, default "trinary"
        ``"trinary"``: 0 / 254 / 205 for occupied / free / unknown (map_saver's output).
        ``"scale"``: occupied 0 and free 254 as well, but an unknown cell keeps its probability,
        ``round(255 (1 - p))`` (205 and 254 excluded, so it reads back as unknown).

    Returns
    -------
    (pathlib.Path, pathlib.Path)
        The PGM and the YAML written (each atomically, the image first); the YAML names the image
        relatively. A save interrupted between the two leaves the new image beside the old YAML: two
        files cannot be replaced in one step (save under a new stem to keep the old map whole).

    Raises
    ------
    TypeError
        If ``grid`` is not an OccupancyGrid.
    ValueError
        For thresholds outside [0, 1] or not ``free < occupied``, ``negate`` not 0 or 1, or an
        unknown mode.

    Examples
    --------
    >>> import tempfile, os
    >>> grid = OccupancyGrid.from_probability([[0.0, 1.0, 0.5]], 0.05, origin=(-1.0, 2.0))
    >>> folder = tempfile.mkdtemp()
    >>> pgm, yaml = save_map(grid, os.path.join(folder, "tiny"))
    >>> pgm.read_bytes()
    b'P5\\n3 1\\n255\\n\\xfe\\x00\\xcd'
    >>> print(yaml.read_text().strip())
    image: tiny.pgm
    mode: trinary
    resolution: 0.05
    origin: [-1.0, 2.0, 0.0]
    negate: 0
    occupied_thresh: 0.65
    free_thresh: 0.196
    """
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(f"grid: expected an OccupancyGrid, got {describe(grid)}")
    base = as_file_path(stem, "stem")
    _yaml_name(base.name + ".pgm")                              # refused before anything is written
    f, o = _thresholds(free_thresh, occupied_thresh, _value_error)
    neg = as_int(negate, "negate", minimum=0, maximum=1)
    as_choice(mode, "mode", ["trinary", "scale"])
    free, occ = grid.free_mask(f), grid.occupied_mask(o)
    if mode == "trinary":
        img = np.full(grid.shape, UNKNOWN_VALUE, dtype=np.uint8)
    else:
        v = np.round(255 * (1 - grid.probability))
        v[(v == UNKNOWN_VALUE) | (v == FREE_VALUE)] -= 1        # keep the trinary codes unambiguous
        img = v.astype(np.uint8)
    img[free], img[occ] = FREE_VALUE, OCCUPIED_VALUE
    if neg:
        img = 255 - img
    img = img[::-1]                                             # image row 0 = top of the map
    h, w = img.shape
    pgm, yaml = base.with_name(base.name + ".pgm"), base.with_name(base.name + ".yaml")
    data = f"P5\n{w} {h}\n255\n".encode("ascii") + np.ascontiguousarray(img).tobytes()
    write_atomically(pgm, lambda p: p.write_bytes(data))
    x0, y0 = (float(c) for c in grid.origin)
    text = (f"image: {_yaml_name(pgm.name)}\nmode: {mode}\nresolution: {grid.resolution!r}\norigin: [{x0!r}, {y0!r}, 0.0]\n"
            f"negate: {neg}\noccupied_thresh: {o!r}\nfree_thresh: {f!r}\n")
    write_atomically(yaml, lambda p: p.write_text(text))
    return pgm, yaml


def _yaml_name(name: str) -> str:
    """``name`` as a YAML value that :func:`load_map` reads back as ``name``: plain if it can be,
    else quoted with a quote it does not hold."""
    if any(c in name for c in "\n\r\x00"):
        raise ValueError(f"stem: a map name cannot hold a line break or NUL, got {name[:60]!r}")
    if name == name.strip() and not _YAML_SPECIAL & set(name):
        return name
    for quote in "'\"":
        if quote not in name:
            return f"{quote}{name}{quote}"
    raise ValueError(f"stem: a map name cannot hold both quote characters, got {name[:60]!r}")


def _scalar(text: str, fail) -> Any:
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
        return text[1:-1]
    if text.startswith("["):
        if not text.endswith("]"):
            fail(f"expected a list closed by ']', got {text!r}")
        return [_number(t.strip(), fail) for t in text[1:-1].split(",")] if text[1:-1].strip() else []
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def _number(text: str, fail) -> float:
    try:
        v = float(text)
    except ValueError:
        fail(f"{text!r} is not a number")
    if not math.isfinite(v):
        fail(f"expected a finite number, got {text!r}")
    return v


def _bounded_bytes(path: Path, limit: int, what: str) -> bytes:
    """The bytes of the regular file ``path``, refused (MapFileError) if larger than ``limit``."""
    return read_regular(path, limit, lambda reason: MapFileError(path, f"the {what} {reason}"))


def _parse_yaml(path: Path) -> dict:
    try:
        text = _bounded_bytes(path, MAX_YAML_BYTES, "map description").decode("utf-8")
    except FileNotFoundError:
        raise MapFileError(path, "no such map file") from None
    except UnicodeDecodeError as exc:
        raise MapFileError(path, f"cannot read the map description: {exc}") from None
    out: dict = {}
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()

        def fail(message: str, n: int = n) -> None:
            raise MapFileError(path, f"line {n}: {message}")

        if not line or line.startswith("#"):
            continue
        m = _LINE.match(line)
        if not m:
            fail(f"expected 'key: value', got {raw.strip()!r}")
        key, value = m.group(1), _without_comment(m.group(2).strip(), fail)
        if key in out:
            fail(f"key {key!r} appears twice")
        if not value:
            fail(f"key {key!r} has no value")
        out[key] = _scalar(value, fail)
    return out


def _without_comment(value: str, fail) -> str:
    """A YAML value without its trailing comment; a quoted value keeps a ``#`` inside its quotes."""
    if value[:1] in ("'", '"'):
        end = value.find(value[0], 1)
        if end < 0:
            fail(f"expected a closing {value[0]} in {value[:60]!r}")
        tail = value[end + 1:].strip()
        if tail and not tail.startswith("#"):
            fail(f"unexpected text after a quoted value: {tail[:40]!r}")
        return value[:end + 1]
    return re.split(r"\s#", value)[0].strip()


def _read_pgm(path: Path) -> np.ndarray:
    try:
        data = _bounded_bytes(path, MAX_PGM_BYTES, "map image")
    except FileNotFoundError:
        raise MapFileError(path, "the map image named by the YAML does not exist") from None
    fields, pos = [], 0
    while len(fields) < 4:                                      # magic, width, height, maxval
        while pos < len(data) and (data[pos:pos + 1].isspace() or data[pos:pos + 1] == b"#"):
            if data[pos:pos + 1] == b"#":
                end = data.find(b"\n", pos)
                pos = len(data) if end < 0 else end
            pos += 1
        start = pos
        while pos < len(data) and not data[pos:pos + 1].isspace() and data[pos:pos + 1] != b"#":
            pos += 1
        if start == pos:
            raise MapFileError(path, f"truncated PGM header: expected magic, width, height and maxval, got {len(fields)} fields")
        fields.append(data[start:pos])
    if fields[0] != b"P5":
        raise MapFileError(path, f"expected a binary PGM (magic 'P5'), got {fields[0][:10]!r}")
    try:
        w, h, maxval = (int(f) for f in fields[1:])
    except ValueError:
        raise MapFileError(path, f"PGM header: width, height and maxval must be integers, got {fields[1:]}") from None
    if w <= 0 or h <= 0:
        raise MapFileError(path, f"PGM header: expected a positive width and height, got {w} x {h}")
    if maxval != 255:
        raise MapFileError(path, f"PGM header: expected 8-bit pixels (maxval 255), got maxval {maxval}")
    if pos >= len(data) or not data[pos:pos + 1].isspace():
        raise MapFileError(path, "PGM header: expected one whitespace byte after maxval")
    pixels = data[pos + 1:]
    if len(pixels) != w * h:
        raise MapFileError(path, f"expected {w} x {h} = {w * h} pixel bytes, got {len(pixels)}")
    return np.frombuffer(pixels, dtype=np.uint8).reshape(h, w)


def load_map(yaml_path: Any) -> OccupancyGrid:
    """Read a ROS map_server map (YAML + PGM) as an :class:`OccupancyGrid`.

    Parameters
    ----------
    yaml_path : str or Path

    Returns
    -------
    OccupancyGrid
        Occupied cells have P = 1 and free cells P = 0 (clamped to 0.97 and 0.12 in log odds),
        unknown ones 0.5, so in ``mode: trinary`` the grid's default masks reproduce the file's three
        classes for any thresholds written in it. In ``mode: scale`` unknown cells keep their own
        probability, which the default masks read with the default thresholds (0.65, 0.196), not the
        file's.

    Raises
    ------
    MapFileError
        For a missing file, a malformed line, a missing or repeated key, a bad number, a threshold
        outside [0, 1], ``negate`` not 0 / 1, a non-zero yaw, ``mode: raw``, or a corrupt image.

    Examples
    --------
    >>> import tempfile, os
    >>> folder = tempfile.mkdtemp()
    >>> grid = OccupancyGrid.from_probability([[0.0, 1.0], [0.5, 0.0]], 0.1, origin=(3.0, 4.0))
    >>> back = load_map(save_map(grid, os.path.join(folder, "m"))[1])
    >>> back.origin.tolist(), back.resolution, back.occupied_mask().tolist(), back.unknown_mask().tolist()
    ([3.0, 4.0], 0.1, [[False, True], [False, False]], [[False, False], [True, False]])
    """
    path = as_file_path(yaml_path, "yaml_path")
    keys = _parse_yaml(path)

    def fail(message: str) -> None:
        raise MapFileError(path, message)

    missing = [k for k in _REQUIRED if k not in keys]
    if missing:
        fail(f"missing key(s) {missing} (a map_server YAML needs {list(_REQUIRED)})")
    res = keys["resolution"]
    if isinstance(res, bool) or not isinstance(res, (int, float)) or not (math.isfinite(res) and res > 0):
        fail(f"resolution: expected a positive number, got {keys['resolution']!r}")
    origin = keys["origin"]
    if not isinstance(origin, list) or len(origin) != 3:
        fail(f"origin: expected [x, y, yaw], got {origin!r}")
    if origin[2] != 0.0:
        fail(f"origin: a rotated map (yaw = {origin[2]}) is not supported; expected yaw 0")
    if keys["negate"] not in (0, 1) or isinstance(keys["negate"], float):
        fail(f"negate: expected 0 or 1, got {keys['negate']!r}")
    free_t, occ_t = _thresholds(keys["free_thresh"], keys["occupied_thresh"], fail)
    mode = keys.get("mode", "trinary")
    if mode not in ("trinary", "scale"):
        fail(f"mode: expected 'trinary' or 'scale' ('raw' is not supported), got {mode!r}")
    if not isinstance(keys["image"], str) or not keys["image"]:
        fail(f"image: expected a file name, got {keys['image']!r}")
    image = Path(keys["image"])
    try:
        img = _read_pgm(image if image.is_absolute() else path.parent / image)
    except MapFileError as exc:                                 # say which YAML named the image
        raise MapFileError(path, f"image: {exc}") from None
    v = img[::-1].astype(float)                                 # row 0 = lowest y
    p = v / 255.0 if keys["negate"] else (255.0 - v) / 255.0
    P = np.where(p > occ_t, 1.0, np.where(p < free_t, 0.0, 0.5 if mode == "trinary" else p))
    return OccupancyGrid.from_probability(P, float(res), origin[:2])
