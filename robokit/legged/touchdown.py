"""Touchdown detection from the LittleDog's foot force sensors: hysteresis and debounce.

Each lower leg carries a single-axis force sensor "capable of detecting touchdown events and
measuring approximate lower leg axial forces" (LittleDog User Guide, Sec. 3). A raw threshold on
a noisy trace chatters: a foot that bounces, or noise near the threshold, gives many touchdowns
for one. :func:`detect_contacts` uses the two standard remedies, a hysteresis (Schmitt trigger:
contact begins above ``threshold_on`` and ends below ``threshold_off < threshold_on``) and a
debounce (a change counts only once ``debounce`` consecutive samples agree), and pays for them
with a delay. :mod:`robokit.legged.event_scoring` lists touchdowns (no contact -> contact,
:func:`~robokit.legged.event_scoring.contact_events`) and scores them against the true ones
(:func:`~robokit.legged.event_scoring.event_precision_recall`); it lives apart from the detector so
that assignment 04's grading worker can score a student's detector without holding this one.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Sec. 3).
.. [2] O. H. Schmitt, "A thermionic trigger", *Journal of Scientific Instruments* 15(1), 24-26,
   1938 (the hysteresis comparator).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, check_finite_scalar, check_int
from .event_scoring import match_events

__all__ = ["detect_contacts", "gate_touchdowns"]


def _forward_fill(defined: np.ndarray, values: np.ndarray, first: np.ndarray) -> np.ndarray:
    """``values`` where ``defined``, else the last defined value before (``first`` before any), along axis 0."""
    n = len(values)
    idx = np.where(defined, np.arange(n).reshape((n,) + (1,) * (values.ndim - 1)), -1)
    idx = np.maximum.accumulate(idx, axis=0)
    out = np.take_along_axis(values, np.maximum(idx, 0), axis=0)
    return np.where(idx >= 0, out, first)


def detect_contacts(force: Any, threshold_on: float, threshold_off: float, debounce: int = 1) -> np.ndarray:
    """Contact states from foot force traces: hysteresis, then debounce.

    Parameters
    ----------
    force : array_like, shape (N,) or (N, L)
        Axial foot force per sample (N), one column per leg.
    threshold_on : float
        A sample above it (N) says "contact".
    threshold_off : float
        A sample below it (N) says "no contact"; must be below ``threshold_on``. Between the two
        the state stays as it was.
    debounce : int, default 1
        Consecutive samples (>= 1) the hysteresis state must keep a new value before the output
        takes it; 1 accepts a change at once.

    Returns
    -------
    numpy.ndarray of bool, shape of ``force``
        The debounced contact state.

    Raises
    ------
    ValueError
        For a force that is not 1-D or 2-D or has NaN/inf, ``threshold_off >= threshold_on``, or a
        ``debounce`` below 1.

    Notes
    -----
    The hysteresis state ``h[k]`` is the verdict of the last sample that was above
    ``threshold_on`` (True) or below ``threshold_off`` (False), and False before any (a Schmitt
    trigger, Schmitt 1938). The output copies ``h[k]`` when ``h[k - debounce + 1 .. k]`` all
    agree and otherwise keeps its previous value; the first sample sets it at once.
    **Delay**: a touchdown or lift-off is reported ``debounce - 1`` samples after the hysteresis
    saw it (at the LittleDog's 100 Hz host rate, ``(debounce - 1) * 10`` ms), on top of the time
    the force needs to cross the threshold. A bounce shorter than ``debounce`` samples is ignored.
    Both steps are vectorised (forward fills of indices), without a loop over samples.

    Examples
    --------
    A touchdown with a bounce (the dip to 1 N at sample 4) and noise near the thresholds:

    >>> f = [0.0, 0.5, 4.0, 6.0, 1.0, 6.0, 7.0, 2.5, 7.0, 0.5, 0.2, 0.1]
    >>> detect_contacts(f, 3.0, 2.0).astype(int).tolist()                 # hysteresis only
    [0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 0, 0]
    >>> detect_contacts(f, 3.0, 2.0, debounce=2).astype(int).tolist()     # the bounce is gone, 1 sample late
    [0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 0, 0]
    """
    f = as_array(force, "force")
    if f.ndim not in (1, 2):
        raise ValueError(f"force: expected shape (N,) or (N, L), got shape {f.shape}")
    on = check_finite_scalar(threshold_on, "threshold_on")
    off = check_finite_scalar(threshold_off, "threshold_off")
    if not off < on:
        raise ValueError(f"threshold_off: expected a value below threshold_on = {on}, got {off}")
    count = check_int(debounce, "debounce", minimum=1)
    if len(f) == 0:
        return np.zeros(f.shape, bool)
    decisive = (f > on) | (f < off)
    h = _forward_fill(decisive, f > on, np.zeros(f.shape[1:], bool))          # Schmitt trigger
    n = len(h)
    changed = np.ones(h.shape, bool)
    changed[1:] = h[1:] != h[:-1]
    start = np.maximum.accumulate(np.where(changed, np.arange(n).reshape((n,) + (1,) * (h.ndim - 1)), 0), axis=0)
    settled = np.arange(n).reshape(start.shape[:1] + (1,) * (h.ndim - 1)) - start + 1 >= count
    settled[0] = True                                                          # the first sample sets the state
    return _forward_fill(settled, h, h[0])


def gate_touchdowns(detected: Any, expected: Any, window: int) -> np.ndarray:
    """Keep the detected touchdowns the gait plan expects: the first one near each planned touchdown.

    A host that planned the swing knows when each foot should land. A detection far from any
    planned touchdown (a loaded foot that reads almost nothing mid-stance, then recovers) is then
    not believed, and one planned touchdown accepts only one detection.

    Parameters
    ----------
    detected : array_like of int, shape (K,)
        Sample indices of the detected touchdowns of one foot (whole numbers >= 0).
    expected : array_like of int, shape (M,)
        Sample indices of its planned touchdowns.
    window : int
        Samples (>= 0) a detection may lie before or after a planned touchdown.

    Returns
    -------
    numpy.ndarray of int, shape (<= M,)
        For each planned touchdown, the first free detection within ``window`` of it (none if
        there is none); each detection is used once: the detected side of
        :func:`robokit.legged.event_scoring.match_events`.

    Examples
    --------
    >>> gate_touchdowns([3, 40, 52, 95], [50, 100], 10).tolist()
    [40, 95]
    """
    return match_events(detected, expected, check_int(window, "window", minimum=0))[:, 0]
