"""What a grading worker's filesystem shows when the grader runs as root: an allowlist.

The worker gets a new root directory (an empty tmpfs) into which the launcher mounts, read-only,
only what :class:`View` lists: the interpreter and its standard library, the installed packages'
code (the site-packages directories on ``sys.path``, a virtual environment), the system's shared
libraries, a few files of ``/etc`` the dynamic loader reads, and the worker's kit (shown also in
place of every robocourse package installed in those directories; every installed robokit is
covered by an empty directory). The job's own ``in/``
(read-only), ``work/`` and ``out/``, a private ``/tmp``, a minimal ``/dev`` and a ``/proc`` that
shows only the job's processes complete it. Everything else (the course root with its ``.git``,
``solutions/`` and ``build/``, the other submissions, home directories, other jobs' directories)
is simply not there, editable install or not: nothing is hidden one path at a time.

:func:`runtime_paths` (grader side) lists the interpreter's part; :func:`enter_view` runs in the
sandbox launcher (root, in a fresh mount namespace) and switches the process into the new root.
"""
from __future__ import annotations

import contextlib
import ctypes
import dataclasses
import functools
import glob
import os
import platform
import sys
import sysconfig
from pathlib import Path
from typing import Iterator, Sequence

__all__ = ["View", "runtime_paths", "installed_package_dirs", "enter_view", "bounded_space"]

#: Shared libraries and what the dynamic loader and time functions read.
SYSTEM_PATHS = ("/lib", "/lib32", "/lib64", "/usr/lib", "/usr/lib32", "/usr/lib64", "/usr/share/zoneinfo",
                "/etc/ld.so.cache", "/etc/ld.so.conf", "/etc/ld.so.conf.d", "/etc/localtime")
#: Device nodes the worker may open.
DEVICES = ("null", "zero", "full", "random", "urandom")

_MS_RDONLY, _MS_NOSUID, _MS_NODEV, _MS_NOEXEC, _MS_REMOUNT, _MS_BIND, _MS_MOVE, _MS_REC, _MS_PRIVATE = (
    1, 2, 4, 8, 32, 4096, 8192, 16384, 1 << 18)
_MNT_DETACH = 2
_CLONE_NEWNS, _CLONE_NEWIPC, _CLONE_NEWNET = 0x00020000, 0x08000000, 0x40000000
_SYS_PIVOT_ROOT = {"x86_64": 155, "aarch64": 41, "riscv64": 41, "ppc64le": 203, "s390x": 217}


@dataclasses.dataclass(frozen=True)
class View:
    """The worker's filesystem, as host paths.

    Attributes
    ----------
    read_only : tuple of str
        Shown read-only at the same place (files or directories; missing ones are skipped).
    replace : tuple of (str, str)
        ``(where, what)``: the host directory ``what`` shown read-only at ``where``, over what
        another entry would show there (the kit's robocourse over an installed robocourse).
    hide : tuple of str
        Covered by an empty directory or file where they lie inside a tree another entry shows
        (elsewhere they are not shown anyway).
    """

    read_only: tuple[str, ...]
    replace: tuple[tuple[str, str], ...] = ()
    hide: tuple[str, ...] = ()


def _link_chain(path: str) -> list[str]:
    """``path`` and every path its symbolic links lead through (a venv's python -> python3 -> ...)."""
    chain = [path]
    while os.path.islink(chain[-1]) and len(chain) < 40:
        chain.append(os.path.join(os.path.dirname(chain[-1]), os.readlink(chain[-1])))
    return [os.path.abspath(p) for p in chain]


@functools.lru_cache(maxsize=1)
def runtime_paths() -> tuple[str, ...]:
    """The interpreter, its standard library and the installed packages' code (this process's).

    Of an installation prefix (the interpreter's, a virtual environment's, a conda environment's)
    only ``lib``/``lib64`` (packages and shared libraries) and a venv's ``pyvenv.cfg`` are shown,
    never the whole prefix: ``pip install -e git+...`` checks a project out, ``.git`` and
    solutions included, into ``<prefix>/src``. A ``sys.path`` entry counts only if it is the
    standard library or a ``site-packages`` / ``dist-packages`` directory: a project directory on
    the path (an old-style editable install, ``PYTHONPATH``) holds its ``.git`` and everything else
    beside the package, so it is left out.
    """
    paths = {*_link_chain(sys.executable), *SYSTEM_PATHS}
    for prefix in {sys.base_prefix, sys.prefix}:
        paths.update(os.path.join(prefix, lib) for lib in ("lib", "lib64"))
    if sys.prefix != sys.base_prefix:
        paths.add(os.path.join(sys.prefix, "pyvenv.cfg"))  # a virtual environment's configuration
    for scheme_path in ("stdlib", "platstdlib", "purelib", "platlib"):
        paths.add(sysconfig.get_paths()[scheme_path])
    for entry in sys.path:
        if entry and os.path.basename(entry.rstrip("/")) in ("site-packages", "dist-packages"):
            paths.add(entry)
    return tuple(sorted(p for p in paths if os.path.lexists(p)))


