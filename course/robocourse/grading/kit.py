"""Write the code a grading worker runs with (the *kit*), for one assignment.

The worker needs only its own modules (:mod:`.worker` and what it imports, found by reading their
imports with :mod:`ast`), copied verbatim, an empty stand-in ``__init__`` for each package above
them, and the assignment's data file (:mod:`.data`). It needs no robokit at all: an assignment is
solved with numpy, and the grader, not the worker, computes every expected answer. So the kit
holds no line of the library, nor any lesson's exercises, and :func:`build_kit` refuses to write
one that would (a course error, found when the course is built and tested, not by a student). The
manifest it writes is read by the worker's import barrier (:mod:`.barrier`).
"""
from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from robocourse.grading.barrier import MANIFEST, Manifest
from robocourse.grading.data import data_file
from robocourse.lessons import Assignment
from robocourse.source import closure, module_file

__all__ = ["Kit", "KitError", "build_kit", "WORKER"]

#: The module the sandbox runs (``python -m robocourse.grading.worker``).
WORKER = "robocourse.grading.worker"
_STAND_IN = '"""Stand-in while grading: the grading worker holds only the modules it needs."""\n'


class KitError(ValueError):
    """A kit would hold library or exercise code: a problem of the course, not of a submission."""


@dataclasses.dataclass(frozen=True)
class Kit:
    """A written kit: ``root`` goes first on the worker's ``sys.path``; ``manifest`` says what it holds."""

    root: Path
    manifest: Manifest

    @property
    def package(self) -> Path:
        """The kit's ``robocourse`` directory (shown in place of any installed robocourse, as root)."""
        return self.root / "robocourse"


def _write(dest: Path, relative: Path, text: str) -> None:
    """Write ``text`` at ``dest/relative``, every directory and file readable by anyone."""
    target = dest / relative
    for d in reversed(relative.parents[:-1]):
        (dest / d).mkdir(exist_ok=True)
        os.chmod(dest / d, 0o755)
    target.write_text(text)
    os.chmod(target, 0o644)


def _relative(module: str, package: bool) -> Path:
    parts = module.split(".")
    return Path(*parts, "__init__.py") if package else Path(*parts[:-1], parts[-1] + ".py")


def build_kit(assignment: Assignment, dest: str | Path) -> Kit:
    """Write the kit of ``assignment`` into the empty or new directory ``dest``.

    Parameters
    ----------
    assignment : robocourse.lessons.Assignment
        Its slug names the data file the kit carries.
    dest : path
        Where to write ``robocourse/...`` and the manifest.

    Returns
    -------
    Kit

    Raises
    ------
    KitError
        If the worker's modules would load a robokit module or a lesson's module (the message
        names the chain of imports that pulls it in).

    Examples
    --------
    >>> import tempfile
    >>> from robocourse.lessons import get_assignment
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     kit = build_kit(get_assignment("04_littledog"), tmp)
    >>> kit.manifest.data, any(m.startswith("robokit") for m in kit.manifest.modules)
    ('04_littledog', False)
    """
    via = closure([WORKER, "robocourse.grading.data"], parents=False)
    for module in sorted(via):
        if not module.startswith("robocourse.grading.") and not module.startswith("robocourse.exercises."):
            chain = [module]
            while via[chain[-1]] != chain[-1] and len(chain) < 20:
                chain.append(via[chain[-1]])
            raise KitError(f"{assignment.slug}: the grading worker would load {module} ({' <- '.join(chain)}); "
                           "it must run on robocourse's grading modules alone")
    packages = sorted({".".join(m.split(".")[:i]) for m in via for i in range(1, m.count(".") + 1)})
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    os.chmod(dest, 0o755)
    for module in sorted(via):
        path = module_file(module)
        _write(dest, _relative(module, path.name == "__init__.py"), path.read_text(encoding="utf-8"))
    for package in packages:
        if package not in via:
            _write(dest, _relative(package, True), _STAND_IN)
    data = data_file(assignment.slug)
    has_data = data.is_file()
    if has_data:
        _write(dest, Path("robocourse", "data", data.name), data.read_text(encoding="utf-8"))
    manifest = Manifest(tuple(sorted(via)), tuple(p for p in packages if p not in via),
                        assignment.slug if has_data else "")
    manifest.write(dest)
    os.chmod(dest / MANIFEST, 0o644)
    return Kit(dest, manifest)
