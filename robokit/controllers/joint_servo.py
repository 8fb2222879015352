"""LittleDog's joint servo: a PD law on each joint's angle, run on the robot at 500 Hz, driving a motor voltage.

A joint of inertia ``J`` (the link about the joint plus the rotor's reflected inertia) driven by a
geared DC motor (:mod:`robokit.controllers.dc_motor`) obeys ``J q'' + B q' = K V``, so

    q(s) / V(s) = K / (s (J s + B)) = g / (s (tau s + 1)),   g = K / B,  tau = J / B,

an integrator plus a first-order lag: the loop of :mod:`robokit.controllers.servo_loop`, whose
functions this module calls with the joint's ``tau`` and ``g``. The servo (LittleDog User Guide,
Sec. 2: joint servos on the robot at 500 Hz) is ``V_k = kp (q_ref - q_k) - kd (q_k - q_{k-1}) / dt``
saturated at the battery voltage (:func:`pd_servo_step`); the gains come from continuous pole
placement for a closed-loop bandwidth (:func:`design_servo_gains`), and :func:`servo_analysis` checks
the sampled loop with python-control. Sampling the same gains at 100 Hz (the host loop's rate) costs
about half the phase margin and most of the gain margin: Franklin et al. (2015), Sec. 8.5, advise a sample rate of 20 or more times
the closed-loop bandwidth, and 100 Hz is under 7 times a 15 Hz servo's.

References
----------
.. [1] G. F. Franklin, J. D. Powell and A. Emami-Naeini, *Feedback Control of Dynamic Systems*,
   7th ed., Pearson, 2015.
.. [2] N. S. Nise, *Control Systems Engineering*, 7th ed., Wiley, 2015.
.. [3] Boston Dynamics, *LittleDog User Guide*, v1.0.2, 2006.
"""
from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..config import lazy_module
from ..validation import as_array, as_int, as_positive, require_sample_count
from .dc_motor import DCMotor, reflected_inertia
from .servo_loop import MIN_DT_OVER_TAU, ServoAnalysis, discrete_servo_analysis, servo_plant

control = lazy_module("control")   # python-control, loaded on first use (0.75 s of every import otherwise)

__all__ = ["JointLag", "joint_lag", "joint_plant", "design_servo_gains", "servo_analysis",
           "pd_servo_step", "ServoResponse", "discrete_servo_response"]

class JointLag(NamedTuple):
    """The joint plant as ``g / (s (tau s + 1))``.

    Examples
    --------
    >>> JointLag(0.01, 1.0).tau
    0.01
    """

    tau: float     #: ``J / B`` (s)
    gain: float    #: ``K / B`` (rad/s per V)


def joint_lag(motor: DCMotor, inertia: float) -> JointLag:
    """Time constant ``J / B`` and gain ``K / B`` of a joint of total ``inertia`` driven by ``motor``.

    Parameters
    ----------
    motor : DCMotor
    inertia : float
        TOTAL inertia at the joint (kg m^2): the link about the joint axis plus
        :func:`~robokit.controllers.dc_motor.reflected_inertia` (it cannot be less than the latter).

    Returns
    -------
    JointLag

    Raises
    ------
    ValueError
        ``inertia`` not above the motor's reflected inertia (the link's alone was probably passed).

    Notes
    -----
    ``J q'' + B q' = K V`` (Franklin et al. 2015, Sec. 2.3), divided by ``B``.

    Examples
    --------
    >>> from robokit.controllers.dc_motor import LITTLEDOG_MOTOR
    >>> lag = joint_lag(LITTLEDOG_MOTOR, 2.76e-3)
    >>> round(lag.tau, 5), round(lag.gain, 4)
    (0.01082, 0.9804)
    """
    if not isinstance(motor, DCMotor):
        raise TypeError(f"motor: expected a DCMotor, got {type(motor).__name__}")
    J = as_positive(inertia, "inertia")
    rotor = reflected_inertia(motor)
    if J <= rotor:
        raise ValueError(f"inertia: expected the total inertia at the joint, link + reflected_inertia(motor) "
                         f"(> {rotor:.4g} kg m^2), got {J:.4g}")
    return JointLag(J / motor.damping, motor.torque_per_volt / motor.damping)


