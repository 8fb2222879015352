"""Independent runs in worker processes: same results, same order, same errors as a plain loop."""
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from robokit.parallel import MIN_RUNS, iter_runs, map_runs, worker_count


def test_worker_count_reads_the_environment():
    assert worker_count({"ROBOKIT_WORKERS": "3"}) == 3
    assert worker_count({}) >= 1
    for bad in ("0", "-2", "two", "1.5", "65"):
        with pytest.raises(ValueError, match="ROBOKIT_WORKERS"):
            worker_count({"ROBOKIT_WORKERS": bad})


def test_runs_in_workers_come_back_in_order_and_equal_the_loop():
    tasks = list(range(1, 2 * MIN_RUNS + 1))
    loop = [divmod(100, t) for t in tasks]
    done = []
    assert map_runs(divmod, 100, tasks, workers=1) == loop
    assert map_runs(divmod, 100, tasks, workers=2, progress=lambda k, n: done.append((k, n))) == loop
    assert done[-1] == (len(tasks), len(tasks))


@pytest.mark.parametrize("workers", [1, 2])
def test_results_one_by_one_come_in_order_and_errors_when_reached(workers):
    tasks = [5, 4, 3, 2, 1, 0, 7]
    results = iter_runs(divmod, 100, tasks, workers=workers)
    assert [next(results) for _ in range(5)] == [divmod(100, t) for t in tasks[:5]]   # before the bad run
    with pytest.raises(ZeroDivisionError):
        next(results)
    with pytest.raises(TypeError, match="tasks"):                 # bad arguments: at once, not when iterated
        iter_runs(divmod, 100, 7, workers=workers)


def test_closing_the_results_early_stops_the_workers(tmp_path):
    tasks = [(f"run{k}", 0.2, False) for k in range(40)]           # 4 s of runs on two workers
    results = iter_runs(_slow_fail, tmp_path, tasks, workers=2)
    assert next(results) == "run0"
    begun = len(list(tmp_path.iterdir()))
    results.close()                                # waits for the one or two runs in progress
    started = len(list(tmp_path.iterdir()))
    assert started <= begun + 2
    time.sleep(1.0)                                # a worker left running would start a run every 0.2 s
    assert len(list(tmp_path.iterdir())) == started < 40
    with pytest.raises(StopIteration):
        next(results)


def _large(shared, task):
    return bytes(shared) + bytes([task])


def test_closing_early_with_large_results_in_flight_does_not_hang():
    # multiprocessing's Pool.terminate killed a worker halfway through writing a large result, then
    # waited forever for the lock it held (a lesson's rendered frames, closed after the first batch)
    script = ("from robokit.parallel import iter_runs\n"
              "from test_parallel import _large\n"
              "for _ in range(30):\n"
              "    results = iter_runs(_large, 2_000_000, list(range(8)), workers=2)\n"
              "    assert len(next(results)) == 2_000_001\n"
              "    results.close()\n"
              "print('closed')\n")
    path = os.pathsep.join(filter(None, [str(Path(__file__).parent), os.environ.get("PYTHONPATH")]))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": path})
    assert done.returncode == 0 and done.stdout.strip() == "closed", done.stderr[-2000:]


def _interrupt_handler(shared, task):
    import signal
    return signal.getsignal(signal.SIGINT) == signal.SIG_IGN


def test_workers_leave_an_interrupt_to_the_caller():
    # a kernel interrupt reaches the workers too: one that died of it would be replaced and its run
    # lost, and a caller still taking results would wait for that run forever
    assert all(map_runs(_interrupt_handler, None, list(range(MIN_RUNS)), workers=2))


def _slow_fail(folder, task):
    """A run for the workers: note that it started, wait, then fail if told to."""
    name, wait, fail = task
    (folder / name).touch()
    time.sleep(wait)
    if fail:
        raise ValueError(name)
    return name


def test_an_error_in_a_run_reaches_the_caller():
    with pytest.raises(ZeroDivisionError):
        map_runs(divmod, 1, [3, 2, 0, 1, 4], workers=2)
    with pytest.raises(ZeroDivisionError):
        map_runs(divmod, 1, [3, 0], workers=1)


def test_the_first_error_in_task_order_is_raised_as_by_the_loop(tmp_path):
    # run "b" fails late, run "c" early: the loop would raise "b", and so do the workers
    tasks = [("a", 0.0, False), ("b", 0.6, True), ("c", 0.0, True), ("d", 0.0, False)]
    for workers in (1, 2):
        with pytest.raises(ValueError, match="^b$"):
            map_runs(_slow_fail, tmp_path, tasks, workers=workers)


def test_a_failed_run_stops_the_workers_at_once(tmp_path):
    # the first run fails; the other 30 would take a second each: only the two runs in progress
    # beside it (one per worker) are made, and the error arrives once they end
    tasks = [("first", 0.0, True)] + [(f"run{k}", 1.0, False) for k in range(30)]
    with pytest.raises(ValueError, match="first"):
        map_runs(_slow_fail, tmp_path, tasks, workers=2)
    made = len(list(tmp_path.iterdir()))
    time.sleep(1.5)                               # a worker left running would go on starting runs
    assert len(list(tmp_path.iterdir())) == made <= 3


def test_what_the_workers_cannot_receive_is_named():
    with pytest.raises(TypeError, match="run"):
        map_runs(lambda shared, task: task, 1, [1, 2, 3, 4], workers=2)
    with pytest.raises(TypeError, match="shared"):
        map_runs(divmod, threading.Lock(), [1, 2, 3, 4], workers=2)
    with pytest.raises(TypeError, match="tasks"):
        map_runs(divmod, 1, 5)


