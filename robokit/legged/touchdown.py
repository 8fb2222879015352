"""Touchdown detection from the LittleDog's foot force sensors, and its score against the truth.

Each lower leg carries a single-axis force sensor "capable of detecting touchdown events and
measuring approximate lower leg axial forces" (LittleDog User Guide, Sec. 3). A raw threshold on
a noisy trace chatters: a foot that bounces, or noise near the threshold, gives many touchdowns
for one. :func:`detect_contacts` uses the two standard remedies, a hysteresis (Schmitt trigger:
contact begins above ``threshold_on`` and ends below ``threshold_off < threshold_on``) and a
debounce (a change counts only once ``debounce`` consecutive samples agree), and pays for them
with a delay. :func:`contact_events` lists touchdowns (no contact -> contact) and
:func:`event_precision_recall` scores detected touchdowns against the true ones (MuJoCo's
contacts) within a tolerance.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Sec. 3).
.. [2] O. H. Schmitt, "A thermionic trigger", *Journal of Scientific Instruments* 15(1), 24-26,
   1938 (the hysteresis comparator).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..validation import as_array, check_finite_scalar, check_int

__all__ = ["EventScore", "detect_contacts", "contact_events", "event_precision_recall"]


class EventScore(NamedTuple):
    """How detected touchdowns compare with the true ones."""

    #: Matched detections / detections (1.0 when nothing was detected).
    precision: float
    #: Matched true touchdowns / true touchdowns (1.0 when there were none).
    recall: float
    #: Mean of (detected - true) sample index over the matches (0.0 without matches).
    mean_delay_samples: float


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


def _bool_contacts(value: Any, name: str) -> np.ndarray:
    c = as_array(value, name, dtype=bool)
    if c.ndim not in (1, 2):
        raise ValueError(f"{name}: expected shape (N,) or (N, L), got shape {c.shape}")
    return c


def contact_events(contact: Any) -> np.ndarray | list[np.ndarray]:
    """Sample indices of the touchdowns (no contact -> contact) in contact states.

    Parameters
    ----------
    contact : array_like of bool, shape (N,) or (N, L)

    Returns
    -------
    numpy.ndarray of int, or list of L of them
        For (N,): the indices ``k >= 1`` with ``contact[k]`` and not ``contact[k - 1]`` (a foot
        already down at sample 0 is no event). For (N, L): one such array per leg (column).

    Raises
    ------
    ValueError
        For a shape other than (N,) or (N, L).
    TypeError
        For values that are not booleans (or 0/1 integers).

    Notes
    -----
    Rising edges of a binary signal; not from a paper.

    Examples
    --------
    >>> contact_events([False, True, True, False, True]).tolist()
    [1, 4]
    >>> [e.tolist() for e in contact_events([[True, False], [False, True], [True, True]])]
    [[2], [1]]
    """
    c = _bool_contacts(contact, "contact")
    rising = np.zeros(c.shape, bool)
    rising[1:] = c[1:] & ~c[:-1]
    if c.ndim == 1:
        return np.flatnonzero(rising)
    return [np.flatnonzero(rising[:, j]) for j in range(c.shape[1])]


def _match(detected: np.ndarray, truth: np.ndarray, tol: int) -> np.ndarray:
    """Delays (detected - true) of a maximum matching: each true event takes the earliest detection still
    free within ``[t - tol, t + tol]``. Both index arrays are sorted."""
    delays, j = [], 0
    for t in truth:
        while j < len(detected) and detected[j] < t - tol:
            j += 1                                   # too early for this and every later true event
        if j < len(detected) and detected[j] <= t + tol:
            delays.append(int(detected[j] - t))
            j += 1
    return np.array(delays, dtype=float)


def event_precision_recall(detected: Any, truth: Any, tolerance: int) -> EventScore:
    """Precision, recall and mean delay of detected touchdowns against the true ones.

    Parameters
    ----------
    detected, truth : array_like of bool, shape (N,) or (N, L)
        Contact states per sample (and leg): e.g. :func:`detect_contacts` of the force traces and
        MuJoCo's foot contacts. Their touchdowns are :func:`contact_events`.
    tolerance : int
        Largest ``|detected - true|`` (samples, >= 0) for a detection to count for a true touchdown.

    Returns
    -------
    EventScore
        ``precision`` = matched / detected touchdowns, ``recall`` = matched / true touchdowns,
        ``mean_delay_samples`` = mean of (detected - true) over the matches (positive: late),
        counted over all legs together. Conventions for empty sets: precision 1.0 without
        detections, recall 1.0 without true touchdowns, mean delay 0.0 without matches.

    Raises
    ------
    ValueError
        For shapes that differ or are not (N,) or (N, L), or a negative ``tolerance``.
    TypeError
        For contact states that are not booleans (or 0/1 integers).

    Notes
    -----
    Each true touchdown is matched to at most one detection and each detection to at most one
    true touchdown. Taking, in time order, for each true touchdown the earliest free detection in
    its window gives a matching of maximum size, because all windows have the same width (the
    greedy argument of interval scheduling). Precision and recall as in information retrieval;
    the matching rule is ours.

    Examples
    --------
    True touchdowns at 2 and 8; detections at 3 (1 sample late), 5 (a bounce) and 8:

    >>> truth = np.zeros(12, bool); truth[2:6] = True; truth[8:11] = True
    >>> found = np.zeros(12, bool); found[3:4] = True; found[5:6] = True; found[8:11] = True
    >>> event_precision_recall(found, truth, tolerance=2)
    EventScore(precision=0.6666666666666666, recall=1.0, mean_delay_samples=0.5)
    """
    d = _bool_contacts(detected, "detected")
    t = _bool_contacts(truth, "truth")
    if t.shape != d.shape:
        raise ValueError(f"truth: expected shape {d.shape} (that of detected), got shape {t.shape}")
    tol = check_int(tolerance, "tolerance", minimum=0)
    ev_d, ev_t = contact_events(d), contact_events(t)
    if d.ndim == 1:
        ev_d, ev_t = [ev_d], [ev_t]
    delays = np.concatenate([_match(a, b, tol) for a, b in zip(ev_d, ev_t)])
    n_det, n_true = sum(len(a) for a in ev_d), sum(len(b) for b in ev_t)
    precision = len(delays) / n_det if n_det else 1.0
    recall = len(delays) / n_true if n_true else 1.0
    return EventScore(float(precision), float(recall), float(delays.mean()) if len(delays) else 0.0)
