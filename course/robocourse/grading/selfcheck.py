"""Grade the course's own notebooks: every solution must score full marks, every blank
assignment zero. Used by ``robocourse build`` (writes ``grades.csv`` into the site) and by the
test-suite, so a broken exercise definition or a stale assignment is caught before students are."""
from __future__ import annotations

import csv
import html
from pathlib import Path
from typing import Sequence

from robocourse.site.book import BookPage
from robocourse.lessons import assignments
from robocourse.grading.grader import grade_batch
from robocourse.grading.sandbox import Limits
from robokit.config import worker_count
from robokit.parallel import map_runs
from robokit.validation import as_int

__all__ = ["grade_course", "course_grading_step"]


def grade_course(root: str | Path, *, seed: str = "course-selfcheck", jobs: int | None = None,
                 limits: Limits = Limits(wall_seconds=600, cpu_seconds=600),
                 only: Sequence[str] | None = None) -> list[dict]:
    """Grade ``solutions/NN.ipynb`` and ``assignments/NN.ipynb`` for every assignment with exercises.

    Parameters
    ----------
    root : str or Path
        The course repository.
    seed : str, default "course-selfcheck"
        The grading seed (the cases every notebook is graded on).
    jobs : int, optional
        Assignments graded at once, each in a worker process of :func:`robokit.parallel.map_runs`
        (default: two, or :func:`~robokit.config.worker_count` if smaller; every sandboxed job
        counts against the user's process limit, :class:`~robocourse.grading.sandbox.Limits`).
    limits : Limits
        Per-notebook limits of the sandbox.
    only : sequence of str, optional
        Grade these assignments (their slugs, e.g. ``"03_corridor_localization"``) instead of all.

    Returns
    -------
    list of dict
        One row per notebook: ``assignment``, ``kind`` (solution/assignment), ``total``, ``max``,
        ``expected``, ``ok`` (solution at full marks, assignment at zero, no crash), ``note`` (the
        first message of each exercise that went wrong, whole) and ``log`` (the worker's full log
        with the submission's flags, reason and cell errors).

    Raises
    ------
    ValueError, TypeError
        For ``jobs`` that is not a positive whole number, or ``only`` naming no assignment of the
        course.
    GradingError
        For a host that refuses the sandbox (:func:`~robocourse.grading.grader.grade_batch`).
    """
    root = Path(root)
    jobs = min(2, worker_count()) if jobs is None else as_int(jobs, "jobs", minimum=1)
    slugs = list(assignments())
    if only is not None:
        if isinstance(only, (str, bytes)) or not all(isinstance(slug, str) for slug in only):
            raise TypeError(f"only: expected a sequence of assignment slugs, got {only!r}")
        unknown = [slug for slug in only if slug not in slugs]
        if unknown:
            raise ValueError(f"only: expected assignments of the course ({', '.join(slugs)}), got {unknown}")
        slugs = [slug for slug in slugs if slug in only]
    # one batch per assignment (its solution and blank), ``jobs`` batches at a time, each in a worker
    # process: preparing each notebook's cases is Python work that threads would take turns at
    per_slug = map_runs(_grade_assignment, (root, seed, limits), slugs, workers=jobs, desc="grading self-check",
                        unit="assignment")
    return [row for rows in per_slug for row in rows]


def _grade_assignment(shared: tuple, slug: str) -> list[dict]:
    """The self-check rows of one assignment's solution and blank; ``shared``: root, seed and limits
    (see :func:`grade_course`)."""
    root, seed, limits = shared
    kinds = (("solution", "solutions"), ("assignment", "assignments"))
    paths = {kind: root / folder / f"{slug}.ipynb" for kind, folder in kinds}
    present = [kind for kind, _ in kinds if paths[kind].exists()]
    results = dict(zip(present, grade_batch([paths[k] for k in present], slug, seed, jobs=1, limits=limits,
                                            log=lambda *_: None))) if present else {}
    rows = []
    for kind, folder in kinds:
        if kind not in results:
            rows.append({"assignment": slug, "kind": kind, "total": 0, "max": 0, "expected": "present",
                         "ok": False, "note": f"{folder}/{slug}.ipynb missing", "log": ""})
            continue
        result = results[kind]
        want = result.max_total if kind == "solution" else 0.0
        ok = result.total == want and not result.reason and "worker-ended-early" not in result.flags \
            and "timeout" not in result.flags
        note = "; ".join([result.reason] * bool(result.reason)
                         + [m for s in result.scores for m in s.messages[:1]]) if not ok else ""
        log = "\n".join([f"flags: {', '.join(result.flags) or 'none'}"]
                        + [f"reason: {result.reason}"] * bool(result.reason)
                        + [f"cell error: {e}" for e in result.cell_errors]
                        + ["--- worker log ---", result.worker_log.rstrip()])
        rows.append({"assignment": slug, "kind": kind, "total": result.total, "max": result.max_total,
                     "expected": want, "ok": ok, "note": note, "log": log})
    return rows


def _markdown_text(text: str) -> str:
    """``text`` as literal Markdown table-cell text: one line, with every character MyST would read
    as markup (``$`` maths, ``*`` emphasis, ``|`` cells, ``<`` HTML ...) backslash-escaped."""
    import re

    return re.sub(r"([\\`*_$|\[\]{}<>#])", r"\\\1", text.replace("\n", " "))


def course_grading_step(root: Path, workdir: Path) -> tuple[bool, BookPage]:
    """Extra step for ``robocourse build``: grade the course, write ``grades.csv`` into
    ``workdir`` and return the instructor site's self-check page (verdicts, full worker logs)."""
    rows = grade_course(root)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    table = workdir / "grades.csv"
    fields = ["assignment", "kind", "total", "max", "expected", "ok", "note"]
    with open(table, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    lines = ["# Grading self-check", "",
             "Every solution must score full marks and every blank assignment zero, graded by the same "
             "sandboxed grader that grades submissions (table: {download}`grades.csv <grades.csv>`).", "",
             "| assignment | notebook | score | verdict |", "|---|---|---|---|"]
    for r in rows:
        verdict = "ok" if r["ok"] else "**wrong**: " + _markdown_text(r["note"])
        lines.append(f"| `{r['assignment']}` | {r['kind']} | {r['total']:g} / {r['max']:g} | {verdict} |")
    lines += ["", "## Worker logs", ""]
    for r in rows:
        lines += [f"<details><summary>{html.escape(r['assignment'])}, {r['kind']}: "
                  f"{'ok' if r['ok'] else 'WRONG'}</summary>", "",
                  f"<pre>{html.escape(r['log'] or r['note'])}</pre>", "", "</details>", ""]
    for r in rows:
        print(f"  grading self-check: {r['assignment']:<28} {r['kind']:<10} {r['total']:g}/{r['max']:g} "
              f"{'ok' if r['ok'] else 'WRONG ' + r['note']}")
    return all(r["ok"] for r in rows), BookPage("instructor/selfcheck", "\n".join(lines) + "\n", files=(table,))
