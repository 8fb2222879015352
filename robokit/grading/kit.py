"""Write the robokit a grading worker runs with (the *kit*), for one assignment.

The kit holds the modules the worker executes (``robokit.grading.worker`` and what it imports)
and the modules behind the assignment's helpers (its ``HELPERS``, e.g. ``loop_metrics`` for 05),
found by reading their imports with :mod:`ast`; each is copied verbatim. A package whose own
``__init__`` is not needed gets an empty stand-in, because a package's ``__init__`` re-exports its
modules, references included. :func:`build_kit` refuses a kit in which a module defines or binds
one of the assignment's references (or the kernels behind them), so a helper that lives next to a
reference is caught when the course is built and tested, not by a student. The manifest it writes
is read by the worker's import barrier (:mod:`.barrier`, which describes the worker's side).
"""
from __future__ import annotations

import ast
import dataclasses
import importlib
import os
import sys
from pathlib import Path
from typing import Iterable

from ..exercises.discovery import Assignment
from .barrier import MANIFEST, Manifest

__all__ = ["Kit", "KitError", "build_kit", "WORKER"]

#: The module the sandbox runs (``python -m robokit.grading.worker``).
WORKER = "robokit.grading.worker"
_STAND_IN = '"""Stand-in while grading: the grading worker holds only the modules it needs."""\n'


class KitError(ValueError):
    """A kit would hold a reference, or a helper does not exist: a problem of the course, not of a
    submission."""


@dataclasses.dataclass(frozen=True)
class Kit:
    """A written kit: ``root`` goes first on the worker's ``sys.path``; ``manifest`` says what it holds."""

    root: Path
    manifest: Manifest

    @property
    def package(self) -> Path:
        """The kit's ``robokit`` directory (shown in place of any installed robokit, as root)."""
        return self.root / "robokit"


def _package_dir() -> Path:
    return Path(importlib.import_module("robokit").__file__).parent


def _source(module: str) -> Path:
    """The file of a robokit module, from its dotted name (nothing is imported)."""
    path = _package_dir().joinpath(*module.split(".")[1:])
    return path / "__init__.py" if path.is_dir() else path.with_suffix(".py")


def _exists(module: str) -> bool:
    return _source(module).is_file()


def _imports(module: str) -> set[str]:
    """The robokit modules that run when ``module`` runs (lazy imports in functions included)."""
    path = _source(module)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                anchor = ".".join(parts[:len(parts) - node.level + 1])
                base = f"{anchor}.{base}" if base else anchor
            for alias in node.names:
                found.add(f"{base}.{alias.name}" if _exists(f"{base}.{alias.name}") else base)
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", "")) == "import_module" \
                and node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str):
            found.add(node.args[0].value)
    return {m for m in found if m == "robokit" or m.startswith("robokit.")}


def _closure(roots: Iterable[str]) -> dict[str, str]:
    """Every module that runs when ``roots`` run -> the module that imported it (for messages)."""
    via: dict[str, str] = {}
    todo = [(root, root) for root in roots]
    while todo:
        module, importer = todo.pop()
        if module in via:
            continue
        if not _exists(module):
            raise KitError(f"{importer} imports {module}, which has no source file")
        via[module] = importer
        todo.extend((dep, module) for dep in sorted(_imports(module)))
    return via


def _parents(module: str) -> list[str]:
    parts = module.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def _resolve(dotted: str) -> object:
    module, _, attr = dotted.rpartition(".")
    try:
        return getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError):
        raise KitError(f"{dotted} does not exist") from None


def _forbidden(references: Iterable[str]) -> set[str]:
    """Modules that define or bind a reference, and every exercise module (their ``Exercise``
    objects hold references), among the robokit modules loaded in this (the grader's) process."""
    objects = [_resolve(r) for r in references]
    out = {r.rpartition(".")[0] for r in references}
    for name, module in list(sys.modules.items()):
        if not name.startswith("robokit.") or module is None:
            continue
        values = vars(module).values()
        if hasattr(module, "ASSIGNMENT") or any(v is o for v in values for o in objects):
            out.add(name)
    return out


def _helpers(assignment: Assignment) -> dict[str, str]:
    """Each helper -> the module that defines it."""
    out = {}
    for helper in assignment.helpers:
        where = getattr(_resolve(helper), "__module__", None)
        if not isinstance(where, str) or not where.startswith("robokit."):
            raise KitError(f"{assignment.slug}: HELPERS: {helper} must be a robokit function or class")
        out[helper] = where
    return out


def _copy(module: str, dest: Path, text: str | None = None) -> None:
    """Write ``module`` into the kit at ``dest`` (its source, or ``text``), readable by anyone."""
    source = _source(module)
    target = dest.joinpath(*source.relative_to(_package_dir().parent).parts)
    for d in reversed(target.relative_to(dest).parents[:-1]):
        (dest / d).mkdir(exist_ok=True)
        os.chmod(dest / d, 0o755)
    target.write_text(source.read_text() if text is None else text)
    os.chmod(target, 0o644)


def _importers(module: str, via: dict[str, str]) -> list[str]:
    """The modules through which ``module`` entered the kit, nearest first."""
    chain = []
    while via[module] != module and len(chain) < 20:
        module = via[module]
        chain.append(module)
    return chain


def build_kit(assignment: Assignment, dest: str | Path) -> Kit:
    """Write the kit of ``assignment`` into the empty or new directory ``dest``.

    Parameters
    ----------
    assignment : robokit.exercises.Assignment
        Its exercises' ``references`` and its ``helpers`` decide what the kit refuses and offers.
    dest : path
        Where to write ``robokit/...`` and the manifest.

    Returns
    -------
    Kit

    Raises
    ------
    KitError
        If a module the kit needs defines or binds one of the assignment's references (the message
        names the helper or worker module that pulled it in), or a helper does not exist.

    Examples
    --------
    >>> import tempfile
    >>> from robokit.exercises import get_assignment
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     kit = build_kit(get_assignment("05_gps_sonar_truck"), tmp)
    >>> kit.manifest.helpers
    {'robokit.outdoor.loop_metrics': 'robokit.controllers.servo_loop'}
    >>> "robokit.outdoor.navigator" in kit.manifest.modules, "robokit.outdoor" in kit.manifest.forbidden
    (False, True)
    """
    references = sorted({r for ex in assignment.exercises for r in ex.references})
    helpers = _helpers(assignment)
    via = _closure([WORKER, *sorted(set(helpers.values()))])
    forbidden = _forbidden(references)
    held = sorted(set(via) & forbidden)
    if held:
        chain = " <- ".join([held[0], *_importers(held[0], via)])
        raise KitError(f"{assignment.slug}: the grading worker would load {held[0]}, which holds a reference of "
                       f"this assignment ({chain}); move the helper to a module without references")
    stand_ins = sorted({p for m in via for p in _parents(m)} - set(via))
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    os.chmod(dest, 0o755)
    for module in sorted(via):
        _copy(module, dest)
    for package in stand_ins:
        _copy(package, dest, _STAND_IN)
    manifest = Manifest(tuple(sorted(via)), tuple(stand_ins), helpers, tuple(sorted(forbidden)), tuple(references))
    manifest.write(dest)
    os.chmod(dest / MANIFEST, 0o644)
    return Kit(dest, manifest)
