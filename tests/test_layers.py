"""The import order of docs/DESIGN.md, enforced on the source with ``ast`` (nothing is imported).

* Layers: a unit of ``robokit`` (a subpackage or a top-level module) may import only units of a
  lower layer, or itself. Lazy imports inside functions and ``importlib.import_module("robokit...")``
  calls with a literal name count like any other import.
* No cycles between modules, lazy imports included.
* No private names across modules: ``from .x import _name``, ``thing._name`` and
  ``getattr(thing, "_name")`` (where ``thing`` is not ``self`` or ``cls`` and the file does not define
  ``_name`` itself at module or class level or on ``self``) are reach-ins; make the name public or
  give the other module a public way to do what it needs.

A new subpackage must be placed in ``LAYERS`` (and in DESIGN.md's picture), or this test fails.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "robokit"

#: Bottom to top. A unit may import from units of earlier rows (and from itself).
LAYERS: list[set[str]] = [
    {"validation", "config", "cache", "about"},     # base: input checks, settings, the dataset cache
    {"course"},                                     # notebook tooling (the CPU count from config)
    {"progress"},                                   # the one progress bar (reads fast/headless from config)
    {"parallel"},                                   # independent runs in worker processes
    {"geometry"},                                   # SE(2)/SE(3)/SO(3), the papers' frames
    {"vision"},                                     # detectors, descriptors, matching
    {"sim"},                                        # worlds, sensors, motion (its feature check uses vision)
    {"mapping"},                                    # grids, landmark maps, topological maps
    {"localization", "controllers"},                # pose estimation / control loops
    {"legged", "outdoor", "arm", "navigation"},     # the system lessons; closed-loop navigation
    {"viz"},                                        # meshcat scenes and figures
    {"exercises"},                                  # one module per assignment, and their discovery
    {"grading"},                                    # check(), assignments, the sandboxed grader
    {"cli"},                                        # the ``robokit`` command
]
#: Attribute names that look private but belong to the standard library's public API.
STDLIB_PRIVATE = {"_getframe", "_exit", "_asdict", "_replace", "_fields", "_make", "_field_defaults"}


def _layer_of() -> dict[str, int]:
    return {unit: i for i, row in enumerate(LAYERS) for unit in row}


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


MODULES = _modules()


def _unit(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


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
            if target.split(".")[0] != "robokit":
                continue
            for alias in node.names:  # `from robokit.x import y` may import the module robokit.x.y
                sub = f"{target}.{alias.name}"
                if sub in MODULES:
                    found.append((sub, node.lineno, []))
                else:
                    found.append((_existing(target), node.lineno, [alias.name]))
        elif isinstance(node, ast.Import):
            found += [(_existing(a.name), node.lineno, []) for a in node.names if a.name.startswith("robokit")]
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr == "import_module" and node.args
              and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)
              and node.args[0].value.startswith("robokit")):
            found.append((_existing(node.args[0].value), node.lineno, []))
    return [f for f in found if f[0]]


GRAPH = {m: _imports(m, p) for m, p in MODULES.items()}


def test_every_unit_has_a_layer():
    layer = _layer_of()
    units = {_unit(m) for m in MODULES} - {"__init__"}
    missing = sorted(units - set(layer))
    assert not missing, f"place these robokit units in LAYERS (tests/test_layers.py) and DESIGN.md: {missing}"


def test_no_upward_imports():
    layer = _layer_of()
    bad = []
    for module, imports in GRAPH.items():
        src = _unit(module)
        for target, line, _ in imports:
            dst = _unit(target)
            if src in ("__init__", dst) or dst == "__init__":
                continue
            if layer[dst] >= layer[src]:
                bad.append(f"{MODULES[module].relative_to(PACKAGE.parent)}:{line}: {src} imports {target} "
                           f"({dst} is not below {src})")
    assert not bad, "imports that run up or sideways:\n" + "\n".join(sorted(set(bad)))


def test_package_root_imports_only_the_base():
    allowed = LAYERS[0]
    bad = [t for t, _, _ in GRAPH["robokit"] if _unit(t) not in allowed]
    assert not bad, f"robokit/__init__.py must stay light (import robokit must not load the topics): {bad}"


def test_no_import_cycles():
    graph = {m: sorted({t for t, _, _ in imps if t != m}) for m, imps in GRAPH.items()}
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
    for target, line, names in GRAPH[module]:
        bad += [f"line {line}: imports {n} from {target}" for n in names
                if n.startswith("_") and not n.startswith("__")]
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")
                and node.attr not in own and node.attr not in STDLIB_PRIVATE
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
            bad.append(f"line {node.lineno}: uses {ast.unparse(node)}")
    bad += [f"line {line}: uses the attribute {name!r} by name" for line, name in _getattr_names(tree)
            if name.startswith("_") and not name.startswith("__") and name not in own and name not in STDLIB_PRIVATE]
    assert not bad, f"{path.relative_to(PACKAGE.parent)} reaches into other modules' private names:\n" + "\n".join(bad)
