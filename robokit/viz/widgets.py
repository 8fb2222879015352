"""Sliders that teach: a live ipywidgets slider in JupyterLab, a pre-computed one on the course site.

A lesson asks "what happens when alpha doubles?" with :func:`slider`: it draws one matplotlib
figure per value. With a person at the notebook (JupyterLab, ipywidgets installed) the figure is
redrawn live as the slider moves. Numeric values sit on the track at their values (a gap in the
values shows as a gap on the track) and a number typed into the readout moves the slider to the
nearest value computed; other values (or ``spacing="even"``) sit at equal steps, and the note under
the slider says so. When the notebook runs headless (``ROBOKIT_HEADLESS=1``, set by
the course build and the tests) every value's figure is drawn once and embedded as a PNG behind a
plain HTML range input, so the built site keeps a working slider with no kernel and no network.
"""
from __future__ import annotations

import base64
import html as _html
import io
import itertools
import json
import math
import traceback
from numbers import Real as numbers_Real
from typing import Any, Callable, Sequence

from ..config import headless
from ..validation import as_callable, as_choice, as_int, as_text

__all__ = ["slider", "static_slider_html", "live_slider"]

_ids = itertools.count()
MAX_VALUES = 24  # pre-computed figures embedded in one page


def _values(values: Any) -> list:
    if isinstance(values, (str, bytes)) or not isinstance(values, Sequence) and not hasattr(values, "__iter__"):
        raise TypeError(f"values: expected a sequence of slider values, got {type(values).__name__}")
    out = list(values)
    if not 2 <= len(out) <= MAX_VALUES:
        raise ValueError(f"values: expected 2 to {MAX_VALUES} slider values, got {len(out)}")
    return out


def _checked(draw: Any, values: Any, label: Any, fmt: Any, start: Any, spacing: Any) -> tuple:
    draw = as_callable(draw, "draw", optional=False)
    vals = _values(values)
    spacing = as_choice(spacing, "spacing", ("value", "even"))
    return (draw, vals, as_text(label, "label"), as_text(fmt, "fmt", empty=False),
            as_int(start, "start", minimum=0, maximum=len(vals) - 1), _positions(vals, spacing))


def _positions(vals: list, spacing: str) -> list[float] | None:
    """Where each value sits on the track: the value itself when ``spacing`` is "value" and the
    values are finite real numbers in increasing order; None (equal steps) otherwise."""
    if spacing == "even":
        return None
    numbers = []
    for v in vals:
        if isinstance(v, bool) or not isinstance(v, numbers_Real) or not math.isfinite(v):
            return None
        numbers.append(float(v))
    if any(b <= a for a, b in zip(numbers, numbers[1:])):
        return None
    return numbers


def _nearest(positions: list[float], x: float) -> int:
    """Index of the position nearest ``x`` (the first of two equally near)."""
    return min(range(len(positions)), key=lambda k: abs(positions[k] - x))


def _decimals(positions: list[float]) -> int:
    """The fewest decimals that write every position exactly (0 for counts, 1 for 0.5 steps), at most 4."""
    return next((n for n in range(4) if all(abs(round(p, n) - p) < 1e-9 * max(1.0, abs(p)) for p in positions)), 4)


def _note(texts: list[str], positions: list[float] | None, live: bool) -> str:
    """The line under a slider that says how it moves (the live form also takes typed numbers)."""
    if positions is None:
        return (f"The slider steps through {len(texts)} values at equal steps; drag it or use the arrow keys"
                + (" (text typed into its readout is ignored)." if live else "."))
    return (f"The slider stops at the {len(texts)} values computed ({', '.join(texts)}), each at its place on the "
            "track; " + ("a number typed into the readout moves it to the nearest." if live
                         else "the arrow keys step from one to the next."))