def joint_plant(motor: DCMotor, inertia: float) -> control.TransferFunction:
    """Transfer function from motor voltage to joint angle, ``K / (s (J s + B))``.

    Parameters
    ----------
    motor, inertia
        As in :func:`joint_lag` (``inertia`` is the total: link + reflected).

    Returns
    -------
    control.TransferFunction
        In the form ``g / (tau s^2 + s)`` of :func:`~robokit.controllers.servo_loop.servo_plant`.

    Notes
    -----
    Franklin et al. (2015), Sec. 2.3 (DC motor driving an inertia; inductance neglected).

    Examples
    --------
    >>> from robokit.controllers.dc_motor import LITTLEDOG_MOTOR
    >>> P = joint_plant(LITTLEDOG_MOTOR, 2.76e-3)
    >>> round(float(abs(P(10j))), 5)          # |K / (j10 (j10 J + B))|
    0.09747
    """
    tau, gain = joint_lag(motor, inertia)
    return servo_plant(tau, gain)


def design_servo_gains(motor: DCMotor, inertia: float, bandwidth_hz: float, damping: float = 0.7) -> tuple[float, float]:
    """Gains ``(kp [V/rad], kd [V s/rad])`` that give the continuous joint loop a bandwidth and damping.

    Parameters
    ----------
    motor, inertia
        As in :func:`joint_lag`.
    bandwidth_hz : float
        Closed-loop -3 dB bandwidth (Hz, > 0).
    damping : float, default 0.7
        Damping ratio ``zeta`` of the closed-loop poles (> 0).

    Returns
    -------
    tuple of float
        ``kp = J omega_n^2 / K`` and ``kd = (2 zeta omega_n J - B) / K``.

    Raises
    ------
    ValueError
        A bandwidth so low that the motor's own back-EMF damping exceeds what it asks for
        (``kd < 0``, positive rate feedback): ask for more bandwidth or damping.

    Notes
    -----
    With rate feedback the closed loop is ``K kp / (J s^2 + (B + K kd) s + K kp)``; matching
    ``J (s^2 + 2 zeta omega_n s + omega_n^2)`` places its poles (Franklin et al. 2015, Sec. 4.3).
    ``omega_n`` follows from the bandwidth of a second-order system,
    ``omega_BW = omega_n sqrt(1 - 2 zeta^2 + sqrt(4 zeta^4 - 4 zeta^2 + 2))`` (Nise 2015, Sec. 10.8).

    Examples
    --------
    >>> from robokit.controllers.dc_motor import LITTLEDOG_MOTOR
    >>> kp, kd = design_servo_gains(LITTLEDOG_MOTOR, 2.76e-3, bandwidth_hz=15.0)
    >>> round(kp, 2), round(kd, 4)
    (96.12, 0.4222)
    """
    tau, gain = joint_lag(motor, inertia)
    fb = as_positive(bandwidth_hz, "bandwidth_hz")
    zeta = as_positive(damping, "damping")
    # omega_BW / omega_n = sqrt(a + sqrt(a^2 + 1)), a = 1 - 2 zeta^2 (Nise Sec. 10.8), without cancellation
    a = 1 - 2 * zeta * zeta
    ratio2 = a + math.hypot(a, 1.0) if a >= 0 else 1.0 / (math.hypot(a, 1.0) - a)
    if not ratio2 > 0:
        raise ValueError(f"damping: expected a damping ratio whose bandwidth is representable, got {zeta}")
    wn = 2 * math.pi * fb / math.sqrt(ratio2)
    J, K, B = float(inertia), motor.torque_per_volt, motor.damping
    kp = J * wn * wn / K                        # J omega_n^2 = K kp
    kd = (2 * zeta * wn * J - B) / K            # 2 zeta omega_n J = B + K kd
    if not (math.isfinite(kp) and math.isfinite(kd)):
        raise ValueError(f"bandwidth_hz, damping: expected values whose gains are finite, got {fb} and {zeta}")
    if kd < 0:
        raise ValueError(f"bandwidth_hz: expected a bandwidth the motor's back-EMF damping does not exceed "
                         f"(kd >= 0), got {fb} Hz which needs kd={kd:.3g}; ask for more bandwidth or damping")
    return kp, kd


