"""check(), plain-data conversion, comparisons, the exercise catalog and assignment generation."""
import json
import re

import numpy as np
import pytest

from robocourse.cli import main
from robocourse.exercises import Case, close, exact, unordered_rows
from robocourse.grading import check
from robocourse.grading.assign import RAISES, AssignmentError, make_assignment, mark_stub_failures, write_assignment
from robocourse.lessons import UnknownExerciseError, assignments, get_exercise
from robocourse.exercises.plain import NotPlainData, to_plain
from robocourse.grading.transport import TransportError, read_plain, write_plain
from tests.conftest import ROOT


def test_to_plain_rejects_subclasses_and_objects():
    class Liar(float):
        def __eq__(self, other):
            return True

    with pytest.raises(NotPlainData):
        to_plain(Liar(1.0))
    with pytest.raises(NotPlainData):
        to_plain(object())
    with pytest.raises(NotPlainData):
        to_plain({1: 2})
    assert to_plain((np.float32(1.5), [np.int64(2)], {"a": np.eye(2)}))[1] == [2]


def test_comparisons():
    assert close()(1.0, 1.0 + 1e-12) is None
    assert "values differ" in close(rtol=0, atol=1e-9)([1.0, 2.0], [1.0, 2.1])
    assert "shape" in close()(np.zeros(3), np.zeros(4))
    assert close()({"a": 1.0}, {"a": 1.0}) is None and "missing keys" in close()({"a": 1.0}, {})
    assert exact()("2A", "2a") is not None and exact()("2A", "2A") is None
    rows = np.array([[0.0, 1.0], [2.0, 3.0]])
    assert unordered_rows()(rows, rows[::-1]) is None
    assert unordered_rows()(rows, rows + 1) is not None


def test_array_mismatch_names_the_count_and_the_worst_values():
    expected = np.zeros((3, 4))
    got = expected.copy()
    got[0, 1], got[2, 3], got[1, 0] = 0.5, -2.0, float("nan")
    msg = close(rtol=0, atol=1e-9)(expected, got)
    assert msg.startswith("result: 3 of 12 values differ")
    # worst first: the NaN, then the largest miss (-2 at (2, 3)), then 0.5 at (0, 1)
    assert msg.index("(1, 0)") < msg.index("(2, 3)") < msg.index("(0, 1)")
    many = close(rtol=0, atol=1e-9)(np.zeros(50), np.arange(50.0))
    assert "49 of 50 values differ" in many and many.count("at index") == 3 and "(49,)" in many.split(";")[1]
    assert close()(2.0, 2.5) == "result: expected 2, got 2.5 (tolerance 1e-09 + 1e-06*|expected|)"


def test_a_list_and_an_array_are_the_same_answer_in_every_comparison():
    idx, vals = np.array([2, 0, 1]), np.array([[0.5, 1.0]])
    for cmp in (close(), exact()):
        assert cmp(idx, [2, 0, 1]) is None and cmp([2, 0, 1], idx) is None
        assert cmp(idx, [2, 1, 0]) is not None and cmp(idx, [[2, 0, 1]]) is not None
    assert close()(vals, [[0.5, 1.0]]) is None and unordered_rows()(vals, [[0.5, 1.0]]) is None
    assert exact()(np.array([], dtype=int), []) is None
    assert "2 of 3 values differ; first at index (1,): expected 0, got 1" in exact()(idx, [2, 1, 0])
    # numbers by value everywhere (a count returned by np.ceil is still the count), as close() does
    assert exact()(idx, [2.0, 0.0, 1.0]) is None and exact()(17, 17.0) is None and exact()(17, 16.5) is not None
    assert close()(idx, [2.0, 0.0, 1.0]) is None and exact()(idx, [2.5, 0.0, 1.0]) is not None
    # a boolean is not a number, a string is not either, in close() and exact() alike
    assert exact()(np.array([True, False]), [True, False]) is None
    assert exact()(np.array([True, False]), [1, 0]) == "expected booleans, got numbers: array(2,) [1, 0]"
    assert exact()(17, "17") == "expected the integer 17, got the string '17'"
    assert exact()(1, True) == "expected the integer 1, got the boolean True"
    assert close()(2.0, "2.0") is not None and close()([1.5], ["1.5"]) is not None
    assert exact()(idx, ["2", "0", "1"]) is not None and exact()(idx, None) is not None
    # "nothing" is one answer however it is written
    for cmp in (close(), exact(), unordered_rows()):
        assert cmp(np.empty((0, 2)), []) is None and cmp(np.empty((0, 2), int), np.array([])) is None
    # unordered rows report in sorted order and say so
    assert unordered_rows()([[0.0, 1.0], [2.0, 3.0]], [[2.0, 3.0], [0.0, 5.0]]).startswith("rows sorted by value")


