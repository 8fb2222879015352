"""Inspect web pages as a student's browser shows them: headless Chromium with the network off.

:class:`Browser` keeps one Chromium running (:class:`robocourse.site.cdp.DevToolsPipe`) and opens
each page in a fresh tab with the network emulated offline (``file://`` pages load, every
``http(s)`` request fails). :meth:`Browser.inspect` returns a :class:`PageReport`: failed requests,
console errors and uncaught exceptions, the state of the maths (MathJax 3: formulas rendered, in
error, left as TeX, and whether MathJax's own web fonts loaded), and a screenshot of every 3D scene
(``<iframe title="robokit meshcat scene">``). :func:`~robocourse.site.screenshots.changed_fraction`
and :func:`~robocourse.site.screenshots.content_fraction` (re-exported here) measure how much of a
scene's screenshot shows something. The test-suite uses it to check every page of the course site.
"""
from __future__ import annotations

import base64
import json
import numbers
import time
from os import PathLike
from pathlib import Path

from robocourse.site.cdp import BrowserError, DevToolsPipe, as_seconds
from robocourse.site.page_report import ConsoleMessage, FailedRequest, MathReport, PageReport, SceneShot
from robocourse.site.screenshots import changed_fraction, content_fraction, decode_png

__all__ = ["Browser", "PageReport", "FailedRequest", "ConsoleMessage", "MathReport", "SceneShot",
           "changed_fraction", "content_fraction", "decode_png", "SCENE_TITLE", "BrowserError"]

#: The ``title`` of the iframes that hold a robokit 3D scene (``robokit.viz.Scene``'s HTML).
SCENE_TITLE = "robokit meshcat scene"

#: Text MathJax puts in the page when a formula fails (MathJax 2, and MathJax 3's compile/typeset errors).
MATH_ERROR_TEXTS = ("Math Processing Error", "Math input error", "Math output error")

#: Extra screenshots of a scene, this many seconds apart, taken until two in a row are the same.
_SETTLE_SHOTS, _SETTLE_PAUSE = 4, 0.25

_OFFLINE = {"offline": True, "latency": 0, "downloadThroughput": -1, "uploadThroughput": -1}

_MATH_JS = r"""async (timeoutMs, errorTexts) => {
  const sleep = (ms, value) => new Promise(r => setTimeout(() => r(value), ms));
  const frame = () => Promise.race([new Promise(r => requestAnimationFrame(() => r())), sleep(100)]);
  const mj = window.MathJax;
  const scripted = [...document.scripts].some(s => /mathjax/i.test(s.src));
  let state = 'absent';
  if (mj && mj.startup && mj.startup.promise) {
    state = await Promise.race([mj.startup.promise.then(() => 'ready', e => 'failed: ' + e),
                                sleep(timeoutMs, 'timeout')]);
  } else if (mj && mj.version) { state = 'not MathJax 3'; }
  else if (mj || scripted) { state = 'not loaded'; }
  if (state !== 'absent' && document.fonts) {
    document.body && document.body.offsetHeight;          // lay out, so the fonts in use start loading
    await frame(); await frame();
    await Promise.race([document.fonts.ready, sleep(timeoutMs)]);
  }
  const fonts = {};
  for (const f of (document.fonts || [])) {
    const family = f.family.replace(/["']/g, '');
    if (!family.startsWith('MJX')) continue;
    const rank = {error: 4, loading: 3, loaded: 2, unloaded: 1};
    if (!fonts[family] || rank[f.status] > rank[fonts[family]]) fonts[family] = f.status;
  }
  const merrors = [...document.querySelectorAll('mjx-merror')].map(
      e => e.getAttribute('data-mjx-error') || e.textContent);
  const text = document.body ? document.body.innerText : '';
  let errorTextCount = 0;
  for (const t of errorTexts) errorTextCount += text.split(t).length - 1;
  const skip = new Set(['SCRIPT', 'STYLE', 'PRE', 'CODE', 'TEXTAREA', 'NOSCRIPT', 'MJX-CONTAINER']);
  const tex = /\\\(|\\\[|\$\$|\\begin\{/;
  const leftovers = [];
  const walker = document.createTreeWalker(document.body || document, NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    if (!tex.test(n.data)) continue;
    let p = n.parentElement, skipped = false;
    for (; p; p = p.parentElement) if (skip.has(p.tagName)) { skipped = true; break; }
    if (!skipped) leftovers.push(n.data.trim().slice(0, 80));
  }
  return {state, version: (mj && mj.version) || null,
          rendered: document.querySelectorAll('mjx-container').length,
          errors: merrors.length + errorTextCount, errorTexts: merrors.slice(0, 10),
          unrendered: leftovers.length, unrenderedSamples: leftovers.slice(0, 5), fonts};
}"""

