"""The lab experiment's cache key covers every module whose code decides its result, and no more."""
import ast
import importlib
from pathlib import Path

import robokit
from robokit.cache import code_version
from robokit.localization.lab_experiment import EXPERIMENT_MODULES

ROOT = Path(robokit.__file__).resolve().parent


def _is_module(dotted: str) -> bool:
    path = ROOT.parent.joinpath(*dotted.split("."))
    return path.with_suffix(".py").is_file() or path.is_dir()


def _homes(package: str, name: str) -> set[str]:
    """The robokit modules that ``from package import name`` really depends on: the module that
    defines a function or class, a submodule itself, or the modules that assign a constant (a
    package's ``__init__`` only re-exports, so it is followed to the defining module)."""
    if _is_module(f"{package}.{name}"):
        return {f"{package}.{name}"}
    obj = getattr(importlib.import_module(package), name)
    home = getattr(obj, "__module__", None) or ""
    if callable(obj) and home.startswith("robokit."):
        return {home}
    module = importlib.import_module(package)
    if not hasattr(module, "__path__"):
        return {package}
    found = set()
    for source in Path(module.__path__[0]).glob("*.py"):
        for node in ast.parse(source.read_text()).body:
            targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
            if source.stem != "__init__" and any(isinstance(t, ast.Name) and t.id == name for t in targets):
                found.add(f"{package}.{source.stem}")
    return found or {package}


def _closure(start: str) -> set[str]:
    """Every robokit module reached from ``start`` through its imports, names followed to their homes."""
    seen, todo = set(), [start]
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        path = Path(importlib.import_module(name).__file__)
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")[:len(package.split(".")) - node.level + 1] if node.level else []
                source = ".".join(base + ([node.module] if node.module else []))
                if source.startswith("robokit"):
                    for alias in node.names:
                        todo.extend(_homes(source, alias.name))
            elif isinstance(node, ast.Import):
                todo.extend(a.name for a in node.names if a.name.startswith("robokit."))
    return {name.removeprefix("robokit.") for name in seen}


def test_the_cache_key_lists_every_module_the_experiment_reaches():
    reached = _closure("robokit.localization.lab_experiment")
    assert "sim.worlds" in reached and "vision.stereo" in reached          # the walk does follow imports
    assert reached <= set(EXPERIMENT_MODULES), sorted(reached - set(EXPERIMENT_MODULES))


def test_an_unrelated_module_does_not_enter_the_key():
    assert "sim.worlds_outdoor" not in EXPERIMENT_MODULES and "sim" not in EXPERIMENT_MODULES
    assert code_version(*EXPERIMENT_MODULES) != code_version(*EXPERIMENT_MODULES, "sim.worlds_outdoor")
