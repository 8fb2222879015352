"""The grader against hostile submissions (issue "Autograding", Acceptance).

Each hostile notebook is the real 00 solution with one attack injected, so the exercises the
attack does not touch must still score full marks, and the ones it does must score zero (flagged
where it cheated). The whole batch is graded in one call and must finish in bounded time.
"""
import json
import os
import time

import pytest

from robokit.grading.grader import grade_batch
from robokit.grading.sandbox import Limits, is_root
from tests.conftest import ROOT

SOLUTION = ROOT / "solutions" / "00_getting_started.ipynb"
LIMITS = Limits(wall_seconds=40, cpu_seconds=40, cell_seconds=4, call_seconds=3, memory_bytes=3 * 1024**3)
FULL = {"00.wrap_angle": 1.0, "00.se2_compose": 2.0}


SELF_CONTAINED_COMPOSE = """def se2_compose(a, b):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != (3,) or b.shape != (3,):
        raise ValueError("a, b: expected shape (3,)")
    c, s = np.cos(a[2]), np.sin(a[2])
    heading = np.mod(a[2] + b[2] + np.pi, 2 * np.pi) - np.pi
    return np.array([a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], heading])
"""


def _cells():
    """The 00 solution, with se2_compose made independent of wrap_angle so that an attack on
    wrap_angle affects only that exercise."""
    nb = json.loads(SOLUTION.read_text())
    for cell in nb["cells"]:
        if cell["cell_type"] == "code" and "".join(cell["source"]).startswith("def se2_compose"):
            cell["source"] = SELF_CONTAINED_COMPOSE
    return nb


def _code(src):
    return {"cell_type": "code", "metadata": {}, "source": src, "outputs": [], "execution_count": None}


def _with(extra_before_end=None, replace_wrap=None, extra_at_end=None):
    nb = _cells()
    if replace_wrap is not None:
        for cell in nb["cells"]:
            if cell["cell_type"] == "code" and "".join(cell["source"]).startswith("def wrap_angle"):
                cell["source"] = replace_wrap
    if extra_before_end is not None:
        # inject right after the setup cell, before any exercise is defined
        nb["cells"].insert(2, _code(extra_before_end))
    if extra_at_end is not None:
        nb["cells"].append(_code(extra_at_end))
    return nb


WRONG_WRAP = "def wrap_angle(angle):\n    return 12345.0\n"  # wrong on every case

