"""The LittleDog quadruped: its published facts and a MuJoCo model written from them by code.

One source of truth: the constants below give the kinematics (:mod:`robokit.legged.leg_kinematics`
computes with them) and :func:`littledog_mjcf` writes the same numbers into MJCF for the physics,
so the two can never disagree.

What comes from where:

* The *LittleDog User Guide* (Question 2 of the course's assignment; Sec. 3 "Platform
  Specification"): body 340 x 180 x 143 mm, ground clearance 120 mm, leg length 180 mm, total mass
  3 kg, twelve actuated degrees of freedom (three motors per leg), a single-axis force sensor in
  each lower leg, a MEMS IMU, a 2.1 Ah / 14.8 V battery; Sec. 2: joint servos at 500 Hz, host loop
  at 100 Hz. The joints' names (hip roll, hip pitch, knee) are the MIT model's.
  :data:`GUIDE` holds them.
* The guide's Sec. 4 figures (body, hip and leg frames) did not survive the text extraction, and
  the guide gives no hip positions, segment lengths, masses of parts or joint limits. Those come
  from the MIT LittleDog model (converted from the CSAIL LittleDog simulator; Drake's
  ``examples/LittleDog/LittleDog.urdf``): hips at x = +-0.101 m, y = +-0.03625 m; the hip-pitch axis
  0.0236 m further out (0.0207 m on the hind-right leg, as that model gives it: :data:`HIP_OFFSETS`);
  upper leg 0.0751 m; the foot centre 0.0985 m down the lower leg and 0.0265 m off its line
  (backwards on the front legs, forwards on the hind ones); the parts' masses and the joint limits.
  We draw the lower leg straight from knee to foot (0.1020 m): that only moves the knee angle's zero
  by :data:`KNEE_ZERO` = 0.2628 rad, so our knee angle is the model's plus 0.2628 rad on a front
  leg and minus 0.2628 rad on a hind one, and :data:`JOINT_LIMITS` are the model's limits moved by
  the same amount (:data:`SOURCE_JOINT_LIMITS` keeps them as the model states them). Knees and feet
  then stand exactly where the model's do; ``tests/test_legged_source_model.py`` compares them with
  the model's file.
* Assumptions of ours, not the model's: the shapes drawn and simulated for the links (cylinders and
  capsules, whose inertias and centres of mass MuJoCo takes from those shapes), the foot sphere's
  radius, the motors (:mod:`robokit.controllers.dc_motor`) and the trunk below.
* Our reading of the guide's body size: the trunk is 0.24 x 0.09 x 0.023 m and, standing, its
  bottom is 0.120 m above the ground (the guide's clearance) and its top 0.143 m (the guide's
  height); the trunk mass makes the total 3 kg (the MIT model's parts sum to 2.75 kg).

Frames: the body frame has its origin at the trunk's centre, x forward, y left, z up; the world
frame has z up. Legs are ordered ``FL, FR, HL, HR`` and each has joints ``hip_roll`` (about x),
``hip_pitch`` (about y) and ``knee`` (about y); a 12-vector ``q`` is leg-major. Positive pitch and
knee angles swing the foot backwards.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Secs. 2-4).
.. [2] R. Tedrake et al., the LittleDog model of the Drake toolbox (``examples/LittleDog``),
   converted from the CSAIL LittleDog simulator, MIT, 2014.
.. [3] E. Todorov, T. Erez and Y. Tassa, "MuJoCo: a physics engine for model-based control",
   *IROS* 2012; MuJoCo documentation, "XML reference" (MJCF).
"""
from __future__ import annotations

import functools

import numpy as np

from ..controllers.dc_motor import DCMotor, reflected_inertia
from ..validation import as_finite_scalar, as_positive
from .terrain import Terrain, terrain_transform

__all__ = ["LEGS", "JOINTS", "JOINT_NAMES", "GUIDE", "HIP_POSITIONS", "HIP_OFFSETS", "UPPER_LEG", "SHANK",
           "LOWER_LEG", "KNEE_ZERO", "KNEE_SHIFT", "SOURCE_JOINT_LIMITS", "FOOT_RADIUS", "TRUNK_SIZE", "TRUNK_MASS",
           "LEG_MASSES", "TOTAL_MASS",
           "STANDING_HEIGHT", "STANCE_FEET", "MARKERS", "JOINT_LIMITS", "TIMESTEP", "littledog_mjcf",
           "littledog_model"]

