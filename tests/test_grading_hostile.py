"""The grader against hostile submissions (issue "Autograding", Acceptance).

Each hostile notebook is the real 00 solution with one attack injected, so the exercises the
attack does not touch must still score full marks, and the ones it does must score zero (flagged
where it cheated). The whole batch is graded in one call and must finish in bounded time.
"""
import json
import os
import time
from pathlib import Path

import numpy as np
import pytest

from robocourse.grading.grader import grade_batch
from robocourse.grading.sandbox import Limits, is_root
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
    # raising on everything passes every bad-input case; they count only after a right result
    "always_raises": (_with(replace_wrap="def wrap_angle(*args, **kwargs):\n    raise ValueError('no')\n"),
                      {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, None),
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
                        {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}, "imported-robokit"),
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


# Every hostile submission graded in one batch (about 45 s): its tests are slow (`make check` runs them).
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
    cases["check_from_its_module"] = (_with(extra_at_end="from robokit.grading import check\n"
                                                         "check('00.wrap_angle', lambda angle: angle)\n"
                                                         "from robocourse import check\n"
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
@pytest.mark.slow
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
        assert result.flags == ([] if is_root() else ["sandbox=limited"]) and result.worker_log == ""


@pytest.mark.slow
def test_check_is_silenced_however_it_is_imported(graded):
    # check() on public cases would fail this lambda and raise in the cell; under grading it only
    # prints that it is skipped, whether imported from robocourse or under its old name, robokit.grading
    results, _, _, _, _ = graded
    assert results["check_from_its_module"].cell_errors == []


@pytest.mark.slow
def test_batch_time_is_bounded(graded):
    _, cases, elapsed, _, _ = graded
    # two jobs; at most a few submissions reach the 40 s wall limit
    assert elapsed < 180, f"batch of {len(cases)} took {elapsed:.0f}s"


@pytest.mark.slow
def test_output_paths_untouched(graded):
    _, _, _, out, feedback = graded
    if not is_root():
        pytest.skip("hiding output paths needs root")
    assert (feedback / "victim.md").read_text() == "original"
    assert not (out / "grades.csv").exists()


@pytest.mark.slow
def test_no_worker_processes_left(graded):
    if not is_root():
        pytest.skip("job uids exist only when grading as root")
    import fcntl

    from robocourse.grading.sandbox import JOB_UIDS, UID_LEASE_DIR

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
    from robocourse.grading.reports import feedback_text

    nb = _with(extra_at_end="import posix, sys\nsys.__stderr__.write('about to die\\n')\nsys.__stderr__.flush()\nposix._exit(3)\n")
    path = tmp_path / "crasher.ipynb"
    path.write_text(json.dumps(nb))
    result = grade_batch([path], "00_getting_started", "s", limits=LIMITS, log=lambda *_: None)[0]
    assert "worker-ended-early" in result.flags
    assert all(s.points == 0 for s in result.scores)
    assert "about to die" in result.worker_log
    assert "Last lines the worker process wrote" in feedback_text(result, "00_getting_started")


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
                                                 + through), wrong_only, "imported-robokit"),
        # a fresh copy of the module, built after the trap was installed
        "g_reload_module": (_with(replace_wrap="import importlib\nimport robokit.geometry.planar as _p\n"
                                               "_ref = importlib.reload(_p).wrap_angle\n" + through),
                            wrong_only, "imported-robokit"),
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
            "    return float(out[0]) if a.ndim == 0 else out.reshape(a.shape)\n")), wrong_only, "imported-robokit"),
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


# ---- issue 12, helper F: the grader trusts nothing the worker or the submission gives it ---------
# These batches run `robocourse grade` in a child process with a bounded address space, so that a
# grader that follows /dev/zero or waits on a FIFO fails the test (MemoryError, no gradebook, or
# the generous safety timeout) instead of taking the test machine down.

import csv  # noqa: E402
import re  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import textwrap  # noqa: E402

OUT = "os.path.join(os.path.dirname(os.getcwd()), 'out')"  # the job's out/, seen from the worker's cwd


