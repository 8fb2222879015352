"""OS-level isolation for the grading worker (Linux).

What is enforced, and where:

* Always (any user): a fresh process session killed as a group at the wall-clock limit;
  ``RLIMIT_CPU`` (CPU seconds), ``RLIMIT_AS`` (address space), ``RLIMIT_FSIZE`` (largest file),
  ``RLIMIT_NOFILE``, ``RLIMIT_CORE = 0``; a scrubbed environment (no inherited variables, ``HOME``
  and the working directory an empty job directory); single-threaded numeric libraries.
* As root (CI, Gradescope, a grading container): additionally a private mount namespace in which
  the protected paths (solutions, submissions, grader outputs, the instructor's home) are covered
  by empty read-only tmpfs mounts — only the Python installation and robokit are mounted back —,
  an empty network namespace (no interface but a down loopback), a private ``/proc`` mounted
  with ``hidepid=2`` (other users' processes, the grader's included, are invisible), a unique unprivileged uid/gid
  per job (so ``RLIMIT_NPROC`` caps a fork bomb and leftover processes can be swept by uid), and no
  supplementary groups.
* Not root: the namespace and uid steps are skipped; the report marks the run ``sandbox=limited``.
"""
from __future__ import annotations

import ctypes
import dataclasses
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Sequence

from .protocol import JobDir

__all__ = ["Limits", "WorkerExit", "run_sandboxed", "is_root", "JOB_UID_BASE"]

#: Jobs run as uid/gid JOB_UID_BASE + slot (no passwd entry is needed).
JOB_UID_BASE = 61000

_CLONE_NEWNS = 0x00020000
_CLONE_NEWNET = 0x40000000
_MS_RDONLY, _MS_NOSUID, _MS_NODEV, _MS_BIND, _MS_REC, _MS_PRIVATE = 1, 2, 4, 4096, 16384, 1 << 18


@dataclasses.dataclass(frozen=True)
class Limits:
    """Resource limits of one worker.

    Attributes
    ----------
    wall_seconds : float
        Whole worker, killed with its process group when exceeded.
    cpu_seconds : int
        ``RLIMIT_CPU``.
    memory_bytes : int
        ``RLIMIT_AS`` (virtual address space).
    max_processes : int
        ``RLIMIT_NPROC`` for the job uid (root only; a per-user count otherwise meaningless).
    file_bytes : int
        ``RLIMIT_FSIZE``: the largest file the worker may write (stdout/stderr included).
    cell_seconds, call_seconds : float
        Per notebook cell and per exercise call, enforced inside the worker by an interval timer.
    """

    wall_seconds: float = 300.0
    cpu_seconds: int = 300
    memory_bytes: int = 4 * 1024**3
    max_processes: int = 64
    file_bytes: int = 64 * 1024**2
    cell_seconds: float = 60.0
    call_seconds: float = 20.0


@dataclasses.dataclass
class WorkerExit:
    """How the worker ended: ``returncode``, ``timed_out``, ``seconds``, ``isolated``, ``log`` tail."""

    returncode: int | None
    timed_out: bool
    seconds: float
    isolated: bool
    log: str


def is_root() -> bool:
    """Return whether the grader runs as root (full isolation available)."""
    return os.geteuid() == 0


def _libc():
    libc = ctypes.CDLL(None, use_errno=True)
    libc.mount.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_ulong, ctypes.c_char_p]
    return libc


def _check(ret: int, what: str) -> None:
    if ret != 0:
        err = ctypes.get_errno()
        raise OSError(err, f"{what}: {os.strerror(err)}")


def _blocked_ancestor(path: Path) -> tuple[Path, Path] | None:
    """Return (ancestor, child) where ``ancestor`` denies traversal to others on the way to path."""
    parts = path.parts
    for i in range(1, len(parts)):
        anc = Path(*parts[:i])
        try:
            if not os.stat(anc).st_mode & 0o001:
                return anc, Path(*parts[: i + 1])
        except OSError:
            return None
    return None