LEGS = ("FL", "FR", "HL", "HR")
"""Leg order: front-left, front-right, hind-left, hind-right."""
JOINTS = ("hip_roll", "hip_pitch", "knee")
"""Joint order within a leg."""
JOINT_NAMES = tuple(f"{leg}_{joint}" for leg in LEGS for joint in JOINTS)
"""The twelve actuated joints, leg-major (the order of every 12-vector ``q``)."""

GUIDE = {
    "body_size": (0.340, 0.180, 0.143),   # m, Sec. 3.i
    "ground_clearance": 0.120,            # m, Sec. 3.i
    "leg_length": 0.180,                  # m, Sec. 3.i
    "total_mass": 3.0,                    # kg, Sec. 3.i
    "servo_rate": 500.0,                  # Hz, Sec. 2
    "host_rate": 100.0,                   # Hz, Sec. 2 ("every 10ms")
    "battery_capacity": 2.1,              # Ah, Sec. 3.ii
    "battery_voltage": 14.8,              # V, Sec. 3.ii (4 LiPo cells in series)
    "runtime": 30 * 60.0,                 # s, Sec. 1 ("approximately 30 minutes")
}
"""The LittleDog User Guide's numbers (SI units), with the section that states each."""

HIP_POSITIONS = np.array([[0.101, 0.03625, 0.0], [0.101, -0.03625, 0.0],
                          [-0.101, 0.03625, 0.0], [-0.101, -0.03625, 0.0]])
"""Hip-roll joint of each leg in the body frame (m); MIT model."""
HIP_OFFSETS = np.array([0.0236, 0.0236, 0.0236, 0.0207])
"""Lateral distance from each leg's hip-roll joint to its hip-pitch axis (m, outwards), legs in
:data:`LEGS` order; MIT model, whose hind-right leg has 0.0207 m (the guide gives no value)."""
UPPER_LEG = 0.0751
"""Hip pitch to knee (m); MIT model."""
SHANK = (0.0265, 0.0985)
"""The MIT model's foot centre seen from the knee (m): off the leg's line, along it."""
LOWER_LEG = float(np.hypot(*SHANK))
"""Knee to foot centre (m): 0.1020, the MIT model's bent shank drawn straight."""
KNEE_ZERO = float(np.arctan2(*SHANK))
"""How far our straight-shank knee zero turns from the MIT model's (rad): 0.2628."""
KNEE_SHIFT = np.array([KNEE_ZERO, KNEE_ZERO, -KNEE_ZERO, -KNEE_ZERO])
"""Our knee angle minus the MIT model's, per leg (rad): the front feet sit behind the knee's line."""
FOOT_RADIUS = 0.01
"""Radius of the foot sphere (m); ours."""
TRUNK_SIZE = (0.24, 0.09, 0.023)
"""Trunk box, full lengths (m); ours, read from the guide's height and clearance."""
LEG_MASSES = (0.0623, 0.1279, 0.0464)
"""Hip, upper-leg and lower-leg masses (kg); MIT model."""
TOTAL_MASS = GUIDE["total_mass"]
TRUNK_MASS = TOTAL_MASS - 4 * sum(LEG_MASSES)
"""The trunk takes what the legs leave of the guide's 3 kg (2.0536 kg)."""
STANDING_HEIGHT = GUIDE["ground_clearance"] + TRUNK_SIZE[2] / 2
"""Height of the trunk's centre when standing (m): 0.1315."""
STANCE_FEET = np.array([[0.16, 0.08, 0.0], [0.16, -0.08, 0.0],
                        [-0.16, 0.08, 0.0], [-0.16, -0.08, 0.0]]) + [0.0, 0.0, FOOT_RADIUS - STANDING_HEIGHT]
"""Nominal stance: foot centres in the body frame (m) when standing on flat ground."""
MARKERS = np.array([[0.10, 0.03, 0.0115], [0.10, -0.04, 0.0115],
                    [-0.11, 0.035, 0.0115], [-0.05, -0.02, 0.04]])