def test_what_the_workers_cannot_rebuild_is_named_not_retried_forever():
    # a class defined in a script run with python -c (or in a notebook) pickles here but cannot be
    # found by the workers: the runs fail with a named error instead of restarting workers forever
    import subprocess
    import sys
    code = ("from robokit.parallel import map_runs\n"
            "class Local:\n    pass\n"
            "for shared, tasks in ((Local(), [1, 2, 3, 4]), (1, [Local() for _ in range(4)])):\n"
            "    try:\n        map_runs(divmod, shared, tasks, workers=2)\n"
            "    except TypeError as exc:\n        print('named:', str(exc).split(':')[0])\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.split("\n")[:2] == ["named: shared", "named: tasks"], out.stdout + out.stderr[-2000:]


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="run"):
        map_runs(None, 1, [1])
    with pytest.raises(ValueError, match="workers"):
        map_runs(divmod, 1, [1], workers=0)
    with pytest.raises(TypeError, match="progress"):
        map_runs(divmod, 1, [1], progress=3)


@pytest.mark.slow    # a lesson experiment built whole; make check
def test_table_2_runs_do_not_depend_on_the_number_of_workers(monkeypatch):
    # each run is seeded from its start and number: made side by side, they give the same table
    monkeypatch.setenv("ROBOKIT_FAST", "1")
    from robocourse.lessons.corridor_localization.experiment import corridor_map
    from robocourse.lessons.corridor_localization.trials import localization_trials
    setup = corridor_map(fast=True)
    for method in ("amcl", "ours"):
        a = localization_trials(setup, method, trials=2, positions=[0, 1], max_distance=6.0, cache=False, workers=1)
        b = localization_trials(setup, method, trials=2, positions=[0, 1], max_distance=6.0, cache=False, workers=2)
        for name in ("positions", "converged", "iterations", "distance", "error", "settled", "retrieval_error"):
            assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=getattr(a, name).dtype.kind == "f"), \
                (method, name)


def _opencv_threads(shared, task):
    import cv2
    return cv2.getNumThreads()


def test_workers_leave_the_cores_to_each_other(monkeypatch):
    # two workers on this machine's CPUs: OpenCV inside each uses its share, not every core again
    threads = map_runs(_opencv_threads, None, list(range(MIN_RUNS)), workers=2)
    assert set(threads) == {max(1, worker_count() // 2)}
    # a notebook of a course build is given fewer cores than the machine has: its workers share those
    monkeypatch.setenv("ROBOKIT_WORKERS", "2")
    assert set(map_runs(_opencv_threads, None, list(range(MIN_RUNS)), workers=2)) == {1}


def test_navigation_runs_do_not_depend_on_the_number_of_workers(monkeypatch):
    # lesson 02's runs are each seeded by their number: side by side they follow the same paths
    from robocourse.lessons.omni_localization.experiment import office_setup
    from robocourse.lessons.omni_localization.navigation import navigation_trials
    setup = office_setup(fast=True)
    runs = {}
    for workers in ("1", "2"):
        monkeypatch.setenv("ROBOKIT_WORKERS", workers)
        runs[workers] = navigation_trials(setup, MIN_RUNS, n_path_nodes=3, max_time=6.0, cache=False).runs
    for a, b in zip(runs["1"], runs["2"]):
        assert np.array_equal(a.true_poses, b.true_poses) and np.array_equal(a.fixes, b.fixes)


class _Unrebuildable(Exception):
    """An error whose constructor takes two arguments: it pickles but does not unpickle."""

    def __init__(self, a, b):
        super().__init__(f"{a} and {b}")


class _BadResult:
    def __reduce__(self):
        return (_refuse, ())


def _refuse():
    raise ValueError("cannot rebuild")


def _awkward(shared, task):
    """Runs that end in ways a worker pool cannot carry back as they are."""
    if task == "unrebuildable":
        raise _Unrebuildable(1, 2)
    if task == "exit":
        raise SystemExit(3)
    if task == "result":
        return _BadResult()
    return task


@pytest.mark.parametrize("task, error, text", [("unrebuildable", RuntimeError, "_Unrebuildable"),
                                               ("exit", RuntimeError, "SystemExit"),
                                               ("result", TypeError, "result")])
def test_a_run_that_ends_badly_is_an_error_not_a_hang(task, error, text):
    # each of these used to leave the pool waiting forever for a lost run
    started = time.perf_counter()
    with pytest.raises(error, match=text):
        map_runs(_awkward, None, ["fine", task, "fine", "fine"], workers=2)
    assert time.perf_counter() - started < 60


def test_a_script_without_a_main_guard_gets_an_error_not_fewer_results(tmp_path):
    """Workers import the calling script; one that starts runs at import (no ``if __name__ ==
    "__main__":``) once made the feeder stop early, and the caller got an empty list (which a lesson
    then cached as an empty recording)."""
    script = tmp_path / "no_guard.py"
    script.write_text("from robokit.parallel import map_runs\n"
                      "print('results', len(map_runs(divmod, 100, list(range(1, 9)), workers=2)))\n")
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env,
                          cwd=tmp_path)
    assert "results 0" not in done.stdout, done.stdout
    assert done.returncode != 0 or done.stdout.strip() == "results 8", (done.stdout, done.stderr[-2000:])
    if done.returncode != 0:
        assert "__main__" in done.stderr, done.stderr[-2000:]
