"""The import order of docs/DESIGN.md, enforced on the source with ``ast`` (nothing is imported).

Two packages: ``robokit``, the library, and ``robocourse``, the course built on it. robokit never
imports robocourse; robocourse may import any of robokit.

* Layers: within each package a unit (a subpackage or a top-level module) may import only units of
  a lower layer, or itself. Lazy imports inside functions and ``importlib.import_module("...")``
  calls with a literal name count like any other import.
* No cycles between modules, lazy imports included.
* No private names across modules: ``from .x import _name``, ``thing._name`` and
  ``getattr(thing, "_name")`` (where ``thing`` is not ``self`` or ``cls`` and the file does not define
  ``_name`` itself at module or class level or on ``self``) are reach-ins; make the name public or
  give the other module a public way to do what it needs. No text anywhere in the repository
  names another module's private function either (a dotted name of ours ending in ``._name``).

A new subpackage must be placed in ``PACKAGES`` (and in DESIGN.md's picture), or this test fails.
"""
from __future__ import annotations

import ast
import functools
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Each package's folder and its layers, bottom to top: a unit may import from units of earlier
#: rows (and from itself).
PACKAGES: dict[str, tuple[Path, list[set[str]]]] = {
    "robokit": (ROOT / "robokit", [
        {"validation", "config"},                       # base: input checks, settings
        {"files"},                                      # bounded readers and atomic writers
        {"cache"},                                      # the dataset cache (its files through files)
        {"progress"},                                   # the one progress bar (reads fast/headless from config)
        {"parallel"},                                   # independent runs in worker processes
        {"geometry"},                                   # SE(2)/SE(3)/SO(3), the papers' frames
        {"vision"},                                     # detectors, descriptors, matching
        {"sim"},                                        # worlds, sensors, motion (its view check uses vision)
        {"mapping"},                                    # grids, landmark maps, topological maps
        {"localization", "controllers"},                # pose estimation / control loops
        {"legged", "outdoor", "arm", "navigation"},     # the system lessons; closed-loop navigation
        {"viz"},                                        # meshcat scenes and figures
    ]),
    "robocourse": (ROOT / "course" / "robocourse", [
        {"config", "source", "environment"},            # fast mode; the code an experiment or the worker runs;
                                                        # the installation check of lesson 00
        {"site"},                                       # notebook execution, hygiene, the two sites, browser checks
        {"exercises"},                                  # the vocabulary: Case, Exercise, comparisons, plain data
        {"lessons"},                                    # each lesson's experiments and exercises; their discovery
        {"grading"},                                    # check(), assignments, the sandboxed grader
        {"cli"},                                        # the ``robocourse`` command
    ]),
}
#: Attribute names that look private but belong to the standard library's public API.
STDLIB_PRIVATE = {"_getframe", "_exit", "_asdict", "_replace", "_fields", "_make", "_field_defaults"}


def _layer_of() -> dict[str, int]:
    """(package, unit) -> its layer's row."""
    return {(pkg, unit): i for pkg, (_, rows) in PACKAGES.items() for i, row in enumerate(rows) for unit in row}


def _modules() -> dict[str, Path]:
    out = {}
    for folder, _ in PACKAGES.values():
        for path in sorted(folder.rglob("*.py")):
            parts = path.relative_to(folder.parent).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            out[name] = path
    return out


MODULES = _modules()


def _unit(module: str) -> tuple[str, str]:
    """(package, unit): the unit is the subpackage or top-level module, ``__init__`` for the package."""
    parts = module.split(".")
    return parts[0], parts[1] if len(parts) > 1 else "__init__"


