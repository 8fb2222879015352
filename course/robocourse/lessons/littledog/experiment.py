"""Lesson 04's experiment: LittleDog crawls and trots 1 m in MuJoCo, and each of the guide's numbers is tested.

Each function makes one of the lesson's tables from trials of :func:`robokit.legged.simulate_walk`:

* :func:`lesson_plans` - the crawl and the trot the lesson walks (1 m; 0.3 m in fast mode);
* :func:`loop_table` - servo rate (the guide's 500 Hz against 100 Hz) x link latency
  (0 / 10 / 30 / 50 ms) x servo stiffness: set-point tracking, distance, falls, motor power;
* :func:`host_table` - the same latencies (and packet loss) under a host that plays the plan and
  under hosts that feed the MoCap's trunk pose back (:class:`robokit.legged.PostureFeedback`):
  trunk tilt and height against the plan, falls, distance;
* :func:`estimation_table` - the trunk's pose from MoCap alone, from the IMU alone and fused,
  against the simulator's truth; :func:`imu_drift` - why the IMU alone drifts so far;
* :func:`touchdown_table` - touchdown detection on the lower-leg force sensors against MuJoCo's
  true contacts;
* :func:`endurance_table` - the motors' electrical power against the battery's 31.08 Wh and the
  guide's "about 30 minutes";
* :func:`true_margins` - the static stability margin of the true centre of mass over the feet
  truly on the ground.

No cache: every trial runs in about a second (the simulation runs at more than 20 x real time; a
reactive host's trial in about two); :func:`host_table` runs its trials side by side
(:func:`robokit.parallel.map_runs`).

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Secs. 1-3.
.. [2] G. Gabrielli and T. von Karman, "What price speed?", *Mechanical Engineering* 72(10), 1950,
   and V. A. Tucker, "The energetic cost of moving about", *American Scientist* 63(4), 1975 (cost of
   transport, unnumbered).
.. [3] O. J. Woodman, "An introduction to inertial navigation", Technical Report UCAM-CL-TR-696,
   University of Cambridge Computer Laboratory, 2007, Sec. 6 (a gyro bias tilts the attitude; the
   gravity it leaks in grows the position error with the cube of time).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from robocourse import FAST
from robokit.controllers import LITTLEDOG_MOTOR, servo_analysis
from robokit.geometry import so3_log
from robokit.parallel import map_runs
from robokit.progress import progress_bar
from robokit.validation import as_array, as_callable, as_int, as_positive, describe
from robokit.legged.gait import WalkPlan, walking_plan
from robokit.legged.gait_schedule import crawl_gait, trot_gait
from robokit.legged.littledog import GUIDE, MARKERS, STANCE_FEET, STANDING_HEIGHT, TIMESTEP, TOTAL_MASS
from robokit.legged.mocap import mocap_body_poses
from robokit.legged.posture import PostureFeedback, delay_gain_limit
from robokit.legged.power import battery_energy, cost_of_transport, endurance
from robokit.legged.servo_design import SERVO_BANDWIDTH, littledog_servo_gains, servo_inertia
from robokit.legged.imu import GRAVITY
from robokit.legged.simulation import LoopSettings, SensorSettings, TrialOutcome, simulate_walk
from robokit.legged.state_estimation import fuse_body_state, orientation_errors, position_errors
from robokit.legged.support import stability_margins
from robokit.legged.touchdown import contact_events, event_precision_recall, score_leg_events
from robokit.legged.touchdown import detect_contacts, gate_touchdowns
from robokit.legged.trial_log import TrialLog

__all__ = ["LESSON_CRAWL", "LESSON_TROT", "LESSON_DISTANCE", "LATENCIES", "TOUCHDOWN_DETECTORS", "lesson_plans",
           "loop_table", "HOST_GAINS", "HostLag", "host_lag", "host_table", "posture_errors", "estimation_table", "ImuDrift", "imu_drift", "touchdown_table", "endurance_table",
           "true_margins"]

LESSON_CRAWL = {"period": 2.0, "step_length": 0.08, "step_height": 0.04, "duty_factor": 0.9}
"""The lesson's crawl: a 2 s cycle, 8 cm steps (0.04 m/s)."""
LESSON_TROT = {"period": 0.5, "step_length": 0.06, "step_height": 0.04}
"""The lesson's trot: a 0.5 s cycle, 6 cm steps (0.12 m/s); 4 cm foot lift (3 cm scuffs)."""
LESSON_DISTANCE = 0.3 if FAST else 1.0
"""How far the lesson walks (m): 1 m, the issue's distance (0.3 m in fast mode)."""
LATENCIES = (0.0, 0.01, 0.03, 0.05)
"""Link latencies of the loop table (s)."""
HOST_GAINS = (20.0, 50.0)
"""Integral gains (1/s) of the reactive hosts the lesson compares with the plan-playing host."""
TOUCHDOWN_DETECTORS = (("threshold 2 N", 2.0, 2.0 - 1e-9, 1), ("hysteresis 3 / 1 N", 3.0, 1.0, 1),
                       ("hysteresis + debounce 2", 3.0, 1.0, 2))
