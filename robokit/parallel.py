"""Independent runs of an experiment in worker processes, results in order, the one way for robokit.

An experiment made of many independent, separately seeded runs (lesson 03's Table 2 trials and its
rendered recordings) gives the same results whatever order the runs are made in, so a student's
multi-core laptop can make them side by side. :func:`map_runs` does that in worker processes started
by Python's fork server (spawn where there is none), not forked from the caller: a forked Jupyter
kernel can inherit a held lock of OpenCV's or ZeroMQ's threads. The fork server imports robokit
once, so only the first pool of a session pays the import (about a second) when robokit is the
first to use the fork server (its preload list is the process's, :func:`map_runs` sets it to the
run's module); a spawned worker pays it every time. The object every run needs (a map, a world) is
sent to each worker once, not with every run, together with the caller's ``ROBOKIT_*`` settings.
With one worker, or fewer runs than :data:`MIN_RUNS`, the runs are made here, one after the other,
exactly as a plain loop would; the results are the same either way (the tests compare them).
:func:`iter_runs` gives the same results one by one as they come, for a caller that works on the
first ones while the workers make the next (lesson 02 builds its map from a tour's images as they are
rendered).

``ROBOKIT_WORKERS`` sets the number of workers (default: the CPUs this process may use). A plain
script that makes runs in workers needs the ``if __name__ == "__main__":`` guard, as every use of
:mod:`multiprocessing` does (workers import the script's top level); notebooks need nothing.
"""
from __future__ import annotations

import multiprocessing
import os
import pickle
import queue
import signal
import sys
import threading
import traceback
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable, Iterator, Sequence

import cv2

from .config import worker_count
from .progress import progress_bar
from .validation import as_callable, as_int

__all__ = ["MIN_RUNS", "worker_count", "map_runs", "iter_runs"]   # worker_count lives in config (the course build reads it too)

#: Fewer runs than this are made in this process: starting workers (each imports robokit, numpy
#: and OpenCV) costs more than a few runs save.
MIN_RUNS = 4

_SHARED: dict = {}    # in a worker: the run and the object every run needs, sent once by _receive


def _receive(blobs: dict, settings: dict, threads: int) -> None:
    # an interrupt is the caller's to handle (it stops the runs): a worker that died of it would
    # break the whole pool and lose every run in progress
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.environ.update(settings)            # the caller's ROBOKIT_* settings, not the fork server's
    os.environ["ROBOKIT_WORKERS"] = "1"     # a run that makes runs of its own makes them in place
    cv2.setNumThreads(threads)             # the workers already fill the cores: no OpenCV threads on top
    _SHARED.clear()
    for name, blob in blobs.items():       # "run", then "shared"
        try:                               # a failure here would break the pool before any run
            _SHARED[name] = pickle.loads(blob)
        except BaseException as exc:       # noqa: BLE001 - reported by every run instead
            _SHARED["error"] = _unreadable(name, exc)
            return


def _unreadable(name: str, exc: BaseException) -> TypeError:
    return TypeError(f"{name}: the worker processes could not rebuild it ({type(exc).__name__}: {exc}); "
                     f"its classes must be defined in an importable module, not in a notebook or with python -c")


def _run_shared(blob: bytes) -> bytes:
    """One run in a worker: everything goes in and comes out as bytes, and every failure comes back as
    an error the caller can rebuild, so no failure can kill a worker (the pool would break and lose
    every run in progress) or the executor's result thread."""
    if "error" in _SHARED:
        raise _SHARED["error"]
    try:
        task = pickle.loads(blob)
    except BaseException as exc:           # noqa: BLE001 - a task the worker cannot rebuild is named
        raise _unreadable("tasks", exc) from None
    try:
        return pickle.dumps(_SHARED["run"](_SHARED["shared"], task), protocol=pickle.HIGHEST_PROTOCOL)
    except KeyboardInterrupt:
        raise
    except BaseException as exc:           # noqa: BLE001 - sys.exit in a run, or an error that does not pickle
        raise _portable(exc) from None


def _portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives the trip to the caller, else a RuntimeError carrying its text and traceback."""
    if isinstance(exc, Exception):
        try:
            pickle.loads(pickle.dumps(exc))
            return exc
        except Exception:                  # noqa: BLE001 - any failure of the round trip
            pass
    trace = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    return RuntimeError(f"{type(exc).__name__} in a worker: {exc}\n{trace}")


def _pickled(value: Any, name: str) -> bytes:
    try:
        return pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    except (pickle.PicklingError, TypeError, AttributeError) as exc:
        raise TypeError(f"{name}: expected objects that pickle (they are sent to the workers), "
                        f"got {type(value).__name__}: {exc}") from exc


def _context(run: Callable):
    """The fork server's context, which imports ``run``'s module once for every later worker."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    module = getattr(run, "__module__", None)
    if isinstance(module, str) and module != "__main__":   # a library's or a lesson's module
        context.set_forkserver_preload([module])     # no effect once the server runs
    return context


