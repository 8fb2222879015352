"""LittleDog walking in MuJoCo with the guide's two loops: joint servos on the robot, a host over a link.

The guide (LittleDog User Guide, Sec. 2) splits control in two: the robot runs a servo on every
joint at 500 Hz, and a host computer sends new joint set-points every 10 ms (100 Hz) over a
wireless link, reading back a snapshot of the state and logging everything. :func:`simulate_walk`
runs exactly that loop around MuJoCo:

* every physics step (1 ms): each joint's torque comes from its DC motor, given the voltage the
  servo holds and the joint's speed (back-EMF) - :func:`robokit.controllers.joint_torque`, which
  MuJoCo's affine actuators apply (:func:`~robokit.legged.littledog.littledog_mjcf` with a motor);
* every servo tick (2 ms at 500 Hz): the robot takes the newest set-point that has arrived over
  the link and sets a new voltage by a discrete PD law - :func:`robokit.controllers.pd_servo_step`;
* every host cycle (10 ms): the host logs the state and the sensors, and sends the set-point that
  the walking plan asks for next (leg IK of the planned feet seen from the planned body) over the
  link, which may delay, jitter or drop it - :class:`robokit.controllers.SetpointChannel`. A
  reactive host (``host=``, :class:`~robokit.legged.posture.PostureFeedback`) first fits the trunk's
  pose to the MoCap markers of that cycle and solves the IK for a body pose corrected by it.

The sensors are recorded true and then corrupted the way the real ones are (MoCap marker noise and
dropouts, IMU noise and bias), so the trial log holds what the host would have seen. The IMU
reports the average of its readings over each host period, as an IMU's anti-aliasing filter does:
sampled once per 10 ms instead, the impacts of touchdowns (a few milliseconds long) would alias
into its 100 Hz data.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Secs. 2-3.
.. [2] E. Todorov, T. Erez and Y. Tassa, "MuJoCo: a physics engine for model-based control",
   *IROS* 2012.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, NamedTuple

import mujoco
import numpy as np

from ..controllers import LITTLEDOG_MOTOR, DCMotor, SetpointChannel, motor_current, pd_servo_step
from ..geometry import as_se3, fit_rigid, quat_to_matrix, se3_from_rt
from ..validation import as_array, as_rng, as_int, as_positive
from .gait import WalkPlan
from .imu import simulate_imu
from .leg_kinematics import UnreachableFootError, body_ik
from .littledog import LEGS, MARKERS, TIMESTEP, littledog_model
from .mocap import MocapFrames, simulate_mocap
from .posture import PostureFeedback
from .power import trial_power
from .servo_design import littledog_servo_gains
from .terrain import Terrain
from .trial_log import TrialLog, empty_streams, trial_meta

__all__ = ["LoopSettings", "SensorSettings", "TrialOutcome", "simulate_walk", "FALL_HEIGHT", "CONTACT_FORCE"]

FALL_HEIGHT = 0.06
"""The robot has fallen when its trunk's centre is lower than this (m) or it tips past 45 deg."""

SET_DOWN_DEPTH = 1e-6
"""How far below the plan's first body pose the robot is set down (m): its standing feet then start
in contact. Feet placed exactly on the ground are a tie that MuJoCo breaks by rounding, so whether the
first record shows them loaded would depend on the model's last digits."""

CONTACT_FORCE = 0.2
"""A foot is truly in contact (the log's ``contact``) when the ground pushes it with more than this
normal force (N): MuJoCo also reports touching contacts that carry nothing."""


