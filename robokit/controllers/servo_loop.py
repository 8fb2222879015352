"""An integrator plus a first-order lag under PD control, continuous and sampled: models and figures of merit.

Plant: an input ``u`` drives the output through a first-order lag and an integrator,
``y(s) / u(s) = g / (s (tau s + 1))`` (Franklin, Powell & Emami-Naeini 2015, Sec. 3.1). Two lessons
meet it: the heading of a skid-steer truck under a yaw-rate command (``tau`` the motors' lag, ``g``
the slip; :mod:`robokit.controllers.heading`) and a geared DC-motor joint under a voltage
(``K / (s (J s + B))``, so ``g = K / B`` and ``tau = J / B``; :mod:`robokit.controllers.joint_servo`).

Controller: proportional on the error plus rate feedback (derivative on the measurement),
``u = kp (y_ref - y) - kd dy/dt``, which makes the continuous closed loop exactly second order,

    T(s) = g kp / (tau s^2 + (1 + g kd) s + g kp)

(Franklin et al. 2015, Sec. 4.3). Run by a computer every ``dt`` seconds, the same law is
``u_k = kp (y_ref - y_k) - kd (y_k - y_{k-1}) / dt`` and the plant, seen through a zero-order hold,
is ``control.c2d(P, dt, "zoh")`` (Franklin et al. 2015, Sec. 8.3). :func:`loop_metrics` measures the
continuous loop; :func:`discrete_servo_analysis` the sampled one (poles, margins, bandwidth, step),
and it reports an unstable loop instead of raising.

References
----------
.. [1] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015.
.. [2] N. S. Nise, *Control Systems Engineering*, 7th ed., Wiley, 2015.
.. [3] The python-control developers, *python-control: the Python Control Systems Library*,
   version 0.10, https://python-control.org.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any, NamedTuple

import numpy as np
from scipy.optimize import brentq

from ..config import lazy_module
from ..validation import as_array, as_int, as_positive, require_sample_count

control = lazy_module("control")   # python-control, loaded on first use (0.75 s of every import otherwise)

__all__ = ["MIN_DT_OVER_TAU", "servo_plant", "servo_closed_loop", "servo_loop_gain", "servo_step_response", "servo_frequency_response",
           "loop_metrics", "DiscreteServoLoop", "discrete_servo_loop", "ServoAnalysis", "discrete_servo_analysis"]


def servo_plant(tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Transfer function of an integrator plus a first-order lag, ``g / (s (tau s + 1))``.

    Parameters
    ----------
    tau : float
        Time constant of the lag (s, > 0).
    gain : float, default 1
        Steady-state rate per unit input ``g`` (> 0).

    Returns
    -------
    control.TransferFunction

    Notes
    -----
    First-order actuator plus integrator (Franklin et al. 2015, Sec. 3.1).

    Examples
    --------
    >>> servo_plant(0.3).den[0][0].tolist()      # 0.3 s^2 + s
    [0.3, 1.0, 0.0]
    """
    t = as_positive(tau, "tau")
    g = as_positive(gain, "gain")
    return control.tf([g], [t, 1.0, 0.0])


