"""Grading outputs: the CSV gradebook, per-student feedback and Gradescope's results.json."""
from __future__ import annotations

import csv
import json
import re
from pathlib import Path
from typing import Sequence

from .grader import SubmissionResult

__all__ = ["write_gradebook", "write_feedback", "feedback_text", "gradescope_results", "write_gradescope", "FLAG_TEXT"]

FLAG_TEXT = {
    "called-reference": "called a disabled reference implementation (that exercise scores zero)",
    "timeout": "stopped at the time limit",
    "worker-ended-early": "the notebook ended the grading process before it finished",
    "not-a-notebook": "not a readable notebook",
    "wrong-assignment": "submitted for another assignment",
    "unreadable": "the file could not be read",
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
            w.writerow([r.student, r.path.name, *[f"{s.points:g}" for s in r.scores], f"{r.total:g}",
                        f"{r.max_total:g}", " ".join(r.flags), r.reason])
    return path


def _safe_name(student: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", student)[:100] or "student"


def feedback_text(r: SubmissionResult, assignment: str) -> str:
    """Return the markdown feedback for one submission."""
    lines = [f"# Feedback: {assignment} — {r.student}", "",
             f"**Score: {r.total:g} / {r.max_total:g}** (written questions are graded separately)", ""]
    if r.reason:
        lines += [f"Not graded: {r.reason}.", ""]
    lines += ["| exercise | points | cases passed |", "|---|---|---|"]
    lines += [f"| {s.id} | {s.points:g} / {s.max_points:g} | {s.passed} / {s.total} |" for s in r.scores]
    for s in r.scores:
        if s.messages and s.passed < s.total:
            lines += ["", f"## {s.id}", *[f"- {m}" for m in s.messages]]
    if r.cell_errors:
        lines += ["", "## Cells that raised an error", *[f"- {e}" for e in r.cell_errors[:10]]]
    notes = [FLAG_TEXT.get(f, f) for f in r.flags]
    if notes:
        lines += ["", "## Notes", *[f"- {n}" for n in notes]]
    if r.worker_log:
        lines += ["", "## Last lines of the grading process", "```", r.worker_log, "```"]
    return "\n".join(lines) + "\n"


def write_feedback(results: Sequence[SubmissionResult], folder: str | Path, assignment: str) -> list[Path]:
    """Write ``<folder>/<student>.md`` for every submission."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for r in results:
        p = folder / f"{_safe_name(r.student)}.md"
        p.write_text(feedback_text(r, assignment), encoding="utf-8")
        written.append(p)
    return written


def gradescope_results(r: SubmissionResult, assignment: str) -> dict:
    """Return Gradescope's autograder ``results.json`` structure for one submission."""
    tests = []
    for s in r.scores:
        tests.append({"name": s.id, "score": s.points, "max_score": s.max_points,
                      "output": "\n".join(s.messages) or f"{s.passed}/{s.total} cases passed",
                      "visibility": "visible"})
    return {"score": r.total, "output": feedback_text(r, assignment), "tests": tests,
            "stdout_visibility": "hidden"}


def write_gradescope(r: SubmissionResult, assignment: str, path: str | Path) -> Path:
    """Write :func:`gradescope_results` of one submission to ``path`` (Gradescope's results.json)."""
    path = Path(path)
    path.write_text(json.dumps(gradescope_results(r, assignment), indent=2))
    return path
