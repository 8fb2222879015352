"""What the grader and its sandboxed worker exchange: the job directory and the records in it.

A job directory (:class:`JobDir`) holds::

    in/job         JobSpec        the grader's request: code cells, skip flags, reference names to
                                  disable, time limits, each exercise's function name and case
                                  inputs (never the seed, never the expected answers)
    work/                         the worker's current and home directory
    out/cells      CellsReport    written after the last notebook cell
    out/ex<k>      ExerciseReport written right after exercise k ran, so a submission that kills
                                  its process loses only what had not run yet
    out/done       DoneReport     written last: the worker finished
    out/flags.log                 one line per event reported while student code runs
                                  (``reference:<dotted name>``: graded code called a disabled
                                  reference function)

Records travel as plain data (:mod:`~robokit.grading.transport`). Everything under ``out/`` is
written by untrusted code, so the grader reads it only through the ``read_*`` methods of
:class:`JobDir`, which bound what they read and validate every field; they return clean records
(or ``None`` for a file the worker never wrote) and raise
:class:`~robokit.grading.transport.TransportError` for a malformed one.
"""
from __future__ import annotations

import dataclasses
import math
import os
import tempfile
from pathlib import Path
from typing import Any

from ..exercises.plain import NotPlainData, to_plain
from ..exercises.spec import Case
from .transport import TransportError, read_plain, write_plain

__all__ = ["JobDir", "JobSpec", "ExerciseJob", "CellRecord", "CellsReport", "CallResult", "ErrorRecord",
           "ExerciseReport", "DoneReport", "ReferenceSolutionDisabled", "log_reference_call", "CELL_STATUSES"]

#: Bounds on what the grader accepts from the worker (names, messages, MRO length, cells, flags).
MAX_NAME, MAX_MESSAGE, MAX_MRO, MAX_CELLS, MAX_OUTPUT = 100, 500, 12, 500, 20_000
MAX_FLAG_BYTES, MAX_FLAG_LINES = 64 * 1024, 100
CELL_STATUSES = ("ok", "error", "timeout", "skipped")
_REFERENCE_FLAG = "reference:"


class ReferenceSolutionDisabled(Exception):
    """Raised in the worker when graded code calls a robokit reference implementation directly."""


def _seconds(value: Any) -> float:
    """A duration reported by the worker: a finite non-negative number, else 0."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value >= 0
    return float(value) if ok else 0.0


def log_reference_call(fd: int, dotted: str) -> None:
    """Append ``reference:<dotted>`` to the flags log open as ``fd`` (never raises).

    Called by the worker when graded code calls the disabled reference ``dotted``; the grader reads
    it back with :meth:`JobDir.read_reference_calls`.
    """
    try:
        os.write(fd, f"{_REFERENCE_FLAG}{dotted}\n".encode())
    except OSError:
        pass


@dataclasses.dataclass(frozen=True)
class ErrorRecord:
    """An exception raised by student code, as data.

    Attributes
    ----------
    type : str
        The exception's class name.
    classes : tuple of str
        Class names of its method resolution order, ``"mro"`` on the wire (so that
        ``raises="ValueError"`` accepts a subclass).
    message : str
        ``str(exc)``, truncated.
    line : str
        ``"line N: source"`` of the student's innermost frame, where known (``check()`` only).
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
        mro = tuple(c.__name__ for c in type(exc).__mro__)[:MAX_MRO]
        return cls(type(exc).__name__[:MAX_NAME], mro, message, line)

    @classmethod
    def not_plain(cls, exc: NotPlainData) -> ErrorRecord:
        """The value a function returned is not plain data (never accepted as any ``raises``)."""
        return cls("NotPlainData", ("NotPlainData",), str(exc)[:MAX_MESSAGE])

    @classmethod
    def from_plain(cls, raw: Any) -> ErrorRecord:
        """Validate an error record read from the worker (``line`` is not taken)."""
        if not isinstance(raw, dict):
            raise TransportError("malformed error record")
        mro = raw.get("mro") if isinstance(raw.get("mro"), list) else []
        return cls(str(raw.get("type"))[:MAX_NAME], tuple(str(m)[:MAX_NAME] for m in mro[:MAX_MRO]),
                   str(raw.get("message"))[:MAX_MESSAGE])

    def to_plain(self) -> dict:
        """The record as plain data (``line`` only when known)."""
        out = {"type": self.type, "mro": list(self.classes), "message": self.message}
        return {**out, "line": self.line} if self.line else out