"""MoCap markers in the body frame (m): three on the trunk's top, one on a post (not coplanar)."""
SOURCE_JOINT_LIMITS = np.array([
    [-0.6, 0.6], [-3.5, 2.4], [-3.1, 1.0],     # FL
    [-0.6, 0.6], [-3.5, 2.4], [-3.1, 1.0],     # FR
    [-0.6, 0.6], [-2.4, 3.5], [-1.0, 3.1],     # HL
    [-0.6, 0.6], [-2.4, 3.5], [-1.0, 3.1],     # HR
])
"""Joint limits (rad) as the MIT model states them (its knee zero), rows in :data:`JOINT_NAMES` order."""
JOINT_LIMITS = SOURCE_JOINT_LIMITS.copy()
JOINT_LIMITS[2::3] += KNEE_SHIFT[:, None]                     # the knee rows, one per leg
"""Joint limits (rad) in our convention, rows in :data:`JOINT_NAMES` order: the MIT model's, its
knee rows moved by :data:`KNEE_SHIFT` (front knees -2.8372 to 1.2628, hind -1.2628 to 2.8372)."""
TIMESTEP = 0.001
"""MuJoCo's physics step (s): two steps per 500 Hz servo tick."""


def _f(x: float) -> str:
    return f"{x:.15g}"


def _vec(v) -> str:
    return " ".join(_f(float(x)) for x in v)


def _leg_xml(i: int, armature: float, damping: float) -> str:
    leg = LEGS[i]
    side = 1.0 if leg.endswith("L") else -1.0
    lim = JOINT_LIMITS[3 * i:3 * i + 3]
    offset = HIP_OFFSETS[i]
    m_hip, m_upper, m_lower = LEG_MASSES
    m_foot = 0.005
    joint = f'armature="{_f(armature)}" damping="{_f(damping)}"'
    return f"""
      <body name="{leg}_hip" pos="{_vec(HIP_POSITIONS[i])}">
        <joint name="{leg}_hip_roll" axis="1 0 0" range="{_vec(lim[0])}" {joint}/>
        <geom class="link" type="cylinder" size="0.012 0.012" fromto="0 0 0 0 {_f(side * offset)} 0" mass="{_f(m_hip)}"/>
        <body name="{leg}_upper" pos="0 {_f(side * offset)} 0">
          <joint name="{leg}_hip_pitch" axis="0 1 0" range="{_vec(lim[1])}" {joint}/>
          <geom class="link" type="capsule" size="0.011" fromto="0 0 0 0 0 {_f(-UPPER_LEG)}" mass="{_f(m_upper)}"/>
          <body name="{leg}_lower" pos="0 0 {_f(-UPPER_LEG)}">
            <joint name="{leg}_knee" axis="0 1 0" range="{_vec(lim[2])}" {joint}/>
            <site name="{leg}_force" pos="0 0 0"/>
            <geom class="link" type="capsule" size="0.008" fromto="0 0 0 0 0 {_f(-LOWER_LEG + FOOT_RADIUS)}" mass="{_f(m_lower - m_foot)}"/>
            <geom name="{leg}_foot" class="foot" pos="0 0 {_f(-LOWER_LEG)}" mass="{_f(m_foot)}"/>
            <site name="{leg}_foot" pos="0 0 {_f(-LOWER_LEG)}"/>
          </body>
        </body>
      </body>"""


def _terrain_xml(terrain: Terrain | None) -> str:
    """The terrain's boards as static boxes that collide like the ground, and its markers as sites."""
    if terrain is None:
        return ""
    if not isinstance(terrain, Terrain):
        raise TypeError(f"terrain: expected a robokit.legged.Terrain or None, got {type(terrain).__name__}")
    T = terrain_transform(terrain)
    out = []
    for k, (x0, x1, y0, y1, h) in enumerate(terrain.blocks):
        centre = T[:3, :3] @ [(x0 + x1) / 2, (y0 + y1) / 2, h / 2] + T[:3, 3]
        half = [(x1 - x0) / 2, (y1 - y0) / 2, h / 2]
        out.append(f'\n    <geom name="terrain{k}" type="box" pos="{_vec(centre)}" size="{_vec(half)}" '
                   f'euler="0 0 {_f(terrain.pose[2])}" contype="1" conaffinity="1" rgba="0.72 0.6 0.42 1"/>')
    for k, m in enumerate(terrain.markers):
        out.append(f'\n    <site name="terrain_marker{k}" pos="{_vec(T[:3, :3] @ m + T[:3, 3])}" size="0.006" '
                   f'rgba="0.9 0.9 0.9 1"/>')
    return "".join(out)