def test_case_call_text_shows_the_inputs_within_a_bound():
    case = Case(("$GPRMC,123519,A,4807.038,N*6A",), {"strict": True})
    assert case.call_text("parse") == "parse('$GPRMC,123519,A,4807.038,N*6A', strict=True)"
    big = Case((np.arange(10_000.0), "x" * 1000))
    text = big.call_text("f")
    assert len(text) <= 400 and text.startswith("f(array(10000,)") and text.endswith("...)")
    # inputs are stored as plain lists; a list of numbers is shown as the array it stands for
    rows = Case((np.arange(210.0).reshape(70, 3) / 7,)).call_text("robust_pose")
    assert rows.startswith("robust_pose(array(70, 3) [[ 0. , 0.1429,") and len(rows) < 200, rows
    assert Case(([0.5],)).call_text("f") == "f([0.5])"


def test_transport_round_trip_and_limits(tmp_path):
    value = {"a": np.arange(3.0), "b": [1, "x", None, float("nan")], "c": np.array([True, False])}
    write_plain(value, tmp_path / "v")
    back = read_plain(tmp_path / "v")
    assert np.array_equal(back["a"], value["a"]) and back["b"][:3] == [1, "x", None] and np.isnan(back["b"][3])
    np.save(tmp_path / "obj.npy", np.array([object()], dtype=object), allow_pickle=True)
    (tmp_path / "w.json").write_text(json.dumps({"__robokit_array__": "a0"}))
    np.savez(tmp_path / "w.npz", a0=np.array([{"x": 1}], dtype=object))
    with pytest.raises(TransportError):
        read_plain(tmp_path / "w")  # pickled object arrays are refused
    with pytest.raises(TransportError, match="missing"):
        read_plain(tmp_path / "nothing")


def test_check_reports_and_raises(capsys):
    def good(angle):
        a = np.asarray(angle, float)
        if np.isnan(a).any():
            raise ValueError("nan")
        r = np.mod(a + np.pi, 2 * np.pi) - np.pi
        return float(r) if r.ndim == 0 else r

    assert check("00.wrap_angle", good) is None          # nothing for the notebook to show as Out[...]
    assert "6/6 public cases passed" in capsys.readouterr().out
    with pytest.raises(AssertionError, match="public cases failed") as failed:
        check("00.wrap_angle", lambda a: a)
    report = capsys.readouterr().out
    assert "2/6 public cases passed" in report and "FAIL" not in report   # failures: in the message only
    # the message itself names the failed cases, and IPython shows only that message
    assert str(failed.value).count("FAIL  case") == 4
    # each failed case shows the call that broke it, with its inputs
    assert str(failed.value).count("input: wrap_angle(") == 4
    assert failed.value._render_traceback_() == [f"CheckFailed: {failed.value}"]

    def stub(angle):
        raise NotImplementedError

    with pytest.raises(NotImplementedError) as stubbed:
        check("00.wrap_angle", stub)
    assert stubbed.value._render_traceback_() == ["NotImplementedYet: 00.wrap_angle is not implemented yet"]
    assert "not implemented yet" in capsys.readouterr().out
    with pytest.raises(UnknownExerciseError):
        check("99.nothing", good)
    with pytest.raises(TypeError, match="fn"):
        check("00.wrap_angle", 3)


def test_case_inputs_are_plain():
    with pytest.raises(NotPlainData):
        Case((object(),))


