"""Grading runs at once on one host (issue 12): each job leases its own uid, so no run's sweep of
leftover processes can kill another run's workers."""
import csv
import os
import subprocess
import sys
from pathlib import Path

import pytest

from robocourse.grading.sandbox import is_root
from tests.conftest import ROOT

SOLUTION = ROOT / "solutions" / "00_getting_started.ipynb"


def _start_grader(folder: Path, copies: int) -> subprocess.Popen:
    folder.mkdir()
    for i in range(copies):
        (folder / f"student{i:02d}.ipynb").write_text(SOLUTION.read_text())
    env = {**os.environ, "ROBOKIT_GRADING_SEED": f"concurrent-{folder.name}"}
    return subprocess.Popen([sys.executable, "-m", "robocourse.cli", "grade", *sorted(map(str, folder.glob("*.ipynb"))),
                             "--assignment", "00_getting_started", "--out", str(folder / "grades.csv"),
                             "--jobs", "2", "--timeout", "120"],
                            env=env, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def test_two_graders_at_once_both_complete(tmp_path):
    if not is_root():
        pytest.skip("job uids exist only when grading as root")
    runs = [_start_grader(tmp_path / name, 8) for name in ("first", "second")]
    for name, proc in zip(("first", "second"), runs):
        out, _ = proc.communicate(timeout=600)
        assert proc.returncode == 0, out[-2000:]
        with open(tmp_path / name / "grades.csv") as f:
            rows = list(csv.DictReader(f))
        assert len(rows) == 8
        bad = [(r["student"], r["total"], r["flags"]) for r in rows if float(r["total"]) != 3.0 or r["flags"]]
        assert not bad, f"{name} run: {bad}\n{out[-2000:]}"