def _require_importable(run: Callable) -> None:
    """Workers find ``run`` by its module and name: a lambda, a nested function or one defined in a
    notebook cell cannot be found there."""
    name = getattr(run, "__qualname__", "")
    module = getattr(run, "__module__", None)
    main = module == "__main__" and not getattr(sys.modules.get("__main__"), "__file__", None)
    if "<lambda>" in name or "<locals>" in name or main or module is None:
        raise TypeError(f"run: expected a function defined at the top of an importable module (workers "
                        f"import it by name), got {name or type(run).__name__!r} from {module!r}")


def map_runs(run: Callable, shared: Any, tasks: Sequence, *, workers: int | None = None, desc: str = "runs",
             unit: str = "run", progress: Callable | None = None) -> list:
    """``[run(shared, task) for task in tasks]``, made side by side in worker processes.

    Parameters
    ----------
    run : callable ``(shared, task) -> result``
        One independent run; a module-level function (workers import it by name). It must not
        depend on the order of the runs (seed each run from its task).
    shared : object
        What every run needs (picklable); sent to each worker once.
    tasks : sequence
        One picklable item per run.
    workers : int, optional
        Worker processes, 1 to 64 (default :func:`worker_count`); 1 makes the runs here.
    desc, unit : str
        The progress bar's text (:func:`robokit.progress.progress_bar`).
    progress : callable ``(done, total)``, optional
        Told as runs finish.

    Returns
    -------
    list
        The results in the order of ``tasks``.

    Raises
    ------
    TypeError, ValueError
        For a ``run`` or ``progress`` that is not callable, ``tasks`` that is not a sequence, a bad
        ``workers``; with workers, a ``run`` they cannot import (a lambda, a nested function, one
        defined in a notebook), a ``shared`` object or task that does not pickle, or one whose
        class the workers cannot import (defined in a notebook), or a result that cannot be
        rebuilt here. An error inside a run is raised here, the first in the order of ``tasks`` (as
        the plain loop would raise it); then, as when the caller is interrupted, no further run
        starts and the call returns once the runs in progress end. A worker that dies (killed, out
        of memory) is a ``RuntimeError``. With workers, an error that cannot travel back (it does
        not pickle, or it is ``SystemExit``) comes as a ``RuntimeError`` carrying its text and
        traceback.

    Notes
    -----
    Course convention (DESIGN.md, "Independent runs"); not from a paper. Each worker lets OpenCV use
    its share of this process's cores (:func:`worker_count` divided by the workers), since the
    workers already fill them.

    Examples
    --------
    >>> from robokit.parallel import map_runs
    >>> map_runs(divmod, 7, [1, 2, 3], workers=1)
    [(7, 0), (3, 1), (2, 1)]
    """
    return list(iter_runs(run, shared, tasks, workers=workers, desc=desc, unit=unit, progress=progress))


def iter_runs(run: Callable, shared: Any, tasks: Sequence, *, workers: int | None = None, desc: str = "runs",
              unit: str = "run", progress: Callable | None = None) -> Iterator:
    """The results of :func:`map_runs`, one by one in the order of ``tasks``, as the workers make them.

    A caller that consumes the results while the workers make the next ones (a map builder taking
    the frames of a recording as they are rendered) overlaps its own work with theirs.

    Parameters
    ----------
    run, shared, tasks, workers, desc, unit, progress
        As for :func:`map_runs`.

    Returns
    -------
    iterator
        ``run(shared, task)`` for each task, in order. The workers start at the first result asked
        for and stop once the iterator is asked past its last result (as a ``for`` loop does), at
        the first error, or when it is closed (``close()``, or ``with contextlib.closing(...)``);
        an iterator left unfinished keeps its workers until it is freed, so close it. Results not
        yet taken wait in this process (the workers do not wait for the caller).

    Raises
    ------
    TypeError, ValueError
        Bad arguments, at once (as :func:`map_runs`); errors of the runs, when their result is
        reached.

    Notes
    -----
    Course convention (DESIGN.md, "Independent runs"); not from a paper.

    Examples
    --------
    >>> from robokit.parallel import iter_runs
    >>> results = iter_runs(divmod, 7, [1, 2, 3], workers=1)
    >>> next(results), list(results)
    ((7, 0), [(3, 1), (2, 1)])
    """
    run = as_callable(run, "run", optional=False)
    progress = as_callable(progress, "progress")
    if isinstance(tasks, (str, bytes)) or not hasattr(tasks, "__iter__"):
        raise TypeError(f"tasks: expected a sequence of tasks, got {type(tasks).__name__}")
    tasks = list(tasks)
    workers = worker_count() if workers is None else as_int(workers, "workers", minimum=1, maximum=64)
    workers = min(workers, len(tasks))
    if workers <= 1 or len(tasks) < MIN_RUNS:
        return _in_place(run, shared, tasks, desc, unit, progress)
    _require_importable(run)
    settings = {k: v for k, v in os.environ.items() if k.startswith("ROBOKIT_")}
    # sent as bytes: a worker that cannot rebuild them reports it as the runs' error
    blobs = {"run": _pickled(run, "run"), "shared": _pickled(shared, "shared")}
    jobs = [_pickled(task, "tasks") for task in tasks]
    return _in_workers(run, blobs, settings, jobs, workers, desc, unit, progress)


