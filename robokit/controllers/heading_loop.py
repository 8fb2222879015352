"""The heading servo loop of a skid-steer vehicle, in the heading lesson's names.

Plant: a yaw-rate command ``u`` reaches the wheels through the motors' first-order lag, so the
heading obeys ``theta(s) / u(s) = g / (s (tau s + 1))`` (``g`` = 1 when the slip model is right;
:mod:`robokit.outdoor.truck`). Controller: proportional on the heading error plus rate feedback
(derivative on the measurement), ``u = kp (theta_ref - theta) - kd dtheta/dt``, which makes the
closed loop exactly second order (Franklin, Powell & Emami-Naeini 2015, Sec. 4.3). That loop, an
integrator plus a first-order lag under PD, is also a geared joint under a voltage (lesson 04), so
it is modelled once, in :mod:`robokit.controllers.servo_loop`; the functions here are that
module's, under the names lesson 05 uses (``tau`` the motor lag, ``gain`` the slip factor), and
:func:`loop_metrics` is re-exported from it. Choosing the gains is
:func:`robokit.controllers.heading.design_heading_gains`.

References
----------
.. [1] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015.
"""
from __future__ import annotations

from typing import Any

import control
import numpy as np

from .servo_loop import (loop_metrics, servo_closed_loop, servo_frequency_response, servo_loop_gain, servo_plant,
                         servo_step_response)

__all__ = ["heading_plant", "heading_closed_loop", "heading_loop_gain", "heading_step_response",
           "heading_frequency_response", "loop_metrics"]


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
