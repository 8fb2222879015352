"""The course site: the executed notebooks rendered as a book with Sphinx, myst-nb and
sphinx-book-theme, twice from one build.

* ``build/course/``, the **student site**: a home page, the lessons (executed), the blank
  assignments, a reference of the robokit library generated from its numpydoc docstrings, and the
  papers behind each lesson. It never contains solution code (``tests/test_course_site.py``).
* ``build/instructor/``, the **instructor site**: the same, plus every solution (executed), the
  grading self-check with each worker's full log, and the build report (status and time of every
  notebook). It must stay private.

The committed sources of both live in ``book/`` (``conf.py``, the two home pages, the references,
the style sheet); :func:`write_sources` copies them next to the notebooks and generates the tables of
contents and the library reference, and :func:`sphinx_build` renders the result. Nothing is
executed here: myst-nb runs with ``nb_execution_mode = "off"``.
"""
from __future__ import annotations

import ast
import dataclasses
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Mapping, Sequence

from .slim import slim_site

__all__ = ["SITES", "API_MODULES", "SITE_TOOLS", "BookPage", "is_import_cell", "prepare_notebook",
           "write_sources", "sphinx_build", "SiteBuild", "site_tool_problems", "site_out_problem",
           "replace_site"]

#: The two sites of one build: name -> whether it is the instructor's.
SITES = {"course": False, "instructor": True}

#: Modules whose public functions the library reference documents, in the order of the house
#: (DESIGN.md), then the two course functions a student calls in a notebook.
API_MODULES = ("robokit.geometry", "robokit.vision", "robokit.sim", "robokit.mapping",
               "robokit.localization", "robokit.controllers", "robokit.legged", "robokit.outdoor",
               "robokit.arm", "robokit.navigation", "robokit.viz", "robocourse.grading.check",
               "robocourse.grading.data")
#: Of a course module, only these members are documented.
_COURSE_MEMBERS = {"robocourse.grading.check": "check", "robocourse.grading.data": "assignment_data"}

#: myst-nb's cell tag that folds a cell's code behind a "show code" button.
HIDE_INPUT = "hide-input"


@dataclasses.dataclass
class BookPage:
    """A generated Markdown page: ``name`` (path under the site without suffix), its ``text``, and
    ``files`` copied next to it (the page links them with MyST's ``{download}`` role)."""

    name: str
    text: str
    files: tuple[Path, ...] = ()


@dataclasses.dataclass
class SiteBuild:
    """Outcome of one :func:`sphinx_build`: ``ok``, ``seconds``, the ``warnings`` Sphinx printed
    and the site's ``index`` page."""

    ok: bool
    seconds: float
    warnings: str
    index: Path


def is_import_cell(source: str) -> bool:
    """Return whether a code cell only imports (every statement an ``import``; comments allowed).

    Such cells are folded on the site (they open every lesson and say little); they stay one
    click away.

    Examples
    --------
    >>> is_import_cell("import numpy as np\\n# the library\\nfrom robokit import sim")
    True
    >>> is_import_cell("import numpy as np\\nprint(np.pi)")
    False
    >>> is_import_cell("%matplotlib inline")
    False
    """
    if not isinstance(source, str):
        raise TypeError(f"source: expected a cell's source text, got {type(source).__name__}")
    try:
        body = ast.parse(source).body
    except SyntaxError:
        return False
    return bool(body) and all(isinstance(node, (ast.Import, ast.ImportFrom)) for node in body)


def _is_title(cell: dict) -> bool:
    """Whether a notebook cell is Markdown opening with a level-1 heading (the page's title)."""
    return cell.get("cell_type") == "markdown" and "".join(cell.get("source", "")).lstrip().startswith("# ")


