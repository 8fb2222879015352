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
    assert 'min="0" max="3"' in page and 'value="2"' in page and "3.0" in page
    assert "http" not in page, "the static slider must work offline"
    assert set(plt.get_fignums()) == open_before, "every pre-computed figure is closed"


@pytest.mark.parametrize("kwargs, error", [
    ({"draw": 3, "values": [1, 2]}, "draw"),
    ({"draw": _draw, "values": [1]}, "values"),
    ({"draw": _draw, "values": list(range(100))}, "values"),
    ({"draw": _draw, "values": "ab"}, "values"),
    ({"draw": lambda v: None, "values": [1, 2]}, "draw"),
    ({"draw": _draw, "values": [1, 2], "start": 5}, "start"),
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