def test_a_case_that_knows_its_answer_is_judged_by_it_not_by_the_answer():
    """A simulator's truth (lesson 04's touchdowns) travels in the case: the answer is not called."""
    from robocourse.exercises import Exercise
    from robocourse.grading.judge import call_student, expected_output, judge

    calls = []
    ex = Exercise(id="00.truth", function="truth", signature="truth(x)", points=1, cases=lambda rng: [],
                  answer=lambda x: calls.append(x) or 0.0)
    case = Case((1.0,), expected=(np.int64(7), 8.5), label="simulated")
    assert case.expected == [7, 8.5] and type(case.expected[0]) is int
    assert expected_output(ex, case) == [7, 8.5] and not calls
    assert judge(ex, case, expected_output(ex, case), call_student(lambda x: [7, 8.5], case)).passed
    assert not judge(ex, case, expected_output(ex, case), call_student(lambda x: 0.0, case)).passed
    assert expected_output(ex, Case((2.0,))) == 0.0 and calls == [2.0]
    with pytest.raises(ValueError, match="expected"):
        Case((1.0,), raises="ValueError", expected=1.0)
    with pytest.raises(NotPlainData):
        Case((1.0,), expected=object())


@pytest.mark.parametrize("slug", list(assignments()))
def test_cases_are_deterministic_per_seed(slug):
    for ex in assignments()[slug]:
        a, b = repr(ex.make_cases("seed-a")), repr(ex.make_cases("seed-a"))
        assert a == b
    # a different secret seed gives different cases for at least one exercise
    assert any(repr(ex.make_cases("seed-a")) != repr(ex.make_cases("seed-b")) for ex in assignments()[slug])


def test_committed_assignments_are_generated():
    for slug in assignments():
        if (ROOT / "solutions" / f"{slug}.ipynb").exists():
            assert not write_assignment(ROOT, slug, verify=True), (
                f"assignments/{slug}.ipynb differs from what `robocourse assign {slug}` generates")


def test_assignment_hides_solutions_and_carries_nbgrader_metadata():
    nb = json.loads((ROOT / "assignments" / "00_getting_started.ipynb").read_text())
    text = json.dumps(nb)
    assert "BEGIN SOLUTION" not in text and "np.mod" not in text
    grade_cells = [c["metadata"]["nbgrader"] for c in nb["cells"] if c["metadata"]["nbgrader"]["grade"]]
    assert {c["grade_id"]: c["points"] for c in grade_cells} == {"00.wrap_angle": 1.0, "00.se2_compose": 2.0,
                                                               "00.why_seeds": 1.0}
    assert all(c["metadata"]["nbgrader"]["schema_version"] == 3 for c in nb["cells"])
    assert nb["metadata"]["robokit"]["assignment"] == "00_getting_started"


def _cell(source, *, grade=False, solution=False):
    return {"cell_type": "code", "source": source, "outputs": [], "execution_count": None,
            "metadata": {"nbgrader": {"grade": grade, "solution": solution}}}


def test_only_cells_a_blank_exercise_can_break_are_marked_to_let_run_all_go_on():
    cases = [("import numpy as np\nfrom robocourse import check", False),      # setup: a real error must stop
             ("check('00.f', f)", True),
             ("data = np.arange(3)", False),                                    # given data
             ("y = f(data)\nz = 2", True),                                      # uses the student's function
             ("print(z + 1)", True),                                            # uses what that cell made
             ("print(data.sum())", False),                                      # given data only
             ("for i in range(2):\n    raise NotImplementedError", True),       # a stub's raise, run at the top
             ("res = {}\nres['a'] = f(1)", True),
             ("print(res)", True),                                              # filled by a tagged cell
             ("out = []\nout.append(f(2))", True),
             ("print(out)", True),
             ("w = 1", False),
             ("w += f(1)", True),
             ("v = w + 1", True),                                               # w changed by a tagged cell
             ("w = 5", False),                                                  # bound afresh: clean again
             ("u = w * 2", False),
             ("import math\nt = f(0)", True),
             ("print(math.pi)", False),                                         # its import stays clean
             ("def g():\n    return f(1)", True),                               # g would call the stub
             ("del t", True),
             ("%matplotlib inline\nimport cmath\nprint(cmath.pi)", False)]      # magics parse
    nb = {"cells": [_cell("def f(x):\n    raise NotImplementedError", solution=True)]
          + [_cell(src, grade=src.startswith("check(")) for src, _ in cases]
          + [_cell("def h():\n    return f(1)\nh_value = h()", solution=True),    # runs a stub: marked
             _cell("def k():\n    return f(1)", solution=True)]}                  # only defines: not
    marked = [RAISES in c["metadata"].get("tags", []) for c in mark_stub_failures(nb)["cells"]]
    assert marked == [False] + [want for _, want in cases] + [True, False]
    assert mark_stub_failures(nb)["cells"][2]["metadata"]["tags"] == [RAISES]      # idempotent
    with pytest.raises(TypeError, match="nb"):
        mark_stub_failures([{"cell_type": "code"}])


