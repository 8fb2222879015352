"""Gait schedules of a quadruped: when each leg is in stance, for a crawl and a trot.

A gait is a periodic pattern of stance and swing (McGhee & Frank 1968): a period ``T``, a duty
factor ``beta`` (the fraction of the cycle each foot is on the ground) and the phase of the cycle
at which each leg lifts. :class:`GaitSchedule` holds one; :func:`stance_pattern` says which feet
are down at any time; :func:`robokit.legged.gait.walking_plan` turns a schedule into a walk.

* :func:`crawl_gait` lifts one leg at a time in the order hind-left, front-left, hind-right,
  front-right (``beta >= 3/4``), the creeping sequence McGhee & Frank found the most stable.
* :func:`trot_gait` swings the diagonal pairs front-left + hind-right and front-right + hind-left
  (``beta = 1/2``).

Legs in the model's order ``("FL", "FR", "HL", "HR")``.

References
----------
.. [1] R. B. McGhee and A. A. Frank, "On the stability properties of quadruped creeping gaits",
   *Mathematical Biosciences* 3, 331-351, 1968.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..validation import as_array, as_positive, as_text, describe
from .littledog import LEGS

__all__ = ["GaitSchedule", "crawl_gait", "trot_gait", "stance_pattern", "as_gait_schedule", "CRAWL_SEQUENCE", "TROT_PAIRS"]

#: The crawl's lift-off order (McGhee & Frank's most stable creeping sequence).
CRAWL_SEQUENCE = ("HL", "FL", "HR", "FR")
#: The trot's diagonal pairs, each swinging together.
TROT_PAIRS = (("FL", "HR"), ("FR", "HL"))


@dataclasses.dataclass(frozen=True, eq=False)
class GaitSchedule:
    """A periodic gait: when each leg is in stance and how far and high it steps.

    Attributes
    ----------
    name : str
        ``"crawl"``, ``"trot"`` or your own.
    period : float
        Cycle time ``T`` (s): every leg lifts once per cycle.
    duty_factor : float
        ``beta`` in (0, 1): the fraction of the cycle each leg is on the ground; it swings for
        ``(1 - beta) T``.
    phase_offsets : numpy.ndarray, shape (4,)
        For each leg (order ``FL, FR, HL, HR``), the fraction of the cycle, in [0, 1), at which it
        lifts off. (McGhee & Frank measure a leg's phase at its touchdown, relative to a reference
        leg; touchdown follows lift-off by ``(1 - beta) T`` for every leg, so relative phases agree.)
    step_length : float
        How far (m) a foot moves forward in a steady-state swing, which is also how far the body
        advances per cycle (mean speed ``step_length / period``).
    step_height : float
        Peak lift (m) of a swinging foot above the line between its footholds (>= 0).

    Raises
    ------
    ValueError, TypeError
        For a non-positive period or step length, a duty factor outside (0, 1), a negative step
        height, or offsets that are not four numbers in [0, 1).

    Notes
    -----
    McGhee & Frank (1968), the gait as a duty factor and leg phases (unnumbered).
    :attr:`max_swinging` counts the legs in the air at once: 1 for a crawl (``beta >= 3/4`` with
    swings a quarter cycle apart), 2 for a trot.

    Examples
    --------
    >>> g = GaitSchedule("crawl", 3.2, 0.875, [0.25, 0.75, 0.0, 0.5], 0.08, 0.03)
    >>> g.swing_duration, g.max_swinging, g.speed
    (0.4, 1, 0.025)
    """

    name: str
    period: float
    duty_factor: float
    phase_offsets: np.ndarray
    step_length: float
    step_height: float

    def __post_init__(self) -> None:
        as_text(self.name, "name", empty=False)
        period = as_positive(self.period, "period")
        beta = as_positive(self.duty_factor, "duty_factor")
        if not beta < 1:
            raise ValueError(f"duty_factor: expected a fraction of the cycle in (0, 1), got {beta}")
        offsets = as_array(self.phase_offsets, "phase_offsets", shape=(4,)).copy()
        if not np.all((offsets >= 0) & (offsets < 1)):
            raise ValueError(f"phase_offsets: expected fractions of the cycle in [0, 1), got {offsets.tolist()}")
        offsets.setflags(write=False)
        for name, value in (("period", period), ("duty_factor", beta), ("phase_offsets", offsets),
                            ("step_length", as_positive(self.step_length, "step_length")),
                            ("step_height", as_positive(self.step_height, "step_height", allow_zero=True))):
            object.__setattr__(self, name, value)

    @property
    def swing_duration(self) -> float:
        """Seconds each swing takes: ``(1 - duty_factor) * period``."""
        return (1.0 - self.duty_factor) * self.period

    @property
    def speed(self) -> float:
        """Steady-state body speed (m/s): ``step_length / period``."""
        return self.step_length / self.period

    @property
    def max_swinging(self) -> int:
        """Most legs in the air at once (the count is largest just as some leg lifts)."""
        lag = np.mod(self.phase_offsets[:, None] - self.phase_offsets[None, :], 1.0)   # leg j's phase when i lifts
        return int(((lag < 1.0 - self.duty_factor - 1e-12) | (lag == 0)).sum(axis=1).max())


def crawl_gait(period: float = 4.0, step_length: float = 0.08, step_height: float = 0.03,
               duty_factor: float = 0.9) -> GaitSchedule:
    """The statically stable crawl: one leg at a time, hind-left, front-left, hind-right, front-right.

    Parameters
    ----------
    period : float, default 4.0
        Cycle time (s).
    step_length : float, default 0.08
        Forward step (m) of each foot per cycle; the body's mean speed is ``step_length / period``
        (0.02 m/s at the defaults). LittleDog's legs reach 0.08 m steps with 5 mm to spare.
    step_height : float, default 0.03
        Foot lift (m).
    duty_factor : float, default 0.9
        At least 0.75, so that swings never overlap. Above 0.75 there is a four-foot phase of
        ``(duty_factor - 0.75) * period`` between swings, in which
        :func:`robokit.legged.gait.walking_plan` shifts the body (0.6 s of shift and 0.4 s of swing
        per leg at the defaults: the trunk accelerates at most 0.6 m/s^2).

    Returns
    -------
    GaitSchedule
        Lift-off phases 0 (HL), 1/4 (FL), 1/2 (HR), 3/4 (FR).

    Raises
    ------
    ValueError
        For a duty factor below 0.75 (two legs would be up at once) or the schedule's own errors.

    Notes
    -----
    McGhee & Frank (1968) prove that of the six leg sequences of a regular creeping gait with
    ``beta >= 3/4``, the one in which each hind leg is followed by the front leg on its own side
    (left hind, left front, right hind, right front) has the largest longitudinal stability
    margin (unnumbered).

    Examples
    --------
    >>> g = crawl_gait()
    >>> dict(zip(("FL", "FR", "HL", "HR"), g.phase_offsets.tolist()))
    {'FL': 0.25, 'FR': 0.75, 'HL': 0.0, 'HR': 0.5}
    """
    beta = as_positive(duty_factor, "duty_factor")
    if not beta >= 0.75:
        raise ValueError(f"duty_factor: expected >= 0.75 for a crawl (one leg up at a time), got {beta}")
    offsets = np.zeros(4)
    offsets[[LEGS.index(leg) for leg in CRAWL_SEQUENCE]] = [0.0, 0.25, 0.5, 0.75]
    return GaitSchedule("crawl", period, beta, offsets, step_length, step_height)


def trot_gait(period: float = 0.5, step_length: float = 0.06, step_height: float = 0.03,
              duty_factor: float = 0.5) -> GaitSchedule:
    """The trot: diagonal pairs swing together, front-left with hind-right, front-right with hind-left.

    Parameters
    ----------
    period : float, default 0.5
        Cycle time (s).
    step_length : float, default 0.06
        Forward step (m) per cycle; mean speed ``step_length / period`` (0.12 m/s at the defaults).
    step_height : float, default 0.03
        Foot lift (m).
    duty_factor : float, default 0.5
        In [0.5, 1): 0.5 hands the weight from one pair to the other at once; more gives a brief
        four-foot phase at each hand-over.

    Returns
    -------
    GaitSchedule
        Lift-off phases 0 (FL, HR) and 1/2 (FR, HL).

    Raises
    ------
    ValueError
        For a duty factor below 0.5 (a flight phase: running, not walking) or the schedule's own
        errors.

    Notes
    -----
    McGhee & Frank (1968) classify gaits by duty factor and leg phases (unnumbered); the trot's
    diagonal legs share a phase.

    Examples
    --------
    >>> trot_gait().phase_offsets.tolist()
    [0.0, 0.5, 0.5, 0.0]
    """
    beta = as_positive(duty_factor, "duty_factor")
    if not beta >= 0.5:
        raise ValueError(f"duty_factor: expected >= 0.5 for a walking trot (no flight phase), got {beta}")
    offsets = np.zeros(4)
    for phase, pair in zip((0.0, 0.5), TROT_PAIRS):
        offsets[[LEGS.index(leg) for leg in pair]] = phase
    return GaitSchedule("trot", period, beta, offsets, step_length, step_height)


def as_gait_schedule(schedule: Any) -> GaitSchedule:
    """Return ``schedule`` if it is a :class:`GaitSchedule`.

    Raises
    ------
    TypeError
        Otherwise, naming the argument ``schedule``.

    Examples
    --------
    >>> as_gait_schedule(trot_gait()).name
    'trot'
    """
    if not isinstance(schedule, GaitSchedule):
        raise TypeError(f"schedule: expected a GaitSchedule (crawl_gait(), trot_gait()), got {describe(schedule)}")
    return schedule


def stance_pattern(schedule: GaitSchedule, t: Any) -> np.ndarray:
    """Which legs are on the ground at times ``t`` of a periodic gait.

    Parameters
    ----------
    schedule : GaitSchedule
    t : array_like, shape (N,) or scalar
        Gait time (s); leg ``i`` lifts at ``(phase_offsets[i] + k) * period`` for every integer k.

    Returns
    -------
    numpy.ndarray of bool, shape (N, 4)
        ``True`` where the leg is in stance (a scalar ``t`` gives one row).

    Raises
    ------
    ValueError, TypeError
        For a schedule that is not a :class:`GaitSchedule` or non-finite times.

    Notes
    -----
    McGhee & Frank (1968), unnumbered: leg ``i`` is in swing while its phase
    ``u = (t / T - phase_offsets[i]) mod 1`` is below ``1 - beta``, in stance for the remaining
    fraction ``beta`` of the cycle.

    Examples
    --------
    >>> stance_pattern(trot_gait(), [0.0, 0.3]).astype(int)
    array([[0, 1, 1, 0],
           [1, 0, 0, 1]])
    """
    schedule = as_gait_schedule(schedule)
    times = as_array(t, "t")
    if times.ndim > 1:
        raise ValueError(f"t: expected a scalar or shape (N,), got shape {times.shape}")
    u = np.mod(times.reshape(-1, 1) / schedule.period - schedule.phase_offsets, 1.0)
    return ~(u < 1.0 - schedule.duty_factor)