def prepare_notebook(src: Path, dst: Path, *, title: tuple[str, str] | None = None,
                     note: str = "") -> Path:
    """Copy the notebook ``src`` to ``dst`` for the site, folding the cells that only import.

    Parameters
    ----------
    src, dst : Path
        The notebook (executed or not) and where its site copy goes.
    title : (str, str), optional
        Replace the first occurrence of ``title[0]`` in the first heading by ``title[1]`` (the
        instructor site calls a solution notebook "Solution 01", not "Assignment 01").
    note : str, optional
        A warning shown under the title (used when the notebook failed to run in this build).

    Returns
    -------
    Path
        ``dst``.
    """
    src, dst = Path(src), Path(dst)
    if title is not None and (not isinstance(title, tuple) or len(title) != 2
                              or not all(isinstance(t, str) and t for t in title)):
        raise TypeError(f"title: expected a pair of non-empty strings (old, new), got {title!r}")
    if not isinstance(note, str):
        raise TypeError(f"note: expected a string, got {type(note).__name__}")
    if not src.is_file():
        raise FileNotFoundError(f"src: expected a notebook file, got {str(src)!r}")
    nb = json.loads(src.read_text(encoding="utf-8"))
    renamed = title is None
    cells = nb.setdefault("cells", [])
    if not any(_is_title(c) for c in cells):    # every page needs a title for the sidebar and the browser tab
        cells.insert(0, {"cell_type": "markdown", "metadata": {}, "source": f"# {src.stem}"})
    if note:
        first = next((i for i, c in enumerate(cells) if c.get("cell_type") == "markdown"), -1)
        cells.insert(first + 1, {"cell_type": "markdown", "metadata": {},
                                 "source": f"```{{warning}}\n{note}\n```\n"})
    for cell in cells:
        text = "".join(cell.get("source", ""))
        if cell.get("cell_type") == "code" and is_import_cell(text):
            tags = cell.setdefault("metadata", {}).setdefault("tags", [])
            if HIDE_INPUT not in tags:
                tags.append(HIDE_INPUT)
        if not renamed and _is_title(cell):
            cell["source"] = text.replace(title[0], title[1], 1)
            renamed = True
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_text(json.dumps(nb, ensure_ascii=False), encoding="utf-8")
    return dst


def _toctree(caption: str, entries: Sequence[str]) -> str:
    lines = "\n".join(entries)
    return f"\n```{{toctree}}\n:caption: {caption}\n:maxdepth: 1\n\n{lines}\n```\n"


def _api_pages(modules: Sequence[str]) -> list[BookPage]:
    if not modules:
        return []
    pages = []
    for module in modules:
        options = f":members: {_COURSE_MEMBERS[module]}\n" if module in _COURSE_MEMBERS else ":members:\n:imported-members:\n"
        pages.append(BookPage(f"api/{module.removeprefix('robokit.').removeprefix('robocourse.')}",
                              f"# `{module}`\n\n```{{eval-rst}}\n.. automodule:: {module}\n"
                              + "".join(f"   {line}\n" for line in options.splitlines()) + "```\n"))
    entries = [p.name.removeprefix("api/") for p in pages]
    index = ("# Library reference\n\nThe public functions of `robokit` that the lessons use, grouped by "
             "subpackage in the order they build on each other, then the two functions of the course "
             "(`robocourse`) an assignment calls. Each docstring names the paper and equation it "
             "implements.\n" + _toctree("Subpackages", entries))
    return [BookPage("api/index", index)] + pages


