"""Documentation the lessons rely on: runnable examples and full citations.

* Every robokit function or class that a lesson or solution notebook uses has an ``Examples``
  section with at least one ``>>>`` line (they run as doctests under ``make test``, see
  ``pyproject.toml``).
* Every module of a topic subpackage that cites a source in its docstrings has a ``References``
  section in its module docstring giving the full citation.
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
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("robokit"):
                for a in node.names:
                    full = f"{node.module}.{a.name}"
                    aliases[a.asname or a.name] = full
                    used.add(full)
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.startswith("robokit"):
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
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and obj.__module__.startswith("robokit"):
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
    return out


@pytest.mark.parametrize("module", _topic_modules())
def test_modules_that_cite_sources_give_full_references(module):
    path = ROOT / Path(*module.split(".")).with_suffix(".py")
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = [ast.get_docstring(n) or "" for n in ast.walk(tree)
            if isinstance(n, (ast.Module, ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef))]
    if not any(_CITATION.search(d) for d in docs):
        pytest.skip("cites no source")
    module_doc = ast.get_docstring(tree) or ""
    assert re.search(r"^References\n-{10}\n", module_doc, re.M), (
        f"{module} cites sources: its module docstring needs a numpydoc 'References' section with the "
        "full citations (authors, title, venue, year)")
