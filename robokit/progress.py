"""Progress bars for the steps a student waits for: one tqdm helper for the whole library.

Live (a notebook or a terminal) a step shows tqdm's own bar; headless (the course build, the tests)
it prints one final line; in fast mode it is quiet (:func:`robokit.config.fast_mode`,
:func:`robokit.config.headless`).
"""
from __future__ import annotations

import os
import time
from typing import Callable

from .config import fast_mode, headless
from .validation import as_int

__all__ = ["ProgressBar", "progress_bar"]


class ProgressBar:
    """A progress bar for a step a student waits for; see :func:`progress_bar`.

    Call it as ``bar(done, total)`` (the ``progress`` callback protocol of robokit's long steps) or
    ``bar.update(n)``; close it (or use it as a context manager) when the step ends.
    """

    def __init__(self, total: int, desc: str, unit: str, mode: str, callback: Callable | None):
        self.total, self.desc, self.unit, self.mode, self.callback = total, desc, unit, mode, callback
        self.done = 0
        self._bar = None
        self._closed = False
        if mode == "live":
            from tqdm.auto import tqdm

            self._bar = tqdm(total=total, desc=desc, unit=unit, leave=True)
        self._start = time.perf_counter()

    def __call__(self, done: int, total: int | None = None) -> None:
        if total is not None and total != self.total:
            self.total = int(total)
            if self._bar is not None:
                self._bar.total = self.total
        step = int(done) - self.done
        self.done = int(done)
        if self._bar is not None and step:
            self._bar.update(step)
        if self.callback is not None:
            self.callback(self.done, self.total)

    def update(self, n: int = 1) -> None:
        """Advance the bar by ``n`` steps."""
        self(self.done + int(n))

    def line(self) -> str:
        """The bar's current state as one line of text (what a saved notebook shows)."""
        from tqdm import tqdm

        elapsed = time.perf_counter() - self._start
        return tqdm.format_meter(self.done, self.total, elapsed, prefix=self.desc, unit=self.unit, ncols=80)

    def close(self) -> None:
        """End the bar: a live one stays as it is; a headless one prints its one final line."""
        if self._closed:
            return
        self._closed = True
        if self._bar is not None:
            self._bar.close()
        elif self.mode == "line":
            print(self.line(), flush=True)

    def __enter__(self) -> "ProgressBar":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def progress_bar(total: int, desc: str, *, unit: str = "step", callback: Callable | None = None,
                 environ: "os._Environ[str] | dict[str, str] | None" = None) -> ProgressBar:
    """A tqdm progress bar for a step that takes more than a few seconds, in one place for robokit.

    Live (a student's notebook or terminal) it is tqdm's own bar (``tqdm.auto``: a widget in
    Jupyter, text in a terminal). Headless (``ROBOKIT_HEADLESS=1``: the course build, the tests) it
    prints one line when the step ends, the bar's final state with its time, so an executed
    notebook and the course site show one clean line instead of hundreds of updates (and no
    widget, whose JavaScript the site does not run). In fast mode (``ROBOKIT_FAST=1``) it is quiet.

    Parameters
    ----------
    total : int
        Steps in all (at least 0).
    desc : str
        What is being done, e.g. ``"mapping the lab"``.
    unit : str, default "step"
        What one step is (``"frame"``, ``"trial"``).
    callback : callable, optional
        A caller's own ``progress(done, total)``, called on every step too.
    environ : mapping, optional
        Environment to read (default :data:`os.environ`).

    Returns
    -------
    ProgressBar
        Call it as ``bar(done, total)`` or ``bar.update()``; use it as a context manager.

    Raises
    ------
    ValueError
        For a negative ``total`` or an empty ``desc`` or ``unit``.
    TypeError
        For a ``total`` that is not an integer (numpy integers are) or a ``callback`` that is not
        callable.

    Notes
    -----
    Course convention (issue 17: progress bars on every step a student waits for); not from a paper.

    Examples
    --------
    >>> with progress_bar(3, "counting", unit="number", environ={"ROBOKIT_HEADLESS": "1"}) as bar:
    ...     for k in range(3):
    ...         bar.update()                                # doctest: +ELLIPSIS
    counting: 100%|...| 3/3 [...]
    >>> with progress_bar(3, "counting", environ={"ROBOKIT_FAST": "1"}) as bar:
    ...     bar(3, 3)
    >>> bar.done
    3
    """
    total = as_int(total, "total", minimum=0)
    for name, value in (("desc", desc), ("unit", unit)):
        if not isinstance(value, str) or not value.strip():
            raise ValueError(f"{name}: expected a non-empty string, got {value!r}")
    if callback is not None and not callable(callback):
        raise TypeError(f"callback: expected a callable progress(done, total) or None, got {type(callback).__name__}")
    if fast_mode(environ):
        mode = "quiet"
    elif headless(environ):
        mode = "line"
    else:
        mode = "live"
    return ProgressBar(total, desc, unit, mode, callback)
