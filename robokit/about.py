"""What robokit runs on: versions of Python and the libraries the course uses."""
from __future__ import annotations

import platform
from importlib import metadata

__all__ = ["versions", "REQUIRED"]

#: Distribution names the lessons need at run time (pyproject.toml's runtime dependencies).
REQUIRED = ("numpy", "scipy", "matplotlib", "opencv-python-headless", "meshcat", "control", "nbformat")


def versions(extra: tuple[str, ...] = ()) -> dict[str, str]:
    """Return installed versions of Python, robokit and its runtime dependencies.

    Parameters
    ----------
    extra : tuple of str
        Further distribution names to report.

    Returns
    -------
    dict
        Name to version string; ``"missing"`` for a package that is not installed.

    Raises
    ------
    TypeError
        If ``extra`` is not a tuple or list of non-empty strings (a lone string would be read
        letter by letter).

    Notes
    -----
    Environment check for lesson 00; not from a paper.

    Examples
    --------
    >>> from robokit.about import versions
    >>> v = versions()
    >>> "python" in v and "numpy" in v and v["robokit"] != "missing"
    True
    """
    if not isinstance(extra, (tuple, list)) or not all(isinstance(n, str) and n for n in extra):
        raise TypeError(f"extra: expected a tuple of distribution names, got {extra!r:.60}")
    out = {"python": platform.python_version(), "robokit": _version("robokit")}
    for name in REQUIRED + tuple(extra):
        out[name] = _version(name)
    return out


def _version(dist: str) -> str:
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return "missing"
