"""The heading servo of a skid-steer truck: its loop, gains by pole placement, the discrete controller.

Plant: a yaw-rate command ``u`` reaches the wheels through the motors' first-order lag, so the
heading obeys ``theta(s) / u(s) = g / (s (tau s + 1))`` (``g`` = 1 when the slip model is right;
:mod:`robokit.outdoor.truck`). Controller: proportional on the heading error plus rate feedback
(derivative on the measurement), ``u = kp (theta_ref - theta) - kd dtheta/dt``. That loop, an
integrator plus a first-order lag under PD, is also a geared joint under a voltage (lesson 04), so
it is modelled once, in :mod:`robokit.controllers.servo_loop`; the ``heading_*`` functions here are
that module's, under the names lesson 05 uses (``tau`` the motor lag, ``gain`` the slip factor),
and :func:`loop_metrics` is re-exported from it. Its closed loop is exactly second order
(Franklin, Powell & Emami-Naeini 2015, Sec. 4.3),

    T(s) = g kp / (tau s^2 + (1 + g kd) s + g kp),

so ``kp`` and ``kd`` place its poles for a chosen overshoot ``M`` and settling time ``Ts`` with
the standard relations ``zeta = -ln M / sqrt(pi^2 + ln^2 M)`` and ``omega_n = 4 / (zeta Ts)``, the
settling time to within 2 % of the final value (Nise 2015, Sec. 4.6; Franklin, Powell &
Emami-Naeini 2015, Sec. 3.4, use the 1 % criterion ``4.6 / (zeta omega_n)`` instead). The 2 %
criterion is also python-control's default in :func:`loop_metrics`. Hamid et al. (2009) steer by
the compass bearing but do not give their control law; this design is ours.

References
----------
.. [1] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015.
.. [2] N. S. Nise, *Control Systems Engineering*, 7th ed., Wiley, 2015.
.. [3] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..config import lazy_module
from ..geometry import wrap_angle
from ..validation import as_finite_scalar, as_positive
from .servo_loop import (loop_metrics, servo_closed_loop, servo_frequency_response, servo_loop_gain, servo_plant,
                         servo_step_response)

control = lazy_module("control")   # python-control, loaded on first use (0.75 s of every import otherwise)

__all__ = ["design_heading_gains", "HeadingController", "heading_plant", "heading_closed_loop", "heading_loop_gain",
           "heading_step_response", "heading_frequency_response", "loop_metrics"]


def design_heading_gains(tau: float, overshoot: float, settling_time: float, gain: float = 1.0) -> np.ndarray:
    """Gains ``[kp, kd]`` that give the closed loop a chosen overshoot and 2 % settling time.

    Parameters
    ----------
    tau : float
        Motor time constant (s).
    overshoot : float
        Fractional overshoot of the step response, in (0, 1) (e.g. 0.05 for 5 %).
    settling_time : float
        2 % settling time (s).
    gain : float, default 1
        Plant gain ``g``.

    Returns
    -------
    numpy.ndarray
        ``[kp, kd]`` with ``kp = tau omega_n^2 / g`` and ``kd = (2 zeta omega_n tau - 1) / g``.

    Raises
    ------
    ValueError
        Out-of-range arguments, or a spec so slow (``settling_time > 8 tau``) that it would need
        ``kd = (8 tau / settling_time - 1) / gain < 0`` (positive rate feedback): ask for a shorter
        settling time.

    Notes
    -----
    Matching ``tau s^2 + (1 + g kd) s + g kp`` with ``tau (s^2 + 2 zeta omega_n s + omega_n^2)``;
    ``zeta`` from the overshoot and ``omega_n`` from the 2 % settling time ``4 / (zeta omega_n)``
    (Nise 2015, Sec. 4.6).

    Examples
    --------
    >>> np.round(design_heading_gains(0.3, overshoot=0.05, settling_time=1.5), 3).tolist()
    [4.479, 0.6]
    """
    t = as_positive(tau, "tau")
    m = as_positive(overshoot, "overshoot")
    if not m < 1:
        raise ValueError(f"overshoot: expected a fraction in (0, 1), got {m}")
    ts = as_positive(settling_time, "settling_time")
    g = as_positive(gain, "gain")
    zeta = -math.log(m) / math.sqrt(math.pi ** 2 + math.log(m) ** 2)    # Nise Sec. 4.6, overshoot
    wn = 4.0 / (zeta * ts)                                              # Nise Sec. 4.6, 2 % settling
    kp = t * wn ** 2 / g                                                # tau omega_n^2 = g kp
    kd = (2 * zeta * wn * t - 1) / g                                    # 2 zeta omega_n tau = 1 + g kd
    if kd < 0:
        raise ValueError(f"settling_time: expected a spec the plant cannot meet unaided (kd >= 0), got "
                         f"settling_time={ts} which needs kd={kd:.3g}; choose a shorter settling time")
    return np.array([kp, kd])


class HeadingController:
    """Discrete heading controller: ``u = kp * wrap(ref - theta) - kd * rate``, saturated.

    Parameters
    ----------
    kp, kd : float
        Gains from :func:`design_heading_gains`.
    max_rate : float
        Saturation of the yaw-rate command (rad/s).
    rate_filter : float, default 0.1
        Time constant (s) of the first-order filter on the heading-difference rate estimate.

    Notes
    -----
    Rate from successive compass headings (finite difference, low-pass filtered); Franklin et al.
    (2015), Sec. 8.3 (emulation of a continuous design).

    Examples
    --------
    >>> ctl = HeadingController(4.479, 0.6, max_rate=3.0)
    >>> ctl.command(reference=0.5, heading=0.0), ctl.command(reference=2.0, heading=0.0)   # saturated
    (2.2395, 3.0)
    """

    def __init__(self, kp: float, kd: float, max_rate: float, rate_filter: float = 0.1) -> None:
        self.kp = as_positive(kp, "kp")
        self.kd = as_positive(kd, "kd", allow_zero=True)
        self.max_rate = as_positive(max_rate, "max_rate")
        self.rate_filter = as_positive(rate_filter, "rate_filter", allow_zero=True)
        self.reset()

    def reset(self) -> None:
        """Forget the previous heading and rate (start of a new manoeuvre)."""
        self._last: float | None = None
        self.rate = 0.0

    def measure(self, heading: float, dt: float) -> None:
        """Feed a new heading measurement (rad, CCW) taken ``dt`` seconds after the previous one.

        Notes
        -----
        Backward difference plus first-order low-pass (Franklin et al. 2015, Sec. 8.3).
        """
        h = as_finite_scalar(heading, "heading")
        if self._last is not None:
            raw = wrap_angle(h - self._last) / as_positive(dt, "dt")
            a = dt / (dt + self.rate_filter) if self.rate_filter else 1.0
            self.rate += a * (raw - self.rate)
        self._last = h

    def command(self, reference: float, heading: float) -> float:
        """Yaw-rate command (rad/s) to turn ``heading`` towards ``reference`` (both rad, CCW).

        Notes
        -----
        Proportional action on the wrapped error plus rate feedback, saturated (Franklin et al.
        2015, Sec. 4.3).
        """
        u = self.kp * wrap_angle(reference - heading) - self.kd * self.rate
        return float(min(max(u, -self.max_rate), self.max_rate))


def heading_plant(tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Transfer function from yaw-rate command to heading, ``g / (s (tau s + 1))``: :func:`~.servo_loop.servo_plant`.

    Parameters
    ----------
    tau : float
        Motor time constant (s, > 0), from :class:`robokit.outdoor.truck.SkidSteerTruck`.
    gain : float, default 1
        Ratio of true to modelled yaw rate (slip and track uncertainty).

    Notes
    -----
    First-order actuator plus integrator (Franklin et al. 2015, Sec. 3.1).

    Examples
    --------
    >>> heading_plant(0.3).den[0][0].tolist()      # 0.3 s^2 + s
    [0.3, 1.0, 0.0]
    """
    return servo_plant(tau, gain)


