"""``robocourse build``: run every lesson and solution notebook, then write the two course sites.

Layout of one build. The two sites go where asked (by default under ``build/``); everything else
stays in the repository's private ``build/`` whatever the sites' folders are::

    build/course/           the student site: lessons, blank assignments, library reference, references
    build/instructor/       the instructor site: that plus solutions, grading self-check, build report
    build/executed/         the executed notebooks (lessons/NN_slug.ipynb, solutions/NN_slug.ipynb) and each
                            notebook's last run time (timings-full.json, timings-fast.json)
    build/reports/          grades.csv of the grading self-check
    build/.site/<site>/     Sphinx's sources (src/), output before it is moved (html/), doctrees,
                            myst-nb's jupyter_execute/ and sphinx-warnings.txt, per site
"""
from __future__ import annotations

import html
import json
import math
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from pathlib import Path
from typing import Callable, Sequence

from robokit.config import available_cpus, worker_count
from robocourse.site.book import (API_MODULES, SITES, BookPage, SiteBuild, site_out_problem, site_tool_problems, sphinx_build,
                   write_sources)
from robocourse.site.execute import NotebookRun, run_notebook

__all__ = ["discover", "build_course", "run_notebooks", "write_sites", "format_summary", "build_report_page"]

#: Directories whose notebooks the course build executes, in site order.
BUILD_DIRS = ("lessons", "solutions")
#: Directories whose notebooks the test-suite executes.
ALL_DIRS = ("lessons", "solutions", "assignments")

#: An extra step of the build: ``step(root, workdir) -> (ok, page)``; the page joins the
#: instructor site (``robocourse.grading.selfcheck.course_grading_step`` is the one the CLI adds).
ExtraStep = Callable[[Path, Path], "tuple[bool, BookPage]"]


def discover(root: str | Path, dirs: Sequence[str] = BUILD_DIRS) -> list[Path]:
    """Return the notebooks under ``root/<dir>`` for each of ``dirs``, sorted by name.

    Checkpoints (``.ipynb_checkpoints``) are ignored.
    """
    root = Path(root)
    found = []
    for d in dirs:
        found += sorted(p for p in (root / d).glob("*.ipynb") if ".ipynb_checkpoints" not in p.parts)
    return found


def _name(run: NotebookRun, root: Path) -> str:
    return str(run.path.relative_to(root)) if run.path.is_relative_to(root) else str(run.path)


def format_summary(runs: Sequence[NotebookRun], root: Path) -> str:
    """Return a plain-text table of notebook, status and run time."""
    names = [_name(r, root) for r in runs]
    width = max([len(n) for n in names] + [8])
    lines = [f"{'notebook':<{width}}  {'status':<8}  {'time':>8}", "-" * (width + 20)]
    for name, run in zip(names, runs):
        lines.append(f"{name:<{width}}  {run.status:<8}  {run.seconds:7.1f}s")
    lines.append(f"{sum(r.ok for r in runs)} of {len(runs)} notebooks ok")
    return "\n".join(lines)


def build_report_page(runs: Sequence[NotebookRun], root: Path, *, fast: bool) -> BookPage:
    """The instructor site's build report: status and run time of every notebook, full error tails.

    Parameters
    ----------
    runs : sequence of NotebookRun
    root : Path
        Repository root (notebook names are shown relative to it).
    fast : bool
        Whether the notebooks ran in fast mode (said on the page).

    Returns
    -------
    BookPage
        ``instructor/build``.
    """
    rows = "".join(f"| `{_name(r, root)}` | {'ok' if r.ok else '**' + r.status + '**'} | {r.seconds:.1f} s |\n"
                   for r in runs)
    errors = "".join(f"\n## `{_name(r, root)}`: {r.status}\n\n<pre>{html.escape(r.error)}</pre>\n"
                     for r in runs if not r.ok)
    total = sum(r.seconds for r in runs)
    text = (f"# Build report\n\n{sum(r.ok for r in runs)} of {len(runs)} notebooks ran without error "
            f"({'fast mode' if fast else 'full size'}; {total:.0f} s of notebook time in all).\n\n"
            "| notebook | status | run time |\n|---|---|---|\n" + rows + errors)
    return BookPage("instructor/build", text)


def _failure_note(run: NotebookRun) -> str:
    if run.ok:
        return ""
    return (f"This notebook did not run to the end when the site was built ({run.status}); the "
            "outputs below stop where it stopped.")


