"""Touchdowns from the LittleDog's foot force sensors, and their score against the truth.

Each lower leg carries a single-axis force sensor "capable of detecting touchdown events and
measuring approximate lower leg axial forces" (LittleDog User Guide, Sec. 3). A raw threshold on
a noisy trace chatters: a foot that bounces, or noise near the threshold, gives many touchdowns
for one. :func:`detect_contacts` uses the two standard remedies, a hysteresis (Schmitt trigger:
contact begins above ``threshold_on`` and ends below ``threshold_off < threshold_on``) and a
debounce (a change counts only once ``debounce`` consecutive samples agree), and pays for them
with a delay.

A touchdown is a rising edge of a foot's contact state (:func:`contact_events`). A detector's
touchdowns are scored against the true ones (MuJoCo's contacts, or a synthetic trace's generator)
by matching each true touchdown to at most one detection within a tolerance: :func:`score_events`
on sample indices, :func:`event_precision_recall` on contact states.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Sec. 3).
.. [2] O. H. Schmitt, "A thermionic trigger", *Journal of Scientific Instruments* 15(1), 24-26,
   1938 (the hysteresis comparator).
.. [3] C. J. van Rijsbergen, *Information Retrieval*, 2nd ed., Butterworths, 1979, Ch. 7
   (precision and recall).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..validation import as_array, as_finite_scalar, as_int, describe

__all__ = ["detect_contacts", "gate_touchdowns", "EventScore", "contact_events", "match_events", "score_events",
           "score_leg_events", "event_precision_recall"]


class EventScore(NamedTuple):
    """How detected touchdowns compare with the true ones."""

    #: Matched detections / detections (1.0 when nothing was detected).
    precision: float
    #: Matched true touchdowns / true touchdowns (1.0 when there were none).
    recall: float
    #: Mean of (detected - true) sample index over the matches (0.0 without matches).
    mean_delay_samples: float


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


def _pairs(detected: np.ndarray, truth: np.ndarray, tol: int) -> np.ndarray:
    """Unchecked :func:`match_events` on sorted index arrays."""
    pairs, j = [], 0
    for t in truth:
        while j < len(detected) and detected[j] < t - tol:
            j += 1                                   # too early for this and every later true event
        if j < len(detected) and detected[j] <= t + tol:
            pairs.append((int(detected[j]), int(t)))
            j += 1
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def _match(detected: np.ndarray, truth: np.ndarray, tol: int) -> np.ndarray:
    """Delays (detected - true) of the matching of :func:`match_events`."""
    p = _pairs(detected, truth, tol)
    return (p[:, 0] - p[:, 1]).astype(float)


def match_events(detected: Any, truth: Any, tolerance: int) -> np.ndarray:
    """Pair detected events with true (or expected) ones: each takes the earliest free detection near it.

    Parameters
    ----------
    detected, truth : array_like of int, shape (K,)
        Sample indices (whole numbers >= 0, any order: sorted here).
    tolerance : int
        Largest ``|detected - true|`` (samples, >= 0) for a pair.

    Returns
    -------
    numpy.ndarray of int, shape (P, 2)
        ``(detected, true)`` index pairs in time order; each index is used at most once.

    Notes
    -----
    Taking, in time order, for each true event the earliest free detection in its window gives a
    matching of maximum size, because all windows have the same width (the greedy argument of
    interval scheduling); ours, not from a paper.

    Examples
    --------
    >>> match_events([3, 5, 8], [2, 8], tolerance=2).tolist()
    [[3, 2], [8, 8]]
    """
    d, t = _indices(detected, "detected"), _indices(truth, "truth")
    return _pairs(d, t, as_int(tolerance, "tolerance", minimum=0))


def _score(delays: np.ndarray, n_detected: int, n_true: int) -> EventScore:
    precision = len(delays) / n_detected if n_detected else 1.0
    recall = len(delays) / n_true if n_true else 1.0
    return EventScore(float(precision), float(recall), float(delays.mean()) if len(delays) else 0.0)


def _indices(value: Any, name: str) -> np.ndarray:
    idx = as_array(value, name, ndim=1, dtype=np.int64)
    if np.any(idx < 0):
        raise ValueError(f"{name}: expected sample indices >= 0, got {int(idx.min())}")
    return np.sort(idx)


def score_events(detected: Any, truth: Any, tolerance: int) -> EventScore:
    """Precision, recall and mean delay of detected touchdowns, given as sample indices.

    Parameters
    ----------
    detected, truth : array_like of int, shape (K,)
        Sample indices of the detected and of the true touchdowns of one foot, in any order
        (sorted here); whole numbers, ``>= 0``. A repeated detection counts twice (and can match
        only once).
    tolerance : int
        Largest ``|detected - true|`` (samples, >= 0) for a detection to count for a true touchdown.

    Returns
    -------
    EventScore
        ``precision`` = matched / detected, ``recall`` = matched / true, ``mean_delay_samples`` =
        mean of (detected - true) over the matches (positive: late). Without detections the
        precision is 1.0, without true touchdowns the recall is 1.0, without matches the delay 0.0.

    Raises
    ------
    ValueError
        For indices that are negative, fractional or not 1-D, NaN, or a negative ``tolerance``.
    TypeError
        For values that are not numbers, or a ``tolerance`` that is not an integer.

    Notes
    -----
    Each true touchdown is matched to at most one detection and each detection to at most one
    true touchdown. Taking, in time order, for each true touchdown the earliest free detection in
    its window gives a matching of maximum size, because all windows have the same width (the
    greedy argument of interval scheduling). Precision and recall as in van Rijsbergen (1979),
    Ch. 7 (unnumbered); the matching rule is ours.

    Examples
    --------
    True touchdowns at 2 and 8; detections at 3 (1 sample late), 5 (a bounce) and 8:

    >>> score_events([3, 5, 8], [2, 8], tolerance=2)
    EventScore(precision=0.6666666666666666, recall=1.0, mean_delay_samples=0.5)
    """
    d, t = _indices(detected, "detected"), _indices(truth, "truth")
    tol = as_int(tolerance, "tolerance", minimum=0)
    return _score(_match(d, t, tol), len(d), len(t))


def score_leg_events(detected: Any, truth: Any, tolerance: int) -> EventScore:
    """:func:`score_events` counted over several legs: one list of touchdown indices per leg.

    Parameters
    ----------
    detected, truth : sequence of array_like of int
        One entry per leg (the same number of legs in both), each as in :func:`score_events`.
    tolerance : int

    Returns
    -------
    EventScore
        Matches, detections and true touchdowns summed over the legs (a detection can only match a
        touchdown of its own leg).

    Examples
    --------
    >>> score_leg_events([[3, 5, 8], [10]], [[2, 8], [30]], tolerance=2)
    EventScore(precision=0.5, recall=0.6666666666666666, mean_delay_samples=0.5)
    """
    tol = as_int(tolerance, "tolerance", minimum=0)
    if isinstance(detected, (str, bytes, np.ndarray)) or isinstance(truth, (str, bytes, np.ndarray)) or \
            not hasattr(detected, "__len__") or not hasattr(truth, "__len__") or len(detected) != len(truth):
        raise ValueError("detected, truth: expected two lists with one array of indices per leg, as many legs in "
                         f"each, got {describe(detected)} and {describe(truth)}")
    d = [_indices(a, f"detected[{i}]") for i, a in enumerate(detected)]
    t = [_indices(b, f"truth[{i}]") for i, b in enumerate(truth)]
    delays = np.concatenate([_match(a, b, tol) for a, b in zip(d, t)] + [np.zeros(0)])
    return _score(delays, sum(len(a) for a in d), sum(len(b) for b in t))


def event_precision_recall(detected: Any, truth: Any, tolerance: int) -> EventScore:
    """Precision, recall and mean delay of detected touchdowns against the true ones, from contact states.

    Parameters
    ----------
    detected, truth : array_like of bool, shape (N,) or (N, L)
        Contact states per sample (and leg): e.g. :func:`robokit.legged.touchdown.detect_contacts`
        of the force traces and MuJoCo's foot contacts. Their touchdowns are :func:`contact_events`.
    tolerance : int
        Largest ``|detected - true|`` (samples, >= 0) for a detection to count for a true touchdown.

    Returns
    -------
    EventScore
        As :func:`score_events`, counted over all legs together (a detection can only match a true
        touchdown of its own leg).

    Raises
    ------
    ValueError
        For shapes that differ or are not (N,) or (N, L), or a negative ``tolerance``.
    TypeError
        For contact states that are not booleans (or 0/1 integers).

    Notes
    -----
    The matching of :func:`score_events` leg by leg; precision and recall as in van Rijsbergen
    (1979), Ch. 7 (unnumbered).

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
    ev_d, ev_t = contact_events(d), contact_events(t)
    if d.ndim == 1:
        ev_d, ev_t = [ev_d], [ev_t]
    return score_leg_events(ev_d, ev_t, tolerance)


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
    on = as_finite_scalar(threshold_on, "threshold_on")
    off = as_finite_scalar(threshold_off, "threshold_off")
    if not off < on:
        raise ValueError(f"threshold_off: expected a value below threshold_on = {on}, got {off}")
    count = as_int(debounce, "debounce", minimum=1)
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
        :func:`robokit.legged.touchdown.match_events`.

    Examples
    --------
    >>> gate_touchdowns([3, 40, 52, 95], [50, 100], 10).tolist()
    [40, 95]
    """
    return match_events(detected, expected, as_int(window, "window", minimum=0))[:, 0]
