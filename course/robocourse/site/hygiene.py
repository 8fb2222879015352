"""Checks that committed notebooks are clean: no outputs, no execution counts, a kernelspec."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from robokit.files import write_atomically

__all__ = ["notebook_problems", "strip_notebook", "strip_file"]


def notebook_problems(path: str | Path) -> list[str]:
    """Return the hygiene problems of a committed notebook (empty list when clean).

    Parameters
    ----------
    path : str or Path
        Notebook file.

    Returns
    -------
    list of str
        One human-readable message per problem: unreadable or not JSON, not nbformat 4, a code
        cell with outputs or an execution count, a missing kernelspec.

    Notes
    -----
    Course rule (LESSON_GUIDE.md: "committed without outputs"); not from a paper.
    """
    path = Path(path)
    try:
        nb = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        return [f"{path}: not a readable JSON notebook ({exc.__class__.__name__}: {exc})"]
    if not isinstance(nb, dict) or nb.get("nbformat") != 4:
        return [f"{path}: expected an nbformat 4 notebook"]
    problems = []
    for i, cell in enumerate(nb.get("cells", [])):
        if cell.get("cell_type") != "code":
            continue
        if cell.get("outputs"):
            problems.append(f"{path}: cell {i} has outputs (strip them: robocourse strip {path})")
        if cell.get("execution_count") is not None:
            problems.append(f"{path}: cell {i} has an execution count")
    spec = nb.get("metadata", {}).get("kernelspec")
    if not isinstance(spec, dict) or not spec.get("name"):
        problems.append(f"{path}: metadata has no kernelspec (expected e.g. name 'python3')")
    return problems


def strip_notebook(nb: dict[str, Any]) -> dict[str, Any]:
    """Remove outputs, execution counts and volatile metadata from a notebook dict, in place.

    Returns
    -------
    dict
        The same notebook, for chaining.
    """
    for cell in nb.get("cells", []):
        if cell.get("cell_type") == "code":
            cell["outputs"] = []
            cell["execution_count"] = None
        md = cell.get("metadata", {})
        for key in ("execution", "collapsed", "scrolled"):
            md.pop(key, None)
    nb.get("metadata", {}).pop("widgets", None)
    return nb


def strip_file(path: str | Path) -> bool:
    """Strip a notebook file in place; return whether it changed."""
    path = Path(path)
    before = path.read_text(encoding="utf-8")
    nb = strip_notebook(json.loads(before))
    after = json.dumps(nb, indent=1, ensure_ascii=False) + "\n"
    if after != before:
        write_atomically(path, lambda tmp: tmp.write_text(after, encoding="utf-8"))
        return True
    return False