def build_course(root: str | Path = ".", out: str | Path = "build/course", *,
                 instructor_out: str | Path = "build/instructor", jobs: int | None = None,
                 timeout: float = 900, fast: bool = False, notebooks: Sequence[Path] | None = None,
                 log: Callable[[str], None] = print, extra_steps: Sequence[ExtraStep] = (),
                 api_reference: bool = True) -> int:
    """Execute the course notebooks in parallel, build the student and instructor sites, return an exit code.

    Parameters
    ----------
    root : path, default "."
        Repository root (holds ``lessons/``, ``solutions/``, ``assignments/`` and ``book/``).
    out : path, default "build/course"
        The student site (relative paths are from ``root``). It may be published.
    instructor_out : path, default "build/instructor"
        The instructor site, with the solutions: keep it private. The executed notebooks, the
        grading report and Sphinx's work stay in ``root/build/`` whatever these two are.
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
        Called as ``step(root, workdir)`` after the notebooks; each returns ``(ok, page)`` and the
        page joins the instructor site (the grading self-check).
    api_reference : bool, default True
        Include the library reference (generated from robokit's docstrings; about half of the
        site's build time).

    Returns
    -------
    int
        0 if every notebook, every extra step and both sites succeeded, 1 otherwise, 2 if nothing was
        run (a site tool or ``book/`` missing, an output folder that cannot be replaced).

    Notes
    -----
    Course tooling (DESIGN.md, "Course build"); not from a paper.
    """
    root = Path(root).resolve()
    work = root / "build"
    outs = {name: (p if p.is_absolute() else root / p).resolve()
            for name, p in (("course", Path(out)), ("instructor", Path(instructor_out)))}
    problems = site_tool_problems(root / "book")
    problems += [p for site in outs.values() for p in [site_out_problem(site, work / ".site")] if p]
    if outs["course"].is_relative_to(outs["instructor"]) or outs["instructor"].is_relative_to(outs["course"]):
        problems.append(f"instructor_out: expected a folder apart from the student site {str(outs['course'])!r}, "
                        f"got {str(outs['instructor'])!r}")
    if problems:
        for problem in problems:
            log(f"robocourse build: {problem}")
        return 2
    executed = work / "executed"
    paths = [Path(p).resolve() for p in notebooks] if notebooks else discover(root)
    if not paths:
        log(f"no notebooks found under {root} in {', '.join(BUILD_DIRS)}")
        return 1
    runs = run_notebooks(paths, executed, root=root, jobs=jobs, timeout=timeout, fast=fast, log=log)
    ok = all(r.ok for r in runs)
    pages = [build_report_page(runs, root, fast=fast)]
    for step in extra_steps:
        step_ok, page = step(root, work / "reports")
        ok = ok and step_ok
        pages.append(page)
    sites = write_sites(root, runs, outs, pages, log=log, api_modules=API_MODULES if api_reference else (),
                        work=work / ".site")
    ok = ok and all(s.ok for s in sites.values())
    log("")
    log(format_summary(runs, root))
    for name, site in sites.items():
        n_warn = len(site.warnings.splitlines())
        log(f"{name} site: {site.index} ({'ok' if site.ok else 'FAILED'}, {site.seconds:.1f} s, "
            f"{n_warn} Sphinx warning lines{'' if not n_warn else ' in build/.site/' + name + '/sphinx-warnings.txt'})")
        if not site.ok:
            log(site.warnings[-3000:])
    return 0 if ok else 1


