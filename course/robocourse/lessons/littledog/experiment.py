"""Lesson 04's experiment: LittleDog crawls and trots 1 m in MuJoCo, and each of the guide's numbers is tested.

Each function makes one of the lesson's tables from trials of :func:`robokit.legged.simulate_walk`:

* :func:`lesson_plans` - the crawl and the trot the lesson walks (1 m; 0.3 m in fast mode);
* :func:`loop_table` - servo rate (the guide's 500 Hz against 100 Hz) x link latency
  (0 / 10 / 30 / 50 ms) x servo stiffness: set-point tracking, distance, falls, motor power;
* :func:`estimation_table` - the trunk's pose from MoCap alone, from the IMU alone and fused,
  against the simulator's truth; :func:`imu_drift` - why the IMU alone drifts so far;
* :func:`touchdown_table` - touchdown detection on the lower-leg force sensors against MuJoCo's
  true contacts;
* :func:`endurance_table` - the motors' electrical power against the battery's 31.08 Wh and the
  guide's "about 30 minutes";
* :func:`true_margins` - the static stability margin of the true centre of mass over the feet
  truly on the ground.

No cache: every trial runs in about a second (the simulation runs at more than 20 x real time).

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
from robokit.progress import progress_bar
from robokit.validation import as_array, as_callable, as_int, as_positive, describe
from robokit.legged.gait import WalkPlan, walking_plan
from robokit.legged.gait_schedule import crawl_gait, trot_gait
from robokit.legged.littledog import GUIDE, MARKERS, TOTAL_MASS
from robokit.legged.mocap import mocap_body_poses
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
           "loop_table", "estimation_table", "ImuDrift", "imu_drift", "touchdown_table", "endurance_table",
           "true_margins"]

LESSON_CRAWL = {"period": 2.0, "step_length": 0.08, "step_height": 0.04, "duty_factor": 0.9}
"""The lesson's crawl: a 2 s cycle, 8 cm steps (0.04 m/s)."""
LESSON_TROT = {"period": 0.5, "step_length": 0.06, "step_height": 0.04}
"""The lesson's trot: a 0.5 s cycle, 6 cm steps (0.12 m/s); 4 cm foot lift (3 cm scuffs)."""
LESSON_DISTANCE = 0.3 if FAST else 1.0
"""How far the lesson walks (m): 1 m, the issue's distance (0.3 m in fast mode)."""
LATENCIES = (0.0, 0.01, 0.03, 0.05)
"""Link latencies of the loop table (s)."""
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