def _tamper(code):
    """The 00 solution whose se2_compose first runs ``code`` once, in the exercise phase (after the
    cells record and exercise 0's report are written), with ``out`` bound to the job's out/."""
    compose = SELF_CONTAINED_COMPOSE.replace(
        "def se2_compose(a, b):\n",
        "def se2_compose(a, b):\n    global _tampered\n"
        f"    if not _tampered and os.path.exists(os.path.join({OUT}, 'ex0.json')):\n"
        "        _tampered = True\n        _tamper()\n")
    source = (f"import os\n_tampered = False\ndef _tamper():\n    out = {OUT}\n" + textwrap.indent(code, "    ")
              + "\n" + compose)
    nb = _cells()
    for cell in nb["cells"]:
        if cell["cell_type"] == "code" and "".join(cell["source"]).startswith("def se2_compose"):
            cell["source"] = source
    return nb


def _replace_by(name, how):
    return f"p = os.path.join(out, {name!r})\nos.unlink(p)\n{how}\n"


ONLY_COMPOSE = {"00.wrap_angle": 0.0, "00.se2_compose": 2.0}
NOTHING = {"00.wrap_angle": 0.0, "00.se2_compose": 0.0}
FORGED = ("```` ~~~\n\n**Score: 3 / 3**\n\n<script>alert('pwned')</script><img src=x onerror=alert(1)>"
          "\x1b[2J\x1b]0;owned\x07\x1b[31m\u202e\r\x00 =cmd|' /C calc'!A0")
FORGED_NAME = '=HYPERLINK("evil")<img src=x>**Score 3 of 3**'

WORKER_OUTPUT_ATTACKS = {
    # name: (notebook, expected points, expected flags)
    "out_flags_log_fifo": (_tamper(_replace_by("flags.log", "os.mkfifo(p)")), NOTHING, ["unusable-results"]),
    "out_flags_log_to_dev_zero": (_tamper(_replace_by("flags.log", "os.symlink('/dev/zero', p)")), NOTHING,
                                  ["unusable-results"]),
    "out_cells_to_dev_zero": (_tamper(_replace_by("cells.json", "os.symlink('/dev/zero', p)")), FULL,
                              ["unusable-results"]),
    "out_cells_fifo": (_tamper(_replace_by("cells.json", "os.mkfifo(p)")), FULL, ["unusable-results"]),
    "out_npz_garbage": (_tamper("p = os.path.join(out, 'ex0.npz')\nraw = bytearray(open(p, 'rb').read())\n"
                                "raw[len(raw) // 2] ^= 0xFF\nopen(p, 'wb').write(bytes(raw))\n"),
                        ONLY_COMPOSE, ["unusable-results"]),
    "out_npz_to_dev_zero": (_tamper(_replace_by("ex0.npz", "os.symlink('/dev/zero', p)")), ONLY_COMPOSE,
                            ["unusable-results"]),
    "out_report_directory": (_tamper(_replace_by("ex0.json", "os.mkdir(p)")), ONLY_COMPOSE, ["unusable-results"]),
    "out_wrong_types": (_tamper("import json\np = os.path.join(out, 'ex0.json')\nr = json.load(open(p))\n"
                                "r['seconds'] = 10 ** 4000\nopen(p, 'w').write(json.dumps(r))\n"
                                "open(os.path.join(out, 'cells.json'), 'w').write(json.dumps([{'cell': 10 ** 300, "
                                "'status': 'error', 'error': {'type': ['x'], 'classes': 5, 'message': {}}}]))\n"),
                        ONLY_COMPOSE, ["unusable-results"]),
    "returns_huge_int": (_with(replace_wrap="def wrap_angle(angle):\n    return 10 ** 400\n"), ONLY_COMPOSE, []),
    "forged_feedback": (_with(f"raise RuntimeError({FORGED!r})\n",
                              replace_wrap=f"def wrap_angle(angle):\n    raise RuntimeError({FORGED!r})\n"),
                        ONLY_COMPOSE, []),
}


def _grade_cli(paths, out):
    """Run `robocourse grade` on ``paths`` in a child process; return (exit code, stdout, stderr)."""
    def bounded():  # the grader's own address space; workers set theirs below it
        hard = resource.getrlimit(resource.RLIMIT_AS)[1]
        soft = 3 * 1024**3 if hard == resource.RLIM_INFINITY else min(3 * 1024**3, hard)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))

    cmd = [sys.executable, "-c", "import sys; from robocourse.cli import main; sys.exit(main())", "grade",
           *map(str, paths), "--assignment", "00_getting_started", "--seed", "hostile-seed", "--jobs", "2",
           "--out", str(out / "grades.csv"), "--feedback", str(out / "feedback"), "--timeout", "40",
           "--memory-mb", "2048", "--root", str(ROOT)]
    proc = subprocess.run(cmd, capture_output=True, text=True, errors="replace", timeout=900, preexec_fn=bounded,
                          cwd=out, env={**os.environ, "OPENBLAS_NUM_THREADS": "1",  # the robokit under test:
                                        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])})
    return proc.returncode, proc.stdout, proc.stderr


