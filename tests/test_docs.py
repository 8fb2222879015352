"""Documentation the lessons rely on: the packages' maps, runnable examples and full citations.

* Each package's ``__init__`` docstring is its map (docs/DESIGN.md): one line per module or
  subpackage, ``name  what it holds``, and exactly the ones that exist.
* Every robokit or robocourse function or class that a lesson or solution notebook uses has an
  ``Examples`` section with at least one ``>>>`` line (they run as doctests under ``make test``,
  see ``pyproject.toml``).
* Every module of a topic subpackage or a lesson that cites a source in its docstrings has a
  ``References`` section in its module docstring giving the full citation.
* Every dotted ``robokit.`` or ``robocourse.`` name written in a notebook, a docstring, the README
  or docs/ names something that exists (a renamed function leaves no stale name behind).
"""
from __future__ import annotations

import ast
import importlib
import inspect
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TOPICS = ("geometry", "sim", "vision", "mapping", "localization", "controllers", "legged", "outdoor", "arm",
          "navigation")
_CITATION = re.compile(r"et al\.|\b(19|20)\d\d\b")


def _code(path: Path) -> str:
    nb = json.loads(path.read_text(encoding="utf-8"))
    return "\n".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code")


def _trees(source: str):
    """Syntax trees of the source; a cell with IPython magics is parsed without its magic lines."""
    try:
        yield ast.parse(source)
    except SyntaxError:
        yield ast.parse("\n".join(l for l in source.splitlines() if not l.lstrip().startswith(("%", "!"))))


def _names_used(source: str) -> set[str]:
    """Dotted robokit names a notebook's code uses (``robokit.sim.lab_room``, ...)."""
    aliases: dict[str, str] = {}
    used: set[str] = set()
    for tree in _trees(source):
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(("robokit", "robocourse")):
                for a in node.names:
                    full = f"{node.module}.{a.name}"
                    aliases[a.asname or a.name] = full
                    used.add(full)
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.startswith(("robokit", "robocourse")):
                        aliases[a.asname or a.name.split(".")[0]] = a.asname and a.name or a.name.split(".")[0]
    for alias, full in aliases.items():
        for m in re.finditer(rf"(?<![\w.]){re.escape(alias)}((?:\.\w+)+)", source):
            parts = m.group(1).split(".")[1:]
            used.update(full + "." + ".".join(parts[:k]) for k in range(1, len(parts) + 1))
    return used