"""The touchdown detectors the lesson compares: ``(label, threshold_on, threshold_off, debounce)``
(N, N, host samples); the plain threshold's off level is a nanonewton below its on level."""


def lesson_plans(distance: float = LESSON_DISTANCE) -> dict:
    """The crawl and the trot the lesson walks, as host-rate plans.

    Parameters
    ----------
    distance : float
        Metres along +x.

    Returns
    -------
    dict
        ``{"crawl": WalkPlan, "trot": WalkPlan}``.

    Examples
    --------
    >>> plans = lesson_plans(0.2)
    >>> sorted(plans), round(float(plans["trot"].T_world_body[-1, 0, 3]), 6)
    (['crawl', 'trot'], 0.2)
    """
    distance = as_positive(distance, "distance")
    return {"crawl": walking_plan(crawl_gait(**LESSON_CRAWL), distance),
            "trot": walking_plan(trot_gait(**LESSON_TROT), distance)}


def loop_table(plan: WalkPlan, *, servo_rates: Any = (500.0, 100.0), latencies: Any = LATENCIES,
               bandwidths: Any = (SERVO_BANDWIDTH,), rng: Any = 0, progress: Any = None) -> list:
    """Walk one plan under every combination of servo rate, link latency and servo stiffness.

    Parameters
    ----------
    plan : WalkPlan
    servo_rates : sequence of float
        Hz; each must divide the 1 kHz physics rate.
    latencies : sequence of float
        One-way link delays (s).
    bandwidths : sequence of float
        Closed-loop bandwidths the servo gains are designed for (Hz,
        :func:`~robokit.legged.servo_design.littledog_servo_gains`).
    rng : int
        Seed of every trial (the same for all, so rows differ only by the loop).
    progress : callable, optional
        ``progress(done, total)``.

    Returns
    -------
    list of dict
        One row per trial: ``servo_rate``, ``latency``, ``bandwidth``, ``stable`` (the sampled
        servo's linear analysis, :func:`robokit.controllers.servo_analysis`), ``gain_margin``,
        ``fell``, ``distance`` (m), ``tracking_deg`` (RMS, deg), ``power`` (mean motor power, W).

    Examples
    --------
    >>> rows = loop_table(lesson_plans(0.05)["trot"], servo_rates=(500,), latencies=(0.0,))
    >>> rows[0]["stable"], rows[0]["fell"]
    (True, False)
    """
    if not isinstance(plan, WalkPlan):
        raise TypeError(f"plan: expected a WalkPlan, got {type(plan).__name__}")
    rates = as_array(servo_rates, "servo_rates", ndim=1, min_size=1)
    lats = as_array(latencies, "latencies", ndim=1, min_size=1)
    bws = as_array(bandwidths, "bandwidths", ndim=1, min_size=1)
    progress = as_callable(progress, "progress")
    for rate in rates:              # every setting is refused by name before the first trial runs
        try:
            LoopSettings(servo_rate=float(rate))
        except ValueError as exc:
            raise ValueError(f"servo_rates: {exc}") from None
    if np.any(lats < 0):
        raise ValueError(f"latencies: expected non-negative delays (s), got {lats.tolist()}")
    if np.any(bws <= 0):
        raise ValueError(f"bandwidths: expected positive frequencies (Hz), got {bws.tolist()}")
    total = len(bws) * len(rates) * len(lats)
    rows = []
    bar = progress_bar(total, "walking trials", unit="trial", callback=progress)
    for bw in map(float, bws):
        gains = littledog_servo_gains(bw)
        for rate in map(float, rates):
            analysis = servo_analysis(gains[0], gains[1], LITTLEDOG_MOTOR, servo_inertia(), rate)   # one per loop
            for lat in map(float, lats):
                out = simulate_walk(plan, LoopSettings(servo_rate=rate, latency=lat, gains=gains), rng=rng)
                rows.append({"servo_rate": rate, "latency": lat, "bandwidth": bw, "stable": bool(analysis.stable),
                             "gain_margin": float(analysis.gain_margin), "fell": out.fell,
                             "distance": out.distance, "tracking_deg": float(np.degrees(out.tracking_rms)),
                             "power": out.energy / _duration(out.log)})
                bar(len(rows), total)
    bar.close()
    return rows