def _resolve(module: str, path: Path, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    base = package.split(".")
    base = base[: len(base) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def _existing(name: str) -> str:
    """The longest prefix of a dotted name that is a robokit module."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name


def _imports(module: str, path: Path) -> list[tuple[str, int, list[str]]]:
    """(imported robokit module, line, names taken from it) for every import in the file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            target = _resolve(module, path, node)
            if target.split(".")[0] not in PACKAGES:
                continue
            for alias in node.names:  # `from robokit.x import y` may import the module robokit.x.y
                sub = f"{target}.{alias.name}"
                if sub in MODULES:
                    found.append((sub, node.lineno, []))
                else:
                    found.append((_existing(target), node.lineno, [alias.name]))
        elif isinstance(node, ast.Import):
            found += [(_existing(a.name), node.lineno, []) for a in node.names if a.name.split(".")[0] in PACKAGES]
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr == "import_module" and node.args
              and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)
              and node.args[0].value.split(".")[0] in PACKAGES):
            found.append((_existing(node.args[0].value), node.lineno, []))
    return [f for f in found if f[0]]


@functools.cache
def _graph() -> dict:
    """Every module's imports (parsed on first use, not at collection by every test worker)."""
    return {m: _imports(m, p) for m, p in MODULES.items()}


def test_every_unit_has_a_layer():
    layer = _layer_of()
    units = {_unit(m) for m in MODULES if _unit(m)[1] != "__init__"}
    missing = sorted(units - set(layer))
    assert not missing, f"place these units in PACKAGES (tests/test_layers.py) and DESIGN.md: {missing}"


def test_the_library_never_imports_the_course():
    bad = [f"{MODULES[m].relative_to(ROOT)}:{line}: imports {t}" for m, imps in _graph().items() if m.startswith("robokit")
           for t, line, _ in imps if t.startswith("robocourse")]
    assert not bad, "robokit must not depend on the course:\n" + "\n".join(bad)


def test_no_upward_imports():
    layer = _layer_of()
    bad = []
    for module, imports in _graph().items():
        src = _unit(module)
        for target, line, _ in imports:
            dst = _unit(target)
            if dst[0] != src[0] or src[1] == "__init__" or dst[1] == "__init__" or src == dst:
                continue     # across packages: the test above; a package's __init__ re-exports
            if layer[dst] >= layer[src]:
                bad.append(f"{MODULES[module].relative_to(ROOT)}:{line}: {src[1]} imports {target} "
                           f"({dst[1]} is not below {src[1]})")
    assert not bad, "imports that run up or sideways:\n" + "\n".join(sorted(set(bad)))


def test_package_roots_stay_light():
    for package, (_, rows) in PACKAGES.items():
        bad = [t for t, _, _ in _graph()[package] if t.startswith(package + ".") and _unit(t)[1] not in rows[0]
               and t.split(".")[1] != "grading"]
        assert not bad, f"{package}/__init__.py must import only its base layer ({package}.grading lazily): {bad}"


def test_no_import_cycles():
    graph = {m: sorted({t for t, _, _ in imps if t != m}) for m, imps in _graph().items()}
    # a package's __init__ importing its own submodules is how packages are built, not a cycle
    for m in graph:
        graph[m] = [t for t in graph[m] if not t.startswith(m + ".")]
    state: dict[str, int] = {}
    stack: list[str] = []
    cycles: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for t in graph.get(m, []):
            if state.get(t) == 1:
                cycles.append(" -> ".join(stack[stack.index(t):] + [t]))
            elif t not in state:
                visit(t)
        stack.pop()
        state[m] = 2

    for m in graph:
        if m not in state:
            visit(m)
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def _defined_private(tree: ast.Module) -> set[str]:
    """Private names this file defines for itself: module- and class-level functions, classes and
    assignments, and attributes it sets (``self._x = ...``, a marker like ``socket._x = True``, or
    ``object.__setattr__(self, "_x", ...)``); arguments and local variables do not count."""
    names = set()
    scopes = [tree.body] + [n.body for n in ast.walk(tree) if isinstance(n, ast.ClassDef)]
    for body in scopes:
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                names.update(n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name))
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "__setattr__"
              and len(node.args) >= 2 and isinstance(node.args[1], ast.Constant)):
            names.add(str(node.args[1].value))
    return {n for n in names if n.startswith("_")}


