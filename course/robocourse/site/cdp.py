"""Headless Chromium driven through the Chrome DevTools Protocol over a pipe (no websocket).

:class:`DevToolsPipe` starts Chromium with ``--remote-debugging-pipe``: Chromium reads commands
from its file descriptor 3 and writes responses and events to its descriptor 4, each message a
JSON object followed by a NUL byte. A small trampoline (``python -c``) moves the two pipe ends onto
descriptors 3 and 4 before Chromium starts, so no ``preexec_fn`` runs in a possibly threaded parent.
Chromium runs in its own process group, which :meth:`DevToolsPipe.close` kills (also when the
object is garbage collected or the interpreter exits), and in a throw-away profile directory.

The network is cut at launch (every host name resolves to "not found"), on top of the per-page
offline emulation that :mod:`robocourse.site.browser` adds.
"""
from __future__ import annotations

import json
import math
import numbers
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time
import weakref
from pathlib import Path
from typing import Any, Callable, Sequence

from robocourse.site.execute import kill_process_group

__all__ = ["find_chromium", "DevToolsPipe", "BrowserError", "CHROMIUM_NAMES", "as_seconds"]

#: Executable names tried, in order, by :func:`find_chromium`.
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome")

#: Flags that work headless in a container (no GPU, no sandbox) and keep Chromium quiet and offline.
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--no-default-browser-check", "--disable-background-networking", "--disable-component-update",
         "--disable-sync", "--disable-dev-shm-usage", "--mute-audio", "--enable-unsafe-swiftshader",
         "--host-resolver-rules=MAP * ~NOTFOUND", "--remote-debugging-pipe")

# Runs in the child: move the pipe ends (argv 1, 2) onto descriptors 3 and 4, then become Chromium.
_TRAMPOLINE = ("import os, sys\n"
               "r, w = int(sys.argv[1]), int(sys.argv[2])\n"
               "a, b = os.dup(r), os.dup(w)\n"
               "os.dup2(a, 3); os.dup2(b, 4)\n"
               "os.set_inheritable(3, True); os.set_inheritable(4, True)\n"   # dup2(3, 3) keeps close-on-exec
               "for fd in {a, b, r, w} - {3, 4}: os.close(fd)\n"
               "os.execv(sys.argv[3], sys.argv[3:])\n")


class BrowserError(RuntimeError):
    """Chromium is missing, failed to start, died, or answered a command with an error."""