def _isolate(job_dir: Path, hide: Sequence[Path], expose: Sequence[Path]) -> None:
    """Runs in the child before exec (root only): namespaces, hidden paths, exposed interpreter."""
    libc = _libc()
    _check(libc.unshare(_CLONE_NEWNS | _CLONE_NEWNET), "unshare")
    _check(libc.mount(b"none", b"/", None, _MS_REC | _MS_PRIVATE, None), "make mounts private")
    # 1. where an ancestor (e.g. /root, mode 0700) blocks the interpreter or robokit, cover the
    #    ancestor with an empty tmpfs and mount back only the children that are needed
    needed: dict[Path, set[Path]] = {}
    for path in expose:
        blocked = _blocked_ancestor(path)
        if blocked is not None:
            needed.setdefault(blocked[0], set()).add(blocked[1])
    stash = job_dir / ".stash"
    for a, (ancestor, children) in enumerate(sorted(needed.items())):
        kept = []
        for c, child in enumerate(sorted(children)):
            keep = stash / f"{a}-{c}"
            keep.mkdir(parents=True, exist_ok=True)
            _check(libc.mount(str(child).encode(), str(keep).encode(), None, _MS_BIND | _MS_REC, None),
                   f"stash {child}")
            kept.append((keep, child))
        _check(libc.mount(b"tmpfs", str(ancestor).encode(), b"tmpfs", _MS_NOSUID | _MS_NODEV,
                          b"mode=0755,size=64k"), f"cover {ancestor}")
        for keep, child in kept:
            target = ancestor / child.name
            target.mkdir(exist_ok=True)
            _check(libc.mount(str(keep).encode(), str(target).encode(), None, _MS_BIND | _MS_REC, None),
                   f"expose {child}")
    # 2. cover protected paths, keeping the interpreter, robokit and the job directory visible
    keep = [Path(p) for p in expose] + [job_dir]
    for path in hide:
        _hide(libc, Path(path), keep, depth=0)
    # 3. a private /proc that shows only the job's own processes (the grader's command line, which
    #    may hold --seed, stays invisible)
    _check(libc.mount(b"proc", b"/proc", b"proc", _MS_NOSUID | _MS_NODEV, b"hidepid=2"), "mount /proc")


def _hide(libc, path: Path, keep: Sequence[Path], depth: int) -> None:
    """Cover ``path`` with an empty read-only tmpfs (a directory) or /dev/null (a file).

    A directory that contains a kept path is not covered itself: its other entries are, one level
    further down.
    """
    if any(path == k for k in keep):
        return
    if path.is_symlink() or not path.exists():
        return
    if path.is_file():
        _check(libc.mount(b"/dev/null", str(path).encode(), None, _MS_BIND, None), f"hide {path}")
        return
    if not path.is_dir():
        return
    if any(path in k.parents for k in keep):
        if depth < 8:
            for entry in sorted(path.iterdir()):
                _hide(libc, entry, keep, depth + 1)
        return
    _check(libc.mount(b"tmpfs", str(path).encode(), b"tmpfs", _MS_NOSUID | _MS_NODEV | _MS_RDONLY,
                      b"mode=0555,size=4k"), f"hide {path}")


def _limits(limits: Limits, uid: int | None) -> None:
    resource.setrlimit(resource.RLIMIT_CPU, (limits.cpu_seconds, limits.cpu_seconds + 5))
    resource.setrlimit(resource.RLIMIT_AS, (limits.memory_bytes, limits.memory_bytes))
    resource.setrlimit(resource.RLIMIT_FSIZE, (limits.file_bytes, limits.file_bytes))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_NOFILE, (256, 256))
    if uid is not None:
        resource.setrlimit(resource.RLIMIT_NPROC, (limits.max_processes, limits.max_processes))


