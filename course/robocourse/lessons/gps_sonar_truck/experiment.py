"""Lesson 05's experiment: Hamid et al.'s waypoint courses driven again and again, seeded and cached.

The paper (Hamid et al. 2009) drives its truck through waypoint courses with obstacles; the lesson
repeats that on seeded random courses (:func:`robokit.outdoor.random_course`), one mission each
(:func:`robokit.outdoor.simulate`), and tabulates them with :func:`robokit.outdoor.summarize_runs`.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
"""
from __future__ import annotations

from typing import Any

from robocourse.source import code_version_of
from robokit.cache import (cache_dir, cache_key, read_arrays, record_names, records_from_arrays, records_to_arrays,
                           write_arrays)
from robokit.outdoor import RunResult, random_course, simulate
from robokit.progress import progress_bar
from robokit.validation import as_callable, as_int, as_mapping, describe

__all__ = ["run_courses"]


def run_courses(seeds: Any, *, firing: str = "chained", course_options: dict | None = None,
                progress: Any = None, cache: bool = True, **options: Any) -> list[RunResult]:
    """Simulate one mission per seed on :func:`robokit.outdoor.random_course` ``(seed)``.

    Parameters
    ----------
    seeds : iterable of int
    firing : {"chained", "free"}
    course_options : dict, optional
        Keyword arguments of :func:`robokit.outdoor.random_course`.
    progress : callable, optional
        ``progress(i, n)`` after each run, besides the progress bar (:func:`robokit.progress.progress_bar`).
    cache : bool, default True
        Load from / save to ``robokit.cache.cache_dir("outdoor")``, keyed by the seeds, every option and
        the code (:func:`robocourse.source.code_version_of`); a corrupt or stale cache file is rebuilt,
        never loaded. Options that are not plain data (a custom ``truck``) are not cached.
    **options
        Passed to :func:`robokit.outdoor.simulate`.

    Returns
    -------
    list of RunResult

    Raises
    ------
    ValueError, TypeError
        For a negative or non-integer seed, or bad options (see :func:`robokit.outdoor.simulate`).

    Notes
    -----
    The seeded repetition of Hamid et al.'s experiment (2009) used by the lesson; course
    ``s`` is driven with ``simulate(..., seed=10_000 + s)``; deterministic, hence cacheable
    (DESIGN.md, "Caching").

    Examples
    --------
    >>> small = {"n_waypoints": 1, "size": (30.0, 20.0), "n_obstacles": 2}
    >>> [(r.reached, r.collisions) for r in run_courses([0], course_options=small)]
    [(1, 0)]
    """
    try:
        items = None if isinstance(seeds, (str, bytes)) else list(seeds)
    except TypeError:   # not iterable (a number, a 0-d array, None)
        items = None
    if items is None:
        raise TypeError(f"seeds: expected an iterable of non-negative integers, got {describe(seeds)}")
    seeds = [as_int(s, f"seeds[{i}]", minimum=0) for i, s in enumerate(items)]
    course_options = as_mapping(course_options, "course_options")
    progress = as_callable(progress, "progress")
    target = meta = None
    if cache:
        meta = {"seeds": seeds, "firing": firing, "course_options": course_options or {}, "options": options,
                "code": code_version_of(__name__)}
        try:
            target = cache_dir("outdoor") / f"courses-{cache_key(**meta)}.npz"
        except TypeError:           # an option that is not plain data: run without the cache
            target = None
    if target is not None:
        data = read_arrays(target, record_names(RunResult, len(seeds)), meta)
        if data is not None:
            return records_from_arrays(data, RunResult, len(seeds))
    out = []
    with progress_bar(len(seeds), f"courses ({firing})", unit="course", callback=progress) as bar:
        for s in seeds:
            course = random_course(s, **(course_options or {}))
            out.append(simulate(course, seed=10_000 + s, firing=firing, **options))
            bar.update()
    if target is not None:
        write_arrays(target, records_to_arrays(out, RunResult), meta)
    return out
