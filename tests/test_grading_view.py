"""The worker's filesystem view as root (issue 12): an allowlist of the interpreter, the installed
packages' code, the kit and the job's own directories; nothing else of the disk.

Each test runs a small probe in the real sandbox (``run_sandboxed``) that writes what it can see
into the job's ``out/``.
"""
import json
import os
import shutil
import sys
from pathlib import Path

import pytest

from robocourse.lessons import get_assignment
from robocourse.grading.filesystem_view import View, bounded_space, installed_package_dirs, runtime_paths
from robocourse.grading.grader import worker_view
from robocourse.grading.kit import build_kit
from robocourse.grading.protocol import JobDir
from robocourse.grading.sandbox import Limits, is_root, run_sandboxed
from tests.conftest import ROOT, public_tmp

needs_root = pytest.mark.skipif(not is_root(), reason="the filesystem view needs root (namespaces)")

LIMITS = Limits(wall_seconds=60, cpu_seconds=60)

PROBE = """
import glob, json, os, sys
out = {"root": sorted(os.listdir("/")), "robokit": None, "robocourse": None, "exists": {}, "readable": {}, "listing": {}}
for p in json.loads(sys.argv[1]):
    out["exists"][p] = os.path.lexists(p)
    try:
        with open(p, "rb") as f:
            f.read(1)
        out["readable"][p] = True
    except OSError:
        out["readable"][p] = False
for d in json.loads(sys.argv[2]):
    try:
        out["listing"][d] = sorted(os.listdir(d))
    except OSError as e:
        out["listing"][d] = str(e)
out["uids"] = sorted({os.stat(p).st_uid for p in glob.glob("/proc/[0-9]*")})
out["me"] = os.getuid()
for name in ("robokit", "robocourse"):
    try:
        out[name] = __import__(name).__file__
    except ImportError as e:
        out[name] = str(e)
with open(os.path.join(os.environ["HOME"], "..", "out", "probe.json"), "w") as f:
    json.dump(out, f)
"""


@pytest.fixture
def base():
    with public_tmp() as path:
        yield path


def _probe(base: Path, view_of, paths, listings):
    kit = build_kit(get_assignment("00_getting_started"), base / "kit")
    other = JobDir.create(base)  # another job of the same run
    (other.inbox / "job").write_text("bob's cells")
    job = JobDir.create(base)
    exit_ = run_sandboxed(["-c", PROBE, json.dumps([str(p) for p in paths]),
                           json.dumps([str(d) for d in listings(job)])], job.root, LIMITS, view=view_of(kit),
                          env_extra={"PYTHONPATH": str(kit.root), "PYTHONSAFEPATH": "1"})
    assert exit_.returncode == 0 and exit_.isolated, exit_.log
    return json.loads((job.outbox / "probe.json").read_text()), kit, job, other


@needs_root
def test_the_worker_sees_only_the_allowlist(base):
    submission = base / "alice" / "00_getting_started.ipynb"
    submission.parent.mkdir()
    shutil.copy(ROOT / "solutions" / "00_getting_started.ipynb", submission)
    secret_paths = [ROOT / "solutions" / "00_getting_started.ipynb", ROOT / ".git", ROOT / "README.md",
                    ROOT / "robokit" / "geometry" / "planar.py", ROOT / "course" / "robocourse" / "grading" / "grader.py",
                    submission, Path.home() / ".bashrc", Path("/etc/shadow"), Path("/etc/passwd"),
                    Path("/usr/bin/git"), Path("/bin/sh"), Path(sys.executable).resolve().parent / "pip"]
    checks = [str(p) for p in secret_paths]
    visible_needed = [sys.executable, str(Path(sys.executable).resolve())]
    result, kit, job, other = _probe(
        base, lambda kit: worker_view(kit), [*checks, *visible_needed],
        lambda job: [job.root.parent, job.root, "/tmp", str(ROOT), "/root"])
    assert not any(result["exists"][p] for p in checks), {p: result["exists"][p] for p in checks}
    assert all(result["readable"][p] for p in visible_needed)
    listing = result["listing"]
    # the run's folder shows the kit and this job only (not the other job, not alice/); the job
    # shows no launch file or log
    assert listing[str(base)] == sorted(["kit", job.root.name]), listing[str(base)]
    assert listing[str(job.root)] == ["in", "out", "work"]
    # /tmp shows this run's folder, and nothing else but where the interpreter lives if it is there
    runtime_in_tmp = {Path(p).parts[2] for p in runtime_paths() if Path(p).parts[1:2] == ("tmp",) and len(Path(p).parts) > 2}
    assert set(listing["/tmp"]) == {base.name, *runtime_in_tmp}, listing["/tmp"]
    assert not isinstance(listing[str(ROOT)], list) or listing[str(ROOT)] == [".venv"], listing[str(ROOT)]
    assert result["uids"] == [result["me"]] and result["me"] != 0
    assert result["robokit"] == "No module named 'robokit'"
    assert result["robocourse"] == str(kit.package / "__init__.py")
    # "/" holds only the system folders and the top folders of the paths the view lets through
    # (where the interpreter and the packages live depends on the machine: /work, /opt, a CI clone)
    allowed_tops = {Path(p).parts[1] for p in (*runtime_paths(), str(kit.root)) if len(Path(p).parts) > 1}
    assert set(result["root"]) <= {"dev", "etc", "proc", "tmp", "root", *allowed_tops}, (result["root"], allowed_tops)
    assert "home" not in result["root"] or "home" in allowed_tops


