"""What :meth:`robocourse.site.browser.Browser.inspect` reports about one page.

Plain records, filled in from Chromium's events and from scripts run in the page; the judgement
of a page lives in :meth:`PageReport.problems`, so a test prints the same lines a person reads.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from robocourse.site.screenshots import decode_png

__all__ = ["FailedRequest", "ConsoleMessage", "MathReport", "SceneShot", "PageReport"]


@dataclass
class FailedRequest:
    """A request that failed (``error`` from Chromium, e.g. ``net::ERR_FILE_NOT_FOUND``) or was
    answered with an HTTP ``status`` of 400 or more (then ``error`` says ``HTTP 404``, ...).

    ``kind`` is Chromium's resource type (``"Script"``, ``"Image"``, ``"Font"``, ``"Document"``...);
    ``canceled`` marks a request the page itself abandoned.

    Examples
    --------
    >>> FailedRequest("file:///site/_static/missing.js", "net::ERR_FILE_NOT_FOUND", kind="Script").error
    'net::ERR_FILE_NOT_FOUND'
    """

    url: str
    error: str
    status: int | None = None
    kind: str = ""
    canceled: bool = False


@dataclass
class ConsoleMessage:
    """A console error, a browser log entry of level error, or an uncaught exception (``source``
    is ``"console"``, the log's source such as ``"network"``, ``"exception"`` or ``"crash"``).

    ``line`` is 1-based, ``None`` when Chromium gives none.

    Examples
    --------
    >>> ConsoleMessage("exception", "TypeError: x is undefined", "file:///site/index.html", 12).source
    'exception'
    """

    source: str
    text: str
    url: str = ""
    line: int | None = None


@dataclass
class MathReport:
    """The page's maths after MathJax finished (or timed out).

    Attributes
    ----------
    state : str
        ``"absent"`` (no MathJax), ``"ready"``, ``"timeout"``, ``"failed: ..."``, ``"not loaded"``
        (configured or referenced but not running) or ``"not MathJax 3"``.
    version : str or None
        ``MathJax.version``.
    rendered : int
        Formulas typeset (``mjx-container`` elements).
    errors : int
        ``mjx-merror`` elements plus occurrences of :data:`~robocourse.site.browser.MATH_ERROR_TEXTS` in the page's text.
    error_texts : list of str
        The first error messages.
    unrendered : int
        Text nodes outside code that still hold TeX delimiters (``\\(``, ``\\[``, ``$$``, ``\\begin{``).
    unrendered_samples : list of str
        The first of them.
    fonts : dict
        MathJax's web font families (``MJX...``) and their status (``"loaded"``, ``"error"``, ...).

    Examples
    --------
    >>> MathReport("ready", "3.2.2", rendered=3, fonts={"MJXTEX": "loaded", "MJXTEX-B": "unloaded"}).fonts_loaded
    True
    >>> MathReport("ready", "3.2.2", rendered=3, fonts={"MJXTEX": "error"}).fonts_loaded
    False
    """

    state: str = "absent"
    version: str | None = None
    rendered: int = 0
    errors: int = 0
    error_texts: list[str] = field(default_factory=list)
    unrendered: int = 0
    unrendered_samples: list[str] = field(default_factory=list)
    fonts: dict[str, str] = field(default_factory=dict)

    @property
    def fonts_loaded(self) -> bool:
        """Whether MathJax's web fonts were used: one ``MJX`` family loaded and none failed."""
        return "loaded" in self.fonts.values() and "error" not in self.fonts.values()


@dataclass
class SceneShot:
    """A screenshot of one 3D scene's iframe (its content box, as far as it is in the viewport).

    Attributes
    ----------
    index : int
        Position among the page's scene iframes.
    rect : tuple of float
        ``(x, y, width, height)`` of the shot in CSS pixels of the page (document coordinates).
    png : bytes
        The screenshot.
    canvas : bool or None
        Whether the iframe holds a non-empty ``<canvas>`` (``None`` if its document is not readable).
    clipped : bool
        Whether part of the iframe was outside the viewport.
    settled : bool
        Whether two screenshots in a row were identical (false for an animation still playing,
        or a scene that kept changing for a second; ``png`` is then the last shot).

    Examples
    --------
    >>> import io, matplotlib.pyplot as plt
    >>> buf = io.BytesIO(); plt.imsave(buf, np.ones((420, 640, 3)), format="png")
    >>> SceneShot(0, (8.0, 100.0, 640.0, 420.0), buf.getvalue()).pixels().shape
    (420, 640, 3)
    """

    index: int
    rect: tuple[float, float, float, float]
    png: bytes
    canvas: bool | None = None
    clipped: bool = False
    settled: bool = False

    def pixels(self) -> np.ndarray:
        """The screenshot as an ``(H, W, 3)`` ``uint8`` array (see :func:`~robocourse.site.screenshots.decode_png`)."""
        return decode_png(self.png)


@dataclass
class PageReport:
    """What :meth:`~robocourse.site.browser.Browser.inspect` found on one page.

    Attributes
    ----------
    url, final_url : str
        The URL asked for and the one shown at the end.
    title : str
        ``document.title``.
    failed_requests : list of FailedRequest
    console_errors : list of ConsoleMessage
        Console errors, error log entries and uncaught exceptions, in order.
    math : MathReport
    scenes : list of SceneShot
    timeouts : list of str
        What did not finish in time (loading, MathJax, a script).
    seconds : float
        Wall-clock time of the inspection.

    Examples
    --------
    >>> report = PageReport("file:///site/index.html", title="Robotics",
    ...                     failed_requests=[FailedRequest("https://cdn.example/require.js",
    ...                                                    "net::ERR_INTERNET_DISCONNECTED")])
    >>> report.problems()
    ['failed request: https://cdn.example/require.js (net::ERR_INTERNET_DISCONNECTED)']
    >>> report.ok
    False
    """

    url: str
    final_url: str = ""
    title: str = ""
    failed_requests: list[FailedRequest] = field(default_factory=list)
    console_errors: list[ConsoleMessage] = field(default_factory=list)
    math: MathReport = field(default_factory=MathReport)
    scenes: list[SceneShot] = field(default_factory=list)
    timeouts: list[str] = field(default_factory=list)
    seconds: float = 0.0

    def problems(self) -> list[str]:
        """One line per problem a student would meet (empty for a clean page).

        The browser's own "Failed to load resource" log lines are left out when the request is
        already listed as failed. Whether a scene shows enough is left to the caller
        (:func:`~robocourse.site.screenshots.changed_fraction`).
        """
        out = [f"timeout: {t}" for t in self.timeouts]
        out += [f"failed request: {r.url} ({r.error})" for r in self.failed_requests]
        failed = {r.url for r in self.failed_requests}
        for c in self.console_errors:
            if c.source == "network" and c.url in failed:
                continue
            where = f" ({c.url}" + (f":{c.line})" if c.line is not None else ")") if c.url else ""
            out.append(f"{c.source} error: {c.text.splitlines()[0] if c.text else ''}{where}")
        m = self.math
        if m.state not in ("absent", "ready"):
            out.append(f"MathJax {m.state}")
        if m.errors:
            out.append(f"{m.errors} formula error(s): {m.error_texts}")
        if m.unrendered:
            out.append(f"{m.unrendered} piece(s) of TeX left unrendered: {m.unrendered_samples}")
        if m.rendered and not m.fonts_loaded:
            used = {f: status for f, status in m.fonts.items() if status != "unloaded"}
            out.append(f"MathJax web fonts not in use: {used or 'no MJX font face loaded'}")
        out += [f"scene {s.index} is not visible (size {s.rect[2]:g} x {s.rect[3]:g})"
                for s in self.scenes if not s.png]
        out += [f"scene {s.index} has no canvas" for s in self.scenes if s.png and s.canvas is False]
        return out

    @property
    def ok(self) -> bool:
        """Whether :meth:`problems` is empty."""
        return not self.problems()
