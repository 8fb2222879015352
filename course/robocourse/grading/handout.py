"""``robocourse student-kit``: the students' handout, without the solutions: one zip.

The handout holds the lessons, the blank assignments, the robokit library and the course package
(``check()``, the assignments' data, the lessons' experiments), with the files that install them
(``pyproject.toml``, ``course/pyproject.toml``, ``environment.yml``, the ``Makefile`` for
``make lab``) and a README that is the repository README's student guide. It leaves out
``solutions/`` (reference code and model answers), the tests, benchmarks, design notes and the
sites' sources. An assignment that differs from what ``robocourse assign`` generates, or a
notebook with outputs, stops the handout: students get what the course checks.
"""
from __future__ import annotations

import re
import zipfile
from pathlib import Path

from robokit.files import write_atomically

__all__ = ["HANDOUT_PATHS", "handout_files", "write_handout"]

#: What the handout copies from the course root (folders whole, minus caches and build leftovers).
HANDOUT_PATHS = ("lessons", "assignments", "robokit", "course/robocourse", "course/pyproject.toml", "pyproject.toml",
             "environment.yml", "Makefile")
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


def handout_files(root: str | Path) -> dict[str, Path]:
    """The files of the handout: path inside the handout (POSIX) to the file it copies.

    Raises
    ------
    FileNotFoundError
        If ``root`` lacks one of :data:`HANDOUT_PATHS` or its README.md.
    """
    root = Path(root)
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
            files["/".join(parts)] = f
    if not (root / "README.md").is_file():
        raise FileNotFoundError(f"root: {root} has no README.md")
    return files


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
    FileNotFoundError
        If ``root`` is not a course repository.

    Notes
    -----
    Course tooling (README, "Instructor guide"); not from a paper.
    """
    from robocourse.grading.assign import write_assignment
    from robocourse.lessons import assignments
    from robocourse.site.hygiene import notebook_problems

    root, output = Path(root).resolve(), Path(output).resolve()
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
    readme = _student_readme((root / "README.md").read_text(encoding="utf-8"))

    def write(path: Path) -> None:
        with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
            for rel, f in sorted(files.items()):
                z.write(f, f"{TOP}/{rel}")
            z.writestr(f"{TOP}/README.md", readme)

    output.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(output, write)
    return output, len(files) + 1
