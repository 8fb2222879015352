"""``robocourse student-kit``: the students' handout, without the solutions: one zip.

The handout holds the lessons, the blank assignments, the robokit library and the course package
(``check()``, the assignments' data, the lessons' experiments), with the files that install them
(``pyproject.toml``, ``course/pyproject.toml``) and three written for students: a README that is the
repository README's student guide, an ``environment.yml`` without the developers' extra and a
``Makefile`` whose ``make lab`` installs what the lessons need and opens JupyterLab. It leaves out
``solutions/`` (the solution notebooks and the model answers to written questions), the tests,
benchmarks, design notes and the sites' sources. In a git checkout only tracked files are packed.
An assignment that differs from what ``robocourse assign`` generates, or a notebook with outputs,
stops the handout: students get what the course checks.

The course package carries the exercises' reference answers (``check()`` computes the public cases'
expected results with them); most are robokit's own functions, some are written out in
``robocourse/lessons/*/exercises.py``. Grades come from hidden cases in a worker that has neither.
"""
from __future__ import annotations

import os
import re
import subprocess
import zipfile
from pathlib import Path

from robokit.files import write_atomically

__all__ = ["HANDOUT_PATHS", "STUDENT_MAKEFILE", "handout_files", "write_handout"]

#: What the handout copies from the course root (folders whole, minus caches and build leftovers).
HANDOUT_PATHS = ("lessons", "assignments", "robokit", "course/robocourse", "course/pyproject.toml", "course/README.md",
                 "pyproject.toml", "constraints.txt")
#: The handout's own Makefile: a student's ``make lab`` (no test or developer extras).
STUDENT_MAKEFILE = """\
# robokit courseware, the students' handout. `make lab` sets up .venv on first use and opens JupyterLab.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.robokit-installed

.PHONY: lab venv

$(STAMP): pyproject.toml course/pyproject.toml constraints.txt
\t@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
\t$(BIN)/python -m pip install --quiet --upgrade pip
\t$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[legged,arm]' -e './course[lab]'
\t@touch $(STAMP)

venv: $(STAMP)

lab: $(STAMP)
\t$(BIN)/jupyter lab --notebook-dir=.
"""
_SKIP_PARTS = {"__pycache__", ".ipynb_checkpoints", ".pytest_cache"}
_SKIP_SUFFIXES = (".pyc", ".pyo", ".egg-info")
TOP = "robokit-course"


def _student_readme(readme: str) -> str:
    """The README's student guide as the handout's README (its own title and a line on what is left out)."""
    match = re.search(r"^## Student guide\n(.*?)(?=^## )", readme, re.S | re.M)
    if match is None:
        raise ValueError("README.md: expected a '## Student guide' section to copy into the handout")
    return ("# robokit courseware: the students' handout\n\n"
            "Lessons, blank assignments, the robokit library and the course package (the `check()` feedback\n"
            "and the assignments' data). The solutions, the tests and the instructor's tools are not in it.\n\n"
            "## Student guide\n" + match.group(1).rstrip() + "\n")


def _student_environment(text: str) -> str:
    """environment.yml without its blocks of the developers' extra (tests, peers, benchmarks) and of the
    opt-in GPL-3 ``cholmod`` extra (a student who wants it installs ``robokit[cholmod]``)."""
    for extra, required in (("dev", True), ("cholmod", False)):
        match = re.search(rf"^  # robokit's {extra} extra.*\n(?:  - (?!pip:).*\n)+", text, re.M)
        if match is None:
            if required:
                raise ValueError(f"environment.yml: expected a '# robokit's {extra} extra' block to leave out of the handout")
            continue
        text = text[:match.start()] + text[match.end():]
    return text


def _tracked(root: Path) -> set[str] | None:
    """The files git tracks under ``root`` (POSIX paths), or None when it is not a git checkout."""
    if not (root / ".git").exists():
        return None
    try:
        out = subprocess.run(["git", "-C", str(root), "ls-files", "-z"], capture_output=True, timeout=60, check=True)
    except (OSError, subprocess.SubprocessError):
        return None
    return set(out.stdout.decode("utf-8", "surrogateescape").split("\0")) - {""}


