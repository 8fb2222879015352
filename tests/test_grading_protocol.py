"""The grader/worker protocol, the rejections of unusable submissions, and the catalog's checks.

What the worker writes is untrusted: each reader must bound it, validate it and turn anything
malformed into a TransportError (or "missing"), never into a crash of the grader.
"""
import json
import os

import numpy as np
import pytest

from robocourse.exercises import Case, Exercise
from robocourse.lessons import Assignment, catalog
from robocourse.grading.protocol import (MAX_FLAG_LINES, MAX_MESSAGE, CallResult, DoneReport, ErrorRecord, ExerciseReport,
                                      JobDir, JobSpec, log_withheld_import)
from robocourse.grading.submission import (NotANotebook, SymlinkedSubmission, UnreadableSubmission, WrongAssignment,
                                        read_submission)
from robocourse.grading.transport import TransportError, write_plain


def _exercise(ex_id="00.double"):
    return Exercise(id=ex_id, function="double", signature="double(x)", points=1,
                    cases=lambda rng: [Case((1.0,))], answer=lambda x: 2 * x)


@pytest.fixture
def job(tmp_path):
    return JobDir.create(tmp_path)


def test_job_spec_round_trip(job):
    case = Case((np.arange(3.0), [1, "a"]), {"k": 2})
    spec = JobSpec(("x = 1",), (False,), 4.0, 3.0,
                   (("double", ((case.args, case.kwargs),)),))
    job.write_spec(spec)
    back = job.read_spec()
    assert back.cells == ("x = 1",) and back.skip == (False,) and back.call_seconds == 3.0
    function, ((args, kwargs),) = back.exercises[0]
    assert function == "double" and np.array_equal(args[0], np.arange(3.0)) and args[1] == [1, "a"]
    assert kwargs == {"k": 2}


def test_the_worker_gets_case_inputs_only(job):
    from robocourse.grading.grader import job_spec, prepare_cases
    from robocourse.grading.sandbox import Limits
    from robocourse.grading.submission import Submission

    prepared = prepare_cases("00_getting_started", "secret")
    job.write_spec(job_spec(Submission(("x = 1",), (False,)), prepared, Limits()))
    text = (job.inbox / "job.json").read_text()
    assert "wrap_angle" in text and "se2_compose" in text
    labels = [c.label for cs in prepared.cases for c in cs]
    assert "ValueError" not in text and "secret" not in text and not any(label in text for label in labels)
    assert [len(inputs) for _, inputs in job.read_spec().exercises] == [len(cs) for cs in prepared.cases]


def test_the_worker_never_gets_a_cases_known_answer(job):
    from robocourse.grading.grader import PreparedCases, job_spec
    from robocourse.grading.sandbox import Limits
    from robocourse.grading.submission import Submission

    case = Case((1.25,), expected=[987654.321], label="a simulated truth")
    prepared = PreparedCases((_exercise(),), [[case]], [[case.expected]], [[frozenset()]], "00_getting_started", "s")
    job.write_spec(job_spec(Submission(("x = 1",), (False,)), prepared, Limits()))
    text = (job.inbox / "job.json").read_text()
    assert "1.25" in text and "987654" not in text and "simulated" not in text


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
    import robocourse.grading.protocol as protocol

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
    write_plain({"defined": True, "results": [{"value": None, "error": error}], "seconds": 0.5}, job.exercise_file(0))
    report = job.read_exercise(0, 1)
    err = report.results[0].error
    assert len(err.type) == 100 and len(err.classes) == 12 and len(err.message) == MAX_MESSAGE
    assert err.line == "" and report.seconds == 0.5
    write_plain({"defined": False, "results": ["anything"]}, job.exercise_file(1))
    assert job.read_exercise(1, 5) == ExerciseReport(defined=False)


@pytest.mark.parametrize("raw", [5, {"cells": 5}, "abc", {"other": []}])
def test_malformed_cells_reports_are_refused(job, raw):
    write_plain(raw, job.outbox / "cells")
    with pytest.raises(TransportError):
        job.read_cells()


@pytest.mark.parametrize("bad", [{"cell": "1" * 10**5, "status": "error", "error": None}, {"cell": 2, "status": "???"},
                                 7, {"cell": 3, "status": "error", "error": "x"}, {"cell": True, "status": "ok"},
                                 {"cell": -1, "status": "ok"}])
def test_one_malformed_cell_record_makes_the_report_unusable(job, bad):
    good = {"cell": 1, "status": "error", "error": {"type": "NameError", "classes": [], "message": "x"}}
    write_plain([good, bad], job.outbox / "cells")
    with pytest.raises(TransportError):
        job.read_cells()