def as_seconds(value: Any, name: str, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a finite, positive (or zero, if allowed) number of seconds.

    The course tooling sits beside :mod:`robokit.validation` in the layers, not above it, so it
    checks its few arguments itself; the messages follow the same pattern.

    Raises
    ------
    TypeError
        If ``value`` is not a real number (booleans and strings are refused).
    ValueError
        If it is negative, zero (unless ``allow_zero``), NaN or infinite.

    Examples
    --------
    >>> as_seconds(2, "timeout")
    2.0
    >>> as_seconds(-1, "timeout")
    Traceback (most recent call last):
    ...
    ValueError: timeout: expected a positive, finite number of seconds, got -1
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a number of seconds, got {value!r:.60}")
    out = float(value)
    if not math.isfinite(out) or out < 0 or (out == 0 and not allow_zero):
        want = "non-negative" if allow_zero else "positive"
        raise ValueError(f"{name}: expected a {want}, finite number of seconds, got {value!r}")
    return out


def _text(value: Any, name: str) -> str:
    if not isinstance(value, str) or not value:
        raise TypeError(f"{name}: expected a non-empty str, got {value!r:.60}")
    return value


def find_chromium(names: Sequence[str] = CHROMIUM_NAMES) -> str:
    """Return the path of the first Chromium executable on ``PATH`` among ``names``.

    Parameters
    ----------
    names : sequence of str
        Executable names to look for, in order.

    Returns
    -------
    str
        The full path.

    Raises
    ------
    BrowserError
        If none is found; the message says how to install one.

    Examples
    --------
    >>> find_chromium(["no-such-browser"])
    Traceback (most recent call last):
    ...
    robocourse.site.cdp.BrowserError: no Chromium found on PATH (looked for no-such-browser); ...
    """
    if isinstance(names, str) or not isinstance(names, Sequence):
        raise TypeError(f"names: expected a sequence of executable names, got {names!r:.60}")
    for name in names:
        found = shutil.which(_text(name, "names[i]"))
        if found:
            return found
    raise BrowserError(f"no Chromium found on PATH (looked for {', '.join(names)}); install the Debian "
                       "package 'chromium' (.ci/run does) or pass the executable's path")


def _kill(proc: subprocess.Popen, profile: str, fds: tuple[int, ...]) -> None:
    """Kill Chromium's process group (it leads its own session), close our pipe ends, remove its profile."""
    kill_process_group(proc)
    for fd in fds:
        try:
            os.close(fd)
        except OSError:
            pass
    shutil.rmtree(profile, ignore_errors=True)


class DevToolsPipe:
    """A running headless Chromium and its DevTools pipe.

    Parameters
    ----------
    executable : str or None
        Chromium's path; ``None`` looks for one with :func:`find_chromium`.
    args : sequence of str
        Extra command-line flags, after :data:`FLAGS`.
    timeout : float
        Seconds to wait for Chromium to answer its first command.

    Attributes
    ----------
    on_event : callable or None
        Called with each event message (a dict with ``method``, ``params`` and, for a page,
        ``sessionId``) as it arrives, while :meth:`call` or :meth:`wait` read the pipe. It may
        :meth:`send` commands, but not :meth:`call`.

    Examples
    --------
    >>> with DevToolsPipe() as pipe:                     # doctest: +SKIP
    ...     pipe.call("Browser.getVersion")["product"]
    'HeadlessChrome/156.0.8078.114'
    """

    def __init__(self, executable: str | None = None, *, args: Sequence[str] = (), timeout: float = 30.0) -> None:
        exe = find_chromium() if executable is None else _text(executable, "executable")
        if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
            raise BrowserError(f"executable: {exe!r} is not an executable file")
        if isinstance(args, str) or not all(isinstance(a, str) for a in args):
            raise TypeError(f"args: expected a sequence of str flags, got {args!r:.60}")
        as_seconds(timeout, "timeout")
        self.on_event: Callable[[dict], Any] | None = None
        self._next_id = 0
        self._buffer = bytearray()
        self._replies: dict[int, dict] = {}
        self._profile = tempfile.mkdtemp(prefix="robokit-chromium-")
        to_chrome_r, self._to_chrome = os.pipe()
        self._from_chrome, from_chrome_w = os.pipe()
        self._log = Path(self._profile) / "stderr.txt"
        try:
            with open(self._log, "wb") as log:
                self._proc = subprocess.Popen(
                    [sys.executable, "-I", "-S", "-c", _TRAMPOLINE, str(to_chrome_r), str(from_chrome_w), exe,
                     *FLAGS, f"--user-data-dir={self._profile}", *args],
                    pass_fds=(to_chrome_r, from_chrome_w), stdin=subprocess.DEVNULL, stdout=log, stderr=log,
                    start_new_session=True)
        except BaseException:
            for fd in (to_chrome_r, from_chrome_w, self._to_chrome, self._from_chrome):
                os.close(fd)
            shutil.rmtree(self._profile, ignore_errors=True)
            raise
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self._finalizer = weakref.finalize(self, _kill, self._proc, self._profile,
                                          (self._to_chrome, self._from_chrome))
        try:
            self.version = self.call("Browser.getVersion", timeout=timeout)
        except BaseException:
            self.close()
            raise

    # -- messages ---------------------------------------------------------------------------------
    def send(self, method: str, params: dict | None = None, session: str | None = None) -> int:
        """Send a command without waiting; return its id (its reply is kept for :meth:`reply`)."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        data = json.dumps(message).encode() + b"\0"
        try:
            while data:
                data = data[os.write(self._to_chrome, data):]
        except OSError as exc:
            raise BrowserError(f"Chromium stopped reading commands ({exc}){self._stderr_tail()}") from exc
        return self._next_id

    def call(self, method: str, params: dict | None = None, session: str | None = None, *,
             timeout: float = 30.0) -> dict:
        """Send a command and return its result, dispatching events that arrive meanwhile.

        Raises
        ------
        BrowserError
            If Chromium answers with an error or exits.
        TimeoutError
            If no answer comes within ``timeout`` seconds.
        """
        ident = self.send(method, params, session)
        self.wait(lambda: ident in self._replies, timeout, f"{method} got no answer")
        reply = self._replies.pop(ident)
        if "error" in reply:
            raise BrowserError(f"{method} failed: {reply['error'].get('message')} {reply['error'].get('data', '')}")
        return reply.get("result", {})

    def reply(self, ident: int) -> dict | None:
        """The reply to a command sent with :meth:`send`, if it has arrived (and forget it)."""
        return self._replies.pop(ident, None)

    def wait(self, done: Callable[[], bool], timeout: float, what: str = "condition") -> None:
        """Read the pipe, dispatching events, until ``done()`` is true; ``TimeoutError`` after
        ``timeout`` seconds (the message says ``what`` was awaited)."""
        if not callable(done):
            raise TypeError(f"done: expected a callable, got {done!r:.60}")
        as_seconds(timeout, "timeout", allow_zero=True)
        deadline = time.monotonic() + timeout
        while not done():
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError(f"{what} within {timeout:g} s")
            self._read(left)

    def _read(self, timeout: float) -> None:
        ready, _, _ = select.select([self._from_chrome], [], [], timeout)
        if not ready:
            return
        chunk = os.read(self._from_chrome, 1 << 20)
        if not chunk:
            code = self._proc.poll()
            how = "still running" if code is None else f"exit code {code}"
            raise BrowserError(f"Chromium closed its DevTools pipe ({how}){self._stderr_tail()}")
        self._buffer += chunk
        *messages, rest = self._buffer.split(b"\0")
        self._buffer = bytearray(rest)
        for raw in messages:
            message = json.loads(raw)
            if "id" in message:
                self._replies[message["id"]] = message
                if len(self._replies) > 1000:          # replies to fire-and-forget commands nobody reads
                    for old in sorted(self._replies)[:500]:
                        del self._replies[old]
            elif self.on_event is not None:
                self.on_event(message)

    def _stderr_tail(self) -> str:
        try:
            lines = self._log.read_text(errors="replace").strip().splitlines()[-5:]
        except OSError:
            return ""
        return (": " + " | ".join(lines)) if lines else ""

    # -- lifetime ---------------------------------------------------------------------------------
    @property
    def pid(self) -> int:
        """Process id of Chromium (the leader of its process group)."""
        return self._proc.pid

    def close(self) -> None:
        """Ask Chromium to quit, then kill its process group and delete its profile (idempotent)."""
        if not self._finalizer.alive:
            return
        if self._proc.poll() is None:
            try:
                self.send("Browser.close")
                self._proc.wait(timeout=5)
            except (BrowserError, subprocess.TimeoutExpired):
                pass
        self._finalizer()

    def __enter__(self) -> "DevToolsPipe":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
