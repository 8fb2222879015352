"""The lessons' sliders: a pre-computed static form that works with no kernel, and clear errors."""
from __future__ import annotations

import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from robokit.config import headless  # noqa: E402
from robokit.viz import slider
from robokit.viz.widgets import static_slider_html  # noqa: E402
from tests.conftest import needs_chromium  # noqa: E402


def _draw(k):
    fig, ax = plt.subplots(figsize=(2, 1))
    ax.plot([0, 1], [0, k])
    ax.set_title(f"k = {k}")
    return fig


def test_the_static_slider_embeds_one_distinct_figure_per_value_and_shows_the_start():
    open_before = set(plt.get_fignums())
    page = static_slider_html(_draw, [1, 2, 3, 4], label="slope", fmt="{:.1f}", start=2)
    images = re.findall(r'<img src="data:image/png;base64,([^"]+)"[^>]*style="display:(\w+)', page)
    assert len(images) == 4
    assert len({png for png, _ in images}) == 4, "each value must have its own figure"
    assert [shown for _, shown in images] == ["none", "none", "block", "none"]
    assert 'min="1.0" max="4.0"' in page and 'value="3.0"' in page and "3.0" in page
    assert "http" not in page, "the static slider must work offline"
    assert set(plt.get_fignums()) == open_before, "every pre-computed figure is closed"


@pytest.mark.parametrize("kwargs, error", [
    ({"draw": 3, "values": [1, 2]}, "draw"),
    ({"draw": _draw, "values": [1]}, "values"),
    ({"draw": _draw, "values": list(range(100))}, "values"),
    ({"draw": _draw, "values": "ab"}, "values"),
    ({"draw": lambda v: None, "values": [1, 2]}, "draw"),
    ({"draw": _draw, "values": [1, 2], "start": 5}, "start"),
    ({"draw": _draw, "values": [1, 2], "spacing": "log"}, "spacing"),
])
def test_bad_slider_input_names_the_argument(kwargs, error):
    with pytest.raises((TypeError, ValueError), match=error):
        static_slider_html(**kwargs)


def test_headless_shows_the_static_form(monkeypatch):
    shown = []
    monkeypatch.setenv("ROBOKIT_HEADLESS", "1")
    monkeypatch.setattr("IPython.display.display", lambda obj, raw=False: shown.append(obj))
    slider(_draw, [1, 2], label="slope")
    assert len(shown) == 1 and shown[0]["text/html"].count("<img") == 2


def test_headless_refuses_a_typo():
    assert headless({"ROBOKIT_HEADLESS": "yes"}) is True
    with pytest.raises(ValueError, match="ROBOKIT_HEADLESS"):
        headless({"ROBOKIT_HEADLESS": "maybe"})


def test_numbers_sit_at_their_values_and_anything_else_at_equal_steps():
    uneven = static_slider_html(_draw, [0.5, 1.0, 8.0], start=1)
    assert 'min="0.5" max="8.0" step="any" value="1.0"' in uneven and "each at its place" in uneven
    assert "onkeydown" in uneven and "arrow keys step" in uneven and "typed" not in uneven   # no typing there
    for values, spacing in (([3, 1, 2], "value"), (["a", "b"], "value"), ([1, 2, 4], "even"),
                            ([1.0, float("nan")], "value"), ([True, False], "value")):
        page = static_slider_html(_draw, values, spacing=spacing)
        assert f'min="0" max="{len(values) - 1}" step="1"' in page and "at equal steps" in page, values