def _getattr_names(tree: ast.Module):
    """(line, name) of ``getattr(x, "_name")`` / ``setattr`` / ``hasattr`` with a literal private name."""
    for node in ast.walk(tree):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id in ("getattr", "setattr", "hasattr") and len(node.args) >= 2
                and isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str)):
            yield node.lineno, node.args[1].value


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_private_names_across_modules(module):
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    own = _defined_private(tree)
    bad = []
    for target, line, names in _graph()[module]:
        bad += [f"line {line}: imports {n} from {target}" for n in names
                if n.startswith("_") and not n.startswith("__")]
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")
                and node.attr not in own and node.attr not in STDLIB_PRIVATE
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
            bad.append(f"line {node.lineno}: uses {ast.unparse(node)}")
    bad += [f"line {line}: uses the attribute {name!r} by name" for line, name in _getattr_names(tree)
            if name.startswith("_") and not name.startswith("__") and name not in own and name not in STDLIB_PRIVATE]
    assert not bad, f"{path.relative_to(ROOT)} reaches into other modules' private names:\n" + "\n".join(bad)


#: A dotted name of ours that ends in a private name (a module path, a dot, an underscore, a name).
PRIVATE_NAME = re.compile(r"\b(robokit|robocourse)(\.[A-Za-z][A-Za-z0-9_]*)*\._[A-Za-z][A-Za-z0-9_]*")
TEXT_SUFFIXES = {".py", ".ipynb", ".md", ".toml", ".yml", ".txt", ".cfg", ".json"}


def _text_files():
    for path in sorted(ROOT.rglob("*")):
        parts = path.relative_to(ROOT).parts
        if path.suffix in TEXT_SUFFIXES and path.is_file() and parts[0] not in (".git", ".venv", "build") \
                and "__pycache__" not in parts and not any(p.endswith(".egg-info") for p in parts):
            yield path


def test_no_text_names_a_private_function():
    bad = [f"{path.relative_to(ROOT)}: {match.group(0)}" for path in _text_files()
           for match in PRIVATE_NAME.finditer(path.read_text(encoding="utf-8", errors="replace"))]
    assert not bad, "names of private functions in the repository's text:\n" + "\n".join(bad[:40])


def _private_uses(tree: ast.Module) -> list[str]:
    """Private names of ours a file outside the packages takes: ``from robokit.x import _y`` or
    ``m._y`` where ``m`` is a module of ours it imported."""
    ours = lambda name: (name or "").split(".")[0] in PACKAGES
    modules, bad = set(), []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and ours(node.module):
            for a in node.names:
                if a.name.startswith("_") and not a.name.startswith("__"):
                    bad.append(f"line {node.lineno}: imports {a.name} from {node.module}")
                elif f"{node.module}.{a.name}" in MODULES:
                    modules.add(a.asname or a.name)
        elif isinstance(node, ast.Import):
            modules.update(a.asname for a in node.names if ours(a.name) and a.asname)
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in modules
                and node.attr.startswith("_") and not node.attr.startswith("__")):
            bad.append(f"line {node.lineno}: uses {node.value.id}.{node.attr}")
    return bad


def test_tests_and_benchmarks_use_no_private_names_of_ours():
    bad = [f"{path.relative_to(ROOT)}: {b}" for folder in ("tests", "benchmarks") for path in sorted((ROOT / folder).glob("*.py"))
           for b in _private_uses(ast.parse(path.read_text(encoding="utf-8")))]
    assert not bad, "make these public (or test them through a public function):\n" + "\n".join(bad)


def test_the_private_name_checks_can_fail():
    assert PRIVATE_NAME.search("see robokit.vision.colour" + "._made_up")
    assert _private_uses(ast.parse("from robokit.vision.colour import _made_up\nfrom robokit.arm import jit\njit._x"))
