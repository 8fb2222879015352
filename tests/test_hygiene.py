"""Committed notebooks carry no outputs or execution counts and declare a kernelspec."""
import json

import pytest

from robocourse.site.build import ALL_DIRS, discover
from robocourse.site.hygiene import notebook_problems, strip_file
from tests.conftest import ROOT

NOTEBOOKS = discover(ROOT, ALL_DIRS)


def test_there_are_notebooks():
    assert NOTEBOOKS, "expected notebooks under lessons/, solutions/, assignments/"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_committed_notebook_is_clean(path):
    assert notebook_problems(path) == []


def _copy(tmp_path):
    src = json.loads(NOTEBOOKS[0].read_text())
    return src, tmp_path / "nb.ipynb"


def test_checker_catches_outputs(tmp_path):
    nb, dst = _copy(tmp_path)
    cell = next(c for c in nb["cells"] if c["cell_type"] == "code")
    cell["outputs"] = [{"output_type": "stream", "name": "stdout", "text": "hi\n"}]
    cell["execution_count"] = 3
    dst.write_text(json.dumps(nb))
    problems = notebook_problems(dst)
    assert any("has outputs" in p for p in problems) and any("execution count" in p for p in problems)
    assert strip_file(dst) and notebook_problems(dst) == []


def test_checker_catches_missing_kernelspec(tmp_path):
    nb, dst = _copy(tmp_path)
    del nb["metadata"]["kernelspec"]
    dst.write_text(json.dumps(nb))
    assert any("kernelspec" in p for p in notebook_problems(dst))


def test_checker_catches_non_json(tmp_path):
    dst = tmp_path / "bad.ipynb"
    dst.write_text("{not json")
    assert "not a readable JSON notebook" in notebook_problems(dst)[0]
