"""One control group per grading job (root only): a bound on the job as a whole, not per process.

``RLIMIT_AS`` and ``RLIMIT_CPU`` bound each process of a worker; a worker that forks 60 children
could hold 60 times the memory limit, and children that each start a session (``setsid``) each
get their own share of the CPU, slowing the other jobs graded at the same time. The launcher
therefore joins a control group made for the job before it drops privileges, so that every
process of the job together gets at most ``memory_bytes`` of resident memory (the tmpfs pages it
writes included), at most ``max_processes`` processes, and one job's share of the CPU; and when
the worker is done, :meth:`JobCgroup.kill` ends whatever the job left running, all at once.

Both cgroup versions are supported: v1 (one hierarchy per controller, as in many containers)
and v2 (the unified hierarchy). The group is made below the grader's own group, so a
container's limits still hold around it. Where the host does not let the grader make groups (no
cgroup file system, read-only, or a v2 group that cannot delegate controllers), :func:`create`
returns ``None`` and only the per-process limits apply; :func:`cgroup_note` says which.
"""
from __future__ import annotations

import dataclasses
import os
import signal
import time
from pathlib import Path

__all__ = ["JobCgroup", "create", "cgroup_note"]

#: The controllers a job's group uses (v1: ``freezer`` is how the job is ended at once).
CONTROLLERS = ("memory", "pids", "cpu", "freezer")


@dataclasses.dataclass(frozen=True)
class JobCgroup:
    """The directories of one job's group (one per v1 hierarchy, or one v2 directory)."""

    dirs: tuple[str, ...]

    def join(self, pid: int = 0) -> None:
        """Move process ``pid`` (0: this one) into the group; its future children follow."""
        for d in self.dirs:
            Path(d, "cgroup.procs").write_text(str(pid or os.getpid()))

    def processes(self) -> set[int]:
        """The processes in the group now (every hierarchy's ``cgroup.procs``)."""
        found: set[int] = set()
        for d in self.dirs:
            try:
                found |= {int(x) for x in Path(d, "cgroup.procs").read_text().split()}
            except (OSError, ValueError):
                pass
        return found

    def kill(self, wait: float = 2.0) -> bool:
        """End every process in the group at once; return whether the group is empty within ``wait`` s.

        v2: ``cgroup.kill`` (Linux 5.14) kills the whole group in the kernel. Otherwise the group is
        frozen first (v2 ``cgroup.freeze``, v1 ``freezer.state``), so that no process can fork
        while its siblings are listed and sent ``SIGKILL``, then thawed, and the frozen processes
        die. No race with a process that forks and exits faster than ``/proc`` can be read.
        """
        for d in self.dirs:
            if Path(d, "cgroup.kill").exists():
                Path(d, "cgroup.kill").write_text("1")
                return self._empty(wait)
        freeze = next(((Path(d, "cgroup.freeze"), "1", "0") for d in self.dirs if Path(d, "cgroup.freeze").exists()),
                      None) or next(((Path(d, "freezer.state"), "FROZEN", "THAWED") for d in self.dirs
                                     if Path(d, "freezer.state").exists()), None)
        if freeze is None:                  # no freezer: signal what is listed (the uid sweep follows)
            self._signal_all()
            return self._empty(wait)
        path, frozen, thawed = freeze
        path.write_text(frozen)
        try:
            deadline = time.monotonic() + wait
            while not self._frozen(path) and time.monotonic() < deadline:
                time.sleep(0.005)
            self._signal_all()
        finally:                            # never leave the job frozen: killed, it dies on thawing
            path.write_text(thawed)
        return self._empty(wait)

    @staticmethod
    def _frozen(path: Path) -> bool:
        if path.name == "freezer.state":
            return path.read_text().strip() == "FROZEN"
        events = Path(path.parent, "cgroup.events").read_text().split()   # v2: "frozen 1"
        return "frozen" in events and events[events.index("frozen") + 1] == "1"

    def _signal_all(self) -> None:
        for pid in self.processes():
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass

    def _empty(self, wait: float) -> bool:
        deadline = time.monotonic() + wait
        while self.processes():
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return True

    def remove(self, wait: float = 2.0) -> bool:
        """Remove the group once its processes are gone (the caller has killed them); return
        whether every directory could be removed within ``wait`` seconds."""
        deadline = time.monotonic() + wait
        left = list(self.dirs)
        while left:
            for d in list(left):
                try:
                    os.rmdir(d)
                    left.remove(d)
                except FileNotFoundError:
                    left.remove(d)
                except OSError:
                    pass
            if left and time.monotonic() > deadline:
                return False
            if left:
                time.sleep(0.02)
        return True