_SCENE_RECT_JS = r"""async (title, index) => {
  const f = [...document.querySelectorAll('iframe')].filter(f => f.title === title)[index];
  f.scrollIntoView({block: 'center', inline: 'nearest'});
  const w = f.contentWindow;                 // let the scene's own animation loop run twice
  const frame = () => new Promise(r => {
    setTimeout(r, 500);
    try { w.requestAnimationFrame(() => r()); } catch (e) {}
  });
  await frame(); await frame();
  const r = f.getBoundingClientRect();
  let canvas = null;
  try { const c = f.contentDocument && f.contentDocument.querySelector('canvas');
        canvas = f.contentDocument ? Boolean(c && c.width > 0 && c.height > 0) : null; } catch (e) {}
  const x = Math.max(r.left + f.clientLeft, 0), y = Math.max(r.top + f.clientTop, 0);
  const right = Math.min(r.left + f.clientLeft + f.clientWidth, innerWidth);
  const bottom = Math.min(r.top + f.clientTop + f.clientHeight, innerHeight);
  return {x: x + scrollX, y: y + scrollY, width: Math.max(right - x, 0), height: Math.max(bottom - y, 0), canvas,
          clipped: f.clientWidth > right - x || f.clientHeight > bottom - y};
}"""


class Browser:
    """One headless Chromium that inspects many pages, each in a fresh tab with the network off.

    Every page is opened in its own new browser context (no cookies, storage or cache from the
    pages before, as on a student's first visit), so a report does not depend on the order in
    which pages are inspected; this costs about 0.4 s per page.

    Parameters
    ----------
    executable : str or None
        Chromium's path; ``None`` finds ``chromium``, ``chromium-browser`` or ``google-chrome``
        on ``PATH`` (a :class:`BrowserError` says so if there is none).
    width, height : int
        Viewport size in CSS pixels.
    timeout : float
        Default seconds a page may take to load (see :meth:`inspect`).

    Examples
    --------
    >>> with Browser() as browser:                                    # doctest: +SKIP
    ...     report = browser.inspect("build/course/index.html")
    >>> report.problems()                                             # doctest: +SKIP
    []
    """

    def __init__(self, executable: str | None = None, *, width: int = 1280, height: int = 900,
                 timeout: float = 30.0) -> None:
        self.width, self.height = _pixels(width, "width"), _pixels(height, "height")
        self.timeout = as_seconds(timeout, "timeout")
        self._pipe = DevToolsPipe(executable, args=(f"--window-size={self.width},{self.height}",))
        self._pipe.on_event = self._on_event
        self._page: _PageState | None = None

    @property
    def pid(self) -> int:
        """Process id of Chromium, the leader of its own process group."""
        return self._pipe.pid

    def close(self) -> None:
        """Quit Chromium (killing its processes) and delete its profile; safe to call twice."""
        self._pipe.close()

    def __enter__(self) -> "Browser":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def inspect(self, page: str | PathLike, *, timeout: float | None = None, math_timeout: float = 10.0,
                scene_wait: float = 0.3) -> PageReport:
        """Open ``page`` offline and report what a student would meet there.

        Parameters
        ----------
        page : str or path-like
            A URL (``file://...``) or the path of an existing local file.
        timeout : float or None
            Seconds to wait for the load event (``None``: the browser's default). A page that does
            not load in time gets a line in ``timeouts`` and is inspected as it is.
        math_timeout : float
            Seconds to wait for MathJax to finish typesetting and for fonts to load.
        scene_wait : float
            Seconds of real time given to each scene to draw after it is scrolled into view (WebGL
            is software-rendered in headless Chromium).

        Returns
        -------
        PageReport

        Examples
        --------
        >>> with Browser() as browser:                                # doctest: +SKIP
        ...     report = browser.inspect("build/course/lessons/01_lab.html")
        >>> report.math.rendered, report.math.fonts_loaded, len(report.scenes)    # doctest: +SKIP
        (42, True, 2)
        """
        url = _as_url(page)
        timeout = self.timeout if timeout is None else as_seconds(timeout, "timeout")
        math_timeout = as_seconds(math_timeout, "math_timeout")
        scene_wait = as_seconds(scene_wait, "scene_wait", allow_zero=True)
        if scene_wait > 60:
            raise ValueError(f"scene_wait: expected seconds in [0, 60], got {scene_wait!r}")
        report = PageReport(url=url)
        start = time.monotonic()
        pipe = self._pipe
        # A fresh browser context per page: no storage or cache carried over, as for a first visit.
        context = pipe.call("Target.createBrowserContext")["browserContextId"]
        try:
            target = pipe.call("Target.createTarget", {"url": "about:blank", "browserContextId": context})["targetId"]
            session = pipe.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
            self._page = state = _PageState(report, {session})
            pipe.call("Emulation.setDeviceMetricsOverride", {"width": self.width, "height": self.height,
                                                             "deviceScaleFactor": 1, "mobile": False}, session)
            for method, params in _setup_commands(page=True):
                pipe.call(method, params, session)
            self._visit(session, state, url, timeout, math_timeout, scene_wait)
        except TimeoutError as exc:
            report.timeouts.append(str(exc))
        finally:
            self._page = None
            try:
                pipe.call("Target.disposeBrowserContext", {"browserContextId": context}, timeout=10)
            except (TimeoutError, BrowserError):
                pass
            report.seconds = time.monotonic() - start
        return report

    # -- the steps of one inspection -------------------------------------------------------------
    def _visit(self, session: str, state: "_PageState", url: str, timeout: float, math_timeout: float,
               scene_wait: float) -> None:
        pipe, report = self._pipe, state.report
        deadline = time.monotonic() + timeout
        nav = pipe.call("Page.navigate", {"url": url}, session, timeout=timeout)
        if nav.get("errorText"):
            if not any(r.url == url for r in report.failed_requests):
                report.failed_requests.append(FailedRequest(url, nav["errorText"], kind="Document"))
            return
        try:
            pipe.wait(lambda: state.loaded or state.crashed, max(deadline - time.monotonic(), 0.01))
        except TimeoutError:
            report.timeouts.append(f"the page did not finish loading within {timeout:g} s")
            pipe.send("Page.stopLoading", session=session)
            pipe.send("Runtime.terminateExecution", session=session)     # stops a script stuck in a loop
        if state.crashed:
            return
        # A small query must answer within this; the page's own thread also runs its software-rendered
        # WebGL scenes, and on a loaded 2-core machine lesson 04's animated scenes kept it busy past 5 s
        # (make check, twice, 2026-12-07); a page that hangs still fails, 15 s later.
        short = min(timeout, 15.0)
        report.title, report.final_url = self._evaluate(session, "() => [document.title, location.href]",
                                                        timeout=short, what="its title")
        math = self._evaluate(session, _MATH_JS, math_timeout * 1000, list(MATH_ERROR_TEXTS),
                              timeout=2 * math_timeout + short, what="its maths")
        report.math = MathReport(math["state"], math["version"], math["rendered"], math["errors"],
                                 math["errorTexts"], math["unrendered"], math["unrenderedSamples"], math["fonts"])
        count = self._evaluate(session, "(t) => [...document.querySelectorAll('iframe')].filter("
                                        "f => f.title === t).length", SCENE_TITLE, timeout=short, what="its scenes")
        for index in range(count):
            rect = self._evaluate(session, _SCENE_RECT_JS, SCENE_TITLE, index, timeout=short, what=f"scene {index}")
            box = (rect["x"], rect["y"], rect["width"], rect["height"])
            png, settled = b"", False
            if rect["width"] >= 1 and rect["height"] >= 1:
                self._pause(scene_wait)
                clip = {"x": box[0], "y": box[1], "width": box[2], "height": box[3], "scale": 1}
                for _ in range(1 + _SETTLE_SHOTS):    # until two shots in a row agree: the scene has drawn
                    shot = pipe.call("Page.captureScreenshot", {"format": "png", "clip": clip}, session,
                                     timeout=short + 10)
                    new = base64.b64decode(shot["data"])
                    settled, png = new == png, new
                    if settled:
                        break
                    self._pause(_SETTLE_PAUSE)
            report.scenes.append(SceneShot(index, box, png, rect["canvas"], rect["clipped"], settled))

    def _evaluate(self, session: str, function: str, *args: object, timeout: float, what: str) -> object:
        """Call the JavaScript ``function`` with ``args`` in the page and return its (awaited) value."""
        expression = f"({function})({', '.join(json.dumps(a) for a in args)})"
        try:
            result = self._pipe.call("Runtime.evaluate", {"expression": expression, "awaitPromise": True,
                                                          "returnByValue": True}, session, timeout=timeout)
        except TimeoutError:
            self._pipe.send("Runtime.terminateExecution", session=session)
            raise TimeoutError(f"the page did not answer within {timeout:g} s (asked for {what})") from None
        if "exceptionDetails" in result:
            details = result["exceptionDetails"]
            raise BrowserError("an inspection script failed in the page: "
                               f"{details.get('exception', {}).get('description') or details.get('text')}")
        return result["result"].get("value")

    def _pause(self, seconds: float) -> None:
        """Let real time pass while events keep being read."""
        try:
            self._pipe.wait(lambda: False, seconds)
        except TimeoutError:
            pass

    def _on_event(self, message: dict) -> None:
        state = self._page
        if state is None or message.get("sessionId") not in state.sessions:
            return
        state.handle(message, self._pipe)


