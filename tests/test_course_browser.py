"""The page inspector of the course site's browser test finds what it is meant to find.

Tiny pages are built in a temporary directory, each with one known fault (a missing script, a
remote image, a console error, a broken formula, MathJax's fonts out of reach, a page that never
finishes loading) next to a clean control, so every check is seen both failing and passing.
"""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from robocourse.site.browser import Browser, BrowserError, changed_fraction, content_fraction
from robocourse.site.cdp import find_chromium
from tests.conftest import CHROMIUM, needs_chromium



def _slow(test):
    """Marks a test that drives Chromium: slow, and skipped where there is none."""
    return pytest.mark.slow(needs_chromium(test))


def _mathjax() -> Path | None:
    """MathJax 3 as the course site ships it (the wheel of sphinx-mathjax-offline)."""
    try:
        spec = importlib.util.find_spec("sphinx-mathjax-offline")
    except (ImportError, ValueError):
        return None
    if spec is None or spec.origin is None:
        return None
    path = Path(spec.origin).parent / "static" / "mathjax"
    return path if (path / "tex-chtml.js").is_file() else None


MATHJAX = _mathjax()


@pytest.fixture(scope="module")
def browser():
    if CHROMIUM is None:
        pytest.skip("no Chromium on PATH")
    with Browser(timeout=30) as b:
        yield b


def page(tmp_path: Path, name: str, body: str, head: str = "") -> Path:
    path = tmp_path / f"{name}.html"
    path.write_text(f"<!doctype html><html><head><meta charset='utf-8'><title>{name}</title>{head}</head>"
                    f"<body>{body}</body></html>", encoding="utf-8")
    return path


def test_a_missing_chromium_is_named():
    with pytest.raises(BrowserError, match="no Chromium found on PATH.*no-such-browser"):
        find_chromium(["no-such-browser"])
    with pytest.raises(BrowserError, match="not an executable file"):
        Browser("/nonexistent/chromium")


@pytest.mark.parametrize("bad, match", [({"width": 10}, "width"), ({"timeout": -1.0}, "timeout"),
                                        ({"executable": 3}, "executable")])
def test_browser_arguments_are_validated(bad, match):
    with pytest.raises((TypeError, ValueError), match=match):
        Browser(**bad)


@pytest.mark.parametrize("call, match", [
    (lambda: changed_fraction(np.zeros((4, 4, 3)), np.zeros((4, 5, 3))), "reference"),
    (lambda: changed_fraction(np.zeros((4, 4)), np.zeros((4, 4))), "image"),
    (lambda: content_fraction(np.full((2, 2, 3), 300.0)), r"image: expected values in \[0, 255\]"),
    (lambda: content_fraction(np.zeros((2, 2, 3)), tolerance=-1), "tolerance"),
])
def test_coverage_helpers_validate_their_inputs(call, match):
    with pytest.raises((TypeError, ValueError), match=match):
        call()


def test_coverage_helpers_measure_the_changed_part():
    empty = np.zeros((10, 10, 3)) + np.arange(10)[:, None, None] * 20     # a vertical gradient
    shot = empty.copy()
    shot[2:6, 3:8] = (255, 0, 255)
    assert changed_fraction(shot, empty) == pytest.approx(0.2)
    assert changed_fraction(empty, empty) == 0.0
    assert content_fraction(shot) == pytest.approx(0.2)
    assert content_fraction(empty) == 0.0


@_slow
def test_a_clean_page_has_no_problems(browser, tmp_path):
    report = browser.inspect(page(tmp_path, "clean", "<p>Hello</p><script>console.log('fine')</script>"))
    assert report.problems() == []
    assert report.title == "clean" and report.final_url.startswith("file://")


@_slow
def test_failed_requests_are_reported_with_the_network_off(browser, tmp_path):
    body = ("<script src='missing.js'></script><img src='https://example.com/logo.png'>"
            "<iframe srcdoc=\"<img src='https://example.org/inside.png'>\"></iframe>")
    report = browser.inspect(page(tmp_path, "requests", body))
    failed = {r.url: r.error for r in report.failed_requests}
    assert failed[(tmp_path / "missing.js").as_uri()] == "net::ERR_FILE_NOT_FOUND"
    assert "https://example.com/logo.png" in failed              # offline: fails, never reaches the host
    assert "https://example.org/inside.png" in failed            # requests of a srcdoc iframe are seen too
    assert not report.ok


@_slow
def test_console_errors_and_exceptions_are_reported(browser, tmp_path):
    report = browser.inspect(page(tmp_path, "console", "<script>console.error('x')</script>"
                                                       "<script>throw new TypeError('boom')</script>"))
    kinds = [(m.source, m.text.splitlines()[0]) for m in report.console_errors]
    assert ("console", "x") in kinds and ("exception", "TypeError: boom") in kinds
    assert any("console error: x" in p for p in report.problems())


@_slow
def test_a_page_that_never_loads_is_a_timeout_not_a_hang(browser, tmp_path):
    report = browser.inspect(page(tmp_path, "loops", "<p>x</p><script>while (true) {}</script>"), timeout=3)
    assert report.timeouts and "did not finish loading" in report.timeouts[0]
    assert browser.inspect(page(tmp_path, "after", "<p>fine</p>")).ok   # the browser still serves pages


