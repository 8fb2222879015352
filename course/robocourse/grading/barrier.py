"""The grading worker's import barrier: what graded code may import of the course, and nothing of robokit.

The worker runs from a *kit* (:mod:`.kit` writes it for one assignment): a directory holding a
``robocourse`` package with only the worker's own modules, an empty stand-in ``__init__`` for each
package above them, the assignment's data file and a manifest (:class:`Manifest`, ``kit.json``).
No robokit module and no lesson's exercises are in it, so no library function can be loaded,
reloaded, found by the garbage collector or unwrapped from a trap: the trusted grader computes
every expected answer.

:func:`seal` runs in the worker before any student code. It gives the ``robocourse`` package the
two names a notebook imports from it, ``check`` (silenced: it only prints that it is skipped) and
``assignment_data`` (the kit's data file), keeps an old notebook's ``from robokit.grading import
check`` working, takes the worker's own modules out of ``sys.modules`` (the worker keeps its
references), and puts an import finder first on ``sys.meta_path`` that refuses every other
``robokit`` or ``robocourse`` name with :class:`RobokitWithheld`, the kit's modules included: graded
code may import exactly what the refusal message says. Each refusal is logged, so the grader flags
the submission ``imported-robokit``.

The barrier makes the rule visible; it is not what keeps the library out of reach. Graded code can
remove a ``sys.meta_path`` entry. When grading as root, the worker's filesystem
(:mod:`.filesystem_view`) holds no robokit and no other robocourse source than the kit; without
root (``sandbox=limited``) the installed packages stay readable on disk, as the README says.
"""
from __future__ import annotations

import dataclasses
import importlib.abc
import importlib.machinery
import json
import sys
import types
from pathlib import Path
from typing import Callable

from robocourse.grading.data import assignment_data

__all__ = ["Manifest", "MANIFEST", "RobokitWithheld", "seal", "quiet_check"]

#: The manifest's file name, at the top of a kit (next to its ``robocourse`` package).
MANIFEST = "kit.json"
#: Where old notebooks import ``check`` from (kept working while grading).
OLD_CHECK = "robokit.grading"
_PACKAGES = ("robokit", "robocourse")


class RobokitWithheld(ModuleNotFoundError):
    """Raised in the worker when graded code imports robokit, or a part of robocourse the kit does
    not hold: an assignment is solved with numpy, and the worker has no library."""


@dataclasses.dataclass(frozen=True)
class Manifest:
    """What a kit holds.

    Attributes
    ----------
    modules : tuple of str
        Modules copied verbatim into the kit (the worker's own).
    stand_ins : tuple of str
        Packages present only as an empty ``__init__``.
    data : str
        The assignment whose data file the kit carries (``""`` if it has none).
    """

    modules: tuple[str, ...]
    stand_ins: tuple[str, ...]
    data: str = ""

    def write(self, kit_root: Path) -> None:
        """Write ``kit.json`` into ``kit_root``."""
        (Path(kit_root) / MANIFEST).write_text(json.dumps(dataclasses.asdict(self), indent=1, sort_keys=True))

    @classmethod
    def read(cls, kit_root: Path) -> Manifest:
        """Read ``kit.json`` from ``kit_root``."""
        raw = json.loads((Path(kit_root) / MANIFEST).read_text())
        return cls(tuple(raw["modules"]), tuple(raw["stand_ins"]), str(raw["data"]))


def quiet_check(*args, **kwargs) -> None:
    """``check()`` while grading: public cases are feedback only, so it just says it is skipped."""
    print("(check() is skipped during official grading)")


def _is_ours(name: str) -> bool:
    return name.split(".")[0] in _PACKAGES


class _Served(importlib.abc.Loader):
    """Loads a stand-in module the barrier made (the old name of ``check``), never a file."""

    def __init__(self, module: types.ModuleType):
        self.module = module

    def create_module(self, spec):
        return self.module

    def exec_module(self, module):
        pass


class _Barrier(importlib.abc.MetaPathFinder):
    """First on ``sys.meta_path``: lets the names of ``allowed`` through (``robocourse``, the kit's
    stand-in package), serves the stand-ins itself (so a submission that drops them from
    ``sys.modules`` gets them back, never the files), and refuses every other name of ours."""

    def __init__(self, allowed: set[str], served: dict[str, types.ModuleType],
                 refuse: Callable[[str], BaseException]):
        self.allowed, self.served, self.refuse = allowed, served, refuse

    def find_spec(self, name, path=None, target=None):
        if name in self.served:
            return importlib.machinery.ModuleSpec(name, _Served(self.served[name]), is_package=True)
        if not _is_ours(name) or name in self.allowed:
            return None
        raise self.refuse(name)


def _refusal(log: Callable[[str], None]) -> Callable[[str], BaseException]:
    def refuse(name: str) -> BaseException:
        log(name)
        # no ``name=``: ``from package import x`` would then turn this into a bare "cannot import name"
        return RobokitWithheld(f"{name} is not available while grading: an assignment is solved with numpy "
                               "and the standard library, and the notebook may import only check and "
                               "assignment_data from robocourse")

    return refuse


def _stand_in(name: str, doc: str, refuse: Callable[[str], BaseException], **attributes) -> types.ModuleType:
    """A package ``name`` registered in ``sys.modules`` and on its parent, holding ``attributes``;
    any other attribute is refused (and logged) like an import of it."""
    module = types.ModuleType(name, doc)
    module.__path__ = []            # a package, so that a submodule import reaches the barrier
    vars(module).update(attributes)

    def __getattr__(attr: str):
        if attr.startswith("_"):   # probes by Python and tools (__file__, _repr_html_) find nothing
            raise AttributeError(attr)
        raise refuse(f"{name}.{attr}")

    module.__getattr__ = __getattr__
    sys.modules[name] = module
    parent, _, child = name.rpartition(".")
    if parent:
        setattr(sys.modules[parent], child, module)
    return module


def seal(manifest: Manifest, log: Callable[[str], None]) -> None:
    """Limit what graded code can import of ours to the kit, before any student code runs.

    ``log(name)`` records an attempt on anything else (the worker appends it to the flags log).

    Raises
    ------
    RuntimeError
        If a module of ours outside the kit is already loaded (the worker must not start then).
    """
    kit = {*manifest.modules, *manifest.stand_ins}
    leaked = sorted(m for m in sys.modules if _is_ours(m) and m not in kit)
    if leaked:
        raise RuntimeError(f"modules outside the grading kit are loaded: {leaked}")

    def data(slug: str) -> dict:
        if slug != manifest.data:
            raise ValueError(f"slug: expected this assignment's data ({manifest.data or 'none'}), got {slug!r}")
        return assignment_data(slug)

    top = sys.modules["robocourse"]                       # the kit's stand-in
    top.__dict__.update(check=quiet_check, assignment_data=data)
    for name in sorted(kit - {"robocourse"}, reverse=True):
        # the worker holds what it needs; graded code finds only what the refusal message names
        sys.modules.pop(name, None)
        parent, _, child = name.rpartition(".")
        if parent == "robocourse":
            top.__dict__.pop(child, None)
    refuse = _refusal(log)
    served = {"robokit": _stand_in("robokit", "robokit while grading: only the old name of check()", refuse)}
    served[OLD_CHECK] = _stand_in(OLD_CHECK, "check() while grading: skipped", refuse, check=quiet_check)
    sys.meta_path.insert(0, _Barrier({"robocourse"}, served, refuse))
