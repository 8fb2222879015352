"""The grader/worker protocol, the rejections of unusable submissions, and the catalog's checks.

What the worker writes is untrusted: each reader must bound it, validate it and turn anything
malformed into a TransportError (or "missing"), never into a crash of the grader.
"""
import json
import os

import numpy as np
import pytest

from robokit.exercises import Assignment, Case, Exercise, catalog
from robokit.grading.protocol import (MAX_FLAG_LINES, MAX_MESSAGE, CallResult, DoneReport, ErrorRecord, ExerciseReport,
                                      JobDir, JobSpec, log_reference_call)
from robokit.grading.submission import (NotANotebook, UnreadableSubmission, WrongAssignment, read_submission)
from robokit.grading.transport import TransportError, write_plain


def _exercise(ex_id="00.double"):
    return Exercise(id=ex_id, function="double", signature="double(x)", points=1,
                    cases=lambda rng: [Case((1.0,))], reference=lambda x: 2 * x)


@pytest.fixture
def job(tmp_path):
    return JobDir.create(tmp_path)


def test_job_spec_round_trip(job):
    case = Case((np.arange(3.0), [1, "a"]), {"k": 2})
    spec = JobSpec(("x = 1",), (False,), ("robokit.geometry.wrap_angle",), 4.0, 3.0,
                   (("double", ((case.args, case.kwargs),)),))
    job.write_spec(spec)
    back = job.read_spec()
    assert back.cells == ("x = 1",) and back.skip == (False,) and back.call_seconds == 3.0
    assert back.references == ("robokit.geometry.wrap_angle",)
    function, ((args, kwargs),) = back.exercises[0]
    assert function == "double" and np.array_equal(args[0], np.arange(3.0)) and args[1] == [1, "a"]
    assert kwargs == {"k": 2}


def test_the_worker_gets_case_inputs_only(job):
    from robokit.grading.grader import job_spec, prepare_cases
    from robokit.grading.sandbox import Limits
    from robokit.grading.submission import Submission

    prepared = prepare_cases("00_getting_started", "secret")
    job.write_spec(job_spec(Submission(("x = 1",), (False,)), prepared, Limits()))
    text = (job.inbox / "job.json").read_text()
    assert "wrap_angle" in text and "se2_compose" in text
    labels = [c.label for cs in prepared.cases for c in cs]
    assert "ValueError" not in text and "secret" not in text and not any(label in text for label in labels)
    assert [len(inputs) for _, inputs in job.read_spec().exercises] == [len(cs) for cs in prepared.cases]


def test_exercise_report_round_trip(job):
    class Odd(ValueError):
        pass

    results = (CallResult.returned(np.float32(2.5)), CallResult.raised(Odd("no")), CallResult.returned(object()))
    job.write_exercise(0, ExerciseReport(True, results, 0.25))
    report = job.read_exercise(0, 3)
    assert report.defined and report.seconds == 0.25
    assert report.results[0] == CallResult(value=2.5)
    assert report.results[1].error.type == "Odd" and "ValueError" in report.results[1].error.classes
    assert report.results[2].error.classes == ("NotPlainData",)  # never accepted as a TypeError
    assert job.read_exercise(1, 3) is None  # never written


def test_results_too_large_to_write_read_as_unusable(job, monkeypatch):
    import robokit.grading.protocol as protocol

    real = protocol.write_plain
    calls = []

    def failing_once(value, stem):
        calls.append(stem)
        if len(calls) == 1:
            raise OSError("file too large")
        real(value, stem)

    monkeypatch.setattr(protocol, "write_plain", failing_once)
    job.write_exercise(0, ExerciseReport(True, (CallResult(value=1.0),), 0.5))
    with pytest.raises(TransportError, match="expected 1 results, got 0"):
        job.read_exercise(0, 1)
    assert len(calls) == 2


@pytest.mark.parametrize("raw, message", [
    ([1, 2], "malformed results"),
    ({"defined": True, "results": "xx"}, "malformed results"),
    ({"defined": True, "results": [{"value": 1, "error": None}]}, "expected 2 results, got 1"),
    ({"defined": True, "results": [{"value": 1, "error": None}, {"value": 1}]}, "malformed result entry"),
    ({"defined": True, "results": [{"value": 1, "error": None}, {"value": 1, "error": {}}]}, "malformed result entry"),
    ({"defined": True, "results": [{"value": 1, "error": None}, {"value": None, "error": "boom"}]},
     "malformed result entry"),
])
def test_malformed_exercise_reports_are_refused(job, raw, message):
    write_plain(raw, job.exercise_file(0))
    with pytest.raises(TransportError, match=message):
        job.read_exercise(0, 2)