@needs_root
def test_installed_packages_show_as_the_kit_and_as_nothing(base):
    # a wheel install (Gradescope, a container) puts both packages' whole source in site-packages,
    # which the view shows: the kit's robocourse must stand in robocourse's place, and robokit
    # must not be there at all
    site = base / "venv" / "lib" / "site-packages"
    shutil.copytree(ROOT / "robokit", site / "robokit", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "course" / "robocourse", site / "robocourse", ignore=shutil.ignore_patterns("__pycache__"))
    assert installed_package_dirs([str(site)], "robokit") == [str(site / "robokit")]
    assert installed_package_dirs([str(site)], "robocourse") == [str(site / "robocourse")]

    def view_of(kit):
        return View((*runtime_paths(), str(kit.root), str(site)), ((str(site / "robocourse"), str(kit.package)),),
                    (str(site / "robokit"),))

    planar = site / "robokit" / "geometry" / "planar.py"
    spec = site / "robocourse" / "lessons" / "getting_started" / "exercises.py"
    worker = site / "robocourse" / "grading" / "worker.py"
    result, kit, _, _ = _probe(base, view_of, [planar, spec, worker], lambda job: [site / "robocourse", site / "robokit"])
    assert not result["exists"][str(planar)] and not result["exists"][str(spec)]
    assert result["readable"][str(worker)]
    assert result["listing"][str(site / "robocourse")] == sorted(os.listdir(kit.package))
    assert result["listing"][str(site / "robokit")] == []


def test_runtime_paths_leave_out_project_directories(monkeypatch):
    # an old-style editable install or PYTHONPATH puts a project directory (with its .git and
    # solutions) on sys.path: only site-packages and the standard library count
    runtime_paths.cache_clear()
    monkeypatch.setattr(sys, "path", [*sys.path, str(ROOT), str(ROOT / "tests")])
    try:
        paths = runtime_paths()
    finally:
        runtime_paths.cache_clear()
    assert not any(p == str(ROOT) or p.startswith(str(ROOT) + "/") and "/.venv" not in p for p in paths), paths


def test_runtime_paths_show_a_prefix_s_lib_not_its_checkouts(tmp_path, monkeypatch):
    # `pip install -e git+...#egg=robokit` checks the course out into <venv>/src: the worker read
    # solutions/ and imported the real reference from there while the whole prefix was shown
    venv = tmp_path / "venv"
    site = venv / "lib" / "python3.11" / "site-packages"
    (venv / "src" / "robokit" / "solutions").mkdir(parents=True)
    site.mkdir(parents=True)
    (venv / "pyvenv.cfg").write_text("home = /usr/bin\n")
    runtime_paths.cache_clear()
    monkeypatch.setattr(sys, "prefix", str(venv))
    try:
        paths = runtime_paths()
    finally:
        runtime_paths.cache_clear()
    inside = sorted(p for p in paths if p == str(venv) or p.startswith(str(venv) + "/"))
    assert inside == [str(venv / "lib"), str(venv / "pyvenv.cfg")], inside


def test_a_robokit_in_the_base_interpreter_s_packages_is_found(tmp_path):
    # a venv's base interpreter shows its lib/ (shared libraries); a robokit installed in its
    # site-packages must be covered too, as must one in a system dist-packages or an egg
    lib = tmp_path / "base" / "lib"
    found = [lib / "python3.11" / "site-packages" / "robokit", tmp_path / "usr" / "python3" / "dist-packages" / "robokit",
             tmp_path / "usr" / "python3" / "dist-packages" / "robokit-1.0.egg" / "robokit"]
    for d in found:
        d.mkdir(parents=True)
        (d / "__init__.py").write_text("")
    assert installed_package_dirs([str(lib), str(tmp_path / "usr")], "robokit") == sorted(map(str, found))


