"""The grading worker's robokit: what student code may import, and the barrier around the rest.

The worker runs from a *kit* (:mod:`robokit.grading.kit` writes it for one assignment): a
directory that holds a ``robokit`` package with only the modules the worker itself executes and
the assignment's student-facing helpers, copied verbatim, an empty stand-in ``__init__`` for every
package whose own ``__init__`` is not needed (a package's ``__init__`` re-exports its references),
and a manifest (:class:`Manifest`, ``kit.json``). No reference implementation, and no kernel
behind one, is in the kit, so none can be loaded, reloaded, found by the garbage collector or
unwrapped from a trap: the trusted grader computes every expected answer.

:func:`seal` runs in the worker before any student code. It provides ``check`` (silenced: it only
prints that it is skipped), makes each helper importable under the name the notebook uses (``from
robokit.outdoor import loop_metrics``), and puts an import finder first on ``sys.meta_path`` that
refuses every other ``robokit`` name with a clear error. A name that holds one of the assignment's
references (its module, a package that re-exports it, an exercise module, or the function's name
taken from such a package) raises :class:`~.protocol.ReferenceSolutionDisabled` and is logged, so
the grader flags the submission ``called-reference``.

The barrier makes the rules visible; it is not what keeps the reference out of reach. Graded code
can remove a ``sys.meta_path`` entry. When grading as root, the worker's filesystem
(:mod:`.filesystem_view`) holds no other robokit source than the kit; without root (``sandbox=limited``)
the installed robokit stays readable on disk, as the README says.
"""
from __future__ import annotations

import dataclasses
import importlib
import importlib.abc
import json
import sys
import types
from pathlib import Path
from typing import Callable

from .protocol import ReferenceSolutionDisabled

__all__ = ["Manifest", "MANIFEST", "CHECK", "seal", "quiet_check"]

#: The manifest's file name, at the top of a kit (next to its ``robokit`` package).
MANIFEST = "kit.json"
#: The one name every notebook imports; while grading it is :func:`quiet_check`.
CHECK = "robokit.grading.check"


@dataclasses.dataclass(frozen=True)
class Manifest:
    """What a kit holds and what it must refuse.

    Attributes
    ----------
    modules : tuple of str
        Modules copied verbatim into the kit.
    stand_ins : tuple of str
        Packages present only as an empty ``__init__``.
    helpers : dict of str to str
        A helper as the notebook names it (``"robokit.outdoor.loop_metrics"``) -> the module that
        defines it (``"robokit.controllers.servo_loop"``, one of ``modules``).
    forbidden : tuple of str
        Modules that define or bind one of the assignment's references (importing one is flagged).
    references : tuple of str
        The assignment's references and the kernels behind them, as dotted names.
    """

    modules: tuple[str, ...]
    stand_ins: tuple[str, ...]
    helpers: dict[str, str]
    forbidden: tuple[str, ...]
    references: tuple[str, ...]

    def write(self, kit_root: Path) -> None:
        """Write ``kit.json`` into ``kit_root``."""
        (Path(kit_root) / MANIFEST).write_text(json.dumps(dataclasses.asdict(self), indent=1, sort_keys=True))

    @classmethod
    def read(cls, kit_root: Path) -> Manifest:
        """Read ``kit.json`` from ``kit_root``."""
        raw = json.loads((Path(kit_root) / MANIFEST).read_text())
        return cls(tuple(raw["modules"]), tuple(raw["stand_ins"]), dict(raw["helpers"]),
                   tuple(raw["forbidden"]), tuple(raw["references"]))

    def holds_reference(self, name: str) -> bool:
        """Whether the dotted ``name`` (a module, or a module and an attribute) reaches a reference.

        Examples
        --------
        >>> m = Manifest((), (), {}, ("robokit.geometry", "robokit.geometry.planar"),
        ...              ("robokit.geometry.planar.wrap_angle",))
        >>> [m.holds_reference(n) for n in ("robokit.geometry.planar", "robokit.wrap_angle", "robokit.sim")]
        [True, True, False]
        """
        if name in self.forbidden or name in self.references:
            return True
        if name != "robokit" and any(f.startswith(name + ".") for f in self.forbidden):
            return True
        package, _, attr = name.rpartition(".")
        return any(r.rpartition(".")[2] == attr and r.startswith(package + ".") for r in self.references)


