"""The trial log: every sample of a LittleDog trial, checked, with a documented layout, and its file.

"A complete log of all robot state, motion capture data, and robot commands is collected on the
Host computer whenever an experimental trial is performed" (LittleDog User Guide, Sec. 2). Robokit's
log holds the same, plus the simulator's ground truth, one row per 10 ms host cycle (the guide's
100 Hz host loop): ``N`` rows of every stream of :data:`LOG_LAYOUT`, and a metadata dict saying how
the trial was run (rates, gait, the wireless link's latency, jitter and loss, the seed).

:class:`TrialLog` holds both (read-only arrays, ``log.q``), checked when built so a log in hand is
complete and consistent; :func:`empty_streams` and :func:`trial_meta` give a simulation loop arrays
to fill and the metadata; :func:`save_trial` and :func:`load_trial` write and read a log as one
file (:func:`describe_layout` documents it). A
MoCap marker the cameras did not see has ``mocap_visible`` False and no measurement in ``mocap``
(zeros by convention, never NaN: the mask says what is missing).

The file is a numpy ``.npz`` (a zip of ``.npy`` arrays, readable without robokit): one array per
stream, named as in :data:`LOG_LAYOUT`, plus two JSON strings, ``__meta__`` (the metadata, with
``format`` = :data:`LOG_FORMAT` and ``version`` = :data:`LOG_VERSION`) and ``__layout__`` (the
layout: shape, dtype, unit, description of every stream). It loads with ``allow_pickle=False``, so
a log file can never run code. A file that is truncated or corrupt, of another format or version,
or that lacks a stream or holds one of the wrong shape raises :class:`TrialLogError`.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Sec. 2 (host loop 100 Hz,
   servos 500 Hz, the trial log) and Sec. 3 (sensors: encoders, IMU, lower-leg force sensors).
.. [2] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Sec. 2 (the host computer's
   log of every trial).
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping, NamedTuple

import numpy as np

from ..files import as_file_path, open_regular, read_npz, save_npz, write_atomically
from ..geometry import quat_to_matrix, se3_from_rt
from ..validation import as_array, as_finite_scalar, as_int, as_positive, as_text, describe
from .littledog import GUIDE, TIMESTEP

__all__ = ["LOG_FORMAT", "LOG_VERSION", "MAX_LOG_BYTES", "MAX_META_CHARS", "LOG_LAYOUT", "META_KEYS", "StreamSpec", "TrialLogError", "TrialLog",
           "empty_streams", "trial_meta", "save_trial", "load_trial", "describe_layout"]


LOG_FORMAT = "robokit-littledog-trial"
"""What a trial log file says it is (``meta["format"]``)."""
LOG_VERSION = 1
"""The layout version this code writes and reads (``meta["version"]``)."""
MAX_LOG_BYTES = 2 * 1024**3
"""The largest trial log :func:`load_trial` reads (bytes; also its bound on values per stream)."""
MAX_META_CHARS = 1_000_000
"""The longest ``__meta__`` JSON text :func:`load_trial` parses."""


class StreamSpec(NamedTuple):
    """One stream of the log: trailing shape (after the ``N`` rows), dtype, unit, description."""

    shape: tuple
    dtype: str
    unit: str
    description: str


_F, _B = "float64", "bool"
LOG_LAYOUT: Mapping[str, StreamSpec] = MappingProxyType({
    "t": StreamSpec((), _F, "s", "time of the host cycle since the trial started (strictly increasing)"),
    "q": StreamSpec((12,), _F, "rad", "measured joint angles (encoders), leg-major FL, FR, HL, HR"),
    "qd": StreamSpec((12,), _F, "rad/s", "measured joint velocities"),
    "q_cmd": StreamSpec((12,), _F, "rad", "set-points the host sent this cycle"),
    "q_ref": StreamSpec((12,), _F, "rad", "set-points the robot was servoing to (what arrived over the link)"),
    "tau": StreamSpec((12,), _F, "N m", "joint torques"),
    "voltage": StreamSpec((12,), _F, "V", "motor voltages"),
    "current": StreamSpec((12,), _F, "A", "motor currents"),
    "body_pos": StreamSpec((3,), _F, "m", "true trunk position (world), the simulator's"),
    "body_quat": StreamSpec((4,), _F, "1", "true trunk orientation, unit quaternion [w, x, y, z] (world)"),
    "body_vel": StreamSpec((6,), _F, "m/s, rad/s", "true linear velocity (world) then angular velocity (body)"),
    "com": StreamSpec((3,), _F, "m", "true centre of mass (world)"),
    "feet": StreamSpec((4, 3), _F, "m", "true foot centres (world)"),
    "contact": StreamSpec((4,), _B, "-", "true foot contacts"),
    "foot_force": StreamSpec((4,), _F, "N", "axial lower-leg force sensors, compression positive"),
    "imu_gyro": StreamSpec((3,), _F, "rad/s", "IMU angular rate (body axes), its average over the host period ending at t"),
    "imu_acc": StreamSpec((3,), _F, "m/s^2", "IMU specific force (body axes; +9.81 on z at rest, level), averaged likewise"),
    "mocap": StreamSpec((4, 3), _F, "m", "MoCap marker positions (world); no measurement where not visible"),
    "mocap_visible": StreamSpec((4,), _B, "-", "whether the MoCap system saw each marker"),
})
"""The streams of a trial log, in order: name -> :class:`StreamSpec`. Every stream has one row per
host cycle (100 Hz, :data:`~robokit.legged.littledog.GUIDE`), so ``N`` rows in all."""

META_KEYS: Mapping[str, str] = MappingProxyType({
    "format": f"str, always {LOG_FORMAT!r}",
    "version": f"int, the layout's version ({LOG_VERSION})",
    "host_rate": "Hz, host control loop (one log row per cycle)",
    "servo_rate": "Hz, joint servo loop on the robot",
    "physics_timestep": "s, the simulator's step",
    "gait": "str, the gait's name ('' if none)",
    "link_latency": "s, the wireless link's fixed delay",
    "link_jitter": "s, spread of the extra delay (controllers.SetpointChannel: uniform in [0, jitter])",
    "link_loss": "fraction of host commands lost, in [0, 1]",
    "seed": "int or None, the seed of the trial's randomness",
    "notes": "str, free text",
})
"""The metadata every log carries (more keys may be added, if JSON-able): name -> what it is."""


class TrialLogError(ValueError):
    """A trial log that cannot be used: a truncated or corrupt file, another format or version, a
    missing stream, one of the wrong shape, dtype or length, or bad metadata.

    A ``ValueError``, so code that refuses bad input in general catches it too; the message names
    the stream or key at fault.

    Examples
    --------
    >>> streams = empty_streams(3)
    >>> del streams["contact"]
    >>> try:
    ...     TrialLog(streams, trial_meta())
    ... except TrialLogError as err:
    ...     print(isinstance(err, ValueError), err)
    True streams: expected exactly the streams of LOG_LAYOUT version 1; missing ['contact'], unknown []
    """


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{describe(value)} is not JSON-able")


def _checked_meta(meta: Any) -> dict:
    if not isinstance(meta, Mapping):
        raise TypeError(f"meta: expected a dict of metadata (see META_KEYS), got {describe(meta)}")
    meta = dict(meta)
    if meta.setdefault("format", LOG_FORMAT) != LOG_FORMAT:
        raise TrialLogError(f"meta['format']: expected {LOG_FORMAT!r}, got {describe(meta['format'])}")
    version = meta.setdefault("version", LOG_VERSION)
    if type(version) is not int or version != LOG_VERSION:
        raise TrialLogError(f"meta['version']: expected {LOG_VERSION} (the version this code reads), "
                            f"got {describe(meta['version'])}")
    missing = [k for k in META_KEYS if k not in meta]
    if missing:
        raise TrialLogError(f"meta: expected the keys {list(META_KEYS)}, missing {missing} (trial_meta fills them)")
    for key in ("host_rate", "servo_rate", "physics_timestep"):
        as_positive(meta[key], f"meta['{key}']")
    for key in ("link_latency", "link_jitter"):
        as_positive(meta[key], f"meta['{key}']", allow_zero=True)
    if not 0 <= as_finite_scalar(meta["link_loss"], "meta['link_loss']") <= 1:
        raise ValueError(f"meta['link_loss']: expected a fraction in [0, 1], got {meta['link_loss']}")
    if meta["seed"] is not None:
        as_int(meta["seed"], "meta['seed']", minimum=0)
    as_text(meta["gait"], "meta['gait']")
    as_text(meta["notes"], "meta['notes']")
    try:    # a copy through JSON: what is kept is exactly what a file gives back
        return json.loads(json.dumps(meta, default=_json_default, allow_nan=False))
    except (TypeError, ValueError) as err:
        raise TypeError(f"meta: expected JSON-able values (numbers, strings, lists, dicts, None), {err}") from None


def _checked_streams(streams: Any) -> dict:
    if not isinstance(streams, Mapping):
        raise TypeError(f"streams: expected a dict of arrays named as in LOG_LAYOUT, got {describe(streams)}")
    unknown = [k for k in streams if k not in LOG_LAYOUT]
    missing = [k for k in LOG_LAYOUT if k not in streams]
    if unknown or missing:
        raise TrialLogError(f"streams: expected exactly the streams of LOG_LAYOUT version {LOG_VERSION}; "
                            f"missing {missing}, unknown {unknown}")
    out, n = {}, None
    for name, spec in LOG_LAYOUT.items():
        label = f"streams['{name}']"
        arr = as_array(streams[name], label, dtype=spec.dtype)
        if n is None:
            n = arr.shape[0] if arr.ndim else -1
        if arr.shape != (n,) + spec.shape or n < 1:
            want = "(" + ", ".join(["N"] + [str(s) for s in spec.shape]) + ")"
            got = f"shape {arr.shape}" + (f" ({n} rows in t)" if name != "t" else "")
            raise TrialLogError(f"{label}: expected shape {want} with N >= 1 rows, one per host cycle, got {got}")
        view = arr.view()
        view.flags.writeable = False
        out[name] = view
    t = out["t"]
    if np.any(np.diff(t) <= 0):
        k = int(np.argmax(np.diff(t) <= 0))
        raise TrialLogError(f"streams['t']: expected strictly increasing times, got t[{k}] = {t[k]} "
                            f"then t[{k + 1}] = {t[k + 1]}")
    norm = np.linalg.norm(out["body_quat"], axis=1)
    if np.any(np.abs(norm - 1) > 1e-6):
        k = int(np.argmax(np.abs(norm - 1)))
        raise TrialLogError(f"streams['body_quat']: expected unit quaternions, got norm {norm[k]:.6g} in row {k}")
    return out


@dataclass(frozen=True, eq=False)
class TrialLog:
    """One trial: its streams (:data:`LOG_LAYOUT`, ``N`` rows each) and its metadata.

    Parameters
    ----------
    streams : dict of str to array_like
        Exactly the streams of :data:`LOG_LAYOUT`, each of shape ``(N,) + spec.shape`` and of its
        dtype (float64, or bool for ``contact`` and ``mocap_visible``; 0/1 integers are taken as
        booleans). Kept as read-only views (converted copies where the dtype differs).
    meta : dict
        The keys of :data:`META_KEYS` (:func:`trial_meta` builds them); ``format`` and ``version``
        are filled in when absent. Kept as a JSON round-trip copy, so a saved and loaded log has
        exactly the same metadata.

    Attributes
    ----------
    streams, meta : read-only mappings
        Every stream is an attribute too: ``log.q``, ``log.feet``; ``len(log)`` is ``N``.

    Raises
    ------
    TrialLogError
        For a missing or unknown stream, a wrong shape (``N`` differs between streams, or is 0),
        times that do not strictly increase, a body quaternion off unit length, or metadata of
        another format or version or without a required key.
    ValueError, TypeError
        For non-finite values, wrong dtypes or metadata of the wrong type (naming the stream or key).

    Notes
    -----
    The layout of the LittleDog User Guide's trial log (Sec. 2: robot state, MoCap data and
    commands, every host cycle), with the simulator's ground truth beside the sensors.

    Examples
    --------
    >>> log = TrialLog(empty_streams(3), trial_meta(gait="stand"))
    >>> len(log), log.q.shape, log.t.tolist(), log.meta["host_rate"]
    (3, (3, 12), [0.0, 0.01, 0.02], 100.0)
    >>> log.T_world_body()[0, :3, 3].tolist()
    [0.0, 0.0, 0.0]
    """

    streams: Mapping[str, np.ndarray]
    meta: Mapping[str, Any]

    def __post_init__(self) -> None:
        object.__setattr__(self, "streams", MappingProxyType(_checked_streams(self.streams)))
        object.__setattr__(self, "meta", MappingProxyType(_checked_meta(self.meta)))

    def validate(self) -> "TrialLog":
        """Check the log again (its arrays may have changed through other references); returns
        ``self``, or raises as the constructor does.

        Examples
        --------
        >>> TrialLog(empty_streams(2), trial_meta()).validate().meta["version"]
        1
        """
        _checked_streams(self.streams)
        _checked_meta(self.meta)
        return self

    def __getattr__(self, name: str) -> np.ndarray:
        if name in LOG_LAYOUT and "streams" in self.__dict__:
            return self.__dict__["streams"][name]
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r} (streams: {list(LOG_LAYOUT)})")

    def __dir__(self) -> list:
        return sorted(set(super().__dir__()) | set(LOG_LAYOUT))

    def __len__(self) -> int:
        return len(self.streams["t"])

    def __repr__(self) -> str:
        t = self.streams["t"]
        return (f"TrialLog({len(self)} rows, t = {t[0]:.3f}..{t[-1]:.3f} s, gait={self.meta['gait']!r}, "
                f"version={self.meta['version']})")

    def T_world_body(self) -> np.ndarray:
        """The trunk's true pose at every row, (N, 4, 4), from ``body_pos`` and ``body_quat``
        (:func:`robokit.geometry.quat_to_matrix`, :func:`robokit.geometry.se3_from_rt`).

        Examples
        --------
        >>> streams = empty_streams(2)
        >>> streams["body_pos"][:] = [0.1, 0.0, 0.13]
        >>> TrialLog(streams, trial_meta()).T_world_body()[1, :3, 3].tolist()
        [0.1, 0.0, 0.13]
        """
        return se3_from_rt(quat_to_matrix(self.streams["body_quat"], validate=False), self.streams["body_pos"])

    def slice(self, start: int, stop: int) -> "TrialLog":
        """Rows ``start`` to ``stop`` (excluded; Python's slicing rules) as a log of their own, with
        the same metadata and views of the rows (no copy); a ValueError if the range holds no row.

        Examples
        --------
        >>> log = TrialLog(empty_streams(10), trial_meta())
        >>> part = log.slice(2, -3)
        >>> len(part), part.t[0]
        (5, np.float64(0.02))
        """
        start = as_int(start, "start")
        stop = as_int(stop, "stop")
        rows = range(len(self))[start:stop]
        if len(rows) == 0:
            raise ValueError(f"start, stop: expected a range that holds rows of this {len(self)}-row log, "
                             f"got [{start}, {stop})")
        s = slice(rows.start, rows.stop)
        return TrialLog({k: v[s] for k, v in self.streams.items()}, dict(self.meta))


def trial_meta(*, gait: str = "", host_rate: float = GUIDE["host_rate"], servo_rate: float = GUIDE["servo_rate"],
               physics_timestep: float = TIMESTEP, link_latency: float = 0.0, link_jitter: float = 0.0,
               link_loss: float = 0.0, seed: int | None = None, notes: str = "", **extra: Any) -> dict:
    """The metadata of a trial, with the guide's rates as defaults.

    Parameters
    ----------
    gait, notes : str, default ""
    host_rate, servo_rate, physics_timestep : float
        Hz, Hz, s; default 100 and 500 (LittleDog User Guide, Sec. 2) and 1 ms.
    link_latency, link_jitter, link_loss : float, default 0
        The wireless link's fixed delay (s), the spread of its extra delay (s; uniform in
        [0, jitter], :class:`robokit.controllers.SetpointChannel`), the fraction of commands lost.
    seed : int or None
    **extra
        More JSON-able entries.

    Returns
    -------
    dict
        All of :data:`META_KEYS`; a ValueError or TypeError names a bad key.

    Examples
    --------
    >>> meta = trial_meta(gait="crawl", link_latency=0.004, seed=3)
    >>> meta["format"], meta["version"], meta["servo_rate"], meta["gait"]
    ('robokit-littledog-trial', 1, 500.0, 'crawl')
    """
    meta = {"format": LOG_FORMAT, "version": LOG_VERSION, "host_rate": host_rate, "servo_rate": servo_rate,
            "physics_timestep": physics_timestep, "gait": gait, "link_latency": link_latency,
            "link_jitter": link_jitter, "link_loss": link_loss, "seed": seed, "notes": notes, **extra}
    return _checked_meta(meta)


def empty_streams(n: int, host_rate: float = GUIDE["host_rate"]) -> dict:
    """Zero-filled streams of ``n`` rows for a simulation loop to fill in, then ``TrialLog(streams, meta)``.

    Parameters
    ----------
    n : int
        Rows (host cycles), at least 1.
    host_rate : float, default 100
        Hz; ``t = k / host_rate``. Every other stream is zeros (False), ``body_quat`` [1, 0, 0, 0].

    Examples
    --------
    >>> streams = empty_streams(4)
    >>> streams["feet"].shape, streams["contact"].dtype, streams["body_quat"][0].tolist()
    ((4, 4, 3), dtype('bool'), [1.0, 0.0, 0.0, 0.0])
    """
    n = as_int(n, "n", minimum=1, maximum=100_000_000)
    rate = as_positive(host_rate, "host_rate")
    streams = {name: np.zeros((n,) + spec.shape, spec.dtype) for name, spec in LOG_LAYOUT.items()}
    streams["t"][:] = np.arange(n) / rate
    streams["body_quat"][:, 0] = 1.0
    return streams


def _layout_json() -> str:
    return json.dumps({k: {"shape": list(s.shape), "dtype": s.dtype, "unit": s.unit, "description": s.description}
                       for k, s in LOG_LAYOUT.items()})


def save_trial(path: Any, log: TrialLog) -> Path:
    """Write a trial log to one compressed ``.npz``, atomically.

    Parameters
    ----------
    path : str or pathlib.Path
        The file (written as given; ``.npz`` is the usual suffix).
    log : TrialLog

    Returns
    -------
    pathlib.Path

    Raises
    ------
    TypeError, TrialLogError
        If ``log`` is not a TrialLog or ``path`` not a path; if the log's arrays were changed into
        an invalid state since it was built.

    Notes
    -----
    :func:`robokit.files.save_npz` through :func:`robokit.files.write_atomically`: a reader finds the
    old file, the complete new one or none, never half of one. The layout is in the module docstring.

    Examples
    --------
    >>> import tempfile
    >>> from robokit.legged.trial_log import empty_streams, trial_meta
    >>> target = Path(tempfile.mkdtemp()) / "trial.npz"
    >>> save_trial(target, TrialLog(empty_streams(5), trial_meta())).name
    'trial.npz'
    >>> len(load_trial(target))
    5
    """
    target = as_file_path(path, "path")
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a TrialLog, got {describe(log)}")
    log.validate()
    arrays = dict(log.streams)
    arrays["__meta__"] = np.array(json.dumps(dict(log.meta)))
    arrays["__layout__"] = np.array(_layout_json())

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            save_npz(fh, arrays)

    return write_atomically(target, write)


def _is_lone_npy(source: Path) -> bool:
    """Whether a file :func:`read_npz` refused is a single ``.npy`` array (for a clearer message)."""
    try:
        with open_regular(source, MAX_LOG_BYTES, ValueError) as fh:
            return fh.read(6) == b"\x93NUMPY"
    except (OSError, ValueError):
        return False


def load_trial(path: Any) -> TrialLog:
    """Read a trial log written by :func:`save_trial`.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    TrialLog

    Raises
    ------
    TrialLogError
        For a truncated or corrupt file, a file of another format or of another version (the
        message says which version it is and which this code reads), a missing or unexpected
        stream, or one of the wrong shape, dtype or length.
    FileNotFoundError, TypeError
        If there is no such file; if ``path`` is not a path.

    Notes
    -----
    Read by :func:`robokit.files.read_npz` within :data:`MAX_LOG_BYTES` (sizes checked before data
    are read; nothing is unpickled, so a log file can never run code); the metadata JSON within
    :data:`MAX_META_CHARS`.

    Examples
    --------
    >>> import tempfile
    >>> target = Path(tempfile.mkdtemp()) / "cut.npz"
    >>> _ = target.write_bytes(b"PK\\x03\\x04 truncated")
    >>> load_trial(target)
    Traceback (most recent call last):
    ...
    robokit.legged.trial_log.TrialLogError: ...cut.npz: not a readable trial log (truncated or corrupt: ...)
    """
    source = as_file_path(path, "path")
    try:
        arrays = read_npz(source, max_bytes=MAX_LOG_BYTES, max_arrays=len(LOG_LAYOUT) + 8, max_values=MAX_LOG_BYTES)
    except FileNotFoundError:
        raise
    except (OSError, ValueError) as err:
        if _is_lone_npy(source):
            raise TrialLogError(f"{source}: not a {LOG_FORMAT} file (one .npy array, not an .npz archive)") from None
        raise TrialLogError(f"{source}: not a readable trial log (truncated or corrupt: {err})") from None
    if "__meta__" not in arrays:
        raise TrialLogError(f"{source}: not a {LOG_FORMAT} file (it has no __meta__ record; arrays "
                            f"{list(arrays)[:6]})")
    try:
        text = str(arrays.pop("__meta__")[()])
        if len(text) > MAX_META_CHARS:
            raise ValueError(f"{len(text)} characters, more than {MAX_META_CHARS}")
        meta = json.loads(text)
    except (ValueError, TypeError, IndexError, RecursionError) as err:
        raise TrialLogError(f"{source}: its __meta__ record is not JSON ({str(err)[:200]})") from None
    if not isinstance(meta, dict) or meta.get("format") != LOG_FORMAT:
        got = meta.get("format") if isinstance(meta, dict) else describe(meta)
        raise TrialLogError(f"{source}: a file of format {got!r}, not a {LOG_FORMAT!r} trial log")
    if meta.get("version") != LOG_VERSION:
        raise TrialLogError(f"{source}: a {LOG_FORMAT} file of version {meta.get('version')!r}; this code reads "
                            f"version {LOG_VERSION} only (convert the file, or read it with the robokit that wrote it)")
    arrays.pop("__layout__", None)
    missing = [k for k in LOG_LAYOUT if k not in arrays]
    if missing:
        raise TrialLogError(f"{source}: stream(s) {missing} missing (version {LOG_VERSION} has {list(LOG_LAYOUT)})")
    try:
        return TrialLog(arrays, meta)
    except (ValueError, TypeError) as err:
        raise TrialLogError(f"{source}: {err}") from None


def describe_layout() -> str:
    """The log's layout as a text table: each stream's name, shape, dtype, unit and description,
    then the metadata keys (a str).

    Examples
    --------
    >>> print(describe_layout().splitlines()[0])
    stream         shape     dtype    unit        description
    >>> print(describe_layout().splitlines()[2])
    q              (N, 12)   float64  rad         measured joint angles (encoders), leg-major FL, FR, HL, HR
    """
    rows = [f"{'stream':<14} {'shape':<9} {'dtype':<8} {'unit':<11} description"]
    for name, spec in LOG_LAYOUT.items():
        shape = "(" + ", ".join(["N"] + [str(s) for s in spec.shape]) + ")"
        rows.append(f"{name:<14} {shape:<9} {spec.dtype:<8} {spec.unit:<11} {spec.description}")
    rows += ["", f"one row per host cycle; file: {LOG_FORMAT} version {LOG_VERSION} (.npz, metadata as JSON):"]
    rows += [f"  {key:<17} {what}" for key, what in META_KEYS.items()]
    return "\n".join(rows)