def _in_place(run: Callable, shared: Any, tasks: list, desc: str, unit: str, progress: Callable | None) -> Iterator:
    """The runs made here, one after the other, exactly as a plain loop would."""
    with progress_bar(len(tasks), desc, unit=unit, callback=progress) as bar:
        for task in tasks:
            result = run(shared, task)
            bar.update()
            yield result


def _in_workers(run: Callable, blobs: dict, settings: dict, jobs: list, workers: int, desc: str, unit: str,
                progress: Callable | None) -> Iterator:
    """The runs made by a pool of ``workers`` processes, results rebuilt here in order.

    A :class:`~concurrent.futures.ProcessPoolExecutor`, not :class:`multiprocessing.pool.Pool`: the
    latter's ``terminate`` can kill a worker while it holds the lock of the results pipe (a large
    result half written), and then waits for that lock forever. The executor is never killed. A
    feeder thread keeps at most ``workers`` runs submitted and not finished (the executor would queue
    more, which could no longer be cancelled), so at the end, on an error, an interrupt or a closed
    iterator, no run starts after the stop and the call returns once the runs in progress end; the
    workers never wait for the caller. Each result is let go once it is handed over.
    """
    threads = max(1, worker_count() // workers)     # this process's share of the cores, per worker
    pool = ProcessPoolExecutor(workers, mp_context=_context(run), initializer=_receive,
                               initargs=(blobs, settings, threads))
    submitted: queue.SimpleQueue = queue.SimpleQueue()     # futures in task order, then None
    slots, stop = threading.Semaphore(workers), threading.Event()

    def feed() -> None:
        try:
            for job in jobs:
                slots.acquire()
                if stop.is_set():
                    return
                future = pool.submit(_run_shared, job)
                future.add_done_callback(lambda _: slots.release())
                submitted.put(future)
        except BrokenProcessPool as exc:   # a worker died while runs were being handed out
            failed = Future()
            failed.set_exception(exc)
            submitted.put(failed)
        except Exception as exc:           # noqa: BLE001 - the workers could not be started: never fewer results
            failed = Future()
            failed.set_exception(RuntimeError(
                f"run: the worker processes could not be started ({type(exc).__name__}: {exc}); if the caller "
                "is a script, it must start runs under `if __name__ == \"__main__\":` (the workers import it)"))
            failed.exception().__cause__ = exc
            submitted.put(failed)
        finally:
            submitted.put(None)

    feeder = threading.Thread(target=feed, name="robokit-runs-feeder", daemon=True)
    with progress_bar(len(jobs), desc, unit=unit, callback=progress) as bar:
        feeder.start()
        try:
            for future in iter(submitted.get, None):      # in order
                result = _rebuilt(future)
                bar.update()
                yield result
        finally:
            stop.set()
            slots.release()                               # a feeder waiting for a slot sees the stop
            feeder.join()
            pool.shutdown(wait=True, cancel_futures=True)


def _rebuilt(future: Future) -> Any:
    """A run's result, rebuilt here; a worker that died is named."""
    try:
        blob = future.result()
    except BrokenProcessPool as exc:
        raise RuntimeError("run: a worker process died during the runs (killed, out of memory, a crash in "
                           "compiled code, or a script that starts runs outside `if __name__ == \"__main__\":`); "
                           "the runs in progress are lost") from exc
    try:
        return pickle.loads(blob)
    except Exception as exc:                  # noqa: BLE001 - named, then the workers stop
        raise TypeError(f"run: its result could not be rebuilt here ({type(exc).__name__}: {exc})") from exc