@dataclass(frozen=True)
class LoopSettings:
    """The two control loops and the link between them.

    Parameters
    ----------
    servo_rate : float, default 500
        Joint servo rate on the robot (Hz; the guide's 500). Must divide the 1 kHz physics rate.
    latency, jitter : float, default 0
        One-way link delay and its spread (s) for every set-point packet.
    loss : float, default 0
        Probability that a packet is lost.
    gains : (float, float), optional
        Servo ``(kp, kd)`` in V/rad and V s/rad; default :func:`littledog_servo_gains` for the motor
        the trial uses.

    Examples
    --------
    >>> LoopSettings(servo_rate=100.0, latency=0.03).servo_rate
    100.0
    >>> LoopSettings(servo_rate=300.0)
    Traceback (most recent call last):
    ...
    ValueError: servo_rate: expected a rate that divides the 1000 Hz physics rate (e.g. 500, 250, 100), got 300.0
    """

    servo_rate: float = 500.0
    latency: float = 0.0
    jitter: float = 0.0
    loss: float = 0.0
    gains: tuple | None = None

    def __post_init__(self):
        rate = as_positive(self.servo_rate, "servo_rate")
        steps = 1.0 / (rate * TIMESTEP)
        if abs(steps - round(steps)) > 1e-9 or round(steps) < 1:
            raise ValueError(f"servo_rate: expected a rate that divides the {1 / TIMESTEP:.0f} Hz physics "
                             f"rate (e.g. 500, 250, 100), got {self.servo_rate}")
        as_positive(self.latency, "latency", allow_zero=True)
        as_positive(self.jitter, "jitter", allow_zero=True)
        loss = as_positive(self.loss, "loss", allow_zero=True)
        if loss >= 1:
            raise ValueError(f"loss: expected a probability in [0, 1), got {loss}")
        if self.gains is not None:
            if not isinstance(self.gains, (tuple, list)) or len(self.gains) != 2:
                raise ValueError(f"gains: expected (kp, kd) or None, got {self.gains!r}")
            as_positive(self.gains[0], "gains[0] (kp)")
            as_positive(self.gains[1], "gains[1] (kd)", allow_zero=True)


@dataclass(frozen=True)
class SensorSettings:
    """How the simulated sensors err (standard deviations per sample; biases constant).

    The defaults are ours (the guide gives none): Vicon-class marker noise of 0.5 mm with 5 % of
    markers occluded, and now and then (probability 0.005 per frame) the whole trunk hidden for
    0.2 s; a MEMS gyro with 0.02 rad/s bias, an accelerometer with 0.1 m/s^2 bias; 0.1 N of force
    sensor noise.

    Examples
    --------
    >>> import dataclasses
    >>> perfect = dataclasses.replace(SensorSettings(), gyro_bias=(0.0, 0.0, 0.0), force_noise=0.0)
    >>> perfect.gyro_bias, perfect.force_noise, SensorSettings().gyro_bias
    ((0.0, 0.0, 0.0), 0.0, (0.02, -0.015, 0.01))
    """

    mocap_noise: float = 0.0005
    mocap_dropout: float = 0.05
    mocap_bursts: float = 0.005
    mocap_burst_length: int = 20
    gyro_noise: float = 0.005
    acc_noise: float = 0.05
    gyro_bias: tuple = (0.02, -0.015, 0.01)
    acc_bias: tuple = (0.1, -0.05, 0.08)
    force_noise: float = 0.1

    def __post_init__(self):
        # refused here, by name, rather than after the whole walk has run (the sensors are corrupted last)
        for name in ("mocap_noise", "gyro_noise", "acc_noise", "force_noise"):
            as_positive(getattr(self, name), name, allow_zero=True)
        for name in ("mocap_dropout", "mocap_bursts"):
            if as_positive(getattr(self, name), name, allow_zero=True) > 1:
                raise ValueError(f"{name}: expected a probability in [0, 1], got {getattr(self, name)}")
        as_int(self.mocap_burst_length, "mocap_burst_length", minimum=1)
        for name in ("gyro_bias", "acc_bias"):
            as_array(getattr(self, name), name, shape=(3,))


class TrialOutcome(NamedTuple):
    """What one walking trial produced.

    Attributes
    ----------
    log : TrialLog
        Every host-cycle sample (:mod:`robokit.legged.trial_log`).
    fell : bool
        The trunk dropped below :data:`FALL_HEIGHT` or tipped past 45 deg (the trial stops there).
    distance : float
        Forward progress of the trunk along the plan's direction (m).
    energy : float
        Electrical energy the twelve motors drew (J): over every servo tick, the held voltage times
        the current at the joint's mean speed over the tick (its angle change over the tick; the
        current is linear in the speed, so this is the tick's mean current), without regeneration
        (a joint's negative power is lost: :func:`robokit.legged.trial_power`).
    tracking_rms : float
        RMS over joints and host cycles of the set-point the host sent minus the angle the joint had
        reached one host period later, when the next set-point went out (rad).
    link : dict
        The link's packet counters.
    """

    log: TrialLog
    fell: bool
    distance: float
    energy: float
    tracking_rms: float
    link: dict