def _launch(config_path: str) -> None:
    """Entry point of the launcher process: isolate, drop privileges, limit, then exec the worker.

    It runs as a fresh single-threaded process (never as a ``preexec_fn`` of a threaded grader).
    """
    import json

    cfg = json.loads(Path(config_path).read_text())
    job_dir = Path(cfg["job_dir"])
    limits = Limits(**cfg["limits"])
    uid = cfg["uid"]
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # an oversized write fails instead of killing
    if uid is not None:
        _isolate(job_dir, [Path(p) for p in cfg["hide"]], [Path(p) for p in cfg["expose"]])
        os.setgroups([])
        os.setgid(uid)
        os.setuid(uid)
    os.chdir(JobDir(job_dir).work)
    _limits(limits, uid)
    os.execve(sys.executable, [sys.executable, *cfg["args"]], cfg["env"])


def _sweep_uid(uid: int) -> None:
    """Kill every process still running as the job uid (fork-bomb children that escaped the group)."""
    for _ in range(3):
        found = False
        for entry in Path("/proc").iterdir():
            if not entry.name.isdigit():
                continue
            try:
                if entry.stat().st_uid == uid:
                    os.kill(int(entry.name), signal.SIGKILL)
                    found = True
            except (OSError, ValueError):
                pass
        if not found:
            return
        time.sleep(0.05)


def run_sandboxed(args: Sequence[str], job_dir: Path, limits: Limits, *, slot: int = 0,
                  hide: Sequence[Path] = (), env_extra: dict[str, str] | None = None) -> WorkerExit:
    """Run ``python args...`` in ``job_dir/work`` under the limits; see the module docstring.

    ``job_dir`` is a :class:`~robokit.grading.protocol.JobDir` root: the job uid (when running as
    root) gets ``work/`` (its cwd and HOME) and ``out/`` (where it writes), and may only read ``in/``.
    """
    root = is_root()
    uid = JOB_UID_BASE + slot if root else None
    job = JobDir(job_dir)
    if uid is not None:
        for sub in (job.work, job.outbox):
            os.chown(sub, uid, uid)
            os.chmod(sub, 0o700)  # concurrent jobs (other uids) cannot look in
        os.chmod(job_dir, 0o711)
        os.chmod(job.inbox, 0o755)
        for f in job.inbox.iterdir():
            os.chmod(f, 0o644)
    expose = sorted({Path(sys.base_prefix).resolve(), Path(sys.prefix).resolve(),
                     Path(sys.executable).resolve().parent, Path(__file__).resolve().parents[2]})
    env = {
        "PATH": f"{Path(sys.executable).parent}:/usr/bin:/bin",
        "HOME": str(job.work),
        "TMPDIR": str(job.work),
        "LANG": "C.UTF-8",
        "PYTHONHASHSEED": "0",
        "PYTHONDONTWRITEBYTECODE": "1",
        "MPLBACKEND": "Agg",
        "MPLCONFIGDIR": str(job.work),
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
        "ROBOKIT_FAST": "1",
        "ROBOKIT_CACHE": str(job.work / ".cache"),
    }
    env.update(env_extra or {})
    import json

    config = job_dir / "launch.json"  # root-only: the job uid never reads it
    config.write_text(json.dumps({
        "job_dir": str(job_dir), "limits": dataclasses.asdict(limits), "uid": uid,
        "hide": [str(Path(p).resolve()) for p in hide], "expose": [str(p) for p in expose],
        "args": list(args), "env": env,
    }))
    os.chmod(config, 0o600)
    start = time.perf_counter()
    timed_out = False
    with open(job.log_file, "wb") as log:
        proc = subprocess.Popen(
            [sys.executable, "-m", "robokit.grading.sandbox", str(config)], cwd=job_dir,
            env={"PATH": env["PATH"], "LANG": "C.UTF-8"}, stdin=subprocess.DEVNULL, stdout=log,
            stderr=subprocess.STDOUT, close_fds=True, start_new_session=True,
        )
        try:
            proc.wait(timeout=limits.wall_seconds)
        except subprocess.TimeoutExpired:
            timed_out = True
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    if uid is not None:
        _sweep_uid(uid)
    seconds = time.perf_counter() - start
    return WorkerExit(proc.returncode, timed_out, seconds, uid is not None, job.read_log_tail())


if __name__ == "__main__":
    _launch(sys.argv[1])
