"""Independent runs in worker processes: same results, same order, same errors as a plain loop."""
import numpy as np
import pytest

from robokit.parallel import MIN_RUNS, map_runs, worker_count


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


def test_an_error_in_a_run_reaches_the_caller():
    with pytest.raises(ZeroDivisionError):
        map_runs(divmod, 1, [3, 2, 0, 1, 4], workers=2)
    with pytest.raises(ZeroDivisionError):
        map_runs(divmod, 1, [3, 0], workers=1)


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="run"):
        map_runs(None, 1, [1])
    with pytest.raises(ValueError, match="workers"):
        map_runs(divmod, 1, [1], workers=0)
    with pytest.raises(TypeError, match="progress"):
        map_runs(divmod, 1, [1], progress=3)


def test_table_2_runs_do_not_depend_on_the_number_of_workers(monkeypatch):
    # each run is seeded from its start and number: made side by side, they give the same table
    monkeypatch.setenv("ROBOKIT_FAST", "1")
    from robokit.navigation.corridor_experiment import corridor_map
    from robokit.navigation.corridor_trials import localization_trials
    setup = corridor_map(fast=True)
    a = localization_trials(setup, "amcl", trials=2, positions=[0, 1], max_distance=6.0, cache=False, workers=1)
    b = localization_trials(setup, "amcl", trials=2, positions=[0, 1], max_distance=6.0, cache=False, workers=2)
    for name in ("positions", "converged", "iterations", "distance", "error", "settled", "retrieval_error"):
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=getattr(a, name).dtype.kind == "f"), name
