"""Every page of the student site, opened in headless Chromium with the network off, as a student
would: no failed request, no console error, every formula rendered with MathJax's own fonts, every
3D scene drawn and covering a reasonable part of its view. The site is the one the ``fast_course``
fixture built from the repository's notebooks."""
import base64
import html
import re

import pytest

from robocourse.site.browser import SCENE_TITLE, Browser
from robocourse.site.screenshots import changed_span, changed_fraction
from tests.conftest import CHROMIUM, needs_chromium

pytestmark = [pytest.mark.slow, pytest.mark.notebook, needs_chromium]

#: A scene is drawn if this share of its pixels differs from its camera's view of the empty grid ...
MIN_SCENE_PIXELS = 0.002
#: ... and framed on its content if what differs spans this share of the view's height or width. A
#: robot arm or a path drawn with lines changes few pixels however well it is framed; spans measure
#: framing instead. Measured at full size: a 0.5 m box lost in a view framed on 30 m spans 0.02, the
#: lesson scenes framed with viz.fit_view 0.37 (lesson 06's self-motion, lines in the corners of
#: its box) to 0.98.
MIN_SCENE_SPAN = 0.3


@pytest.fixture(scope="module")
def reports(fast_course):
    pages = sorted(fast_course.student.rglob("*.html"))
    pages = [p for p in pages if "_static" not in p.parts and "_sources" not in p.parts]
    with Browser(CHROMIUM) as browser:
        return {str(p.relative_to(fast_course.student)): browser.inspect(p, timeout=90) for p in pages}


SCENE_IFRAME = re.compile(r'<iframe srcdoc="([^"]*)"[^>]*title="' + re.escape(SCENE_TITLE) + '"')
COMMANDS = re.compile(r"var robokitCommands = \[(.*?)\];", re.S)


def camera_only(page_html: str) -> str:
    """The scene page with every command dropped but the camera's (position, target, clipping
    planes): the same view of meshcat's empty grid, the reference a drawn scene is compared with."""
    import umsgpack

    def keep(encoded: str) -> bool:
        command = umsgpack.unpackb(base64.b64decode(encoded.strip().strip('"')))
        return command.get("type") == "set_target" or str(command.get("path", "")).startswith("/Cameras")

    match = COMMANDS.search(page_html)
    kept = [c for c in match.group(1).split(",") if c.strip() and keep(c)]
    return page_html[:match.start(1)] + ",".join(kept) + page_html[match.end(1):]


def scene_coverage(browser: Browser, scene, scene_html: str, folder) -> tuple[float, float]:
    """(share of pixels, larger share of the view's height or width spanned) that differ from the
    same camera's view of an empty scene."""
    width, height = round(scene.rect[2]), round(scene.rect[3])
    page = folder / f"empty-{abs(hash(scene_html))}.html"
    page.write_text(f'<html><body style="margin:0"><iframe title="{SCENE_TITLE}" style="width:{width}px;'
                    f'height:{height}px;border:0" srcdoc="{html.escape(camera_only(scene_html), quote=True)}">'
                    "</iframe></body></html>")
    empty = browser.inspect(page).scenes[0].pixels()
    return changed_fraction(scene.pixels(), empty), changed_span(scene.pixels(), empty)


def test_every_page_was_inspected(reports):
    for page in ("index.html", "search.html", "references.html", "api/index.html"):
        assert page in reports
    assert sum(p.startswith("lessons/") for p in reports) >= 8
    assert sum(p.startswith("assignments/") for p in reports) >= 7


def test_no_page_has_a_problem_offline(reports):
    problems = {page: r.problems() for page, r in reports.items() if r.problems()}
    assert not problems, "\n".join(f"{page}: {p}" for page, ps in problems.items() for p in ps[:4])


def test_maths_renders_with_its_own_fonts(reports):
    with_maths = {page: r.math for page, r in reports.items() if r.math.rendered}
    assert len(with_maths) >= 6, sorted(with_maths)        # the lessons are full of formulas
    for page, math in with_maths.items():
        assert math.state == "ready" and math.errors == 0 and math.unrendered == 0, (page, math)
        assert math.fonts_loaded, (page, math.fonts)


def test_every_scene_is_drawn_and_fills_its_view(reports, fast_course, tmp_path):
    thin, n_scenes = [], 0
    with Browser(CHROMIUM) as browser:
        for page, report in reports.items():
            if not report.scenes:
                continue
            sources = [html.unescape(m.group(1)) for m in
                       SCENE_IFRAME.finditer((fast_course.student / page).read_text(encoding="utf-8"))]
            assert len(sources) == len(report.scenes), page
            for scene, source in zip(report.scenes, sources):
                n_scenes += 1
                assert scene.png, f"{page}: scene {scene.index} not visible"
                pixels, span = scene_coverage(browser, scene, source, tmp_path)
                if pixels < MIN_SCENE_PIXELS or span < MIN_SCENE_SPAN:
                    thin.append(f"{page} scene {scene.index}: {pixels:.3f} of its pixels differ from its camera's "
                                f"view of the empty grid, spanning {span:.2f} of the view")
    assert n_scenes >= 8, "every lesson shows at least one 3D scene"
    assert not thin, "\n".join(thin)


def test_the_coverage_measure_catches_a_speck_on_the_grid(tmp_path):
    """A 10 cm box in a view framed on 30 m (the grid seen from the same camera) scores far below the
    threshold, and the same box framed on itself far above: the scene check can fail."""
    from robokit.viz import Scene, fit_view

    def coverage(scene):
        page = tmp_path / f"scene-{len(list(tmp_path.iterdir()))}.html"
        page.write_text(f"<html><body style='margin:0'>{scene._repr_html_()}</body></html>")
        with Browser(CHROMIUM, width=700) as browser:       # about the site's content column
            shot = browser.inspect(page).scenes[0]
            return scene_coverage(browser, shot, scene.html(), tmp_path)

    speck = fit_view(Scene(height=420).add_box("speck", (0.1, 0.1, 0.1), color=0xFF00FF),
                     (0.5, -1.0, 0.9), bounds=[[-15, -15, 0], [15, 15, 1]])
    filled = fit_view(Scene(height=420).add_box("speck", (0.1, 0.1, 0.1), color=0xFF00FF), (0.5, -1.0, 0.9))
    pixels, span = coverage(speck)
    assert pixels < 0.01 and span < 0.05 < MIN_SCENE_SPAN
    pixels, span = coverage(filled)
    assert pixels > 0.2 > MIN_SCENE_PIXELS and span > 0.8 > MIN_SCENE_SPAN


def test_page_titles_are_the_pages_own(reports):
    for page, r in reports.items():
        if page.startswith(("lessons/", "assignments/")):
            assert r.title.split(" — ")[0].startswith(("Lesson", "Assignment")), (page, r.title)