@dataclasses.dataclass(frozen=True)
class CallResult:
    """What one call of a student function gave: a plain ``value``, or an ``error``."""

    value: Any = None
    error: ErrorRecord | None = None

    @classmethod
    def returned(cls, value: Any) -> CallResult:
        """The function returned ``value``: keep it converted to plain data, or say why not."""
        try:
            return cls(value=to_plain(value))
        except NotPlainData as exc:
            return cls(error=ErrorRecord.not_plain(exc))

    @classmethod
    def raised(cls, exc: BaseException, *, line: str = "") -> CallResult:
        """The function raised ``exc``."""
        return cls(error=ErrorRecord.from_exception(exc, line=line))

    @classmethod
    def from_plain(cls, raw: Any) -> CallResult:
        """Validate one result read from the worker: exactly ``{"value": ...}`` or ``{"error": {...}}``."""
        if isinstance(raw, dict) and set(raw) == {"value"}:
            return cls(value=raw["value"])
        if isinstance(raw, dict) and set(raw) == {"error"} and isinstance(raw["error"], dict):
            return cls(error=ErrorRecord.from_plain(raw["error"]))
        raise TransportError("malformed result entry")

    def to_plain(self) -> dict:
        """``{"value": ...}`` or ``{"error": {...}}``."""
        return {"value": self.value} if self.error is None else {"error": self.error.to_plain()}


@dataclasses.dataclass(frozen=True)
class ExerciseJob:
    """One exercise as the worker sees it: the function to look up and the inputs to call it on."""

    id: str
    function: str
    cases: tuple[Case, ...]

    def to_plain(self) -> dict:
        """Plain data; a case travels as its inputs only (not what it expects, not its label)."""
        return {"id": self.id, "function": self.function,
                "cases": [{"args": list(c.args), "kwargs": c.kwargs} for c in self.cases]}


@dataclasses.dataclass(frozen=True)
class JobSpec:
    """The grader's request to the worker (trusted: the worker cannot write ``in/``)."""

    cells: tuple[str, ...]
    skip: tuple[bool, ...]
    references: tuple[str, ...]
    cell_seconds: float
    call_seconds: float
    exercises: tuple[ExerciseJob, ...]

    @classmethod
    def from_plain(cls, raw: dict) -> JobSpec:
        """Rebuild the request written by :meth:`to_plain`."""
        exercises = tuple(ExerciseJob(e["id"], e["function"], tuple(Case(tuple(c["args"]), c["kwargs"])
                                                                    for c in e["cases"]))
                          for e in raw["exercises"])
        return cls(tuple(raw["cells"]), tuple(raw["skip"]), tuple(raw["references"]),
                   raw["cell_seconds"], raw["call_seconds"], exercises)

    def to_plain(self) -> dict:
        """Plain data for :func:`~robokit.grading.transport.write_plain`."""
        return {"cells": list(self.cells), "skip": list(self.skip), "references": list(self.references),
                "cell_seconds": self.cell_seconds, "call_seconds": self.call_seconds,
                "exercises": [e.to_plain() for e in self.exercises]}


@dataclasses.dataclass(frozen=True)
class CellRecord:
    """How one code cell ran: its index among the code cells, a status and the error, if any."""

    cell: int
    status: str
    error: ErrorRecord | None = None

    @classmethod
    def from_plain(cls, raw: Any) -> CellRecord:
        """Validate one cell record read from the worker."""
        if (not isinstance(raw, dict) or type(raw.get("cell")) is not int
                or raw.get("status") not in CELL_STATUSES):
            raise TransportError("malformed cell record")
        error = raw.get("error")
        return cls(raw["cell"], raw["status"], None if error is None else ErrorRecord.from_plain(error))

    def to_plain(self) -> dict:
        """Plain data."""
        return {"cell": self.cell, "status": self.status,
                "error": None if self.error is None else self.error.to_plain()}


@dataclasses.dataclass(frozen=True)
class CellsReport:
    """The notebook's cells as run by the worker, and the first characters they printed."""

    cells: tuple[CellRecord, ...]
    output: str = ""
    output_dropped: int = 0

    @classmethod
    def from_plain(cls, raw: Any) -> CellsReport:
        """Validate the report; keeps the first ``MAX_CELLS`` well-formed cell records."""
        if not isinstance(raw, dict) or not isinstance(raw.get("cells"), list):
            raise TransportError("malformed cells report")
        cells = []
        for entry in raw["cells"][:MAX_CELLS]:
            try:
                cells.append(CellRecord.from_plain(entry))
            except TransportError:
                continue
        dropped = raw.get("output_dropped")
        return cls(tuple(cells), str(raw.get("output", ""))[:MAX_OUTPUT],
                   dropped if type(dropped) is int and dropped >= 0 else 0)

    def to_plain(self) -> dict:
        """Plain data."""
        return {"cells": [c.to_plain() for c in self.cells], "output": self.output,
                "output_dropped": self.output_dropped}


@dataclasses.dataclass(frozen=True)
class ExerciseReport:
    """One exercise as run by the worker.

    ``defined`` is false when the notebook has no such function; ``results`` holds one
    :class:`CallResult` per case; ``seconds`` is the time spent in the calls; ``write_error`` says
    why the results could not be written (they are then empty, and the grader calls them unusable).
    """

    defined: bool
    results: tuple[CallResult, ...] = ()
    seconds: float = 0.0
    write_error: ErrorRecord | None = None

    @classmethod
    def from_plain(cls, raw: Any, n_cases: int) -> ExerciseReport:
        """Validate the report of an exercise with ``n_cases`` cases."""
        if isinstance(raw, dict) and raw.get("defined") is False:
            return cls(defined=False)
        if not isinstance(raw, dict) or not isinstance(raw.get("results"), list):
            raise TransportError("malformed results")
        if len(raw["results"]) != n_cases:
            raise TransportError(f"expected {n_cases} results, got {len(raw['results'])}")
        return cls(True, tuple(CallResult.from_plain(r) for r in raw["results"]), _seconds(raw.get("seconds")))

    def to_plain(self) -> dict:
        """Plain data."""
        out = {"defined": self.defined, "results": [r.to_plain() for r in self.results], "seconds": self.seconds}
        return out if self.write_error is None else {**out, "write_error": self.write_error.to_plain()}


