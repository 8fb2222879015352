"""`robocourse grade` end to end: gradebook, feedback, Gradescope JSON, and clear errors on bad input."""
import csv
import json
import shutil
from pathlib import Path

import pytest

from robocourse.cli import main
from robocourse.grading.selfcheck import grade_course
from robocourse.lessons import assignments
from tests.conftest import ROOT

SOL = ROOT / "solutions" / "00_getting_started.ipynb"
BLANK = ROOT / "assignments" / "00_getting_started.ipynb"


#: ``make test`` grades these two assignments' solution and blank in the sandbox (the smallest, and one
#: with a data file and a simulator); ``make check`` grades the rest too, as every ``make course`` does.
EVERYDAY_GRADED = ("00_getting_started", "03_corridor_localization")


def _graded_groups() -> list:
    assert set(EVERYDAY_GRADED) <= set(assignments()), f"EVERYDAY_GRADED names no assignment: {EVERYDAY_GRADED}"
    rest = tuple(slug for slug in assignments() if slug not in EVERYDAY_GRADED)
    return [pytest.param(EVERYDAY_GRADED, id="everyday"), pytest.param(rest, id="the-rest", marks=pytest.mark.slow)]


@pytest.mark.parametrize("slugs", _graded_groups())
def test_every_solution_full_marks_and_every_blank_assignment_zero(slugs):
    rows = grade_course(ROOT, only=slugs)
    assert sorted({r["assignment"] for r in rows}) == sorted(slugs) and len(rows) == 2 * len(slugs)
    bad = [r for r in rows if not r["ok"]]
    assert not bad, bad


def test_the_self_check_refuses_an_assignment_the_course_lacks():
    with pytest.raises(ValueError, match="only: expected assignments of the course.*99_nothing"):
        grade_course(ROOT, only=["99_nothing"])
    with pytest.raises(TypeError, match="only: expected a sequence"):
        grade_course(ROOT, only="03_corridor_localization")


def test_grade_writes_gradebook_feedback_and_gradescope(tmp_path, capsys):
    subs = tmp_path / "subs"
    subs.mkdir()
    shutil.copy(SOL, subs / "alice.ipynb")
    code = main(["grade", str(subs / "alice.ipynb"), "--assignment", "00_getting_started", "--seed", "s",
                 "--out", str(tmp_path / "g.csv"), "--feedback", str(tmp_path / "fb"),
                 "--gradescope", str(tmp_path / "results.json")])
    assert code == 0
    rows = list(csv.DictReader(open(tmp_path / "g.csv")))
    assert rows[0]["student"] == "alice" and rows[0]["total"] == "3" and rows[0]["max"] == "3"
    assert "Score: 3 / 3" in (tmp_path / "fb" / "alice.md").read_text()
    gs = json.loads((tmp_path / "results.json").read_text())
    assert gs["score"] == 3 and {t["name"] for t in gs["tests"]} == {"00.wrap_angle", "00.se2_compose"}


def test_missing_function_is_zero_with_feedback(tmp_path):
    nb = json.loads(SOL.read_text())
    nb["cells"] = [c for c in nb["cells"] if not "".join(c["source"]).startswith("def se2_compose")]
    (tmp_path / "bob.ipynb").write_text(json.dumps(nb))
    assert main(["grade", str(tmp_path / "bob.ipynb"), "--assignment", "00_getting_started", "--seed", "s",
                 "--out", str(tmp_path / "g.csv"), "--feedback", str(tmp_path / "fb")]) == 0
    fb = (tmp_path / "fb" / "bob.md").read_text()
    assert "function not defined" in fb and "| 00.se2_compose | 0 / 2 |" in fb and "| 00.wrap_angle | 1 / 1 |" in fb


