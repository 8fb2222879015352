"""``robocourse gradescope``: package an assignment as a Gradescope autograder zip.

The zip holds the robokit and robocourse wheels, ``setup.sh`` (installs them into a virtual
environment on Gradescope's Ubuntu image), ``run_autograder`` (grades
``/autograder/submission/*.ipynb`` with ``robocourse grade`` and writes
``/autograder/results/results.json``) and the secret seed, read into an environment variable so it
never appears on a command line. Gradescope runs the autograder as root, so student code gets the
full sandbox: its own unprivileged uid, the autograder's source folder hidden, no network.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

from robocourse.lessons import exercises_for

__all__ = ["build_autograder"]

_SETUP = """#!/usr/bin/env bash
# Gradescope autograder setup: install robokit and robocourse from the wheels shipped in this zip.
set -euo pipefail
apt-get update -qq
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3 python3-venv python3-pip >/dev/null
python3 -m venv /opt/robocourse
/opt/robocourse/bin/pip install --quiet {wheels}
"""

_RUN = """#!/usr/bin/env bash
# Gradescope autograder entry point: grade the submitted notebook in robocourse's sandbox.
# Every path is quoted, so the script also runs where a path holds a space (its tests rewrite them).
set -uo pipefail
mkdir -p "/autograder/results"
shopt -s nullglob
notebooks=("/autograder/submission"/*.ipynb)
if [ ${{#notebooks[@]}} -eq 0 ]; then
  printf '{{"score": 0, "output": "No .ipynb file was submitted: upload your {slug}.ipynb notebook."}}' \\
    > "/autograder/results/results.json"
  exit 0
fi
ROBOKIT_GRADING_SEED="$(cat "/autograder/source/seed.txt")" "/opt/robocourse/bin/robocourse" grade "${{notebooks[0]}}" \\
  --assignment {slug} --out "/autograder/results/grades.csv" --gradescope "/autograder/results/results.json" \\
  --feedback "/autograder/results/feedback" --root "/autograder/source" --timeout {timeout} \\
  --hide "/autograder/source"
"""


def _wheel(root: Path, folder: str, package: str, tmp: Path) -> Path:
    """Build the wheel of ``root/folder`` (which holds ``package``) from a clean copy: an in-tree
    build leaves ``build/lib`` behind, whose stale modules would end up in later wheels."""
    src = tmp / f"src-{package}"
    shutil.copytree(root / folder / package, src / package, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(root / folder / name, src / name)
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(tmp), str(src)],
                          capture_output=True, text=True)
    wheels = list(tmp.glob(f"{package}-*.whl"))
    if proc.returncode != 0 or not wheels:
        raise RuntimeError(f"building the {package} wheel failed: {proc.stderr[-800:]}")
    return wheels[0]


def build_autograder(slug: str, seed: str, output: str | Path, *, root: str | Path = ".",
                     timeout: float = 600) -> Path:
    """Write the Gradescope autograder zip for assignment ``slug``.

    Parameters
    ----------
    slug : str
        Assignment, e.g. ``"05_gps_sonar_truck"``.
    seed : str
        The instructor's secret seed (stored inside the zip, which only instructors see).
    output : path
        Zip file to write.
    root : path, default "."
        The course repository (the wheels are built from it).
    timeout : float, default 600
        Seconds allowed per submission.

    Raises
    ------
    ValueError
        Unknown assignment or empty seed.
    RuntimeError
        If a wheel cannot be built.

    Notes
    -----
    Gradescope's autograder specification (setup.sh, run_autograder, results/results.json).
    """
    exercises_for(slug)
    if not seed:
        raise ValueError("seed: a non-empty secret seed is required")
    output = Path(output)
    root = Path(root).resolve()
    with tempfile.TemporaryDirectory() as tmp:
        wheels = [_wheel(root, ".", "robokit", Path(tmp)), _wheel(root, "course", "robocourse", Path(tmp))]
        with zipfile.ZipFile(output, "w", zipfile.ZIP_DEFLATED) as z:
            for wheel in wheels:
                z.write(wheel, wheel.name)
            setup = _SETUP.format(wheels=" ".join(f"/autograder/source/{w.name}" for w in wheels))
            for name, text in (("setup.sh", setup),
                               ("run_autograder", _RUN.format(slug=slug, timeout=int(timeout)))):
                info = zipfile.ZipInfo(name)
                info.external_attr = 0o755 << 16
                z.writestr(info, text)
            z.writestr("seed.txt", seed)
    return output
