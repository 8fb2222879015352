"""What the grader and its sandboxed worker exchange: the job directory and the records in it.

A job directory (:class:`JobDir`) holds::

    in/job         JobSpec         the request: cells, skip flags, time limits, each exercise's
                                   function and case inputs (only those)
    work/                          the worker's current and home directory
    out/cells      CellRecord...   written after the last notebook cell
    out/ex<k>      ExerciseReport  written as soon as exercise k has run
    out/done       DoneReport      written last: the worker finished
    out/flags.log                  ``robokit:<name>``: graded code tried to import what the kit withholds
    worker.log                     the worker process's own stdout and stderr

Records are dataclasses, stored as their fields in plain data (:mod:`.transport`). ``out/`` (and,
without root, the whole job directory) is writable by untrusted code, which may replace any file
in it by a link, a FIFO, a directory or garbage, before or after the grader looks. The grader reads
it only through :class:`JobDir`'s ``read_*`` methods, and nothing else opens those files: they open
``out/`` itself without following a link and each file with
:func:`~.transport.read_untrusted` (no link followed, no FIFO waited on, regular files only, bounded
reads), validate every field strictly, and return clean records, ``None`` for a file never written,
or raise :class:`~.transport.TransportError`: a record with one wrong field is unusable as a whole.
"""
from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import tempfile
from pathlib import Path
from typing import Any, Iterator

from robocourse.exercises.plain import NotPlainData, to_plain
from robocourse.grading.transport import NotWritten, TransportError, open_directory, read_plain, read_untrusted, write_plain

__all__ = ["JobDir", "JobSpec", "CellRecord", "CallResult", "ErrorRecord", "ExerciseReport", "DoneReport",
           "log_withheld_import", "CELL_STATUSES"]

#: Bounds on what the grader takes from the worker.
MAX_NAME, MAX_MESSAGE, MAX_CLASSES, MAX_CELLS = 100, 500, 12, 500
MAX_FLAG_BYTES, MAX_FLAG_LINES, MAX_LOG_BYTES = 64 * 1024, 100, 4000
#: A duration (s) or a cell index beyond these is malformed, not just large.
MAX_SECONDS, MAX_CELL_INDEX = 1e7, 10**6
CELL_STATUSES = ("ok", "error", "timeout", "skipped")
_WITHHELD_FLAG = "robokit:"


def log_withheld_import(fd: int, dotted: str) -> None:
    """Append ``robokit:<dotted>`` to the flags log open as ``fd`` (never raises)."""
    try:
        os.write(fd, f"{_WITHHELD_FLAG}{dotted}\n".encode())
    except OSError:
        pass


def _plain(record: Any) -> Any:
    """A record as plain data: its fields by name, nested records likewise, tuples as lists."""
    if dataclasses.is_dataclass(record):
        return {f.name: _plain(getattr(record, f.name)) for f in dataclasses.fields(record)}
    return [_plain(v) for v in record] if isinstance(record, tuple) else record


def _seconds(value: Any) -> float:
    """A duration reported by the worker: a number in [0, MAX_SECONDS], else a TransportError."""
    if type(value) is int and 0 <= value <= MAX_SECONDS:
        return float(value)
    if type(value) is float and math.isfinite(value) and 0 <= value <= MAX_SECONDS:
        return value
    raise TransportError("malformed duration")


def _text(raw: Any, limit: int) -> str:
    """A string field read from the worker, truncated to ``limit``; anything else is malformed."""
    if type(raw) is not str:
        raise TransportError("malformed text field")
    return raw[:limit]


@dataclasses.dataclass(frozen=True)
class ErrorRecord:
    """An exception raised by student code, as data.

    ``type`` is the class name, ``classes`` the names of its method resolution order (so that
    ``raises="ValueError"`` accepts a subclass), ``message`` is ``str(exc)`` truncated, and
    ``line`` the student's ``"line N: source"`` where known (``check()`` only; the grader drops it).
    """

    type: str
    classes: tuple[str, ...]
    message: str
    line: str = ""

    @classmethod
    def from_exception(cls, exc: BaseException, *, line: str = "") -> ErrorRecord:
        """Describe ``exc``, whose ``__str__`` may itself be hostile."""
        try:
            message = str(exc)[:MAX_MESSAGE]
        except BaseException:
            message = "<unprintable exception>"
        classes = tuple(c.__name__ for c in type(exc).__mro__)[:MAX_CLASSES]
        return cls(type(exc).__name__[:MAX_NAME], classes, message, line)

    @classmethod
    def from_plain(cls, raw: Any) -> ErrorRecord:
        """Validate an error record read from the worker (its ``line`` is dropped)."""
        if not isinstance(raw, dict) or not isinstance(raw.get("classes"), list):
            raise TransportError("malformed error record")
        return cls(_text(raw.get("type"), MAX_NAME), tuple(_text(c, MAX_NAME) for c in raw["classes"][:MAX_CLASSES]),
                   _text(raw.get("message"), MAX_MESSAGE))