def _figure_png(draw: Callable[[Any], Any], value: Any, dpi: int = 80) -> str:
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    fig = draw(value)
    if not isinstance(fig, Figure):
        raise TypeError(f"draw: expected draw(value) to return a matplotlib Figure, got {type(fig).__name__}")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def static_slider_html(draw: Callable[[Any], Any], values: Sequence[Any], *, label: str = "value",
                       fmt: str = "{}", start: int = 0, spacing: str = "value") -> str:
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
    spacing : {"value", "even"}, default "value"
        "value": increasing real values sit on the track at their values and the input snaps to
        the nearest; "even" (and any other values): equal steps.

    Returns
    -------
    str
        A self-contained HTML fragment (images inline, a one-line ``oninput`` handler, the note
        that says how the slider moves).

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
    >>> page = static_slider_html(draw, [1, 2, 4], label="slope")
    >>> page.count("<img"), 'min="1.0" max="4.0"' in page
    (3, True)
    """
    return _static_html(*_checked(draw, values, label, fmt, start, spacing))


def _static_html(draw: Callable[[Any], Any], vals: list, label: str, fmt: str, start: int,
                 positions: list[float] | None) -> str:
    """:func:`static_slider_html` on checked arguments."""
    texts = [fmt.format(v) for v in vals]
    pngs = [_figure_png(draw, v) for v in vals]
    uid = f"robokit-slider-{next(_ids)}"
    images = "".join(
        f'<img src="data:image/png;base64,{png}" alt="{_html.escape(label)} = {_html.escape(t)}" '
        f'style="display:{"block" if k == start else "none"};max-width:100%">'
        for k, (png, t) in enumerate(zip(pngs, texts)))
    names = json.dumps(texts)
    show = ("var box=this.parentNode.parentNode;"
            "box.querySelectorAll('img').forEach(function(im,i){im.style.display=i==k?'block':'none'});"
            f"this.nextSibling.textContent=' '+{names}[k];")
    if positions is None:
        track, keys = f'min="0" max="{len(vals) - 1}" step="1" value="{start}"', ""
        handler = f"var k=+this.value;{show}"
    else:
        track = f'min="{positions[0]!r}" max="{positions[-1]!r}" step="any" value="{positions[start]!r}"'
        places = json.dumps(positions)
        nearest = f"var p={places},x=+this.value,k=0;p.forEach(function(v,i){{if(Math.abs(v-x)<Math.abs(p[k]-x))k=i}});"
        handler = f"{nearest}this.value=p[k];{show}"
        # the arrow keys step to the next computed value (a step of "any" would snap back to the same one)
        step = ("var d={ArrowRight:1,ArrowUp:1,ArrowLeft:-1,ArrowDown:-1}[event.key];if(!d)return;"
                f"event.preventDefault();{nearest}k=Math.min(p.length-1,Math.max(0,k+d));this.value=p[k];{show}")
        keys = f' onkeydown="{_html.escape(step, quote=True)}"'
    return (f'<div id="{uid}" class="robokit-slider"><label>{_html.escape(label)} '
            f'<input type="range" {track} oninput="{_html.escape(handler, quote=True)}"{keys}>'
            f'<span> {_html.escape(texts[start])}</span></label>'
            f'<div style="font-size:smaller;color:#555">{_html.escape(_note(texts, positions, False))}</div>'
            f'{images}</div>')


def slider(draw: Callable[[Any], Any], values: Sequence[Any], *, label: str = "value", fmt: str = "{}",
           start: int = 0, spacing: str = "value") -> None:
    """Show ``draw(value)`` under a slider over ``values``: live in JupyterLab, pre-computed headless.

    Parameters
    ----------
    draw : callable
        ``draw(value) -> matplotlib.figure.Figure``; called only with members of ``values``.
    values : sequence
        2 to 24 values, in slider order.
    label : str, default "value"
        The slider's caption (say the unit, e.g. ``"alpha (1/m)"``).
    fmt : str, default "{}"
        ``str.format`` pattern of the value shown beside the slider.
    start : int, default 0
        Index of the value shown first.
    spacing : {"value", "even"}, default "value"
        "value": increasing real values sit on the track at their values, and a number typed into
        the readout moves the slider to the nearest of them; "even" (and any other values, such
        as names): equal steps, text typed into the readout ignored. A note under the slider says which.

    Raises
    ------
    TypeError, ValueError
        As :func:`static_slider_html`.

    Notes
    -----
    Live form: an ipywidgets ``FloatSlider`` that snaps to the values (``SelectionSlider`` for
    equal steps) above an ``Output`` that is redrawn; ipywidgets is in the ``lab`` extra. A live
    slider needs its kernel: in a notebook reopened from disk JupyterLab shows "Error displaying
    widget" until the cell runs again, which the note says. Static form: :func:`static_slider_html`,
    used when ``ROBOKIT_HEADLESS=1`` (:func:`robokit.config.headless`) or when ipywidgets is not
    installed.

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
    checked = _checked(draw, values, label, fmt, start, spacing)
    from IPython.display import display

    widgets = None
    if not headless():
        try:
            import ipywidgets as widgets
        except ImportError:  # the static form still teaches
            widgets = None
    if widgets is None:
        display({"text/html": _static_html(*checked)}, raw=True)
        return
    box, _, redraw = _live(widgets, *checked)
    display(box)
    redraw()


