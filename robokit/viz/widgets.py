"""Sliders that teach: a live ipywidgets slider in JupyterLab, a pre-computed one on the course site.

A lesson asks "what happens when alpha doubles?" with :func:`slider`: it draws one matplotlib
figure per value. With a person at the notebook (JupyterLab, ipywidgets installed) the figure is
redrawn live as the slider moves. When the notebook runs headless (``ROBOKIT_HEADLESS=1``, set by
the course build and the tests) every value's figure is drawn once and embedded as a PNG behind a
plain HTML range input, so the built site keeps a working slider with no kernel and no network.
"""
from __future__ import annotations

import base64
import html as _html
import io
import itertools
import json
from typing import Any, Callable, Sequence

from ..config import headless
from ..validation import as_callable, as_int, as_text

__all__ = ["slider", "static_slider_html"]

_ids = itertools.count()
MAX_VALUES = 24  # pre-computed figures embedded in one page


def _values(values: Any) -> list:
    if isinstance(values, (str, bytes)) or not isinstance(values, Sequence) and not hasattr(values, "__iter__"):
        raise TypeError(f"values: expected a sequence of slider values, got {type(values).__name__}")
    out = list(values)
    if not 2 <= len(out) <= MAX_VALUES:
        raise ValueError(f"values: expected 2 to {MAX_VALUES} slider values, got {len(out)}")
    return out


def _checked(draw: Any, values: Any, label: Any, fmt: Any, start: Any) -> tuple:
    draw = as_callable(draw, "draw", optional=False)
    vals = _values(values)
    return (draw, vals, as_text(label, "label"), as_text(fmt, "fmt", empty=False),
            as_int(start, "start", minimum=0, maximum=len(vals) - 1))


def _figure_png(draw: Callable[[Any], Any], value: Any) -> str:
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    fig = draw(value)
    if not isinstance(fig, Figure):
        raise TypeError(f"draw: expected draw(value) to return a matplotlib Figure, got {type(fig).__name__}")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def static_slider_html(draw: Callable[[Any], Any], values: Sequence[Any], *, label: str = "value",
                       fmt: str = "{}", start: int = 0) -> str:
    """The pre-computed form of :func:`slider`: one PNG per value behind an HTML range input.

    Parameters
    ----------
    draw : callable
        ``draw(value) -> matplotlib.figure.Figure`` (closed after it is drawn).
    values : sequence
        2 to 24 values, in slider order.
    label : str, default "value"
    fmt : str, default "{}"
        ``str.format`` pattern of the value shown beside the slider.
    start : int, default 0
        Index of the value shown first.

    Returns
    -------
    str
        A self-contained HTML fragment (images inline, a one-line ``oninput`` handler).

    Raises
    ------
    TypeError, ValueError
        For a non-callable ``draw``, a ``draw`` that does not return a Figure, too few or too many
        values, or ``start`` outside them.

    Notes
    -----
    Course convention (DESIGN.md, "Visualisation"); not from a paper.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> def draw(k):
    ...     fig, ax = plt.subplots(figsize=(2, 1))
    ...     ax.plot([0, 1], [0, k])
    ...     return fig
    >>> page = static_slider_html(draw, [1, 2, 3], label="slope")
    >>> page.count("<img"), 'max="2"' in page
    (3, True)
    """
    draw, vals, label, fmt, start = _checked(draw, values, label, fmt, start)
    texts = [fmt.format(v) for v in vals]
    pngs = [_figure_png(draw, v) for v in vals]
    uid = f"robokit-slider-{next(_ids)}"
    images = "".join(
        f'<img src="data:image/png;base64,{png}" alt="{_html.escape(label)} = {_html.escape(t)}" '
        f'style="display:{"block" if k == start else "none"};max-width:100%">'
        for k, (png, t) in enumerate(zip(pngs, texts)))
    names = _html.escape(json.dumps(texts), quote=True)
    handler = ("var k=+this.value,box=this.parentNode.parentNode;"
               "box.querySelectorAll('img').forEach(function(im,i){im.style.display=i==k?'block':'none'});"
               f"this.nextSibling.textContent=' '+{names}[k];")
    return (f'<div id="{uid}" class="robokit-slider"><label>{_html.escape(label)} '
            f'<input type="range" min="0" max="{len(vals) - 1}" step="1" value="{start}" '
            f'oninput="{handler}"><span> {_html.escape(texts[start])}</span></label>{images}</div>')


def slider(draw: Callable[[Any], Any], values: Sequence[Any], *, label: str = "value", fmt: str = "{}",
           start: int = 0) -> None:
    """Show ``draw(value)`` under a slider over ``values``: live in JupyterLab, pre-computed headless.

    Parameters
    ----------
    draw : callable
        ``draw(value) -> matplotlib.figure.Figure``.
    values : sequence
        2 to 24 values, in slider order.
    label : str, default "value"
        The slider's caption (say the unit, e.g. ``"alpha (1/m)"``).
    fmt : str, default "{}"
        ``str.format`` pattern of the value shown beside the slider.
    start : int, default 0
        Index of the value shown first.

    Raises
    ------
    TypeError, ValueError
        As :func:`static_slider_html`.

    Notes
    -----
    Live form: ``ipywidgets.interact`` with a ``SelectionSlider`` (ipywidgets is in the ``lab``
    extra). Static form: :func:`static_slider_html`, used when ``ROBOKIT_HEADLESS=1``
    (:func:`robokit.config.headless`) or when ipywidgets is not installed.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> def draw(k):
    ...     fig, ax = plt.subplots(figsize=(2, 1))
    ...     ax.plot([0, 1], [0, k])
    ...     return fig
    >>> slider(draw, [1, 2], label="slope")  # doctest: +SKIP
    """
    draw, vals, label, fmt, start = _checked(draw, values, label, fmt, start)
    from IPython.display import display

    widgets = None
    if not headless():
        try:
            import ipywidgets as widgets
        except ImportError:  # the static form still teaches
            widgets = None
    if widgets is None:
        display({"text/html": static_slider_html(draw, vals, label=label, fmt=fmt, start=start)}, raw=True)
        return

    import matplotlib.pyplot as plt

    def show(value):
        draw(value)
        plt.show()

    options = [(fmt.format(v), v) for v in vals]
    widgets.interact(show, value=widgets.SelectionSlider(options=options, value=vals[start], description=label,
                                                          continuous_update=False))
