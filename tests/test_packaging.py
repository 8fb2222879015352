"""The two packages' pyproject files and environment.yml list the same dependencies; the library
needs none of the course's; no sys.path hacks."""
import re
import tomllib
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
# PyPI name -> conda-forge name where they differ.
CONDA_NAME = {"meshcat": "meshcat-python"}


def _name(req: str) -> str:
    return re.split(r"[<>=!~;\[ ]", req.strip(), maxsplit=1)[0].lower().replace("_", "-")


#: Each package's pyproject and the extras `make venv` installs with it.
PACKAGES = {"pyproject.toml": ("legged", "arm", "dev"), "course/pyproject.toml": ("lab",)}
#: What only the course needs: the library must not depend on any of it.
COURSE_ONLY = {"nbformat", "nbclient", "nbconvert", "ipython", "ipykernel", "jupyterlab", "sphinx", "myst-nb",
               "sphinx-book-theme", "sphinx-mathjax-offline"}


def _project(path):
    return tomllib.loads((ROOT / path).read_text())["project"]


def _pyproject_names():
    reqs = []
    for path, extras in PACKAGES.items():
        project = _project(path)
        reqs += project["dependencies"]
        for extra in extras:
            reqs += project["optional-dependencies"][extra]
    return {CONDA_NAME.get(_name(r), _name(r)) for r in reqs} - {"robokit"}


def _environment_names():
    env = yaml.safe_load((ROOT / "environment.yml").read_text())
    names, pip = set(), []
    for dep in env["dependencies"]:
        if isinstance(dep, dict):
            pip += dep.get("pip", [])
        elif _name(dep) not in {"python", "pip"}:
            names.add(_name(dep))
    editable = [p for p in pip if p.startswith("-e")]
    names |= {_name(p) for p in pip if not p.startswith("-e")}
    return names, editable


def test_environment_mirrors_pyproject():
    env_names, editable = _environment_names()
    py_names = _pyproject_names()
    assert env_names == py_names, (f"only in pyproject: {sorted(py_names - env_names)}; "
                                   f"only in environment.yml: {sorted(env_names - py_names)}")
    assert editable == ["-e .", "-e ./course"], "environment.yml must install both packages in editable mode via pip"


def test_the_library_needs_nothing_of_the_course():
    project = _project("pyproject.toml")
    runtime = project["dependencies"] + [r for e in ("legged", "arm") for r in project["optional-dependencies"][e]]
    assert not {_name(r) for r in runtime} & COURSE_ONLY
    assert "scripts" not in project


def test_console_script_declared():
    assert _project("course/pyproject.toml")["scripts"]["robocourse"] == "robocourse.cli:main"


def test_no_sys_path_hacks():
    offenders = []
    for folder in ("robokit", "course", "tests", "benchmarks"):
        for path in (ROOT / folder).rglob("*.py"):
            text = path.read_text(encoding="utf-8")
            if re.search(r"sys\.path\.(insert|append)|sys\.path\s*\+?=", text):
                offenders.append(str(path.relative_to(ROOT)))
    for path in ROOT.glob("*/*.ipynb"):
        if "sys.path" in path.read_text(encoding="utf-8"):
            offenders.append(str(path.relative_to(ROOT)))
    assert not offenders, f"sys.path manipulation in {offenders}"


def test_importing_the_library_loads_none_of_the_course_tools():
    import subprocess
    import sys

    subpackages = sorted(p.name for p in (ROOT / "robokit").iterdir() if (p / "__init__.py").is_file())
    code = ("import sys\n" + "".join(f"import robokit.{s}\n" for s in subpackages) +
            "heavy = sorted(m for m in sys.modules if m.split('.')[0] in "
            "('IPython', 'nbformat', 'nbclient', 'sphinx', 'robocourse'))\nprint(heavy)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert len(subpackages) >= 11 and out.stdout.strip() == "[]", out.stdout