@pytest.mark.parametrize("slug", sorted(assignments()))
def test_every_check_and_every_cell_using_a_stub_is_marked_in_the_committed_assignments(slug):
    nb = json.loads((ROOT / "assignments" / f"{slug}.ipynb").read_text())
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    grade = [c for c in code if c["metadata"]["nbgrader"]["grade"]]
    assert grade and all(RAISES in c["metadata"]["tags"] for c in grade)
    assert not any(RAISES in c["metadata"].get("tags", []) for c in code if c["metadata"]["nbgrader"]["solution"])
    solutions = json.loads((ROOT / "solutions" / f"{slug}.ipynb").read_text())
    assert all(RAISES not in c["metadata"].get("tags", []) for c in solutions["cells"])  # solutions still stop


def test_run_all_on_a_blank_assignment_runs_every_cell_and_shows_every_check(tmp_path):
    """nbclient without allow_errors stops at the first error, as JupyterLab's Run All does, except
    on cells tagged raises-exception: the blank assignment runs to its end."""
    from robocourse.site.execute import execute_in_process

    src = ROOT / "assignments" / "00_getting_started.ipynb"
    status, error = execute_in_process(src, tmp_path / "out.ipynb", cwd=tmp_path, cell_timeout=120)
    assert status == "ok", error
    out = json.loads((tmp_path / "out.ipynb").read_text())
    code = [c for c in out["cells"] if c["cell_type"] == "code"]
    assert all(c["execution_count"] for c in code)
    checks = [c for c in code if c["metadata"]["nbgrader"]["grade"]]
    assert len(checks) == 2 and all(any(o["output_type"] == "error" for o in c["outputs"]) for c in checks)
    text = json.dumps([c["outputs"] for c in checks])
    assert "00.wrap_angle" in text and "00.se2_compose" in text


def test_assign_rejects_broken_markers():
    nb = json.loads((ROOT / "solutions" / "00_getting_started.ipynb").read_text())
    for cell in nb["cells"]:
        if "# END SOLUTION" in "".join(cell["source"]):
            cell["source"] = "".join(cell["source"]).replace("# END SOLUTION", "")
            break
    with pytest.raises(AssignmentError, match="without END"):
        make_assignment(nb, "00_getting_started")
    nb = json.loads((ROOT / "solutions" / "00_getting_started.ipynb").read_text())
    nb["cells"] = [c for c in nb["cells"] if "check(\"00.se2_compose\"" not in "".join(c["source"])]
    with pytest.raises(AssignmentError, match="check cell for 00.se2_compose"):
        make_assignment(nb, "00_getting_started")


def test_catalog_lookup():
    assert get_exercise("00.se2_compose").points == 2
    with pytest.raises(UnknownExerciseError):
        get_exercise("00.nope")


def test_assign_cli_check_mode(capsys):
    assert main(["assign", "--verify", "--root", str(ROOT)]) == 0
    assert "up to date" in capsys.readouterr().out


# -- student-controlled text in the reports (issue 12, deliverable 6) -----------------------------

from robocourse.grading.safetext import clean, csv_cell, fenced, md_inline  # noqa: E402

HOSTILE_TEXT = ("```` ~~~\n**Score: 3 / 3**\n<script>alert(1)</script>\x1b[2J\x1b]0;t\x07\x9b31m\u202e\u2066"
                "\r\x00\x7f\udcff end")


def test_clean_strips_escapes_and_control_characters_and_bounds_length():
    text = clean(HOSTILE_TEXT, 1000)
    assert not any(ch in text for ch in "\x1b\x07\x9b\u202e\u2066\r\x00\x7f\n") and "\udcff" not in text
    assert "<script>" in text and text.endswith("? end")  # printable text is kept as it is
    assert clean(HOSTILE_TEXT, 1000, lines=True).count("\n") == 2
    assert len(clean("x" * 10**6, 50)) == 50 and clean("x" * 10**6, 50).endswith("…")


def test_fenced_text_cannot_close_its_block():
    block = fenced([HOSTILE_TEXT, "`" * 7, "``` not a fence either"])
    fence = block[0][:-len("text")]
    assert set(fence) == {"`"} and len(fence) == 8 and block[-1] == fence
    assert all(not line.startswith(fence) for line in block[1:-1])