def _tipped(quat: np.ndarray) -> bool:
    # the body z axis' world z component is 1 - 2(x^2 + y^2); below cos 45 deg the robot has tipped
    return 1 - 2 * (quat[1] ** 2 + quat[2] ** 2) < np.cos(np.pi / 4)


class _Probes(NamedTuple):
    """Where the model keeps what the host reads: feet, force sensors, IMU and trunk."""

    foot_geoms: list
    foot_sites: list
    force_adr: list
    imu: slice
    trunk: int

    @classmethod
    def of(cls, model: mujoco.MjModel) -> "_Probes":
        gyro = model.sensor_adr[model.sensor("imu_gyro").id]
        if model.sensor_adr[model.sensor("imu_acc").id] != gyro + 3:
            raise RuntimeError("the model's IMU sensors are not gyro then accelerometer")
        return cls([model.geom(f"{leg}_foot").id for leg in LEGS], [model.site(f"{leg}_foot").id for leg in LEGS],
                   [model.sensor_adr[model.sensor(f"{leg}_force").id] + 2 for leg in LEGS],
                   slice(gyro, gyro + 6), model.body("trunk").id)


class _Servo:
    """The robot's joint servo: every tick it takes the newest set-point and holds a new voltage.

    It also keeps each tick's voltage and mean joint speed, from which the trial's energy comes.
    """

    def __init__(self, q_ref: np.ndarray, q: np.ndarray, gains: tuple, dt: float, motor: DCMotor, max_ticks: int):
        self.q_ref, self.q_prev, self.voltage = q_ref.copy(), q.copy(), np.zeros(12)
        self.kp, self.kd = gains
        self.dt, self.motor = dt, motor
        self.tick_voltage, self.tick_speed, self.ticks = np.zeros((max_ticks + 1, 12)), np.zeros((max_ticks + 1, 12)), 0

    def tick(self, arrived: np.ndarray | None, q_now: np.ndarray) -> np.ndarray:
        """One servo period: the set-point that ``arrived`` (if any), then the PD voltage for ``q_now``."""
        if arrived is not None:
            self.q_ref = arrived
        self.tick_speed[self.ticks] = (q_now - self.q_prev) / self.dt        # the tick that just ended
        self.voltage = pd_servo_step(self.q_ref, q_now, self.q_prev, self.kp, self.kd, self.dt,
                                     self.motor.voltage_max, validate=False)
        self.ticks += 1
        self.tick_voltage[self.ticks] = self.voltage
        self.q_prev = q_now
        return self.voltage

    def energy(self, q_end: np.ndarray) -> float:
        """Electrical energy drawn over the ticks so far, the last one ending at ``q_end`` (J)."""
        self.tick_speed[self.ticks] = (q_end - self.q_prev) / self.dt
        # the voltage is held over a tick and the current is linear in the speed, so each tick's V i is
        # the one at its mean speed; no regeneration (trial_power clips a braking joint's power)
        n = self.ticks + 1
        return float(trial_power(self.tick_voltage[1:n], self.tick_speed[1:n], self.motor).sum()) * self.dt


def _host_period(plan: WalkPlan) -> tuple[float, int]:
    """The plan's host period (s) and its number of physics steps, or a ValueError naming the plan."""
    t = as_array(plan.t, "plan.t", ndim=1, min_size=2)
    as_array(plan.feet_world, "plan.feet_world", shape=(len(t), 4, 3))
    as_se3(plan.T_world_body, "plan.T_world_body", batch=True)
    host_dt = float(t[1] - t[0])
    host_steps = int(round(host_dt / TIMESTEP))
    if host_steps < 1 or abs(host_steps * TIMESTEP - host_dt) > 1e-9 or np.any(np.abs(np.diff(t) - host_dt) > 1e-9):
        raise ValueError(f"plan.t: expected even steps of a whole number of {1000 * TIMESTEP:.0f} ms physics steps "
                         f"(the host period), got a first step of {host_dt} s")
    if len(plan.T_world_body) != len(t):
        raise ValueError(f"plan.T_world_body: expected {len(t)} poses (one per plan.t), got {len(plan.T_world_body)}")
    return host_dt, host_steps


