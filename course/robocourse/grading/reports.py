"""Grading outputs: the CSV gradebook, per-student feedback and Gradescope's results.json.

Every string that comes from a student (names, exception messages, returned values, the worker's
log) is written through :mod:`.safetext`: in markdown it is escaped or inside a code block its text
cannot close, in the gradebook it cannot start a spreadsheet formula, and nowhere does it keep
control characters or terminal escapes.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Sequence

from robocourse.grading.grader import SubmissionResult
from robocourse.grading.safetext import clean, csv_cell, fenced, md_inline
from robocourse.grading.submission import feedback_stem

__all__ = ["write_gradebook", "write_feedback", "feedback_text", "gradescope_results", "write_gradescope", "FLAG_TEXT"]

FLAG_TEXT = {
    "imported-robokit": ("tried to import robokit, the course's library, which the grader withholds "
                         "(an exercise that failed for it scores zero)"),
    "timeout": "stopped at the time limit",
    "worker-ended-early": "the notebook ended the grading process before it finished",
    "unusable-results": "the grading process left results the grader could not use (those parts score zero)",
    "not-a-notebook": "not a readable notebook",
    "wrong-assignment": "submitted for another assignment",
    "unreadable": "the file could not be read",
    "symlink": "the file or the student's folder is a symbolic link, which is not followed",
    "duplicate-name": "several files map to this student name: each is graded under a numbered name",
    "grader-error": "the grader failed on this file (not the student's fault): regrade it",
    "sandbox=limited": "graded without root: resource limits only (see README)",
}


def write_gradebook(results: Sequence[SubmissionResult], path: str | Path) -> Path:
    """Write one row per student: per-exercise points, total, maximum, flags and a note."""
    path = Path(path)
    ids = [s.id for s in results[0].scores] if results else []
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["student", "file", *ids, "total", "max", "flags", "note"])
        for r in sorted(results, key=lambda r: r.student):
            w.writerow([csv_cell(r.student), csv_cell(r.path.name), *[f"{s.points:g}" for s in r.scores],
                        f"{r.total:g}", f"{r.max_total:g}", csv_cell(" ".join(r.flags)),
                        csv_cell(r.reason or "; ".join(r.notes + r.problems), 1000)])
    return path


def feedback_text(r: SubmissionResult, assignment: str) -> str:
    """Return the markdown feedback for one submission."""
    lines = [f"# Feedback: {md_inline(assignment)} — {md_inline(r.student, 100)}", "",
             f"**Score: {r.total:g} / {r.max_total:g}** (written questions are graded separately)", ""]
    if r.reason:
        lines += ["Not graded:", "", *fenced([r.reason]), ""]
    lines += ["| exercise | points | cases passed |", "|---|---|---|"]
    lines += [f"| {s.id} | {s.points:g} / {s.max_points:g} | {s.passed} / {s.total} |" for s in r.scores]
    for s in r.scores:
        if s.messages and s.passed < s.total:
            lines += ["", f"## {s.id}", "", *fenced(s.messages)]
    if r.cell_errors:
        lines += ["", "## Cells that raised an error", "", *fenced(r.cell_errors[:10])]
    if r.problems:
        lines += ["", "## What the grader could not use", "", *fenced(r.problems[:10])]
    notes = [FLAG_TEXT.get(f, f) for f in r.flags] + [md_inline(n, 1000) for n in r.notes]
    if notes:
        lines += ["", "## Notes", *[f"- {n}" for n in notes]]
    if r.worker_log:
        lines += ["", "## Last lines the worker process wrote (the submission's own code may have written them too)",
                  "", *fenced(r.worker_log.splitlines(), max_lines=20)]
    return "\n".join(lines) + "\n"


def write_feedback(results: Sequence[SubmissionResult], folder: str | Path, assignment: str) -> list[Path]:
    """Write ``<folder>/<student>.md`` for every submission.

    Raises
    ------
    ValueError
        If two results would share a feedback file (:func:`~.grader.grade_batch` names every
        student once, so this means results from elsewhere): nothing is overwritten.
    """
    folder = Path(folder)
    stems = [feedback_stem(r.student) for r in results]
    if len({s.casefold() for s in stems}) != len(stems):
        raise ValueError("results: two students would share a feedback file; give each a unique name")
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for r, stem in zip(results, stems):
        p = folder / f"{stem}.md"
        p.write_text(feedback_text(r, assignment), encoding="utf-8")
        written.append(p)
    return written


def gradescope_results(r: SubmissionResult, assignment: str) -> dict:
    """Return Gradescope's autograder ``results.json`` structure for one submission: the feedback
    as markdown, each exercise's messages as plain text."""
    tests = []
    for s in r.scores:
        tests.append({"name": s.id, "score": s.points, "max_score": s.max_points,
                      "output": "\n".join(clean(m, 600) for m in s.messages) or f"{s.passed}/{s.total} cases passed",
                      "visibility": "visible"})
    return {"score": r.total, "output": feedback_text(r, assignment), "output_format": "md",
            "test_output_format": "text", "test_name_format": "text", "tests": tests, "stdout_visibility": "hidden"}


def write_gradescope(r: SubmissionResult, assignment: str, path: str | Path) -> Path:
    """Write :func:`gradescope_results` of one submission to ``path`` (Gradescope's results.json)."""
    path = Path(path)
    path.write_text(json.dumps(gradescope_results(r, assignment), indent=2))
    return path