def _mounts() -> tuple[dict[str, tuple[str, str]], tuple[str, str] | None]:
    """``(v1, v2)``: the v1 mount of each controller and the v2 mount, as (mount point, root)."""
    v1: dict[str, tuple[str, str]] = {}
    v2 = None
    try:
        lines = Path("/proc/self/mountinfo").read_text().splitlines()
    except OSError:
        return v1, v2
    for line in lines:
        left, _, right = line.partition(" - ")
        fields, rest = left.split(), right.split()
        if len(fields) < 5 or len(rest) < 3:
            continue
        root, point = fields[3], fields[4]
        if rest[0] == "cgroup":
            for option in rest[2].split(","):
                if option in CONTROLLERS:
                    v1.setdefault(option, (point, root))
        elif rest[0] == "cgroup2" and v2 is None:
            v2 = (point, root)
    return v1, v2


def _own_groups() -> dict[str, str]:
    """This process's group per v1 controller, and under ``""`` its v2 group (``/proc/self/cgroup``)."""
    own: dict[str, str] = {}
    try:
        lines = Path("/proc/self/cgroup").read_text().splitlines()
    except OSError:
        return own
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) == 3:
            for controller in parts[1].split(",") if parts[1] else [""]:
                own[controller] = parts[2]
    return own


def _below(mount: tuple[str, str], group: str) -> Path:
    """The directory of ``group`` (a path as /proc/self/cgroup shows it) in a mount of root ``root``."""
    point, root = mount
    if root != "/" and (group == root or group.startswith(root.rstrip("/") + "/")):
        group = group[len(root):]
    return Path(point, group.lstrip("/"))


def _make(parent: Path, name: str, settings: dict[str, str]) -> str:
    path = parent / name
    path.mkdir(exist_ok=True)
    for key, value in settings.items():
        (path / key).write_text(value)
    return str(path)


def create(name: str, memory_bytes: int, max_processes: int) -> JobCgroup | None:
    """Make (or reuse) the group ``name`` below the grader's own, with its limits; ``None`` where
    the host does not allow it (see the module docstring), which includes a grader that is not
    root. ``name`` must be unique on the host (the job's leased uid makes it so)."""
    v1, v2 = _mounts()
    own = _own_groups()
    made: list[str] = []
    try:
        if "memory" in v1 and "pids" in v1:
            limits = {"memory": {"memory.limit_in_bytes": str(int(memory_bytes))},
                      "pids": {"pids.max": str(int(max_processes))}, "cpu": {}, "freezer": {}}
            for controller, settings in limits.items():
                if controller in v1 and controller in own:
                    made.append(_make(_below(v1[controller], own[controller]), name, settings))
            return JobCgroup(tuple(made))
        if v2 is not None and "" in own:
            parent = _below(v2, own[""])
            enabled = (parent / "cgroup.subtree_control").read_text().split()
            missing = [c for c in CONTROLLERS if c not in enabled and c != "freezer"]   # v2 freezes built in
            if missing:  # fails (EBUSY) if the grader's own group holds processes: then no group
                (parent / "cgroup.subtree_control").write_text(" ".join(f"+{c}" for c in missing))
            made.append(_make(parent, name, {"memory.max": str(int(memory_bytes)),
                                             "pids.max": str(int(max_processes))}))
            return JobCgroup(tuple(made))
    except OSError:
        JobCgroup(tuple(made)).remove(wait=0.0)
    return None


def cgroup_note() -> str:
    """How a job is bounded as a whole on this host, for the grader's start-up line."""
    probe = create(f"robokit-probe-{os.getpid()}", 1 << 30, 64)
    if probe is None:
        return "per-process limits only (no control group for the job)"
    probe.remove(wait=0.0)
    return "a control group per job"