def posture_errors(log: TrialLog, plan: WalkPlan) -> tuple[float, float]:
    """RMS of the trunk's true tilt (roll and pitch, deg) and height (mm) against the plan's, over a trial.

    Parameters
    ----------
    log : TrialLog
        A trial of ``plan`` (its first ``len(log)`` host cycles).
    plan : WalkPlan

    Returns
    -------
    (float, float)
        Tilt RMS (deg) of the rotation vector ``log(R_plan^T R_true)``'s x and y components, and
        height RMS (mm).

    Examples
    --------
    >>> plan = lesson_plans(0.05)["crawl"]
    >>> tilt, height = posture_errors(simulate_walk(plan).log, plan)
    >>> tilt < 2 and height < 10
    True
    """
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a TrialLog, got {type(log).__name__}")
    if not isinstance(plan, WalkPlan):
        raise TypeError(f"plan: expected a WalkPlan, got {type(plan).__name__}")
    n = len(log)
    if n > len(plan.t):
        raise ValueError(f"log: expected at most the plan's {len(plan.t)} host cycles, got {n}")
    R_err = np.swapaxes(plan.T_world_body[:n, :3, :3], 1, 2) @ log.T_world_body()[:, :3, :3]
    tilt = so3_log(R_err)[:, :2]
    height = log.body_pos[:, 2] - plan.T_world_body[:n, 2, 3]
    return float(np.degrees(_rms(tilt))), 1000 * _rms(height)


class HostLag(NamedTuple):
    """How the standing trunk answers a step in the body height the host asks for."""

    #: (N,) host cycles since the step was sent.
    cycles: np.ndarray
    #: (N,) height change as a fraction of the step.
    response: np.ndarray
    #: Host cycles until the trunk is half-way (interpolated).
    half_cycles: float


def host_lag(step: float = 0.005, *, latency: float = 0.0, dt: float = 0.01) -> HostLag:
    """The lag a reactive host has to live with: the standing trunk's answer to a height step.

    The host plays a plan that stands still and, at one cycle, asks for the body ``step`` metres
    higher (feet where they are); the trunk's true height is read every cycle after. The cycles it
    takes to get half-way are the delay of the loop a reactive host closes (servo, motors, legs),
    before any link latency.

    Parameters
    ----------
    step : float, default 0.005
        Height step (m, 0.001 to 0.02: well above the servo's resolution, within the legs' reach).
    latency : float, default 0
        One-way link delay (s, 0 to 20 host periods: the trunk is watched for 40).
    dt : float, default 0.01
        Host period (s): a whole number of 1 ms physics steps, at most 0.05.

    Returns
    -------
    HostLag

    Raises
    ------
    ValueError
        For values outside the ranges above.
    RuntimeError
        If the trunk never gets half-way within the 40 host periods it is watched.

    Examples
    --------
    >>> lag = host_lag()
    >>> 1 < lag.half_cycles < 3
    True
    """
    step = as_positive(step, "step")
    if not 0.001 <= step <= 0.02:
        raise ValueError(f"step: expected 0.001 to 0.02 m, got {step}")
    dt = as_positive(dt, "dt")
    if dt > 0.05 or abs(dt / TIMESTEP - round(dt / TIMESTEP)) > 1e-9:
        raise ValueError(f"dt: expected a whole number of 1 ms physics steps, at most 0.05 s, got {dt}")
    before, after = 20, 40
    latency = as_positive(latency, "latency", allow_zero=True)
    if latency > after / 2 * dt:
        raise ValueError(f"latency: expected at most {after // 2} host periods ({after / 2 * dt:g} s), got {latency}")
    n = before + after
    T = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    T[:, 2, 3] = STANDING_HEIGHT + np.where(np.arange(n) >= before, step, 0.0)
    feet = np.broadcast_to(STANCE_FEET + [0.0, 0.0, STANDING_HEIGHT], (n, 4, 3))
    plan = WalkPlan(np.arange(n) * dt, T, feet, np.ones((n, 4), bool), np.zeros(n), "stand")
    z = simulate_walk(plan, LoopSettings(latency=latency), rng=0).log.body_pos[:, 2]
    response = (z[before:] - z[before - 1]) / step
    if not np.any(response >= 0.5):
        raise RuntimeError(f"the trunk did not get half-way up a {step} m step within {after} host periods")
    k = int(np.argmax(response >= 0.5))
    half = k - 1 + (0.5 - response[k - 1]) / (response[k] - response[k - 1]) if k > 0 else 0.0
    return HostLag(np.arange(after), response, float(half))


