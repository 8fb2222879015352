"""Rubrics of the written questions (issue 37, deliverable 4): in every solution notebook, in the
grading guide ``robocourse grade`` writes for TAs, and never in what students get."""
from __future__ import annotations

import json
import shutil

import pytest

from robocourse.cli import main
from robocourse.grading.assign import make_assignment
from robocourse.grading.rubrics import LEVELS, RubricError, grading_guide, written_questions
from robocourse.lessons import catalog
from tests.conftest import ROOT

SLUGS = list(catalog())


def _solution(slug):
    return json.loads((ROOT / "solutions" / f"{slug}.ipynb").read_text(encoding="utf-8"))


@pytest.mark.parametrize("slug", SLUGS)
def test_every_written_question_has_a_rubric_after_its_model_answer(slug):
    questions = written_questions(_solution(slug), slug)     # raises RubricError for a missing or bad one
    assert sorted(q.id for q in questions) == sorted(catalog()[slug].written)
    for q in questions:
        assert q.answer and q.question, q.id
        items = [line[3:].split(":*")[0] for line in q.rubric.splitlines() if line.startswith("- *")]
        assert [item.split(" (")[0] for item in items] == list(LEVELS), q.id     # full, partial, failing
        assert items[0] == f"Full ({q.points:g})" and items[-1] == "Failing (0)", q.id


@pytest.mark.parametrize("slug", SLUGS)
def test_students_never_see_a_rubric(slug):
    """Neither the committed assignment nor one generated afresh holds a rubric or a model answer."""
    committed = (ROOT / "assignments" / f"{slug}.ipynb").read_text(encoding="utf-8")
    generated = json.dumps(make_assignment(_solution(slug), slug), ensure_ascii=False)
    for text in (committed, generated):
        assert "*Rubric (" not in text and "Failing (0)" not in text
    for q in written_questions(_solution(slug), slug):
        assert q.answer.splitlines()[0] not in committed, q.id


def test_a_missing_or_malformed_rubric_is_refused():
    nb = _solution("00_getting_started")
    cell = next(c for c in nb["cells"] if "BEGIN SOLUTION 00.why_seeds" in "".join(c["source"]))
    text = "".join(cell["source"])
    cell["source"] = text.replace("*Rubric (1 point).*", "*Rubric (2 points).*")
    with pytest.raises(RubricError, match="WRITTEN gives 1"):
        written_questions(nb, "00_getting_started")
    cell["source"] = text.replace("- *Partial", "- *Half")
    with pytest.raises(RubricError, match="no Partial item"):
        written_questions(nb, "00_getting_started")
    rubric = text[text.index("*Rubric"):text.index("<!-- END")]
    cell["source"] = text.replace(rubric, rubric + "\n" + rubric)
    with pytest.raises(RubricError, match="more than one"):
        written_questions(nb, "00_getting_started")
    cell["source"] = text.split("*Rubric")[0] + "<!-- END SOLUTION -->"
    with pytest.raises(RubricError, match="has no"):
        written_questions(nb, "00_getting_started")


@pytest.mark.parametrize("slug", SLUGS)
def test_the_guide_lists_exercises_by_kind_and_every_rubric(slug):
    guide = grading_guide(slug, _solution(slug))
    for ex in catalog()[slug].exercises:
        assert f"| {ex.id} | {ex.kind} | {ex.points:g} |" in guide
    for q in written_questions(_solution(slug), slug):
        assert q.rubric in guide and q.answer in guide, q.id


def test_grade_writes_the_guide_beside_the_gradebook(tmp_path, capsys):
    sub = tmp_path / "subs" / "alice.ipynb"
    sub.parent.mkdir()
    shutil.copy(ROOT / "assignments" / "00_getting_started.ipynb", sub)
    out = tmp_path / "grades" / "g.csv"
    out.parent.mkdir()
    assert main(["grade", str(sub), "--assignment", "00_getting_started", "--seed", "s", "--out", str(out),
                 "--feedback", str(tmp_path / "fb"), "--root", str(ROOT)]) == 0
    guide = (tmp_path / "grades" / "g-guide.md").read_text()
    assert "00.why_seeds" in guide and "*Full (1):*" in guide and "| 00.se2_compose | derivation | 2 |" in guide
    assert "Rubric" not in (tmp_path / "fb" / "alice.md").read_text()      # feedback goes to students
    assert "grading guide for TAs" in capsys.readouterr().out


def test_grade_without_the_solutions_says_the_guide_lacks_them(tmp_path, capsys):
    sub = tmp_path / "alice.ipynb"
    shutil.copy(ROOT / "assignments" / "00_getting_started.ipynb", sub)
    assert main(["grade", str(sub), "--assignment", "00_getting_started", "--seed", "s",
                 "--out", str(tmp_path / "g.csv"), "--guide", str(tmp_path / "guide.md"),
                 "--root", str(tmp_path)]) == 0
    assert "model answers and rubrics are missing" in (tmp_path / "guide.md").read_text()
    assert "no solutions/00_getting_started.ipynb" in capsys.readouterr().err
