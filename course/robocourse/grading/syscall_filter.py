"""No privilege gain and no new namespaces for the grading worker: ``no_new_privs`` and a seccomp filter.

The worker's launcher calls :func:`lock_down` last, after it has entered the job's view and
dropped to the job uid, right before it starts the worker. From then on, for the worker and every
process it starts:

* ``PR_SET_NO_NEW_PRIVS``: no set-uid or file-capability program gains privileges;
* a seccomp filter (classic BPF, installed with ``prctl``) refuses with ``EPERM``: ``unshare``,
  ``setns`` and ``clone`` with any namespace flag (so no user namespace, in which an unprivileged
  process would be root again and could mount a tmpfs or make a pid namespace); ``mount``,
  ``umount2``, ``pivot_root``, ``chroot`` and the new mount API; ``keyctl``, ``add_key``,
  ``request_key``; ``bpf``, ``userfaultfd``, ``perf_event_open``; ``ptrace`` and
  ``process_vm_readv/writev``; module loading, ``kexec``, ``reboot``, swap and ``acct``. ``clone3``
  gets ``ENOSYS`` (its flags are behind a pointer a filter cannot read), so the C library falls
  back to ``clone``, whose flags it checks; ``io_uring`` is refused (it can issue calls the filter
  never sees). A system call of any other architecture (x32 included) kills the process
  (``SIGSYS``).

The filter's table of system-call numbers is x86-64's; on another machine :func:`lock_down`
installs ``no_new_privs`` only and says so (:func:`filter_supported`). Not from a paper: Linux's
seccomp documentation (``Documentation/userspace-api/seccomp_filter.rst``).
"""
from __future__ import annotations

import ctypes
import errno
import platform
import struct

from robocourse.grading.budget import BudgetExceeded, run_within

__all__ = ["lock_down", "filter_supported", "probe", "REFUSED"]

_PR_SET_NO_NEW_PRIVS = 38
_PR_SET_SECCOMP = 22
_SECCOMP_MODE_FILTER = 2
_AUDIT_ARCH_X86_64 = 0xC000003E
_X32_SYSCALL_BIT = 0x40000000

_RET_ALLOW = 0x7FFF0000
_RET_ERRNO = 0x00050000
_RET_KILL_PROCESS = 0x80000000

# classic BPF opcodes
_LD_W_ABS = 0x20
_JEQ_K = 0x15
_JGE_K = 0x35
_JSET_K = 0x45
_RET_K = 0x06

#: Offsets in ``struct seccomp_data``: the call's number, the architecture, the low word of arg 0.
_NR, _ARCH, _ARG0_LOW = 0, 4, 16

#: Every namespace flag of ``clone``: NEWTIME, NEWNS, NEWCGROUP, NEWUTS, NEWIPC, NEWUSER, NEWPID, NEWNET.
NAMESPACE_FLAGS = 0x00000080 | 0x00020000 | 0x02000000 | 0x04000000 | 0x08000000 | 0x10000000 | 0x20000000 | 0x40000000

#: The refused system calls (x86-64 numbers), by name.
REFUSED = {
    "unshare": 272, "setns": 308, "mount": 165, "umount2": 166, "pivot_root": 155, "chroot": 161,
    "open_tree": 428, "move_mount": 429, "fsopen": 430, "fsconfig": 431, "fsmount": 432, "fspick": 433,
    "mount_setattr": 442, "keyctl": 250, "add_key": 248, "request_key": 249, "bpf": 321,
    "userfaultfd": 323, "perf_event_open": 298, "ptrace": 101, "process_vm_readv": 310,
    "process_vm_writev": 311, "init_module": 175, "finit_module": 313, "delete_module": 176,
    "kexec_load": 246, "kexec_file_load": 320, "reboot": 169, "swapon": 167, "swapoff": 168, "acct": 163,
    "io_uring_setup": 425, "io_uring_enter": 426, "io_uring_register": 427,
}
_CLONE, _CLONE3 = 56, 435


def filter_supported() -> bool:
    """Whether this process's system calls are the ones the filter's table names (64-bit x86 Linux)."""
    return platform.system() == "Linux" and platform.machine() in ("x86_64", "AMD64") and struct.calcsize("P") == 8


