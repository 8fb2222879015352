"""The grader against attacks on what it trusts (issue "Grader, round three").

Each attack is a real solution with one change; the honest solution is graded beside it in the same
batch and must keep full marks.
"""
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from robocourse.exercises.spec import PUBLIC_SEED
from robocourse.exercises.trivial import CONSTANTS, data_values, explained
from robocourse.grading import job_cgroup
from robocourse.grading.data import assignment_data, data_file
from robocourse.grading.grader import grade_batch, prepare_cases, score_exercise
from robocourse.grading.judge import expected_output
from robocourse.grading.protocol import CallResult, ErrorRecord
from robocourse.grading.sandbox import Limits, is_root
from robocourse.lessons import assignments, get_assignment
from tests.conftest import ROOT, public_tmp, wrap_angle_unless


# Returns, on its first valid input only, a rectangular list of zeros whose last item is a
# 700-character string, inside every bound of the protocol. Numpy would make it an array of
# strings of 700 x 4 bytes per value: 8.4 GB for 3 million zeros (9 MB of JSON; past the answer-size
# cap), 2.8 GB for 999,000 (under the cap: the item types stop it).
MEMORY_BOMB = """
_honest_wrap_angle, _sent = wrap_angle, []
def wrap_angle(angle):
    value = _honest_wrap_angle(angle)
    if not _sent:
        _sent.append(True)
        rows = [[0] * {columns} for _ in range(1000)]
        rows[-1][-1] = "x" * 700
        return rows
    return value
"""


def _notebook_with(extra_cell: str | None = None, slug: str = "00_getting_started") -> dict:
    nb = json.loads((ROOT / "solutions" / f"{slug}.ipynb").read_text())
    if extra_cell is not None:
        nb["cells"].append({"cell_type": "code", "metadata": {}, "source": extra_cell, "outputs": [],
                            "execution_count": None})
    return nb


def _grade_notebook(nb: dict, slug: str, seed: str):
    """Grade one notebook for ``slug`` in the sandbox; its result."""
    with public_tmp() as folder:
        path = folder / f"{seed}.ipynb"
        path.write_text(json.dumps(nb))
        [result] = grade_batch([path], slug, seed, limits=Limits(wall_seconds=240, cpu_seconds=240),
                               log=lambda *_: None)
    return result


def _grade_with(extra_cell: str, seed: str, slug: str = "00_getting_started"):
    """Grade the solution of ``slug`` with ``extra_cell`` appended; its result."""
    return _grade_notebook(_notebook_with(extra_cell, slug), slug, seed)


def _grade_capped(folder: Path, names: list[str], memory_bytes: int) -> tuple[subprocess.CompletedProcess, dict]:
    """Run ``robocourse grade`` on ``folder/<name>.ipynb`` with the grader and its workers all in
    one control group of ``memory_bytes``; return the process and the gradebook's rows by student."""
    group = job_cgroup.create(f"robokit-test-cap-{os.getpid()}", memory_bytes, 512)
    if group is None:
        pytest.skip("this host does not let the tests make a control group")
    out = folder / "grades.csv"
    try:
        proc = subprocess.Popen(
            [sys.executable, "-m", "robocourse.cli", "grade", "--assignment", "00_getting_started", "--seed",
             "cap-seed", "--out", str(out), "--jobs", "2", "--timeout", "60", "--root", str(ROOT),
             *[str(folder / f"{n}.ipynb") for n in names]],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=folder)
        group.join(proc.pid)       # before it has read a single notebook
        stdout, _ = proc.communicate(timeout=600)
    finally:
        group.remove(wait=5.0)
    done = subprocess.CompletedProcess(proc.args, proc.returncode, stdout, "")
    rows = {r["student"]: r for r in csv.DictReader(out.open())} if out.exists() else {}
    return done, rows