def _host_trial(plan: WalkPlan, task: tuple) -> dict:
    """One row of :func:`host_table`: the plan walked under one host, latency and loss."""
    gain, latency, loss, seed, lag = task
    host = None if gain == 0 else PostureFeedback(gain=gain)
    out = simulate_walk(plan, LoopSettings(latency=latency, loss=loss), host=host, rng=seed)
    tilt, height = posture_errors(out.log, plan)
    dt = float(plan.t[1] - plan.t[0])
    delay = int(round(lag + latency / dt))                  # the legs' own lag, then the link
    return {"gain": gain, "latency": latency, "loss": loss, "fell": out.fell, "distance": out.distance,
            "tilt_deg": tilt, "height_mm": height, "tracking_deg": float(np.degrees(out.tracking_rms)),
            "step_gain": gain * dt, "delay_cycles": delay,
            "predicted_stable": None if gain == 0 else bool(gain * dt < delay_gain_limit(delay))}


def host_table(plan: WalkPlan, *, gains: Any = HOST_GAINS, latencies: Any = LATENCIES, losses: Any = (0.0,),
               rng: int = 0, progress: Any = None) -> list:
    """Walk one plan under a host that plays it and under reactive hosts, over links of every latency.

    Parameters
    ----------
    plan : WalkPlan
    gains : sequence of float
        Integral gains (1/s, > 0) of the reactive hosts (:class:`robokit.legged.PostureFeedback`,
        default axes: height, roll, pitch); a plan-playing host (gain 0) is always walked too.
    latencies : sequence of float
        One-way link delays (s, >= 0).
    losses : sequence of float
        Packet-loss probabilities (in [0, 1)).
    rng : int
        Seed of every trial (the same for all, so rows differ only by the host and the link).
    progress : callable, optional
        ``progress(done, total)``.

    Returns
    -------
    list of dict
        One row per (gain, latency, loss), the plan-playing host first: ``gain`` (0 for it),
        ``latency``, ``loss``, ``fell``, ``distance`` (m), ``tilt_deg`` and ``height_mm``
        (:func:`posture_errors`), ``tracking_deg``, ``step_gain`` (``gain dt``), ``delay_cycles``
        (:func:`host_lag`'s half-way time plus the latency, in host cycles, rounded) and ``predicted_stable``
        (``step_gain`` below :func:`robokit.legged.delay_gain_limit` of that delay; None for the
        plan-playing host).

    Notes
    -----
    The trials are independent and made side by side (:func:`robokit.parallel.map_runs`).

    Examples
    --------
    >>> rows = host_table(lesson_plans(0.05)["crawl"], gains=(20.0,), latencies=(0.0,))
    >>> [(r["gain"], r["fell"], r["predicted_stable"]) for r in rows]
    [(0.0, False, None), (20.0, False, True)]
    """
    if not isinstance(plan, WalkPlan):
        raise TypeError(f"plan: expected a WalkPlan, got {type(plan).__name__}")
    g = as_array(gains, "gains", ndim=1, min_size=0)
    lats = as_array(latencies, "latencies", ndim=1, min_size=1)
    losses = as_array(losses, "losses", ndim=1, min_size=1)
    progress = as_callable(progress, "progress")
    if np.any(g <= 0):
        raise ValueError(f"gains: expected positive integral gains (1/s), got {g.tolist()}")
    for lat in lats:
        for loss in losses:     # every setting is refused by name before the first trial runs
            try:
                LoopSettings(latency=float(lat), loss=float(loss))
            except ValueError as exc:
                raise ValueError(f"latencies, losses: {exc}") from None
    seed = as_int(rng, "rng", minimum=0)
    lag = host_lag(dt=float(plan.t[1] - plan.t[0])).half_cycles
    tasks = [(float(gain), float(lat), float(loss), seed, lag) for gain in (0.0, *g) for lat in lats for loss in losses]
    return map_runs(_host_trial, plan, tasks, desc="walking trials", unit="trial", progress=progress)


