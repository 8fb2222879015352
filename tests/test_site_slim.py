"""A built site slimmed on a small hand-made tree (the full sites: tests/test_course_site.py): scenes at
any depth load the one shared viewer, downloads lose their outputs, MathJax keeps what its bundle
uses, source maps go, and a layout it does not know is left whole."""
import html
import json

import pytest

from robocourse.site.slim import VIEWER_SCRIPT, slim_site
from robokit.viz.scene import viewer_javascript


def _scene() -> str:
    page = f"<html><body><script>{viewer_javascript()}</script><script>var viewer;</script></body></html>"
    return f'<iframe srcdoc="{html.escape(page, quote=True)}"></iframe>'


def _tree(tmp_path, bundle="tex-chtml.js"):
    site = tmp_path / "site"
    mathjax = site / "_static" / "mathjax"
    files = [bundle, "tex-svg-full.js", "input/tex/extensions/ams.js", "input/mml/x.js",
             "output/chtml/fonts/woff-v2/MathJax_Main-Regular.woff", "output/svg/fonts/tex.js", "sre/mathmaps/en.json",
             "a11y/semantic-enrich.js", "ui/menu.js", "adaptors/liteDOM.js"]
    for rel in files:
        (mathjax / rel).parent.mkdir(parents=True, exist_ok=True)
        (mathjax / rel).write_text("x" * 100)
    script = f'<script defer="defer" src="{{root}}_static/mathjax/{bundle}"></script>'
    (site / "index.html").write_text(f"<html>{script.format(root='')}</html>")
    (site / "lessons").mkdir()
    (site / "lessons" / "01.html").write_text(f"<html>{script.format(root='../')}{_scene()}{_scene()}</html>")
    (site / "api" / "deep").mkdir(parents=True)
    (site / "api" / "deep" / "viz.html").write_text(f"<html>{script.format(root='../../')}{_scene()}</html>")
    notebook = {"cells": [{"cell_type": "code", "source": ["1 + 1"], "metadata": {}, "execution_count": 3,
                           "outputs": [{"output_type": "execute_result", "data": {"text/plain": ["2"]}}]}],
                "metadata": {}, "nbformat": 4, "nbformat_minor": 5}
    (site / "_sources" / "lessons").mkdir(parents=True)
    (site / "_sources" / "lessons" / "01.ipynb").write_text(json.dumps(notebook))
    (site / "_static" / "scripts").mkdir()
    (site / "_static" / "scripts" / "theme.js.map").write_text("{}")
    return site


def test_scenes_at_any_depth_share_one_viewer_and_the_rest_is_trimmed(tmp_path):
    site = _tree(tmp_path)
    saved = slim_site(site)
    assert saved["viewer"] > 1.5 * len(viewer_javascript()) and saved["maps"] == 2
    lesson, api = (site / "lessons" / "01.html").read_text(), (site / "api" / "deep" / "viz.html").read_text()
    assert lesson.count(html.escape(f'<script src="../{VIEWER_SCRIPT}"></script>', quote=True)) == 2
    assert api.count(html.escape(f'<script src="../../{VIEWER_SCRIPT}"></script>', quote=True)) == 1
    assert viewer_javascript()[:200] not in html.unescape(lesson + api)
    assert (site / VIEWER_SCRIPT).read_text(encoding="utf-8") == viewer_javascript()
    cells = json.loads((site / "_sources" / "lessons" / "01.ipynb").read_text())["cells"]
    assert cells[0]["outputs"] == [] and cells[0]["execution_count"] is None and cells[0]["source"] == ["1 + 1"]
    mathjax = site / "_static" / "mathjax"
    kept = sorted(str(p.relative_to(mathjax)) for p in mathjax.rglob("*") if p.is_file())
    assert kept == ["a11y/semantic-enrich.js", "adaptors/liteDOM.js", "input/tex/extensions/ams.js",
                    "output/chtml/fonts/woff-v2/MathJax_Main-Regular.woff", "sre/mathmaps/en.json", "tex-chtml.js",
                    "ui/menu.js"]
    assert not list(site.rglob("*.js.map")) and not (site / "_static" / "scripts").exists()


def test_a_site_without_scenes_or_a_named_bundle_keeps_its_mathjax(tmp_path):
    site = _tree(tmp_path, bundle="es5/tex-chtml.js")          # a layout the pruning does not know
    for page in ("lessons/01.html", "api/deep/viz.html"):
        (site / page).write_text("<html>no scene</html>")
    before = sorted(p for p in (site / "_static" / "mathjax").rglob("*") if p.is_file())
    saved = slim_site(site)
    assert saved["viewer"] == 0 and saved["mathjax"] == 0 and not (site / VIEWER_SCRIPT).exists()
    assert sorted(p for p in (site / "_static" / "mathjax").rglob("*") if p.is_file()) == before


def test_only_a_built_site_is_slimmed(tmp_path):
    with pytest.raises(ValueError, match="site"):
        slim_site(tmp_path)
