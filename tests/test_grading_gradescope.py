"""The Gradescope autograder zip: its run_autograder script, run against a simulated /autograder."""
import json
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from robocourse.grading.gradescope import build_autograder
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def autograder(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gs")
    zpath = build_autograder("00_getting_started", "gs-secret", tmp / "autograder.zip", root=ROOT)
    return tmp, zpath


def _simulate(tmp: Path, zpath: Path, submission: Path | None) -> dict:
    base = tmp / "autograder"
    shutil.rmtree(base, ignore_errors=True)
    (base / "source").mkdir(parents=True)
    (base / "submission").mkdir()
    with zipfile.ZipFile(zpath) as z:
        z.extractall(base / "source")
    if submission is not None:
        shutil.copy(submission, base / "submission" / "my_work.ipynb")
    script = (base / "source" / "run_autograder").read_text()
    script = script.replace("/autograder", str(base)).replace("/opt/robocourse/bin/robocourse",
                                                              str(Path(sys.executable).parent / "robocourse"))
    (base / "run").write_text(script)
    subprocess.run(["bash", str(base / "run")], check=True, timeout=300, cwd=tmp)
    return json.loads((base / "results" / "results.json").read_text())


def test_zip_contents(autograder):
    _, zpath = autograder
    with zipfile.ZipFile(zpath) as z:
        names = set(z.namelist())
        assert {"setup.sh", "run_autograder", "seed.txt"} <= names
        assert any(n.startswith("robokit-") and n.endswith(".whl") for n in names)
        assert any(n.startswith("robocourse-") and n.endswith(".whl") for n in names)
        assert z.read("seed.txt") == b"gs-secret"
        assert (z.getinfo("run_autograder").external_attr >> 16) & 0o111
    for name in ("setup.sh", "run_autograder"):
        text = zipfile.ZipFile(zpath).read(name).decode()
        assert subprocess.run(["bash", "-n"], input=text, text=True).returncode == 0


def test_run_autograder_grades_solution_and_blank(autograder):
    tmp, zpath = autograder
    full = _simulate(tmp, zpath, ROOT / "solutions" / "00_getting_started.ipynb")
    assert full["score"] == 3 and len(full["tests"]) == 2
    blank = _simulate(tmp, zpath, ROOT / "assignments" / "00_getting_started.ipynb")
    assert blank["score"] == 0


def test_run_autograder_without_notebook(autograder):
    tmp, zpath = autograder
    assert _simulate(tmp, zpath, None)["score"] == 0


def test_bad_requests():
    with pytest.raises(ValueError, match="seed"):
        build_autograder("00_getting_started", "", "/tmp/never.zip", root=ROOT)
    with pytest.raises(ValueError, match="unknown assignment"):
        build_autograder("99_nope", "s", "/tmp/never.zip", root=ROOT)