def littledog_mjcf(*, armature: float = 0.0, damping: float = 0.0, friction: float = 1.0,
                   timestep: float = TIMESTEP, motor: DCMotor | None = None, terrain: Terrain | None = None) -> str:
    """Write the LittleDog model as MJCF (MuJoCo's XML), from this module's constants.

    Parameters
    ----------
    armature : float, default 0
        Inertia added to every joint (kg m^2): a geared motor's rotor inertia reflected through its
        gearbox, ``J_m N^2`` (:func:`robokit.controllers.reflected_inertia`). With ``motor`` it is
        the motor's unless given.
    damping : float, default 0
        Viscous friction at every joint (N m s/rad); must stay 0 with ``motor``, whose damping
        already holds it.
    friction : float, default 1
        Coulomb friction coefficient between the feet and the ground.
    timestep : float, default :data:`TIMESTEP`
        Physics step (s).
    motor : DCMotor, optional
        Drive every joint with this geared DC motor: ``ctrl`` is then the motor voltage (clipped to
        ``+-motor.voltage_max``) and MuJoCo applies the joint torque ``K V - B dq/dt`` of
        :func:`robokit.controllers.joint_torque` itself, every physics step, as an affine actuator
        (gain ``K`` = ``motor.torque_per_volt``, bias ``-B dq/dt`` with ``B`` = ``motor.damping``).
        Without it ``ctrl`` is the joint torque (N m).
    terrain : Terrain, optional
        Boards on the floor (:class:`robokit.legged.terrain.Terrain`): each a static box
        ``terrain<k>`` the feet and the trunk collide with as with the ground, and its MoCap markers
        as sites ``terrain_marker<k>``. Default: the flat floor alone.

    Returns
    -------
    str
        MJCF with a free-floating trunk (``trunk``), twelve hinge joints named as
        :data:`JOINT_NAMES`, one actuator per joint (named like its joint), sites
        ``imu`` (gyro ``imu_gyro`` and accelerometer ``imu_acc``), ``marker0``..``marker3`` and per
        leg ``<leg>_force`` (a 3-axis ``force`` sensor at the knee, in the lower leg's frame whose z
        axis runs from the knee to the foot centre, about 15 deg from the MIT model's bent shank:
        the guide's single-axis lower-leg force sensor is its z component) and ``<leg>_foot``.

    Notes
    -----
    Only the feet and the trunk collide, and only with the ground and the terrain's boards; the
    legs' capsules carry mass and inertia (from their shapes) and are drawn, but pass through each
    other and through the boards.

    Examples
    --------
    >>> import mujoco
    >>> model = mujoco.MjModel.from_xml_string(littledog_mjcf())
    >>> model.nu, model.nq, round(float(sum(model.body_mass)), 4)
    (12, 19, 3.0)
    >>> from robokit.legged.terrain import Terrain
    >>> board = Terrain([[0.3, 0.5, -0.3, 0.3, 0.02]])
    >>> mujoco.MjModel.from_xml_string(littledog_mjcf(terrain=board)).geom("terrain0").size.tolist()
    [0.1, 0.3, 0.01]
    """
    armature = as_positive(armature, "armature", allow_zero=True)
    damping = as_positive(damping, "damping", allow_zero=True)
    if motor is not None:
        if not isinstance(motor, DCMotor):
            raise TypeError(f"motor: expected a DCMotor or None, got {type(motor).__name__}")
        if damping:
            raise ValueError(f"damping: expected 0 with a motor (its damping holds the joint's friction), got {damping}")
        armature = armature or reflected_inertia(motor)
    friction = as_positive(friction, "friction")
    timestep = as_positive(timestep, "timestep")
    if timestep > 0.01:
        raise ValueError(f"timestep: expected at most 0.01 s (the host period), got {timestep}")
    boards = _terrain_xml(terrain)
    legs = "".join(_leg_xml(i, armature, damping) for i in range(4))
    markers = "".join(f'\n      <site name="marker{k}" pos="{_vec(m)}" size="0.006" rgba="0.9 0.9 0.9 1"/>'
                      for k, m in enumerate(MARKERS))
    if motor is None:
        motors = "".join(f'\n    <motor name="{n}" joint="{n}"/>' for n in JOINT_NAMES)
    else:   # joint_torque's K V - B dq/dt, as MuJoCo's affine actuator
        vmax, gain, bias = _f(motor.voltage_max), _f(motor.torque_per_volt), _f(-motor.damping)
        motors = "".join(f'\n    <general name="{n}" joint="{n}" ctrlrange="-{vmax} {vmax}" gainprm="{gain}" '
                         f'biastype="affine" biasprm="0 0 {bias}"/>' for n in JOINT_NAMES)
    forces = "".join(f'\n    <force name="{leg}_force" site="{leg}_force"/>' for leg in LEGS)
    lx, ly, lz = (s / 2 for s in TRUNK_SIZE)
    return f"""<mujoco model="littledog">
  <compiler angle="radian" inertiafromgeom="true" autolimits="true"/>
  <option timestep="{_f(timestep)}" gravity="0 0 -9.81" integrator="implicitfast"/>
  <default>
    <geom contype="0" conaffinity="0" friction="{_f(friction)} 0.005 0.0001"/>
    <default class="link"><geom rgba="0.25 0.25 0.28 1"/></default>
    <default class="foot"><geom type="sphere" size="{_f(FOOT_RADIUS)}" contype="1" rgba="0.1 0.1 0.1 1"/></default>
  </default>
  <worldbody>
    <geom name="ground" type="plane" size="5 5 0.1" contype="1" conaffinity="1" rgba="0.8 0.8 0.8 1"/>{boards}
    <body name="trunk" pos="0 0 {_f(STANDING_HEIGHT)}">
      <freejoint name="trunk"/>
      <geom name="trunk" type="box" size="{_f(lx)} {_f(ly)} {_f(lz)}" contype="1" mass="{_f(TRUNK_MASS)}" rgba="0.15 0.15 0.6 1"/>
      <site name="imu" pos="0 0 0"/>{markers}{legs}
    </body>
  </worldbody>
  <actuator>{motors}
  </actuator>
  <sensor>
    <gyro name="imu_gyro" site="imu"/>
    <accelerometer name="imu_acc" site="imu"/>{forces}
  </sensor>
</mujoco>
"""