def _duration(log: TrialLog) -> float:
    """Seconds a trial ran: one host period per logged cycle (the energy covers every one)."""
    return len(log) * float(log.t[1] - log.t[0])


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x ** 2))) if x.size else float("nan")


def estimation_table(log: TrialLog) -> dict:
    """The trunk's pose three ways against the simulator's truth: MoCap alone, IMU alone, fused.

    * MoCap alone: a least-squares rigid fit of the visible markers per frame
      (:func:`~robokit.legged.mocap.mocap_body_poses`), holding the last pose when fewer than
      three markers are seen;
    * IMU alone: the fusion filter with no MoCap update after the first frame (gyro and
      accelerometer integrated, biases and all);
    * fused: :func:`~robokit.legged.state_estimation.fuse_body_state` with every good MoCap frame.

    Parameters
    ----------
    log : TrialLog

    Returns
    -------
    dict
        ``{method: {"position_mm", "position_lost_mm", "orientation_deg", "orientation_lost_deg",
        "final_position_mm"}}`` for methods ``"mocap"``, ``"imu"``, ``"fused"``: RMS errors over all
        frames and over the frames MoCap lost (fewer than three markers); plus ``"lost_fraction"``.

    Examples
    --------
    >>> out = simulate_walk(lesson_plans(0.05)["trot"])
    >>> table = estimation_table(out.log)
    >>> table["fused"]["position_mm"] < table["imu"]["position_mm"]
    True
    """
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a TrialLog, got {type(log).__name__}")
    truth = log.T_world_body()
    mocap = mocap_body_poses(MARKERS, log.mocap, log.mocap_visible)
    imu = _imu_alone(log, truth, mocap.T_world_body)
    fused = fuse_body_state(log.imu_gyro, log.imu_acc, float(log.t[1] - log.t[0]), mocap.T_world_body, mocap.ok,
                            R0=truth[0, :3, :3], p0=truth[0, :3, 3])
    lost = ~mocap.ok
    table = {"lost_fraction": float(lost.mean())}
    for name, R, p in (("mocap", mocap.T_world_body[:, :3, :3], mocap.T_world_body[:, :3, 3]),
                       ("imu", imu.R, imu.p), ("fused", fused.R, fused.p)):
        pe = position_errors(p, truth[:, :3, 3]) * 1000
        oe = np.degrees(orientation_errors(R, truth[:, :3, :3]))
        table[name] = {"position_mm": _rms(pe), "position_lost_mm": _rms(pe[lost]),
                       "orientation_deg": _rms(oe), "orientation_lost_deg": _rms(oe[lost]),
                       "final_position_mm": float(pe[-1])}
    return table


def _imu_alone(log: TrialLog, truth: np.ndarray, mocap_poses: np.ndarray):
    """The fusion filter with only the first MoCap frame: gyro and accelerometer integrated, biases and all."""
    first = np.zeros(len(log), bool)
    first[0] = True
    return fuse_body_state(log.imu_gyro, log.imu_acc, float(log.t[1] - log.t[0]), mocap_poses, first,
                           R0=truth[0, :3, :3], p0=truth[0, :3, 3])


class ImuDrift(NamedTuple):
    """Why the IMU alone drifts: measured errors against two growth laws (:func:`imu_drift`)."""

    t: np.ndarray                  # s from the trial's start
    position_error: np.ndarray     # m, |p_imu - p_true|
    tilt_error: np.ndarray         # rad, angle between the true and the estimated up axis
    tilt_rate: float               # rad/s, the gyro bias about the horizontal axes
    from_tilt: np.ndarray          # m, g * tilt_rate * t^3 / 6: gravity leaking through the tilt
    from_acc_bias: np.ndarray      # m, |acc_bias| * t^2 / 2: the accelerometer's own bias


