"""``robocourse student-kit``: the handout holds what a student needs and nothing of the solutions."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import zipfile

import pytest

from robocourse.cli import main
from robocourse.grading.handout import TOP, handout_files, write_handout
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def handout(tmp_path_factory):
    path, count = write_handout(ROOT, tmp_path_factory.mktemp("kit") / "kit.zip")
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
        assert len(names) == count
        folder = tmp_path_factory.mktemp("unpacked")
        z.extractall(folder)
    return folder / TOP, names


def _solution_texts() -> list[str]:
    """Every solution block and model answer of solutions/, as text a leak would contain."""
    found = []
    for nb in (ROOT / "solutions").glob("*.ipynb"):
        for cell in json.loads(nb.read_text())["cells"]:
            src = "".join(cell["source"])
            found += re.findall(r"#\s*BEGIN SOLUTION\n(.*?)#\s*END SOLUTION", src, re.S)
            found += re.findall(r"<!--\s*BEGIN SOLUTION[^>]*-->(.*?)<!--\s*END SOLUTION\s*-->", src, re.S)
    return [t.strip() for t in found if len(t.strip()) > 40]


def test_the_handout_has_the_lessons_assignments_and_packages_and_no_solutions(handout):
    folder, names = handout
    lessons = sorted(p.name for p in (ROOT / "lessons").glob("*.ipynb"))
    assert sorted(p.name for p in (folder / "lessons").glob("*.ipynb")) == lessons
    assert sorted(p.name for p in (folder / "assignments").glob("*.ipynb")) == \
        sorted(p.name for p in (ROOT / "assignments").glob("*.ipynb"))
    for needed in ("pyproject.toml", "course/pyproject.toml", "environment.yml", "constraints.txt", "Makefile", "README.md",
                   "course/README.md", "robokit/__init__.py", "course/robocourse/grading/check.py", "course/robocourse/data/04_littledog.json"):
        assert (folder / needed).is_file(), needed
    assert not any(part in ("solutions", "tests", "benchmarks", "__pycache__") for n in names for part in n.split("/"))
    texts = _solution_texts()
    assert len(texts) > 40                                  # the leak check reads real solutions
    for f in folder.rglob("*"):
        if f.is_file() and f.suffix in (".py", ".ipynb", ".md", ".json"):
            body = f.read_text(encoding="utf-8")
            leaked = [t[:60] for t in texts if t in body]
            assert not leaked, (f, leaked[:2])
    readme = (folder / "README.md").read_text()
    assert "## Student guide" in readme and "## Instructor guide" not in readme and "make lab" in readme
    environment = (folder / "environment.yml").read_text()
    assert "numpy" in environment and "mujoco" in environment and "jupyterlab" in environment
    assert not any(dev in environment for dev in ("pytest", "gtsam", "roboticstoolbox", "hypothesis", "cvxopt"))
    makefile = (folder / "Makefile").read_text()
    assert "'.[legged,arm]'" in makefile and "dev" not in makefile and "\tlab" not in makefile
    assert (folder / "course" / "README.md").is_file()                # course/pyproject.toml names it


def test_the_handout_imports_its_own_course_package_and_check_works(handout):
    folder, _ = handout
    env = dict(os.environ, PYTHONPATH=f"{folder}{os.pathsep}{folder / 'course'}")
    code = ("import robocourse, robokit; from robocourse import check, assignment_data\n"
            "print(robocourse.__file__); print(robokit.__file__)\n"
            "print(sorted(assignment_data('04_littledog')))\n"
            "import numpy as np\n"
            "def wrap(a):\n"
            "    a = np.asarray(a, dtype=float)\n"
            "    if not np.all(np.isfinite(a)): raise ValueError('angle: NaN')\n"
            "    return (a + np.pi) % (2 * np.pi) - np.pi\n"
            "check('00.wrap_angle', wrap)")
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=folder, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = out.stdout.splitlines()
    assert lines[0].startswith(str(folder)) and lines[1].startswith(str(folder)), lines[:2]
    assert "model_facts" in lines[2] and "00.wrap_angle" in out.stdout


def test_a_stale_assignment_or_a_bad_output_stops_the_handout(tmp_path, capsys):
    with pytest.raises(ValueError, match="output"):
        write_handout(ROOT, tmp_path / "kit.tar")
    with pytest.raises(ValueError, match="inside what the handout copies"):
        write_handout(ROOT, ROOT / "lessons" / "kit.zip")
    with pytest.raises(FileNotFoundError, match="root"):
        handout_files(tmp_path)
    with pytest.raises(TypeError, match="output"):
        write_handout(ROOT, 3)
    with pytest.raises(TypeError, match="root"):
        handout_files(None)
    assert main(["student-kit", "--root", str(tmp_path), "-o", str(tmp_path / "k.zip")]) == 2
    assert "robocourse student-kit: error" in capsys.readouterr().err
    assert not (tmp_path / "k.zip").exists()
