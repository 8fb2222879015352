"""Write the static HTML course site: one page per executed notebook and an index."""
from __future__ import annotations

import datetime as _dt
import html
from pathlib import Path
from typing import Sequence

from .execute import NotebookRun

__all__ = ["notebook_page", "write_index", "page_name", "install_mathjax"]

#: MathJax is copied next to the pages so equations render offline (nbconvert's default is a CDN).
MATHJAX_URL = "mathjax/MathJax.js?config=TeX-AMS-MML_HTMLorMML-full,Safe"

_STYLE = """
body{font-family:system-ui,sans-serif;max-width:70rem;margin:2rem auto;padding:0 1rem;color:#222}
table{border-collapse:collapse;width:100%}th,td{border-bottom:1px solid #ddd;padding:.4rem .6rem;
text-align:left;vertical-align:top}th{background:#f4f4f4}.ok{color:#11772b;font-weight:600}
.failed,.timeout{color:#b00020;font-weight:600}pre{background:#fff4f4;padding:.5rem;white-space:pre-wrap;
font-size:.8rem;margin:.3rem 0 0}td.num{text-align:right;font-variant-numeric:tabular-nums}
"""


def page_name(run: NotebookRun) -> str:
    """Return the site file name of a notebook's page, e.g. ``lessons-00_getting_started.html``."""
    return f"{run.path.parent.name}-{run.path.stem}.html"


def install_mathjax(out_dir: Path) -> bool:
    """Copy MathJax (from the ``jupyter-server-mathjax`` package) into ``out_dir/mathjax``.

    Returns whether a local MathJax is available; without it pages fall back to nbconvert's CDN
    address, which needs a network connection to render equations.
    """
    try:
        import jupyter_server_mathjax
    except ImportError:
        return False
    import shutil

    src = Path(jupyter_server_mathjax.__file__).parent / "static"
    dst = out_dir / "mathjax"
    if not (dst / "MathJax.js").exists():
        shutil.copytree(src, dst, dirs_exist_ok=True)
    return True


def notebook_page(run: NotebookRun, out_dir: Path, *, local_mathjax: bool = False) -> Path:
    """Render the executed notebook of ``run`` to HTML in ``out_dir`` and return the page path.

    Figures are embedded as data URIs and meshcat scenes as self-contained HTML, so the site
    works offline. A notebook that failed before producing any output gets a page with its error.
    """
    target = out_dir / page_name(run)
    body = None
    if run.executed is not None and run.executed.exists():
        try:
            import nbformat
            from nbconvert import HTMLExporter

            exporter = HTMLExporter(template_name="lab")
            if local_mathjax:
                exporter.mathjax_url = MATHJAX_URL
            body, _ = exporter.from_notebook_node(nbformat.read(run.executed, as_version=4))
        except Exception as exc:  # a broken notebook must not break the whole site
            body = None
            run.error = (run.error + f"\n(HTML export failed: {exc})").strip()
    if body is None:
        body = (f"<html><head><meta charset='utf-8'><style>{_STYLE}</style></head><body>"
                f"<h1>{html.escape(run.path.name)}</h1><p class='{run.status}'>{run.status}</p>"
                f"<pre>{html.escape(run.error)}</pre></body></html>")
    target.write_text(body, encoding="utf-8")
    return target


def write_index(runs: Sequence[NotebookRun], out_dir: Path, root: Path,
                extra_html: str = "") -> Path:
    """Write ``index.html`` listing every notebook with its status, run time and error tail."""
    rows = []
    for run in runs:
        rel = run.path.relative_to(root) if run.path.is_relative_to(root) else run.path
        err = f"<pre>{html.escape(run.error)}</pre>" if run.error and not run.ok else ""
        rows.append(
            f"<tr><td>{html.escape(run.path.parent.name)}</td>"
            f"<td><a href='{html.escape(page_name(run))}'>{html.escape(str(rel))}</a>{err}</td>"
            f"<td class='{run.status}'>{run.status}</td><td class='num'>{run.seconds:.1f} s</td></tr>"
        )
    n_ok = sum(r.ok for r in runs)
    stamp = _dt.datetime.now().strftime("%Y-%m-%d %H:%M")
    page = (
        "<!DOCTYPE html><html><head><meta charset='utf-8'><title>robokit course</title>"
        f"<style>{_STYLE}</style></head><body><h1>robokit course</h1>"
        f"<p>{n_ok} of {len(runs)} notebooks ran without error (built {stamp}).</p>"
        "<table><tr><th>part</th><th>notebook</th><th>status</th><th>run time</th></tr>"
        + "".join(rows) + "</table>" + extra_html + "</body></html>"
    )
    index = out_dir / "index.html"
    index.write_text(page, encoding="utf-8")
    return index