def test_the_live_slider_snaps_a_typed_value_to_the_nearest_and_draws_it():
    pytest.importorskip("ipywidgets")
    from robokit.viz.widgets import live_slider

    drawn = []

    def draw(k):
        drawn.append(k)
        return _draw(k)

    open_before = set(plt.get_fignums())
    box, control, redraw = live_slider(draw, [0.5, 1.0, 2.0, 8.0], label="alpha", fmt="{:.1f}", start=1)
    assert type(control).__name__ == "FloatSlider" and (control.min, control.max, control.value) == (0.5, 8.0, 1.0)
    assert control.readout_format == ".1f"                  # as few decimals as the values need
    redraw()
    control.value = 6.1                      # typed into the readout
    control.value = 4.9                      # nearer 2.0 than 8.0
    assert control.value == 2.0 and drawn == [1.0, 8.0, 2.0]
    shown = box.children[2].outputs[0]["data"]
    assert shown["text/plain"] == "alpha = 2.0" and len(shown["image/png"]) > 100
    assert "each at its place" in box.children[1].value and "Run this cell again" in box.children[1].value
    assert set(plt.get_fignums()) == open_before

    box, control, redraw = live_slider(draw, ["chained", "free"], start=1)
    assert type(control).__name__ == "SelectionSlider" and control.value == 1
    assert live_slider(draw, [0, 7, 14])[1].readout_format == ".0f"
    control.value = 0
    assert drawn[-1] == "chained" and "at equal steps" in box.children[1].value and "ignored" in box.children[1].value


def test_a_failing_draw_shows_its_error_where_the_figure_was():
    pytest.importorskip("ipywidgets")
    from robokit.viz.widgets import live_slider

    def draw(k):
        if k > 1:
            raise ZeroDivisionError("no figure for this value")
        return _draw(k)

    box, control, redraw = live_slider(draw, [1.0, 2.0])
    redraw()
    control.value = 2.0
    shown = box.children[2].outputs[0]
    assert shown["name"] == "stderr" and "ZeroDivisionError: no figure for this value" in shown["text"]


@pytest.mark.slow
@needs_chromium
def test_the_static_slider_snaps_and_steps_in_a_browser(tmp_path):
    """The pre-computed slider's own script, run by Chromium: a drag snaps to the nearest value,
    the arrow keys step to the next one (a range of step "any" alone would snap back), negative
    values and quotes in the label included."""
    import time

    from robocourse.site.cdp import DevToolsPipe

    page = static_slider_html(_draw, [-3.0, -1.0, 0.5, 8.0], label='x "q"', fmt="{:.1f}", start=1)
    html = tmp_path / "slider.html"
    html.write_text(f"<!doctype html><html><body>{page}</body></html>", encoding="utf-8")
    state = ("[document.querySelector('input').value, document.querySelector('span').textContent.trim(), "
             "[...document.querySelectorAll('img')].findIndex(i => i.style.display == 'block')]")
    with DevToolsPipe() as pipe:
        target = pipe.call("Target.createTarget", {"url": html.as_uri()})["targetId"]
        session = pipe.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]

        def js(expression):
            return pipe.call("Runtime.evaluate", {"expression": expression, "returnByValue": True},
                             session)["result"].get("value")

        deadline = time.monotonic() + 20
        while not js("document.readyState == 'complete' && document.querySelector('input') !== null") \
                and time.monotonic() < deadline:              # the tab starts on about:blank
            time.sleep(0.1)
        assert js(state) == ["-1", "-1.0", 1]
        js("document.querySelector('input').focus()")
        seen = []
        for key, code in (("ArrowRight", 39), ("ArrowRight", 39), ("ArrowRight", 39), ("ArrowLeft", 37)):
            for kind in ("keyDown", "keyUp"):
                pipe.call("Input.dispatchKeyEvent", {"type": kind, "key": key, "code": key,
                                                     "windowsVirtualKeyCode": code}, session)
            seen.append(js(state))
        assert seen == [["0.5", "0.5", 2], ["8", "8.0", 3], ["8", "8.0", 3], ["0.5", "0.5", 2]]
        for dragged, expected in (("-2.5", ["-3", "-3.0", 0]), ("3", ["0.5", "0.5", 2])):
            js(f"var i = document.querySelector('input'); i.value = '{dragged}'; i.dispatchEvent(new Event('input'))")
            assert js(state) == expected