def imu_drift(log: TrialLog, sensors: SensorSettings = SensorSettings()) -> ImuDrift:
    """The IMU-only pose's errors over a trial, beside what the sensor biases predict.

    A gyro bias ``b`` about a horizontal axis tilts the estimated attitude by ``b t``; the
    accelerometer's reading of gravity, rotated by that wrong attitude, leaves ``g sin(b t) ~ g b t`` of
    false horizontal acceleration, which integrates twice to ``g b t^3 / 6``. An accelerometer bias
    ``a`` alone gives ``a t^2 / 2`` (Woodman 2007, Sec. 6, propagates both errors this way).

    Parameters
    ----------
    log : TrialLog
        A trial simulated with ``sensors``.
    sensors : SensorSettings, default SensorSettings()
        The biases the trial's IMU had.

    Returns
    -------
    ImuDrift

    Examples
    --------
    >>> drift = imu_drift(simulate_walk(lesson_plans(0.05)["crawl"]).log)
    >>> bool(drift.position_error[-1] > drift.from_acc_bias[-1])      # the tilt term dominates
    True
    """
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a TrialLog, got {type(log).__name__}")
    if not isinstance(sensors, SensorSettings):
        raise TypeError(f"sensors: expected a SensorSettings, got {type(sensors).__name__}")
    truth = log.T_world_body()
    imu = _imu_alone(log, truth, mocap_body_poses(MARKERS, log.mocap, log.mocap_visible).T_world_body)
    t = log.t - log.t[0]
    up_true, up_est = truth[:, :3, 2], imu.R[:, :, 2]
    tilt = np.arccos(np.clip(np.einsum("ij,ij->i", up_true, up_est), -1.0, 1.0))
    rate = float(np.hypot(*np.asarray(sensors.gyro_bias, float)[:2]))
    return ImuDrift(t, position_errors(imu.p, truth[:, :3, 3]), tilt, rate, GRAVITY * rate * t ** 3 / 6,
                    0.5 * float(np.linalg.norm(sensors.acc_bias)) * t ** 2)


def _detectors(detectors: Any, log: TrialLog) -> list:
    """The detectors as ``(label, on, off, debounce)`` rows, each tried on the log's first sample."""
    if detectors is None:
        return list(TOUCHDOWN_DETECTORS)
    want = "a sequence of (label, threshold_on, threshold_off, debounce)"
    if isinstance(detectors, (str, bytes)):
        raise TypeError(f"detectors: expected {want}, got {describe(detectors)}")
    try:
        rows = [tuple(d) for d in detectors]
    except TypeError:
        raise TypeError(f"detectors: expected {want}, got {describe(detectors)}") from None
    if not rows or any(len(r) != 4 or not isinstance(r[0], str) for r in rows):
        raise ValueError(f"detectors: expected {want}, got {describe(detectors)}")
    for k, (_, on, off, debounce) in enumerate(rows):
        try:
            detect_contacts(log.foot_force[:1], on, off, debounce)
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"detectors[{k}]: {exc}") from None
    return rows