def _place(model: mujoco.MjModel, T_world_body: np.ndarray, q: np.ndarray) -> mujoco.MjData:
    """The robot standing at the plan's first body pose with joint angles ``q``, its feet
    :data:`SET_DOWN_DEPTH` into the ground."""
    data = mujoco.MjData(model)
    data.qpos[:3] = T_world_body[:3, 3] - [0.0, 0.0, SET_DOWN_DEPTH]
    mujoco.mju_mat2Quat(data.qpos[3:7], T_world_body[:3, :3].ravel())
    data.qpos[7:] = q
    mujoco.mj_forward(model, data)
    return data


def _snapshot(rec: dict, k: int, model: mujoco.MjModel, data: mujoco.MjData, probes: _Probes, servo: _Servo) -> None:
    """Host cycle ``k``'s record of the true state, the servo and the foot contacts (guide Sec. 3)."""
    rec["q"][k] = data.qpos[7:]
    rec["qd"][k] = data.qvel[6:]
    rec["q_ref"][k] = servo.q_ref
    rec["voltage"][k] = servo.voltage
    rec["tau"][k] = data.actuator_force
    rec["current"][k] = motor_current(servo.voltage, data.qvel[6:], servo.motor, validate=False)
    rec["body_pos"][k] = data.qpos[:3]
    rec["body_quat"][k] = data.qpos[3:7]
    rec["body_vel"][k, :3] = data.qvel[:3]
    rec["body_vel"][k, 3:] = data.qvel[3:6]
    rec["com"][k] = data.subtree_com[probes.trunk]
    rec["feet"][k] = data.site_xpos[probes.foot_sites]
    rec["foot_force"][k] = -data.sensordata[probes.force_adr]      # compression along the shank
    wrench = np.zeros(6)
    for c in range(data.ncon):
        pair = (data.contact.geom1[c], data.contact.geom2[c])
        for i, g in enumerate(probes.foot_geoms):
            if g in pair:
                mujoco.mj_contactForce(model, data, c, wrench)
                rec["contact"][k, i] |= wrench[0] > CONTACT_FORCE      # normal force, contact frame


class _MocapFeed:
    """The MoCap frames a reactive host sees as the walk runs: each frame's markers where the trunk
    truly is, corrupted by noise and occlusions drawn before the walk (they do not depend on the pose),
    and the trunk's pose fitted to them (None when fewer than three markers are seen)."""

    def __init__(self, n: int, sensors: SensorSettings, gen: np.random.Generator):
        frames = simulate_mocap(np.broadcast_to(np.eye(4), (n, 4, 4)), MARKERS, sensors.mocap_noise,
                                sensors.mocap_dropout, gen, bursts=sensors.mocap_bursts,
                                burst_length=sensors.mocap_burst_length)
        self.visible = frames.visible
        self.noise = np.where(frames.visible[..., None], frames.positions - MARKERS, 0.0)
        self.positions = np.zeros_like(self.noise)

    def see(self, k: int, qpos: np.ndarray) -> np.ndarray | None:
        """Frame ``k`` of the trunk at MuJoCo's ``qpos`` (position, quaternion first): record the markers
        the MoCap reports, return the pose fitted to them."""
        vis = self.visible[k]
        markers = MARKERS @ quat_to_matrix(qpos[3:7], validate=False).T + qpos[:3]   # where the log's pose puts them
        self.positions[k] = np.where(vis[:, None], markers + self.noise[k], 0.0)
        if vis.sum() < 3:
            return None
        fit = fit_rigid(MARKERS, self.positions[k], vis.astype(float), validate=False)
        return None if fit.degenerate else se3_from_rt(fit.R, fit.t, validate=False)

    def frames(self, rows: int) -> MocapFrames:
        """The frames the host saw in the first ``rows`` cycles."""
        return MocapFrames(self.positions[:rows], self.visible[:rows])