def _resolve(dotted: str):
    """The object a dotted name means in code: ``from a.b import c`` takes the attribute ``c`` of
    ``a.b`` before a submodule of that name, as Python does."""
    parts = dotted.split(".")
    for i in range(len(parts) - 1, 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for p in parts[i:]:
            obj = getattr(obj, p, None)
            if obj is None:
                return None
        return obj
    return None


def _lesson_api() -> dict[str, object]:
    found = {}
    for nb in sorted((ROOT / "lessons").glob("*.ipynb")) + sorted((ROOT / "solutions").glob("*.ipynb")):
        for name in _names_used(_code(nb)):
            obj = _resolve(name)
            obj = inspect.unwrap(obj) if callable(obj) else obj   # e.g. functools.lru_cache
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and obj.__module__.startswith(("robokit", "robocourse")):
                found[f"{obj.__module__}.{obj.__qualname__}"] = obj
    return found


LESSON_API = _lesson_api()


def test_the_lessons_use_the_library():
    assert len(LESSON_API) > 40, sorted(LESSON_API)


@pytest.mark.parametrize("name", sorted(LESSON_API))
def test_lesson_api_has_runnable_examples(name):
    doc = inspect.getdoc(LESSON_API[name]) or ""
    section = re.search(r"^Examples\n-{8}\n(.*?)(?=^\w[\w ]*\n-{3,}\n|\Z)", doc, re.S | re.M)
    assert section and ">>>" in section.group(1), (
        f"{name} is used by a lesson: give its docstring an 'Examples' section with a doctest")


def _topic_modules() -> list[str]:
    out = []
    for topic in TOPICS:
        base = ROOT / "robokit" / topic
        for path in sorted(base.glob("*.py")) if base.is_dir() else []:
            if path.name != "__init__.py":
                out.append(f"robokit.{topic}.{path.stem}")
    for path in sorted((ROOT / "course" / "robocourse" / "lessons").glob("*/*.py")):
        if path.name != "__init__.py":
            out.append(f"robocourse.lessons.{path.parent.name}.{path.stem}")
    return out


@pytest.mark.parametrize("module", _topic_modules())
def test_modules_that_cite_sources_give_full_references(module):
    top = ROOT / "course" if module.startswith("robocourse") else ROOT
    path = top / Path(*module.split(".")).with_suffix(".py")
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = [ast.get_docstring(n) or "" for n in ast.walk(tree)
            if isinstance(n, (ast.Module, ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef))]
    if not any(_CITATION.search(d) for d in docs):
        pytest.skip("cites no source")
    module_doc = ast.get_docstring(tree) or ""
    assert re.search(r"^References\n-{10}\n", module_doc, re.M), (
        f"{module} cites sources: its module docstring needs a numpydoc 'References' section with the "
        "full citations (authors, title, venue, year)")


PACKAGE_DIRS = sorted(p.parent for top in (ROOT / "robokit", ROOT / "course" / "robocourse")
                      for p in top.rglob("__init__.py"))
#: A line of a package's map: a module or subpackage name at the start of the line, two spaces,
#: what it holds (continuation lines are indented).
MAP_LINE = re.compile(r"^([a-z_][a-z0-9_]*) {2,}\S", re.M)


@pytest.mark.parametrize("package", PACKAGE_DIRS, ids=lambda p: str(p.relative_to(ROOT)))
def test_each_package_docstring_maps_exactly_its_modules(package):
    children = {p.stem for p in package.glob("*.py") if p.name != "__init__.py"}
    children |= {d.name for d in package.iterdir() if (d / "__init__.py").is_file()}
    doc = ast.get_docstring(ast.parse((package / "__init__.py").read_text(encoding="utf-8"))) or ""
    listed = MAP_LINE.findall(doc)
    assert len(listed) == len(set(listed)), f"{package.name}: a module is listed twice: {listed}"
    assert set(listed) == children, (f"{package.relative_to(ROOT)}/__init__.py: its map misses "
                                     f"{sorted(children - set(listed))} and names {sorted(set(listed) - children)}")


def test_the_map_test_reads_a_map():
    doc = "Summary.\n\nplanar  SE(2)\nrotations   SO(3),\n            continued\nNot a line.\n"
    assert MAP_LINE.findall(doc) == ["planar", "rotations"]


_DOTTED = re.compile(r"(?<![\w.])((?:robokit|robocourse)(?:\.[A-Za-z_]\w*)+)")
#: Dotted names that are not Python names on purpose: a notebook metadata key, and the module an
#: old submission imports ``check`` from (the grader maps it to ``robocourse.check``).
_NOT_PYTHON = {"robokit.cold_seconds": "metadata.robokit.cold_seconds, a notebook metadata key",
               "robokit.grading": "the old home of check(), still accepted in submissions (barrier.py)"}


def _resolves(name: str) -> bool:
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        try:
            for part in parts[i:]:
                obj = getattr(obj, part)
        except AttributeError:
            return False
        return True
    return False


def _written_names() -> dict[str, set[str]]:
    texts = {}
    for folder in ("lessons", "solutions", "assignments"):
        for nb in sorted((ROOT / folder).glob("*.ipynb")):
            cells = json.loads(nb.read_text(encoding="utf-8"))["cells"]
            texts[f"{folder}/{nb.name}"] = "\n".join("".join(c["source"]) for c in cells)
    for path in [*ROOT.glob("robokit/**/*.py"), *ROOT.glob("course/robocourse/**/*.py"), *ROOT.glob("docs/*.md"),
                 *ROOT.glob("book/**/*.md"), ROOT / "README.md", ROOT / "course" / "README.md"]:
        texts[str(path.relative_to(ROOT))] = path.read_text(encoding="utf-8")
    names: dict[str, set[str]] = {}
    for where, text in texts.items():
        for name in _DOTTED.findall(text):
            names.setdefault(name, set()).add(where)
    return names


def test_every_dotted_library_name_in_the_text_exists():
    names = _written_names()
    assert len(names) > 200, len(names)                     # the scan reads what it should
    stale = {name: sorted(where)[:3] for name, where in names.items()
             if name not in _NOT_PYTHON and not _resolves(name)}
    assert not stale, f"names that do not resolve (renamed or removed?): {stale}"


def test_the_name_check_catches_a_stale_name():
    assert _resolves("robokit.viz.fit_view") and _resolves("robocourse.check")
    assert not _resolves("robokit.viz.frame") and not _resolves("robokit.no_such_module.f")