@dataclasses.dataclass(frozen=True)
class DoneReport:
    """The worker's last word: time spent in the student's cells and calls."""

    compute_seconds: float

    @classmethod
    def from_plain(cls, raw: Any) -> DoneReport:
        """Validate the report (a bad duration reads as 0)."""
        if not isinstance(raw, dict):
            raise TransportError("malformed done report")
        return cls(_seconds(raw.get("compute_seconds")))

    def to_plain(self) -> dict:
        """Plain data."""
        return {"compute_seconds": self.compute_seconds}


@dataclasses.dataclass(frozen=True)
class JobDir:
    """The directory of one grading job (layout in the module docstring).

    Examples
    --------
    >>> job = JobDir(Path("/tmp/job-x"))
    >>> job.work.name, job.exercise_file(2).name
    ('work', 'ex2')
    """

    root: Path

    @classmethod
    def create(cls, parent: str | Path | None = None) -> JobDir:
        """Make a fresh job directory (with ``in/``, ``work/`` and ``out/``) under ``parent``."""
        job = cls(Path(tempfile.mkdtemp(prefix="job-", dir=parent)))
        for sub in (job.inbox, job.work, job.outbox):
            sub.mkdir()
        return job

    @property
    def inbox(self) -> Path:
        """``in/``: written by the grader, read-only to the worker."""
        return self.root / "in"

    @property
    def work(self) -> Path:
        """``work/``: the worker's current and home directory."""
        return self.root / "work"

    @property
    def outbox(self) -> Path:
        """``out/``: written by the worker, read by the grader."""
        return self.root / "out"

    def exercise_file(self, k: int) -> Path:
        """Stem of the report of exercise ``k`` (``out/ex<k>``)."""
        return self.outbox / f"ex{k}"

    # -- the grader's side ------------------------------------------------------------------------

    def write_spec(self, spec: JobSpec) -> None:
        """Write the request ``in/job``."""
        write_plain(spec.to_plain(), self.inbox / "job")

    def read_cells(self) -> CellsReport | None:
        """The cells report, or ``None`` if it is missing or malformed."""
        try:
            return CellsReport.from_plain(read_plain(self.outbox / "cells"))
        except TransportError:
            return None

    def read_exercise(self, k: int, n_cases: int) -> ExerciseReport | None:
        """The report of exercise ``k``; ``None`` if the worker never wrote it.

        Raises
        ------
        TransportError
            If it was written but is malformed, too large or unsafe.
        """
        stem = self.exercise_file(k)
        if not stem.with_suffix(".json").exists():
            return None
        return ExerciseReport.from_plain(read_plain(stem), n_cases)

    def read_done(self) -> DoneReport | None:
        """The final report; ``None`` if the worker did not get that far.

        A malformed report still says that the worker finished; its duration then reads as 0.
        """
        if not (self.outbox / "done.json").exists():
            return None
        try:
            return DoneReport.from_plain(read_plain(self.outbox / "done"))
        except TransportError:
            return DoneReport(0.0)

    def read_reference_calls(self) -> list[str]:
        """Dotted names of the disabled references graded code called (first lines of the log only)."""
        try:
            with open(self.outbox / "flags.log", "rb") as f:
                text = f.read(MAX_FLAG_BYTES).decode(errors="replace")
        except OSError:
            return []
        return [line[len(_REFERENCE_FLAG):][:MAX_NAME] for line in text.splitlines()[:MAX_FLAG_LINES]
                if line.startswith(_REFERENCE_FLAG)]

    # -- the worker's side ------------------------------------------------------------------------

    def read_spec(self) -> JobSpec:
        """Read the request ``in/job``."""
        return JobSpec.from_plain(read_plain(self.inbox / "job"))

    def open_flags(self) -> int:
        """Open ``out/flags.log`` for appending; return the file descriptor."""
        return os.open(self.outbox / "flags.log", os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)

    def write_cells(self, report: CellsReport) -> None:
        """Write ``out/cells``."""
        write_plain(report.to_plain(), self.outbox / "cells")

    def write_exercise(self, k: int, report: ExerciseReport) -> None:
        """Write ``out/ex<k>``; if the results cannot be written (e.g. too large), write the reason."""
        try:
            write_plain(report.to_plain(), self.exercise_file(k))
        except Exception as exc:
            failed = ExerciseReport(report.defined, (), report.seconds, ErrorRecord.from_exception(exc))
            write_plain(failed.to_plain(), self.exercise_file(k))

    def write_done(self, report: DoneReport) -> None:
        """Write ``out/done``, the worker's last act."""
        write_plain(report.to_plain(), self.outbox / "done")
