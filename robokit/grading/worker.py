"""The grading worker: runs a submission's cells, then its exercise functions, inside the sandbox.

Started by :mod:`robokit.grading.sandbox` as ``python -m robokit.grading.worker JOB_DIR``. It
reads ``JOB_DIR/in/job`` (cells and input cases — never the seed or the expected answers), runs the
code cells in order in an IPython shell (magics work; a failing cell is recorded and the next one
runs), then calls each exercise function on each case and writes ``JOB_DIR/out/ex<k>`` right after
each exercise, so a submission that kills its process loses only what had not run yet. Everything
it writes is untrusted data to the grader, which validates it and does all the judging.
"""
from __future__ import annotations

import copy
import importlib
import io
import os
import signal
import sys
import time
from pathlib import Path

_real_exit = os._exit
_MAIN_PID = os.getpid()
_OUTPUT_CAP = 20_000


class GraderTimeout(BaseException):
    """Raised inside the worker when a cell or a call runs past its time limit."""


class ReferenceSolutionDisabled(Exception):
    """Raised when graded code calls a robokit reference implementation directly."""


class _CappedText(io.TextIOBase):
    """A text stream that keeps the first characters written and counts the rest."""

    def __init__(self, cap: int = _OUTPUT_CAP):
        self.cap, self.kept, self.dropped = cap, [], 0
        self._size = 0

    def writable(self):
        return True

    def write(self, text):
        text = str(text)
        room = self.cap - self._size
        if room > 0:
            self.kept.append(text[:room])
            self._size += min(room, len(text))
        self.dropped += max(0, len(text) - max(room, 0))
        return len(text)

    def flush(self):
        pass


def _alarm(seconds: float) -> None:
    signal.setitimer(signal.ITIMER_REAL, max(0.0, seconds))


def _on_alarm(signum, frame):
    raise GraderTimeout("time limit exceeded")


def _install_traps(references: list[str], flag_fd: int) -> None:
    """Replace each reference function so that a direct call from graded code fails and is flagged.

    Calls made from inside robokit itself (a library function that uses a helper which happens to
    be a reference) pass through, so legitimate use of other robokit functions keeps working.
    """
    for dotted in references:
        module_name, _, attr = dotted.rpartition(".")
        try:
            module = importlib.import_module(module_name)
            real = getattr(module, attr)
        except (ImportError, AttributeError):
            continue
        package_dir = str(Path(importlib.import_module("robokit").__file__).parent)

        def trap(*args, __real=real, __name=dotted, **kwargs):
            caller = sys._getframe(1).f_code.co_filename
            if caller.startswith(package_dir) and "/grading/" not in caller:
                return __real(*args, **kwargs)
            try:
                os.write(flag_fd, f"reference:{__name}\n".encode())
            except OSError:
                pass
            raise ReferenceSolutionDisabled(f"{__name} is the reference solution and is disabled while grading")

        trap.__name__ = getattr(real, "__name__", attr)
        trap.__doc__ = getattr(real, "__doc__", None)
        for mod in list(sys.modules.values()):  # also names re-exported by packages
            if getattr(mod, "__name__", "").startswith("robokit") and getattr(mod, attr, None) is real:
                setattr(mod, attr, trap)


def _quiet_check(*args, **kwargs):
    print("(check() is skipped during official grading)")


def _error_record(exc: BaseException) -> dict:
    try:
        message = str(exc)[:500]
    except BaseException:
        message = "<unprintable exception>"
    mro = [c.__name__ for c in type(exc).__mro__][:12]
    return {"type": type(exc).__name__[:100], "mro": mro, "message": message}


def main(job_dir: str) -> None:
    """Run the job in ``job_dir`` (see the module docstring) and exit the process.

    Notes
    -----
    Grading design (DESIGN.md, "Grading"); not from a paper.
    """
    from IPython.core.interactiveshell import InteractiveShell

    from ..exercises.plain import NotPlainData, to_plain
    from .transport import read_plain, write_plain

    job = Path(job_dir)
    spec = read_plain(job / "in" / "job")
    out = job / "out"
    flag_fd = os.open(out / "flags.log", os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
    signal.signal(signal.SIGALRM, _on_alarm)

    import robokit.grading
    import robokit.grading.check as check_module

    robokit.grading.check = _quiet_check
    check_module.check = _quiet_check
    _install_traps(spec["references"], flag_fd)

    def _no_exit(code=0):
        raise SystemExit(code)

    os._exit = _no_exit  # a notebook calling os._exit ends its cell, not the grading
    stream = _CappedText()
    sys.stdout = sys.stderr = stream
    shell = InteractiveShell.instance(colors="NoColor")
    compute = 0.0
    cells = []
    for index, (source, skip) in enumerate(zip(spec["cells"], spec["skip"])):
        if skip:
            cells.append({"cell": index, "status": "skipped"})
            continue
        start = time.perf_counter()
        status, error = "ok", None
        try:
            _alarm(spec["cell_seconds"])
            result = shell.run_cell(source, store_history=False, silent=False)
            _alarm(0)
            exc = result.error_in_exec or result.error_before_exec
            if exc is not None:
                status = "timeout" if isinstance(exc, GraderTimeout) else "error"
                error = _error_record(exc)
        except GraderTimeout as exc:
            status, error = "timeout", _error_record(exc)
        except BaseException as exc:  # the shell itself failed on this cell
            _alarm(0)
            status, error = "error", _error_record(exc)
        if os.getpid() != _MAIN_PID:  # a fork of the worker (e.g. a fork bomb) stops here
            _real_exit(0)
        compute += time.perf_counter() - start
        cells.append({"cell": index, "status": status, "error": error})
    write_plain({"cells": cells, "output": "".join(stream.kept), "output_dropped": stream.dropped},
                out / "cells")
    user_ns = shell.user_ns
    for k, exercise in enumerate(spec["exercises"]):
        fn = user_ns.get(exercise["function"])
        results = []
        if not callable(fn):
            write_plain({"defined": False, "results": [], "seconds": 0.0}, out / f"ex{k}")
            continue
        ex_time = 0.0
        for case in exercise["cases"]:
            args, kwargs = copy.deepcopy(case["args"]), copy.deepcopy(case["kwargs"])
            start = time.perf_counter()
            try:
                _alarm(spec["call_seconds"])
                value = fn(*args, **kwargs)
                _alarm(0)
                record = {"value": to_plain(value)}
            except NotPlainData as exc:
                _alarm(0)
                record = {"error": {"type": "NotPlainData", "mro": ["NotPlainData"], "message": str(exc)[:300]}}
            except BaseException as exc:  # includes GraderTimeout and SystemExit from student code
                _alarm(0)
                record = {"error": _error_record(exc)}
            if os.getpid() != _MAIN_PID:
                _real_exit(0)
            ex_time += time.perf_counter() - start
            results.append(record)
        compute += ex_time
        try:
            write_plain({"defined": True, "results": results, "seconds": ex_time}, out / f"ex{k}")
        except Exception as exc:  # e.g. a value too large to write
            write_plain({"defined": True, "results": [], "seconds": ex_time,
                         "write_error": _error_record(exc)}, out / f"ex{k}")
    write_plain({"compute_seconds": compute}, out / "done")
    _real_exit(0)


if __name__ == "__main__":
    main(sys.argv[1])