@functools.lru_cache(maxsize=8)
def _compiled(armature: float, damping: float, friction: float, timestep: float, motor: DCMotor | None,
              terrain: Terrain | None):
    import mujoco
    return mujoco.MjModel.from_xml_string(littledog_mjcf(armature=armature, damping=damping, friction=friction,
                                                         timestep=timestep, motor=motor, terrain=terrain))


def littledog_model(*, armature: float = 0.0, damping: float = 0.0, friction: float = 1.0,
                    timestep: float = TIMESTEP, motor: DCMotor | None = None, terrain: Terrain | None = None):
    """The compiled MuJoCo model of :func:`littledog_mjcf` (compiled once per set of arguments).

    Parameters
    ----------
    armature, damping, friction, timestep : float
        As in :func:`littledog_mjcf`.
    motor : DCMotor, optional
        As in :func:`littledog_mjcf`: voltage-driven joints.
    terrain : Terrain, optional
        As in :func:`littledog_mjcf`: boards on the floor (a terrain is hashable, so each compiles once).

    Returns
    -------
    mujoco.MjModel
        A fresh copy: change it freely (``mujoco.MjModel`` is mutable).

    Examples
    --------
    >>> model = littledog_model()
    >>> model.opt.timestep, model.nsensordata      # gyro 3 + accelerometer 3 + 4 forces x 3
    (0.001, 18)
    """
    import copy
    args = [as_finite_scalar(v, n) for v, n in ((armature, "armature"), (damping, "damping"),
                                                   (friction, "friction"), (timestep, "timestep"))]
    littledog_mjcf(armature=args[0], damping=args[1], friction=args[2], timestep=args[3], motor=motor,
                   terrain=terrain)  # validates
    return copy.deepcopy(_compiled(*args, motor, terrain))
