"""OS-level isolation for the grading worker (Linux).

What is enforced, and where:

* Always (any user): a fresh process session killed as a group at the wall-clock limit;
  ``RLIMIT_CPU`` (CPU seconds), ``RLIMIT_AS`` (address space), ``RLIMIT_FSIZE`` (largest file),
  ``RLIMIT_NOFILE``, ``RLIMIT_CORE = 0``; a scrubbed environment (no inherited variables, ``HOME``
  and the working directory an empty job directory); single-threaded numeric libraries; a
  grader whose secret cannot be read through ``/proc`` by a process of the same user
  (:func:`conceal_secret`); and no privilege gain, no new namespaces and no mounts
  (:mod:`.syscall_filter`: ``no_new_privs`` and a seccomp filter, set last by the launcher).
* As root (CI, Gradescope, a grading container): additionally a private mount namespace whose
  root holds only what :mod:`.filesystem_view` allows (the interpreter, the installed packages'
  code, the worker's kit, the job's own directories), an empty network namespace (no
  interface but a down loopback), a private ``/proc`` mounted with ``hidepid=2`` (other users'
  processes, the grader's included, are invisible), a unique unprivileged uid/gid per job, leased
  across every grading run on the host (:func:`lease_job_uid`; so ``RLIMIT_NPROC`` caps a fork
  bomb), no supplementary groups, and a control group per job (:mod:`.job_cgroup`) through which
  whatever the job leaves running is ended at once; processes of the job uid are also swept
  through ``/proc``, for hosts that give no control group.
* Not root: the namespace and uid steps are skipped; the report marks the run ``sandbox=limited``.
  A fork bomb is still bounded: ``RLIMIT_NPROC`` allows the user ``max_processes`` more threads
  and processes than they ran when the job started.
"""
from __future__ import annotations

import contextlib
import ctypes
import dataclasses
import errno
import fcntl
import json
import os
import pwd
import random
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Iterator, Sequence

from robocourse.grading import job_cgroup
from robocourse.grading.filesystem_view import View, bounded_space, enter_view
from robocourse.grading.protocol import JobDir
from robocourse.grading.syscall_filter import lock_down

__all__ = ["Limits", "WorkerExit", "run_sandboxed", "is_root", "lease_job_uid", "conceal_secret",
           "job_space", "JOB_UIDS", "UID_LEASE_DIR"]

