"""The grading worker: runs a submission's cells, then its exercise functions, inside the sandbox.

Started by :mod:`robocourse.grading.sandbox` as ``python -m robocourse.grading.worker JOB_DIR``, from a
kit (:mod:`robocourse.grading.kit`): this module, what it imports and the assignment's data, and no
robokit. It works in four phases, one function each:

1. :func:`set_up`: discard the output, seal the kit (:func:`.barrier.seal`: ``check()`` silenced,
   ``assignment_data`` provided, robokit and the rest of robocourse refused) and make ``os._exit``
   end a cell rather than the grading;
2. :func:`run_cells`: run the code cells in order in an IPython shell (magics work; a failing cell
   is recorded and the next one runs), each under a time limit;
3. :func:`run_exercises`: call each exercise function on each case, writing each exercise's report
   as soon as it is done, so a submission that kills its process loses only what had not run yet;
4. :func:`finish`: write the final report and exit.

The files it reads and writes are described in :mod:`robocourse.grading.protocol`. Everything it
writes is untrusted data to the grader, which validates it and does all the judging.
"""
from __future__ import annotations

import copy
import io
import os
import signal
import sys
import time
from pathlib import Path
from typing import Any, Callable

from robocourse.grading.barrier import Manifest, seal
from robocourse.grading.protocol import CallResult, CellRecord, DoneReport, ErrorRecord, ExerciseReport, JobDir, JobSpec, log_withheld_import

__all__ = ["main", "set_up", "run_cells", "run_exercises", "finish", "GraderTimeout"]

_real_exit = os._exit
_MAIN_PID = os.getpid()


class GraderTimeout(BaseException):
    """Raised inside the worker when a cell or a call runs past its time limit."""


class _Discard(io.TextIOBase):
    """Where graded code's prints go: nowhere (the worker's own log must stay the grader's)."""

    def writable(self):
        return True

    def write(self, text):
        return len(text)


def _alarm(seconds: float) -> None:
    signal.setitimer(signal.ITIMER_REAL, max(0.0, seconds))


def _on_alarm(signum, frame):
    raise GraderTimeout("time limit exceeded")


def _leave_if_forked() -> None:
    """A fork of the worker (e.g. a fork bomb) stops here instead of grading a second time."""
    if os.getpid() != _MAIN_PID:
        _real_exit(0)


# -- phase 1: set-up -------------------------------------------------------------------------------

def set_up(job: JobDir, kit_root: Path) -> None:
    """Prepare the process for graded code.

    In order: the time-limit signal; the kit sealed (:func:`.barrier.seal`, with the manifest in
    ``kit_root``): ``check()`` silenced, ``assignment_data`` provided, every robokit name refused
    and each attempt logged for the grader's ``imported-robokit`` flag;
    ``os._exit`` turned into ``SystemExit`` (a notebook calling it ends its cell, not the
    grading); and ``sys.stdout``/``sys.stderr`` discarded, so graded code cannot write into the
    worker's log, whose tail the instructor's feedback shows when the worker ends early.
    """
    flag_fd = job.open_flags()
    signal.signal(signal.SIGALRM, _on_alarm)
    seal(Manifest.read(kit_root), lambda name: log_withheld_import(flag_fd, name))

    def _no_exit(code=0):
        raise SystemExit(code)

    os._exit = _no_exit
    sys.stdout = sys.stderr = _Discard()


# -- phase 2: the notebook's cells -----------------------------------------------------------------

def run_cell(shell, source: str, seconds: float) -> tuple[str, ErrorRecord | None]:
    """Run one cell under a time limit; return its status and error record."""
    try:
        _alarm(seconds)
        result = shell.run_cell(source, store_history=False, silent=False)
        _alarm(0)
        exc = result.error_in_exec or result.error_before_exec
        if exc is None:
            return "ok", None
        return ("timeout" if isinstance(exc, GraderTimeout) else "error"), ErrorRecord.from_exception(exc)
    except GraderTimeout as exc:
        return "timeout", ErrorRecord.from_exception(exc)
    except BaseException as exc:  # the shell itself failed on this cell
        _alarm(0)
        return "error", ErrorRecord.from_exception(exc)


def run_cells(shell, spec: JobSpec) -> tuple[tuple[CellRecord, ...], float]:
    """Run the code cells not marked skip, in order; return their records and the seconds they took."""
    records, seconds = [], 0.0
    for index, (source, skip) in enumerate(zip(spec.cells, spec.skip)):
        if skip:
            records.append(CellRecord(index, "skipped"))
            continue
        start = time.perf_counter()
        status, error = run_cell(shell, source, spec.cell_seconds)
        _leave_if_forked()
        seconds += time.perf_counter() - start
        records.append(CellRecord(index, status, error))
    return tuple(records), seconds


# -- phase 3: the exercises ------------------------------------------------------------------------

def call_case(fn: Callable[..., Any], args: tuple, kwargs: dict, seconds: float) -> CallResult:
    """Call ``fn`` on copies of a case's inputs under a time limit; any exception is data."""
    args, kwargs = copy.deepcopy(args), copy.deepcopy(kwargs)
    try:
        _alarm(seconds)
        value = fn(*args, **kwargs)
        _alarm(0)
        return CallResult.returned(value)
    except BaseException as exc:  # includes GraderTimeout and SystemExit from student code
        _alarm(0)
        return CallResult.raised(exc)


def run_exercises(namespace: dict, spec: JobSpec, job: JobDir) -> float:
    """Call each exercise's function (looked up in ``namespace``) on its cases; write each report.

    Returns the seconds spent in the calls.
    """
    total = 0.0
    for k, (function, inputs) in enumerate(spec.exercises):
        fn = namespace.get(function)
        if not callable(fn):
            job.write_exercise(k, ExerciseReport(defined=False))
            continue
        results, seconds = [], 0.0
        for args, kwargs in inputs:
            start = time.perf_counter()
            results.append(call_case(fn, args, kwargs, spec.call_seconds))
            _leave_if_forked()
            seconds += time.perf_counter() - start
        total += seconds
        job.write_exercise(k, ExerciseReport(True, tuple(results), seconds))
    return total


# -- phase 4: finish -------------------------------------------------------------------------------

def finish(job: JobDir, compute_seconds: float) -> None:
    """Write the final report and end the process at once (skipping any exit handlers it set)."""
    job.write_done(DoneReport(compute_seconds))
    _real_exit(0)


def main(job_dir: str) -> None:
    """Run the job in ``job_dir`` (see the module docstring) and exit the process.

    Notes
    -----
    Grading design (DESIGN.md, "Grading"); not from a paper.
    """
    from IPython.core.interactiveshell import InteractiveShell

    job = JobDir(Path(job_dir))
    spec = job.read_spec()
    set_up(job, Path(__file__).resolve().parents[2])
    shell = InteractiveShell.instance(colors="NoColor")
    cells, cell_seconds = run_cells(shell, spec)
    job.write_cells(cells)
    finish(job, cell_seconds + run_exercises(shell.user_ns, spec, job))


if __name__ == "__main__":
    main(sys.argv[1])