def servo_analysis(kp: float, kd: float, motor: DCMotor, inertia: float, rate_hz: float,
                   duration: float = 0.25) -> ServoAnalysis:
    """The joint servo sampled at ``rate_hz``: poles, stability, margins, bandwidth, step (python-control).

    Parameters
    ----------
    kp : float
        Proportional gain (V/rad, > 0).
    kd : float
        Rate-feedback gain (V s/rad, >= 0).
    motor, inertia
        As in :func:`joint_lag`.
    rate_hz : float
        Servo rate (Hz): 500 on LittleDog.
    duration : float, default 0.25
        Length of the step response (s).

    Returns
    -------
    ServoAnalysis
        An unstable gain is reported with ``stable=False`` (and margins as python-control gives
        them), not raised.

    Notes
    -----
    :func:`~robokit.controllers.servo_loop.discrete_servo_analysis` on the joint's ``tau`` and ``g``:
    ``control.c2d`` (ZOH) of :func:`joint_plant` under the sampled PD (Franklin et al. 2015, Sec. 8.3).
    Linear: the voltage's saturation is left out (:func:`discrete_servo_response` has it).

    Examples
    --------
    >>> from robokit.controllers.dc_motor import LITTLEDOG_MOTOR
    >>> a = servo_analysis(96.12, 0.4222, LITTLEDOG_MOTOR, 2.76e-3, rate_hz=500.0)
    >>> a.stable, round(a.phase_margin_deg), round(a.bandwidth_hz, 1)
    (True, 64, 16.1)
    >>> servo_analysis(10 * 96.12, 0.4222, LITTLEDOG_MOTOR, 2.76e-3, rate_hz=100.0).stable
    False
    """
    tau, gain = joint_lag(motor, inertia)
    rate = as_positive(rate_hz, "rate_hz")
    if not 1.0 / (rate * tau) > MIN_DT_OVER_TAU:       # the lag must be visible at the sample rate
        raise ValueError(f"inertia, rate_hz: expected a joint whose time constant J / B = {tau:.3g} s the servo "
                         f"period {1 / rate:.3g} s can resolve")
    return discrete_servo_analysis(kp, kd, tau, rate, gain, duration)


def pd_servo_step(q_ref: Any, q: Any, q_prev: Any, kp: Any, kd: Any, dt: float, voltage_max: float,
                  validate: bool = True) -> float | np.ndarray:
    """One tick of the joint servo: ``V = kp (q_ref - q) - kd (q - q_prev) / dt``, saturated at ``+-voltage_max``.

    Parameters
    ----------
    q_ref : float or array_like
        Set-points (rad), one per joint (or one for all).
    q : float or array_like
        Joint angles measured at this tick (rad).
    q_prev : float or array_like
        Joint angles measured at the previous tick (rad), same shape as ``q``.
    kp : float or array_like
        Proportional gains (V/rad, >= 0), one for all joints or one per joint.
    kd : float or array_like
        Rate-feedback gains (V s/rad, >= 0), likewise.
    dt : float
        Servo period (s, > 0): 0.002 at 500 Hz.
    voltage_max : float
        Saturation (V, > 0): the battery's 14.8 V.
    validate : bool, default True
        Validate the inputs; ``False`` is the simulation's fast path (called 500 times per simulated
        second): plain numpy arithmetic on what it is given.

    Returns
    -------
    float or numpy.ndarray
        The voltages, shaped like ``q`` (a float for a scalar ``q``).

    Raises
    ------
    ValueError
        NaN or infinite set-points (the message names ``q_ref``), angles, gains or period; shapes
        that do not match. A robot must not act on a NaN: the host link rejects such packets before
        they get here (:class:`~robokit.controllers.host_link.SetpointChannel`).

    Notes
    -----
    PD with the derivative on the measurement (no kick when the set-point jumps; Franklin et al.
    2015, Sec. 4.3), the rate by a backward difference (the emulation of Franklin et al. 2015,
    Sec. 8.3), saturated like the driver.

    Examples
    --------
    >>> round(pd_servo_step(0.1, 0.0, 0.0, kp=96.12, kd=0.4222, dt=0.002, voltage_max=14.8), 3)
    9.612
    >>> pd_servo_step([0.5, 0.0], [0.0, 0.01], [0.0, 0.0], 96.12, 0.4222, 0.002, 14.8).round(3).tolist()
    [14.8, -3.072]
    """
    if validate:
        qn = as_array(q, "q")
        shape = qn.shape
        qp = as_array(q_prev, "q_prev")
        if qp.shape != shape:
            raise ValueError(f"q_prev: expected the shape of q {shape}, got {qp.shape}")
        ref = _per_joint(q_ref, "q_ref", shape)
        p = _per_joint(kp, "kp", shape, nonnegative=True)
        d = _per_joint(kd, "kd", shape, nonnegative=True)
        period = as_positive(dt, "dt")
        vmax = as_positive(voltage_max, "voltage_max")
        v = p * (ref - qn) - d * ((qn - qp) / period)
        if not np.all(np.isfinite(v)):
            raise ValueError("kp, kd, dt: expected values whose voltage is finite, got an overflow (values too large?)")
        out = np.clip(v, -vmax, vmax)
        return float(out) if out.ndim == 0 else out
    # np.clip's own arithmetic without its wrapper (about 0.7 us a tick)
    return np.minimum(np.maximum(kp * (q_ref - q) - kd * ((q - q_prev) / dt), -voltage_max), voltage_max)


