"""Execute a notebook headless in a fresh kernel, with a time limit and no network.

:func:`run_notebook` is used by both the test-suite and ``robocourse build``. Each notebook
runs in its own worker process (``python -m robocourse.site.execute``) that starts a fresh Jupyter
kernel with nbclient; the parent enforces a wall-clock limit on the whole notebook and kills the
worker's process group (kernel included) when it is exceeded, so a hanging notebook is reported as
``timeout`` and never blocks the others. Every kernel runs with:

* ``ROBOKIT_FAST`` set as requested (``1`` under tests), ``ROBOKIT_HEADLESS=1``,
* its working directory a fresh temporary directory,
* a private ``IPYTHONDIR`` whose startup file installs :mod:`robocourse.site.netguard`,
* ``PYTHONHASHSEED=0`` for reproducible ordering.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

__all__ = ["NotebookRun", "run_notebook", "execute_in_process", "kill_process_group", "THREAD_VARIABLES"]

#: Exception names an assignment notebook may raise: the stubs students have not filled in yet
#: (``NotImplementedYet`` is the ``NotImplementedError`` that ``check()`` raises on a stub).
STUB_ERRORS = ("NotImplementedError", "NotImplementedYet")

_STARTUP = "from robocourse.site import netguard as _rk_netguard\n_rk_netguard.install()\ndel _rk_netguard\n"


@dataclasses.dataclass
class NotebookRun:
    """Outcome of executing one notebook.

    Attributes
    ----------
    path : Path
        The source notebook.
    status : str
        ``"ok"``, ``"failed"`` or ``"timeout"``.
    seconds : float
        Wall-clock run time.
    error : str
        The last lines of the error (empty when ``ok``).
    executed : Path or None
        The executed notebook with outputs, if it was written.
    """

    path: Path
    status: str
    seconds: float
    error: str = ""
    executed: Path | None = None

    @property
    def ok(self) -> bool:
        return self.status == "ok"


def _tail(text: str, lines: int = 12) -> str:
    import re

    text = re.sub(r"\x1b\[[0-9;]*m", "", text)  # strip ANSI colours from tracebacks
    return "\n".join(text.strip().splitlines()[-lines:])


#: Environment variables that cap the threads of numpy's BLAS (OpenBLAS, MKL, OpenMP) and OpenCV.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OPENCV_FOR_THREADS_NUM")


def _kernel_env(workdir: Path, fast: bool, workers: int | None = None) -> dict[str, str]:
    ipydir = workdir / ".ipython"
    startup = ipydir / "profile_default" / "startup"
    startup.mkdir(parents=True, exist_ok=True)
    (startup / "00-robokit-netguard.py").write_text(_STARTUP)
    env = dict(os.environ)
    env.update(
        ROBOKIT_FAST="1" if fast else "0",
        ROBOKIT_HEADLESS="1",  # sliders show their pre-computed static form (robokit.viz.slider)
        IPYTHONDIR=str(ipydir),
        PYTHONHASHSEED="0",
        JUPYTER_PLATFORM_DIRS="1",
        PYDEVD_DISABLE_FILE_VALIDATION="1",
    )
    env.pop("MPLBACKEND", None)  # the inline backend must stay in charge inside the kernel
    if workers is not None:
        env["ROBOKIT_WORKERS"] = str(workers)   # robokit.parallel's worker processes for this notebook
        # and at most as many threads for BLAS and OpenCV (a caller's own lower cap stays): a notebook
        # beside others on the cores that spins up threads of its own only slows them all (lesson 02
        # in a two-notebook build: 143 -> 126 s)
        for name in THREAD_VARIABLES:
            own = env.get(name, "")
            env[name] = str(min(workers, int(own))) if own.isdigit() and int(own) > 0 else str(workers)
    return env


def execute_in_process(src: Path, dst: Path, *, cwd: Path, cell_timeout: int,
                       allowed_errors: tuple[str, ...] = (), runtime_dir: Path | None = None) -> tuple[str, str]:
    """Execute ``src`` with nbclient in this process and write the executed notebook to ``dst``.

    The kernel talks over Unix sockets created in ``runtime_dir`` (default: a new temporary
    directory), never in ``cwd``, so the notebook starts in an empty directory.

    Returns ``(status, error_tail)``. Like JupyterLab's Run All, execution stops at the first error
    of a cell not tagged ``raises-exception``; with ``allowed_errors`` an error of a tagged cell
    fails the notebook only if its exception name is not in the list (used for assignments, whose
    stubs raise ``NotImplementedError`` in the cells ``robocourse assign`` tags).
    """
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

    from jupyter_client import KernelManager

    nb = nbformat.read(src, as_version=4)
    # Unix-socket (IPC) transport: kernels started side by side by a parallel build cannot race for
    # the same free TCP ports (seen as "Kernel died before replying to kernel_info")
    sockets = Path(runtime_dir) if runtime_dir else Path(tempfile.mkdtemp(prefix="robokit-kernel-"))
    client = NotebookClient(
        nb,
        km=KernelManager(kernel_name="python3", transport="ipc", ip=str(sockets / "kernel")),
        timeout=cell_timeout,
        kernel_name="python3",
        allow_errors=False,               # an untagged cell's error stops the run, as in JupyterLab
        resources={"metadata": {"path": str(cwd)}},
        record_timing=False,
    )
    status, error = "ok", ""
    try:
        client.execute(cwd=str(cwd))
    except CellTimeoutError as exc:
        status, error = "timeout", _tail(str(exc))
    except (CellExecutionError, DeadKernelError) as exc:
        status, error = "failed", _tail(str(exc))
    except Exception as exc:  # kernel failed to start, bad notebook, ...
        status, error = "failed", _tail(f"{type(exc).__name__}: {exc}")
    if status == "ok" and allowed_errors:
        for i, cell in enumerate(nb.cells):
            for out in cell.get("outputs", []):
                if out.get("output_type") == "error" and out.get("ename") not in allowed_errors:
                    status = "failed"
                    error = _tail(f"cell {i}: {out.get('ename')}: {out.get('evalue')}\n"
                                  + "\n".join(out.get("traceback", [])))
                    break
            if status != "ok":
                break
    nbformat.write(nb, dst)
    return status, error


def run_notebook(path: str | Path, *, timeout: float = 600, fast: bool = True,
                 output: str | Path | None = None, assignment: bool | None = None,
                 workers: int | None = None) -> NotebookRun:
    """Execute a notebook in a fresh kernel in a worker process and report the outcome.

    Parameters
    ----------
    path : str or Path
        Notebook to run.
    timeout : float, default 600
        Wall-clock limit for the whole notebook in seconds; the worker and its kernel are killed
        when it is exceeded and the run is reported as ``"timeout"``.
    fast : bool, default True
        Value of ``ROBOKIT_FAST`` inside the kernel.
    output : str or Path, optional
        Where to write the executed notebook; defaults to a file in the temporary directory.
    assignment : bool, optional
        Treat the notebook as a student assignment (``NotImplementedError`` from stubs is allowed).
        Defaults to whether the notebook lives in an ``assignments`` directory.
    workers : int, optional
        ``ROBOKIT_WORKERS`` inside the kernel (worker processes for independent runs) and the
        thread counts of BLAS and OpenCV (:data:`THREAD_VARIABLES`, lowered to it, never raised);
        default: inherited.

    Returns
    -------
    NotebookRun

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        If ``timeout`` is not positive.

    Notes
    -----
    Course tooling (DESIGN.md, "Fast mode"); not from a paper.
    """
    path = Path(path).resolve()
    if not path.is_file():
        raise FileNotFoundError(f"path: notebook {path} does not exist")
    if not timeout > 0:
        raise ValueError(f"timeout: expected a positive number of seconds, got {timeout!r}")
    if workers is not None and (not isinstance(workers, int) or isinstance(workers, bool) or not 1 <= workers <= 64):
        raise ValueError(f"workers: expected a whole number of worker processes from 1 to 64, got {workers!r}")
    if assignment is None:
        assignment = path.parent.name == "assignments"
    workdir = Path(tempfile.mkdtemp(prefix="robokit-nb-"))
    cwd = workdir / "cwd"
    cwd.mkdir()
    dst = Path(output).resolve() if output else workdir / path.name
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.unlink(missing_ok=True)    # a worker killed at the time limit writes nothing: never show an old run
    result_file = workdir / "result.json"
    cmd = [sys.executable, "-m", "robocourse.site.execute", str(path), str(dst), str(result_file),
           "--cwd", str(cwd), "--runtime-dir", str(workdir), "--cell-timeout", str(int(max(1, timeout)))]
    if assignment:
        cmd += ["--allow-errors", *STUB_ERRORS]
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, env=_kernel_env(workdir, fast, workers), cwd=cwd, start_new_session=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        log, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        kill_process_group(proc)
        log = ""
        status, error = "timeout", f"stopped after the notebook time limit of {timeout:g} s"
    else:
        kill_process_group(proc)  # the kernel may outlive a crashed worker
        try:
            result = json.loads(result_file.read_text())
            status, error = result["status"], result["error"]
        except (OSError, ValueError, KeyError):
            status, error = "failed", _tail(log or f"worker exited with code {proc.returncode}")
    seconds = time.perf_counter() - start
    return NotebookRun(path, status, seconds, error, dst if dst.exists() else None)


def kill_process_group(proc: subprocess.Popen) -> None:
    """Kill the process group that ``proc`` leads (started with ``start_new_session=True``: a
    notebook worker and its kernel, or Chromium and its helpers) and reap ``proc``."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        pass