def _gradebook(out):
    with open(out / "grades.csv", newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def worker_output_batch(tmp_path_factory):
    subs, out = tmp_path_factory.mktemp("subs-worker-output"), tmp_path_factory.mktemp("out-worker-output")
    cases = {**WORKER_OUTPUT_ATTACKS, "honest": (_cells(), FULL, []), FORGED_NAME: (_cells(), FULL, [])}
    paths = []
    for name, (nb, _, _) in cases.items():
        paths.append(subs / f"{name}.ipynb")
        paths[-1].write_text(json.dumps(nb))
    code, stdout, stderr = _grade_cli(paths, out)
    return code, stdout, stderr, out, cases


def test_worker_output_batch_completes_with_exit_0(worker_output_batch):
    code, _, stderr, out, cases = worker_output_batch
    assert code == 0, stderr[-3000:]
    assert len(_gradebook(out)) == len(cases) and "Traceback" not in stderr


@pytest.mark.parametrize("name", list(WORKER_OUTPUT_ATTACKS) + ["honest"])
def test_hostile_worker_output_costs_only_what_it_touches(worker_output_batch, name):
    _, _, stderr, out, cases = worker_output_batch
    rows = {r["file"]: r for r in _gradebook(out)}
    row = rows[f"{name}.ipynb"]
    _, expected, flags = cases[name]
    assert {k: float(row[k]) for k in expected} == expected, (row, stderr[-2000:])
    assert [f for f in row["flags"].split() if f != "sandbox=limited"] == flags, row


def _outside_code_blocks(markdown):
    """The lines of ``markdown`` outside fenced code blocks, by CommonMark's rules for fences."""
    outside, fence = [], None
    for line in markdown.split("\n"):
        m = re.match(r"^ {0,3}(`{3,}|~{3,})(.*)$", line)
        if fence is None:
            if m and not (m.group(1)[0] == "`" and "`" in m.group(2)):
                fence = m.group(1)
            else:
                outside.append(line)
        elif m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence) and not m.group(2).strip():
            fence = None
    return outside


def test_feedback_shows_student_text_only_as_inert_text(worker_output_batch):
    _, stdout, _, out, _ = worker_output_batch
    feedback = list((out / "feedback").glob("*.md"))
    text = (out / "feedback" / "forged_feedback.md").read_text(encoding="utf-8")
    assert "RuntimeError" in text and "pwned" in text  # the student's message is shown ...
    outside = "\n".join(_outside_code_blocks(text))
    assert outside.count("**Score:") == 1 and "**Score: 2 / 3**" in outside  # ... but cannot forge a score
    assert "<script" not in outside and "<img" not in outside
    for page in feedback:  # no control characters or terminal escapes anywhere, in any feedback
        body = page.read_text(encoding="utf-8")
        assert not re.search(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]", body), page.name
        assert all(not re.search(r"(?<!\\)[<>*]", line) for line in _outside_code_blocks(body)
                   if line.startswith("# Feedback")), page.name
    assert "\x1b" not in stdout


def test_gradebook_cells_cannot_start_a_formula(worker_output_batch):
    _, _, _, out, _ = worker_output_batch
    with open(out / "grades.csv", newline="", encoding="utf-8") as f:
        cells = [c for row in csv.reader(f) for c in row]
    assert not [c for c in cells if c[:1] in ("=", "+", "-", "@", "\t", "\r")]
    assert any(c.startswith("'=HYPERLINK") for c in cells)


def _sparse(path, size):
    with open(path, "wb") as f:
        f.write(b'{"cells": [')
        f.truncate(size)


