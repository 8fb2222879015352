"""Exercises of assignment 04 (the LittleDog quadruped as a system, from the LittleDog User Guide).

Inputs come from the model of :mod:`robokit.legged.littledog` (hips, legs, markers, the servo's
gains and period, the battery) with random joint angles, poses and loads; the touchdown loop
exercise's cases are the lesson's crawl simulated in MuJoCo
(:func:`robocourse.lessons.littledog.data.crawl_touchdowns`): the lower legs' forces and the plan's
stance go to the student, MuJoCo's true touchdowns are the case's expected answer.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Secs. 1-3).
.. [2] K. S. Arun, T. S. Huang and S. D. Blostein, "Least-squares fitting of two 3-D point sets",
   IEEE Trans. Pattern Analysis and Machine Intelligence 9(5), 698-700, 1987.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from robokit.controllers.joint_servo import pd_servo_step
from robokit.geometry import se3_from_rt, so3_exp, transform_points
from robokit.legged.touchdown import contact_events, detect_contacts, gate_touchdowns, match_events, score_leg_events
from robocourse.lessons.littledog.data import crawl_touchdowns, model_facts
from robokit.legged.leg_kinematics import KNEE_BRANCH, foot_position, leg_ik
from robokit.legged.littledog import HIP_POSITIONS, JOINT_LIMITS, LEGS, MARKERS, STANCE_FEET, STANDING_HEIGHT
from robokit.legged.mocap import fit_marker_pose
from robokit.legged.power import battery_energy, endurance
from robokit.legged.support import stability_margin
from robokit.validation import as_array, as_positive
from robocourse.exercises.compare import close
from robocourse.exercises.plain import summarize
from robocourse.exercises.spec import Case, Exercise

ASSIGNMENT = "04_littledog"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"04.architecture": 2, "04.touchdown_tradeoff": 2, "04.marker_geometry": 2, "04.system": 3}


def data() -> dict:
    """What the notebook's exercises work on: the model's constants (:func:`~.data.model_facts`).

    Examples
    --------
    >>> data()["model_facts"]["UPPER_LEG"]
    0.0751
    """
    return {"model_facts": model_facts()}
#: A detected touchdown counts for a true one within this many samples (50 ms at the host's 100 Hz).
TOUCHDOWN_TOLERANCE = 5
#: Precision and recall a touchdown detector must both reach on a crawl, counted over the four legs.
TOUCHDOWN_SCORE = 0.9
#: The touchdown cases' links: the range (s) of the delay every set-point has, and what the case tests.
#: A foot lands from about 0.02 s before to 0.16 s after its planned touchdown; the quick and the
#: slow link are far enough apart that no one shift of the plan's touchdowns passes both.
TOUCHDOWN_LINKS = ((0.0, 0.01, "a quick link"), (0.04, 0.06, "a lagging link"), (0.12, 0.14, "a slow link"))
#: Where :func:`detect_touchdowns` looks for each planned touchdown: from this long before it to
#: this long after (s).
TOUCHDOWN_GATE = (0.04, 0.18)
#: How far (m) a fitted pose may move any point within 0.2 m of the body's origin (per axis) from
#: where the least-squares optimum puts it: far below the markers' noise (1-2 mm), far above the
#: error of a converged iterative solver (about 3e-6 m with scipy's default tolerances).
FIT_TOLERANCE = 5e-5
_CUBE = np.array([[x, y, z, 1.0] for x in (-0.2, 0.2) for y in (-0.2, 0.2) for z in (-0.2, 0.2)])

SERVO = {"kp": 96.12, "kd": 0.4222, "dt": 0.002, "voltage_max": 14.8}
"""Example servo settings for the cases: gains (V/rad, V s/rad) of the order of the lesson's (a 15 Hz
design on a lighter joint), 500 Hz, the battery's 14.8 V."""


def battery_endurance(capacity_ah: float, voltage: float, mean_power_w: float) -> float:
    """Minutes a battery lasts at a mean electrical power: ``capacity x 3600 x voltage / power / 60``.

    Examples
    --------
    >>> round(battery_endurance(2.1, 14.8, 62.0), 2)      # LittleDog's pack: the guide's "about 30 minutes"
    30.08
    """
    return endurance(battery_energy(capacity_ah, voltage), mean_power_w) / 60.0