@pytest.mark.slow
@pytest.mark.skipif(not is_root(), reason="a memory cap on the whole batch needs a control group (root)")
def test_a_memory_bomb_answer_costs_only_its_own_case_under_a_1_gib_cap():
    with public_tmp() as folder:
        (folder / "honest.ipynb").write_text(json.dumps(_notebook_with()))
        (folder / "bomb.ipynb").write_text(json.dumps(_notebook_with(MEMORY_BOMB.format(columns=3000))))
        (folder / "bomb_under_cap.ipynb").write_text(json.dumps(_notebook_with(MEMORY_BOMB.format(columns=999))))
        done, rows = _grade_capped(folder, ["bomb", "bomb_under_cap", "honest"], 1 << 30)
    assert done.returncode == 0, done.stdout[-3000:]
    assert set(rows) == {"bomb", "bomb_under_cap", "honest"}, done.stdout[-3000:]
    assert float(rows["honest"]["total"]) == float(rows["honest"]["max"]) == 3.0, (rows["honest"], done.stdout)
    assert rows["honest"]["flags"] == ""           # as root (the test runs only then)
    # the bomb's own case is wrong; its other cases and exercise score as the honest ones
    for name in ("bomb", "bomb_under_cap"):
        assert 2.0 < float(rows[name]["total"]) < 3.0, rows[name]
        assert rows[name]["flags"] == "", rows[name]



def test_a_judging_breach_costs_only_that_submission(monkeypatch):
    # a comparison that would need unbounded memory or time (none of ours should): the judging of
    # that submission is stopped at its budget, and only that submission pays
    import robocourse.grading.grader as grader

    real = grader.judge

    def judge(exercise, case, expected, result):
        if type(result.value) is float and result.value == 4242.0:
            return bytearray(8 << 30)          # past the memory budget: a MemoryError in the child
        if type(result.value) is float and result.value == 4343.0:
            time.sleep(60)                     # past the time budget: the child is killed
        return real(exercise, case, expected, result)

    monkeypatch.setattr(grader, "judge", judge)
    with public_tmp() as folder:
        for name, extra in [("honest", None), ("memory", "def wrap_angle(angle):\n    return 4242.0\n"),
                            ("time", "def wrap_angle(angle):\n    return 4343.0\n")]:
            (folder / f"{name}.ipynb").write_text(json.dumps(_notebook_with(extra)))
        limits = Limits(wall_seconds=60, cpu_seconds=60, judge_memory_bytes=256 << 20, judge_seconds=5)
        results = {r.student: r for r in grade_batch(sorted(folder.glob("*.ipynb")), "00_getting_started", "s",
                                                     jobs=2, limits=limits, log=lambda *_: None)}
    assert results["honest"].total == 3.0 and set(results["honest"].flags) <= {"sandbox=limited"}
    for name, what in [("memory", "memory budget (256 MiB)"), ("time", "5 s budget")]:
        r = results[name]
        assert r.total == 0 and r.graded and "unusable-results" in r.flags, (name, r.flags, r.problems)
        assert any(what in p for p in r.problems), r.problems


# -- constants earn nothing --------------------------------------------------------------------------

RAISED = CallResult(error=ErrorRecord("ValueError", ("ValueError", "Exception", "BaseException"), "bad input"))


def _public(ex):
    return [c for c in ex.make_cases(PUBLIC_SEED)]


def _listed(value):
    return value.tolist()


def public_all(ex):
    """The answers of every public case (None for the bad-input ones)."""
    return [expected_output(ex, c) for c in _public(ex)]


def _data_values(slug):
    """Every value inside the assignment's data (what the kit hands a notebook), or nothing."""
    return data_values(assignment_data(slug)) if data_file(slug).is_file() else []