def live_slider(draw: Callable[[Any], Any], values: Sequence[Any], *, label: str = "value", fmt: str = "{}",
                start: int = 0, spacing: str = "value") -> tuple:
    """The widgets of :func:`slider`'s live form, unshown: ``(box, control, redraw)``.

    ``box`` holds the slider, the note that says how it moves and the figure; ``control`` is the
    slider (its ``description`` is ``label``); ``redraw()`` draws the figure of the control's value
    into the box (a call of ``draw``, its figure shown and closed). Moving
    ``control`` (or setting its value, as a typed readout does) snaps it to the nearest value and
    redraws. Arguments as :func:`slider`; needs ipywidgets.

    Raises
    ------
    TypeError, ValueError
        As :func:`static_slider_html`.

    Notes
    -----
    Course convention (DESIGN.md, "Visualisation"); not from a paper.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> drawn = []
    >>> def draw(k):
    ...     drawn.append(k)
    ...     return plt.figure()
    >>> box, control, redraw = live_slider(draw, [1.0, 2.0, 8.0])
    >>> control.value = 6.5          # as if typed: it snaps to 8.0 and draws that figure
    >>> control.value, drawn
    (8.0, [8.0])
    """
    import ipywidgets as widgets

    return _live(widgets, *_checked(draw, values, label, fmt, start, spacing))


def _live(widgets: Any, draw: Callable[[Any], Any], vals: list, label: str, fmt: str, start: int,
          positions: list[float] | None) -> tuple:
    """:func:`live_slider` on checked arguments, with the ipywidgets module it builds from."""
    texts = [fmt.format(v) for v in vals]
    note = _note(texts, positions, True) + (" Reopened the notebook and see 'Error displaying widget'? "
                                                 "Run this cell again.")
    if positions is None:
        control = widgets.SelectionSlider(options=[(t, k) for k, t in enumerate(texts)], value=start,
                                          description=label, continuous_update=False)
    else:
        control = widgets.FloatSlider(min=positions[0], max=positions[-1], step=None, value=positions[start],
                                      description=label, continuous_update=False,
                                      readout_format=f".{_decimals(positions)}f")
    control.style.description_width = "initial"
    output = widgets.Output()

    def index() -> int:
        return control.value if positions is None else _nearest(positions, control.value)

    def redraw() -> None:
        k = index()
        try:
            png = _figure_png(draw, vals[k], dpi=100)     # whatever matplotlib backend the kernel runs
        except Exception:                                 # shown where the figure would be, not lost
            output.outputs = ({"output_type": "stream", "name": "stderr",
                               "text": f"draw({texts[k]}) failed:\n{traceback.format_exc()}"},)
            return
        output.outputs = ({"output_type": "display_data", "metadata": {},
                           "data": {"image/png": png, "text/plain": f"{label} = {texts[k]}"}},)

    def changed(change) -> None:
        if positions is not None and change["new"] != positions[index()]:
            control.value = positions[index()]     # snapping sets the value again, which redraws
            return
        redraw()

    control.observe(changed, names="value")
    box = widgets.VBox([control, widgets.HTML(f'<span style="font-size:smaller;color:#555">{_html.escape(note)}</span>'),
                        output])
    return box, control, redraw