def detect_touchdowns(force: Any, planned_stance: Any, dt: float) -> list:
    """The touchdowns of a crawl's four feet, from their force sensors and the plan (the loop exercise's reference).

    Each foot's touchdowns are the rising edges of a hysteresis on its force (contact above 3 N,
    none below 1 N: :func:`~robokit.legged.touchdown.detect_contacts`), gated by the plan
    (:func:`~robokit.legged.touchdown.gate_touchdowns`): for each planned touchdown, the first one
    from 0.04 s before it to 0.18 s after (:data:`TOUCHDOWN_GATE`: the set-points may reach the robot
    up to 0.14 s late). The lesson's Sec. 9 method with a wider gate.

    Parameters
    ----------
    force : array_like, shape (N, 4)
        Lower-leg axial forces (N), legs ``FL, FR, HL, HR``, one row per host cycle.
    planned_stance : array_like of bool, shape (N, 4)
        The plan's feet on the ground at the same samples.
    dt : float
        Sample period (s, > 0).

    Returns
    -------
    list of 4 lists of int
        Each leg's touchdowns (sample indices, increasing).

    Raises
    ------
    ValueError
        For a force that is not (N, 4) or holds NaN or inf, a ``planned_stance`` of another shape,
        or a non-positive ``dt``.
    TypeError
        For a ``planned_stance`` that is not booleans (or 0/1).

    Examples
    --------
    One foot lands 3 samples after its planned touchdown (sample 4) and reads nothing for a sample
    mid-stance; the other three stand:

    >>> f = np.full((14, 4), 9.0)
    >>> f[:, 0] = [9, 9, 0, 0, 0, 0, 0, 9, 9, 0.5, 9, 9, 9, 9]
    >>> plan = np.ones((14, 4), bool)
    >>> plan[2:4, 0] = False
    >>> detect_touchdowns(f, plan, 0.01)
    [[7], [], [], []]
    """
    f = as_array(force, "force", shape=(None, 4))
    stance = as_array(planned_stance, "planned_stance", dtype=bool)
    if stance.shape != f.shape:
        raise ValueError(f"planned_stance: expected shape {f.shape} (that of force), got shape {stance.shape}")
    period = as_positive(dt, "dt")
    early, late = (round(s / period) for s in TOUCHDOWN_GATE)
    found = contact_events(detect_contacts(f, 3.0, 1.0))
    return [gate_touchdowns(d, p + (late - early) // 2, (late + early + 1) // 2).tolist()
            for d, p in zip(found, contact_events(stance))]


def _leg_indices(got: Any) -> list | str:
    """A student's touchdowns as 4 lists of sample indices, or what is wrong with them."""
    values = got.tolist() if isinstance(got, np.ndarray) else got
    if not isinstance(values, (list, tuple)) or len(values) != 4:
        return f"expected 4 lists of sample indices (legs FL, FR, HL, HR), got {summarize(got)}"
    legs = [v.tolist() if isinstance(v, np.ndarray) else v for v in values]
    if not all(isinstance(v, (list, tuple)) and all(type(k) in (int, float) for k in v) for v in legs):
        return f"expected 4 lists of sample indices (legs FL, FR, HL, HR), got {summarize(got)}"
    return [list(v) for v in legs]


def _first_misses(expected: list, legs: list) -> str:
    """Where the first true touchdown without a detection and the first detection without a true
    touchdown are (legs and samples), for the feedback."""
    notes = []
    for what, pick in (("the first touchdown you missed", 1), ("the first false one", 0)):
        firsts = []
        for leg, truth, found in zip(LEGS, expected, legs):
            pairs = match_events(found, truth, TOUCHDOWN_TOLERANCE)
            own = np.asarray(truth if pick else found, dtype=np.int64)
            left = np.setdiff1d(own, pairs[:, pick]) if len(own) else own
            if len(left):
                firsts.append((int(left.min()), leg))
        if firsts:
            k, leg = min(firsts)
            notes.append(f"{what}: {leg} at sample {k}")
    return "; ".join(notes)


def _touchdowns_found(expected: Any, got: Any) -> str | None:
    """Accept each leg's sample indices when precision and recall against the true touchdowns,
    counted over the four legs, both reach 0.9."""
    legs = _leg_indices(got)
    if isinstance(legs, str):
        return legs
    try:
        score = score_leg_events(legs, expected, TOUCHDOWN_TOLERANCE)
    except (TypeError, ValueError) as exc:
        return f"expected whole sample indices >= 0 ({exc})"
    if score.precision >= TOUCHDOWN_SCORE and score.recall >= TOUCHDOWN_SCORE:
        return None
    found, true = sum(len(v) for v in legs), sum(len(v) for v in expected)
    right = round(score.recall * true)
    return (f"precision {score.precision:.2f}, recall {score.recall:.2f}: both must reach {TOUCHDOWN_SCORE} "
            f"({found} touchdowns found, {true} true ones; {right} right, {found - right} false, "
            f"{true - right} missed; a detection counts within {TOUCHDOWN_TOLERANCE} samples of a true "
            f"touchdown of its leg; {_first_misses(expected, legs)})")


def _same_rigid_fit(expected: Any, got: Any) -> str | None:
    """Accept a proper rigid transform that is the least-squares optimum (the answer's) within
    ``FIT_TOLERANCE`` on every point within 0.2 m of the body's origin."""
    try:
        G = np.array(got, dtype=float)
    except (TypeError, ValueError):
        return f"expected a 4x4 matrix of numbers, got {summarize(got)}"
    if G.shape != (4, 4) or not np.all(np.isfinite(G)):
        return f"expected a finite 4x4 matrix, got {summarize(got)}"
    if np.abs(G[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-9:
        return f"expected the last row [0, 0, 0, 1], got {G[3].tolist()}"
    R = G[:3, :3]
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-6 or abs(np.linalg.det(R) - 1.0) > 1e-6:
        return (f"expected a rotation block with R^T R = I and det R = +1, got det {np.linalg.det(R):.6g} "
                "(a det of -1 is a reflection)")
    moved = np.abs((G - np.asarray(expected, dtype=float)) @ _CUBE.T).max()
    if moved > FIT_TOLERANCE:
        return (f"not the least-squares fit: your pose puts points 0.2 m from the body's origin up to "
                f"{moved * 1e3:.3g} mm away from where the optimum puts them (tolerance {FIT_TOLERANCE * 1e3:g} mm)")
    return None


# --- cases ------------------------------------------------------------------------------------

def _random_q(rng: np.random.Generator, leg: int) -> np.ndarray:
    lim = JOINT_LIMITS[3 * leg:3 * leg + 3]
    return rng.uniform(lim[:, 0], lim[:, 1]).round(4)


def _fk_cases(rng: np.random.Generator) -> list[Case]:
    return [
        Case(([0.0, 0.0, 0.0], "FL"), label="all joints at zero: the leg hangs straight down"),
        *[Case((_random_q(rng, i).tolist(), leg), label=f"random angles, leg {leg}") for i, leg in enumerate(LEGS)],
        Case(([0.3, 0.0, 0.0], "HR"), label="hip roll alone swings the foot sideways"),
        Case(([0.1, 0.2], "FL"), raises="ValueError", label="two angles instead of three"),
        Case(([0.0, 0.1, 0.2], "XX"), raises="ValueError", label="an unknown leg"),
    ]


def _ik_cases(rng: np.random.Generator) -> list[Case]:
    cases = []
    for i, leg in enumerate(LEGS):
        branch = KNEE_BRANCH[i]
        q = [rng.uniform(-0.4, 0.4), rng.uniform(-0.8, 0.8), branch * rng.uniform(0.5, 2.0)]
        cases.append(Case((foot_position(q, leg).round(6).tolist(), leg, branch),
                          label=f"a reachable foot, leg {leg}, its own knee branch"))
    q = [rng.uniform(-0.3, 0.3), rng.uniform(-0.5, 0.5), rng.uniform(0.6, 1.6)]
    cases += [
        Case((foot_position(q, "FL").round(6).tolist(), "FL", +1), label="a front leg with the knee bent forwards"),
        Case((STANCE_FEET[3].tolist(), "HR", -1), label="the nominal stance foot, knee backwards"),
        Case(((HIP_POSITIONS[0] + [0.0, 0.0, -0.3]).tolist(), "FL", -1), raises="ValueError",
             label="0.3 m below the hip: out of reach"),
        Case(((HIP_POSITIONS[2] + [0.05, 0.01, 0.0]).tolist(), "HL", +1), raises="ValueError",
             label="closer to the roll axis than the hip offset"),
        Case((STANCE_FEET[0].tolist(), "FL", 0), raises="ValueError", label="a branch that is not -1 or +1"),
    ]
    return cases


def _margin_cases(rng: np.random.Generator) -> list[Case]:
    feet = STANCE_FEET[:, :2]
    shift = rng.uniform(-0.03, 0.03, 2).round(4)
    five = np.vstack([feet, rng.uniform(-0.1, 0.1, (1, 2))])[rng.permutation(5)]
    return [
        Case((feet.tolist(), [0.0, 0.0]), label="standing on four feet, centre of mass in the middle"),
        Case((feet[1:].tolist(), shift.tolist()), label="a crawl: FL lifted, three feet"),
        Case((feet[[0, 3, 1]].tolist(), [0.05, 0.02]), label="a triangle, feet in any order"),
        Case((feet.tolist(), [0.3, 0.02]), label="centre of mass ahead of the feet: negative"),
        Case((feet.tolist(), [0.16, 0.01]), label="centre of mass on the front edge: zero"),
        Case((five.round(4).tolist(), shift.tolist()), label="a foot inside the hull of the others"),
        Case((feet[:2].tolist(), [0.0, 0.0]), raises="ValueError", label="two feet: no support polygon"),
    ]


def _servo_cases(rng: np.random.Generator) -> list[Case]:
    gains = [SERVO["kp"], SERVO["kd"], SERVO["dt"], SERVO["voltage_max"]]
    q = rng.uniform(-1.0, 1.0, 12)
    q_prev = q - rng.normal(0, 0.002, 12)
    small = q + rng.normal(0, 0.02, 12)
    kp = rng.uniform(50.0, 150.0, 12).round(3)
    nan_ref = small.copy()
    nan_ref[4] = np.nan
    return [
        Case(([0.1], [0.0], [0.0], *gains), label="one joint, at rest: kp times the error"),
        Case((small.round(5).tolist(), q.round(5).tolist(), q_prev.round(5).tolist(), *gains),
             label="twelve joints, small errors: no saturation"),
        Case(((q + 0.5).round(5).tolist(), q.round(5).tolist(), q_prev.round(5).tolist(), *gains),
             label="large errors: saturated at +-voltage_max"),
        Case((small.round(5).tolist(), q.round(5).tolist(), q_prev.round(5).tolist(), kp.tolist(), 0.3,
              SERVO["dt"], SERVO["voltage_max"]), label="a gain per joint"),
        Case(([0.2, 0.2], [0.0, 0.1], [-0.01, 0.1], *gains), label="the rate term acts on the measurement"),
        Case((nan_ref.round(5).tolist(), q.round(5).tolist(), q_prev.round(5).tolist(), *gains),
             raises="ValueError", label="a NaN set-point: a corrupted packet"),
    ]


def _T_world_body(rng: np.random.Generator, big: bool = False) -> np.ndarray:
    rotvec = rng.normal(0, 1.5 if big else 0.1, 3) + [0.0, 0.0, rng.uniform(-np.pi, np.pi)]
    return se3_from_rt(so3_exp(rotvec), [*rng.uniform(-1.0, 1.0, 2), STANDING_HEIGHT])


def _seen(rng, T, markers, noise, visible):
    obs = transform_points(T, markers) + rng.normal(0, noise, (len(markers), 3))
    obs[~np.asarray(visible)] = 0.0
    return obs.round(7).tolist()


def _fit_cases(rng: np.random.Generator) -> list[Case]:
    m = MARKERS
    rig = rng.uniform(-0.15, 0.15, (6, 3))
    all4, no_post, no_fl = [True] * 4, [True, True, True, False], [False, True, True, True]
    T = [_T_world_body(rng) for _ in range(4)] + [_T_world_body(rng, big=True) for _ in range(2)]
    return [
        Case((m.tolist(), _seen(rng, T[0], m, 0.0, all4), all4), label="four markers, no noise: exact"),
        Case((m.tolist(), _seen(rng, T[1], m, 0.001, all4), all4), label="four markers, 1 mm noise"),
        Case((m.tolist(), _seen(rng, T[2], m, 0.002, no_post), no_post), label="the post's marker hidden"),
        Case((m.tolist(), _seen(rng, T[3], m, 0.001, no_fl), no_fl), label="the front-left marker hidden"),
        Case((rig.round(4).tolist(), _seen(rng, T[4], rig.round(4), 0.001, [True] * 5 + [False]),
              [True] * 5 + [False]), label="another rig: six markers, one hidden, a large rotation"),
        Case((m.tolist(), _seen(rng, T[5], m, 0.001, all4), all4), label="upside down or tilted far"),
        Case((m.tolist(), _seen(rng, T[1], m, 0.001, [True, False, False, True]), [True, False, False, True]),
             raises="ValueError", label="two visible markers: no pose"),
    ]


#: The crawls of the touchdown cases: ranges of :func:`~robokit.legged.crawl_gait`'s parameters. Around
#: the lesson's crawl (2 s cycle, 8 cm steps, 4 cm lift, duty factor 0.9), a little slower and with a
#: higher lift: at the lesson's own, an unloaded hind foot sometimes leaves the ground for a few
#: samples just before its lift-off, and MuJoCo's truth then counts a touchdown no plan foresees.
TOUCHDOWN_CRAWLS = {"period": (2.2, 2.6), "step_length": (0.06, 0.08), "step_height": (0.045, 0.05),
                    "duty_factor": (0.9, 0.94)}


def _crawl_case(rng: np.random.Generator, link: tuple) -> Case:
    low, high, label = link
    gait = {key: round(float(rng.uniform(*span)), 3) for key, span in TOUCHDOWN_CRAWLS.items()}
    latency = round(float(rng.uniform(low, high)), 3)
    run = crawl_touchdowns(gait, distance=round(float(rng.uniform(0.2, 0.3)), 2), latency=latency,
                           force_noise=round(float(rng.uniform(0.05, 0.3)), 2), seed=int(rng.integers(2 ** 31)))
    return Case((np.round(run["force"], 4).tolist(), run["planned_stance"], run["dt"]), expected=run["touchdowns"],
                label=f"a crawl ({gait['period']:.2f} s cycle, {gait['step_length'] * 100:.1f} cm steps) over {label}: "
                      f"set-points {latency * 1000:.0f} ms late")


def _touchdown_cases(rng: np.random.Generator) -> list[Case]:
    cases = [_crawl_case(rng, link) for link in TOUCHDOWN_LINKS]
    force, stance, dt = cases[0].args
    nan = [row[:] for row in force]
    nan[50][2] = float("nan")
    return cases + [
        Case((nan, stance, dt), raises="ValueError", label="a NaN sample"),
        Case((force, stance[:-1], dt), raises="ValueError", label="a plan one sample shorter than the forces"),
        Case((force, stance, 0.0), raises="ValueError", label="a sample period of zero"),
        Case(([row[0] for row in force], [row[0] for row in stance], dt), raises="ValueError",
             label="one foot's trace instead of four"),
    ]


def _plan_late(samples: int):
    """The shortcut that ignores the force: the plan's touchdowns, ``samples`` late."""
    def shortcut(force, planned_stance, dt):
        return [(e + samples).tolist() for e in contact_events(np.asarray(planned_stance, bool))]
    return shortcut


#: Ways to pass a touchdown case without the force sensors: the plan's touchdowns shifted by a
#: fixed delay (no one shift passes a quick and a slow link).
TOUCHDOWN_SHORTCUTS = {"the plan's touchdowns" + (f", {abs(k)} samples {'late' if k > 0 else 'early'}" if k else ""):
                       _plan_late(k) for k in range(-4, 19)}


def _endurance_cases(rng: np.random.Generator) -> list[Case]:
    return [
        Case((2.1, 14.8, 62.0), label="LittleDog's pack at 62 W: the guide's 30 minutes"),
        Case((2.1, 14.8, round(float(rng.uniform(20.0, 120.0)), 2)), label="LittleDog's pack, another gait"),
        Case((round(float(rng.uniform(1.0, 5.0)), 2), round(float(rng.uniform(7.4, 22.2)), 1),
              round(float(rng.uniform(10.0, 200.0)), 1)), label="another battery"),
        Case((-2.1, 14.8, 62.0), raises="ValueError", label="a negative capacity"),
        Case((2.1, 14.8, 0.0), raises="ValueError", label="no power drawn: no finite answer"),
    ]


EXERCISES = [
    Exercise(
        id="04.leg_fk", function="leg_fk", signature="leg_fk(q_leg: [q1, q2, q3], leg: 'FL'|'FR'|'HL'|'HR') -> [x, y, z]",
        points=1, cases=_fk_cases, answer=foot_position, compare=close(rtol=0, atol=1e-9),
        kind="warm-up",
        description="The foot centre in the body frame from the leg's hip roll, hip pitch and knee (m); "
                    "ValueError for a wrong number of angles or an unknown leg."),
    Exercise(
        id="04.leg_ik", function="leg_ik",
        signature="leg_ik(p_foot: [x, y, z], leg: str, branch: -1|+1) -> [q1, q2, q3]",
        points=2, cases=_ik_cases, answer=leg_ik, compare=close(rtol=0, atol=1e-7),
        kind="derivation",
        description="Closed-form IK: the roll root with the foot below the hip, the knee on the given branch, "
                    "angles in (-pi, pi]; ValueError for an unreachable target or a bad branch."),
    Exercise(
        id="04.stability_margin", function="stability_margin",
        signature="stability_margin(feet_xy: (k, 2), com_xy: (2,)) -> float",
        points=1, cases=_margin_cases, answer=stability_margin, compare=close(rtol=1e-9, atol=1e-12),
        kind="derivation",
        description="McGhee & Frank's margin, signed: distance to the support polygon's boundary, negative "
                    "outside; ValueError for fewer than three feet."),
    Exercise(
        id="04.pd_servo_step", function="pd_servo_step",
        signature="pd_servo_step(q_ref, q, q_prev, kp, kd, dt, voltage_max) -> list of voltages",
        points=1, cases=_servo_cases, answer=pd_servo_step, compare=close(rtol=1e-9, atol=1e-9),
        kind="warm-up",
        description="One 500 Hz servo tick, V = kp (q_ref - q) - kd (q - q_prev) / dt clipped at +-voltage_max; "
                    "ValueError for a NaN set-point."),
    Exercise(
        id="04.marker_fit", function="marker_fit",
        signature="marker_fit(markers_body: (M, 3), observed: (M, 3), visible: (M,) bool) -> 4x4 list",
        points=2, cases=_fit_cases, answer=fit_marker_pose, compare=_same_rigid_fit,
        kind="open",
        description="Open: T_world_body minimising the squared distances of the visible markers, by any method "
                    "(SVD, quaternions, least squares); ValueError for fewer than three visible markers."),
    Exercise(
        id="04.detect_touchdowns", function="detect_touchdowns",
        signature="detect_touchdowns(force: (N, 4) newtons, planned_stance: (N, 4) bool, dt: float) "
                  "-> 4 lists of sample indices",
        points=2, cases=_touchdown_cases, answer=detect_touchdowns, compare=_touchdowns_found,
        shortcuts=TOUCHDOWN_SHORTCUTS,
        kind="loop",
        description="Loop: the four feet's touchdowns in a simulated crawl from the lower-leg forces and the plan's "
                    "stance, graded against MuJoCo's true contacts; precision and recall within 5 samples over "
                    "the legs must both reach 0.9; ValueError for NaN, shapes that differ or are not (N, 4), "
                    "or dt <= 0."),
    Exercise(
        id="04.battery_endurance", function="battery_endurance",
        signature="battery_endurance(capacity_ah, voltage, mean_power_w) -> minutes",
        points=1, cases=_endurance_cases, answer=battery_endurance, compare=close(rtol=1e-9, atol=1e-12),
        kind="warm-up",
        description="Minutes of running: capacity x 3600 x voltage / power / 60; ValueError for non-positive "
                    "inputs."),
]