class _PageState:
    """Events of one inspected page (its tab's session and the sessions of its child targets)."""

    def __init__(self, report: PageReport, sessions: set[str]) -> None:
        self.report = report
        self.top = next(iter(sessions))
        self.sessions = sessions
        self.loaded = self.crashed = False
        self.requests: dict[str, tuple[str, str]] = {}

    def handle(self, message: dict, pipe: DevToolsPipe) -> None:
        method, p, report = message["method"], message.get("params", {}), self.report
        if method == "Network.requestWillBeSent":
            self.requests[p["requestId"]] = (p["request"]["url"], p.get("type", ""))
        elif method == "Network.responseReceived" and p["response"].get("status", 0) >= 400:
            status = int(p["response"]["status"])
            report.failed_requests.append(FailedRequest(p["response"]["url"], f"HTTP {status}", status,
                                                        p.get("type", "")))
        elif method == "Network.loadingFailed":
            url, kind = self.requests.get(p["requestId"], ("(unknown URL)", p.get("type", "")))
            error = p.get("errorText", "") + (f" ({p['blockedReason']})" if p.get("blockedReason") else "")
            report.failed_requests.append(FailedRequest(url, error, None, kind, bool(p.get("canceled"))))
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            frames = (p.get("stackTrace") or {}).get("callFrames") or [{}]
            text = " ".join(_remote_text(a) for a in p.get("args", []))
            line = frames[0].get("lineNumber")
            report.console_errors.append(ConsoleMessage("console", text, frames[0].get("url", ""),
                                                        None if line is None else line + 1))
        elif method == "Log.entryAdded" and p["entry"].get("level") == "error":
            entry = p["entry"]
            line = entry.get("lineNumber")
            report.console_errors.append(ConsoleMessage(entry.get("source", "log"), entry.get("text", ""),
                                                        entry.get("url", ""), None if line is None else line + 1))
        elif method == "Runtime.exceptionThrown":
            d = p["exceptionDetails"]
            text = (d.get("exception") or {}).get("description") or d.get("text", "")
            line = d.get("lineNumber")
            report.console_errors.append(ConsoleMessage("exception", text, d.get("url", ""),
                                                        None if line is None else line + 1))
        elif method == "Page.loadEventFired" and message.get("sessionId") == self.top:
            self.loaded = True
        elif method == "Inspector.targetCrashed" and message.get("sessionId") == self.top:
            self.crashed = True
            report.console_errors.append(ConsoleMessage("crash", "the page's renderer process crashed"))
        elif method == "Page.javascriptDialogOpening":
            pipe.send("Page.handleJavaScriptDialog", {"accept": True}, message["sessionId"])
        elif method == "Target.attachedToTarget":
            child = p["sessionId"]
            self.sessions.add(child)
            page_like = p.get("targetInfo", {}).get("type") in ("iframe", "page")
            for command, params in _setup_commands(page=page_like):
                pipe.send(command, params, child)
            pipe.send("Runtime.runIfWaitingForDebugger", session=child)


