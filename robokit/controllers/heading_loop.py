"""The heading servo loop of a skid-steer vehicle as transfer functions, and its figures of merit.

Plant: a yaw-rate command ``u`` reaches the wheels through the motors' first-order lag, so the
heading obeys ``theta(s) / u(s) = g / (s (tau s + 1))`` (``g`` = 1 when the slip model is right;
:mod:`robokit.outdoor.truck`). Controller: proportional on the heading error plus rate feedback
(derivative on the measurement), ``u = kp (theta_ref - theta) - kd dtheta/dt``, which makes the
closed loop exactly second order (Franklin, Powell & Emami-Naeini 2015, Sec. 4.3). This module
models and measures that loop with python-control (step response, margins, frequency response);
choosing the gains is :func:`robokit.controllers.heading.design_heading_gains`.

It holds no exercise reference, so graded notebooks may import :func:`loop_metrics` (assignment
05 declares it in ``HELPERS``; the grading worker provides it).

References
----------
.. [1] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015.
.. [2] N. S. Nise, *Control Systems Engineering*, 7th ed., Wiley, 2015.
.. [3] The python-control developers, *python-control: the Python Control Systems Library*,
   version 0.10, https://python-control.org.
"""
from __future__ import annotations

import math
from typing import Any

import control
import numpy as np

from ..validation import as_array, check_int, check_positive

__all__ = ["heading_plant", "heading_closed_loop", "heading_loop_gain", "heading_step_response",
           "heading_frequency_response", "loop_metrics"]