@pytest.mark.parametrize("args, message", [
    (["--assignment", "99_nothing", "--seed", "s"], "unknown assignment"),
    (["--assignment", "00_getting_started"], "secret seed is required"),
])
def test_request_errors_are_clear(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.delenv("ROBOKIT_GRADING_SEED", raising=False)
    code = main(["grade", str(SOL), "--out", str(tmp_path / "g.csv"), *args])
    err = capsys.readouterr().err
    assert code == 2 and message in err and "Traceback" not in err


def test_unreadable_and_wrong_assignment_exit_nonzero_but_batch_completes(tmp_path, capsys):
    wrong = json.loads(BLANK.read_text())
    wrong["metadata"]["robokit"]["assignment"] = "05_gps_sonar_truck"
    (tmp_path / "wrong.ipynb").write_text(json.dumps(wrong))
    shutil.copy(SOL, tmp_path / "good.ipynb")
    code = main(["grade", str(tmp_path / "wrong.ipynb"), str(tmp_path / "missing.ipynb"), str(tmp_path / "good.ipynb"),
                 "--assignment", "00_getting_started", "--seed", "s", "--out", str(tmp_path / "g.csv")])
    captured = capsys.readouterr()
    assert code == 1 and "Traceback" not in captured.err
    assert "could not be read" in captured.err and "not '00_getting_started'" in captured.err
    rows = {r["student"]: r for r in csv.DictReader(open(tmp_path / "g.csv"))}
    assert rows["good"]["total"] == "3" and rows["wrong"]["total"] == "0" and rows["missing"]["total"] == "0"


def test_a_batch_draws_only_the_cases_of_the_files_it_grades(tmp_path, monkeypatch):
    # preparing an assignment's cases takes up to 2.8 s, and each graded file draws its own: the batch
    # seed's own draw is made only for files that are rejected, once, to name the cases they score zero on
    import robocourse.grading.grader as grader

    real, seeds = grader.prepare_cases, []
    monkeypatch.setattr(grader, "prepare_cases", lambda assignment, seed: seeds.append(seed) or real(assignment, seed))
    shutil.copy(SOL, tmp_path / "good.ipynb")
    shutil.copy(BLANK, tmp_path / "blank.ipynb")
    results = grader.grade_batch([tmp_path / "good.ipynb", tmp_path / "blank.ipynb"], "00_getting_started", "s",
                                 log=lambda *_: None)
    assert [r.total for r in results] == [3, 0] and len(seeds) == 2 and "s" not in seeds
    seeds.clear()
    (tmp_path / "bad.ipynb").write_text("{}")
    (tmp_path / "worse.ipynb").write_text("[")
    bad, _ = grader.grade_batch([tmp_path / "bad.ipynb", tmp_path / "worse.ipynb"], "00_getting_started", "s",
                                log=lambda *_: None)
    assert seeds == ["s"] and bad.total == 0 and bad.max_total == 3
    assert [s.total for s in bad.scores] == [len(cases) for cases in real("00_getting_started", "s").cases]


def test_a_draw_that_never_shows_work_costs_its_file_or_with_the_batch_seed_the_batch(tmp_path, monkeypatch):
    # a file's cases are drawn from the seed and its code: if only that draw fails, the file is a
    # grader error and the batch goes on; if the batch seed's own draw fails too, the course is at fault
    import robocourse.grading.grader as grader

    real, failing = grader.prepare_cases, set()

    def draw(assignment, seed):
        if seed in failing or (seed != "s" and "file" in failing):
            raise grader.GradingError("00.wrap_angle: in 21 draws of its cases, trivial answers pass every valid case")
        return real(assignment, seed)

    monkeypatch.setattr(grader, "prepare_cases", draw)
    shutil.copy(SOL, tmp_path / "good.ipynb")
    failing.add("file")
    (result,) = grader.grade_batch([tmp_path / "good.ipynb"], "00_getting_started", "s", log=lambda *_: None)
    assert result.flags == ["grader-error"] and result.total == 0 and "00.wrap_angle" in result.reason
    failing.add("s")
    with pytest.raises(grader.GradingError, match="00.wrap_angle: in 21 draws"):
        grader.grade_batch([tmp_path / "good.ipynb"], "00_getting_started", "s", log=lambda *_: None)


def test_every_file_that_could_not_be_graded_makes_the_exit_code_1(tmp_path, capsys):
    # the README: exit 1 when a file could not be graded; a 200 MB notebook used to exit 0
    big = tmp_path / "big.ipynb"
    with open(big, "wb") as f:
        f.write(b'{"cells": [')
        f.truncate(200_000_000)
    (tmp_path / "garbage.ipynb").write_text("this is not a notebook {")
    for path in (big, tmp_path / "garbage.ipynb"):
        code = main(["grade", str(path), "--assignment", "00_getting_started", "--seed", "s",
                     "--out", str(tmp_path / "g.csv")])
        captured = capsys.readouterr()
        assert code == 1 and path.name in captured.err and "Traceback" not in captured.err
        (row,) = csv.DictReader(open(tmp_path / "g.csv"))
        assert row["total"] == "0" and row["flags"] == "not-a-notebook" and row["note"]


def test_duplicate_names_are_numbered_flagged_and_exit_1(tmp_path, monkeypatch, capsys):
    # without workers: every path here is rejected, which is enough to check the bookkeeping
    from robocourse.grading.grader import unique_students

    paths = [tmp_path / "alice.ipynb", tmp_path / "alice" / "00_getting_started.ipynb", tmp_path / "sec2" / "alice.ipynb",
             tmp_path / "Alice.ipynb", tmp_path / "a b.ipynb", tmp_path / "a_b.ipynb", tmp_path / "bob.ipynb"]
    names = [n for n, _ in unique_students(paths, "00_getting_started")]
    assert names == ["alice#1", "alice#2", "alice#3", "Alice#4", "a b#1", "a_b#2", "bob"]
    for p in paths:
        p.parent.mkdir(exist_ok=True)
        p.write_text("{}")
    code = main(["grade", *map(str, paths), "--assignment", "00_getting_started", "--seed", "s",
                 "--out", str(tmp_path / "g.csv"), "--feedback", str(tmp_path / "fb")])
    assert code == 1 and "4 files map to student 'alice'" in capsys.readouterr().err
    rows = {r["student"]: r for r in csv.DictReader(open(tmp_path / "g.csv"))}
    assert set(rows) == set(names) and "duplicate-name" in rows["alice#2"]["flags"] and rows["bob"]["flags"] == \
        "not-a-notebook"
    assert len(list((tmp_path / "fb").glob("*.md"))) == len(paths)


def test_a_failure_of_the_grader_on_one_file_costs_only_that_file(tmp_path, monkeypatch, capsys):
    import robocourse.grading.grader as grader

    real = grader.grade_submission

    def flaky(path, *args, **kwargs):
        if path.name == "broken.ipynb":
            raise RuntimeError("disk full")
        return real(path, *args, **kwargs)

    monkeypatch.setattr(grader, "grade_submission", flaky)
    shutil.copy(SOL, tmp_path / "broken.ipynb")
    (tmp_path / "other.ipynb").write_text("{}")
    code = main(["grade", str(tmp_path / "broken.ipynb"), str(tmp_path / "other.ipynb"), "--assignment",
                 "00_getting_started", "--seed", "s", "--out", str(tmp_path / "g.csv")])
    assert code == 1 and "disk full" in capsys.readouterr().err
    rows = {r["student"]: r for r in csv.DictReader(open(tmp_path / "g.csv"))}
    assert rows["broken"]["flags"] == "grader-error" and rows["other"]["flags"] == "not-a-notebook"


def test_a_file_name_that_is_not_utf8_still_gives_a_gradebook(tmp_path, capsys):
    import os

    name = os.fsdecode(b"\xff\xfe\x1b[31m=evil.ipynb")  # a name the student chose, not valid UTF-8
    (tmp_path / name).write_text("{}")
    code = main(["grade", str(tmp_path / name), "--assignment", "00_getting_started", "--seed", "s",
                 "--out", str(tmp_path / "g.csv"), "--feedback", str(tmp_path / "fb")])
    captured = capsys.readouterr()
    assert code == 1 and "Traceback" not in captured.err and "\x1b" not in captured.err + captured.out
    (row,) = csv.DictReader(open(tmp_path / "g.csv", encoding="utf-8"))
    assert row["flags"] == "not-a-notebook" and "\x1b" not in row["student"]
    assert len(list((tmp_path / "fb").glob("*.md"))) == 1


def test_long_duplicate_names_are_numbered_within_the_file_name_bound():
    # names that agree in the part a feedback file name keeps used to loop forever
    from robocourse.grading.grader import unique_students
    from robocourse.grading.submission import feedback_stem

    paths = [Path("x" * 100 + "a.ipynb"), Path("x" * 100 + "b.ipynb"), Path("x" * 99 + "#1.ipynb")]
    names = [n for n, _ in unique_students(paths, "00_getting_started")]
    stems = [feedback_stem(n).casefold() for n in names]
    assert len(set(stems)) == 3 and all(len(s) <= 100 for s in stems), names


def test_names_that_differ_only_by_invisible_characters_are_one_name():
    # 'bob' and 'bob' + a zero-width space both read 'bob' in the gradebook: numbered and flagged
    from robocourse.grading.grader import unique_students

    names = unique_students([Path("bob/00_getting_started.ipynb"), Path("bob\u200b/00_getting_started.ipynb")],
                            "00_getting_started")
    assert [n for n, _ in names] == ["bob#1", "bob#2"] and all(note for _, note in names)


def test_a_feedback_file_name_stays_within_the_file_system_limit():
    # NFC turns U+FAD7 (3 bytes) into U+27ED3 (4 bytes): 84 of them made a 336-byte file name
    from robocourse.grading.submission import feedback_stem

    stem = feedback_stem("\ufad7" * 84)
    assert stem and len(stem.encode()) <= 200