def touchdown_table(log: TrialLog, detectors: Any = None, *, tolerance: int = 5, plan: Any = None,
                    gate: int = 10) -> list:
    """Touchdowns detected on the lower-leg force sensors against MuJoCo's true contacts.

    Parameters
    ----------
    log : TrialLog
    detectors : sequence of (str, float, float, int), optional
        ``(label, threshold_on, threshold_off, debounce)`` (N, N, samples); default
        :data:`TOUCHDOWN_DETECTORS`.
    tolerance : int, default 5
        Host samples (50 ms) within which a detection counts for a true touchdown.
    plan : WalkPlan, optional
        The plan the trial walked: adds a row for the last detector gated by the plan
        (:func:`~robokit.legged.touchdown.gate_touchdowns`, ``gate`` samples either side of each
        planned touchdown).
    gate : int, default 10
        Host samples (100 ms) of the gate.

    Returns
    -------
    list of dict
        ``label``, ``precision``, ``recall``, ``delay_ms``, ``true_touchdowns``, ``detected``.

    Examples
    --------
    >>> out = simulate_walk(lesson_plans(0.1)["crawl"])
    >>> rows = touchdown_table(out.log)
    >>> [r["label"] for r in rows][0], rows[-1]["recall"] > 0.9
    ('threshold 2 N', True)
    """
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a TrialLog, got {type(log).__name__}")
    detectors = _detectors(detectors, log)
    tolerance = as_int(tolerance, "tolerance", minimum=0)
    gate = as_int(gate, "gate", minimum=0)
    dt_ms = 1000.0 * float(log.t[1] - log.t[0])
    truth = np.asarray(log.contact)
    rows = []
    for label, on, off, debounce in detectors:
        detected = detect_contacts(log.foot_force, on, off, debounce)
        score = event_precision_recall(detected, truth, tolerance)
        rows.append({"label": str(label), "precision": score.precision, "recall": score.recall,
                     "delay_ms": score.mean_delay_samples * dt_ms,
                     "true_touchdowns": int(sum(len(e) for e in contact_events(truth))),
                     "detected": int(sum(len(e) for e in contact_events(detected)))})
    if plan is not None:
        if not isinstance(plan, WalkPlan) or len(plan.t) < len(log):
            raise ValueError("plan: expected the WalkPlan the trial walked (at least as many rows as the log)")
        true_events, planned = contact_events(truth), contact_events(plan.stance[:len(log)])
        gated = [gate_touchdowns(d, p, gate) for d, p in zip(contact_events(detected), planned)]
        score = score_leg_events(gated, true_events, tolerance)
        rows.append({"label": f"{label}, gated by the plan", "precision": score.precision, "recall": score.recall,
                     "delay_ms": score.mean_delay_samples * dt_ms, "true_touchdowns": sum(len(t) for t in true_events),
                     "detected": sum(len(g) for g in gated)})
    return rows


def endurance_table(outcomes: dict) -> list:
    """The motors' electrical power on each trial against the battery and the guide's 30 minutes.

    Parameters
    ----------
    outcomes : dict of str to TrialOutcome
        Trials by name.

    Returns
    -------
    list of dict
        ``name``, ``power`` (mean motor power, W), ``speed`` (m/s), ``endurance_min`` (the
        battery's 31.08 Wh at that power, motors only), ``guide_power`` (the 62.2 W that 30 minutes
        implies), ``motor_share`` (power / guide_power) and ``cost_of_transport`` (dimensionless,
        ``E / (m g d)``).

    Examples
    --------
    >>> out = simulate_walk(lesson_plans(0.05)["trot"])
    >>> row = endurance_table({"trot": out})[0]
    >>> round(row["guide_power"], 1), row["endurance_min"] > 30
    (62.2, True)
    """
    if not isinstance(outcomes, dict) or not outcomes:
        raise TypeError(f"outcomes: expected a non-empty dict of TrialOutcome, got {type(outcomes).__name__}")
    energy = battery_energy(GUIDE["battery_capacity"], GUIDE["battery_voltage"])
    guide_power = energy / GUIDE["runtime"]
    rows = []
    for name, out in outcomes.items():
        if not isinstance(out, TrialOutcome):
            raise TypeError(f"outcomes[{name!r}]: expected a TrialOutcome, got {type(out).__name__}")
        duration = _duration(out.log)
        power = out.energy / duration
        rows.append({"name": str(name), "power": power, "speed": out.distance / duration,
                     "endurance_min": endurance(energy, power) / 60.0, "guide_power": guide_power,
                     "motor_share": power / guide_power,
                     "cost_of_transport": cost_of_transport(out.energy, TOTAL_MASS, max(out.distance, 1e-9))})
    return rows


def true_margins(log: TrialLog) -> np.ndarray:
    """Static stability margin (m) of the true centre of mass over the feet truly in contact.

    ``-inf`` at instants with fewer than three feet down (:func:`~robokit.legged.support.stability_margins`).

    Examples
    --------
    >>> out = simulate_walk(lesson_plans(0.1)["crawl"])
    >>> bool(true_margins(out.log).min() > 0)
    True
    """
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a TrialLog, got {type(log).__name__}")
    return stability_margins(log.feet[:, :, :2], log.contact, log.com[:, :2])
