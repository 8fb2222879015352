"""``robokit course build``: run every lesson and solution notebook and write the course site."""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Callable, Sequence

from .execute import NotebookRun, run_notebook
from .site import install_mathjax, notebook_page, write_index

__all__ = ["discover", "build_course", "format_summary"]

#: Directories whose notebooks the course build executes, in site order.
BUILD_DIRS = ("lessons", "solutions")
#: Directories whose notebooks the test-suite executes.
ALL_DIRS = ("lessons", "solutions", "assignments")


def discover(root: str | Path, dirs: Sequence[str] = BUILD_DIRS) -> list[Path]:
    """Return the notebooks under ``root/<dir>`` for each of ``dirs``, sorted by name.

    Checkpoints (``.ipynb_checkpoints``) are ignored.
    """
    root = Path(root)
    found = []
    for d in dirs:
        found += sorted(p for p in (root / d).glob("*.ipynb") if ".ipynb_checkpoints" not in p.parts)
    return found


def format_summary(runs: Sequence[NotebookRun], root: Path) -> str:
    """Return a plain-text table of notebook, status and run time."""
    names = [str(r.path.relative_to(root)) if r.path.is_relative_to(root) else str(r.path) for r in runs]
    width = max([len(n) for n in names] + [8])
    lines = [f"{'notebook':<{width}}  {'status':<8}  {'time':>8}", "-" * (width + 20)]
    for name, run in zip(names, runs):
        lines.append(f"{name:<{width}}  {run.status:<8}  {run.seconds:7.1f}s")
    lines.append(f"{sum(r.ok for r in runs)} of {len(runs)} notebooks ok")
    return "\n".join(lines)


def build_course(root: str | Path = ".", out: str | Path = "build/course", *, jobs: int | None = None,
                 timeout: float = 900, fast: bool = False, notebooks: Sequence[Path] | None = None,
                 log: Callable[[str], None] = print,
                 extra_steps: Sequence[Callable[[Path, Path], tuple[bool, str]]] = ()) -> int:
    """Execute the course notebooks in parallel, write the HTML site and return an exit code.

    Parameters
    ----------
    root : path, default "."
        Repository root (holds ``lessons/`` and ``solutions/``).
    out : path, default "build/course"
        Site directory; created if needed.
    jobs : int, optional
        Notebooks run at once; defaults to the number of available cores.
    timeout : float, default 900
        Per-notebook wall-clock limit in seconds.
    fast : bool, default False
        Run with ``ROBOKIT_FAST=1``.
    notebooks : sequence of Path, optional
        Run these instead of discovering ``lessons/`` and ``solutions/``.
    log : callable, default print
        Receives progress lines and the summary table.
    extra_steps : sequence of callables, optional
        Called as ``step(root, out)`` after the notebooks; each returns ``(ok, html_fragment)``
        appended to the index (used by the grader to add ``grades.csv``).

    Returns
    -------
    int
        0 if every notebook (and every extra step) succeeded, 1 otherwise.

    Notes
    -----
    Course tooling (issue "Course platform"); not from a paper.
    """
    root = Path(root).resolve()
    out = Path(out)
    out = (out if out.is_absolute() else root / out).resolve()
    (out / "executed").mkdir(parents=True, exist_ok=True)
    paths = [Path(p).resolve() for p in notebooks] if notebooks else discover(root)
    if not paths:
        log(f"no notebooks found under {root} in {', '.join(BUILD_DIRS)}")
        return 1
    if not jobs:
        jobs = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)

    def one(path: Path) -> NotebookRun:
        run = run_notebook(path, timeout=timeout, fast=fast,
                           output=out / "executed" / f"{path.parent.name}-{path.name}")
        log(f"  {run.status:<8} {run.seconds:6.1f}s  {path.relative_to(root) if path.is_relative_to(root) else path}")
        return run

    log(f"building the course site from {len(paths)} notebooks with {jobs} parallel jobs "
        f"({'fast' if fast else 'full'} mode) ...")
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        runs = list(pool.map(one, paths))
    local_mathjax = install_mathjax(out)
    for run in runs:
        notebook_page(run, out, local_mathjax=local_mathjax)
    ok = all(r.ok for r in runs)
    fragments = []
    for step in extra_steps:
        step_ok, fragment = step(root, out)
        ok = ok and step_ok
        fragments.append(fragment)
    index = write_index(runs, out, root, "".join(fragments))
    log("")
    log(format_summary(runs, root))
    log(f"site: {index}")
    return 0 if ok else 1
