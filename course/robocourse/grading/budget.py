"""Run one piece of the trusted grader's work under a memory and time budget, in a forked child.

Reading a worker's results and judging them is the only work the grader does on data a student
controls. The protocol bounds each file and :mod:`~robocourse.exercises.plain` checks every answer
before numpy sees it, but a bound missed anywhere (a comparison that grows with its input, a parser
that widens what it reads) would cost the grader's process, and with it the batch. So that work
runs in a child forked from the grader, whose address space may grow by at most a budget
(``RLIMIT_AS`` set to what the child holds at the fork plus ``memory_bytes``) and which is killed at
a deadline. A breach costs that submission alone (:func:`run_within` raises
:class:`BudgetExceeded`). The child returns its result pickled through a pipe: the pickle is
written by the grader's own code in the child, from the scores it computed, never by student code.

Forking a threaded process (the grader grades several submissions at once) is safe here: the
child runs only the grader's own pure-Python and numpy code, takes no lock another thread could
hold (Python takes the import lock across ``fork``), closes every file descriptor but its own
pipe (a sibling's pipe held open would keep its reader waiting), prints nothing, sets its OOM score
so that the kernel ends it before the grader, and leaves by ``os._exit``. Its reply is
length-prefixed, so a complete reply is read without waiting for the pipe to close.
"""
from __future__ import annotations

import os
import pickle
import resource
import select
import signal
import time
from typing import Any, Callable

__all__ = ["BudgetExceeded", "run_within"]

_MAX_REPLY = 64 * 1024**2   # the child's pickled result (scores and messages): far below this


class BudgetExceeded(RuntimeError):
    """The work went over its memory or time budget, or its process died; ``what`` says which:
    ``"memory"``, ``"time"`` or ``"ended"``."""

    def __init__(self, what: str, message: str):
        super().__init__(message)
        self.what = what


def _address_space() -> int:
    """This process's current virtual size in bytes (``VmSize``), 0 if unknown."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


def _child(work: Callable[[], Any], memory_bytes: int, fd: int) -> None:
    """In the forked child: keep only its own pipe, cap the address space, run ``work``, write the
    length-prefixed pickle of ``(status, payload)``."""
    try:
        # fds of other threads' children and pipes are not ours: holding a sibling's pipe open
        # would keep its reader waiting for an end of file that this child owes it
        limit = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
        os.closerange(3, fd)
        os.closerange(fd + 1, limit if limit != resource.RLIM_INFINITY else 65536)
        try:
            with open("/proc/self/oom_score_adj", "w") as f:    # if memory runs out, this child goes first
                f.write("1000")
        except OSError:
            pass
        size = _address_space()
        if size:                  # unknown size: the deadline and the OOM score still bound the child
            hard = resource.getrlimit(resource.RLIMIT_AS)[1]
            limit = size + memory_bytes if hard == resource.RLIM_INFINITY else min(size + memory_bytes, hard)
            resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
        try:
            reply = ("ok", work())
        except MemoryError:
            reply = ("memory", None)
        except BaseException as exc:  # reported to the parent, which raises it as a grader failure
            reply = ("error", f"{type(exc).__name__}: {exc}"[:500])
        try:
            data = pickle.dumps(reply, protocol=pickle.HIGHEST_PROTOCOL)
        except MemoryError:
            data = pickle.dumps(("memory", None))
        except Exception as exc:  # a result that does not pickle is the grader's bug
            data = pickle.dumps(("error", f"unpicklable result: {type(exc).__name__}"))
        view = memoryview(len(data).to_bytes(8, "little") + data)
        while view:
            view = view[os.write(fd, view):]
    finally:
        os._exit(0)


def _read_reply(fd: int, deadline: float) -> bytes | None:
    """The child's reply (its 8-byte length, then that many bytes); ``None`` at the deadline, and
    ``b""`` if the pipe ends first (the child died)."""
    buffer, want = bytearray(), None
    while want is None or len(buffer) < want + 8:
        left = deadline - time.monotonic()
        if left <= 0:
            return None
        ready, _, _ = select.select([fd], [], [], left)
        if not ready:
            return None
        chunk = os.read(fd, 1 << 20)
        if not chunk:
            return b""
        buffer += chunk
        if want is None and len(buffer) >= 8:
            want = int.from_bytes(buffer[:8], "little")
            if want > _MAX_REPLY:
                raise BudgetExceeded("memory", "the grader's judging produced an oversized reply")
    return bytes(buffer[8:want + 8])


def run_within(work: Callable[[], Any], *, memory_bytes: int, seconds: float) -> Any:
    """Return ``work()`` computed in a forked child whose memory may grow by at most
    ``memory_bytes`` and which is killed after ``seconds``.

    ``work`` and its result must be the grader's own (its result is pickled back).

    Raises
    ------
    BudgetExceeded
        If the child ran out of its memory budget, passed its deadline or died.
    RuntimeError
        If ``work`` raised in the child (the message names the exception).

    Examples
    --------
    >>> run_within(lambda: sum(range(10)), memory_bytes=1 << 28, seconds=10)
    45
    >>> run_within(lambda: bytearray(1 << 32), memory_bytes=1 << 28, seconds=10)
    Traceback (most recent call last):
    ...
    robocourse.grading.budget.BudgetExceeded: judging your results needed more than the grader's memory budget (256 MiB)
    """
    read_fd, write_fd = os.pipe()
    try:
        pid = os.fork()
    except OSError:
        os.close(read_fd)
        os.close(write_fd)
        raise
    if pid == 0:
        _child(work, memory_bytes, write_fd)
    os.close(write_fd)
    data = None
    try:
        data = _read_reply(read_fd, time.monotonic() + seconds)
    finally:
        os.close(read_fd)
        if not data:                # past the deadline, refused or died: make sure the child is gone
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        _, status = os.waitpid(pid, 0)
    if data is None:
        raise BudgetExceeded("time", f"judging your results took longer than the grader's {seconds:g} s budget")
    try:
        state, payload = pickle.loads(data) if data else ("ended", None)
    except Exception:  # a reply cut short (the child killed while writing): as if it had died
        state, payload = "ended", None
    if state == "ended":
        how = f"signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status) else f"exit status {os.WEXITSTATUS(status)}"
        raise BudgetExceeded("ended", f"the grader's judging process ended without a result ({how}; "
                                      "the system may have run out of memory)")
    if state == "memory":
        raise BudgetExceeded("memory", "judging your results needed more than the grader's memory budget "
                                       f"({memory_bytes / 1024**2:.0f} MiB)")
    if state == "error":
        raise RuntimeError(f"the grader's judging failed: {payload}")
    return payload