def _per_joint(value: Any, name: str, shape: tuple[int, ...], nonnegative: bool = False) -> np.ndarray:
    """``value`` as a finite array broadcast to ``shape`` (one for all joints or one per joint)."""
    arr = as_array(value, name)
    try:
        np.broadcast_to(arr, shape)
    except ValueError:
        raise ValueError(f"{name}: expected a scalar or shape {shape} (one per joint), got shape {arr.shape}") from None
    if nonnegative and np.any(arr < 0):
        raise ValueError(f"{name}: expected non-negative gains, got {arr.min()}")
    return arr


class ServoResponse(NamedTuple):
    """A simulated servo step: samples at the servo ticks.

    Examples
    --------
    >>> ServoResponse(np.zeros(2), np.zeros(2), np.zeros(2)).q.shape
    (2,)
    """

    t: np.ndarray          #: tick times (s), ``k dt``
    q: np.ndarray          #: joint angle at each tick (rad)
    voltage: np.ndarray    #: voltage applied from each tick to the next (V)


def discrete_servo_response(kp: float, kd: float, motor: DCMotor, inertia: float, rate_hz: float, steps: int,
                            q_ref: float = 1.0, saturate: bool = True) -> ServoResponse:
    """Our own simulation of :func:`pd_servo_step` on the exactly discretised (ZOH) joint, from rest.

    Parameters
    ----------
    kp, kd, motor, inertia, rate_hz
        As in :func:`servo_analysis`.
    steps : int
        Number of servo ticks (>= 1).
    q_ref : float, default 1
        The step's set-point (rad), applied from tick 0.
    saturate : bool, default True
        Saturate the voltage at ``motor.voltage_max`` as the robot does; ``False`` gives the linear
        loop that :func:`servo_analysis` models (python-control's ``forced_response`` of its closed
        loop matches it to rounding).

    Returns
    -------
    ServoResponse

    Notes
    -----
    Between ticks the voltage is held, so the joint's state (angle ``q``, rate ``w``) moves exactly
    by the solution of ``tau w' + w = g V`` over ``dt`` (the ZOH equivalent; Franklin et al. 2015,
    Sec. 8.3), with ``a = exp(-dt / tau)``:

        w+ = a w + g (1 - a) V,
        q+ = q + tau (1 - a) w + g (dt - tau (1 - a)) V.

    Examples
    --------
    >>> from robokit.controllers.dc_motor import LITTLEDOG_MOTOR
    >>> r = discrete_servo_response(96.12, 0.4222, LITTLEDOG_MOTOR, 2.76e-3, 500.0, steps=150, q_ref=0.1)
    >>> round(float(r.q.max()) / 0.1, 3), round(float(r.q[-1]), 4), round(float(r.voltage[0]), 3)
    (1.056, 0.1, 9.612)
    """
    tau, g = joint_lag(motor, inertia)
    p = as_positive(kp, "kp")
    d = as_positive(kd, "kd", allow_zero=True)
    rate = as_positive(rate_hz, "rate_hz")
    n = as_int(steps, "steps", minimum=1)
    require_sample_count(n, "steps")
    ref = float(as_array(q_ref, "q_ref", shape=()))
    dt = 1.0 / rate
    a = math.exp(-dt / tau)
    vmax = motor.voltage_max if saturate else math.inf
    q = np.zeros(n)
    volts = np.zeros(n)
    angle = w = prev = 0.0
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(n):
            q[k] = angle
            v = float(pd_servo_step(ref, angle, prev, p, d, dt, vmax, validate=False))
            volts[k] = v
            prev = angle
            angle = angle + tau * (1 - a) * w + g * (dt - tau * (1 - a)) * v     # ZOH: q+
            w = a * w + g * (1 - a) * v                                          # ZOH: w+
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(volts))):
        raise ValueError("kp, kd, q_ref: expected a response that stays finite, got an overflow (an unstable "
                         "loop without saturation: check servo_analysis(...).stable)")
    return ServoResponse(np.arange(n) * dt, q, volts)