def quiet_check(*args, **kwargs) -> None:
    """``check()`` while grading: public cases are feedback only, so it just says it is skipped."""
    print("(check() is skipped during official grading)")


def _is_robokit(name: str) -> bool:
    return name == "robokit" or name.startswith("robokit.")


class _Barrier(importlib.abc.MetaPathFinder):
    """First on ``sys.meta_path``: lets the kit's modules through, refuses every other robokit name."""

    def __init__(self, allowed: set[str], refuse: Callable[[str], BaseException]):
        self.allowed, self.refuse = allowed, refuse

    def find_spec(self, name, path=None, target=None):
        if not _is_robokit(name) or name in self.allowed:
            return None
        raise self.refuse(name)


def _refusal(manifest: Manifest, log: Callable[[str], None]) -> Callable[[str], BaseException]:
    """The exception for a robokit name the kit does not provide (logging references)."""
    offered = ", ".join(sorted({CHECK, *manifest.helpers}))

    def refuse(name: str) -> BaseException:
        if manifest.holds_reference(name):
            log(name)
            return ReferenceSolutionDisabled(f"{name} holds the course's reference solution, which graded code may "
                                             "not use")
        # no ``name=``: ``from package import x`` would then turn this into a bare "cannot import name"
        return ModuleNotFoundError(f"{name} is not available while grading: this assignment's notebook may import "
                                   f"only {offered} from robokit")

    return refuse


def _lazy_attributes(module_name: str, lazy: dict[str, str]):
    """A module ``__getattr__`` that loads each helper on first use. Any other name raises
    ``AttributeError``, so ``from package import name`` goes on to import ``package.name``, which
    the barrier refuses (and flags, if it names a reference)."""

    def __getattr__(attr: str):
        if attr not in lazy:
            raise AttributeError(f"module {module_name!r} has no attribute {attr!r} while grading")
        value = getattr(importlib.import_module(lazy[attr]), attr)
        setattr(sys.modules[module_name], attr, value)
        return value

    return __getattr__


def _package(name: str, kit: set[str]) -> types.ModuleType:
    """The package ``name``: loaded, from the kit, or a new empty one registered in ``sys.modules``
    and on its parent (a helper's package that the kit does not hold)."""
    if name in sys.modules or name in kit:
        return importlib.import_module(name)
    module = types.ModuleType(name, f"{name} as the grading worker provides it: only the notebook's helpers")
    module.__path__ = []  # a package, so that a submodule import reaches the barrier
    sys.modules[name] = module
    parent, _, child = name.rpartition(".")
    setattr(_package(parent, kit), child, module)
    return module


def seal(manifest: Manifest, log: Callable[[str], None]) -> None:
    """Limit the worker's robokit to the kit, before any student code runs.

    ``log(name)`` records an attempt to reach a reference (the worker appends it to the flags
    log). Provides the silenced ``check``, the helpers (loaded on first use) and the barrier; see
    the module docstring.

    Raises
    ------
    RuntimeError
        If a robokit module outside the kit is already loaded (the worker must not start then).
    """
    kit = {*manifest.modules, *manifest.stand_ins}
    leaked = sorted(m for m in sys.modules if _is_robokit(m) and m not in kit)
    if leaked:
        raise RuntimeError(f"robokit modules outside the grading kit are loaded: {leaked}")
    check = types.ModuleType(CHECK, "check() while grading: skipped")
    check.check = quiet_check
    sys.modules[CHECK] = check
    _package("robokit.grading", kit).check = quiet_check
    lazy: dict[str, dict[str, str]] = {}
    for helper, source in manifest.helpers.items():
        package, _, attr = helper.rpartition(".")
        lazy.setdefault(package, {})[attr] = source
    for package, attrs in lazy.items():
        _package(package, kit).__getattr__ = _lazy_attributes(package, attrs)
    allowed = {*kit, CHECK, *lazy}
    sys.meta_path.insert(0, _Barrier(allowed, _refusal(manifest, log)))