def handout_files(root: str | Path) -> dict[str, Path]:
    """The files of the handout: path inside the handout (POSIX) to the file it copies.

    Raises
    ------
    TypeError
        If ``root`` is not a path.
    FileNotFoundError
        If ``root`` lacks one of :data:`HANDOUT_PATHS`, its README.md or its environment.yml.
    """
    root = _as_path(root, "root")
    tracked = _tracked(root)
    files: dict[str, Path] = {}
    for rel in HANDOUT_PATHS:
        path = root / rel
        if not path.exists():
            raise FileNotFoundError(f"root: {root} has no {rel} (is it the course repository?)")
        found = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
        for f in found:
            parts = f.relative_to(root).parts
            if _SKIP_PARTS & set(parts) or any(p.endswith(_SKIP_SUFFIXES) for p in parts) or f.is_symlink():
                continue
            if tracked is not None and "/".join(parts) not in tracked:      # untracked leftovers stay home
                continue
            files["/".join(parts)] = f
    for rel in ("README.md", "environment.yml"):
        if not (root / rel).is_file():
            raise FileNotFoundError(f"root: {root} has no {rel}")
    return files


def _as_path(value: object, name: str) -> Path:
    if not isinstance(value, (str, os.PathLike)) or not str(value):
        raise TypeError(f"{name}: expected a path (str or os.PathLike), got {value!r:.60}")
    return Path(value)


def write_handout(root: str | Path, output: str | Path) -> tuple[Path, int]:
    """Write the students' handout of the course at ``root`` as the zip ``output`` (atomically).

    Parameters
    ----------
    root : str or Path
        The course repository.
    output : str or Path
        The zip to write, e.g. ``build/robokit-student.zip``; it unpacks into ``robokit-course/``.

    Returns
    -------
    (Path, int)
        The zip written and the number of files in it.

    Raises
    ------
    ValueError
        If an assignment is stale (differs from what ``robocourse assign`` generates), a notebook
        carries outputs, ``output`` does not end in ``.zip`` or lies inside a folder the handout copies.
    TypeError
        If ``root`` or ``output`` is not a path.
    FileNotFoundError
        If ``root`` is not a course repository.

    Notes
    -----
    Course tooling (README, "Instructor guide"); not from a paper.
    """
    from robocourse.grading.assign import write_assignment
    from robocourse.lessons import assignments
    from robocourse.site.hygiene import notebook_problems

    root, output = _as_path(root, "root").resolve(), _as_path(output, "output").resolve()
    if output.suffix != ".zip":
        raise ValueError(f"output: expected a path ending in .zip, got {str(output)!r}")
    if any(output.is_relative_to(root / rel) for rel in HANDOUT_PATHS):
        raise ValueError(f"output: {output} lies inside what the handout copies; write it elsewhere (e.g. build/)")
    files = handout_files(root)
    stale = [slug for slug in assignments() if (root / "solutions" / f"{slug}.ipynb").is_file()
             and write_assignment(root, slug, verify=True)]
    if stale:
        raise ValueError(f"assignments {stale} differ from what `robocourse assign` generates; run it first")
    problems = [m for rel, f in files.items() if rel.endswith(".ipynb") for m in notebook_problems(f)]
    if problems:
        raise ValueError(f"notebooks must be stripped before they are handed out: {problems[:3]}")
    written = {"README.md": _student_readme((root / "README.md").read_text(encoding="utf-8")),
               "environment.yml": _student_environment((root / "environment.yml").read_text(encoding="utf-8")),
               "Makefile": STUDENT_MAKEFILE}                  # the handout's own versions

    def write(path: Path) -> None:
        with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
            for rel, f in sorted(files.items()):
                z.write(f, f"{TOP}/{rel}")
            for rel, text in written.items():
                z.writestr(f"{TOP}/{rel}", text)

    output.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(output, write)
    return output, len(files) + len(written)