def test_cells_report_keeps_the_first_records(job):
    good = {"cell": 1, "status": "error", "error": {"type": "NameError", "classes": [], "message": "x"}}
    write_plain([good], job.outbox / "cells")
    cells = job.read_cells()
    assert [c.cell for c in cells] == [1] and cells[0].error.type == "NameError"
    write_plain([good] * 600, job.outbox / "cells")
    assert len(job.read_cells()) == 500
    assert JobDir.create(job.root).read_cells() is None  # never written


def test_reference_calls_are_read_from_the_flags_log_only_so_far(job):
    fd = job.open_flags()
    log_withheld_import(fd, "robokit.geometry.wrap_angle")
    os.close(fd)
    assert job.read_withheld_imports() == ["robokit.geometry.wrap_angle"]
    with open(job.outbox / "flags.log", "a") as f:
        f.write("noise\n" * MAX_FLAG_LINES + "reference:late\n")
    assert job.read_withheld_imports() == ["robokit.geometry.wrap_angle"]


def test_done_report(job):
    assert job.read_done() is None
    job.write_done(DoneReport(1.5))
    assert job.read_done() == DoneReport(1.5)
    for raw in ({"compute_seconds": -1.0}, {"compute_seconds": float("nan")}, {"compute_seconds": "1"}, [1.0]):
        write_plain(raw, job.outbox / "done")
        with pytest.raises(TransportError):
            job.read_done()


def test_error_record_survives_a_hostile_str():
    class Hostile(Exception):
        def __str__(self):
            raise RuntimeError("no")

    assert ErrorRecord.from_exception(Hostile()).message == "<unprintable exception>"


@pytest.mark.parametrize("content, kind, flag", [
    (None, UnreadableSubmission, "unreadable"),
    ("", NotANotebook, "not-a-notebook"),
    ("{not json", NotANotebook, "not-a-notebook"),
    (json.dumps({"cells": {}}), NotANotebook, "not-a-notebook"),
    (json.dumps({"cells": [], "metadata": {"robokit": {"assignment": "05_gps_sonar_truck"}}}),
     WrongAssignment, "wrong-assignment"),
])
def test_rejections_carry_their_flag(tmp_path, content, kind, flag):
    path = tmp_path / "sub.ipynb"
    if content is not None:
        path.write_text(content)
    with pytest.raises(kind) as info:
        read_submission(path, "00_getting_started")
    assert info.value.flag == flag and str(info.value)


def _code(**fields):
    return {"cell_type": "code", "source": "x = 1", "metadata": {}, **fields}


# every way a notebook can be malformed is a rejection with a flag (issue 12, deliverable 1/6)
MALFORMED_NOTEBOOKS = {
    "code cell metadata not a dict": json.dumps({"cells": [_code(metadata=[1, 2])]}),
    "code cell metadata a string": json.dumps({"cells": [_code(metadata="tags")]}),
    "source a list holding non-strings": json.dumps({"cells": [_code(source=["x = 1\n", 2, None])]}),
    "source a number": json.dumps({"cells": [_code(source=5)]}),
    "tags not a list": json.dumps({"cells": [_code(metadata={"tags": "demo"})]}),
    "tags holding non-strings": json.dumps({"cells": [_code(metadata={"tags": [["demo"]]})]}),
    "a cell that is not an object": json.dumps({"cells": [_code(), 5]}),
    "notebook metadata not a dict": json.dumps({"cells": [], "metadata": []}),
    "robokit metadata not a dict": json.dumps({"cells": [], "metadata": {"robokit": "00"}}),
    "declared assignment not a string": json.dumps({"cells": [], "metadata": {"robokit": {"assignment": [1] * 10**5}}}),
    "5000-digit integer": '{"cells": [], "metadata": {"n": ' + "7" * 5000 + "}}",
    "deeply nested": '{"cells": [], "x": ' + "[" * 100_000 + "]" * 100_000 + "}",
    "invalid UTF-8": b'{"cells": [{"cell_type": "code", "source": "\xff\xfe", "metadata": {}}]}',
    "UTF-16": json.dumps({"cells": []}).encode("utf-16"),
    "only whitespace": "   \n",
}


@pytest.mark.parametrize("name", list(MALFORMED_NOTEBOOKS))
def test_a_malformed_notebook_is_rejected_with_a_flag(tmp_path, name):
    content = MALFORMED_NOTEBOOKS[name]
    path = tmp_path / "sub.ipynb"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(NotANotebook) as info:
        read_submission(path, "00_getting_started")
    assert info.value.flag == "not-a-notebook" and len(str(info.value)) < 200