def _attackers(ex, slug):
    """Answers that solve nothing: every constant, every public answer (check() shows them), every
    value of the assignment's data, each argument unchanged, and the exercise's known shortcuts;
    each as ``(name, case -> value)``."""
    public = [expected_output(ex, c) for c in _public(ex) if not c.raises]
    out = [(f"constant {v!r:.40}", lambda case, v=v: v) for v in (*CONSTANTS, *public, *_data_values(slug))]
    out += [(f"argument {k + 1}", lambda case, k=k: case.args[k] if len(case.args) > k else None) for k in range(8)]
    seen = {json.dumps([list(c.args), c.kwargs], default=_listed): a for c, a in zip(_public(ex), public_all(ex))}
    for fallback in (None, 0.0, []):          # the public answers looked up by input, a constant otherwise
        out.append((f"lookup, else {fallback!r}", lambda case, d=fallback:
                    seen.get(json.dumps([list(case.args), case.kwargs], default=_listed), d)))
    out += [(name, lambda case, f=f: f(*case.args, **case.kwargs)) for name, f in ex.shortcuts.items()]
    return out


# Every exercise's hidden cases drawn (about 30 s with their tests): slow (`make check` runs them).
@pytest.fixture(scope="module")
def hidden_cases():
    """Every assignment's prepared cases for three hidden seeds and the public one."""
    return {(slug, seed): prepare_cases(slug, seed) for slug in assignments() for seed in ("h1", "h2", str(PUBLIC_SEED))}


@pytest.mark.slow
def test_constants_that_raise_on_bad_input_score_nothing(hidden_cases):
    # the strongest trivial submission: the answer is a constant (or an argument, or a shortcut)
    # and the function raises exactly on the bad inputs
    earned = []
    for (slug, seed), prepared in hidden_cases.items():
        for ex, cases, expected, trivial in zip(prepared.exercises, prepared.cases, prepared.expected, prepared.trivial):
            for name, answer in _attackers(ex, slug):
                results = []
                for case in cases:
                    try:
                        results.append(RAISED if case.raises else CallResult.returned(answer(case)))
                    except Exception as exc:
                        results.append(CallResult.raised(exc))
                score, _ = score_exercise(ex, cases, expected, trivial, results)
                if score.points:
                    earned.append((ex.id, seed, name, score.points))
    assert not earned


@pytest.mark.slow
def test_an_honest_function_unlocks_every_exercise(hidden_cases):
    # the other side of the rule: in every draw, a right function's passes show work
    locked = []
    for (slug, seed), p in hidden_cases.items():
        for ex, cases, trivial in zip(p.exercises, p.cases, p.trivial):
            valid = [i for i, c in enumerate(cases) if not c.raises]
            locked.append((ex.id, seed, explained(valid, valid, trivial)))
    assert [x for x in locked if x[2] is not None] == []


def test_a_draw_a_trivial_answer_could_pass_is_drawn_again():
    # an exercise whose valid cases all expect the same index for some seeds: those draws are
    # replaced, deterministically, and one that can never show work is a course error
    from robocourse.exercises.spec import Case, Exercise
    from robocourse.grading import grader

    same = Exercise(id="00.pick", function="pick", signature="pick(x) -> int", points=1,
                    cases=lambda rng: [Case((float(v),)) for v in rng.integers(0, 2, 3)] + [Case((float(rng.random()),))],
                    answer=lambda x: int(x))
    seeds = [f"s{k}" for k in range(40)]
    first = [grader.draw_cases(same, s)[0] for s in seeds]
    assert all(len({int(c.args[0]) for c in cases}) > 1 for cases in first)   # never one answer for all
    assert [c.args for c in first[0]] == [c.args for c in grader.draw_cases(same, seeds[0])[0]]
    always = Exercise(id="00.zero", function="zero", signature="zero(x) -> float", points=1,
                      cases=lambda rng: [Case((float(rng.random()),))], answer=lambda x: 0.0)
    with pytest.raises(grader.GradingError, match="00.zero"):
        grader.draw_cases(always, "s")


def _json_literal(value) -> str:
    return repr(json.dumps(value, default=lambda o: o.tolist()))