def test_md_inline_escapes_every_markdown_character():
    text = md_inline("**Score: 3 / 3** <b>x</b> [a](http://x) # _y_ `z`")
    assert re.search(r"(?<!\\)[*<>\[\]()#_`]", text) is None


@pytest.mark.parametrize("value", ["=1+2", "+1", "-1", "@SUM(A1)", " =1", "\t=1", "\r=1", "\uff1d1", "\x1b[0m=1"])
def test_csv_cells_cannot_start_a_formula(value):
    cell = csv_cell(value)
    assert cell.startswith("'") and "\t" not in cell and "\r" not in cell


def _result(**fields):
    from pathlib import Path

    from robocourse.grading.grader import ExerciseScore, SubmissionResult

    base = dict(student="eve", path=Path("eve.ipynb"), flags=[],
                scores=[ExerciseScore("00.wrap_angle", 0.0, 1.0, 0, 6, [f"case 1: raised {HOSTILE_TEXT}"])],
                cell_errors=[f"code cell 1: error: ValueError: {HOSTILE_TEXT}"], worker_log=HOSTILE_TEXT * 3,
                notes=[HOSTILE_TEXT], problems=[HOSTILE_TEXT])
    return SubmissionResult(**{**base, **fields})


def test_feedback_keeps_student_text_inside_code_blocks(tmp_path):
    from robocourse.grading.reports import feedback_text, gradescope_results, write_feedback

    for r in (_result(), _result(student=HOSTILE_TEXT, reason=HOSTILE_TEXT)):
        text = feedback_text(r, "00_getting_started")
        assert not re.search(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069\udc80-\udcff]", text)
        outside, fence = [], None
        for line in text.split("\n"):
            if fence is None and re.match(r"^`{3,}text$", line):
                fence = line[:-4]
            elif fence is not None and line == fence:
                fence = None
            elif fence is None:
                outside.append(line)
        outside = "\n".join(outside)
        assert outside.count("**Score:") == 1 and not re.search(r"(?<!\\)[<>]", outside) and "~~~" not in outside
        (written,) = write_feedback([r], tmp_path / "fb", "00_getting_started")  # no UnicodeEncodeError
        assert written.read_text(encoding="utf-8") == text
    gs = gradescope_results(_result(), "00_getting_started")
    assert gs["output_format"] == "md" and gs["test_output_format"] == "text"
    assert "\x1b" not in json.dumps(gs)


def test_feedback_files_are_never_shared(tmp_path):
    from robocourse.grading.reports import write_feedback

    with pytest.raises(ValueError, match="share a feedback file"):
        write_feedback([_result(student="a b"), _result(student="A_b")], tmp_path, "00_getting_started")


def test_check_refuses_a_function_that_uses_robokit_as_the_grader_would():
    from robokit.geometry import wrap_angle as library_wrap
    from robocourse.grading.check import CheckFailed, library_use

    def uses_it(angle):
        return library_wrap(angle)

    def imports_it(angle):
        from robokit.geometry import wrap_angle
        return wrap_angle(angle)

    def numpy_only(angle):
        return (np.asarray(angle, dtype=float) + np.pi) % (2 * np.pi) - np.pi

    assert library_use(uses_it) == ["library_wrap (robokit.geometry.planar)"]
    assert library_use(imports_it) == ["import of robokit.geometry"] and library_use(numpy_only) == []
    for fn in (uses_it, imports_it):
        with pytest.raises(CheckFailed, match="uses robokit .* would score zero"):
            check("00.wrap_angle", fn)


def test_a_value_of_the_assignment_data_is_a_trivial_answer():
    # a notebook can return any value the kit hands it (assignment 02 hands top_k = 5, an index too)
    from robocourse.exercises.spec import Case, Exercise
    from robocourse.exercises.trivial import data_values, trivial_passes
    ex = Exercise(id="00.pick", function="pick", signature="pick(x) -> int", points=1,
                  cases=lambda rng: [], answer=lambda x: int(x))
    cases = [Case((5.0,)), Case((2.0,))]
    passes = trivial_passes(ex, cases, [5, 2], data=data_values({"ratio": 0.7, "top_k": 5}))
    assert any("assignment's data" in name for name in passes[0])
    assert not any("assignment's data" in name for name in passes[1])