def heading_plant(tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Transfer function from yaw-rate command to heading, ``g / (s (tau s + 1))``.

    Parameters
    ----------
    tau : float
        Motor time constant (s, > 0).
    gain : float, default 1
        Ratio of true to modelled yaw rate (slip and track uncertainty).

    Returns
    -------
    control.TransferFunction

    Notes
    -----
    First-order actuator plus integrator (Franklin et al. 2015, Sec. 3.1); motor lag from
    :class:`robokit.outdoor.truck.SkidSteerTruck`.

    Examples
    --------
    >>> heading_plant(0.3).den[0][0].tolist()      # 0.3 s^2 + s
    [0.3, 1.0, 0.0]
    """
    t = check_positive(tau, "tau")
    g = check_positive(gain, "gain")
    return control.tf([g], [t, 1.0, 0.0])


def heading_closed_loop(kp: float, kd: float, tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Closed loop ``theta / theta_ref`` with rate feedback: ``g kp / (tau s^2 + (1 + g kd) s + g kp)``.

    Notes
    -----
    Franklin et al. (2015), Sec. 4.3 (derivative on the output avoids the closed-loop zero of PD
    control).

    Examples
    --------
    >>> heading_closed_loop(4.0, 0.5, 0.3).den[0][0].tolist()
    [0.3, 1.5, 4.0]
    """
    p = check_positive(kp, "kp")
    d = check_positive(kd, "kd", allow_zero=True)
    t = check_positive(tau, "tau")
    g = check_positive(gain, "gain")
    return control.tf([g * p], [t, 1 + g * d, g * p])


def heading_loop_gain(kp: float, kd: float, tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Loop gain broken at the plant input, ``L(s) = (kp + kd s) g / (s (tau s + 1))``, for margins.

    Notes
    -----
    Franklin et al. (2015), Sec. 6.4 (gain and phase margins of the loop transfer function).

    Examples
    --------
    >>> heading_loop_gain(4.0, 0.5, 0.3).num[0][0].tolist()    # (0.5 s + 4) / (0.3 s^2 + s)
    [0.5, 4.0]
    """
    p = check_positive(kp, "kp")
    d = check_positive(kd, "kd", allow_zero=True)
    return control.tf([d, p], [1.0]) * heading_plant(tau, gain)


_UNSIMULATED = "{names}: expected a loop python-control can simulate, got a NaN step response (values too large?)"


def heading_step_response(kp: float, kd: float, tau: float, gain: float = 1.0,
                          duration: float = 4.0, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Unit-step response ``(t, theta)`` of :func:`heading_closed_loop` over ``duration`` seconds.

    Notes
    -----
    ``control.step_response`` (python-control 0.10) on the closed loop of Franklin et al. (2015),
    Sec. 3.4.

    Examples
    --------
    >>> t, theta = heading_step_response(4.479, 0.6, 0.3)
    >>> len(t), round(float(theta.max()), 3), round(float(theta[-1]), 3)     # 5 % overshoot, settled
    (400, 1.05, 1.0)
    """
    T = heading_closed_loop(kp, kd, tau, gain)
    t = np.linspace(0.0, check_positive(duration, "duration"), max(check_int(n, "n", minimum=0), 2))
    resp = control.step_response(T, t)
    y = np.asarray(resp.outputs).ravel()
    if np.isnan(y).any():
        raise ValueError(_UNSIMULATED.format(names="kp, kd, tau, gain, duration"))
    return np.asarray(resp.time), y


def heading_frequency_response(kp: float, kd: float, tau: float, omega: Any, gain: float = 1.0) -> np.ndarray:
    """Complex loop gain ``L(j omega)`` of :func:`heading_loop_gain` at frequencies ``omega`` (rad/s), for Bode plots.

    Notes
    -----
    Franklin et al. (2015), Sec. 6.1 (frequency response).

    Examples
    --------
    >>> np.round(np.abs(heading_frequency_response(4.479, 0.6, 0.3, [3.434])), 3).tolist()   # at crossover
    [1.0]
    """
    w = as_array(omega, "omega")
    if w.ndim > 1:
        raise ValueError(f"omega: expected a frequency or a 1-D array of them, got shape {w.shape}")
    if np.any(w <= 0):
        raise ValueError("omega: expected positive frequencies in rad/s")
    return np.asarray(heading_loop_gain(kp, kd, tau, gain)(1j * w))


def loop_metrics(kp: float, kd: float, tau: float, gain: float = 1.0, delay: float = 0.0) -> dict:
    """Step-response and stability-margin figures of the heading loop, from python-control.

    Parameters
    ----------
    kp, kd, tau, gain : float
        As in :func:`heading_closed_loop`.
    delay : float, default 0
        Extra loop delay (s), e.g. half the compass sample period, modelled by a first-order Pade
        approximation; included in both the step response and the margins.

    Returns
    -------
    dict
        ``overshoot`` (fraction), ``settling_time`` and ``rise_time`` (s), ``gain_margin``
        (ratio, ``inf`` if none), ``phase_margin_deg`` and ``crossover`` (rad/s).

    Notes
    -----
    ``control.step_info`` and ``control.stability_margins`` (python-control 0.10); overshoot and
    margins as in Franklin et al. (2015), Secs. 3.4 and 6.4; the settling time is to within 2 %
    (python-control's default; Nise 2015, Sec. 4.6), the criterion :func:`design_heading_gains` uses.

    Examples
    --------
    >>> kp, kd = 4.479, 0.6      # design_heading_gains(0.3, overshoot=0.05, settling_time=1.5), rounded
    >>> m = loop_metrics(kp, kd, 0.3)
    >>> round(m["overshoot"], 3), round(m["phase_margin_deg"]), m["gain_margin"]
    (0.05, 69, inf)
    >>> round(loop_metrics(kp, kd, 0.3, delay=0.05)["phase_margin_deg"])    # a 50 ms delay costs margin
    59
    """
    L = heading_loop_gain(kp, kd, tau, gain)
    dly = check_positive(delay, "delay", allow_zero=True)
    if dly > 0:
        num, den = control.pade(dly, 1)
        pade = control.tf(num, den)
        L = L * pade
        plant = heading_plant(tau, gain) * pade
        # theta/ref with rate feedback: kp P / (1 + (kp + kd s) P)
        T = control.feedback(kp * plant, control.tf([kd, kp], [kp]), sign=-1) if kp > 0 else plant
    else:
        T = heading_closed_loop(kp, kd, tau, gain)
    try:
        info = control.step_info(T)
    except IndexError:      # python-control's step_info on a response that is NaN throughout
        raise ValueError(_UNSIMULATED.format(names="kp, kd, tau, gain, delay")) from None
    gm, pm, _, _, wc = control.stability_margins(L)[:5]
    return {"overshoot": float(info["Overshoot"]) / 100.0, "settling_time": float(info["SettlingTime"]),
            "rise_time": float(info["RiseTime"]), "gain_margin": float(gm) if gm is not None else math.inf,
            "phase_margin_deg": float(pm), "crossover": float(wc)}
