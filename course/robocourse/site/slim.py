"""A built site without what its pages never load: one copy of the 3D viewer, clean notebooks to
download, the MathJax parts the pages use, no source maps.

Sphinx writes every 3D scene with meshcat's viewer script inside (about 1 MB each), a second full copy
of every executed notebook for the download button (``_sources``), all of MathJax 3 (about 24 MB, of
which a page loads one bundle, its TeX extensions and its fonts) and the theme's source maps.
:func:`slim_site` rewrites the finished site in place before it is published:

* each scene's ``<iframe srcdoc>`` loads the viewer from ``_static/robokit/meshcat-viewer.js`` (a
  ``srcdoc`` document resolves relative addresses against its page, so this works from ``file://``
  too); the notebooks keep their self-contained scenes;
* the download button gives the notebook without outputs (what a student runs);
* MathJax keeps the combined bundles the pages name and the folders those load on demand;
* ``*.js.map`` files go.
"""
from __future__ import annotations

import html
import os
import re
import shutil
from pathlib import Path
from typing import Iterable

from robokit.files import write_atomically
from robokit.viz.scene import viewer_javascript

from .hygiene import strip_file

__all__ = ["VIEWER_SCRIPT", "slim_site"]

#: Where the shared viewer script goes, relative to the site's root.
VIEWER_SCRIPT = "_static/robokit/meshcat-viewer.js"
#: MathJax folders a combined bundle (``tex-chtml.js``) loads on demand: accessibility and speech, the
#: menu, the DOM adaptor; ``input/<x>`` and ``output/<y>`` are kept for the bundle's own input and output.
_MATHJAX_ON_DEMAND = ("a11y", "adaptors", "sre", "ui")
_BUNDLE = re.compile(r"_static/mathjax/([A-Za-z0-9_-]+\.js)")


def slim_site(site: Path) -> dict[str, int]:
    """Rewrite the Sphinx site in ``site`` (a build's private output) without what its pages never load.

    Parameters
    ----------
    site : Path
        A finished Sphinx HTML build (it holds ``index.html``).

    Returns
    -------
    dict
        Bytes saved by each step: ``"viewer"``, ``"sources"``, ``"mathjax"``, ``"maps"``.

    Raises
    ------
    ValueError
        If ``site`` holds no ``index.html``.

    Notes
    -----
    Course convention (DESIGN.md, "The course site"); not from a paper.
    """
    site = Path(site)
    if not (site / "index.html").is_file():
        raise ValueError(f"site: expected a built site with an index.html, got {str(site)!r}")
    pages = {page: page.read_text(encoding="utf-8") for page in sorted(site.rglob("*.html"))}    # read once
    return {"viewer": _share_viewer(site, pages), "sources": _strip_sources(site),
            "mathjax": _prune_mathjax(site, pages.values()), "maps": _remove(list(site.rglob("*.js.map")))}


def _share_viewer(site: Path, pages: dict[Path, str]) -> int:
    """Every scene's inline viewer script replaced by one file the scenes load."""
    inline = html.escape(f"<script>{viewer_javascript()}</script>", quote=True)
    saved, shared = 0, False
    for page, text in pages.items():
        if inline not in text:
            continue
        root = os.path.relpath(site, page.parent).replace(os.sep, "/")
        tag = html.escape(f'<script src="{root}/{VIEWER_SCRIPT}"></script>', quote=True)
        slimmer = text.replace(inline, tag)
        saved += len(text.encode()) - len(slimmer.encode())
        _write(page, slimmer.encode("utf-8"))
        shared = True
    if shared:
        target = site / VIEWER_SCRIPT
        target.parent.mkdir(parents=True, exist_ok=True)
        script = viewer_javascript().encode("utf-8")
        _write(target, script)
        saved -= len(script)
    return saved


def _strip_sources(site: Path) -> int:
    """The notebooks offered for download, without outputs (:func:`~robocourse.site.hygiene.strip_file`)."""
    saved = 0
    for path in sorted((site / "_sources").rglob("*.ipynb")):
        before = path.stat().st_size
        strip_file(path)
        saved += before - path.stat().st_size
    return saved


def _prune_mathjax(site: Path, texts: Iterable[str]) -> int:
    """MathJax without the bundles no page names and the inputs and outputs those do not use."""
    mathjax = site / "_static" / "mathjax"
    if not mathjax.is_dir():
        return 0
    bundles = {bundle for text in texts for bundle in _BUNDLE.findall(text)}   # the viewer swap keeps these
    if not bundles:             # no page names a top-level bundle (another layout): keep it all
        return 0
    parts = {part for b in bundles for part in b[:-3].split("-")}           # tex-chtml.js: tex, chtml
    keep = {mathjax / b for b in bundles} | {mathjax / d for d in _MATHJAX_ON_DEMAND}
    keep |= {mathjax / "input" / p for p in parts} | {mathjax / "output" / p for p in parts}
    doomed = [p for p in mathjax.rglob("*") if p.is_file() and not any(k == p or k in p.parents for k in keep)]
    return _remove(doomed)


def _write(path: Path, data: bytes) -> None:
    write_atomically(path, lambda tmp: tmp.write_bytes(data))


def _remove(files: list[Path]) -> int:
    saved = 0
    for path in files:
        saved += path.stat().st_size
        path.unlink()
    for folder in sorted({p.parent for p in files}, key=lambda p: len(p.parts), reverse=True):
        if folder.is_dir() and not any(folder.iterdir()):
            shutil.rmtree(folder)
    return saved
