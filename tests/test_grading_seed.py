"""The instructor's seed never reaches graded code (issue 12), with full isolation (root) and in
the limited mode (any other user): not in the worker's environment, nor in the environment or
command line of any process the worker can read, the grader's own included.

The submission answers ``wrap_angle`` correctly only if it finds no trace of the seed, so a leak
costs it the point; a cell also reports what it found, for the failure message.
"""
import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from robocourse.grading.sandbox import is_root
from tests.conftest import ROOT, public_tmp, wrap_angle_unless

SOLUTION = ROOT / "solutions" / "00_getting_started.ipynb"
SEED = "seed-7f3c9a-never-shown"

LOOK = f"""import glob, os
def _leaks():
    found = []
    if any("ROBOKIT_GRADING_SEED" in k or {SEED!r} in v for k, v in os.environ.items()):
        found.append("os.environ")
    for path in ["/proc/self/environ", f"/proc/{{os.getppid()}}/environ", f"/proc/{{os.getppid()}}/cmdline",
                 *glob.glob("/proc/*/environ"), *glob.glob("/proc/*/cmdline")]:
        try:
            with open(path, "rb") as f:
                data = f.read()
        except OSError:
            continue
        if b"ROBOKIT_GRADING_SEED" in data or {SEED!r}.encode() in data:
            found.append(path)
    return sorted(set(found))
"""

def _notebook() -> dict:
    nb = json.loads(SOLUTION.read_text())
    for cell in nb["cells"]:
        if cell["cell_type"] == "code" and "".join(cell["source"]).startswith("def wrap_angle"):
            cell["source"] = LOOK + wrap_angle_unless("_leaks()")
    nb["cells"].append({"cell_type": "code", "metadata": {}, "outputs": [], "execution_count": None,
                        "source": "if _leaks():\n    raise RuntimeError('seed visible in ' + ' '.join(_leaks()))\n"})
    return nb


def _blocked_ancestor(path: Path) -> Path | None:
    """The first directory above ``path`` that other users cannot enter (e.g. /root, mode 0700)."""
    for anc in reversed(path.parents):
        if not os.stat(anc).st_mode & 0o001:
            return anc
    return None


def _needed() -> list[Path]:
    """What the grader needs to read as another user: the interpreter and the clone (its venv)."""
    return sorted({Path(sys.base_prefix).resolve(), ROOT.resolve()})


def _unreadable_by_others() -> list[Path]:
    """Needed folders that other users cannot read themselves (a clone made mode 0700): no mount
    can open them to user nobody, so the limited-mode check cannot run there."""
    return [p for p in _needed() if (os.stat(p).st_mode & 0o005) != 0o005]


def _as_nobody(cmd: list[str]) -> list[str]:
    """``cmd`` as user nobody; as root, in a private mount namespace in which each private ancestor
    of the interpreter and of the clone (pyenv under /root, a clone in a ``mktemp -d`` folder) is
    covered by an empty folder and only what is needed is mounted back."""
    if not is_root():
        return cmd
    groups: dict[Path, list[Path]] = {}
    for path in _needed():
        blocked = _blocked_ancestor(path)
        if blocked is not None:
            groups.setdefault(blocked, []).append(path)
    prep = "set -e\n"
    for k, (blocked, paths) in enumerate(sorted(groups.items())):
        for j, path in enumerate(paths):
            prep += f'S{k}_{j}=$(mktemp -d)\nmount --bind "{path}" "$S{k}_{j}"\n'
        prep += f'mount -t tmpfs -o mode=0755 tmpfs "{blocked}"\n'
        for j, path in enumerate(paths):
            prep += f'mkdir -p "{path}"\nmount --bind "$S{k}_{j}" "{path}"\n'
    prep += 'exec setpriv --reuid=65534 --regid=65534 --clear-groups -- "$@"\n'
    return ["unshare", "--mount", "--propagation", "private", "--", "sh", "-c", prep, "sh", *cmd]


def _grade(folder: Path, *, limited: bool, on_command_line: bool) -> tuple[dict, str]:
    nb = folder / "student.ipynb"
    nb.write_text(json.dumps(_notebook()))
    out = folder / "grades.csv"
    cmd = [sys.executable, "-m", "robocourse.cli", "grade", str(nb), "--assignment", "00_getting_started",
           "--out", str(out), "--feedback", str(folder / "feedback"), "--timeout", "120", "--root", str(ROOT)]
    env = {"PATH": os.environ["PATH"], "HOME": str(folder), "ROBOKIT_CACHE": str(folder / "cache"),
           "LANG": "C.UTF-8"}
    if on_command_line:
        cmd += ["--seed", SEED]
    else:
        env["ROBOKIT_GRADING_SEED"] = SEED
    if limited:
        cmd = _as_nobody(cmd)
    proc = subprocess.run(cmd, env=env, cwd=folder, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-1500:] + proc.stderr[-1500:]
    with open(out) as f:
        row = next(csv.DictReader(f))
    feedback = (folder / "feedback" / "student.md").read_text()
    return row, feedback


@pytest.fixture
def folder():
    with public_tmp(0o777) as path:  # the limited-mode grader runs as another user
        yield path


@pytest.mark.parametrize("on_command_line", [False, True], ids=["environment", "command-line"])
@pytest.mark.parametrize("limited", [False, True], ids=["root", "limited"])
def test_seed_never_visible_to_the_submission(folder, limited, on_command_line):
    if not limited and not is_root():
        pytest.skip("full isolation needs root")
    if limited and is_root() and not (shutil.which("unshare") and shutil.which("setpriv")):
        pytest.skip("running the grader as another user needs util-linux's unshare and setpriv")
    if limited and is_root() and _unreadable_by_others():
        pytest.skip(f"{_unreadable_by_others()[0]} is readable by its owner only, so the grader cannot run as "
                    "another user from it (clone into a folder others can read to run this check)")
    row, feedback = _grade(folder, limited=limited, on_command_line=on_command_line)
    assert ("sandbox=limited" in row["flags"]) == limited
    assert row["00.wrap_angle"] == "1" and row["total"] == "3", (row, feedback[-1500:])
    assert SEED not in feedback