def test_a_notebook_larger_than_the_limit_is_rejected_without_reading_it(tmp_path):
    path = tmp_path / "big.ipynb"
    with open(path, "wb") as f:
        f.write(b'{"cells": [')
        f.truncate(200_000_000)  # sparse: 200 MB
    with pytest.raises(NotANotebook, match="larger than 20 MB"):
        read_submission(path, "00_getting_started")


def _solution_copy(folder):
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / "00_getting_started.ipynb"
    target.write_text(json.dumps({"cells": [_code(source="SOLVED = True")]}))
    return target


def test_a_symlinked_submission_is_refused_not_followed(tmp_path):
    solution = _solution_copy(tmp_path / "solutions")
    (tmp_path / "subs").mkdir()
    link = tmp_path / "subs" / "mallory.ipynb"
    link.symlink_to(solution)
    with pytest.raises(SymlinkedSubmission) as info:
        read_submission(link, "00_getting_started")
    assert info.value.flag == "symlink"


def test_a_symlinked_student_folder_is_refused_not_followed(tmp_path):
    _solution_copy(tmp_path / "solutions")
    (tmp_path / "subs").mkdir()
    (tmp_path / "subs" / "mallory").symlink_to(tmp_path / "solutions")
    with pytest.raises(SymlinkedSubmission, match="folder 'mallory'"):
        read_submission(tmp_path / "subs" / "mallory" / "00_getting_started.ipynb", "00_getting_started")


def test_a_symlinked_folder_above_the_students_is_the_instructors(tmp_path):
    # the instructor may keep submissions behind a link (e.g. /tmp on macOS, a mounted drive)
    _solution_copy(tmp_path / "real" / "alice")
    (tmp_path / "subs").symlink_to(tmp_path / "real")
    sub = read_submission(tmp_path / "subs" / "alice" / "00_getting_started.ipynb", "00_getting_started")
    assert sub.sources == ("SOLVED = True",)
    (tmp_path / "real" / "bob.ipynb").write_text(json.dumps({"cells": []}))
    assert read_submission(tmp_path / "subs" / "bob.ipynb", "00_getting_started").sources == ()


@pytest.mark.parametrize("kind", ["fifo", "directory"])
def test_a_submission_that_is_not_a_regular_file_is_unreadable(tmp_path, kind):
    path = tmp_path / "sub.ipynb"
    os.mkfifo(path) if kind == "fifo" else path.mkdir()
    with pytest.raises(UnreadableSubmission):
        read_submission(path, "00_getting_started")


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
    ({"data": {"x": 1}}, "data must be a function"),
])
def test_assignment_checks_its_declaration(kwargs, message):
    fields = {"slug": "00_demo", "exercises": (_exercise(),), "written": {"00.why": 1}, **kwargs}
    with pytest.raises(ValueError, match=message):
        Assignment(**fields)


def test_catalog_is_read_once_and_read_only():
    assert catalog() is catalog()
    with pytest.raises(TypeError):
        catalog()["00_getting_started"].written["00.why_seeds"] = 5


# -- everything under out/ is hostile: links, FIFOs, directories, garbage, wrong types ------------
# (issue 12, deliverable 1). Each reader must refuse it with a TransportError, at once: no link
# followed, no FIFO waited on, no unbounded read, no other exception.

GOOD_EXERCISE = {"defined": True, "results": [{"value": 1.0, "error": None}], "seconds": 0.1}
READERS = {  # file the worker writes -> how the grader reads it
    "cells.json": lambda job: job.read_cells(),
    "ex0.json": lambda job: job.read_exercise(0, 1),
    "done.json": lambda job: job.read_done(),
    "flags.log": lambda job: job.read_withheld_imports(),
}


def _elsewhere(job):
    other = job.work / "elsewhere.json"
    other.write_text(json.dumps(GOOD_EXERCISE))
    return other


FILE_ATTACKS = {  # the file is replaced by something that is not a regular file of its own
    "symlink to /dev/zero": lambda job, p: p.symlink_to("/dev/zero"),
    "symlink to a valid file": lambda job, p: p.symlink_to(_elsewhere(job)),
    "fifo": lambda job, p: os.mkfifo(p),
    "directory": lambda job, p: p.mkdir(),
    "hard link": lambda job, p: os.link(_elsewhere(job), p),
}
CONTENT_ATTACKS = {  # a regular file with bad content
    "garbage bytes": lambda job, p: p.write_bytes(bytes(range(256)) * 40),
    "truncated JSON": lambda job, p: p.write_text(json.dumps(GOOD_EXERCISE)[:25]),
    "invalid UTF-8": lambda job, p: p.write_bytes(b'{"defined": true, "x": "\xff\xfe"}'),
    "5000-digit integer": lambda job, p: p.write_text('{"seconds": ' + "9" * 5000 + "}"),
    "deeply nested": lambda job, p: p.write_text("[" * 100_000 + "]" * 100_000),
    "larger than the bound": lambda job, p: os.truncate(p.write_text("") or p, 30_000_000),
}