def _setup_commands(page: bool) -> list[tuple[str, dict]]:
    """Commands that make a session report its network, console and exceptions, offline."""
    out = [("Network.enable", {}), ("Network.emulateNetworkConditions", _OFFLINE), ("Runtime.enable", {}),
           ("Log.enable", {})]
    if page:
        out += [("Page.enable", {}), ("Inspector.enable", {}),
                ("Target.setAutoAttach", {"autoAttach": True, "waitForDebuggerOnStart": True, "flatten": True})]
    return out


def _remote_text(obj: dict) -> str:
    """A console argument (a CDP ``RemoteObject``) as text."""
    if "value" in obj:
        return obj["value"] if isinstance(obj["value"], str) else json.dumps(obj["value"])
    return obj.get("description") or obj.get("unserializableValue") or obj.get("type", "")


def _pixels(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: expected an integer number of pixels, got {value!r:.60}")
    if not 64 <= value <= 8192:
        raise ValueError(f"{name}: expected 64 to 8192 pixels, got {value}")
    return int(value)


def _as_url(page: object) -> str:
    if isinstance(page, PathLike):
        path = Path(page)
        if not path.is_file():
            raise ValueError(f"page: expected an existing file or a URL, got the path {str(path)!r} (no such file)")
        return path.resolve().as_uri()
    if not isinstance(page, str):
        raise TypeError(f"page: expected a URL or a path (str or path-like), got {page!r:.60}")
    if "://" not in page and not page.startswith(("about:", "data:")):
        return _as_url(Path(page))
    return page