def write_sources(src: Path, book: Path, *, lessons: Sequence[Path], assignments: Sequence[Path],
                  solutions: Sequence[Path] = (), pages: Sequence[BookPage] = (),
                  instructor: bool = False, api_modules: Sequence[str] = API_MODULES,
                  notes: Mapping[Path, str] | None = None) -> Path:
    """Write a Sphinx source tree for one site into ``src`` and return its ``index.md``.

    Parameters
    ----------
    src : Path
        Source directory (emptied first).
    book : Path
        The committed ``book/`` folder: ``conf.py``, ``home.md``, ``instructor_home.md``,
        ``references.md``, ``_static/``.
    lessons, assignments, solutions : sequences of Path
        Notebooks in site order (lessons and solutions as executed, assignments blank). The student
        site must get no solutions.
    pages : sequence of BookPage
        Extra pages of the instructor site (grading self-check, build report).
    instructor : bool, default False
        Build the instructor site (its home page, solutions and extra pages).
    api_modules : sequence of str, default API_MODULES
        Modules of the library reference; empty for a quicker site without it.
    notes : mapping, optional
        Notebook path -> a warning shown under its title (:func:`prepare_notebook`'s ``note``).

    Returns
    -------
    Path
        The site's ``index.md`` (home page plus the generated tables of contents).

    Raises
    ------
    ValueError
        If the student site is given solutions or instructor pages.
    FileNotFoundError
        If ``book`` has no ``conf.py``, or a notebook is missing.
    TypeError
        If ``api_modules`` is not a sequence of ``robokit.*`` or ``robocourse.*`` names.
    """
    src, book = Path(src), Path(book)
    if isinstance(api_modules, str) or not all(isinstance(m, str) and m.startswith(("robokit.", "robocourse."))
                                               for m in api_modules):
        raise TypeError(f"api_modules: expected a sequence of robokit or robocourse module names, got {api_modules!r}")
    if not (book / "conf.py").is_file():
        raise FileNotFoundError(f"book: expected the site sources (conf.py) in {str(book)!r}")
    if not instructor and (solutions or pages):
        raise ValueError("solutions: the student site must not contain solutions or instructor pages")
    if src.exists():
        shutil.rmtree(src)
    shutil.copytree(book, src, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    home = (book / ("instructor_home.md" if instructor else "home.md")).read_text(encoding="utf-8")
    parts = []
    for caption, folder, notebooks, title in (("Lessons", "lessons", lessons, None),
                                              ("Assignments", "assignments", assignments, None),
                                              ("Solutions", "solutions", solutions, ("Assignment", "Solution"))):
        for path in notebooks:
            prepare_notebook(path, src / folder / Path(path).name, title=title, note=(notes or {}).get(path, ""))
        if notebooks:
            parts.append(_toctree(caption, [f"{folder}/{Path(p).stem}" for p in notebooks]))
    api = _api_pages(api_modules)
    for page in list(pages) + api:
        target = src / f"{page.name}.md"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(page.text, encoding="utf-8")
        for file in page.files:
            shutil.copy(file, target.parent / Path(file).name)
    if pages:
        parts.append(_toctree("Instructor", [p.name for p in pages]))
    parts.append(_toctree("Reference", ["api/index"] * bool(api) + ["references"]))
    index = src / "index.md"
    index.write_text(home.rstrip() + "\n" + "".join(parts), encoding="utf-8")
    return index


#: Python modules the site build needs (the ``lab`` extra), by import name.
SITE_TOOLS = ("sphinx", "myst_nb", "sphinx_book_theme", "sphinx-mathjax-offline")


def site_tool_problems(book: Path) -> list[str]:
    """Return what is missing to build the sites (empty when all is there): a site tool that is not
    installed, or ``book/conf.py``. Checked before any notebook runs, so a build never fails after
    minutes of work for want of a package."""
    import importlib.util

    problems = [f"the course site needs {name!r}: pip install -e './course[lab]'"
                for name in SITE_TOOLS if importlib.util.find_spec(name) is None]
    if not (Path(book) / "conf.py").is_file():
        problems.append(f"book: expected the site's sources (conf.py) in {str(book)!r}; copy book/ from the "
                        "robokit course repository")
    return problems


def site_out_problem(out: Path, work: Path) -> str:
    """Why ``out`` cannot receive a site (empty string if it can): it must lie outside the build's
    private ``work`` folder, and be missing, an empty folder, or an earlier Sphinx site (it holds
    Sphinx's ``.buildinfo``), so that replacing it never deletes anything else."""
    out, work = Path(out).resolve(), Path(work).resolve()
    if work.is_relative_to(out) or out.is_relative_to(work):
        return f"out: expected a folder apart from the build's work folder {str(work)!r}, got {str(out)!r}"
    if out.exists() and (not out.is_dir() or (any(out.iterdir()) and not (out / ".buildinfo").is_file())):
        return (f"out: expected a new or empty folder or an earlier site (with .buildinfo); {str(out)!r} "
                "holds other files, so it is left alone")
    return ""


def replace_site(built: Path, out: Path) -> Path:
    """Move the freshly built site ``built`` to ``out``, replacing the site that was there.

    ``out`` is deleted only if it is empty or is itself a Sphinx site (it holds Sphinx's
    ``.buildinfo``): a mistyped ``--out`` (the repository, ``docs/``) raises instead of being wiped.

    Raises
    ------
    ValueError
        If :func:`site_out_problem` finds one (``out`` holds other files, or overlaps ``built``).
    """
    built, out = Path(built).resolve(), Path(out).resolve()
    problem = site_out_problem(out, built)
    if problem:
        raise ValueError(problem)
    if out.exists():
        shutil.rmtree(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    shutil.move(str(built), str(out))
    return out


def sphinx_build(src: Path, out: Path, *, instructor: bool = False, timeout: float = 600) -> SiteBuild:
    """Render the source tree ``src`` (from :func:`write_sources`) and publish the HTML site at ``out``.

    Sphinx runs in its own process (``python -m sphinx``), from scratch (``-E``), into a private
    folder beside ``src`` (``html/``; myst-nb's ``jupyter_execute/`` and the doctrees go there too),
    and only a finished site, slimmed (:func:`~robocourse.site.slim.slim_site`: one copy of the 3D
    viewer, notebooks without outputs to download, the MathJax parts the pages load), replaces
    ``out`` (:func:`replace_site`), so a site never keeps a page
    the build no longer writes and a failed build leaves the previous site in place. Warnings are
    returned, not fatal: a docstring Sphinx cannot format must not hide the course.

    Parameters
    ----------
    src : Path
        The site's sources; its parent is the site's private work folder.
    out : Path
        Where the site goes.
    instructor : bool, default False
        Passed to ``conf.py`` (``ROBOKIT_SITE``) for the site's title.
    timeout : float, default 600
        Wall-clock limit in seconds for Sphinx.

    Returns
    -------
    SiteBuild
        ``ok`` is false if Sphinx failed, timed out or wrote no ``index.html``; ``warnings`` then
        ends with Sphinx's error output.
    """
    src, out = Path(src), Path(out)
    if not isinstance(timeout, (int, float)) or not timeout > 0:
        raise ValueError(f"timeout: expected a positive number of seconds, got {timeout!r}")
    work = src.parent
    html_dir, doctrees, warnings = work / "html", work / "doctrees", work / "sphinx-warnings.txt"
    for stale in (html_dir, doctrees, work / "jupyter_execute"):
        if stale.exists():
            shutil.rmtree(stale)
    warnings.unlink(missing_ok=True)
    env = dict(os.environ, ROBOKIT_SITE="instructor" if instructor else "student", PYTHONHASHSEED="0")
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-E", "-q", "-d", str(doctrees),
           "-w", str(warnings), str(src), str(html_dir)]
    start = time.perf_counter()
    try:
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
        ok, log = proc.returncode == 0 and (html_dir / "index.html").is_file(), proc.stderr
    except subprocess.TimeoutExpired:
        ok, log = False, f"sphinx-build stopped after the time limit of {timeout:.0f} s"
    text = warnings.read_text(encoding="utf-8") if warnings.exists() else ""
    if ok:
        try:
            slim_site(html_dir)
        except (OSError, ValueError, UnicodeDecodeError) as exc:    # published whole, with a warning
            text = (text + f"\nrobocourse: the site was not slimmed ({type(exc).__name__}: {exc})").strip()
        replace_site(html_dir, out)
    else:
        text = (text + "\n" + log).strip()
    return SiteBuild(ok, time.perf_counter() - start, text, out / "index.html")