def _live_processes(group: int) -> list[int]:
    """Processes of a process group that are not zombies (Linux /proc)."""
    out = []
    for entry in Path("/proc").iterdir():
        try:
            stat = (entry / "stat").read_text()
        except (OSError, ValueError):
            continue
        fields = stat[stat.rindex(")") + 2:].split()        # after "pid (name) ": state, ppid, pgrp, ...
        if entry.name.isdigit() and int(fields[2]) == group and fields[0] != "Z":
            out.append(int(entry.name))
    return out


@_slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_the_browser_is_killed_when_the_block_raises():
    with pytest.raises(RuntimeError, match="stop"):
        with Browser() as b:
            pid = b.pid
            assert pid in _live_processes(pid)       # Chromium leads its own process group
            raise RuntimeError("stop")
    assert _live_processes(pid) == []


def _math_page(tmp_path: Path, name: str, body: str, config: str = "{}") -> Path:
    (tmp_path / "mathjax").exists() or (tmp_path / "mathjax").symlink_to(MATHJAX, target_is_directory=True)
    head = f"<script>window.MathJax = {config}</script><script defer src='mathjax/tex-chtml.js'></script>"
    return page(tmp_path, name, body, head)


needs_mathjax = pytest.mark.skipif(MATHJAX is None, reason="MathJax 3 of the course site not installed "
                                                           "(pip package sphinx-mathjax-offline, a dev dependency)")


@_slow
@needs_mathjax
def test_maths_render_with_mathjax_fonts(browser, tmp_path):
    report = browser.inspect(_math_page(tmp_path, "maths", r"<p>A prime \(x'\) and</p><p>$$x'^2 + \alpha$$</p>"
                                                           r"<pre>\(code, not maths\)</pre>"))
    m = report.math
    assert m.state == "ready" and m.version.startswith("3.")
    assert m.rendered == 2 and m.errors == 0 and m.unrendered == 0
    assert m.fonts_loaded and m.fonts["MJXTEX"] == "loaded"
    assert report.problems() == []


@_slow
@needs_mathjax
def test_broken_maths_is_reported(browser, tmp_path):
    report = browser.inspect(_math_page(tmp_path, "broken", r"<p>\(\frac{a}\) and \(x\)</p><p>$$\frac{$$</p>"))
    m = report.math
    assert m.rendered == 2 and m.errors == 1 and "Missing argument for \\frac" in m.error_texts[0]
    assert m.unrendered == 1 and "\\frac{" in m.unrendered_samples[0]   # unbalanced braces: left as TeX
    assert len(report.problems()) == 2


@_slow
@needs_mathjax
def test_mathjax_falling_back_to_system_fonts_is_reported(browser, tmp_path):
    report = browser.inspect(_math_page(tmp_path, "nofonts", r"<p>\(x'\)</p>",
                                        config="{chtml: {fontURL: 'no-such-fonts'}}"))
    assert report.math.rendered == 1 and not report.math.fonts_loaded
    assert "error" in report.math.fonts.values()
    assert any("no-such-fonts" in r.url for r in report.failed_requests)
    assert any("MathJax web fonts not in use" in p for p in report.problems())


@_slow
def test_mathjax_that_does_not_load_is_reported(browser, tmp_path):
    report = browser.inspect(page(tmp_path, "nomj", r"<p>\(x\)</p>",
                                  "<script>window.MathJax = {}</script><script src='mathjax/none.js'></script>"))
    assert report.math.state == "not loaded" and report.math.unrendered == 1


@_slow
def test_a_scene_is_screenshot_and_differs_from_an_empty_one(browser, tmp_path):
    from robokit.viz import Scene

    box = Scene().add_box("box", (1.5, 1.5, 1.5), color=0xFF00FF)
    spacer = "<div style='height:1200px'></div>"          # the second scene starts below the fold
    report = browser.inspect(page(tmp_path, "scenes", box._repr_html_() + spacer + Scene()._repr_html_()))
    assert report.problems() == []
    assert len(report.scenes) == 2
    drawn, empty = (s.pixels() for s in report.scenes)
    assert all(s.canvas and s.settled for s in report.scenes)
    assert drawn.shape == empty.shape and drawn.shape[0] == box.height - 2   # inside the 1 px border (border-box)
    magenta = (drawn[..., 0] > 120) & (drawn[..., 2] > 120) & (drawn[..., 1] < 60)
    assert magenta.mean() > 0.02
    assert changed_fraction(drawn, empty) > 0.02
    assert content_fraction(drawn) > content_fraction(empty)


@_slow
def test_a_hidden_scene_is_reported(browser, tmp_path):
    from robokit.viz import Scene

    hidden = "<div style='display:none'>" + Scene().add_box("box", (1, 1, 1))._repr_html_() + "</div>"
    report = browser.inspect(page(tmp_path, "hidden", "<p>text</p>" + hidden))
    assert len(report.scenes) == 1 and report.scenes[0].png == b""
    assert report.problems() == ["scene 0 is not visible (size 0 x 0)"]


@_slow
def test_every_page_is_a_first_visit(browser, tmp_path):
    """Nothing a page stores is seen by the next one (a student's first visit is what is checked)."""
    visit = page(tmp_path, "storage", "<script>if (localStorage.getItem('seen')) console.error('stored');"
                                      "localStorage.setItem('seen', '1')</script>")
    assert browser.inspect(visit).ok and browser.inspect(visit).ok
