"""The grader against hostile submissions (issue "Autograding", Acceptance).

Each hostile notebook is the real 00 solution with one attack injected, so the exercises the
attack does not touch must still score full marks, and the ones it does must score zero (flagged
where it cheated). The whole batch is graded in one call and must finish in bounded time.
"""
import json
import os
import time
from pathlib import Path

import pytest

from robokit.grading.grader import grade_batch
from robokit.grading.sandbox import Limits, is_root
from tests.conftest import ROOT, public_tmp, wrap_angle_unless

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
"""
    return _with(replace_wrap=code + wrap_angle_unless("_can_connect()"))


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
    import fcntl

    from robokit.grading.sandbox import JOB_UIDS, UID_LEASE_DIR

    # another grading run on the host may be busy with its own (leased) uids; a process of a uid
    # whose lease is free is a leftover
    left = []
    for entry in os.listdir("/proc"):
        try:
            uid = os.stat(f"/proc/{entry}").st_uid if entry.isdigit() else -1
        except OSError:
            continue
        if uid in JOB_UIDS:
            fd = os.open(UID_LEASE_DIR / f"{uid}.lock", os.O_RDWR | os.O_CREAT, 0o600)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                left.append((entry, uid))
            except BlockingIOError:
                pass
            finally:
                os.close(fd)
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


# -- issue 12, helper G: what the worker can see and load -------------------------------------------
#
# Each attack tries to reach the reference implementation or solved work from the submission's own
# process. The worker must have no reference loaded or importable (the trusted parent computes every
# expected answer) and, as root, must see only the interpreter, the installed packages' code, its
# own job and a robokit that holds the worker and the assignment's student-facing helpers.

PLANAR_SOURCE = ROOT / "robokit" / "geometry" / "planar.py"


def _steal_from(path):
    """Cells that exec the ``def wrap_angle`` cell of the notebook at ``path`` (last, so it wins)."""
    return ("import json\nsrc = json.load(open(%r))\n"
            "exec('\\n'.join(''.join(c['source']) for c in src['cells'] if c['cell_type'] == 'code' "
            "and 'def wrap_angle' in ''.join(c['source'])))\n" % str(path))


def _reference_attacks():
    """name: (notebook, expected points, flag or None); each attack targets wrap_angle only."""
    wrong_only = {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}
    through = "def wrap_angle(angle):\n    return _ref(angle)\n"
    return {
        # the trap's own closure held the real function
        "g_trap_kwdefaults": (_with(replace_wrap="import robokit.geometry as _g\n"
                                                 "_ref = (_g.wrap_angle.__kwdefaults__ or {}).get('__real', _g.wrap_angle)\n"
                                                 + through), wrong_only, "called-reference"),
        # a fresh copy of the module, built after the trap was installed
        "g_reload_module": (_with(replace_wrap="import importlib\nimport robokit.geometry.planar as _p\n"
                                               "_ref = importlib.reload(_p).wrap_angle\n" + through),
                            wrong_only, "called-reference"),
        # robokit's source run under robokit's file name, so the trap took it for library code
        "g_exec_as_robokit": (_with(replace_wrap="import types, robokit\n"
                                                 "_m = types.ModuleType('robokit.geometry.planar')\n"
                                                 "_m.__package__ = 'robokit.geometry'\n"
                                                 f"exec(compile(open({str(PLANAR_SOURCE)!r}).read(), robokit.__file__, 'exec'),"
                                                 " _m.__dict__)\n_ref = _m.wrap_angle\n" + through), wrong_only, None),
        # drop every import hook and every loaded robokit module, point sys.path at the real
        # package, and import again
        "g_import_hooks_removed": (_with(replace_wrap=(
            "import sys\n"
            "sys.meta_path[:] = [f for f in sys.meta_path if getattr(f, '__module__', '').startswith('_frozen')"
            " or getattr(type(f), '__module__', '').startswith(('_frozen', '__editable__'))]\n"
            "for _k in [k for k in sys.modules if k == 'robokit' or k.startswith('robokit.')]:\n"
            "    del sys.modules[_k]\n"
            f"sys.path[:0] = [{str(ROOT)!r}]\n"
            "from robokit.geometry import wrap_angle as _ref\n" + through)), wrong_only, None),
        # another library function that calls the reference inside robokit
        "g_library_calls_it": (_with(replace_wrap=(
            "from robokit.geometry import se2_inverse\n"
            "def wrap_angle(angle):\n"
            "    a = np.asarray(angle, dtype=float)\n"
            "    out = np.array([se2_inverse([0.0, 0.0, -x])[2] for x in a.ravel()])\n"
            "    return float(out[0]) if a.ndim == 0 else out.reshape(a.shape)\n")), wrong_only, "called-reference"),
        # any function object robokit left in the process
        "g_garbage_collector": (_with(replace_wrap=(
            "import gc\n"
            "_found = [o for o in gc.get_objects() if type(o).__name__ == 'function' and o.__name__ == 'wrap_angle'"
            " and (o.__module__ or '').startswith('robokit') and '__real' not in (o.__kwdefaults__ or {})]\n"
            "def wrap_angle(angle):\n"
            "    return _found[0](angle) if _found else 12345.0\n")), wrong_only, None),
    }


def _view_attacks(folder, elsewhere):
    """Attacks on the worker's filesystem view: solved work in the course, the batch and the disk."""
    wrong_only = {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}
    git = ("import json, subprocess\n"
           f"_out = subprocess.run(['git', '-c', 'safe.directory=*', '-C', {str(ROOT)!r}, 'show',"
           " 'HEAD:solutions/00_getting_started.ipynb'], capture_output=True, text=True, timeout=20).stdout\n"
           "exec('\\n'.join(''.join(c['source']) for c in json.loads(_out)['cells'] if c['cell_type'] == 'code'"
           " and 'def wrap_angle' in ''.join(c['source'])))\n")
    return {
        "g_git_show_solution": (_with(replace_wrap=WRONG_WRAP, extra_at_end=git), wrong_only, None),
        "g_course_solutions": (_with(replace_wrap=WRONG_WRAP, extra_at_end=_steal_from(SOLUTION)), wrong_only, None),
        "g_other_student": (_with(replace_wrap=WRONG_WRAP,
                                  extra_at_end=_steal_from(folder / "g_honest" / "00_getting_started.ipynb")),
                            wrong_only, None),
        "g_solved_elsewhere": (_with(replace_wrap=WRONG_WRAP, extra_at_end=_steal_from(elsewhere)), wrong_only, None),
        "g_honest": (_cells(), FULL, None),
    }


