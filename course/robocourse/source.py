"""The robokit and robocourse modules a module runs, found by reading imports with :mod:`ast`.

Two users: the cache key of a lesson's experiment (:func:`code_version_of`: a dataset is rebuilt
when any code it uses changes, and only then) and the grading worker's kit (:mod:`.grading.kit`: the
worker's own modules, which must reach no robokit). Nothing is imported to find them; lazy imports
inside functions and ``importlib.import_module("...")`` calls with a literal name count.
"""
from __future__ import annotations

import ast
import functools
import hashlib
import importlib.util
from pathlib import Path
from typing import Iterable

__all__ = ["PACKAGES", "module_file", "imports_of", "closure", "digest_of", "code_version_of"]

#: The top-level packages whose modules are followed.
PACKAGES = ("robokit", "robocourse")


@functools.lru_cache(maxsize=None)
def _package_dir(top: str) -> Path:
    spec = importlib.util.find_spec(top)
    if spec is None or not spec.submodule_search_locations:
        raise ModuleNotFoundError(f"{top} is not installed")
    return Path(list(spec.submodule_search_locations)[0])


def module_file(name: str) -> Path | None:
    """The source file of a module of :data:`PACKAGES` from its dotted name, or ``None``."""
    top, *rest = name.split(".")
    if top not in PACKAGES:
        return None
    path = _package_dir(top).joinpath(*rest)
    for candidate in (path / "__init__.py", path.with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


def _absolute(module: str, path: Path, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    parts = package.split(".")
    anchor = ".".join(parts[: len(parts) - node.level + 1])
    return f"{anchor}.{node.module}" if node.module else anchor


def _home(package: str, name: str, depth: int = 0) -> str:
    """The module that defines ``name`` imported from ``package``: the submodule an ``__init__``
    re-exports it from (followed through re-exporting subpackages), else the package itself."""
    path = module_file(package)
    if path is None or path.name != "__init__.py" or depth > 10:
        return package
    for node in _tree(path, path.stat().st_mtime_ns).body:
        if isinstance(node, ast.ImportFrom) and any((a.asname or a.name) == name for a in node.names):
            source = _absolute(package, path, node)
            original = next(a.name for a in node.names if (a.asname or a.name) == name)
            if module_file(f"{source}.{original}") is not None:
                return f"{source}.{original}"
            return _home(source, original, depth + 1) if source.split(".")[0] in PACKAGES else package
    return package


@functools.lru_cache(maxsize=None)
def _tree(path: Path, mtime_ns: int) -> ast.Module:
    """A source file's syntax tree, parsed once per version of the file."""
    return ast.parse(path.read_text(encoding="utf-8"), str(path))


def imports_of(module: str, *, homes: bool = False) -> set[str]:
    """The modules of :data:`PACKAGES` that ``module``'s source imports (parents not included).

    With ``homes``, a name taken from a package (``from robokit.sim import Lidar``) counts as the
    module that defines it (``robokit.sim.lidar``), not as the package, whose ``__init__`` imports
    every module of it. ``import a.b.c`` binds ``a`` and lets the code reach anything through the
    packages on the way, so it counts as every one of them.
    """
    path = module_file(module)
    if path is None:
        raise ModuleNotFoundError(f"{module} has no source file")
    found: set[str] = set()
    # what the file itself says is walked once per version of it; which module defines a name is
    # looked up every time, since other files (a package's __init__, a new module) decide that
    for kind, base, name in _import_statements(module, path, path.stat().st_mtime_ns):
        if kind == "import":
            parts = base.split(".")
            found.update(".".join(parts[:i]) for i in range(1, len(parts) + 1))
        elif kind == "from":                       # `from pkg import mod` imports the module pkg.mod
            sub = f"{base}.{name}"
            if module_file(sub) is not None:
                found.add(sub)
            else:
                found.add(_home(base, name) if homes else base)
        else:
            found.add(base)
    return {m for m in found if m.split(".")[0] in PACKAGES}


@functools.lru_cache(maxsize=None)
def _import_statements(module: str, path: Path, mtime_ns: int) -> tuple[tuple[str, str, str], ...]:
    """The import statements of one version of a file, as ``(kind, module, name)``: ``("import", "a.b", "")``,
    ``("from", absolute base, imported name)`` and ``("dynamic", "a.b", "")`` for ``import_module("a.b")``
    (a lesson's cached experiments ask for the same modules' imports many times in one process)."""
    found = []
    for node in ast.walk(_tree(path, mtime_ns)):
        if isinstance(node, ast.Import):
            found.extend(("import", alias.name, "") for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(module, path, node)
            found.extend(("from", base, alias.name) for alias in node.names)
        elif (isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", "")) == "import_module"
              and node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
            found.append(("dynamic", node.args[0].value, ""))
    return tuple(found)


def _parents(module: str) -> list[str]:
    parts = module.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def closure(roots: Iterable[str], *, parents: bool = True, homes: bool = False) -> dict[str, str]:
    """Every module that runs when ``roots`` are imported -> the module that brought it in.

    A module's parent packages run first, so their ``__init__`` modules are followed too, unless
    ``parents`` is False (the grading kit replaces them by empty stand-ins). With ``homes`` (and
    without ``parents``), only the modules whose code the roots use: a name imported from a package
    leads to the module that defines it (:func:`imports_of`).

    Raises
    ------
    ModuleNotFoundError
        If a module imports one of :data:`PACKAGES`' modules that has no source file.
    """
    via: dict[str, str] = {}
    todo = [(root, root) for root in roots]
    while todo:
        module, importer = todo.pop()
        if module in via:
            continue
        if module_file(module) is None:
            raise ModuleNotFoundError(f"{importer} imports {module}, which has no source file")
        via[module] = importer
        todo.extend((dep, module) for dep in sorted(imports_of(module, homes=homes) | set(_parents(module) if parents else ())))
    return via


def digest_of(modules: Iterable[str]) -> str:
    """16 hexadecimal digits of a hash of the named modules' sources (names and bytes, sorted)."""
    digest = hashlib.sha256()
    for name in sorted(set(modules)):
        digest.update(name.encode() + b"\0" + module_file(name).read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def code_version_of(module: str) -> dict:
    """What decides a lesson experiment's cached result besides its parameters: the code it runs.

    A hash of every robokit and robocourse module whose code ``module`` (an experiment's own
    ``__name__``) uses, followed through imports to the modules that define each name
    (:func:`closure` with ``homes``), and the numpy, scipy and OpenCV versions (their numerics
    changed results before). It enters the cache key and is stored in the cache file, so a
    dataset made by other code is never served, and an edit to a module the experiment does not
    use (lesson 05's outdoor worlds, for lesson 01's lab) does not rebuild it.

    Returns
    -------
    dict
        ``{"code": digest, "numpy": version, "scipy": version, "opencv": version}``.

    Notes
    -----
    Course convention (DESIGN.md, "Caching"); not from a paper.

    Examples
    --------
    >>> v = code_version_of("robocourse.lessons.visual_slam.experiment")
    >>> sorted(v), len(v["code"])
    (['code', 'numpy', 'opencv', 'scipy'], 16)
    """
    import cv2
    import numpy as np
    import scipy

    return {"code": digest_of(closure([module], parents=False, homes=True)), "numpy": np.__version__,
            "scipy": scipy.__version__,
            "opencv": cv2.__version__}