def _constants_notebook(slug: str) -> list[str]:
    """Every function of ``slug`` answers the constant (or public answer) that passes the most
    public cases, and raises ValueError on exactly the public bad inputs it has seen."""
    cells = ["import json\nimport numpy as np\n"
             "def _same(a, b):\n    return json.dumps(a, default=lambda o: o.tolist()) == json.dumps(b, default=lambda o: o.tolist())\n"]
    for ex in get_assignment(slug).exercises:
        cases = _public(ex)
        answers = [(c, expected_output(ex, c)) for c in cases if not c.raises]
        best = max((*CONSTANTS, *(a for _, a in answers)),
                   key=lambda v: sum(ex.compare(a, v) is None for _, a in answers))
        bad = [[list(c.args), c.kwargs] for c in cases if c.raises]
        cells.append(f"_bad_{ex.function} = json.loads({_json_literal(bad)})\n"
                     f"def {ex.function}(*args, **kwargs):\n"
                     f"    if any(_same([list(args), kwargs], b) for b in _bad_{ex.function}):\n"
                     f"        raise ValueError('bad input')\n"
                     f"    return json.loads({_json_literal(best)})\n")
    return cells


def _grade_cells(slug: str, cells: list[str], seed: str):
    """Grade a notebook of these code cells alone for ``slug``; its result."""
    nb = {"cells": [{"cell_type": "code", "metadata": {}, "source": c, "outputs": [], "execution_count": None}
                    for c in cells], "metadata": {}, "nbformat": 4, "nbformat_minor": 5}
    return _grade_notebook(nb, slug, seed)


#: The assignment whose per-assignment attacks ``make test`` runs; ``make check`` runs them for every
#: assignment (each takes 0.5-6 s in a sandboxed batch).
EVERYDAY = "03_corridor_localization"


def _every_assignment() -> list:
    assert EVERYDAY in assignments(), f"EVERYDAY names no assignment: {EVERYDAY}"
    return [pytest.param(slug, marks=() if slug == EVERYDAY else pytest.mark.slow) for slug in sorted(assignments())]


@pytest.mark.parametrize("slug", _every_assignment())
def test_a_notebook_of_constants_and_raises_scores_zero(slug):
    result = _grade_cells(slug, _constants_notebook(slug), "constants-seed")
    assert result.graded and "unusable-results" not in result.flags, (result.flags, result.worker_log)
    assert result.total == 0, [(s.id, s.points, s.messages[:1]) for s in result.scores if s.points]


# -- the kit hands out no oracle ----------------------------------------------------------------------

def _reference_notebook(slug: str) -> list[str]:
    """Every function answers by calling the exercise's reference (robokit or the lesson's module),
    or, failing that, by reading the course's modules the worker itself runs on."""
    cells = ["import importlib\n"]
    for ex in get_assignment(slug).exercises:
        module, name = ex.answer.__module__, ex.answer.__name__
        cells.append(f"def {ex.function}(*args, **kwargs):\n"
                     f"    for where in ({module!r}, 'robocourse.grading.protocol', 'robocourse.exercises.plain'):\n"
                     f"        try:\n"
                     f"            found = getattr(importlib.import_module(where), {name!r}, None)\n"
                     f"        except ImportError:\n"
                     f"            continue\n"
                     f"        if found is not None:\n"
                     f"            return found(*args, **kwargs)\n"
                     f"    raise ValueError('nothing to call')\n")
    return cells


@pytest.mark.parametrize("slug", _every_assignment())
def test_no_exercise_can_be_answered_with_what_the_worker_holds(slug):
    result = _grade_cells(slug, _reference_notebook(slug), "oracle-seed")
    assert result.graded, result.reason
    assert {s.id: s.points for s in result.scores} == {ex.id: 0.0 for ex in get_assignment(slug).exercises}
    assert "imported-robokit" in result.flags