def _main(argv: list[str] | None = None) -> int:
    # This process only reads, runs and writes one notebook. nbformat imports jsonschema, which at
    # import builds rfc3987_syntax's grammars for the "iri" string formats (1.0-1.4 s of every
    # notebook's run on the 2-core machine); no notebook schema uses those formats, and jsonschema
    # leaves them out when that package cannot be imported.
    sys.modules.setdefault("rfc3987_syntax", None)
    parser = argparse.ArgumentParser(description="robokit notebook worker (internal)")
    parser.add_argument("src", type=Path)
    parser.add_argument("dst", type=Path)
    parser.add_argument("result", type=Path)
    parser.add_argument("--cwd", type=Path, required=True)
    parser.add_argument("--runtime-dir", type=Path, default=None)
    parser.add_argument("--cell-timeout", type=int, default=600)
    parser.add_argument("--allow-errors", nargs="*", default=[])
    args = parser.parse_args(argv)
    status, error = execute_in_process(args.src, args.dst, cwd=args.cwd, cell_timeout=args.cell_timeout,
                                       allowed_errors=tuple(args.allow_errors), runtime_dir=args.runtime_dir)
    args.result.write_text(json.dumps({"status": status, "error": error}))
    return 0


if __name__ == "__main__":
    sys.exit(_main())