def _plant(job, name, attack):
    path = job.outbox / name
    if path.exists() or path.is_symlink():
        path.unlink()
    attack(job, path)


@pytest.mark.parametrize("name", list(READERS))
@pytest.mark.parametrize("attack", list(FILE_ATTACKS))
def test_a_result_file_that_is_not_a_regular_file_is_refused(job, name, attack):
    _plant(job, name, FILE_ATTACKS[attack])
    with pytest.raises(TransportError):
        READERS[name](job)


@pytest.mark.parametrize("name", ["cells.json", "ex0.json", "done.json"])
@pytest.mark.parametrize("attack", list(CONTENT_ATTACKS))
def test_a_result_file_with_bad_content_is_refused(job, name, attack):
    _plant(job, name, CONTENT_ATTACKS[attack])
    with pytest.raises(TransportError):
        READERS[name](job)


@pytest.mark.parametrize("raw", [
    {**GOOD_EXERCISE, "seconds": 10**4000}, {**GOOD_EXERCISE, "seconds": "0.1"}, {**GOOD_EXERCISE, "seconds": -1},
    {**GOOD_EXERCISE, "seconds": None}, {**GOOD_EXERCISE, "defined": "yes"},
    {**GOOD_EXERCISE, "results": [{"value": None, "error": {"type": ["E"], "classes": [], "message": "m"}}]},
    {**GOOD_EXERCISE, "results": [{"value": None, "error": {"type": "E", "classes": "E", "message": "m"}}]},
    {**GOOD_EXERCISE, "results": [{"value": None, "error": {"type": "E", "classes": [], "message": 10**4000}}]},
])
def test_an_exercise_report_with_a_wrong_type_is_refused(job, raw):
    (job.outbox / "ex0.json").write_text(json.dumps(raw))
    with pytest.raises(TransportError):
        job.read_exercise(0, 1)


@pytest.mark.parametrize("raw", [{"compute_seconds": 10**4000}, {"compute_seconds": None}, "done", [],
                                 {"compute_seconds": True}])
def test_a_final_report_with_a_wrong_type_is_refused(job, raw):
    (job.outbox / "done.json").write_text(json.dumps(raw))
    with pytest.raises(TransportError):
        job.read_done()


def _npy_bytes(header: dict, data: bytes) -> bytes:
    import io

    f = io.BytesIO()
    np.lib.format.write_array_header_1_0(f, header)
    return f.getvalue() + data


def _zip(members: dict[str, bytes], compression=None) -> bytes:
    import io
    import zipfile

    f = io.BytesIO()
    with zipfile.ZipFile(f, "w", compression or zipfile.ZIP_STORED) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return f.getvalue()