@dataclasses.dataclass(frozen=True)
class CallResult:
    """What one call of a student function gave: a plain ``value``, or an ``error``."""

    value: Any = None
    error: ErrorRecord | None = None

    @classmethod
    def returned(cls, value: Any) -> CallResult:
        """The function returned ``value``: kept as plain data; anything else is a ``NotPlainData``
        error, which no ``raises`` of a case accepts."""
        try:
            return cls(value=to_plain(value))
        except NotPlainData as exc:
            return cls(error=ErrorRecord("NotPlainData", ("NotPlainData",), str(exc)[:MAX_MESSAGE]))

    @classmethod
    def raised(cls, exc: BaseException, *, line: str = "") -> CallResult:
        """The function raised ``exc``."""
        return cls(error=ErrorRecord.from_exception(exc, line=line))

    @classmethod
    def from_plain(cls, raw: Any) -> CallResult:
        """Validate one result read from the worker: a value, or an error record, not both."""
        if not isinstance(raw, dict) or set(raw) != {"value", "error"}:
            raise TransportError("malformed result entry")
        if raw["error"] is None:
            return cls(value=raw["value"])
        if raw["value"] is None and isinstance(raw["error"], dict):
            return cls(error=ErrorRecord.from_plain(raw["error"]))
        raise TransportError("malformed result entry")


@dataclasses.dataclass(frozen=True)
class JobSpec:
    """The grader's request to the worker (trusted: the worker cannot write ``in/``).

    ``exercises`` holds ``(function name, ((args, kwargs), ...))`` per exercise: the inputs of its
    cases only, neither what a case expects nor its label.
    """

    cells: tuple[str, ...]
    skip: tuple[bool, ...]
    cell_seconds: float
    call_seconds: float
    exercises: tuple[tuple[str, tuple[tuple[tuple, dict], ...]], ...]

    @classmethod
    def from_plain(cls, raw: dict) -> JobSpec:
        """Rebuild the request as :meth:`JobDir.write_spec` wrote it."""
        exercises = tuple((fn, tuple((tuple(args), kwargs) for args, kwargs in inputs))
                          for fn, inputs in raw["exercises"])
        return cls(tuple(raw["cells"]), tuple(raw["skip"]), raw["cell_seconds"],
                   raw["call_seconds"], exercises)


@dataclasses.dataclass(frozen=True)
class CellRecord:
    """How one code cell ran: its index among the code cells, a status and the error, if any."""

    cell: int
    status: str
    error: ErrorRecord | None = None

    @classmethod
    def from_plain(cls, raw: Any) -> CellRecord:
        """Validate one cell record read from the worker."""
        if not isinstance(raw, dict) or type(raw.get("cell")) is not int or not 0 <= raw["cell"] < MAX_CELL_INDEX \
                or raw.get("status") not in CELL_STATUSES:
            raise TransportError("malformed cell record")
        return cls(raw["cell"], raw["status"], None if raw.get("error") is None else ErrorRecord.from_plain(raw["error"]))


@dataclasses.dataclass(frozen=True)
class ExerciseReport:
    """One exercise as run by the worker: ``defined`` is false when the notebook has no such
    function; ``results`` holds one :class:`CallResult` per case; ``seconds`` is the time the calls took.
    """

    defined: bool
    results: tuple[CallResult, ...] = ()
    seconds: float = 0.0

    @classmethod
    def from_plain(cls, raw: Any, n_cases: int) -> ExerciseReport:
        """Validate the report of an exercise with ``n_cases`` cases."""
        if isinstance(raw, dict) and raw.get("defined") is False:
            return cls(defined=False)
        if not isinstance(raw, dict) or raw.get("defined") is not True or not isinstance(raw.get("results"), list):
            raise TransportError("malformed results")
        if len(raw["results"]) != n_cases:
            raise TransportError(f"expected {n_cases} results, got {len(raw['results'])}")
        return cls(True, tuple(CallResult.from_plain(r) for r in raw["results"]), _seconds(raw.get("seconds")))


@dataclasses.dataclass(frozen=True)
class DoneReport:
    """The worker's last word: the time spent in the student's cells and calls."""

    compute_seconds: float