def run_notebooks(paths: Sequence[Path], executed: Path, *, root: Path, jobs: int | None = None,
                  timeout: float = 900, fast: bool = False, log: Callable[[str], None] = print) -> list[NotebookRun]:
    """Execute ``paths``, ``jobs`` at a time, each in a fresh kernel (:func:`run_notebook`).

    Order: a solution starts only once its lesson (``lessons/`` notebook of the same name, when it
    is among ``paths``) has finished, so it finds the datasets the lesson cached instead of building
    them a second time beside it; among the notebooks ready to start, the longest by the last build's
    times (``executed/timings-full.json`` or ``timings-fast.json``, written afterwards) or, in a
    full build, by the time it declares for an empty cache in its metadata (``robokit.cold_seconds``,
    docs/LESSON_GUIDE.md), whichever is longer, goes first; then the order of ``paths``. So a fresh
    clone, and a build after a code change (whose caches are stale) after a warm one, start the
    slow lessons first.

    Parameters
    ----------
    paths : sequence of Path
        The notebooks.
    executed : Path
        Folder of the executed copies, under their own folder and name (``lessons/01_visual_slam.ipynb``),
        so a page keeps its notebook's name.
    root : Path
        Repository root (progress lines name notebooks relative to it).
    jobs : int, optional
        Notebooks at once; the number of available cores by default (never more than there are
        notebooks). Each notebook gets the cores divided by that number (at least 1, at most the
        caller's own ``ROBOKIT_WORKERS``) as ``ROBOKIT_WORKERS`` for its independent runs
        (:mod:`robokit.parallel`), so that the build never runs more worker processes than cores,
        and as the cap of its BLAS and OpenCV threads.
    timeout : float, default 900
        Per-notebook wall-clock limit in seconds.
    fast : bool, default False
        Run with ``ROBOKIT_FAST=1``.
    log : callable, default print
        Receives one progress line per notebook.

    Returns
    -------
    list of NotebookRun
        In the order of ``paths``.
    """
    if jobs is not None and (not isinstance(jobs, int) or jobs < 1):
        raise ValueError(f"jobs: expected a positive number of notebooks at once, got {jobs!r}")
    cpus = available_cpus()
    jobs = min(jobs or cpus, max(1, len(paths)))
    # the notebooks running at once share the cores between them, and never get more than the caller allows
    workers = min(max(1, cpus // jobs), worker_count())
    executed.mkdir(parents=True, exist_ok=True)

    def one(path: Path) -> NotebookRun:
        run = run_notebook(path, timeout=timeout, fast=fast, output=executed / path.parent.name / path.name,
                           workers=workers)
        log(f"  {run.status:<8} {run.seconds:6.1f}s  {path.relative_to(root) if path.is_relative_to(root) else path}")
        return run

    timings = executed / f"timings-{'fast' if fast else 'full'}.json"
    paths = list(paths)
    names = [f"{p.parent.name}/{p.name}" for p in paths]
    try:
        recorded = {str(k): float(v) for k, v in json.loads(timings.read_text()).items()}
    except (OSError, ValueError, TypeError, AttributeError):
        recorded = {}                         # no earlier build (or an unreadable record): declared times only
    # the longer of the declared cold time and the last build's (which may have been warm)
    expected = {n: max([t for t in (0.0 if fast else _declared_seconds(p), recorded.get(n, 0.0))
                        if math.isfinite(t)] + [0.0]) for n, p in zip(names, paths)}
    lesson_of = {i: names.index(f"lessons/{p.name}") for i, p in enumerate(paths)
                 if p.parent.name == "solutions" and f"lessons/{p.name}" in names}
    log(f"running {len(paths)} notebooks with {jobs} parallel jobs ({'fast' if fast else 'full'} mode) ...")
    runs: dict[int, NotebookRun] = {}
    waiting, running = list(range(len(paths))), {}
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        while waiting or running:
            ready = [i for i in waiting if lesson_of.get(i, -1) in runs or i not in lesson_of]
            ready.sort(key=lambda i: (-expected.get(names[i], 0.0), i))
            for i in ready[:jobs - len(running)]:
                waiting.remove(i)
                running[pool.submit(one, paths[i])] = i
            finished, _ = wait(list(running), return_when=FIRST_COMPLETED)
            for future in finished:
                runs[running.pop(future)] = future.result()
    out = [runs[i] for i in range(len(paths))]
    try:
        timings.write_text(json.dumps({**recorded, **{n: round(r.seconds, 1) for n, r in zip(names, out)}}, indent=1))
    except OSError:
        pass                                  # the order of the next build is only a preference
    return out


def _declared_seconds(path: Path) -> float:
    """``metadata.robokit.cold_seconds`` of a notebook (0 when absent or unreadable)."""
    try:
        value = json.loads(path.read_text(encoding="utf-8"))["metadata"]["robokit"]["cold_seconds"]
        return float(value) if isinstance(value, (int, float)) and value >= 0 else 0.0
    except (OSError, ValueError, KeyError, TypeError):
        return 0.0


def write_sites(root: Path, runs: Sequence[NotebookRun], outs: dict[str, Path], pages: Sequence[BookPage] = (),
                *, log: Callable[[str], None] = print, api_modules: Sequence[str] = API_MODULES,
                work: Path | None = None) -> dict[str, SiteBuild]:
    """Write the Sphinx sources of both sites from the executed ``runs`` and render them side by side.

    Parameters
    ----------
    root : Path
        Repository root (``book/``, ``assignments/``; the work folder is ``root/build/.site``).
    runs : sequence of NotebookRun
        The executed lessons and solutions (a failed run's page shows what ran, with a warning).
    outs : dict
        Where each site of :data:`~robocourse.site.book.SITES` goes (``"course"``, ``"instructor"``).
    pages : sequence of BookPage
        Pages of the instructor site only (build report, grading self-check).
    log : callable, default print
    api_modules : sequence of str
        Modules of the library reference (empty: none).
    work : Path, optional
        The private work folder (sources, Sphinx output before it moves); ``root/build/.site``.

    Returns
    -------
    dict
        Site name -> :class:`~robocourse.site.book.SiteBuild`.
    """
    missing = set(SITES) - set(outs)
    if missing:
        raise ValueError(f"outs: expected a folder for every site {sorted(SITES)}, missing {sorted(missing)}")
    lessons = [r for r in runs if r.path.parent.name == "lessons"]
    solutions = [r for r in runs if r.path.parent.name == "solutions"]
    assignments = discover(root, ("assignments",))
    work = Path(work) if work is not None else root / "build" / ".site"
    # an executed copy if there is one, else the source notebook; a failed run's page gets a warning
    shown = {run.path: run.executed if run.executed is not None and run.executed.exists() else run.path
             for run in runs}
    notes = {shown[run.path]: _failure_note(run) for run in runs if not run.ok}
    for name, instructor in SITES.items():
        write_sources(work / name / "src", root / "book", lessons=[shown[r.path] for r in lessons],
                      assignments=assignments, solutions=[shown[r.path] for r in solutions] if instructor else (),
                      pages=pages if instructor else (), instructor=instructor, api_modules=api_modules,
                      notes=notes)
    log("rendering the student and instructor sites with Sphinx ...")
    with ThreadPoolExecutor(max_workers=len(SITES)) as pool:
        futures = {name: pool.submit(sphinx_build, work / name / "src", outs[name], instructor=instructor)
                   for name, instructor in SITES.items()}
        return {name: f.result() for name, f in futures.items()}