def installed_package_dirs(paths: Sequence[str], name: str) -> list[str]:
    """The packages ``name`` installed in ``paths`` (``robocourse``: copies the kit must stand in
    for; ``robokit``: copies the worker must not see).

    A package counts directly inside a path, in a ``python*/site-packages`` or ``dist-packages``
    below one (the base interpreter's packages beside a virtual environment, a system Python's in
    ``/usr/lib``), or in an ``.egg`` there.
    """
    sites: set[str] = set()
    for path in paths:
        if os.path.isdir(path):
            for site in (path, *glob.glob(os.path.join(glob.escape(path), "python*", "*-packages"))):
                sites.update((site, *glob.glob(os.path.join(glob.escape(site), "*.egg"))))
    return sorted({os.path.join(site, name) for site in sites
                   if os.path.isfile(os.path.join(site, name, "__init__.py"))})


# -- the launcher's side (root, in its own mount namespace) ---------------------------------------

def _libc():
    libc = ctypes.CDLL(None, use_errno=True)
    libc.mount.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_ulong, ctypes.c_char_p]
    libc.umount2.argtypes = [ctypes.c_char_p, ctypes.c_int]
    return libc


def _check(ret: int, what: str) -> None:
    if ret != 0:
        err = ctypes.get_errno()
        raise OSError(err, f"{what}: {os.strerror(err)}")


class _NewRoot:
    """Builds the worker's root directory at ``top`` (a fresh tmpfs) from host paths."""

    def __init__(self, top: Path):
        self.top, self.libc, self.shown = top, _libc(), []

    def mount(self, source, target, fstype, flags, data, what) -> None:
        enc = (lambda v: None if v is None else str(v).encode())
        _check(self.libc.mount(enc(source), enc(target), enc(fstype), flags, enc(data)), what)

    def inside(self, host: str) -> Path:
        return self.top / host.lstrip("/")

    def place(self, host: str, depth: int = 0) -> str:
        """Recreate the symbolic links met on the way to ``host``; return it with links resolved."""
        current = "/"
        parts = Path(host).parts[1:]
        for i, part in enumerate(parts):
            step = os.path.join(current, part)
            if os.path.islink(step):
                link = self.inside(step)
                if not os.path.lexists(link):
                    link.parent.mkdir(parents=True, exist_ok=True)
                    os.symlink(os.readlink(step), link)
                rest = os.path.join(os.path.realpath(step), *parts[i + 1:])
                return self.place(rest, depth + 1) if depth < 40 else rest
            current = step
        return current

    def bind(self, source: str, where: str, *, writable: bool = False, replace: bool = False) -> None:
        """Show host ``source`` at ``where`` (read-only unless ``writable``); skip what is missing
        or already shown by a parent (unless ``replace``)."""
        real = self.place(where)
        if not os.path.exists(source) or (not replace and any(real == s or real.startswith(s.rstrip("/") + "/")
                                                              for s in self.shown)):
            return
        target = self.inside(real)
        if not os.path.lexists(target):
            target.parent.mkdir(parents=True, exist_ok=True)
            target.mkdir() if os.path.isdir(source) else target.touch()
        self.mount(source, target, None, _MS_BIND | _MS_REC, None, f"show {source}")
        flags = _MS_REMOUNT | _MS_BIND | _MS_NOSUID | _MS_NODEV | (0 if writable else _MS_RDONLY)
        self.mount(None, target, None, flags, None, f"limit {source}")
        self.shown.append(real)

    def cover(self, host: str) -> None:
        """Cover ``host`` by an empty read-only directory or file if it lies inside a shown tree
        (a path that merely contains shown ones, like a home directory holding the interpreter,
        is already reduced to them)."""
        real = os.path.realpath(host)
        if not any(real.startswith(s.rstrip("/") + "/") for s in self.shown):
            return
        target = self.inside(real)
        if os.path.isdir(target) and not os.path.islink(target):
            self.mount("tmpfs", target, "tmpfs", _MS_NOSUID | _MS_NODEV | _MS_RDONLY, "mode=0555,size=4k", f"hide {host}")
        elif os.path.isfile(target):
            self.mount(self.inside("/dev/null"), target, None, _MS_BIND, None, f"hide {host}")

    def tmpfs(self, where: str, options: str, flags: int = _MS_NOSUID | _MS_NODEV) -> Path:
        target = self.inside(where)
        target.mkdir(parents=True, exist_ok=True)
        self.mount("tmpfs", target, "tmpfs", flags, options, f"mount {where}")
        return target

    def devices(self) -> None:
        dev = self.tmpfs("/dev", "mode=0755,size=64k", _MS_NOSUID | _MS_NOEXEC)
        for name in DEVICES:
            (dev / name).touch()
            self.mount(f"/dev/{name}", dev / name, None, _MS_BIND, None, f"device {name}")
        for name, target in (("fd", "/proc/self/fd"), ("stdin", "/proc/self/fd/0"), ("stdout", "/proc/self/fd/1"),
                             ("stderr", "/proc/self/fd/2")):
            os.symlink(target, dev / name)
        self.tmpfs("/dev/shm", "mode=1777,size=16m", _MS_NOSUID | _MS_NODEV | _MS_NOEXEC)

    def switch(self) -> None:
        """Make the new root read-only and the process's ``/``; the old root is detached."""
        self.mount(None, self.top, None, _MS_REMOUNT | _MS_BIND | _MS_RDONLY | _MS_NOSUID | _MS_NODEV, None,
                   "seal the new root")
        os.chdir(self.top)
        number = _SYS_PIVOT_ROOT.get(platform.machine())
        if number is not None and self.libc.syscall(number, b".", b".") == 0:
            _check(self.libc.umount2(b".", _MNT_DETACH), "detach the old root")
        else:  # no pivot_root: move the new root over / and enter it (equally closed once the uid drops)
            self.mount(".", "/", None, _MS_MOVE, None, "move the new root")
            os.chroot(".")
        os.chdir("/")


