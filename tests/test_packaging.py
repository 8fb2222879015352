"""pyproject.toml and environment.yml must list the same dependencies; no sys.path hacks."""
import re
import tomllib
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
# PyPI name -> conda-forge name where they differ.
CONDA_NAME = {"meshcat": "meshcat-python"}


def _name(req: str) -> str:
    return re.split(r"[<>=!~;\[ ]", req.strip(), maxsplit=1)[0].lower().replace("_", "-")


def _pyproject_names():
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    reqs = list(data["project"]["dependencies"])
    for extra in ("lab", "dev"):
        reqs += data["project"]["optional-dependencies"][extra]
    return {CONDA_NAME.get(_name(r), _name(r)) for r in reqs}


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
    assert editable == ["-e ."], "environment.yml must install robokit in editable mode via pip"


def test_console_script_declared():
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert data["project"]["scripts"]["robokit"] == "robokit.cli:main"


def test_no_sys_path_hacks():
    offenders = []
    for folder in ("robokit", "tests", "benchmarks"):
        for path in (ROOT / folder).rglob("*.py"):
            text = path.read_text(encoding="utf-8")
            if re.search(r"sys\.path\.(insert|append)|sys\.path\s*\+?=", text):
                offenders.append(str(path.relative_to(ROOT)))
    for path in ROOT.glob("*/*.ipynb"):
        if "sys.path" in path.read_text(encoding="utf-8"):
            offenders.append(str(path.relative_to(ROOT)))
    assert not offenders, f"sys.path manipulation in {offenders}"
