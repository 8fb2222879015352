"""Is this installation complete? Every package the course imports, with the lessons that need it.

Lesson 00 calls :func:`check_environment` so that a missing or broken package (a MuJoCo or numba
that is installed but does not import) shows up in the first five minutes, named with the lesson
that would otherwise fail, not in the middle of lesson 04 or 06. ``tests/test_environment.py`` keeps
:data:`PACKAGES` (with :data:`OPTIONAL`, what robokit can do without) complete: every third-party
module that robokit, robocourse or a notebook imports is in one of them, and each entry's robokit
user does import it.
"""
from __future__ import annotations

import dataclasses
import importlib
from importlib import metadata

__all__ = ["Package", "PACKAGES", "OPTIONAL", "check_environment", "environment_table"]


@dataclasses.dataclass(frozen=True)
class Package:
    """One package the course needs.

    Attributes
    ----------
    distribution : str
        The name pip installs it by (and reports its version under).
    module : str or None
        The module to import to prove it works; None for a program that is not imported (JupyterLab).
    lessons : str
        The lessons that need it, as a student reads it ("all", "04", "01-03").
    used_by : str
        What needs it: a robokit subpackage (``robokit.legged``) or a course tool.
    """

    distribution: str
    module: str | None
    lessons: str
    used_by: str


#: What the course needs at run time, in the order lesson 00 prints it.
PACKAGES = (
    Package("numpy", "numpy", "all", "robokit"),
    Package("scipy", "scipy", "all", "robokit"),
    Package("matplotlib", "matplotlib", "all", "robokit.viz"),
    Package("opencv-python-headless", "cv2", "all", "robokit.sim"),
    Package("meshcat", "meshcat", "all", "robokit.viz"),
    Package("u-msgpack-python", "umsgpack", "all", "robokit.viz"),
    Package("ipython", "IPython", "all", "robokit.viz"),
    Package("tqdm", "tqdm", "all", "robokit.progress"),
    Package("control", "control", "02-05", "robokit.controllers"),
    Package("mujoco", "mujoco", "04", "robokit.legged"),
    Package("numba", "numba", "06", "robokit.arm"),
    Package("ipywidgets", "ipywidgets", "all (live sliders)", "robokit.viz"),
    Package("nbformat", "nbformat", "assignments", "robocourse (check, assignment data)"),
    Package("ipykernel", "ipykernel", "all", "JupyterLab's Python kernel"),
    Package("jupyterlab", None, "all", "JupyterLab"),
)

#: What robokit uses when it is installed and does without otherwise (not checked by lesson 00).
OPTIONAL = (
    Package("cvxopt", "cvxopt", "02-03 (big pose graphs faster; GPL-3, opt-in)", "robokit.mapping"),
)


def _status(package: Package) -> tuple[str, str]:
    """(version, status) where status is "ok", "missing" or "broken: <why>"."""
    try:
        version = metadata.version(package.distribution)
    except metadata.PackageNotFoundError:
        return "missing", "missing"
    if package.module is None:
        return version, "ok"
    try:
        importlib.import_module(package.module)
    except Exception as exc:  # an installed package that fails to import is broken, whatever the reason
        return version, f"broken: {type(exc).__name__}: {exc}"[:200]
    return version, "ok"


def check_environment() -> list[dict[str, str]]:
    """Import every package of :data:`PACKAGES` and report its version and state.

    Returns
    -------
    list of dict
        One row per package, in :data:`PACKAGES` order: ``package`` (distribution name),
        ``version`` (``"missing"`` when not installed), ``status`` (``"ok"``, ``"missing"`` or
        ``"broken: ..."`` with the import error), ``lessons`` and ``used_by``.

    Notes
    -----
    Course tooling for lesson 00; not from a paper. A package counts as present only when it
    imports: an installed MuJoCo whose shared library does not load is "broken", not "ok".

    Examples
    --------
    >>> rows = check_environment()
    >>> [r["package"] for r in rows][:2], {r["status"] for r in rows if r["package"] == "numpy"}
    (['numpy', 'scipy'], {'ok'})
    """
    rows = []
    for package in PACKAGES:
        version, status = _status(package)
        rows.append({"package": package.distribution, "version": version, "status": status,
                     "lessons": package.lessons, "used_by": package.used_by})
    return rows


def environment_table(rows: list[dict[str, str]]) -> str:
    """The rows of :func:`check_environment` as a fixed-width text table, one package per line.

    Raises
    ------
    TypeError
        If ``rows`` is not a list of dicts with the keys :func:`check_environment` gives.

    Examples
    --------
    >>> print(environment_table([{"package": "numpy", "version": "2.1.0", "status": "ok",
    ...                           "lessons": "all", "used_by": "robokit"}]))
    package                  version     lessons              used by                              status
    numpy                    2.1.0       all                  robokit                              ok
    """
    keys = ("package", "version", "status", "lessons", "used_by")
    if not isinstance(rows, list) or not all(isinstance(r, dict) and all(isinstance(r.get(k), str) for k in keys)
                                             for r in rows):
        raise TypeError(f"rows: expected the list of dicts of text check_environment() returns, got {rows!r:.80}")
    lines = [f"{'package':<24} {'version':<11} {'lessons':<20} {'used by':<36} status"]
    for r in rows:
        lines.append(f"{r['package']:<24} {r['version']:<11} {r['lessons']:<20} {r['used_by']:<36} {r['status']}")
    return "\n".join(lines)