class JobDir:
    """The directory of one grading job (layout in the module docstring).

    Examples
    --------
    >>> job = JobDir("/tmp/job-x")
    >>> job.work.name, job.exercise_file(2).name
    ('work', 'ex2')
    """

    def __init__(self, root: str | Path):
        self.root = Path(root)
        self.inbox, self.work, self.outbox = self.root / "in", self.root / "work", self.root / "out"

    @classmethod
    def create(cls, parent: str | Path | None = None) -> JobDir:
        """Make a fresh job directory (with ``in/``, ``work/`` and ``out/``) under ``parent``."""
        job = cls(tempfile.mkdtemp(prefix="job-", dir=parent))
        for sub in (job.inbox, job.work, job.outbox):
            sub.mkdir()
        return job

    def exercise_file(self, k: int) -> Path:
        """Stem of the report of exercise ``k`` (``out/ex<k>``)."""
        return self.outbox / f"ex{k}"

    # -- the grader's side: write the request, read (bounded, validated) what the worker wrote ----

    def write_spec(self, spec: JobSpec) -> None:
        """Write the request ``in/job``."""
        write_plain(_plain(spec), self.inbox / "job")

    @contextlib.contextmanager
    def _outbox_fd(self) -> Iterator[int]:
        """``out/`` opened as a directory, never through a link (the worker may have replaced it)."""
        try:
            fd = open_directory(self.outbox)
        except OSError as exc:
            raise TransportError(f"out/ could not be opened ({exc.strerror})") from None
        try:
            yield fd
        finally:
            os.close(fd)

    def _read_out(self, stem: str) -> Any:
        """The plain data of ``out/<stem>`` (see :func:`~.transport.read_plain`)."""
        with self._outbox_fd() as fd:
            return read_plain(stem, dir_fd=fd)

    def read_cells(self) -> tuple[CellRecord, ...] | None:
        """The first ``MAX_CELLS`` cell records; ``None`` if the worker never wrote them.

        Raises
        ------
        TransportError
            If the file is unsafe, too large or holds a malformed record.
        """
        try:
            raw = self._read_out("cells")
        except NotWritten:
            return None
        if not isinstance(raw, list):
            raise TransportError("malformed cell records")
        return tuple(CellRecord.from_plain(entry) for entry in raw[:MAX_CELLS])

    def read_exercise(self, k: int, n_cases: int) -> ExerciseReport | None:
        """The report of exercise ``k``; ``None`` if the worker never wrote it.

        Raises
        ------
        TransportError
            If it was written but is malformed, too large or unsafe.
        """
        try:
            raw = self._read_out(f"ex{k}")
        except NotWritten:
            return None
        return ExerciseReport.from_plain(raw, n_cases)

    def read_done(self) -> DoneReport | None:
        """The final report; ``None`` if the worker did not get that far.

        Raises
        ------
        TransportError
            If it was written but is malformed, too large or unsafe.
        """
        try:
            raw = self._read_out("done")
        except NotWritten:
            return None
        if not isinstance(raw, dict):
            raise TransportError("malformed final report")
        return DoneReport(_seconds(raw.get("compute_seconds")))

    def read_withheld_imports(self) -> list[str]:
        """Dotted names graded code tried to import and the kit withholds (the log's first lines);
        empty if the log was never written.

        Raises
        ------
        TransportError
            If the log is unsafe (a link, a FIFO, ...) or unreadable.
        """
        try:
            with self._outbox_fd() as fd:
                data = read_untrusted("flags.log", MAX_FLAG_BYTES, dir_fd=fd, keep="head")
        except NotWritten:
            return []
        text = data.decode(errors="replace")
        return [line[len(_WITHHELD_FLAG):][:MAX_NAME] for line in text.splitlines()[:MAX_FLAG_LINES]
                if line.startswith(_WITHHELD_FLAG)]

    @property
    def log_file(self) -> Path:
        """``worker.log``: where the sandbox sends the worker process's stdout and stderr."""
        return self.root / "worker.log"

    def read_log_tail(self) -> str:
        """The last ``MAX_LOG_BYTES`` of ``worker.log`` as text ("" if never written); without root
        the worker can replace that file too, so it is read like the files in ``out/``."""
        try:
            data = read_untrusted(self.log_file, MAX_LOG_BYTES, keep="tail")
        except NotWritten:
            return ""
        except TransportError as exc:
            return f"(the worker's log is unusable: {exc})"
        return data.decode(errors="replace")

    # -- the worker's side ------------------------------------------------------------------------

    def read_spec(self) -> JobSpec:
        """Read the request ``in/job``."""
        return JobSpec.from_plain(read_plain(self.inbox / "job"))

    def open_flags(self) -> int:
        """Open ``out/flags.log`` for appending; return the file descriptor."""
        return os.open(self.outbox / "flags.log", os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)

    def write_cells(self, cells: tuple[CellRecord, ...]) -> None:
        """Write ``out/cells``."""
        write_plain(_plain(cells), self.outbox / "cells")

    def write_exercise(self, k: int, report: ExerciseReport) -> None:
        """Write ``out/ex<k>``; results that cannot be written (e.g. too large) are left out, and
        the grader then calls them unusable."""
        try:
            write_plain(_plain(report), self.exercise_file(k))
        except Exception:
            write_plain(_plain(dataclasses.replace(report, results=())), self.exercise_file(k))

    def write_done(self, report: DoneReport) -> None:
        """Write ``out/done``, the worker's last act."""
        write_plain(_plain(report), self.outbox / "done")