SHARE = """
import ctypes, json, os, sys
libc = ctypes.CDLL(None, use_errno=True)
key, create = 0x526F626F, sys.argv[1] == "create"
sysv = libc.shmget(key, 4096, 0o1666 if create else 0o666)   # IPC_CREAT = 0o1000
try:
    fd = os.open("/dev/shm/robokit-collude", (os.O_CREAT | os.O_RDWR) if create else os.O_RDONLY, 0o666)
    posix = True
except OSError:
    posix = False
with open(os.path.join(os.environ["HOME"], "..", "out", "share.json"), "w") as f:
    json.dump({"sysv": sysv >= 0, "posix": posix}, f)
"""


@needs_root
def test_jobs_share_no_memory(base):
    # alice leaves her answers in shared memory, bob's job looks for them
    kit = build_kit(get_assignment("00_getting_started"), base / "kit")
    seen = {}
    for role in ("create", "open"):
        job = JobDir.create(base)
        exit_ = run_sandboxed(["-c", SHARE, role], job.root, LIMITS, view=worker_view(kit))
        assert exit_.returncode == 0, exit_.log
        seen[role] = json.loads((job.outbox / "share.json").read_text())
    assert seen["create"] == {"sysv": True, "posix": True}
    assert seen["open"] == {"sysv": False, "posix": False}


def test_a_planted_launch_file_costs_only_that_job(tmp_path):
    # a worker of the grader's own user (limited mode) may plant files in a job folder it can list
    job = JobDir.create(tmp_path)
    victim = tmp_path / "instructor-notes.txt"
    victim.write_text("keep me")
    (job.root / "launch.json").symlink_to(victim)
    exit_ = run_sandboxed(["-c", "pass"], job.root, LIMITS, view=View(()))
    assert exit_.returncode is None and "could not start the worker" in exit_.log
    assert victim.read_text() == "keep me"


FILL = """
import json, os
written = {}
for where in ("work", "out"):
    n = 0
    try:
        for i in range(100):
            with open(os.path.join(os.environ["HOME"], "..", where, f"fill{i}"), "wb") as f:
                f.write(bytes(1024 * 1024))
            n += 1
    except OSError:
        pass
    written[where] = n
files = 0
try:
    for i in range(10_000):
        open(os.path.join(os.environ["HOME"], f"empty{i}"), "w").close()
        files += 1
except OSError:
    pass
os.remove(os.path.join(os.environ["HOME"], "..", "out", "fill0"))
with open(os.path.join(os.environ["HOME"], "..", "out", "fill.json"), "w") as f:
    json.dump({"written": written, "files": files}, f)
"""


@needs_root
def test_a_worker_cannot_fill_the_disk(base):
    # RLIMIT_FSIZE bounds each file, not how many: work/ and out/ get a bounded tmpfs each
    job = JobDir.create(base)
    with bounded_space((job.work, job.outbox), 8 * 1024**2, max_files=500):
        exit_ = run_sandboxed(["-c", FILL], job.root, LIMITS, view=View(runtime_paths()))
        assert exit_.returncode == 0, exit_.log
        report = json.loads((job.outbox / "fill.json").read_text())  # the grader reads out/ inside the block
    assert 4 <= report["written"]["work"] <= 8 and 4 <= report["written"]["out"] <= 8, report  # of 100 tried
    assert report["files"] < 500, report
    assert not (job.outbox / "fill.json").exists()  # gone with the mount


HOG = """
import json, os, time
children = []
for _ in range(4):
    pid = os.fork()
    if pid == 0:
        os.setsid()                         # its own session: no help against a job's group
        block = b"\\1" * (150 * 1024 * 1024)  # resident, each well inside the per-process limit
        time.sleep(1.0)
        os._exit(0)
    children.append(pid)
ends = [os.waitpid(pid, 0)[1] for pid in children]
with open(os.path.join(os.environ["HOME"], "..", "out", "hog.json"), "w") as f:
    json.dump({"killed": sum(os.WIFSIGNALED(s) for s in ends), "ok": sum(os.WIFEXITED(s) and os.WEXITSTATUS(s) == 0 for s in ends)}, f)
"""


@needs_root
def test_a_job_as_a_whole_stays_within_its_memory(base):
    # RLIMIT_AS bounds each process: four children of 150 MB each fit a 400 MB per-process limit
    # but not a 400 MB job; the job's control group stops them together
    from robocourse.grading.job_cgroup import cgroup_note

    if cgroup_note() != "a control group per job":
        pytest.skip("this host does not let the grader make control groups")
    job = JobDir.create(base)
    exit_ = run_sandboxed(["-c", HOG], job.root, Limits(wall_seconds=60, cpu_seconds=60, memory_bytes=400 * 1024**2),
                          view=View(runtime_paths()))
    report = json.loads((job.outbox / "hog.json").read_text())
    assert exit_.returncode == 0 and report["killed"] >= 1 and report["ok"] <= 2, (report, exit_.log)