def _bad_crc(job):
    write_plain({"a": np.arange(1000.0)}, job.outbox / "tmp")
    raw = bytearray((job.outbox / "tmp.npz").read_bytes())
    raw[len(raw) // 2] ^= 0xFF
    return bytes(raw)


def _overlapping(job, copies=20):
    """One stored member whose central-directory entry is repeated: every entry points at the same
    bytes (a small file that would cost ``copies`` full reads; zipfile reads each)."""
    import struct

    one = _zip({"a0.npy": _npy_bytes({"descr": "<f8", "fortran_order": False, "shape": (1000,)}, bytes(8000))})
    end = one[-22:]
    cd_size, cd_offset = struct.unpack("<II", end[12:20])
    entry = one[cd_offset:cd_offset + cd_size]
    directory = entry * copies
    return (one[:cd_offset] + directory + end[:8] + struct.pack("<HHII", copies, copies, len(directory), cd_offset)
            + end[20:])


NPZ_ATTACKS = {
    "bad CRC (BadZipFile)": _bad_crc,
    "not a zip": lambda job: b"PK\x03\x04" + bytes(range(256)) * 10,
    "zip bomb": lambda job: _zip({"a0.npy": _npy_bytes({"descr": "<f8", "fortran_order": False, "shape": (9 * 2**20,)},
                                                       bytes(72 * 2**20))}, compression=8),
    "shape larger than the data": lambda job: _zip({"a0.npy": _npy_bytes(
        {"descr": "<f8", "fortran_order": False, "shape": (10**12,)}, bytes(8))}),
    "object dtype (a pickle)": lambda job: _zip({"a0.npy": _npy_bytes(
        {"descr": "|O", "fortran_order": False, "shape": (1,)}, b"\x80\x04N.")}),
    "structured dtype": lambda job: _zip({"a0.npy": _npy_bytes(
        {"descr": [("x", "<f8")], "fortran_order": False, "shape": (1,)}, bytes(8))}),
    "string dtype": lambda job: _zip({"a0.npy": _npy_bytes({"descr": "<U1", "fortran_order": False, "shape": (1,)},
                                                           bytes(4))}),
    "member that is not an array": lambda job: _zip({"a0.npy": bytes(8), "evil.txt": b"x"}),
    "array missing": lambda job: _zip({"a1.npy": _npy_bytes({"descr": "<f8", "fortran_order": False, "shape": (1,)},
                                                            bytes(8))}),
    # members that share their bytes: each costs a full read (a 1 MB file, hours of CPU)
    "overlapping members": _overlapping,
    # more members than the reader allows: refused from the end record, before zipfile lists them
    "too many members": lambda job: _zip({f"a{k}.npy": b"" for k in range(10_001)}),
    "compressed member": lambda job: _zip({"a0.npy": _npy_bytes({"descr": "<f8", "fortran_order": False,
                                                                 "shape": (1,)}, bytes(8))}, compression=8),
}


@pytest.mark.parametrize("attack", list(NPZ_ATTACKS))
def test_a_hostile_npz_is_refused(job, attack):
    report = {"defined": True, "results": [{"value": {"__robokit_array__": "a0"}, "error": None}], "seconds": 0.1}
    (job.outbox / "ex0.json").write_text(json.dumps(report))
    (job.outbox / "ex0.npz").write_bytes(NPZ_ATTACKS[attack](job))
    with pytest.raises(TransportError):
        job.read_exercise(0, 1)


@pytest.mark.parametrize("attack", ["symlink to /dev/zero", "fifo", "directory"])
def test_an_npz_that_is_not_a_regular_file_is_refused(job, attack):
    write_plain(GOOD_EXERCISE, job.exercise_file(0))
    FILE_ATTACKS[attack](job, job.outbox / "ex0.npz")
    with pytest.raises(TransportError):
        job.read_exercise(0, 1)


def test_arrays_of_every_layout_survive_the_checked_reader(job):
    arrays = [np.arange(6.0).reshape(2, 3).T, np.asfortranarray(np.eye(3)), np.array(2.5), np.zeros((0, 3)),
              np.array([True, False]), np.arange(4, dtype=">i4"), np.arange(3, dtype=np.uint8)]
    results = tuple(CallResult.returned(a) for a in arrays)
    job.write_exercise(0, ExerciseReport(True, results, 0.1))
    back = job.read_exercise(0, len(arrays))
    for a, r in zip(arrays, back.results):
        assert r.value.shape == a.shape and np.array_equal(r.value, a)


def test_an_outbox_replaced_by_a_link_is_not_followed(job, tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    write_plain(GOOD_EXERCISE, elsewhere / "ex0")
    job.outbox.rmdir()
    job.outbox.symlink_to(elsewhere)
    with pytest.raises(TransportError):
        job.read_exercise(0, 1)
    with pytest.raises(TransportError):
        job.read_withheld_imports()


@pytest.mark.parametrize("attack", ["symlink to /dev/zero", "fifo", "directory"])
def test_the_worker_log_is_read_like_the_results(job, attack):
    FILE_ATTACKS[attack](job, job.log_file)
    assert "unusable" in job.read_log_tail()
    job.log_file.unlink() if job.log_file.is_symlink() or job.log_file.is_file() or job.log_file.is_fifo() \
        else job.log_file.rmdir()
    job.log_file.write_bytes(b"x" * 10_000 + b"the end\n")
    tail = job.read_log_tail()
    assert tail.endswith("the end\n") and len(tail) <= 4000


def test_an_array_named_twice_is_refused(job):
    # one small int8 array named by every entry of a long list widens to int64 once per name: the
    # grader's memory would grow without bound (100 kB on disk took hundreds of MB)
    write_plain({"a": np.zeros(100_000, dtype=np.int8)}, job.exercise_file(0))
    doc = json.loads(job.exercise_file(0).with_suffix(".json").read_text())
    ref = doc["a"]
    report = {"defined": True, "results": [{"value": [ref, ref], "error": None}], "seconds": 0.1}
    (job.outbox / "ex0.json").write_text(json.dumps(report))
    with pytest.raises(TransportError, match="referenced twice"):
        job.read_exercise(0, 1)