def enter_view(view: View, top: Path, job_dirs: Sequence[tuple[str, bool]]) -> None:
    """Unshare mounts, System V IPC and the network, build the new root at ``top`` and enter it
    (root only). With its own IPC namespace and ``/dev/shm``, a job cannot leave data for another.

    ``job_dirs`` are ``(path, writable)`` pairs: the job's ``in/``, ``work/`` and ``out/``.
    """
    libc = _libc()
    _check(libc.unshare(_CLONE_NEWNS | _CLONE_NEWIPC | _CLONE_NEWNET), "unshare")
    _check(libc.mount(b"none", b"/", None, _MS_REC | _MS_PRIVATE, None), "make mounts private")
    top.mkdir(mode=0o755, exist_ok=True)
    root = _NewRoot(top)
    root.mount("tmpfs", top, "tmpfs", _MS_NOSUID | _MS_NODEV, "mode=0755,size=1m", "mount the new root")
    root.tmpfs("/tmp", "mode=1777,size=64m")
    root.devices()
    proc = root.inside("/proc")
    proc.mkdir()
    root.mount("proc", proc, "proc", _MS_NOSUID | _MS_NODEV | _MS_NOEXEC, "hidepid=2", "mount /proc")
    for path in view.read_only:
        root.bind(path, path)
    for where, what in view.replace:
        root.bind(what, where, replace=True)
    for path, writable in job_dirs:
        root.bind(path, path, writable=writable, replace=True)
    for path in view.hide:
        root.cover(path)
    root.switch()


@contextlib.contextmanager
def bounded_space(paths: Sequence[Path], size_bytes: int, max_files: int = 10_000) -> Iterator[None]:
    """Give each directory of ``paths`` its own tmpfs of ``size_bytes`` and ``max_files`` files
    (root only) while the block runs; what was written there is gone afterwards.

    ``RLIMIT_FSIZE`` bounds each file a worker writes but not how many: without this a worker
    could fill the host's disk (its ``work/`` and ``out/`` live in the grader's temporary folder).
    The mounts are made in the grader's namespace before the worker starts, so the worker's view
    shows them and the grader reads ``out/`` from them after it ends.
    """
    libc = _libc()
    mounted: list[bytes] = []
    try:
        for path in paths:
            target = os.fsencode(path)
            _check(libc.mount(b"tmpfs", target, b"tmpfs", _MS_NOSUID | _MS_NODEV,
                              f"mode=0700,size={int(size_bytes)},nr_inodes={int(max_files)}".encode()),
                   f"bound the space of {path}")
            mounted.append(target)
        yield
    finally:
        for target in reversed(mounted):
            libc.umount2(target, _MNT_DETACH)