@pytest.fixture(scope="module")
def submission_batch(tmp_path_factory):
    subs, out = tmp_path_factory.mktemp("subs-submissions"), tmp_path_factory.mktemp("out-submissions")
    code_cell = {"cell_type": "code", "source": "x = 1", "metadata": {}, "outputs": [], "execution_count": None}
    bad = {
        "meta_not_dict": json.dumps({"cells": [{**code_cell, "metadata": [1]}]}),
        "source_not_strings": json.dumps({"cells": [{**code_cell, "source": ["x = 1\n", 5]}]}),
        "digits_5000": '{"cells": [], "metadata": {"n": ' + "7" * 5000 + "}}",
        "invalid_utf8": b'{"cells": [{"cell_type": "code", "source": "\xff", "metadata": {}}]}',
    }
    paths = []
    for name, content in bad.items():
        paths.append(subs / f"{name}.ipynb")
        paths[-1].write_bytes(content if isinstance(content, bytes) else content.encode())
    paths.append(subs / "huge_200mb.ipynb")
    _sparse(paths[-1], 200_000_000)
    paths.append(subs / "symlink_file.ipynb")
    paths[-1].symlink_to(SOLUTION)  # would be graded as the instructor's solution
    (subs / "symlink_folder").symlink_to(SOLUTION.parent)
    paths.append(subs / "symlink_folder" / "00_getting_started.ipynb")
    honest = json.dumps(_cells())
    for rel in ("honest.ipynb", "alice.ipynb", "alice/00_getting_started.ipynb", "sec2/alice.ipynb"):
        paths.append(subs / rel)
        paths[-1].parent.mkdir(exist_ok=True)
        paths[-1].write_text(honest)
    code, stdout, stderr = _grade_cli(paths, out)
    return code, stdout, stderr, out


EXPECTED_REJECTIONS = {"meta_not_dict": "not-a-notebook", "source_not_strings": "not-a-notebook",
                       "digits_5000": "not-a-notebook", "invalid_utf8": "not-a-notebook",
                       "huge_200mb": "not-a-notebook", "symlink_file": "symlink", "symlink_folder": "symlink"}


def test_submission_batch_completes_and_exits_1(submission_batch):
    code, _, stderr, out = submission_batch
    assert code == 1 and "Traceback" not in stderr, stderr[-3000:]
    rows = {r["student"]: r for r in _gradebook(out)}
    assert rows["honest"]["total"] == "3" and rows["honest"]["flags"] in ("", "sandbox=limited")
    for name in EXPECTED_REJECTIONS:
        assert name in stderr  # robocourse grade names every file it could not grade


@pytest.mark.parametrize("name", list(EXPECTED_REJECTIONS))
def test_a_bad_submission_is_rejected_with_its_flag(submission_batch, name):
    _, _, _, out = submission_batch
    row = {r["student"]: r for r in _gradebook(out)}[name]
    assert row["total"] == "0" and row["flags"] == EXPECTED_REJECTIONS[name] and row["note"], row


def test_duplicate_student_names_are_graded_apart_and_flagged(submission_batch):
    code, _, stderr, out = submission_batch
    rows = [r for r in _gradebook(out) if r["student"].startswith("alice")]
    assert sorted(r["student"] for r in rows) == ["alice#1", "alice#2", "alice#3"]
    assert all(r["total"] == "3" and "duplicate-name" in r["flags"].split() and "3 files" in r["note"] for r in rows)
    pages = sorted(p.name for p in (out / "feedback").glob("alice*.md"))
    assert pages == ["alice_1.md", "alice_2.md", "alice_3.md"]
    assert code == 1 and "3 files map to student 'alice'" in stderr


@pytest.fixture
def limited(monkeypatch):
    """Grade without the root-only isolation, whoever runs the test: the worker then runs as the
    grader's own user and can replace anything in its job directory, not only out/."""
    import robocourse.grading.sandbox as sandbox

    monkeypatch.setattr(sandbox, "is_root", lambda: False)


LIMITED_ATTACKS = {
    # replaces the worker log the grader reads after the worker ends
    "log_fifo": (_tamper("log = os.path.join(os.path.dirname(out), 'worker.log')\nos.unlink(log)\nos.mkfifo(log)\n"),
                 FULL, []),
    # replaces out/ itself by a link to a folder of forged reports
    "outbox_link": (_tamper("import shutil\nforged = out + '-forged'\nshutil.copytree(out, forged)\n"
                            "shutil.rmtree(out)\nos.symlink(forged, out)\n"), NOTHING, ["unusable-results"]),
}