def _sensed(streams: dict, gyro: np.ndarray, acc: np.ndarray, sensors: SensorSettings,
            gen: np.random.Generator, seen: MocapFrames | None = None) -> dict:
    """The true streams with the sensors corrupted as :class:`SensorSettings` says (forces, IMU, MoCap);
    ``seen``: the MoCap frames a reactive host already saw, kept as they were."""
    streams["foot_force"] = streams["foot_force"] + gen.normal(0.0, sensors.force_noise, (len(gyro), 4))
    streams["imu_gyro"], streams["imu_acc"] = simulate_imu(
        gyro, acc, gen, gyro_noise=sensors.gyro_noise, acc_noise=sensors.acc_noise,
        gyro_bias=np.asarray(sensors.gyro_bias), acc_bias=np.asarray(sensors.acc_bias))
    if seen is None:
        T_true = se3_from_rt(quat_to_matrix(streams["body_quat"]), streams["body_pos"])
        seen = simulate_mocap(T_true, MARKERS, sensors.mocap_noise, sensors.mocap_dropout, gen,
                              bursts=sensors.mocap_bursts, burst_length=sensors.mocap_burst_length)
    streams["mocap"], streams["mocap_visible"] = seen
    return streams


def simulate_walk(plan: WalkPlan, loops: LoopSettings = LoopSettings(), sensors: SensorSettings = SensorSettings(),
                  *, motor: DCMotor = LITTLEDOG_MOTOR, host: PostureFeedback | None = None,
                  rng: Any = 0, terrain: Terrain | None = None) -> TrialOutcome:
    """Walk LittleDog through a plan in MuJoCo with the servo and host loops of the guide.

    Parameters
    ----------
    plan : WalkPlan
        Body poses and foot positions at the host rate (:func:`robokit.legged.walking_plan`).
    loops : LoopSettings
        Servo rate, link latency/jitter/loss and servo gains.
    sensors : SensorSettings
        Sensor noise and biases.
    motor : DCMotor
        The joint motors (all twelve alike).
    host : PostureFeedback, optional
        A reactive host: every cycle it fits the trunk's pose to that cycle's MoCap markers and
        solves the IK for the planned feet from the plan's body pose corrected by the feedback
        (:mod:`robokit.legged.posture`); a cycle whose corrected IK is out of reach resends the last
        set-point. Default: the host plays the plan.
    rng : numpy.random.Generator or int, default 0
        Seeds the link and the sensor noise. A reactive host's MoCap noise comes from a generator
        spawned from it, so the link's draws are those of the same seed without feedback.
    terrain : Terrain, optional
        Boards on the floor to walk over (:func:`~robokit.legged.littledog.littledog_mjcf`); the
        trial's meta records it. Default: flat ground.

    Returns
    -------
    TrialOutcome

    Raises
    ------
    TypeError
        If ``plan``, ``loops``, ``sensors``, ``motor``, ``host`` or ``terrain`` is not of its class.
    UnreachableFootError
        (A ``ValueError``) if the plan asks for feet out of reach.
    ValueError
        If the plan's times are not even steps of whole physics steps or its arrays disagree in
        length.

    Notes
    -----
    LittleDog User Guide, Sec. 2: the servo runs on its own clock (every ``1 / servo_rate`` s of
    simulated time, whether or not that divides the host period) and the host every
    ``plan.t[1] - plan.t[0]``.

    Examples
    --------
    >>> from robokit.legged import crawl_gait, walking_plan
    >>> out = simulate_walk(walking_plan(crawl_gait(), 0.05))
    >>> out.fell, len(out.log) == len(walking_plan(crawl_gait(), 0.05).t)
    (False, True)
    """
    for name, value, cls in (("plan", plan, WalkPlan), ("loops", loops, LoopSettings),
                             ("sensors", sensors, SensorSettings), ("motor", motor, DCMotor)):
        if not isinstance(value, cls):
            hint = " (robokit.legged.walking_plan)" if cls is WalkPlan else ""
            raise TypeError(f"{name}: expected a {cls.__name__}{hint}, got {type(value).__name__}")
    if host is not None and not isinstance(host, PostureFeedback):
        raise TypeError(f"host: expected a PostureFeedback or None, got {type(host).__name__}")
    seed = rng if isinstance(rng, int) and not isinstance(rng, bool) else None
    gen = as_rng(rng)
    host_dt, host_steps = _host_period(plan)
    servo_steps = int(round(1.0 / (loops.servo_rate * TIMESTEP)))
    q_cmd, ok = body_ik(plan.feet_world, plan.T_world_body, validate=False)
    if not ok.all():
        raise UnreachableFootError(f"plan: {int((~ok).sum())} host cycles ask for feet out of reach (first at "
                         f"t = {plan.t[~ok][0]:.2f} s)")
    model = littledog_model(motor=motor, terrain=terrain)
    data = _place(model, plan.T_world_body[0], q_cmd[0])
    probes = _Probes.of(model)
    channel = SetpointChannel(period=host_dt, latency=loops.latency, jitter=loops.jitter, loss=loops.loss, rng=gen)
    n = len(plan.t)
    gains = loops.gains if loops.gains is not None else littledog_servo_gains(motor=motor)
    servo = _Servo(q_cmd[0], data.qpos[7:], gains, servo_steps * TIMESTEP, motor, -(-n * host_steps // servo_steps))
    rec = empty_streams(n, 1.0 / host_dt)
    rec["t"][:] = plan.t
    feed = None if host is None else _MocapFeed(n, sensors, gen.spawn(1)[0])     # numpy >= 1.25
    posture = None if host is None else host.start(host_dt)
    imu_true, imu_sum = np.zeros((n, 6)), data.sensordata[probes.imu] * host_steps
    fell, rows = False, n
    for k in range(n):
        now = k * host_dt
        # host cycle: snapshot of the state and sensors, then the next set-point goes out
        _snapshot(rec, k, model, data, probes, servo)
        imu_true[k], imu_sum = imu_sum / host_steps, np.zeros(6)          # the IMU's average over the period
        seen = None if feed is None else feed.see(k, data.qpos)          # every logged row has its MoCap frame
        if data.qpos[2] < FALL_HEIGHT or _tipped(data.qpos[3:7]):
            fell, rows = True, k + 1
            break
        if posture is not None:      # a reactive host: the IK from the plan's body corrected by what MoCap sees
            T_cmd = posture.command(plan.T_world_body[k], seen)
            q, ok = body_ik(plan.feet_world[k], T_cmd, validate=False)
            q_cmd[k] = q[0] if ok[0] else q_cmd[max(k - 1, 0)]
        channel.send(now, q_cmd[k], validate=False)
        for s in range(host_steps):
            if (k * host_steps + s) % servo_steps == 0:                   # the servo's own clock
                data.ctrl[:] = servo.tick(channel.receive(now + s * TIMESTEP, validate=False), data.qpos[7:].copy())
                # MuJoCo's actuators apply joint_torque(voltage, dq/dt)
            mujoco.mj_step(model, data)
            imu_sum += data.sensordata[probes.imu]
    energy = servo.energy(data.qpos[7:])
    rec["q_cmd"][:] = q_cmd
    streams = _sensed({key: value[:rows] for key, value in rec.items()}, imu_true[:rows, :3], imu_true[:rows, 3:],
                      sensors, gen, None if feed is None else feed.frames(rows))
    meta = trial_meta(gait=plan.gait, host_rate=1.0 / host_dt, servo_rate=loops.servo_rate,
                      link_latency=loops.latency, link_jitter=loops.jitter, link_loss=loops.loss, seed=seed,
                      notes="simulated in MuJoCo by robokit.legged.simulate_walk", kp=servo.kp, kd=servo.kd,
                      **({} if terrain is None else {"terrain": asdict(terrain)}),
                      **({} if host is None else {"host": asdict(host)}))
    heading = plan.T_world_body[-1, :3, 3] - plan.T_world_body[0, :3, 3]
    heading = heading / max(np.linalg.norm(heading), 1e-12)
    distance = float((streams["body_pos"][-1] - streams["body_pos"][0]) @ heading)
    tracking = float(np.sqrt(np.mean((streams["q_cmd"][:-1] - streams["q"][1:]) ** 2)))
    counters = {name: getattr(channel, name) for name in ("sent", "delivered", "lost", "stale", "rejected")}
    return TrialOutcome(TrialLog(streams, meta), fell, distance, energy, tracking, counters)
