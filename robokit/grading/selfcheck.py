"""Grade the course's own notebooks: every solution must score full marks, every blank
assignment zero. Used by ``robokit course build`` (writes ``grades.csv`` into the site) and by the
test-suite, so a broken exercise definition or a stale assignment is caught before students are."""
from __future__ import annotations

import csv
import html
from pathlib import Path

from ..exercises.discovery import assignments
from .grader import grade_batch
from .sandbox import Limits

__all__ = ["grade_course", "course_grading_step"]


def grade_course(root: str | Path, *, seed: str = "course-selfcheck", jobs: int = 2,
                 limits: Limits = Limits(wall_seconds=600, cpu_seconds=600)) -> list[dict]:
    """Grade ``solutions/NN.ipynb`` and ``assignments/NN.ipynb`` for every assignment with exercises.

    Returns
    -------
    list of dict
        One row per notebook: ``assignment``, ``kind`` (solution/assignment), ``total``, ``max``,
        ``expected`` and ``ok`` (solution at full marks, assignment at zero, no crash).
    """
    root = Path(root)
    rows = []
    for slug in assignments():
        for kind, folder in (("solution", "solutions"), ("assignment", "assignments")):
            path = root / folder / f"{slug}.ipynb"
            if not path.exists():
                rows.append({"assignment": slug, "kind": kind, "total": 0, "max": 0,
                             "expected": "present", "ok": False, "note": f"{folder}/{slug}.ipynb missing"})
                continue
            result = grade_batch([path], slug, seed, jobs=1, limits=limits, log=lambda *_: None)[0]
            want = result.max_total if kind == "solution" else 0.0
            ok = result.total == want and not result.reason and "worker-ended-early" not in result.flags \
                and "timeout" not in result.flags
            note = "; ".join(m for s in result.scores for m in s.messages[:1]) if not ok else ""
            rows.append({"assignment": slug, "kind": kind, "total": result.total, "max": result.max_total,
                         "expected": want, "ok": ok, "note": note[:300]})
    return rows


def course_grading_step(root: Path, out: Path) -> tuple[bool, str]:
    """Extra step for ``robokit course build``: write ``grades.csv`` and an HTML summary."""
    rows = grade_course(root)
    with open(out / "grades.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["assignment", "kind", "total", "max", "expected", "ok", "note"])
        w.writeheader()
        w.writerows(rows)
    body = "".join(
        f"<tr><td>{html.escape(r['assignment'])}</td><td>{r['kind']}</td><td>{r['total']:g} / {r['max']:g}</td>"
        f"<td class='{'ok' if r['ok'] else 'failed'}'>{'ok' if r['ok'] else 'WRONG: ' + html.escape(r['note'])}</td></tr>"
        for r in rows)
    fragment = ("<h2>Autograder self-check</h2><p>Every solution must score full marks and every blank "
                "assignment zero (<a href='grades.csv'>grades.csv</a>).</p><table><tr><th>assignment</th>"
                f"<th>notebook</th><th>score</th><th>verdict</th></tr>{body}</table>")
    for r in rows:
        print(f"  grading self-check: {r['assignment']:<28} {r['kind']:<10} {r['total']:g}/{r['max']:g} "
              f"{'ok' if r['ok'] else 'WRONG ' + r['note']}")
    return all(r["ok"] for r in rows), fragment