KIT_PROBE = """
import importlib, sys
def _kit_visible():
    import robocourse
    if any(m in sys.modules for m in ("robocourse.grading.protocol", "robocourse.grading.worker",
                                      "robocourse.exercises.plain", "robocourse.grading.data", "robocourse.grading")):
        return True
    if hasattr(robocourse, "grading") or hasattr(robocourse, "exercises"):
        return True
    try:
        importlib.import_module("robocourse.grading.transport")
        return True
    except ImportError as exc:
        return "may import only check and assignment_data from robocourse" not in str(exc)
"""


def test_the_barrier_admits_only_what_its_message_names():
    # graded code finds no kit module in sys.modules or on the package, and importing one is
    # refused (and logged) with the message that names check and assignment_data as all it may import
    result = _grade_with(KIT_PROBE + wrap_angle_unless("_kit_visible()"), "probe-seed")
    assert {s.id: s.points for s in result.scores} == {"00.wrap_angle": 1.0, "00.se2_compose": 2.0}, \
        [s.messages[:2] for s in result.scores]
    assert "imported-robokit" in result.flags


# -- the worker offers no new namespaces and no privilege gain; nothing of the job outlives it --------

NAMESPACE_PROBE = """
import ctypes, os, posix
def _escape_possible():
    status = open("/proc/self/status").read()
    if "NoNewPrivs:\\t1" not in status or "Seccomp:\\t2" not in status:
        return True
    libc = ctypes.CDLL(None, use_errno=True)
    pid = os.fork()
    if pid == 0:      # in a child, so that a success changes nothing of the worker
        ok = libc.unshare(0x10000000 | 0x00020000) == 0                       # a user + mount namespace
        ok = ok or libc.unshare(0x20000000) == 0                              # a pid namespace
        ok = ok or libc.mount(b"none", b"/tmp", b"tmpfs", 0, None) == 0
        ok = ok or libc.syscall(56, 0x10000000 | 17, 0, 0, 0, 0) > 0          # clone(CLONE_NEWUSER)
        posix._exit(1 if ok else 0)       # the worker's os._exit is its own; this one ends the child
    return os.waitpid(pid, 0)[1] != 0
"""


def test_the_filter_refuses_namespaces_mounts_and_io_uring_and_allows_threads_and_forks():
    import ctypes
    import threading

    from robocourse.grading.syscall_filter import filter_supported, lock_down

    if not filter_supported():
        pytest.skip("the filter's table is x86-64's")
    read_fd, write_fd = os.pipe()
    pid = os.fork()
    if pid == 0:
        try:
            lock_down()
            libc = ctypes.CDLL(None, use_errno=True)
            got = [libc.unshare(0x10000000) == -1 and ctypes.get_errno() == 1,           # EPERM
                   libc.unshare(0x20000000 | 0x00020000) == -1,
                   libc.mount(b"none", b"/mnt", b"tmpfs", 0, None) == -1,
                   libc.syscall(56, 0x10000000 | 17, 0, 0, 0, 0) == -1,               # clone(CLONE_NEWUSER)
                   libc.syscall(435, 0, 0) == -1 and ctypes.get_errno() == 38,         # clone3: ENOSYS
                   libc.syscall(425, 1, 0) == -1 and ctypes.get_errno() == 1]          # io_uring_setup
            t = threading.Thread(target=lambda: None)
            t.start()
            t.join()
            child = os.fork()
            if child == 0:
                os._exit(3)
            got.append(os.waitpid(child, 0)[1] >> 8 == 3)
            os.write(write_fd, bytes(int(g) for g in got))
        finally:
            os._exit(0)
    os.close(write_fd)
    reply = os.read(read_fd, 100)
    os.close(read_fd)
    os.waitpid(pid, 0)
    assert list(reply) == [1] * 7, list(reply)


def test_the_worker_can_make_no_namespace_and_gain_no_privilege():
    result = _grade_with(NAMESPACE_PROBE + wrap_angle_unless("_escape_possible()"), "ns-seed")
    assert {s.id: s.points for s in result.scores} == {"00.wrap_angle": 1.0, "00.se2_compose": 2.0}, \
        [s.messages[:2] for s in result.scores]