#: Job uids/gids (no passwd entry is needed; uids that have one are skipped).
JOB_UIDS = range(61000, 65000)
#: Root-only directory of the lock files that lease job uids to grading runs on this host.
UID_LEASE_DIR = Path("/run/robokit-grading/uids")
_PR_SET_DUMPABLE = 4


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
        ``RLIMIT_NPROC`` for the job uid; not as root, the user's threads at the start plus this
        many (``RLIMIT_NPROC`` counts every thread of the user's real uid).
    file_bytes : int
        ``RLIMIT_FSIZE``: the largest file the worker may write (stdout/stderr included).
    disk_bytes : int
        All the worker may write in its ``work/`` and in its ``out/`` (each; root only, see
        :func:`~.filesystem_view.bounded_space`).
    cell_seconds, call_seconds : float
        Per notebook cell and per exercise call, enforced inside the worker by an interval timer.
    judge_memory_bytes, judge_seconds : int, float
        The budget of the grader's own reading and judging of the worker's results, in a child
        process (:func:`~.budget.run_within`): memory beyond what the grader holds, and time.
    """

    wall_seconds: float = 300.0
    cpu_seconds: int = 300
    memory_bytes: int = 4 * 1024**3
    max_processes: int = 64
    file_bytes: int = 64 * 1024**2
    disk_bytes: int = 256 * 1024**2
    cell_seconds: float = 60.0
    call_seconds: float = 20.0
    judge_memory_bytes: int = 512 * 1024**2
    judge_seconds: float = 60.0


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


def _tasks_of(uid: int) -> int:
    """How many threads the real uid ``uid`` runs now: what ``RLIMIT_NPROC`` counts (from ``/proc``)."""
    count = 0
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            try:
                with open(f"{entry.path}/status") as fh:
                    real = next(int(line.split()[1]) for line in fh if line.startswith("Uid:"))
                if real == uid:
                    count += len(os.listdir(f"{entry.path}/task"))
            except (OSError, StopIteration, ValueError, IndexError):   # ended meanwhile, or unreadable
                pass
    return count


def _limits(limits: Limits, uid: int | None) -> None:
    resource.setrlimit(resource.RLIMIT_CPU, (limits.cpu_seconds, limits.cpu_seconds + 5))
    resource.setrlimit(resource.RLIMIT_AS, (limits.memory_bytes, limits.memory_bytes))
    resource.setrlimit(resource.RLIMIT_FSIZE, (limits.file_bytes, limits.file_bytes))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_NOFILE, (256, 256))
    if uid is not None:
        resource.setrlimit(resource.RLIMIT_NPROC, (limits.max_processes, limits.max_processes))
    else:   # as the user, RLIMIT_NPROC counts all their threads: allow this job max_processes more
        hard = resource.getrlimit(resource.RLIMIT_NPROC)[1]
        cap = _tasks_of(os.getuid()) + limits.max_processes
        cap = cap if hard == resource.RLIM_INFINITY else min(cap, hard)
        resource.setrlimit(resource.RLIMIT_NPROC, (cap, cap))


def _launch(config_path: str) -> None:
    """Entry point of the launcher process: isolate, drop privileges, limit, then exec the worker.

    It runs as a fresh single-threaded process (never as a ``preexec_fn`` of a threaded grader).
    """
    cfg = json.loads(Path(config_path).read_text())
    job = JobDir(cfg["job_dir"])
    limits = Limits(**cfg["limits"])
    uid = cfg["uid"]
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # an oversized write fails instead of killing
    if uid is not None:
        if cfg.get("cgroup"):
            try:
                job_cgroup.JobCgroup(tuple(cfg["cgroup"])).join()  # before /sys is out of view
            except OSError as exc:  # the host refused: the per-process limits still hold
                print(f"robokit sandbox: the job runs without its control group ({exc})", file=sys.stderr)
        view = View(tuple(cfg["view"]["read_only"]), tuple(map(tuple, cfg["view"]["replace"])),
                    tuple(cfg["view"]["hide"]))
        enter_view(view, job.root / "root", [(str(job.inbox), False), (str(job.work), True), (str(job.outbox), True)])
        os.setgroups([])
        os.setgid(uid)
        os.setuid(uid)
    os.chdir(job.work)
    _limits(limits, uid)
    lock_down()      # last: no privilege gain, no namespaces, no mounts for the worker and its children
    os.execve(cfg["python"], [cfg["python"], *cfg["args"]], cfg["env"])


# -- job uids: leased per job, unique across every grading run on the host -------------------------

def _lease_dir() -> Path:
    """``UID_LEASE_DIR``, created root-only; refused if anyone else could have planted it."""
    for d in (UID_LEASE_DIR.parent, UID_LEASE_DIR):
        try:
            d.mkdir(mode=0o700)
        except FileExistsError:
            pass
        st = os.lstat(d)
        if not os.path.isdir(d) or os.path.islink(d) or st.st_uid != 0 or st.st_mode & 0o022:
            raise RuntimeError(f"{d}: expected a directory owned by root and writable only by it")
    return UID_LEASE_DIR


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


@contextlib.contextmanager
def lease_job_uid() -> Iterator[int]:
    """Lease a job uid for one worker (root only): no other grading run on this host gets it until
    the lease ends.

    A lease is an exclusive ``flock`` on ``UID_LEASE_DIR/<uid>.lock``, held by this process and
    released by the kernel if the grader dies, so a crashed run never blocks a uid. Candidates are
    tried from a random point of ``JOB_UIDS``; uids with a passwd entry are skipped. Processes left
    running as the uid (by a run that crashed) are killed when the lease starts, and the worker's
    leftovers when it ends.

    Raises
    ------
    RuntimeError
        If every uid of ``JOB_UIDS`` is leased.
    """
    folder = _lease_dir()
    start = random.randrange(len(JOB_UIDS))
    for k in range(len(JOB_UIDS)):
        uid = JOB_UIDS[(start + k) % len(JOB_UIDS)]
        try:
            pwd.getpwuid(uid)
            continue
        except KeyError:
            pass
        fd = os.open(folder / f"{uid}.lock", os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
                continue
            raise
        try:
            _sweep_uid(uid)
            yield uid
        finally:
            _sweep_uid(uid)
            os.close(fd)
        return
    raise RuntimeError(f"no free job uid: all {len(JOB_UIDS)} of {JOB_UIDS} are leased")


# -- the secret ------------------------------------------------------------------------------------

def _overwrite(region_start: int, region_end: int, keep) -> None:
    """Overwrite, in this process's memory, the NUL-separated strings of [start, end) for which
    ``keep(text)`` returns the number of leading bytes to keep (``None``: leave it alone)."""
    if not 0 < region_start < region_end:
        return
    data = ctypes.string_at(region_start, region_end - region_start)
    offset = 0
    for item in data.split(b"\0"):
        kept = keep(item)
        if kept is not None and kept < len(item):
            ctypes.memset(region_start + offset + kept, ord("*"), len(item) - kept)
        offset += len(item) + 1


def conceal_secret(secret: str) -> None:
    """Keep ``secret`` (the grading seed) from every other process of this user, workers included.

    The grader becomes non-dumpable (``PR_SET_DUMPABLE = 0``), so ``/proc/<grader>/environ`` and
    ``mem`` are closed to processes of the same uid (what a worker is in the limited mode), and
    the seed's copies in the memory the kernel shows as ``/proc/<grader>/cmdline`` and ``environ``
    are overwritten (``--seed SECRET``, ``--seed=SECRET``, abbreviated as argparse allows, and
    ``ROBOKIT_GRADING_SEED=SECRET``).
    Python's own copies (``sys.argv``, ``os.environ``) are unchanged. Best effort on Linux; a
    no-op elsewhere.
    """
    libc = ctypes.CDLL(None, use_errno=True)
    if hasattr(libc, "prctl"):
        libc.prctl(_PR_SET_DUMPABLE, 0, 0, 0, 0)
    try:
        with open("/proc/self/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
        arg_start, arg_end, env_start, env_end = (int(v) for v in fields[45:49])
    except (OSError, ValueError, IndexError):
        return
    value = secret.encode()
    previous = [b""]

    def is_seed_option(item: bytes) -> bool:  # --seed, or a prefix argparse accepts
        return len(item) >= 3 and b"--seed".startswith(item)

    def in_argv(item: bytes):
        before, previous[0] = previous[0], item
        option, eq, rest = item.partition(b"=")
        if eq and rest == value and is_seed_option(option):
            return len(option) + 1
        return 0 if item == value and is_seed_option(before) else None

    _overwrite(arg_start, arg_end, in_argv)
    _overwrite(env_start, env_end, lambda item: len(b"ROBOKIT_GRADING_SEED=")
               if item == b"ROBOKIT_GRADING_SEED=" + value else None)


# -- running one worker ----------------------------------------------------------------------------

def _worker_env(job: JobDir, env_extra: dict[str, str] | None) -> dict[str, str]:
    """The worker's whole environment: built from nothing, so no variable of the grader (the seed
    above all) can reach it."""
    env = {
        "PATH": f"{Path(sys.executable).parent}:/usr/bin:/bin",
        "HOME": str(job.work),
        "TMPDIR": str(job.work),
        "LANG": "C.UTF-8",
        "PYTHONHASHSEED": "0",
        "PYTHONDONTWRITEBYTECODE": "1",
        "PYTHONNOUSERSITE": "1",
        "MPLBACKEND": "Agg",
        "MPLCONFIGDIR": str(job.work),
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
        "ROBOKIT_FAST": "1",
        "ROBOKIT_CACHE": str(job.work / ".cache"),
    }
    env.update(env_extra or {})
    return env


def _prepare_job_dir(job: JobDir, uid: int | None) -> None:
    """Give the job uid ``work/`` and ``out/`` (its own) and read access to ``in/``."""
    if uid is None:
        return
    for sub in (job.work, job.outbox):
        os.chown(sub, uid, uid)
        os.chmod(sub, 0o700)  # concurrent jobs (other uids) cannot look in
    os.chmod(job.root, 0o711)
    os.chmod(job.inbox, 0o755)
    for f in job.inbox.iterdir():
        os.chmod(f, 0o644)


def _create(path: Path):
    """Open a new file of the grader's for writing (mode 0600), never through a link or over an
    existing file: in the limited mode a worker of the same user could plant one in a job folder."""
    return os.fdopen(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600), "wb")


def _run(config: Path, job: JobDir, limits: Limits, path_env: str) -> tuple[int | None, bool]:
    """Start the launcher, wait for it up to the wall-clock limit, kill its process group."""
    timed_out = False
    with _create(job.log_file) as log:
        proc = subprocess.Popen(
            [sys.executable, "-m", "robocourse.grading.sandbox", str(config)], cwd=job.root,
            env={"PATH": path_env, "LANG": "C.UTF-8"}, stdin=subprocess.DEVNULL, stdout=log,
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
    return proc.returncode, timed_out


@contextlib.contextmanager
def job_space(job: JobDir, limits: Limits) -> Iterator[None]:
    """While the block runs (the worker, then the grader reading ``out/``), the job's ``work/`` and
    ``out/`` hold at most ``limits.disk_bytes`` each (root only; :func:`~.filesystem_view.bounded_space`)."""
    if not is_root():
        yield
        return
    with bounded_space((job.work, job.outbox), limits.disk_bytes):
        yield


def run_sandboxed(args: Sequence[str], job_dir: Path, limits: Limits, *, view: View,
                  env_extra: dict[str, str] | None = None) -> WorkerExit:
    """Run ``python args...`` in ``job_dir/work`` under the limits; see the module docstring.

    ``job_dir`` is a :class:`~robocourse.grading.protocol.JobDir` root: the job uid (when running as
    root) gets ``work/`` (its cwd and HOME) and ``out/`` (where it writes), and may only read
    ``in/``. ``view`` is what else its filesystem shows (root only); ``env_extra`` adds to its
    otherwise empty environment.
    """
    job = JobDir(job_dir)
    group = None
    try:
        with (lease_job_uid() if is_root() else contextlib.nullcontext(None)) as uid:
            _prepare_job_dir(job, uid)
            env = _worker_env(job, env_extra)
            if uid is not None:  # the job as a whole (job_cgroup); the uid makes the name unique
                group = job_cgroup.create(f"robokit-job-{uid}", limits.memory_bytes, limits.max_processes)
            config = job.root / "launch.json"  # root-only: the job uid never reads it
            start = time.perf_counter()
            try:
                with _create(config) as f:
                    f.write(json.dumps({
                        "job_dir": str(job.root), "limits": dataclasses.asdict(limits), "uid": uid,
                        "python": sys.executable, "view": dataclasses.asdict(view), "args": list(args),
                        "env": env, "cgroup": list(group.dirs) if group else [],
                    }).encode())
                returncode, timed_out = _run(config, job, limits, env["PATH"])
            except OSError as exc:  # e.g. a file planted in the job folder (limited mode)
                return WorkerExit(None, False, 0.0, uid is not None, f"the grader could not start the worker: {exc}")
            finally:
                if group is not None:  # whatever the job left running, at once (the uid sweep follows)
                    with contextlib.suppress(OSError):
                        group.kill()
            seconds = time.perf_counter() - start
    finally:
        if group is not None:  # after the lease's sweep has killed what was left of the job
            group.remove()
    return WorkerExit(returncode, timed_out, seconds, uid is not None, job.read_log_tail())


if __name__ == "__main__":
    _launch(sys.argv[1])