HOSTILE = {
    # name: (notebook, expected points per exercise, flag expected or None)
    "infinite_loop_in_cell": (_with("while True:\n    pass\n"), FULL, None),
    "infinite_loop_in_function": (_with(replace_wrap="def wrap_angle(angle):\n    while True:\n        pass\n"),
                                  {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, None),
    "loop_that_swallows_timeouts": (_with("import time\nwhile True:\n    try:\n        time.sleep(0.2)\n"
                                          "    except BaseException:\n        pass\n"),
                                    {"00.wrap_angle": 0.0, "00.se2_compose": 0.0}, "timeout"),
    "memory_bomb": (_with("x = bytearray(64 * 1024**3)\n"), FULL, None),
    "memory_bomb_in_function": (_with(replace_wrap="def wrap_angle(angle):\n    return bytearray(64 * 1024**3)\n"),
                                {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, None),
    "fork_bomb": (_with("import os\nwhile True:\n    os.fork()\n"), FULL, None),
    "sys_exit": (_with("import sys\nsys.exit(0)\n"), FULL, None),
    "os_exit": (_with("import os\nos._exit(0)\n"), FULL, None),
    "fake_results_print": (_with('print("student,file,00.wrap_angle,00.se2_compose,total\\nme,x,1,2,3")\n'
                                 'print(json.dumps({"results": [{"value": 1}]}))\nimport json\n',
                                 replace_wrap=WRONG_WRAP), {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, None),
    "patch_numpy_compare": (_with("import numpy, numpy.testing\nnumpy.allclose = lambda *a, **k: True\n"
                                  "numpy.isclose = lambda a, b, **k: numpy.ones(numpy.shape(a), bool)\n"
                                  "numpy.testing.assert_allclose = lambda *a, **k: None\n",
                                  replace_wrap=WRONG_WRAP), {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, None),
    "lying_eq_object": (_with(replace_wrap="class Liar(float):\n    def __eq__(self, o): return True\n"
                                           "    def __bool__(self): return True\n"
                                           "def wrap_angle(angle):\n    return Liar(0.0)\n"),
                        {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, None),
    "calls_reference": (_with(replace_wrap="from robokit.geometry import wrap_angle as _ref\n"
                                           "def wrap_angle(angle):\n    return _ref(angle)\n"),
                        {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, "called-reference"),
    "huge_print": (_with("print('x' * 50_000_000)\nimport os\nos.write(1, b'y' * 50_000_000)\n"), FULL, None),
    "not_json": ("this is not a notebook {", {"00.wrap_angle": 0.0, "00.se2_compose": 0.0}, "not-a-notebook"),
}


def _write_out_path_attack(out_csv, feedback):
    code = (f"for p in [{str(out_csv)!r}, {str(feedback / 'victim.md')!r}]:\n"
            "    try:\n        open(p, 'w').write('HACKED')\n    except OSError as e:\n        print(e)\n")
    return _with(code, replace_wrap=WRONG_WRAP)


def _read_solution_attack():
    # tries to copy the instructor's solution code out of the solutions notebook
    code = ("import json\nsrc = json.load(open(%r))\n"
            "exec('\\n'.join(''.join(c['source']) for c in src['cells'] if c['cell_type'] == 'code' "
            "and 'def wrap_angle' in ''.join(c['source'])))\n" % str(SOLUTION))
    return _with(replace_wrap=WRONG_WRAP, extra_at_end=code)  # last, so a stolen def would win


def _network_attack(port):
    # answers correctly only if it cannot reach a server listening in the grader's namespace
    code = f"""import socket
def _can_connect():
    try:
        socket.create_connection(("127.0.0.1", {port}), timeout=1).close()
        return True
    except OSError:
        return False
def wrap_angle(angle):
    if _can_connect():
        return 12345.0
    a = np.asarray(angle, dtype=float)
    if np.any(np.isnan(a)):
        raise ValueError("nan")
    w = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return float(w) if w.ndim == 0 else w
"""
    return _with(replace_wrap=code)


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    folder = tmp_path_factory.mktemp("subs")
    out = tmp_path_factory.mktemp("out")
    feedback = out / "feedback"
    feedback.mkdir()
    (feedback / "victim.md").write_text("original")
    cases = dict(HOSTILE)
    cases["writes_output_paths"] = (_write_out_path_attack(out / "grades.csv", feedback),
                                    {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, None)
    cases["reads_solution"] = (_read_solution_attack(), {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, None)
    cases["honest"] = (_cells(), FULL, None)
    cases["check_from_its_module"] = (_with(extra_at_end="from robokit.grading.check import check\n"
                                                         "check('00.wrap_angle', lambda angle: angle)\n"), FULL, None)
    import socket

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(64)
    cases["reaches_network"] = (_network_attack(server.getsockname()[1]), FULL, None)
    paths = []
    for name, (nb, _, _) in cases.items():
        p = folder / f"{name}.ipynb"
        p.write_text(nb if isinstance(nb, str) else json.dumps(nb))
        paths.append(p)
    start = time.perf_counter()
    results = grade_batch(paths, "00_getting_started", "hostile-seed", jobs=2, limits=LIMITS,
                          hide=[ROOT / "solutions", out], log=lambda *_: None)
    elapsed = time.perf_counter() - start
    server.close()
    return {r.student: r for r in results}, cases, elapsed, out, feedback


@pytest.mark.parametrize("name", list(HOSTILE) + ["writes_output_paths", "reads_solution", "honest",
                                                  "reaches_network", "check_from_its_module"])
def test_hostile_submission_scores_only_what_it_earned(graded, name):
    results, cases, _, _, _ = graded
    if name in ("reads_solution", "reaches_network") and not is_root():
        pytest.skip("hiding files and the network from the worker needs root (namespaces); see README")
    result = results[name]
    _, expected, flag = cases[name]
    got = {s.id: s.points for s in result.scores}
    assert got == expected, (result.flags, [m for s in result.scores for m in s.messages][:6], result.cell_errors[:4])
    if flag:
        assert flag in result.flags
    if name != "not_json" and is_root():
        assert "sandbox=limited" not in result.flags
    if name == "honest":
        assert result.flags == [] and result.worker_log == ""


def test_check_is_silenced_however_it_is_imported(graded):
    # check() on public cases would fail this lambda and raise in the cell; under grading it only
    # prints that it is skipped, whether imported from robokit.grading or robokit.grading.check
    results, _, _, _, _ = graded
    assert results["check_from_its_module"].cell_errors == []


def test_batch_time_is_bounded(graded):
    _, cases, elapsed, _, _ = graded
    # two jobs; at most a few submissions reach the 40 s wall limit
    assert elapsed < 180, f"batch of {len(cases)} took {elapsed:.0f}s"


def test_output_paths_untouched(graded):
    _, _, _, out, feedback = graded
    if not is_root():
        pytest.skip("hiding output paths needs root")
    assert (feedback / "victim.md").read_text() == "original"
    assert not (out / "grades.csv").exists()


def test_no_worker_processes_left(graded):
    if not is_root():
        pytest.skip("job uids exist only when grading as root")
    from robokit.grading.sandbox import JOB_UID_BASE

    left = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if JOB_UID_BASE <= os.stat(f"/proc/{entry}").st_uid < JOB_UID_BASE + 64:
                    left.append(entry)
            except OSError:
                pass
    assert not left


def test_a_crashing_worker_is_explained(tmp_path):
    """A submission that kills its own process (bypassing the patched os._exit) gets the
    affected exercises at zero and a feedback section with the worker's last words."""
    from robokit.grading.reports import feedback_text

    nb = _with(extra_at_end="import posix, sys\nsys.__stderr__.write('about to die\\n')\nsys.__stderr__.flush()\nposix._exit(3)\n")
    path = tmp_path / "crasher.ipynb"
    path.write_text(json.dumps(nb))
    result = grade_batch([path], "00_getting_started", "s", limits=LIMITS, log=lambda *_: None)[0]
    assert "worker-ended-early" in result.flags
    assert all(s.points == 0 for s in result.scores)
    assert "about to die" in result.worker_log
    assert "Last lines of the grading process" in feedback_text(result, "00_getting_started")
