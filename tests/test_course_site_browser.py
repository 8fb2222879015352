"""Every page of the student site, opened in headless Chromium with the network off, as a student
would: no failed request, no console error, every formula rendered with MathJax's own fonts, every
3D scene drawn and covering a reasonable part of its view. The site is the one the ``fast_course``
fixture built from the repository's notebooks."""
import html
import shutil

import pytest

from robokit.course.browser import SCENE_TITLE, Browser, changed_fraction

CHROMIUM = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)

pytestmark = [pytest.mark.slow, pytest.mark.notebook,
              pytest.mark.skipif(CHROMIUM is None, reason="no Chromium on PATH (Debian package 'chromium'; "
                                                          ".ci/run installs it)")]

#: Share of a scene's pixels that must differ from an empty scene of the same size: the robot,
#: world or arm the text talks about fills a reasonable part of the view, not a speck on the grid.
MIN_SCENE_CONTENT = 0.05


@pytest.fixture(scope="module")
def reports(fast_course):
    pages = sorted(fast_course.student.rglob("*.html"))
    pages = [p for p in pages if "_static" not in p.parts and "_sources" not in p.parts]
    with Browser(CHROMIUM) as browser:
        return {str(p.relative_to(fast_course.student)): browser.inspect(p, timeout=90) for p in pages}


@pytest.fixture(scope="module")
def empty_scene(tmp_path_factory):
    """Screenshots of an empty scene, per iframe size, to tell a drawn scene from the bare grid."""
    from robokit.viz import Scene

    cache, folder = {}, tmp_path_factory.mktemp("empty-scenes")

    def shot(width: float, height: float):
        key = (round(width), round(height))
        if key not in cache:
            page = folder / f"empty-{key[0]}x{key[1]}.html"
            page.write_text(f'<html><body style="margin:0"><iframe title="{SCENE_TITLE}" '
                            f'style="width:{key[0]}px;height:{key[1]}px;border:0" '
                            f'srcdoc="{html.escape(Scene().html(), quote=True)}"></iframe></body></html>')
            with Browser(CHROMIUM) as browser:
                cache[key] = browser.inspect(page).scenes[0].pixels()
        return cache[key]

    return shot


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


def test_every_scene_is_drawn_and_fills_its_view(reports, empty_scene):
    scenes = [(page, s) for page, r in reports.items() for s in r.scenes]
    assert len(scenes) >= 8, "every lesson shows at least one 3D scene"
    thin = []
    for page, scene in scenes:
        assert scene.png, f"{page}: scene {scene.index} not visible"
        image = scene.pixels()
        covered = changed_fraction(image, empty_scene(scene.rect[2], scene.rect[3]))
        if covered < MIN_SCENE_CONTENT:
            thin.append(f"{page} scene {scene.index}: {covered:.3f} of the view differs from an empty scene")
    assert not thin, "\n".join(thin)


def test_page_titles_are_the_pages_own(reports):
    for page, r in reports.items():
        if page.startswith(("lessons/", "assignments/")):
            assert r.title.split(" — ")[0].startswith(("Lesson", "Assignment")), (page, r.title)
