"""Lesson 00's environment check names every package the course imports, with the lessons that need it."""
from __future__ import annotations

import ast
import json
import re
import sys
from importlib import metadata

import pytest

from robocourse import environment
from robocourse.environment import OPTIONAL, PACKAGES, check_environment, environment_table
from tests.conftest import ROOT

_STD = set(sys.stdlib_module_names) | {"__future__"}


def _third_party(source: str) -> set[str]:
    code = "\n".join("" if line.lstrip().startswith(("%", "!")) else line for line in source.splitlines())
    found = set()
    for node in ast.walk(ast.parse(code)):
        if isinstance(node, ast.Import):
            found |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            found.add(node.module.split(".")[0])
        elif (isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", "")) == "lazy_module"
              and node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
            found.add(node.args[0].value.split(".")[0])          # robokit.config.lazy_module("control")
    return found - _STD - {"robokit", "robocourse"}


def _notebook_code(path) -> str:
    return "\n".join("".join(c["source"]) for c in json.loads(path.read_text())["cells"] if c["cell_type"] == "code")


def _lesson_number(path) -> int:
    return int(path.name[:2])


def test_every_package_the_library_and_the_notebooks_import_is_checked():
    sources = {p: p.read_text() for p in ROOT.glob("robokit/**/*.py")}
    # the course package as a student's kernel uses it (the site and grading tools are instructor-side)
    sources |= {p: p.read_text() for p in ROOT.glob("course/robocourse/**/*.py") if "site" not in p.parts}
    sources |= {p: _notebook_code(p) for folder in ("lessons", "solutions", "assignments")
                for p in (ROOT / folder).glob("*.ipynb")}
    imported = {}
    for path, text in sources.items():
        for module in _third_party(text):
            imported.setdefault(module, path.relative_to(ROOT))
    checked = {p.module for p in PACKAGES + OPTIONAL}
    missing = {m: str(where) for m, where in imported.items() if m not in checked}
    assert not missing, f"imported but not in robocourse.environment.PACKAGES or OPTIONAL: {missing}"
    assert {"mujoco", "numba", "ipywidgets", "IPython", "tqdm"} <= checked


@pytest.mark.parametrize("package", [p for p in PACKAGES + OPTIONAL if p.used_by.startswith("robokit.")],
                         ids=lambda p: p.distribution)
def test_the_named_robokit_user_imports_the_package(package):
    base = ROOT / package.used_by.replace(".", "/")
    files = list(base.glob("**/*.py")) if base.is_dir() else [base.with_suffix(".py")]
    assert any(package.module in _third_party(f.read_text()) for f in files), package


@pytest.mark.parametrize("package", [p for p in PACKAGES if p.lessons[:1].isdigit()], ids=lambda p: p.distribution)
def test_the_lessons_named_are_the_ones_that_import_its_user(package):
    first, _, last = package.lessons.partition("-")
    named = set(range(int(first), int(last or first) + 1))
    pattern = re.compile(rf"\b{re.escape(package.used_by)}\b|from robokit import [^\n]*\b{package.used_by.split('.')[-1]}\b")
    users = {_lesson_number(p) for p in (ROOT / "lessons").glob("*.ipynb") if pattern.search(_notebook_code(p))}
    assert users == named, (package, sorted(users))


def test_every_package_is_reported_with_its_version():
    rows = check_environment()
    assert [r["package"] for r in rows] == [p.distribution for p in PACKAGES]
    for r in rows:
        assert r["status"] == "ok" and r["version"] == metadata.version(r["package"]), r
    table = environment_table(rows).splitlines()
    assert len(table) == len(PACKAGES) + 1 and "mujoco" in table[10] and table[10].endswith("ok")


def test_a_missing_or_broken_package_is_named(monkeypatch):
    broken = environment.Package("numpy", "robokit_no_such_module", "04", "robokit.legged")
    missing = environment.Package("robokit-no-such-distribution", "x", "06", "robokit.arm")
    monkeypatch.setattr(environment, "PACKAGES", (broken, missing))
    rows = check_environment()
    assert rows[0]["status"].startswith("broken: ModuleNotFoundError") and rows[0]["lessons"] == "04"
    assert rows[1]["status"] == "missing" and rows[1]["version"] == "missing"


@pytest.mark.parametrize("bad", ["rows", [{"package": "numpy"}], None,
                                 [{"package": "numpy", "version": None, "status": "ok", "lessons": "all", "used_by": "x"}]])
def test_the_table_refuses_what_is_not_a_report(bad):
    with pytest.raises(TypeError, match="rows"):
        environment_table(bad)