@pytest.fixture(scope="module")
def graded_g():
    with public_tmp() as base:  # readable by anyone, like a real submissions folder
        yield _grade_g(base)


def _grade_g(base):
    folder, elsewhere = base / "subs", base / "elsewhere" / "solved.ipynb"
    folder.mkdir()
    elsewhere.parent.mkdir()
    elsewhere.write_text(SOLUTION.read_text())
    cases = {**_reference_attacks(), **_view_attacks(folder, elsewhere)}
    paths = []
    for name, (nb, _, _) in cases.items():
        p = folder / name / "00_getting_started.ipynb"  # one folder per student, as in the README
        p.parent.mkdir()
        p.write_text(json.dumps(nb))
        paths.append(p)
    results = grade_batch(paths, "00_getting_started", "hostile-seed-g", jobs=2, limits=LIMITS, log=lambda *_: None)
    return {r.student: r for r in results}, cases


@pytest.mark.parametrize("name", sorted({**_reference_attacks(), **_view_attacks(Path("/x"), Path("/y"))}))
def test_worker_cannot_reach_the_reference_or_solved_work(graded_g, name):
    results, cases = graded_g
    _, expected, flag = cases[name]
    if not is_root() and (name.startswith(("g_git", "g_course", "g_other", "g_solved", "g_exec", "g_import_hooks"))):
        pytest.skip("without root the worker sees the disk (README: run the grader in a container)")
    result = results[name]
    got = {s.id: s.points for s in result.scores}
    assert got == expected, (result.flags, [m for s in result.scores for m in s.messages][:6], result.cell_errors[:4])
    if flag:
        assert flag in result.flags
    if name == "g_honest":
        assert result.flags == ([] if is_root() else ["sandbox=limited"]) and result.worker_log == ""