def heading_closed_loop(kp: float, kd: float, tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Closed loop ``theta / theta_ref`` with rate feedback: :func:`~.servo_loop.servo_closed_loop`.

    Notes
    -----
    ``g kp / (tau s^2 + (1 + g kd) s + g kp)``; Franklin et al. (2015), Sec. 4.3.

    Examples
    --------
    >>> heading_closed_loop(4.0, 0.5, 0.3).den[0][0].tolist()
    [0.3, 1.5, 4.0]
    """
    return servo_closed_loop(kp, kd, tau, gain)


def heading_loop_gain(kp: float, kd: float, tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Loop gain broken at the yaw-rate command, for margins: :func:`~.servo_loop.servo_loop_gain`.

    Notes
    -----
    ``L(s) = (kp + kd s) g / (s (tau s + 1))``; Franklin et al. (2015), Sec. 6.4.

    Examples
    --------
    >>> heading_loop_gain(4.0, 0.5, 0.3).num[0][0].tolist()    # (0.5 s + 4) / (0.3 s^2 + s)
    [0.5, 4.0]
    """
    return servo_loop_gain(kp, kd, tau, gain)


def heading_step_response(kp: float, kd: float, tau: float, gain: float = 1.0,
                          duration: float = 4.0, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Unit-step response ``(t, theta)`` of the heading loop: :func:`~.servo_loop.servo_step_response`.

    Notes
    -----
    ``control.step_response`` on the closed loop of Franklin et al. (2015), Sec. 3.4.

    Examples
    --------
    >>> t, theta = heading_step_response(4.479, 0.6, 0.3)
    >>> len(t), round(float(theta.max()), 3), round(float(theta[-1]), 3)     # 5 % overshoot, settled
    (400, 1.05, 1.0)
    """
    return servo_step_response(kp, kd, tau, gain, duration, n)


def heading_frequency_response(kp: float, kd: float, tau: float, omega: Any, gain: float = 1.0) -> np.ndarray:
    """Complex loop gain ``L(j omega)`` at ``omega`` (rad/s), for Bode plots: :func:`~.servo_loop.servo_frequency_response`.

    Notes
    -----
    Franklin et al. (2015), Sec. 6.1 (frequency response).

    Examples
    --------
    >>> np.round(np.abs(heading_frequency_response(4.479, 0.6, 0.3, [3.434])), 3).tolist()   # at crossover
    [1.0]
    """
    return servo_frequency_response(kp, kd, tau, omega, gain)
