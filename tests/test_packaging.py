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
PACKAGES = {"pyproject.toml": ("legged", "arm", "cholmod", "dev"), "course/pyproject.toml": ("lab",)}
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


def _pins(text: str) -> dict:
    pins = {}
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            assert re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*==[0-9][A-Za-z0-9.+!-]*", line), \
                f"constraints.txt: expected name==version, got {line!r}"
            name, version = line.split("==")
            assert _name(name) not in pins, f"constraints.txt: {name} pinned twice"
            pins[_name(name)] = version
    return pins


def test_every_dependency_is_pinned_and_environment_yml_pins_the_same_versions():
    # a build in March prints what the site printed in January (issue: OpenCV 5.0 -> 5.1 on the index)
    pins = _pins((ROOT / "constraints.txt").read_text())
    pypi = {v: k for k, v in CONDA_NAME.items()}
    assert not {"pip", "setuptools", "robokit", "robocourse"} & set(pins)
    unpinned = sorted(n for n in _pyproject_names() if pypi.get(n, n) not in pins)
    assert not unpinned, f"constraints.txt pins none of {unpinned}"
    env = yaml.safe_load((ROOT / "environment.yml").read_text())
    entries = [d for d in env["dependencies"] if isinstance(d, str)]
    entries += [p for d in env["dependencies"] if isinstance(d, dict) for p in d.get("pip", []) if not p.startswith("-e")]
    differ = []
    for entry in entries:
        name = _name(entry)
        if name in {"python", "pip"}:
            continue
        version = entry.partition("==")[2].split()[0] if "==" in entry else None
        pinned = pins.get(pypi.get(name, name), "nothing")
        if version != pinned:
            differ.append(f"{name}: environment.yml {version or entry!r}, constraints.txt {pinned}")
    assert not differ, "environment.yml must pin what constraints.txt pins: " + "; ".join(differ)
    from packaging.requirements import Requirement
    outside = []
    for project in PACKAGES:                       # each pin lies in the range its pyproject asks for
        for req in _project(project)["dependencies"] + [r for extra in _project(project)["optional-dependencies"].values()
                                                        for r in extra]:
            req = Requirement(req)
            name = _name(req.name)
            if name in pins and not req.specifier.contains(pins[name], prereleases=True):
                outside.append(f"{name}: pinned {pins[name]}, {project} asks {req.specifier}")
    assert not outside, outside


def test_make_installs_with_the_constraints():
    makefile = (ROOT / "Makefile").read_text()
    installs = [line for line in makefile.splitlines() if "pip install" in line and "-e '." in line]
    everyday = [line for line in installs if "$(VENV)-upgrade" not in line]      # make upgrade resolves afresh
    assert everyday and len(installs) == len(everyday) + 1
    assert all("-c constraints.txt" in line for line in everyday)
    from robocourse.grading.handout import HANDOUT_PATHS, STUDENT_MAKEFILE
    assert "-c constraints.txt" in STUDENT_MAKEFILE and "constraints.txt" in HANDOUT_PATHS


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