HOPPER = """
import os, sys
_HOP = "import os\\nwhile True:\\n    try:\\n        if os.fork():\\n            os._exit(0)\\n    except OSError:\\n        pass\\n"
if os.fork() == 0:            # a small process that forks and exits as fast as it can, in its own session
    os.setsid()
    os.execv(sys.executable, [sys.executable, "-S", "-c", _HOP])
"""

# Runs a command as a child subreaper that reaps every orphan at once: the init of a host where a
# fork-and-exit hopper changes its pid faster than /proc can be read.
REAPING_INIT = """
import ctypes, os, subprocess, sys
ctypes.CDLL(None).prctl(36, 1, 0, 0, 0)         # PR_SET_CHILD_SUBREAPER
child = subprocess.Popen(sys.argv[1:])
while True:
    pid, status = os.waitpid(-1, 0)
    if pid == child.pid:
        sys.exit(os.waitstatus_to_exitcode(status))
"""


def _job_uid_processes() -> list[int]:
    from robocourse.grading.sandbox import JOB_UIDS

    found = []
    for entry in os.listdir("/proc"):
        try:
            if entry.isdigit() and os.stat(f"/proc/{entry}").st_uid in JOB_UIDS:
                found.append(int(entry))
        except OSError:
            continue
    return found


@pytest.mark.skipif(not is_root(), reason="job uids and control groups need root")
def test_a_fork_and_exit_hopper_does_not_outlive_its_job():
    before = set(_job_uid_processes())
    with public_tmp() as folder:
        (folder / "hopper.ipynb").write_text(json.dumps(_notebook_with(HOPPER)))
        (folder / "init.py").write_text(REAPING_INIT)
        done = subprocess.run([sys.executable, str(folder / "init.py"), sys.executable, "-m", "robocourse.cli", "grade",
                               "--assignment", "00_getting_started", "--seed", "hop", "--out", str(folder / "g.csv"),
                               "--timeout", "60", "--root", str(ROOT), str(folder / "hopper.ipynb")],
                              capture_output=True, text=True, timeout=300, cwd=folder)
        rows = list(csv.DictReader((folder / "g.csv").open())) if (folder / "g.csv").exists() else []
    time.sleep(1.0)
    left = set(_job_uid_processes()) - before
    for _ in range(200):                      # clean up after a failure, as well as one can
        for pid in _job_uid_processes():
            try:
                os.kill(pid, 9)
            except OSError:
                pass
    assert not left, f"processes of the job outlived it: {sorted(left)[:5]}"
    assert done.returncode == 0 and rows and rows[0]["total"] == "3", done.stdout[-2000:] + done.stderr[-2000:]


MODEL_ORACLE = """
def leg_fk(q_leg, leg):
    # the round-two oracle: the kit's LittleDog model in MuJoCo, no kinematics written
    import mujoco
    import numpy as np
    from robokit.legged.littledog import JOINT_NAMES, littledog_mjcf
    model = mujoco.MjModel.from_xml_string(littledog_mjcf())
    data = mujoco.MjData(model)
    for name, q in zip([j for j in JOINT_NAMES if j.startswith(leg)], q_leg):
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = q
    mujoco.mj_kinematics(model, data)
    body = model.body("trunk").id
    R = data.xmat[body].reshape(3, 3)
    return (R.T @ (data.site(f"{leg}_foot").xpos - data.xpos[body])).tolist()
"""


def test_the_littledog_model_is_no_oracle():
    # the 04 solution with leg_fk answered by MuJoCo on the library's model: the model is not in the
    # worker (no robokit), so the exercise scores 0 and the notebook is flagged; the rest keeps its marks
    result = _grade_with(MODEL_ORACLE, "model-seed", "04_littledog")
    points = {s.id: s.points for s in result.scores}
    assert points["04.leg_fk"] == 0 and "imported-robokit" in result.flags, (points, result.flags)
    assert all(s.points == s.max_points for s in result.scores if s.id != "04.leg_fk"), points