def probe() -> str:
    """Install the filter in a forked child (:func:`~.budget.run_within`) and report: ``""`` if it
    can be, else why not.

    The grader calls this once before a batch, so that a host that refuses ``no_new_privs`` or
    seccomp stops the batch with a clear message instead of failing every worker.
    """
    try:
        return run_within(_refusal, memory_bytes=256 * 1024**2, seconds=30)
    except BudgetExceeded as exc:
        return str(exc)


def _refusal() -> str:
    """In the probing child: ``""`` once the filter is installed, else the kernel's refusal."""
    try:
        lock_down()
    except OSError as exc:
        return str(exc)[:500] or "refused"
    return ""


def _program() -> list[tuple[int, int, int, int]]:
    """The filter, as ``(code, jump if true, jump if false, k)`` instructions (jumps are relative).

    Layout: check the architecture; load the call's number; refuse x32 numbers; refuse each listed
    call; ``clone3`` gets ``ENOSYS``; any call but ``clone`` is allowed; ``clone`` is refused if
    its flags hold a namespace flag. The four return instructions come last.
    """
    refused = sorted(REFUSED.values())
    i_first = 4                                   # after: load arch, check arch, load nr, x32 check
    i_clone3 = i_first + len(refused)
    i_clone = i_clone3 + 1
    i_flags = i_clone + 2                         # after: load flags
    i_allow, i_deny, i_enosys, i_kill = i_flags + 1, i_flags + 2, i_flags + 3, i_flags + 4

    def to(at: int, target: int) -> int:
        return target - at - 1

    prog = [(_LD_W_ABS, 0, 0, _ARCH),
            (_JEQ_K, 0, to(1, i_kill), _AUDIT_ARCH_X86_64),
            (_LD_W_ABS, 0, 0, _NR),
            (_JGE_K, to(3, i_kill), 0, _X32_SYSCALL_BIT)]
    prog += [(_JEQ_K, to(i_first + k, i_deny), 0, nr) for k, nr in enumerate(refused)]
    prog += [(_JEQ_K, to(i_clone3, i_enosys), 0, _CLONE3),
             (_JEQ_K, 0, to(i_clone, i_allow), _CLONE),
             (_LD_W_ABS, 0, 0, _ARG0_LOW),
             (_JSET_K, to(i_flags, i_deny), 0, NAMESPACE_FLAGS),
             (_RET_K, 0, 0, _RET_ALLOW),
             (_RET_K, 0, 0, _RET_ERRNO | errno.EPERM),
             (_RET_K, 0, 0, _RET_ERRNO | errno.ENOSYS),
             (_RET_K, 0, 0, _RET_KILL_PROCESS)]
    assert len(prog) == i_kill + 1
    return prog


def lock_down() -> str:
    """Set ``no_new_privs`` and install the filter on this process and all it will start.

    Returns
    -------
    str
        What was installed, for the worker's log: ``"no_new_privs and seccomp filter"`` or
        ``"no_new_privs only (...)"``.

    Raises
    ------
    OSError
        If the kernel refuses ``no_new_privs`` or the filter (the launcher then does not start the
        worker: a job is never run with less isolation than the report says).
    """
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
        err = ctypes.get_errno()
        raise OSError(err, f"prctl(PR_SET_NO_NEW_PRIVS): {errno.errorcode.get(err, err)}")
    if not filter_supported():
        return f"no_new_privs only (no system-call table for {platform.machine()})"
    prog = _program()
    raw = b"".join(struct.pack("HBBI", *ins) for ins in prog)
    buffer = ctypes.create_string_buffer(raw, len(raw))

    class SockFprog(ctypes.Structure):
        _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_void_p)]

    fprog = SockFprog(len(prog), ctypes.cast(buffer, ctypes.c_void_p))
    if libc.prctl(_PR_SET_SECCOMP, _SECCOMP_MODE_FILTER, ctypes.byref(fprog), 0, 0) != 0:
        err = ctypes.get_errno()
        raise OSError(err, f"prctl(PR_SET_SECCOMP): {errno.errorcode.get(err, err)}")
    return "no_new_privs and seccomp filter"