def servo_closed_loop(kp: float, kd: float, tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Closed loop ``y / y_ref`` with rate feedback: ``g kp / (tau s^2 + (1 + g kd) s + g kp)``.

    Notes
    -----
    Franklin et al. (2015), Sec. 4.3 (derivative on the output avoids the closed-loop zero of PD
    control).

    Examples
    --------
    >>> servo_closed_loop(4.0, 0.5, 0.3).den[0][0].tolist()
    [0.3, 1.5, 4.0]
    """
    p = as_positive(kp, "kp")
    d = as_positive(kd, "kd", allow_zero=True)
    t = as_positive(tau, "tau")
    g = as_positive(gain, "gain")
    return control.tf([g * p], [t, 1 + g * d, g * p])


def servo_loop_gain(kp: float, kd: float, tau: float, gain: float = 1.0) -> control.TransferFunction:
    """Loop gain broken at the plant input, ``L(s) = (kp + kd s) g / (s (tau s + 1))``, for margins.

    Notes
    -----
    Franklin et al. (2015), Sec. 6.4 (gain and phase margins of the loop transfer function).

    Examples
    --------
    >>> servo_loop_gain(4.0, 0.5, 0.3).num[0][0].tolist()    # (0.5 s + 4) / (0.3 s^2 + s)
    [0.5, 4.0]
    """
    p = as_positive(kp, "kp")
    d = as_positive(kd, "kd", allow_zero=True)
    return control.tf([d, p], [1.0]) * servo_plant(tau, gain)


_UNSIMULATED = "{names}: expected a loop python-control can simulate, got a NaN step response (values too large?)"


def servo_step_response(kp: float, kd: float, tau: float, gain: float = 1.0,
                        duration: float = 4.0, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Unit-step response ``(t, y)`` of :func:`servo_closed_loop` over ``duration`` seconds.

    Notes
    -----
    ``control.step_response`` (python-control 0.10) on the closed loop of Franklin et al. (2015),
    Sec. 3.4.

    Examples
    --------
    >>> t, y = servo_step_response(4.479, 0.6, 0.3)
    >>> len(t), round(float(y.max()), 3), round(float(y[-1]), 3)     # 5 % overshoot, settled
    (400, 1.05, 1.0)
    """
    T = servo_closed_loop(kp, kd, tau, gain)
    t = np.linspace(0.0, as_positive(duration, "duration"), max(as_int(n, "n", minimum=0), 2))
    resp = control.step_response(T, t)
    y = np.asarray(resp.outputs).ravel()
    if np.isnan(y).any():
        raise ValueError(_UNSIMULATED.format(names="kp, kd, tau, gain, duration"))
    return np.asarray(resp.time), y


def servo_frequency_response(kp: float, kd: float, tau: float, omega: Any, gain: float = 1.0) -> np.ndarray:
    """Complex loop gain ``L(j omega)`` of :func:`servo_loop_gain` at frequencies ``omega`` (rad/s), for Bode plots.

    Notes
    -----
    Franklin et al. (2015), Sec. 6.1 (frequency response).

    Examples
    --------
    >>> np.round(np.abs(servo_frequency_response(4.479, 0.6, 0.3, [3.434])), 3).tolist()   # at crossover
    [1.0]
    """
    w = as_array(omega, "omega")
    if w.ndim > 1:
        raise ValueError(f"omega: expected a frequency or a 1-D array of them, got shape {w.shape}")
    if np.any(w <= 0):
        raise ValueError("omega: expected positive frequencies in rad/s")
    return np.asarray(servo_loop_gain(kp, kd, tau, gain)(1j * w))


def loop_metrics(kp: float, kd: float, tau: float, gain: float = 1.0, delay: float = 0.0) -> dict:
    """Step-response and stability-margin figures of the continuous loop, from python-control.

    Parameters
    ----------
    kp, kd, tau, gain : float
        As in :func:`servo_closed_loop`.
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
    (python-control's default; Nise 2015, Sec. 4.6), the criterion
    :func:`~robokit.controllers.heading.design_heading_gains` uses. The sampled loop:
    :func:`discrete_servo_analysis`.

    Examples
    --------
    >>> kp, kd = 4.479, 0.6      # design_heading_gains(0.3, overshoot=0.05, settling_time=1.5), rounded
    >>> m = loop_metrics(kp, kd, 0.3)
    >>> round(m["overshoot"], 3), round(m["phase_margin_deg"]), m["gain_margin"]
    (0.05, 69, inf)
    >>> round(loop_metrics(kp, kd, 0.3, delay=0.05)["phase_margin_deg"])    # a 50 ms delay costs margin
    59
    """
    L = servo_loop_gain(kp, kd, tau, gain)
    dly = as_positive(delay, "delay", allow_zero=True)
    if dly > 0:
        num, den = control.pade(dly, 1)
        pade = control.tf(num, den)
        L = L * pade
        plant = servo_plant(tau, gain) * pade
        # y/ref with rate feedback: kp P / (1 + (kp + kd s) P)
        T = control.feedback(kp * plant, control.tf([kd, kp], [kp]), sign=-1) if kp > 0 else plant
    else:
        T = servo_closed_loop(kp, kd, tau, gain)
    try:
        info = control.step_info(T)
    except IndexError:      # python-control's step_info on a response that is NaN throughout
        raise ValueError(_UNSIMULATED.format(names="kp, kd, tau, gain, delay")) from None
    gm, pm, _, _, wc = control.stability_margins(L)[:5]
    return {"overshoot": float(info["Overshoot"]) / 100.0, "settling_time": float(info["SettlingTime"]),
            "rise_time": float(info["RiseTime"]), "gain_margin": float(gm) if gm is not None else math.inf,
            "phase_margin_deg": float(pm), "crossover": float(wc)}


# --- the sampled loop ------------------------------------------------------------------------

#: Smallest ``dt / tau`` the ZOH discretisation resolves (below it ``exp(-dt / tau)`` rounds towards 1).
MIN_DT_OVER_TAU = 1e-9


class DiscreteServoLoop(NamedTuple):
    """The sampled loop's transfer functions in ``z`` (python-control, ``dt`` = the sample period).

    Examples
    --------
    >>> discrete_servo_loop(4.479, 0.6, 0.3, rate_hz=10.0).controller.num[0][0].tolist()   # kp + kd / dt, -kd / dt
    [10.479, -6.0]
    """

    plant: control.TransferFunction        #: ZOH equivalent of :func:`servo_plant`
    controller: control.TransferFunction   #: ``kp + kd (1 - 1/z) / dt`` acting on the measurement
    closed_loop: control.TransferFunction  #: ``y / y_ref``
    loop_gain: control.TransferFunction    #: controller x plant, broken at the plant input


def discrete_servo_loop(kp: float, kd: float, tau: float, rate_hz: float, gain: float = 1.0) -> DiscreteServoLoop:
    """The PD law with backward-difference rate feedback run every ``1 / rate_hz`` s on the ZOH plant.

    Parameters
    ----------
    kp : float
        Proportional gain (> 0), input units per output unit.
    kd : float
        Rate-feedback gain (>= 0), input units per output unit per second.
    tau, gain : float
        The plant :func:`servo_plant`.
    rate_hz : float
        Sample rate of the controller (Hz, > 0).

    Returns
    -------
    DiscreteServoLoop

    Notes
    -----
    The plant through a zero-order hold, ``P(z) = control.c2d(P(s), dt, "zoh")`` (Franklin et al.
    2015, Sec. 8.3). The controller ``u_k = kp (r_k - y_k) - kd (y_k - y_{k-1}) / dt`` is, on the
    measurement, ``C(z) = kp + kd (1 - z^-1) / dt`` and, on the reference, ``kp``; so the closed loop
    is ``T(z) = kp P / (1 + C P)`` and the loop gain ``L(z) = C P``. No computation delay: the
    voltage computed from the sample at ``t_k`` is held from ``t_k`` on.

    Examples
    --------
    >>> loop = discrete_servo_loop(4.479, 0.6, 0.3, rate_hz=10.0)
    >>> round(float(loop.closed_loop.dcgain()), 6), loop.closed_loop.dt
    (1.0, 0.1)
    """
    p = as_positive(kp, "kp")
    d = as_positive(kd, "kd", allow_zero=True)
    rate = as_positive(rate_hz, "rate_hz")
    t = as_positive(tau, "tau")
    dt = 1.0 / rate
    if not dt / t > MIN_DT_OVER_TAU:
        raise ValueError(f"tau, rate_hz: expected a sample period the lag can see (dt / tau > {MIN_DT_OVER_TAU:g}), "
                         f"got dt = {dt:.3g} s for tau = {t:.3g} s")
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        plant = control.c2d(servo_plant(t, gain), dt, "zoh")
        controller = control.tf([p + d / dt, -d / dt], [1.0, 0.0], dt)
        closed = control.feedback(p * plant, controller / p)
        loop = controller * plant
    coefficients = [np.asarray(c[0][0], dtype=float) for tf in (closed, loop) for c in (tf.num, tf.den)]
    if not all(np.all(np.isfinite(c)) for c in coefficients):
        raise ValueError("kp, kd, tau, gain, rate_hz: expected values whose sampled loop has finite coefficients, "
                         "got NaN or inf (values too large?)")
    return DiscreteServoLoop(plant, controller, closed, loop)


@dataclasses.dataclass(frozen=True, eq=False)
class ServoAnalysis:
    """Figures of merit of a sampled servo loop (:func:`discrete_servo_analysis`).

    Attributes
    ----------
    rate_hz : float
        Sample rate (Hz).
    poles : numpy.ndarray
        Closed-loop poles in ``z`` (complex).
    stable : bool
        All poles strictly inside the unit circle.
    gain_margin : float
        Factor by which the loop gain may grow before instability, as ``control.stability_margins``
        gives it (``inf`` if the phase never crosses -180 deg; below 1 when the loop is unstable).
    phase_margin_deg : float
        Phase margin (deg) at the crossover (``inf`` if ``|L|`` never crosses 1).
    crossover : float
        Gain-crossover frequency (rad/s; NaN if ``|L|`` never crosses 1).
    bandwidth_hz : float
        Closed-loop -3 dB bandwidth (Hz): the first frequency where ``|T|`` falls to its DC value over
        ``sqrt(2)``; NaN when the loop is unstable or ``|T|`` stays above that up to the Nyquist frequency.
    overshoot : float
        Step overshoot (fraction); NaN when unstable.
    rise_time, settling_time : float
        10-90 % rise and 2 % settling times (s); NaN when unstable.
    t, y : numpy.ndarray
        The sampled unit-step response (an unstable one is cut before it overflows).

    Examples
    --------
    >>> a = discrete_servo_analysis(4.479, 0.6, 0.3, rate_hz=50.0, duration=4.0)
    >>> len(a.t) == len(a.y) == 201, float(a.y[0])
    (True, 0.0)
    """

    rate_hz: float
    poles: np.ndarray
    stable: bool
    gain_margin: float
    phase_margin_deg: float
    crossover: float
    bandwidth_hz: float
    overshoot: float
    rise_time: float
    settling_time: float
    t: np.ndarray
    y: np.ndarray


def _bandwidth(closed: control.TransferFunction, dt: float) -> float:
    """First frequency (rad/s) below Nyquist where ``|T|`` falls 3 dB under its DC gain, else NaN."""
    nyquist = math.pi / dt
    w = np.geomspace(1e-4 * nyquist, nyquist, 4000)
    level = abs(complex(closed(1.0))) / math.sqrt(2.0)

    def excess(x):
        return np.abs(closed(np.exp(1j * np.asarray(x) * dt))) - level

    below = np.flatnonzero(excess(w) < 0)
    if below.size == 0 or below[0] == 0:
        return math.nan
    i = below[0]
    return float(brentq(excess, w[i - 1], w[i], xtol=1e-12 * nyquist))      # -3 dB point, refined


def discrete_servo_analysis(kp: float, kd: float, tau: float, rate_hz: float, gain: float = 1.0,
                            duration: float = 1.0) -> ServoAnalysis:
    """Poles, stability, margins, bandwidth and step figures of the sampled PD loop, from python-control.

    Parameters
    ----------
    kp, kd, tau, rate_hz, gain : float
        As in :func:`discrete_servo_loop`.
    duration : float, default 1
        Length of the step response (s).

    Returns
    -------
    ServoAnalysis
        A gain that destabilises the loop is reported (``stable=False``), not raised.

    Notes
    -----
    Poles of ``T(z)`` (stable inside the unit circle; Franklin et al. 2015, Sec. 8.2), margins of
    ``L(z)`` on the unit circle by ``control.stability_margins``, the -3 dB bandwidth of ``|T(e^{j w
    dt})|`` found on a grid up to the Nyquist frequency and refined by ``scipy.optimize.brentq``,
    step figures by ``control.step_info`` (10-90 % rise, 2 % settling; Nise 2015, Sec. 4.6).

    Examples
    --------
    >>> fast = discrete_servo_analysis(4.479, 0.6, 0.3, rate_hz=50.0, duration=4.0)
    >>> fast.stable, round(fast.overshoot, 3), round(fast.phase_margin_deg)
    (True, 0.05, 66)
    >>> discrete_servo_analysis(4.479, 0.6, 0.3, rate_hz=1.0).stable    # sampled once a second
    False
    """
    loop = discrete_servo_loop(kp, kd, tau, rate_hz, gain)
    dt = 1.0 / float(rate_hz)
    span = as_positive(duration, "duration")
    require_sample_count(span / dt, "duration, rate_hz")
    poles = np.asarray(loop.closed_loop.poles(), dtype=complex)
    stable = bool(np.all(np.abs(poles) < 1.0))
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            gm, pm, _, _, wc = control.stability_margins(loop.loop_gain)[:5]
        except np.linalg.LinAlgError:       # python-control squares the coefficients: an overflow
            raise ValueError("kp, kd, tau, gain, rate_hz: expected values whose loop gain python-control can "
                             "analyse, got coefficients that overflow (values too large?)") from None
        t = np.arange(int(round(span / dt)) + 1) * dt
        y = np.asarray(control.forced_response(loop.closed_loop, t, np.ones_like(t)).outputs).ravel()
    finite = np.isfinite(y)
    if not finite.all():                 # an unstable response overflowed: keep what is a number
        cut = int(np.argmin(finite))
        t, y = t[:cut], y[:cut]
    nan = math.nan
    overshoot = rise = settle = bandwidth = nan
    if stable:
        info = control.step_info(y, T=t, yfinal=float(np.real(loop.closed_loop.dcgain())))
        overshoot, rise, settle = info["Overshoot"] / 100.0, info["RiseTime"], info["SettlingTime"]
        bandwidth = _bandwidth(loop.closed_loop, dt) / (2 * math.pi)
    return ServoAnalysis(rate_hz=float(rate_hz), poles=poles, stable=stable,
                         gain_margin=float(gm) if gm is not None else math.inf, phase_margin_deg=float(pm),
                         crossover=float(wc), bandwidth_hz=float(bandwidth), overshoot=float(overshoot),
                         rise_time=float(rise), settling_time=float(settle), t=t, y=y)
