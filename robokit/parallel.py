"""Independent runs of an experiment in worker processes, results in order, the one way for robokit.

An experiment made of many independent, separately seeded runs (lesson 03's Table 2 trials)
gives the same results whatever order the runs are made in, so a student's multi-core laptop can
make them side by side. :func:`map_runs` does that in worker processes started by Python's fork
server (spawn where there is none), not forked from the caller: a forked Jupyter kernel can inherit
a held lock of OpenCV's or ZeroMQ's threads. The fork server imports robokit once, so only the first
pool of a session pays the import (about a second); a spawned worker pays it every time. The object
every run needs (a map, a world) is sent to each worker once, not with every run. With one worker, or
fewer runs than :data:`MIN_RUNS`, the runs are made here, one after the other, exactly as a plain
loop would; the results are the same either way (the tests compare them).

``ROBOKIT_WORKERS`` sets the number of workers (default: the CPUs this process may use).
"""
from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any, Callable, Sequence

from .config import available_cpus
from .progress import progress_bar
from .validation import check_callable, check_int

__all__ = ["MIN_RUNS", "worker_count", "map_runs"]

#: Fewer runs than this are made in this process: starting workers (each imports robokit, numpy
#: and OpenCV) costs more than a few runs save.
MIN_RUNS = 4

_SHARED: dict = {}    # in a worker: the object every run needs, sent once by _receive


def worker_count(environ: "os._Environ[str] | dict[str, str] | None" = None) -> int:
    """Number of worker processes for :func:`map_runs`.

    Parameters
    ----------
    environ : mapping, optional
        Environment to read (default :data:`os.environ`).

    Returns
    -------
    int
        ``ROBOKIT_WORKERS`` when set (the course build sets it to share the cores between the
        notebooks it runs at once), else the number of CPUs this process may run on.

    Raises
    ------
    ValueError
        If ``ROBOKIT_WORKERS`` is not a whole number from 1 to 64.

    Notes
    -----
    Course convention (DESIGN.md, "Independent runs"); not from a paper.

    Examples
    --------
    >>> worker_count({"ROBOKIT_WORKERS": "1"})
    1
    """
    env = os.environ if environ is None else environ
    raw = str(env.get("ROBOKIT_WORKERS", "")).strip()
    if raw:
        try:
            value = int(raw)
        except ValueError:
            value = 0
        if not 1 <= value <= 64:
            raise ValueError(f"ROBOKIT_WORKERS: expected a whole number from 1 to 64, got {raw!r}")
        return value
    return available_cpus()


def _receive(shared: Any) -> None:
    _SHARED["value"] = shared


def _run_shared(run: Callable, task: Any) -> Any:
    return run(_SHARED["value"], task)


def _context(run: Callable):
    """The fork server's context, which imports ``run``'s module once for every later worker."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    module = getattr(run, "__module__", None)
    if isinstance(module, str) and module.startswith("robokit."):
        context.set_forkserver_preload([module])     # no effect once the server runs
    return context


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
        For a ``run`` or ``progress`` that is not callable, or a bad ``workers``. An error inside a
        run is raised here, as the plain loop would raise it.

    Notes
    -----
    Course convention (DESIGN.md, "Independent runs"); not from a paper.

    Examples
    --------
    >>> from robokit.parallel import map_runs
    >>> map_runs(divmod, 7, [1, 2, 3], workers=1)
    [(7, 0), (3, 1), (2, 1)]
    """
    run = check_callable(run, "run", optional=False)
    progress = check_callable(progress, "progress")
    tasks = list(tasks)
    workers = worker_count() if workers is None else check_int(workers, "workers", minimum=1, maximum=64)
    workers = min(workers, len(tasks))
    results: list = [None] * len(tasks)
    with progress_bar(len(tasks), desc, unit=unit, callback=progress) as bar:
        if workers <= 1 or len(tasks) < MIN_RUNS:
            for k, task in enumerate(tasks):
                results[k] = run(shared, task)
                bar.update()
            return results
        context = _context(run)
        with ProcessPoolExecutor(workers, mp_context=context, initializer=_receive, initargs=(shared,)) as pool:
            futures = {pool.submit(_run_shared, run, task): k for k, task in enumerate(tasks)}
            for done in as_completed(futures):
                results[futures[done]] = done.result()
                bar.update()
    return results
