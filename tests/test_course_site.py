"""The course sites built from the repository's own notebooks (fast mode): the student site has
every lesson and assignment in order, a library reference and the references, and never any
solution; the instructor site has the solutions. (Browser checks: test_course_site_browser.py.)"""
import html
import json
import re

import pytest

from tests.conftest import ROOT

pytestmark = [pytest.mark.slow, pytest.mark.notebook]

BEGIN_CODE, END_CODE = "# BEGIN SOLUTION", "# END SOLUTION"
BEGIN_TEXT, END_TEXT = re.compile(r"<!--\s*BEGIN SOLUTION[^>]*-->"), re.compile(r"<!--\s*END SOLUTION\s*-->")


def solution_lines(min_length: int = 16) -> dict[str, set[str]]:
    """Every distinctive line of solution code and model answers, per solution notebook."""
    found = {}
    for path in sorted((ROOT / "solutions").glob("*.ipynb")):
        lines = set()
        for cell in json.loads(path.read_text())["cells"]:
            text = "".join(cell["source"])
            if cell["cell_type"] == "code":
                blocks = re.findall(re.escape(BEGIN_CODE) + r"(.*?)" + re.escape(END_CODE), text, re.S)
            else:
                blocks = [m.group(1) for m in re.finditer(BEGIN_TEXT.pattern + r"(.*?)" + END_TEXT.pattern, text, re.S)]
            for block in blocks:
                for line in block.splitlines():
                    line = " ".join(line.split())
                    if len(line) >= min_length and not line.startswith("#"):
                        lines.add(line)
        found[path.name] = lines
    return found


def site_text(site) -> str:
    """All text a reader of ``site`` can get at: page text (tags stripped), sources, scripts."""
    parts = []
    for path in site.rglob("*"):
        if not path.is_file() or path.suffix in {".png", ".jpg", ".woff", ".woff2", ".ico", ".gif", ".svg"}:
            continue
        text = path.read_text(encoding="utf-8", errors="ignore")
        if path.suffix == ".ipynb":
            text = "\n".join("".join(c.get("source", "")) for c in json.loads(text).get("cells", []))
        elif path.suffix == ".html":
            text = html.unescape(re.sub(r"<[^>]+>", "", text))
        parts.append(" ".join(text.split()))
    return "\n".join(parts)


def test_every_notebook_built(fast_course):
    for name, site in fast_course.sites.items():
        assert site.ok, f"{name} site failed:\n{site.warnings[-2000:]}"


def test_student_site_never_contains_solution_code(fast_course):
    solutions = solution_lines()
    assert all(solutions.values()), "every solution notebook has solution lines to look for"
    student = site_text(fast_course.student)
    instructor = site_text(fast_course.instructor)
    for notebook, lines in solutions.items():
        leaked = sorted(line for line in lines if line in student)
        assert not leaked, f"{notebook}: solution lines on the student site: {leaked[:5]}"
        # the same search finds them where they belong, so it can fail
        shown = [line for line in lines if line in instructor]
        assert len(shown) >= 0.8 * len(lines), f"{notebook}: only {len(shown)}/{len(lines)} found on the instructor site"


def test_sidebar_lists_every_lesson_and_assignment_in_order(fast_course):
    index = (fast_course.student / "index.html").read_text()
    nav = index[index.index('class="bd-sidenav"') if 'class="bd-sidenav"' in index else 0:]
    lessons = sorted(p.stem for p in (ROOT / "lessons").glob("*.ipynb"))
    assignments = sorted(p.stem for p in (ROOT / "assignments").glob("*.ipynb"))
    positions = [nav.index(f'href="lessons/{s}.html"') for s in lessons]
    positions += [nav.index(f'href="assignments/{s}.html"') for s in assignments]
    assert positions == sorted(positions)
    assert 'href="api/index.html"' in nav and 'href="references.html"' in nav
    assert "solutions/" not in index


def test_pages_have_real_titles_and_previous_next(fast_course):
    for path in sorted((fast_course.student / "lessons").glob("*.html")):
        page = path.read_text()
        title = re.search(r"<title>(.*?)</title>", page, re.S).group(1)
        assert title.startswith("Lesson 0"), (path.name, title)
        assert 'class="left-prev"' in page and 'class="right-next"' in page, path.name


def test_library_reference_documents_the_lessons_functions(fast_course):
    api = fast_course.student / "api"
    text = (api / "arm.html").read_text()
    assert 'id="robokit.arm.ik_srs"' in text or 'id="robokit.arm.srs.ik_srs"' in text
    assert "Shimizu" in text                         # the docstrings' citations come through
    check = (api / "grading.check.html").read_text()
    assert "check" in check and "NotImplementedYet" in check
    assert "assignment_data" in (api / "grading.data.html").read_text()


def test_home_page_says_what_who_and_how_to_start(fast_course):
    text = html.unescape(re.sub(r"<[^>]+>", " ", (fast_course.student / "index.html").read_text()))
    for phrase in ("Who it is for", "How to start", "Lesson 00"):
        assert phrase in text, phrase


def test_sites_are_light_one_viewer_clean_downloads_and_only_the_mathjax_they_use(fast_course):
    from robocourse.site.slim import VIEWER_SCRIPT
    from robokit.viz.scene import viewer_javascript

    inline = html.escape(viewer_javascript()[:2000], quote=True)
    for site in (fast_course.student, fast_course.instructor):
        size = sum(p.stat().st_size for p in site.rglob("*") if p.is_file())
        assert size < 40e6, f"{site.name}: {size / 1e6:.1f} MB"
        pages = {p: p.read_text(encoding="utf-8") for p in site.rglob("*.html")}
        assert not [p.name for p, text in pages.items() if inline in text], "a scene still carries its own viewer"
        scenes = [p for p, text in pages.items() if "meshcat-viewer.js" in text]
        assert len(scenes) >= 6 and (site / VIEWER_SCRIPT).read_text(encoding="utf-8") == viewer_javascript()
        downloads = sorted((site / "_sources").rglob("*.ipynb"))
        assert len(downloads) >= 8
        for path in downloads:
            cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
            assert not any(c.get("outputs") for c in cells) and any(c["cell_type"] == "code" for c in cells), path
        bundles = set(re.findall(r"_static/mathjax/([\w-]+\.js)", "".join(pages.values())))
        assert bundles and all((site / "_static" / "mathjax" / b).is_file() for b in bundles)
        assert not list(site.rglob("*.js.map")) and not (site / "_static" / "mathjax" / "tex-svg-full.js").exists()