def test_without_root_the_job_directory_is_hostile_too(tmp_path, limited):
    paths = []
    for name, (nb, _, _) in LIMITED_ATTACKS.items():
        paths.append(tmp_path / f"{name}.ipynb")
        paths[-1].write_text(json.dumps(nb))
    results = {r.student: r for r in grade_batch(paths, "00_getting_started", "s", jobs=2, limits=LIMITS,
                                                 log=lambda *_: None)}
    for name, (_, expected, flags) in LIMITED_ATTACKS.items():
        r = results[name]
        assert {s.id: s.points for s in r.scores} == expected, (name, r.flags, r.problems)
        assert r.flags[0] == "sandbox=limited" and r.flags[1:] == flags, (name, r.flags)


# -- issue 12 review: hidden inputs learnt from feedback -------------------------------------------

PROBE_WRAP = """import json
def wrap_angle(angle):
    raise RuntimeError('INPUT=' + json.dumps(np.asarray(angle, dtype=float).tolist()))
"""


def _lookup_wrap(table):
    return ("import json\n_TABLE = " + repr(table) + "\n"
            "def wrap_angle(angle):\n"
            "    key = json.dumps(np.asarray(angle, dtype=float).tolist())\n"
            "    if key not in _TABLE:\n"
            "        raise ValueError('not in the table')\n"
            "    return np.asarray(_TABLE[key]) if isinstance(_TABLE[key], list) else _TABLE[key]\n")


def test_inputs_learnt_from_feedback_do_not_score_the_next_submission(tmp_path):
    # a probe submission prints each hidden input in its error messages; the student computes the
    # answers with the public reference and submits a lookup table (3/3 when every submission
    # got the same cases)
    import re

    from robokit.geometry import wrap_angle
    from robocourse.grading.reports import feedback_text

    seed = "one-seed-per-term"
    probe = tmp_path / "probe" / "00_getting_started.ipynb"
    probe.parent.mkdir()
    probe.write_text(json.dumps(_with(replace_wrap=PROBE_WRAP)))
    (first,) = grade_batch([probe], "00_getting_started", seed, limits=LIMITS, log=lambda *_: None)
    learnt = re.findall(r"INPUT=(\[[^\]]*\]|[-0-9.eE+]+|NaN)", feedback_text(first, "00_getting_started"))
    table = {}
    for text in learnt:
        value = json.loads(text)
        answer = wrap_angle(value) if "NaN" not in text else None
        if answer is not None:
            table[json.dumps(value)] = np.asarray(answer).tolist() if np.ndim(answer) else float(answer)
    assert len(table) >= 3, learnt  # the feedback did show the inputs
    lookup = tmp_path / "lookup" / "00_getting_started.ipynb"
    lookup.parent.mkdir()
    lookup.write_text(json.dumps(_with(replace_wrap=_lookup_wrap(table))))
    (second,) = grade_batch([lookup], "00_getting_started", seed, limits=LIMITS, log=lambda *_: None)
    # the hand-picked edge cases are the same under every seed and a table can hold them; every
    # drawn case is new for the new submission, so the table misses all of those, and the edge
    # cases it gets right are what the public answers looked up by input give: it earns nothing
    from robocourse.lessons import get_assignment

    (exercise,) = [e for e in get_assignment("00_getting_started").exercises if e.id == "00.wrap_angle"]
    drawn = sum(a != b for a, b in zip(map(repr, exercise.make_cases("a")), map(repr, exercise.make_cases("b"))))
    score = {s.id: s for s in second.scores}["00.wrap_angle"]
    assert drawn >= 2 and score.passed == 0 and score.points == 0, (drawn, score)
    assert "trivial answers" in score.messages[0], score.messages
    verdicts = [m for m in score.messages if m.startswith("case ")]
    assert len(verdicts) == drawn and all("not in the table" in m for m in verdicts), score.messages
    # each failed case's verdict is followed by the call that failed, with its (fresh) input
    inputs = [m for m in score.messages if m.startswith("  input: wrap_angle(")]
    assert len(inputs) == len(verdicts), score.messages
    again = grade_batch([probe], "00_getting_started", seed, limits=LIMITS, log=lambda *_: None)[0]
    assert feedback_text(again, "00_getting_started") == feedback_text(first, "00_getting_started")  # regrades identically