def test_worker_values_are_bounded(job):
    error = {"type": "E" * 10_000, "classes": ["M" * 10_000] * 1000, "message": "m" * 10**6, "line": "hidden"}
    write_plain({"defined": True, "results": [{"value": None, "error": error}], "seconds": float("nan")},
                job.exercise_file(0))
    report = job.read_exercise(0, 1)
    err = report.results[0].error
    assert len(err.type) == 100 and len(err.classes) == 12 and len(err.message) == MAX_MESSAGE
    assert err.line == "" and report.seconds == 0.0
    write_plain({"defined": False, "results": ["anything"]}, job.exercise_file(1))
    assert job.read_exercise(1, 5) == ExerciseReport(defined=False)


@pytest.mark.parametrize("raw", [5, {"cells": 5}, "abc", {"other": []}])
def test_malformed_cells_reports_read_as_missing(job, raw):
    write_plain(raw, job.outbox / "cells")
    assert job.read_cells() is None


def test_cells_report_keeps_the_first_well_formed_records(job):
    good = {"cell": 1, "status": "error", "error": {"type": "NameError", "classes": [], "message": "x"}}
    bad = [{"cell": "1" * 10**5, "status": "error", "error": None}, {"cell": 2, "status": "???"}, 7,
           {"cell": 3, "status": "error", "error": "x"}]
    write_plain([good, *bad], job.outbox / "cells")
    cells = job.read_cells()
    assert [c.cell for c in cells] == [1] and cells[0].error.type == "NameError"
    write_plain([good] * 600, job.outbox / "cells")
    assert len(job.read_cells()) == 500


def test_reference_calls_are_read_from_the_flags_log_only_so_far(job):
    fd = job.open_flags()
    log_reference_call(fd, "robokit.geometry.wrap_angle")
    os.close(fd)
    assert job.read_reference_calls() == ["robokit.geometry.wrap_angle"]
    with open(job.outbox / "flags.log", "a") as f:
        f.write("noise\n" * MAX_FLAG_LINES + "reference:late\n")
    assert job.read_reference_calls() == ["robokit.geometry.wrap_angle"]


def test_done_report(job):
    assert job.read_done() is None
    job.write_done(DoneReport(1.5))
    assert job.read_done() == DoneReport(1.5)
    write_plain({"compute_seconds": -1.0}, job.outbox / "done")
    assert job.read_done().compute_seconds == 0.0
    (job.outbox / "done.json").write_text("not json")
    assert job.read_done() is not None  # written, so the worker finished, whatever it says


def test_error_record_survives_a_hostile_str():
    class Hostile(Exception):
        def __str__(self):
            raise RuntimeError("no")

    assert ErrorRecord.from_exception(Hostile()).message == "<unprintable exception>"


@pytest.mark.parametrize("content, kind, flag, read_error", [
    (None, UnreadableSubmission, "unreadable", True),
    ("", NotANotebook, "not-a-notebook", False),
    ("{not json", NotANotebook, "not-a-notebook", False),
    (json.dumps({"cells": {}}), NotANotebook, "not-a-notebook", False),
    (json.dumps({"cells": [], "metadata": {"robokit": {"assignment": "05_gps_sonar_truck"}}}),
     WrongAssignment, "wrong-assignment", True),
])
def test_rejections_carry_their_flag(tmp_path, content, kind, flag, read_error):
    path = tmp_path / "sub.ipynb"
    if content is not None:
        path.write_text(content)
    with pytest.raises(kind) as info:
        read_submission(path, "00_getting_started")
    assert info.value.flag == flag and info.value.read_error == read_error and str(info.value)


def test_submission_cells_and_skip_tags(tmp_path):
    nb = {"cells": [{"cell_type": "markdown", "source": "text"},
                    {"cell_type": "code", "source": ["a = 1\n", "b = 2"], "metadata": {}},
                    {"cell_type": "code", "source": "plot()", "metadata": {"tags": ["demo"]}}]}
    (tmp_path / "s.ipynb").write_text(json.dumps(nb))
    sub = read_submission(tmp_path / "s.ipynb", "00_getting_started")
    assert sub.sources == ("a = 1\nb = 2", "plot()") and sub.skip == (False, True)


@pytest.mark.parametrize("kwargs, message", [
    ({"slug": "0_demo"}, "slug"),
    ({"exercises": (_exercise(), _exercise())}, "unique"),
    ({"written": {"00.double": 1}}, "unique"),
    ({"exercises": (_exercise("01.double"),)}, "lesson number 00"),
    ({"written": {"why": 1}}, "NN.name"),
    ({"written": {"01.why": 1}}, "lesson number 00"),
    ({"written": {"00.why": 0}}, "positive"),
    ({"exercises": ("00.double",)}, "Exercise objects"),
])
def test_assignment_checks_its_declaration(kwargs, message):
    fields = {"slug": "00_demo", "exercises": (_exercise(),), "written": {"00.why": 1}, **kwargs}
    with pytest.raises(ValueError, match=message):
        Assignment(**fields)


def test_catalog_is_read_once_and_read_only():
    assert catalog() is catalog()
    with pytest.raises(TypeError):
        catalog()["00_getting_started"].written["00.why_seeds"] = 5
