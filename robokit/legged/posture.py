"""A host that reacts: the trunk's pose fed back from the MoCap into the set-points it sends.

LittleDog's host computer sees the robot through the Vicon system and sends joint set-points
every 10 ms (LittleDog User Guide, Secs. 1-2). A host that only plays a plan never uses what it
sees; :class:`PostureFeedback` closes that loop. Every host cycle it compares the trunk's pose the
MoCap reports with the plan's, and integrates the error into a correction of the body pose the leg
IK assumes:

``u_k = clip(u_{k-1} + g dt e_k)``,  ``e_k = [p_est - p_plan, log(R_plan^T R_est)]``,

and the set-points are the IK of the planned feet seen from the body pose
``p_plan - u_p``, ``R_plan exp(-u_r)``. With the feet on the ground, legs solved for a body that is
higher than planned push the real body up: a trunk that sags, rolls or lags is brought back to its
plan (the height, the balance over the support polygon, the attitude). Only the axes named in
``axes`` are corrected.

Why latency now matters: the correction acts on the trunk a link delay and a host period after the
error was seen. For a loop ``e_{k+1} = e_k - a e_{k-d}`` (``a = g dt``, a delay of ``d`` host
cycles) the error dies out only if ``a < 2 sin(pi / (2 (2 d + 1)))`` (the root locus of
``z^{d+1} - z^d + a``): 1.0 for one cycle of delay, 0.28 for five (50 ms). A gain chosen for a
fast link makes the trunk oscillate over a slow one; a lost packet adds to the delay. A fixed plan
has no such loop, so it is indifferent to latency in this sense.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Secs. 1-2 (the host, the MoCap
   and the link).
.. [2] G. F. Franklin, J. D. Powell and M. Workman, *Digital Control of Dynamic Systems*, 3rd ed.,
   Addison-Wesley, 1998, Sec. 4.3 (stability of a sampled loop with delay).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import so3_exp, so3_log
from ..validation import as_int, as_positive

__all__ = ["POSTURE_AXES", "PostureFeedback", "delay_gain_limit"]

POSTURE_AXES = ("x", "y", "z", "roll", "pitch", "yaw")
"""The six axes of the trunk's pose: world position, then rotation about the body's x, y, z."""


def delay_gain_limit(delay_cycles: int) -> float:
    """Largest per-cycle gain ``a = g dt`` for which the integrating loop with a delay is stable.

    Parameters
    ----------
    delay_cycles : int
        Host cycles between seeing an error and its correction acting (>= 0).

    Returns
    -------
    float
        ``2 sin(pi / (2 (2 d + 1)))``: the loop ``e_{k+1} = e_k - a e_{k-d}`` decays for
        ``0 < a`` below it (Franklin, Powell & Workman 1998, Sec. 4.3, applied to
        ``z^{d+1} - z^d + a = 0``).

    Raises
    ------
    ValueError, TypeError
        For a negative or non-integer delay.

    Examples
    --------
    >>> round(delay_gain_limit(0), 6), round(delay_gain_limit(1), 6), round(delay_gain_limit(5), 4)
    (2.0, 1.0, 0.2846)
    """
    d = as_int(delay_cycles, "delay_cycles", minimum=0)
    return float(2.0 * np.sin(np.pi / (2 * (2 * d + 1))))


@dataclass(frozen=True)
class PostureFeedback:
    """The host's integral feedback on the trunk pose (LittleDog User Guide, Secs. 1-2).

    Parameters
    ----------
    gain : float, default 20
        Integral gain ``g`` (1/s): each host cycle removes ``g dt`` of the error seen (0.2 at the
        guide's 100 Hz). Positive.
    axes : tuple of str, default ("z", "roll", "pitch")
        Which of :data:`POSTURE_AXES` are corrected: by default the trunk's height and attitude.
    limit : (float, float), default (0.03, 0.2)
        Largest correction of a position axis (m) and of an angle (rad): the legs' reach bounds it.

    Examples
    --------
    >>> PostureFeedback(gain=50.0).axes
    ('z', 'roll', 'pitch')
    >>> PostureFeedback(axes=("z", "heave"))
    Traceback (most recent call last):
    ...
    ValueError: axes: expected names among ('x', 'y', 'z', 'roll', 'pitch', 'yaw'), got ('z', 'heave')
    """

    gain: float = 20.0
    axes: tuple = ("z", "roll", "pitch")
    limit: tuple = (0.03, 0.2)

    def __post_init__(self):
        as_positive(self.gain, "gain")
        if (not isinstance(self.axes, tuple) or not self.axes or len(set(self.axes)) != len(self.axes)
                or any(a not in POSTURE_AXES for a in self.axes)):
            raise ValueError(f"axes: expected names among {POSTURE_AXES}, got {self.axes!r}")
        if not isinstance(self.limit, (tuple, list)) or len(self.limit) != 2:
            raise ValueError(f"limit: expected (metres, radians), got {self.limit!r}")
        as_positive(self.limit[0], "limit[0] (m)")
        as_positive(self.limit[1], "limit[1] (rad)")

    def start(self, dt: float) -> "_PostureLoop":
        """A fresh loop state for a walk whose host runs every ``dt`` seconds (> 0): an object with
        ``command(T_plan, T_est)`` (the body pose the IK should assume this cycle; ``T_est`` None
        when the MoCap has no pose) and ``u``, the correction so far (:data:`POSTURE_AXES` order)."""
        return _PostureLoop(self, as_positive(dt, "dt"))


class _PostureLoop:
    """One walk's running correction of :class:`PostureFeedback` (made by ``feedback.start(dt)``, which
    validates; the host loop's kernel trusts its rigid (4, 4) inputs).

    Attributes
    ----------
    u : numpy.ndarray, shape (6,)
        The current correction, ordered as :data:`POSTURE_AXES` (m, rad).
    """

    def __init__(self, feedback: PostureFeedback, dt: float):
        self.rate = feedback.gain * dt
        self.mask = np.array([a in feedback.axes for a in POSTURE_AXES], float)
        self.bound = np.repeat(np.asarray(feedback.limit, float), 3)
        self.u = np.zeros(6)

    def command(self, T_plan: np.ndarray, T_est: np.ndarray | None) -> np.ndarray:
        """The body pose the IK should assume this cycle, after folding in the error of ``T_est``.

        ``T_est`` None (no MoCap pose this cycle) keeps the correction as it is. Internal kernel of
        the host loop: trusts its (4, 4) rigid inputs.
        """
        if T_est is not None:
            e = np.concatenate([T_est[:3, 3] - T_plan[:3, 3],
                                so3_log(T_plan[:3, :3].T @ T_est[:3, :3], validate=False)])
            self.u = np.clip(self.u + self.rate * self.mask * e, -self.bound, self.bound)
        T = T_plan.copy()
        T[:3, 3] -= self.u[:3]
        T[:3, :3] = T_plan[:3, :3] @ so3_exp(-self.u[3:], validate=False)
        return T
