"""The written questions' rubrics, and the grading guide ``robocourse grade`` writes for TAs.

A written question's solution region in ``solutions/NN_slug.ipynb`` (``<!-- BEGIN SOLUTION NN.name
-->`` ... ``<!-- END SOLUTION -->``, :data:`.assign.WRITTEN_REGION`) holds the model answer and then
its rubric: a line ``*Rubric (N points).*`` followed by what a full, a partial and a failing answer
contains, one list item each (``- *Full (2):* ...``, ``- *Partial (1):* ...``, ``- *Failing (0):*
...``). ``robocourse assign`` replaces the whole region, so students see neither.

The grading guide is one Markdown page per assignment: the auto-graded exercises (kind, points and
what each asks) and every written question with its text, model answer and rubric. It holds the
model answers, so it is for the course staff only.
"""
from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path
from typing import Any

from robocourse.exercises.spec import KINDS
from robocourse.grading.assign import WRITTEN_REGION
from robocourse.lessons import get_assignment

__all__ = ["RUBRIC", "LEVELS", "RubricError", "WrittenQuestion", "written_questions", "grading_guide",
           "write_grading_guide"]

#: The line that starts a rubric inside a solution region.
RUBRIC = re.compile(r"^\*Rubric \((?P<points>\d+(?:\.\d+)?) points?\)\.\*[ \t]*$", re.M)
#: The levels every rubric describes, one list item each: ``- *Full (N):* ...``.
LEVELS = ("Full", "Partial", "Failing")


class RubricError(ValueError):
    """A written question's solution region has no rubric, or a malformed one."""


@dataclasses.dataclass(frozen=True)
class WrittenQuestion:
    """A written question as the solution notebook states it.

    ``question`` is the markdown cell before the answer cell (its text as written), ``answer`` the
    model answer and ``rubric`` the rubric's list (without its ``*Rubric (N points).*`` line).
    """

    id: str
    points: float
    question: str
    answer: str
    rubric: str


def _text(cell: dict) -> str:
    src = cell.get("source", "")
    return "".join(src) if isinstance(src, list) else src


def written_questions(solution: dict[str, Any], slug: str) -> list[WrittenQuestion]:
    """The written questions of a solution notebook, in notebook order, with their rubrics.

    Raises
    ------
    RubricError
        For a question of ``WRITTEN`` whose region has no rubric or two, whose rubric states other
        points than ``WRITTEN`` or lacks one of :data:`LEVELS`, or that has no region at all.

    Examples
    --------
    >>> nb = {"cells": [{"cell_type": "markdown", "source": "## Question (written, 1 point)\\nWhy seeds?"},
    ...       {"cell_type": "markdown", "source": "<!-- BEGIN SOLUTION 00.why_seeds -->\\nTo repeat runs.\\n\\n"
    ...        "*Rubric (1 point).*\\n\\n- *Full (1):* a\\n- *Partial (0.5):* b\\n- *Failing (0):* c\\n"
    ...        "<!-- END SOLUTION -->"}]}
    >>> q = written_questions(nb, "00_getting_started")[0]
    >>> q.id, q.answer, q.rubric.splitlines()[0]
    ('00.why_seeds', 'To repeat runs.', '- *Full (1):* a')
    """
    written = get_assignment(slug).written
    cells = solution.get("cells", [])
    found = []
    for i, cell in enumerate(cells):
        if cell.get("cell_type") != "markdown":
            continue
        for match in WRITTEN_REGION.finditer(_text(cell)):
            qid, body = match.group(1), match.group(2)
            if qid not in written:
                continue
            rubric = RUBRIC.search(body)
            if rubric is None:
                raise RubricError(f"solutions/{slug}.ipynb: {qid} has no '*Rubric (N points).*' after its model answer")
            if float(rubric.group("points")) != float(written[qid]):
                raise RubricError(f"solutions/{slug}.ipynb: {qid}'s rubric is for {rubric.group('points')} points, "
                                  f"WRITTEN gives {written[qid]:g}")
            items = body[rubric.end():].strip()
            if RUBRIC.search(items):
                raise RubricError(f"solutions/{slug}.ipynb: {qid} has more than one rubric")
            missing = [level for level in LEVELS if not re.search(rf"^- \*{level} \([^)]*\):\*", items, re.M)]
            if missing:
                raise RubricError(f"solutions/{slug}.ipynb: {qid}'s rubric has no {', '.join(missing)} item "
                                  f"('- *{missing[0]} (points):* what such an answer contains')")
            before = cells[i - 1] if i > 0 and cells[i - 1].get("cell_type") == "markdown" else {}
            found.append(WrittenQuestion(qid, float(written[qid]), _text(before).strip(),
                                         body[:rubric.start()].strip(), items))
    missing = [q for q in written if q not in {w.id for w in found}]
    if missing:
        raise RubricError(f"solutions/{slug}.ipynb: no solution region for {missing}")
    return found


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


def grading_guide(slug: str, solution: dict[str, Any] | None) -> str:
    """The grading guide of an assignment as Markdown (see the module's docstring).

    ``solution`` is the solution notebook (parsed JSON); without it the guide lists the written
    questions' ids and points and says that their model answers and rubrics are missing.

    Raises
    ------
    RubricError
        As :func:`written_questions`.
    """
    assignment = get_assignment(slug)
    lines = [f"# Grading guide: {slug}", "",
             "For the course staff: it holds the model answers, so keep it private. The gradebook scores the "
             "auto-graded exercises; grade the written questions by hand with the rubrics below.", "",
             "## Auto-graded exercises", "", "| exercise | kind | points | what it asks |", "|---|---|---|---|"]
    lines += [f"| {ex.id} | {ex.kind} | {ex.points:g} | {_cell(ex.description)} |" for ex in assignment.exercises]
    by_kind = {k: sum(ex.points for ex in assignment.exercises if ex.kind == k) for k in KINDS}
    lines += ["", "Points by kind: " + ", ".join(f"{k} {p:g}" for k, p in by_kind.items() if p) + ".", ""]
    total = sum(assignment.written.values())
    lines += [f"## Written questions ({total:g} points)", ""]
    if solution is None:
        lines += [f"No solution notebook (solutions/{slug}.ipynb under the course root): model answers and "
                  "rubrics are missing.", ""]
        lines += [f"- {qid} ({points:g} points)" for qid, points in assignment.written.items()]
        return "\n".join(lines) + "\n"
    for q in written_questions(solution, slug):
        heading, _, rest = q.question.partition("\n") if q.question.startswith("#") else ("", "", q.question)
        title = heading.lstrip("#").strip() or f"Question ({q.points:g} point{'s' if q.points != 1 else ''})"
        lines += [f"### {title}: {q.id}", "",
                  rest.strip() or "(the question's text is not in the cell before the answer)", "",
                  "**Model answer.**", "", q.answer, "", "**Rubric.**", "", q.rubric, ""]
    return "\n".join(lines)


def write_grading_guide(slug: str, root: str | Path, path: str | Path) -> tuple[Path, bool]:
    """Write :func:`grading_guide` to ``path`` from ``<root>/solutions/<slug>.ipynb``; return the path
    and whether the solution notebook was found (without it the guide has no answers or rubrics).

    Raises
    ------
    RubricError
        As :func:`written_questions`.
    """
    source = Path(root) / "solutions" / f"{slug}.ipynb"
    solution = json.loads(source.read_text(encoding="utf-8")) if source.is_file() else None
    path = Path(path)
    path.write_text(grading_guide(slug, solution), encoding="utf-8")
    return path, solution is not None
