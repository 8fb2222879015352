"""A valid call of every fuzzed public function, with the kind of each argument (tests/fuzz_kinds.py).

The fuzz replaces one argument of the valid call at a time by an invalid value of its kind. Every
parameter of a fuzzed function appears here (the test checks it), so a new parameter needs a kind.
"""
from __future__ import annotations

import datetime as dt
import functools
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from tests.fuzz_kinds import (Array, Choice, File, Flag, Func, Given, Int, Kind, Mapping, Obj, Options, Real, Rng, Text,
                              fuzz_folder, npz_extras)


@dataclass
class Call:
    """How to call one function: the kind of each parameter (by name)."""

    kinds: dict[str, Kind]
    #: ``*args`` parameter fuzzed as one more positional kind list (e.g. se3_compose's transforms)
    star: str | None = None
    #: other names an error may use for a parameter (``{"transforms": "transforms[0]"}``)
    aliases: dict[str, str] = field(default_factory=dict)
    #: a valid call is fast: huge values may be tried (they run the function to the end)
    cheap: bool = True


# --- shared valid values (built once) ---------------------------------------------------------

def littledog_motor():
    from robokit.controllers.dc_motor import LITTLEDOG_MOTOR
    return LITTLEDOG_MOTOR


@functools.cache
def iiwa():
    from robokit.arm import iiwa14
    return iiwa14()


@functools.cache
def mcl_run():
    from robocourse.lessons.corridor_localization.mcl_runs import simulate_run
    return simulate_run(np.random.default_rng(0))[0]


@functools.cache
def odometry_run():
    from robocourse.lessons.visual_slam.odometry import odometry_run as run
    return run(0, frames=3)


@functools.cache
def truck_course():
    from robocourse.lessons.gps_sonar_truck.loop import course_case
    return course_case(0).args[0]


@functools.cache
def panda_arm():
    from robokit.arm import panda
    return panda()


@functools.cache
def lab():
    from robokit.sim import lab_room
    return lab_room()


@functools.cache
def camera():
    from robokit.sim import PinholeCamera
    return PinholeCamera.from_fov(np.deg2rad(65), 160, 120)


@functools.cache
def stereo_rig():
    from robokit.sim import StereoRig
    return StereoRig(camera(), baseline=0.12)


@functools.cache
def calibration():
    from robocourse.lessons.visual_slam.experiment import calibrated_rig
    return calibrated_rig(stereo_rig())


@functools.cache
def image():
    from robokit.sim import photo
    return photo("grace_hopper")[200:320, 180:340].copy()


def image_mask():
    return np.ones(image().shape[:2], bool)


@functools.cache
def office_experiment():   # lesson 02's fast office setup (cached on disk after the first build)
    from robocourse.lessons.omni_localization.experiment import office_setup
    return office_setup(fast=True)


def draw_figure(value):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(2, 1))
    ax.plot([0, 1], [0, float(value)])
    return fig


def rec_nodes():
    rng = np.random.default_rng(0)
    return [rng.normal(size=(12, 8)) for _ in range(3)]


@functools.cache
def small_omni():
    from robokit.sim import OmniCamera
    return OmniCamera(width=160, height=120, face_size=60)


@functools.cache
def office():
    from robokit.sim import office_floor
    return office_floor()


@functools.cache
def office_views():      # three small omni images of office_floor() 0.3 m apart (lesson 02's map tests)
    poses = np.array([[12.0, 3.5, 0.0], [12.3, 3.5, 0.2], [12.6, 3.5, 0.0]])
    return np.stack([small_omni().observe(office(), p).image for p in poses]), poses


@functools.cache
def office_map():
    from robokit.mapping import build_topological_map
    images, poses = office_views()
    return build_topological_map(images, poses, small_omni(), similarity=0.001, min_matches=10 ** 6,
                                 occlusion_frames=1, n_features=100, loop_closure=False)


@functools.cache
def omni_views():
    from robokit.mapping import omni_view
    images, _ = office_views()
    return [omni_view(im, small_omni(), n_features=100) for im in images]


@functools.cache
def omni_matches():
    from robokit.vision import DescriptorIndex
    a, b = omni_views()[:2]
    return DescriptorIndex(a.features.descriptors).match(b.features.descriptors, ratio=0.8)


def bearings(n=12, seed=0):
    return points(n, seed) / np.linalg.norm(points(n, seed), axis=1, keepdims=True)


def moved_bearings(n=12, seed=0):
    moved = points(n, seed) + [0.3, 0.1, 0.0]
    return moved / np.linalg.norm(moved, axis=1, keepdims=True)


def essential():
    from robokit.vision.spherical import essential_from_bearings
    return essential_from_bearings(bearings(), moved_bearings())


@functools.cache
def features():
    from robokit.vision import detect_sift_features
    return detect_sift_features(image())


@functools.cache
def orb_features():
    from robokit.vision import detect_orb_features
    return detect_orb_features(image(), 200)


@functools.cache
def course():
    from robokit.outdoor import random_course
    return random_course(0, n_waypoints=2)


@functools.cache
def field_():
    from robokit.outdoor import Field
    return Field(circles=[[2.5, 0.0, 0.3], [1.2, 1.2, 0.3]])


@functools.cache
def plane():
    from robokit.outdoor import LocalTangentPlane
    return LocalTangentPlane(0.1127, 1.7514)


@functools.cache
def scene():
    from robokit.viz import Scene
    return Scene()


def framed_scene():
    from robokit.viz import Scene
    return Scene().add_box("robot/body", (0.5, 0.3, 0.2))


@functools.cache
def axes():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt.subplots()[1]


@functools.cache
def lap():
    from robokit.sim import lab_lap
    return lab_lap(lab())


@functools.cache
def landmark_map():      # map_consistency takes anything with positions, covariances, observations
    import types
    return types.SimpleNamespace(positions=np.array([[10.01, 0.2, 5.0], [0.0, 0.7, 5.0]]),
                                 covariances=np.stack([1e-4 * np.eye(3)] * 2), observations=np.array([3, 1]))


# lesson 02's path following, pose EKF and navigation
KEY_POSES = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 1.0, 0.0]])
EKF_X = np.array([0.0, 0.0, 0.3, 0.5, 0.2])


@functools.cache
def visual_path():
    from robokit.controllers import path_from_poses
    return path_from_poses(KEY_POSES)


def localizer():
    from robokit.navigation.visual_path import gaussian_localizer
    return gaussian_localizer()


@functools.cache
def run_results():
    from robokit.outdoor import simulate
    return [simulate(course(), seed=0, max_time=2.0)]


def target_T():
    return iiwa().fk(np.radians([35, 50, -40, -75, 60, 45, 20]))


def q7():
    return np.radians([0, 30, 0, -60, 0, 60, 0])


def points(n=20, seed=0):
    return np.random.default_rng(seed).uniform(-3, 3, (n, 3)) + [0, 0, 5]


def covs(n=20):
    return np.tile(np.eye(3) * 1e-3, (n, 1, 1))


def when():
    return dt.datetime(2012, 6, 4, 2, 30, 5)


UV = np.array([[80.0, 60.0], [90.0, 50.0]])
P_LEFT = np.hstack([np.array([[100.0, 0, 80], [0, 100, 60], [0, 0, 1]]), np.zeros((3, 1))])
P_RIGHT = P_LEFT - np.hstack([np.zeros((3, 3)), np.array([[12.0], [0], [0]])])
DH = np.array([[0.34, 0.0, -np.pi / 2], [0.0, 0.0, np.pi / 2], [0.4, 0.0, np.pi / 2]])
LAT, LON = np.radians(6.459), np.radians(100.35)


def T_(valid=target_T, **kw):      # one SE(3) transform
    return Array(valid, "4,4", **kw)


def Ts(valid=target_T, **kw):      # one or a stack
    return Array(valid, "4,4|N,4,4", **kw)


def _sensors():
    from robokit.sim import Lidar
    return {"laser": Lidar(beams=36)}


def _mounts():
    from robokit.outdoor.sonar import PAPER_LAYOUT
    return PAPER_LAYOUT


def _sonar():
    from robokit.outdoor import LVMaxSonarEZ
    return LVMaxSonarEZ()


def _truck():
    from robokit.outdoor import PAPER_TRUCK
    return PAPER_TRUCK


@functools.cache
def pose_graph():          # a small generated pose graph (30 poses, loop closures) for robokit.mapping
    from robokit.mapping import manhattan_world_graph
    return manhattan_world_graph(30, seed=1, closure_probability=1.0)[0]


@functools.cache
def intel_graph():         # lesson 02's real benchmark graph (943 poses), read once
    from robocourse.lessons.omni_localization.benchmark import benchmark_graph
    return benchmark_graph()


@functools.cache
def pose_graph_truth():    # the true poses of pose_graph()
    from robokit.mapping import manhattan_world_graph
    return manhattan_world_graph(30, seed=1, closure_probability=1.0)[1]


def pose_graph_loops():    # two of pose_graph()'s loop edges (rows of its edges)
    from robocourse.lessons.omni_localization.alignment import loop_rows
    return loop_rows(pose_graph())[:2]


# --- lesson 03's occupancy grid (robokit.mapping.occupancy_grid, grid_mapping, map_server) ---

def small_grid():
    from robokit.mapping import OccupancyGrid
    return OccupancyGrid.from_probability([[0.0, 1.0, 0.0], [0.5, 0.0, 1.0]], 0.5, origin=(-0.5, -0.5))


def grid_model_kinds() -> dict:
    return {"r_max": Real(2.0), "l_occ": Real(0.85), "l_free": Real(-0.4), "l0": Real(0.0), "thickness": Real(0.1),
            "beam_width": Real(1.6, optional=True)}


def grid_mapping_kinds() -> dict:
    beams = np.array([[1.0, np.inf, 0.8, 0.5], [1.2, 1.5, np.inf, 0.4]])
    return {"poses": Array(np.array([[0.0, 0.0, 0.0], [0.2, 0.1, 0.5]]), "N,3"),
            "scans": Array(beams, "N,4", inf_ok=True), "angles": Array(np.arange(4) * np.pi / 2, "N"),
            "bounds": Array(np.array([-1.0, -1.0, 1.0, 1.0]), "4"), "resolution": Real(0.1),
            "sensor_offset": Array(np.array([0.05, 0.0, 0.1]), "3"),
            "clamp": Array(np.array([-2.0, 3.5]), "2"), **grid_model_kinds()}


def map_folder():
    return fuzz_folder()


@functools.cache
def saved_map():
    from robokit.mapping import save_map
    return str(save_map(small_grid(), map_folder() / "saved")[1])


# --- lesson 03's Monte-Carlo localization (robokit.localization.particle_filter, beam_models, mcl) ---

def small_field():
    from robokit.mapping import likelihood_field
    return likelihood_field(small_grid())


def room_grid():       # a 2 m x 1.5 m box room at 0.1 m
    from robokit.mapping import OccupancyGrid
    P = np.ones((15, 20))
    P[1:-1, 1:-1] = 0.0
    return OccupancyGrid.from_probability(P, 0.1)


def beam_model_kinds() -> dict:
    return {"sensor_offset": Array(np.array([0.05, 0.0, 0.1]), "3"), "sigma_hit": Real(0.2), "z_hit": Real(0.95),
            "z_rand": Real(0.05), "r_max": Real(8.0), "max_beams": Int(30, optional=True), "combine": Choice("ros")}


SCAN = np.array([1.0, np.inf, 0.8, 0.5])
SCAN_ANGLES = np.arange(4) * np.pi / 2
@functools.cache
def corridor_world():
    from robokit.sim import long_corridor
    return long_corridor()


@functools.cache
def corridor_lidar():
    from robokit.sim import Lidar
    return Lidar(noise=0.01)


@functools.cache
def corridor_angles():
    return corridor_lidar().angles


@functools.cache
def corridor_ranges():   # lesson 03: a scan 0.3 m left of the middle line, turned 0.2 rad
    return corridor_lidar().scan(corridor_world(), [14.5, 0.3, 0.2], rng=0)
def orb_descriptors(n=40, seed=0):  # random 256-bit descriptors (robokit.vision lesson 03)
    return np.random.default_rng(seed).integers(0, 256, (n, 32), dtype=np.uint8)


@functools.cache
def bow_vocabulary():
    from robokit.vision import Vocabulary
    return Vocabulary.train([orb_descriptors(40, i) for i in range(4)], branching=3, levels=2, rng=0)


@functools.cache
def corridor_setup():   # lesson 03's fast corridor map (cached on disk after the first build)
    from robocourse.lessons.corridor_localization.experiment import corridor_map
    return corridor_map(fast=True)


@functools.cache
def willow_section():   # lesson 03's part of the Willow Garage map
    from robocourse.lessons.corridor_localization.real_map import willow_section as section
    return section()


@functools.cache
def willow_walls():
    from robokit.sim import Layout
    grid = willow_section()
    return Layout.from_cells(grid.occupied_mask(), grid.resolution, grid.origin)


@functools.cache
def willow_drives():    # one short drive (made when a test first asks, not at import)
    from robocourse.lessons.corridor_localization.real_map import building_routes
    from robokit.sim import waypoint_path
    return [waypoint_path(building_routes(willow_section(), 1, 1.0, rng=0)[0], 0.3).poses]


def willow_groups():    # two groups of global_localization_batch (its own checks of them: test_real_map)
    return [dict(grid=willow_section(), walls=willow_walls(), drives=willow_drives(), particles=200),
            dict(grid=willow_section(), walls=willow_walls(), drives=willow_drives(), particles=300, seed=1)]


@functools.cache
def corridor_calibration():
    from robocourse.lessons.corridor_localization.experiment import calibration_run
    return calibration_run(fast=True)


def snapshot_scene():
    from robokit.viz import Scene
    return Scene().add_box("a", size=(1, 1, 1)).add_box("b", size=(1, 1, 1)).add_box("robot", size=(1, 1, 1))


def distance_grid():   # lesson 03's exercise: distance to a wall at x = 1.55 m on a 20 x 20 grid of 0.1 m
    return np.abs(np.arange(20)[None, :] * 0.1 + 0.05 - 1.55) * np.ones((20, 1))


# --- lesson 04's sensing (robokit.legged.mocap, imu, state_estimation, touchdown) --------------

def sensing_T(n=5):         # a short walk of body poses
    from robokit.geometry import rot_z, se3_from_rt
    k = np.arange(n)
    return se3_from_rt(rot_z(0.05 * k), np.column_stack([0.01 * k, np.zeros(n), np.full(n, 0.13)]))


@functools.cache
def sensing_frames():
    from robokit.legged import MARKERS
    from robokit.legged.mocap import simulate_mocap
    return simulate_mocap(sensing_T(), MARKERS, 0.001, 0.0, 0)


def sensing_markers():
    from robokit.legged import MARKERS
    return MARKERS.copy()


def walk_contacts():
    return np.array([False, True, True, False, True, True, True, False, False, True, True, False])
def unit_square():
    return np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


@functools.cache
def gait(name):
    from robokit.legged import crawl_gait, trot_gait
    return {"crawl": crawl_gait, "trot": trot_gait}[name]()
# --- lesson 04's trial log and LittleDog scenes (robokit.legged.trial_log, viz.legged, viz.legged_plots) ---

@functools.cache
def trial_log():      # 10 rows of a synthetic crawl, self-consistent (tests/legged_logs.py)
    from tests.legged_logs import synthetic_log
    return synthetic_log(10)


def trial_streams():
    return {k: np.array(v) for k, v in trial_log().streams.items()}


def trial_meta_dict():
    return dict(trial_log().meta)


def trial_folder():
    return fuzz_folder()


@functools.cache
def saved_trial():
    from robokit.legged.trial_log import save_trial
    return str(save_trial(trial_folder() / "saved.npz", trial_log()))


def stance_q():
    from robokit.legged.leg_kinematics import body_ik
    from robokit.legged.littledog import STANCE_FEET
    return body_ik(STANCE_FEET).q[0]


@functools.cache
def tiny_walk_plan():   # 0.02 m of trot: a few dozen host cycles, ~0.1 s of MuJoCo per valid call
    from robokit.legged import trot_gait, walking_plan
    return walking_plan(trot_gait(), 0.02)


@functools.cache
def step_board():       # one 2 cm board across the lane ahead, with four markers on it
    from robokit.legged.terrain import Terrain
    return Terrain([[0.3, 0.5, -0.3, 0.3, 0.02]],
                   markers=[[0.3, -0.3, 0.02], [0.3, 0.3, 0.02], [0.5, -0.3, 0.02], [0.5, 0.3, 0.02]])


def board_markers_seen():
    from robokit.geometry import se2_to_se3, transform_points
    return transform_points(se2_to_se3([0.02, -0.01, 0.05]), np.array(step_board().markers))


def loop_settings():
    from robokit.legged.simulation import LoopSettings
    return LoopSettings()


def posture_feedback():
    from robokit.legged.posture import PostureFeedback
    return PostureFeedback()


def sensor_settings():
    from robokit.legged.simulation import SensorSettings
    return SensorSettings()


def trial_outcomes():     # a TrialOutcome around the synthetic log: no MuJoCo needed
    from robokit.legged.simulation import TrialOutcome
    return {"trot": TrialOutcome(trial_log(), False, 0.03, 2.0, 0.01, {})}


def touchdown_detectors():
    from robocourse.lessons.littledog.experiment import TOUCHDOWN_DETECTORS
    return list(TOUCHDOWN_DETECTORS)


SPECS: dict[str, Call] = {
    # --- geometry --------------------------------------------------------------------------
    "robokit.geometry.planar.wrap_angle": Call({"angle": Array(np.array([0.5, 4.0]), "|N|N,N", min_rows=0),
                                                "validate": Flag(True)}),
    "robokit.geometry.planar.se2_compose": Call({"a": Array(np.array([1.0, 2.0, 0.5]), "3|N,3"),
                                                 "b": Array(np.array([0.5, -1.0, 3.0]), "3|N,3"), "validate": Flag(True)}),
    "robokit.geometry.paper_frames.paper_world_to_robokit": Call({
        "points": Array(lambda: points(5), "N,3", min_rows=0), "covariances": Array(lambda: covs(5), "N,3,3", optional=True),
        "camera_height": Real(0.8)}),
    "robokit.geometry.paper_frames.pqt_robot_to_world": Call({
        "points": Array(lambda: points(5), "3|N,3|N,N,3", min_rows=0), "pqt": Array(np.array([0.1, 0.2, 0.3]), "3|N,3"),
        "validate": Flag(True)}),
    "robokit.geometry.paper_frames.pqt_to_se2": Call({"pqt": Array(np.array([0.1, 0.2, 0.3]), "3|N,3")}),
    "robokit.geometry.paper_frames.pqt_to_se3": Call({"pqt": Array(np.array([0.1, 0.2, 0.3]), "3")}),
    "robokit.geometry.paper_frames.se2_to_pqt": Call({"pose": Array(np.array([0.1, 0.2, 0.3]), "3|N,3")}),
    "robokit.geometry.spatial.pose_error": Call({"T_target": Ts(), "T": Ts(lambda: iiwa().fk(q7())), "validate": Flag(True)}),
    "robokit.geometry.spatial.se2_to_se3": Call({"pose": Array(np.array([0.1, 0.2, 0.3]), "3|N,3"), "z": Real(0.0)}),
    "robokit.geometry.spatial.se3_compose": Call({"transforms": Ts()}, star="transforms",
                                                 aliases={"transforms": "transforms[0]"}),
    # --- arm -------------------------------------------------------------------------------
    "robokit.arm.ik_analytic.arm_angle": Call({"chain": Obj(iiwa), "q": Array(q7, "7|N,7")}),
    "robokit.arm.ik_analytic.ik_srs": Call({"chain": Obj(iiwa), "T": T_(), "q0": Array(q7, "7", optional=True),
                                            "tol": Real(1e-6), "n_psi": Int(32)}),
    "robokit.arm.ik_analytic.ik_srs_batch": Call({"chain": Obj(iiwa), "T": Ts(), "q0": Array(q7, "7|N,7", optional=True),
                                                  "tol": Real(1e-6), "n_psi": Int(32)}),
    "robokit.arm.arm_angle_intervals.feasible_arm_angles": Call({"chain": Obj(iiwa), "T": T_()}),
    "robokit.arm.arm_angle_intervals.split_points": Call({"chain": Obj(iiwa), "T": T_()}),
    "robokit.arm.arm_angle_intervals.ik_srs_readable": Call({"chain": Obj(iiwa), "T": T_(),
                                                              "q0": Array(q7, "7", optional=True), "n_psi": Int(32)},
                                                             cheap=False),
    "robokit.arm.position_posture.ik_position_posture": Call({"chain": Obj(iiwa), "T": T_(),
                                                              "q0": Array(q7, "7", optional=True), "tol": Real(1e-6),
                                                              "max_iter": Int(50), "method": Choice("newton")}),
    "robocourse.lessons.redundant_ik.exercises.solve_ik": Call({"T": T_(), "q_start": Array(q7, "7")}, cheap=False),
    "robokit.arm.ik_analytic.ik_srs_branches": Call({"chain": Obj(iiwa), "T": T_(), "psi": Real(0.3),
                                                     "within_limits": Flag(True)}),
    "robokit.arm.ik_numeric.ik_numeric": Call({"chain": Obj(panda_arm), "T": T_(lambda: panda_arm().fk(panda_arm().random_q(rng=3))),
                                               "q0": Array(lambda: panda_arm().random_q(rng=4), "7", optional=True),
                                               "options": Options({"rng": 1})}, cheap=False),
    "robokit.arm.ik_numeric.ik_numeric_batch": Call({
        "chain": Obj(panda_arm), "T": Ts(lambda: panda_arm().fk(panda_arm().random_q(2, rng=3))),
        "q0": Array(lambda: panda_arm().random_q(2, rng=4), "7|N,7", optional=True), "method": Choice("wln"),
        "tol": Real(1e-6), "max_iter": Int(20), "restarts": Int(1), "damping": Real(1e-3), "gain": Real(0.5),
        "clamp": Flag(True), "max_step": Real(0.5), "patience": Int(15), "parallel": Int(1), "rng": Rng(1),
        "history": Flag(False)}, cheap=False),
    "robokit.arm.jacobian.geometric_jacobian": Call({"chain": Obj(iiwa), "q": Array(q7, "7|N,7")}),
    "robokit.arm.jacobian.manipulability": Call({"J": Array(lambda: np.eye(6, 7) + 0.1, "6,7|N,6,7|6,N")}),
    "robokit.arm.robots.iiwa14": Call({}),
    "robokit.arm.robots.panda": Call({}),
    "robokit.arm.srs.elbow_angle": Call({"shoulder": Array(np.array([0.0, 0.0, 0.36]), "3"),
                                         "wrist": Array(np.array([0.3, 0.2, 0.7]), "3"), "d_se": Real(0.42), "d_ew": Real(0.40)}),
    "robokit.arm.srs.shoulder_angles": Call({"shoulder": Array(np.array([0.0, 0.0, 0.36]), "3"),
                                             "wrist": Array(np.array([0.3, 0.2, 0.7]), "3"), "q4": Real(1.2),
                                             "psi": Real(0.3), "d_se": Real(0.42), "d_ew": Real(0.40)}),
    "robokit.arm.srs.wrist_centre": Call({"T": T_(), "d_wf": Real(0.126)}),
    "robokit.arm.dh.dh_transform": Call({"theta": Array(np.array([0.1, 0.2]), "*"), "d": Array(np.array([0.3, 0.0]), "*"),
                                         "a": Array(np.array([0.0, 0.1]), "*"), "alpha": Array(np.array([0.5, -0.5]), "*")}),
    "robokit.arm.chain.dh_fk": Call({"dh": Array(DH, "N,3"), "q": Array(np.array([0.1, 0.2, 0.3]), "3|N,3"),
                                     "modified": Flag(False)}),
    "robokit.arm.jacobian.dh_jacobian": Call({"dh": Array(DH, "N,3"), "q": Array(np.array([0.1, 0.2, 0.3]), "3|N,3"),
                                              "modified": Flag(False)}),
    "robokit.arm.limits.limit_distance_gradient": Call({"chain": Obj(iiwa), "q": Array(q7, "7|N,7"), "validate": Flag(True)}),
    "robokit.arm.ik_steps.null_space_step": Call({"J": Array(lambda: np.eye(6, 7) + 0.1, "6,N|N,6,N"),
                                                  "e": Array(np.full(6, 0.01), "6"), "gradient": Array(np.full(7, 0.1), "7"),
                                                  "damping": Real(0.01), "gain": Real(1.0)}),
    "robocourse.lessons.redundant_ik.exercises.null_space_step_exact": Call({
        "J": Array(lambda: np.eye(6, 7) + 0.1, "6,N"), "e": Array(np.full(6, 0.01), "6"),
        "gradient": Array(np.full(7, 0.1), "7"), "damping": Real(0.01), "gain": Real(1.0)}),
    "robocourse.lessons.redundant_ik.tracking.track_path": Call({
        "dh": Array(lambda: np.stack([iiwa().d, iiwa().a, iiwa().alpha], 1), "7,3"),
        "qmin": Array(lambda: iiwa().qmin, "7"), "qmax": Array(lambda: iiwa().qmax, "7"),
        "q_start": Array(np.radians([10, 40, 0, -70, 0, 50, 0]), "7"),
        "targets": Array(lambda: iiwa().fk(np.radians([12, 42, 2, -68, 2, 52, 2]))[None], "N,4,4"),
        "settings": Mapping({"steps": 3, "tol": 1e-3, "max_step": 0.1, "damping": 0.02, "gain": 1.0})}),
    # --- controllers -----------------------------------------------------------------------
    "robokit.controllers.heading.design_heading_gains": Call({"tau": Real(0.3), "overshoot": Real(0.05),
                                                              "settling_time": Real(1.5), "gain": Real(1.0)}),
    "robokit.controllers.heading.heading_frequency_response": Call({
        "kp": Real(2.0), "kd": Real(0.1), "tau": Real(0.3), "omega": Array(np.array([0.1, 1.0, 10.0]), "N|"), "gain": Real(1.0)}),
    "robokit.controllers.heading.heading_step_response": Call({"kp": Real(2.0), "kd": Real(0.1), "tau": Real(0.3),
                                                               "gain": Real(1.0), "duration": Real(2.0), "n": Int(50)}),
    "robokit.controllers.servo_loop.loop_metrics": Call({"kp": Real(2.0), "kd": Real(0.1), "tau": Real(0.3),
                                                      "gain": Real(1.0), "delay": Real(0.0)}),
    # --- localization, mapping -------------------------------------------------------------
    "robokit.localization.egomotion.ransac_pose": Call({
        "robot_points": Array(lambda: points(20, 1), "N,3"), "world_points": Array(lambda: points(20, 1), "N,3"),
        "robot_covariances": Array(covs, "N,3,3", optional=True), "world_covariances": Array(covs, "N,3,3", optional=True),
        "threshold": Real(0.1), "confidence": Real(0.99), "min_matches": Int(5), "max_iterations": Int(100),
        "odometry": Array(np.zeros(3), "3", optional=True), "odometry_covariance": Array(np.eye(3) * 0.01, "3,3", optional=True),
        "rng": Rng(0)}),
    "robokit.localization.egomotion.pose_from_two": Call({"robot_points": Array(lambda: points(2, 2), "2,3"),
                                                          "world_points": Array(lambda: points(2, 3), "2,3")}),
    "robocourse.lessons.visual_slam.experiment.calibrated_rig": Call({"render_rig": Obj(stereo_rig)}),
    "robocourse.lessons.visual_slam.experiment.lab_experiment": Call({
        "method": Choice("sift"), "descriptor": Choice("sift128"), "rate": Real(1.0), "frames": Int(2, optional=True),
        "test_poses": Array(np.array([[1.0, 1.0, 0.0]]), "N,3", optional=True), "noise": Real(2.0), "seed": Int(0),
        "progress": Func(None, optional=True)}, cheap=False),
    "robocourse.lessons.visual_slam.experiment.map_consistency": Call({
        "landmark_map": Obj(landmark_map), "world": Obj(lab, optional=True), "camera_height": Real(0.8),
        "margin": Real(0.02)}),
    "robokit.mapping.landmarks.kalman_fuse": Call({"s": Array(np.array([1.0, 2.0, 3.0]), "3|N,3"),
                                                   "sigma": Array(np.eye(3) * 0.1, "3,3|N,3,3"),
                                                   "r_new": Array(np.array([1.1, 2.0, 2.9]), "3|N,3"),
                                                   "sigma_new": Array(np.eye(3) * 0.2, "3,3|N,3,3")}),
    # --- outdoor ---------------------------------------------------------------------------
    "robokit.outdoor.field.Field": Call({"size": Array(np.array([100.0, 60.0]), "2"),
                                         "circles": Array(np.array([[2.5, 0.0, 0.3]]), "N,3", optional=True, min_rows=0),
                                         "boxes": Array(np.array([[5.0, 5.0, 1.0, 0.5, 0.2]]), "N,5", optional=True, min_rows=0),
                                         "origin": Array(np.array([0.11, 1.75]), "2")}),
    "robokit.outdoor.field.random_course": Call({"seed": Int(0), "n_waypoints": Int(2), "n_obstacles": Int(4),
                                                 "on_path": Real(0.5), "size": Array(np.array([100.0, 60.0]), "2"),
                                                 "min_gap": Real(2.5)}),
    "robokit.outdoor.geodesy.LocalTangentPlane": Call({"lat0": Real(LAT), "lon0": Real(LON)}),
    "robokit.outdoor.geodesy.distance_bearing": Call({
        "lat1": Array(np.array([LAT, 0.2]), "*"), "lon1": Array(np.array([LON, 0.3]), "*"),
        "lat2": Array(np.array([LAT + 1e-4, 0.25]), "*"), "lon2": Array(np.array([LON, 0.2]), "*"), "model": Choice("sphere")}),
    "robokit.outdoor.geodesy.haversine_distance_bearing": Call({"lat1": Real(LAT), "lon1": Real(LON), "lat2": Real(LAT + 1e-4),
                                                                "lon2": Real(LON + 1e-4), "radius": Real(6371008.8)}),
    "robokit.outdoor.geodesy.vincenty_inverse": Call({
        "lat1": Array(np.array([LAT, 0.2]), "*"), "lon1": Array(np.array([LON, 0.3]), "*"),
        "lat2": Array(np.array([LAT + 1e-4, 0.25]), "*"), "lon2": Array(np.array([LON, 0.2]), "*"),
        "tol": Real(1e-12), "max_iter": Int(200)}),
    "robokit.outdoor.gps.compass_to_heading": Call({"psi_deg": Real(90.0)}),
    "robokit.outdoor.gps.Compass": Call({"noise": Real(0.01), "accuracy": Real(0.035), "resolution": Real(0.017),
                                         "variation": Real(-0.005), "rng": Rng(1)}),
    "robokit.outdoor.gps.GPSReceiver": Call({"plane": Obj(plane), "noise": Real(2.5), "tau": Real(60.0),
                                             "white_noise": Real(0.3), "period": Real(1.0), "rng": Rng(2)}),
    "robocourse.lessons.gps_sonar_truck.experiment.run_courses": Call({"seeds": Array(np.array([0]), "N"), "firing": Choice("chained"),
                                                 "course_options": Mapping({"n_waypoints": 1}, optional=True),
                                                 "progress": Func(None, optional=True), "cache": Flag(False),
                                                 "options": Options({"max_time": 2.0})}, cheap=False),
    "robokit.outdoor.mission.simulate": Call({
        "course": Obj(course), "seed": Int(0), "firing": Choice("chained"), "crosstalk": Flag(True),
        "truck": Obj(_truck, optional=True),
        "max_time": Real(2.0, optional=True), "dt": Real(0.049), "keep_nmea": Int(20), "gps_noise": Real(2.5),
        "compass_accuracy": Real(0.035), "navigator_options": Mapping(None, optional=True)}, cheap=False),
    "robokit.outdoor.mission.summarize_runs": Call({"results": Obj(run_results)}),
    "robokit.outdoor.navigator.Navigator": Call({
        "waypoints": Array(np.array([[LAT, LON]]), "N,2"), "truck": Obj(_truck), "cruise_speed": Real(0.7),
        "arrival_radius": Real(2.0), "gps_gain": Real(0.3), "front": Real(1.2), "side": Real(0.8),
        "bypass_distance": Real(1.5), "bypass_side": Real(0.35), "gains": Array(np.array([1.0, 0.5]), "2", optional=True),
        "guidance": Choice("estimate")}),
    "robokit.outdoor.navigator.avoidance_decision": Call({
        "ranges": Array(np.array([6.45, 0.5, 0.6, 6.45]), "4", inf_ok=True), "front": Real(1.2), "side": Real(0.8),
        "prefer": Choice("left"), "validate": Flag(True)}),
    "robokit.outdoor.nmea.NMEAReader": Call({"source": Obj(b"$GPGGA,1*00\r\n", accepts=("a string",)), "require_checksum": Flag(True),
                                             "on_error": Func(None, optional=True), "chunk_size": Int(64),
                                             "max_line": Int(4096)}),
    "robokit.outdoor.nmea.fix_position": Call({"sentence": Text(
        "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A")}),
    "robokit.outdoor.nmea.nmea_checksum": Call({"sentence": Text("GPGGA,123519")}),
    "robokit.outdoor.nmea.parse_sentence": Call({"sentence": Text(
        "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A"), "require_checksum": Flag(True)}),
    "robokit.outdoor.nmea_write.gga_sentence": Call({
        "when": Obj(lambda: when().time(), optional=True), "latitude": Real(6.45, optional=True), "longitude": Real(100.35, optional=True),
        "quality": Int(1), "satellites": Int(8), "hdop": Real(1.0), "altitude_m": Real(12.0, optional=True),
        "geoid_separation_m": Real(-3.0, optional=True), "talker": Text("GP")}),
    "robokit.outdoor.nmea_write.hdg_sentence": Call({"heading_deg": Real(36.8), "deviation_deg": Real(0.0, optional=True),
                                                     "variation_deg": Real(-0.3, optional=True), "talker": Text("HC")}),
    "robokit.outdoor.nmea_write.random_sentences": Call({"count": Int(3), "rng": Rng(5), "empty_fraction": Real(0.1)}),
    "robokit.outdoor.nmea_write.rmb_sentence": Call({
        "destination_latitude": Real(6.4594, optional=True), "destination_longitude": Real(100.3509, optional=True), "range_m": Real(65.0),
        "bearing_deg": Real(44.0), "cross_track_m": Real(0.0), "origin_id": Text("000"), "destination_id": Text("002"),
        "closing_velocity_mps": Real(0.5), "arrived": Flag(False), "talker": Text("GP")}),
    "robokit.outdoor.nmea_write.rmc_sentence": Call({
        "when": Obj(when), "latitude": Real(6.45, optional=True), "longitude": Real(100.35, optional=True),
        "speed_mps": Real(0.7, optional=True), "course_deg": Real(37.5, optional=True), "valid": Flag(True),
        "magnetic_variation_deg": Real(-0.3, optional=True), "talker": Text("GP")}),
    "robokit.outdoor.sonar.LVMaxSonarEZ": Call({"min_range": Real(0.1524), "max_range": Real(6.4516), "cycle": Real(0.049),
                                                "half_angle": Real(0.35), "resolution": Real(0.0254)}),
    "robokit.outdoor.sonar.firing_schedule": Call({"n_sensors": Int(4), "duration": Real(0.4), "mode": Choice("chained"),
                                                   "cycle": Real(0.049), "rng": Rng(3)}),
    "robokit.outdoor.sonar.pulse_width_to_cm_inches": Call({"pulse_width_us": Real(1470.0)}),
    "robokit.outdoor.sonar.read_sensors": Call({
        "field": Obj(field_), "pose": Array(np.array([0.0, 0.0, 0.0]), "3"), "which": Array(np.array([0, 1, 2, 3]), "N"),
        "ping_times": Array(np.array([0.0, 0.049, 0.098, 0.147]), "N"), "mounts": Obj(_mounts), "sensor": Obj(_sonar),
        "others": Mapping(None, optional=True), "rng": Rng(0), "noise": Real(0.0)}),
    "robokit.outdoor.sonar.sensor_poses": Call({"pose": Array(np.array([1.0, 2.0, 0.3]), "3"), "mounts": Obj(_mounts)}),
    "robokit.outdoor.sonar.true_ranges": Call({"field": Obj(field_), "pose": Array(np.array([0.0, 0.0, 0.0]), "3"),
                                               "mounts": Obj(_mounts), "sensor": Obj(_sonar), "rays": Int(9)}),
    # --- sim -------------------------------------------------------------------------------
    "robokit.sim.camera.PinholeCamera": Call({"fx": Real(100.0), "fy": Real(100.0), "cx": Real(80.0), "cy": Real(60.0),
                                              "width": Int(160), "height": Int(120),
                                              "mount": T_(lambda: np.eye(4), optional=True)}),
    "robokit.sim.camera.StereoRig": Call({"camera": Obj(camera), "baseline": Real(0.12), "trinocular": Flag(False)}),
    "robokit.sim.lidar.Lidar": Call({"beams": Int(36), "r_min": Real(0.15), "r_max": Real(8.0), "noise": Real(0.0),
                                     "height": Real(0.25), "offset": Array(np.zeros(3), "3")}),
    "robokit.sim.motion.lab_lap": Call({"world": Obj(lab), "speed": Real(0.3), "rate": Real(10.0)}),
    "robokit.sim.motion.noisy_odometry": Call({"poses": Array(lambda: lap().poses[:20], "N,3"),
                                               "alphas": Array(np.array([0.01, 0.001, 0.01, 0.001]), "4"), "rng": Rng(0)}),
    "robokit.sim.omni.OmniCamera": Call({"width": Int(64), "height": Int(48), "xi": Real(1.0),
                                         "elevation_range": Array(np.array([-1.0, 0.5]), "2"), "f": Real(20.0, optional=True),
                                         "mount": T_(lambda: np.eye(4), optional=True), "face_size": Int(40)}),
    "robokit.sim.runs.record": Call({"world": Obj(lab), "path": Obj(lambda: lap()._replace(t=lap().t[:3], poses=lap().poses[:3])),
                                     "sensors": Mapping(_sensors), "rate": Real(1.0, optional=True),
                                     "odometry_alphas": Array(np.array([0.01, 0.001, 0.01, 0.001]), "4"), "seed": Int(0),
                                     "cache": Flag(False)}, cheap=False),
    "robokit.sim.runs.record_stream": Call({
        "world": Obj(lab), "path": Obj(lambda: lap()._replace(t=lap().t[:3], poses=lap().poses[:3])),
        "camera": Obj(small_omni), "rate": Real(1.0, optional=True),
        "odometry_alphas": Array(np.array([0.01, 0.001, 0.01, 0.001]), "4"), "seed": Int(0)}, cheap=False),
    "robokit.sim.textures.illuminate": Call({"image": Array(image, "N,N|N,N,3"), "gain": Real(0.5), "offset": Real(0.0),
                                             "gradient": Array(np.array([0.4, 0.0]), "2")}),
    "robokit.sim.textures.photo": Call({"name": Choice("grace_hopper")}),
    "robokit.sim.vehicle.unicycle_step": Call({"pose": Array(np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]), "3|N,3"),
                                               "v": Array(np.array([1.0, 0.5]), "|N"), "omega": Array(np.array([0.3, 0.0]), "|N"),
                                               "dt": Real(0.1), "validate": Flag(True)}),
    "robokit.sim.worlds.lab_room": Call({"seed": Int(3)}, cheap=False),
    "robokit.sim.worlds.long_corridor": Call({"layout": Choice("mixed"), "seed": Int(2), "clutter": Real(0.5)},
                                              cheap=False),
    "robokit.sim.worlds.office_floor": Call({"seed": Int(1)}, cheap=False),
    "robokit.sim.worlds_outdoor.open_field": Call({"seed": Int(0), "size": Array(np.array([30.0, 20.0]), "2"),
                                                   "n_obstacles": Int(2), "shed": Flag(True), "border": Real(3.0)}, cheap=False),
    # --- vision ----------------------------------------------------------------------------
    "robokit.vision.descriptors.detect_and_describe": Call({"image": Array(image, "N,N|N,N,3|N,N,4"), "method": Choice("sift"),
                                                            "descriptor": Choice("sift128"), "kwargs": Options({})}),
    "robokit.vision.descriptors.detect_plot_features": Call({"image": Array(image, "N,N|N,N,3|N,N,4"),
                                                             "params": Obj(None, optional=True), "descriptor": Choice("sift128"),
                                                             "overrides": Options({})}),
    "robokit.vision.descriptors.detect_sift_features": Call({"image": Array(image, "N,N|N,N,3|N,N,4"), "n_features": Int(0),
                                                             "descriptor": Choice("sift128"),
                                                             "mask": Array(image_mask, "N,N", optional=True,
                                                                           accepts=("booleans",)),
                                                             "orientation": Func(None, optional=True)}),
    "robokit.vision.evaluation.recall_precision": Call({
        "features_a": Obj(features), "features_b": Obj(features), "homography": Array(np.eye(3), "3,3"),
        "image_shape_b": Array(np.array([120, 160]), "2|3"), "thresholds": Array(np.array([0.5, 0.6]), "N", optional=True),
        "tolerance": Real(2.5), "method": Choice("kdtree")}),
    "robokit.vision.evaluation.matching_score": Call({
        "features_a": Obj(features), "features_b": Obj(features), "homography": Array(np.eye(3), "3,3"),
        "image_shape_a": Array(np.array([120, 160]), "2|3"), "image_shape_b": Array(np.array([120, 160]), "2|3"),
        "ratio": Real(0.8), "tolerance": Real(2.5), "method": Choice("kdtree")}),
    "robokit.vision.evaluation.similarity_homography": Call({"shape": Array(np.array([120, 160]), "2|3"), "zoom": Real(1.25),
                                                             "angle": Real(0.5)}),
    "robokit.vision.evaluation.warp_image": Call({"image": Array(image, "N,N|N,N,3|N,N,4"), "homography": Array(np.eye(3), "3,3"),
                                                  "shape": Array(np.array([120, 160]), "2", optional=True)}),
    "robokit.vision.matching.ratio_match": Call({"query": Array(lambda: features().descriptors[:20], "N,N", min_rows=0),
                                                 "train": Array(lambda: features().descriptors[10:40], "N,N", min_rows=0),
                                                 "ratio": Real(0.65), "method": Choice("kdtree"),
                                                 "max_distance": Real(0.8, optional=True, inf_ok=True)}),
    "robokit.vision.matching.pair_distances": Call({"query": Array(lambda: features().descriptors[:20], "N,N", min_rows=0),
                                                    "train": Array(lambda: features().descriptors[10:40], "N,N", min_rows=0),
                                                    "query_index": Array(np.array([0, 3, 19]), "N", min_rows=0),
                                                    "train_index": Array(np.array([5, 0, 29]), "N", min_rows=0),
                                                    "precision": Choice("float32"), "validate": Flag(True)}),
    "robokit.vision.plot_readable.detect_plot_readable": Call({"image": Array(image, "N,N|N,N,3|N,N,4"),
                                                                "params": Obj(None, optional=True)}),
    "robokit.vision.plot_detector.plot_scales": Call({"sigma0": Real(1.6, optional=True), "k": Real(1.26, optional=True),
                                                      "n_scales": Int(9, optional=True)}),
    "robokit.vision.plot_detector.scale_space_maxima": Call({
        "responses": Obj(lambda: [np.random.default_rng(n).random(shape, np.float32)
                                  for n, shape in enumerate([(12, 12), (12, 12), (6, 6)])]),
        "steps": Array(np.array([1, 1, 2]), "3"), "threshold": Real(0.1), "border": Int(1)}),
    "robokit.vision.plot_detector.junction_strength": Call({"tensor": Array(np.tile([[1.0, 0.1], [0.1, 2.0]], (4, 5, 1, 1)),
                                                                            "...,2,2")}),
    "robokit.vision.stereo.observe_stereo": Call({"left": Obj(features), "right": Obj(features), "rig": Obj(calibration),
                                                  "sigma_c": Real(1.0), "sigma_r": Real(1.0), "sigma_d": Real(1.0),
                                                  "match_options": Options({})}),
    "robokit.vision.stereo.triangulate_svd": Call({"p_left": Array(P_LEFT, "3,4"), "p_right": Array(P_RIGHT, "3,4"),
                                                   "uv_left": Array(UV, "N,2"), "uv_right": Array(UV - [[10.0, 0.0]], "N,2")}),
    # --- the exercises' own plain-data references --------------------------------------------
    "robocourse.lessons.visual_slam.exercises.match_ratio": Call({"query": Array(lambda: features().descriptors[:20], "N,N", min_rows=0),
                                                       "train": Array(lambda: features().descriptors[10:40], "N,N", min_rows=0),
                                                       "ratio": Real(0.65)}),
    "robocourse.lessons.visual_slam.exercises.stereo_point": Call({
        "c": Array(np.array([320.0, 100.0]), "N"), "r": Array(np.array([240.0, 50.0]), "N"),
        "d": Array(np.array([10.0, 20.0]), "N"), "focal": Real(500.0), "c0": Real(320.0), "r0": Real(240.0),
        "baseline": Real(0.12)}),
    "robocourse.lessons.visual_slam.odometry_loop.robust_pose": Call({
        "robot_points": Array(np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [-1.0, 0.2, 3.0]]), "N,3"),
        "world_points": Array(np.array([[1.0, 0.0, 2.0], [2.0, 0.0, 3.0], [0.0, 0.2, 4.0]]), "N,3")}),
    "robocourse.lessons.visual_slam.exercises.robust_pose_problems": Call({"rng": Rng()}),
    "robocourse.lessons.visual_slam.exercises.hough_candidates": Call({
        "robot_xz": Array(np.array([[0.0, 1.0], [0.5, 2.0]]), "N,2"), "robot_cov_xz": Array(np.tile(np.eye(2) * 1e-3, (2, 1, 1)), "N,2,2"),
        "world_xz": Array(np.array([[0.2, 1.2], [0.7, 2.2]]), "N,2"), "world_cov_xz": Array(np.tile(np.eye(2) * 1e-3, (2, 1, 1)), "N,2,2"),
        "thetas": Array(np.array([0.0, 0.5]), "N")}),
    "robocourse.lessons.visual_slam.odometry_loop.stereo_odometry": Call({
        "features": Obj(lambda: odometry_run()["features"]), "matches": Obj(lambda: odometry_run()["matches"]),
        "start_pose": Array(lambda: odometry_run()["start"], "3")}, cheap=False),
    # --- viz -------------------------------------------------------------------------------
    "robokit.viz.maps.plot_covariance": Call({"mean": Array(np.zeros(2), "2"), "cov": Array(np.eye(2) * 0.1, "2,2"),
                                              "ax": Given(axes), "nsigma": Real(1.0), "kwargs": Given({})}),
    "robokit.viz.maps.plot_footprint": Call({"world": Obj(lab), "ax": Given(axes), "color": Given("k"), "kwargs": Given({})}),
    "robokit.viz.maps.plot_scan": Call({"ranges": Array(np.array([1.0, np.inf, 2.0]), "N", inf_ok=True),
                                        "sensor_pose": Array(np.zeros(3), "3"),
                                        "angles": Array(np.array([0.0, 1.0, 2.0]), "N"), "ax": Given(axes),
                                        "color": Given("tab:red"), "rays": Flag(False)}),
    "robokit.viz.maps.plot_trajectory": Call({"poses": Array(lambda: lap().poses[:10], "N,3"), "ax": Given(axes),
                                              "label": Text("x", optional=True), "every": Int(0), "kwargs": Given({})}),
    "robokit.viz.scene.Scene": Call({"title": Text("t"), "height": Int(300), "live": Flag(False)}),
    "robokit.viz.scene3d.add_camera": Call({"scene": Obj(scene), "path": Text("camera"), "camera": Obj(camera),
                                            "T_world_cam": T_(lambda: np.eye(4)), "depth": Real(0.4), "color": Given(0x2255CC)}),
    "robokit.viz.scene3d.add_landmarks": Call({"scene": Obj(scene), "path": Text("landmarks"),
                                               "points": Array(lambda: points(4), "N,3", min_rows=0),
                                               "covariances": Array(lambda: covs(4), "N,3,3", optional=True),
                                               "nsigma": Real(1.0), "colors": Array(np.full((4, 3), 0.5), "N,3", optional=True),
                                               "max_ellipsoids": Int(10)}),
    "robokit.viz.scene3d.add_trajectory": Call({"scene": Obj(scene), "path": Text("lap"),
                                                "poses": Array(lambda: lap().poses[:10], "N,3"), "z": Real(0.02),
                                                "color": Given(0x22AA22), "every": Int(0)}),
    "robokit.viz.scene3d.add_world": Call({"scene": Obj(scene), "world": Obj(lab), "path": Text("world"), "cell": Int(8),
                                           "ceiling": Flag(False)}, cheap=False),
    "robokit.viz.animation.animate_poses": Call({"scene": Obj(scene), "path": Text("truck"),
                                                 "transforms": Array(lambda: lap().poses[:5], "N,3|N,4,4"),
                                                 "fps": Real(10.0), "repetitions": Int(1)}),
    "robokit.viz.framing.fit_view": Call({"scene": Obj(framed_scene), "direction": Array(np.array([0.5, -1.0, 0.9]), "3"),
                                       "paths": Text(None, optional=True),
                                       "bounds": Array(np.array([[0.0, 0.0, 0.0], [2.0, 1.0, 0.5]]), "2,3", optional=True),
                                       "margin": Real(0.08), "width": Int(1000)}),
    "robokit.viz.framing.look_from": Call({"scene": Obj(scene), "position": Array(np.array([-5.0, -5.0, 9.0]), "3"),
                                           "target": Array(np.array([0.0, 0.0, 0.1]), "3", optional=True)}),
    # --- lesson 02: the assignment's plain-data references, the experiments, graphs and sliders ---
    "robocourse.lessons.omni_localization.exercises.fine_stage_counts": Call({
        "query": Array(lambda: rec_nodes()[1][:4] + 0.01, "N,N", min_rows=0), "node_descriptors": Obj(rec_nodes),
        "candidates": Array(np.array([0, 1, 2]), "N", min_rows=0), "ratio": Real(0.8)}),
    "robocourse.lessons.omni_localization.exercises.recognise_node": Call({
        "query_histogram": Array(np.array([0.1, 0.9, 0.0]), "N"),
        "query_descriptors": Array(lambda: rec_nodes()[1][:4] + 0.01, "N,N", min_rows=0),
        "node_histograms": Array(np.eye(3), "N,N"), "node_descriptors": Obj(rec_nodes), "top_k": Int(2),
        "ratio": Real(0.8)}),
    "robocourse.lessons.omni_localization.relaxation_runs.relax_map": Call({
        "poses": Array(lambda: pose_graph().poses, "N,3"), "edges": Array(lambda: pose_graph().edges, "N,2"),
        "measurements": Array(lambda: pose_graph().measurements, "N,3"),
        "edge_variances": Array(lambda: np.full(pose_graph().n_edges, 0.02), "N"), "tolerance": Real(1e-3),
        "max_sweeps": Int(50)}),
    "robocourse.lessons.omni_localization.exercises.node_fix_update": Call({
        "x": Array(EKF_X, "N"), "P": Array(np.eye(5) * 0.01, "N,N"), "node_pose": Array(np.array([0.5, 0.2, 1.0]), "N"),
        "z": Array(np.array([0.1, 0.2, 3.1]), "N"), "R": Array(np.eye(3) * 0.01, "N,N")}),
    "robocourse.lessons.omni_localization.experiment.office_setup": Call({"fast": Flag(True), "progress": Func(None, optional=True)},
                                                            cheap=False),
    "robocourse.lessons.omni_localization.experiment.localization_trials": Call({
        "setup": Obj(office_experiment), "places": Array(np.array([[13.0, 3.7, 2.0]]), "N,3"),
        "modes": Given(("coarse",)), "map": Choice("relaxed"), "rng": Rng(0), "progress": Func(None, optional=True)},
        cheap=False),
    "robocourse.lessons.omni_localization.experiment.route_recognition": Call({
        "setup": Obj(office_experiment), "n_nodes": Int(2), "offset": Real(0.15), "same_place": Real(0.5),
        "rng": Rng(1)}, cheap=False),
    "robocourse.lessons.omni_localization.checks.query_places": Call({
        "setup": Obj(office_experiment), "n": Int(2), "near": Real(1.0), "clearance": Real(0.4), "rng": Rng(0)}),
    "robocourse.lessons.omni_localization.checks.drive_on": Call({
        "setup": Obj(office_experiment), "start": Array(np.array([12.0, 2.5, 0.0]), "3"), "length": Real(1.0),
        "step": Real(0.25), "clearance": Real(0.3)}),
    "robocourse.lessons.omni_localization.checks.check_trials": Call({
        "setup": Obj(office_experiment), "places": Array(np.array([[13.0, 3.7, 2.0]]), "N,3"),
        "map": Choice("relaxed"), "length": Real(0.5), "step": Real(0.25), "seed": Int(0), "cache": Flag(False),
        "workers": Int(1, optional=True), "progress": Func(None, optional=True)}, cheap=False),
    "robocourse.lessons.omni_localization.checks.mask_trials": Call({
        "setup": Obj(office_experiment), "places": Array(np.array([[13.0, 3.7, 2.0]]), "N,3"),
        "thresholds": Array(np.array([0.15]), "N"), "bins": Int(32), "gain": Real(0.7), "noise": Real(2.0),
        "rng": Rng(0)}, cheap=False),
    "robocourse.lessons.omni_localization.landmarks.landmark_map": Call({
        "tmap": Obj(lambda: office_experiment().relaxed), "camera": Obj(lambda: office_experiment().camera),
        "ratio": Real(0.7), "min_angle": Real(0.26), "max_range": Real(6.0)}),
    "robocourse.lessons.omni_localization.benchmark.benchmark_graph": Call({}),
    "robocourse.lessons.omni_localization.benchmark.solve_benchmark": Call({
        "graph": Obj(intel_graph), "max_sweeps": Int(5, optional=True), "method": Choice("gauss-newton"),
        "fast": Flag(True, optional=True)}, cheap=False),
    "robocourse.lessons.omni_localization.alignment.loop_rows": Call({"graph": Obj(pose_graph)}),
    "robocourse.lessons.omni_localization.alignment.loop_subsets": Call({"graph": Obj(pose_graph), "k": Int(3)}),
    "robocourse.lessons.omni_localization.alignment.held_share": Call({
        "graph": Obj(pose_graph), "keep": Array(pose_graph_loops, "N", optional=True, min_rows=0)}),
    "robocourse.lessons.omni_localization.alignment.with_loops": Call({
        "graph": Obj(pose_graph), "keep": Array(pose_graph_loops, "N", optional=True, min_rows=0)}),
    "robocourse.lessons.omni_localization.alignment.alignment_errors": Call({
        "graph": Obj(pose_graph), "truth": Array(pose_graph_truth, "N,3"),
        "keep": Array(pose_graph_loops, "N", optional=True, min_rows=0), "max_sweeps": Int(20000)}),
    "robocourse.lessons.omni_localization.alignment.loop_edge_errors": Call({
        "graph": Obj(pose_graph), "truth": Array(pose_graph_truth, "N,3"),
        "keep": Array(pose_graph_loops, "N", optional=True, min_rows=0)}),
    "robocourse.lessons.omni_localization.alignment.odometry_redraws": Call({
        "graph": Obj(pose_graph), "truth": Array(pose_graph_truth, "N,3"),
        "keep": Array(pose_graph_loops, "N", optional=True, min_rows=0), "draws": Int(3), "rng": Rng(0)}),
    "robocourse.lessons.omni_localization.navigation.navigation_trials": Call({
        "setup": Obj(office_experiment), "n_starts": Int(1), "first_node": Int(0, optional=True),
        "n_path_nodes": Int(3), "clearance": Real(0.3), "fix_period": Real(1.0), "alpha": Real(2.0),
        "offset": Real(0.3), "heading": Real(0.3), "max_time": Real(3.0, optional=True), "success_radius": Real(0.3),
        "localize": Func(localizer, optional=True),
        "seed": Int(3), "cache": Flag(False), "progress": Func(None, optional=True)}, cheap=False),
    "robokit.viz.maps.plot_graph": Call({
        "poses": Array(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]), "N,3"),
        "edges": Array(np.array([[0, 1], [1, 2]]), "N,2", min_rows=0), "ax": Given(axes),
        "label": Text("map", optional=True),
        "highlight": Array(np.array([False, True]), "N", optional=True, accepts=("booleans",)), "kwargs": Given({})}),
    "robokit.viz.scene3d.add_graph": Call({
        "scene": Obj(scene), "path": Text("map"),
        "poses": Array(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]), "N,3"),
        "edges": Array(np.array([[0, 1], [1, 2]]), "N,2", min_rows=0), "z": Real(0.05), "node_color": Given(0x2255CC),
        "edge_color": Given(0x2255CC), "size": Real(0.12)}),
    "robokit.viz.scene3d.add_image": Call({"scene": Obj(scene), "path": Text("view"),
                                           "image": Given(np.zeros((4, 6, 3), np.uint8)),
                                           "centre": Array(np.array([1.0, 2.0, 3.0]), "3"), "width": Real(1.5)}),
    "robokit.viz.widgets.slider": Call({"draw": Func(lambda: draw_figure), "values": Given([1.0, 2.0]), "label": Text("k"),
                                        "fmt": Text("{}"), "start": Int(0), "spacing": Choice("value")}, cheap=False),
    # --- lesson 02: controllers.path_following(_loop), localization.pose_ekf, navigation.visual_path --------
    "robokit.controllers.path_geometry.VisualPath": Call({
        "poses": Array(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]), "N,3"),
        "s": Array(np.array([0.0, 1.0, 2.0]), "N"), "curvature": Array(np.zeros(3), "N"),
        "key_poses": Array(np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]), "N,3", optional=True)}),
    "robokit.controllers.path_geometry.path_from_poses": Call({"poses": Array(KEY_POSES, "N,3"), "spacing": Real(0.1)}),
    "robokit.controllers.path_geometry.reference_point": Call({
        "path": Obj(visual_path), "pose": Array(np.array([1.0, 0.2, 0.1]), "3"), "previous": Int(5, optional=True),
        "window": Real(1.0, optional=True), "validate": Flag(True)}),
    "robokit.controllers.path_following.path_following_gains": Call({"alpha": Real(2.0), "xi": Real(0.7)}),
    "robokit.controllers.path_following.path_following_command": Call({
        "d": Array(np.array([0.1, -0.2]), "*"), "theta_tilde": Array(np.array([0.1, 0.0]), "*"),
        "curvature": Array(np.array([0.0, 0.5]), "*"), "v": Array(np.array([0.3, 0.3]), "*"), "k2": Real(4.0),
        "k3": Real(2.8)}),
    "robokit.controllers.path_following.saturate_command": Call({
        "v": Array(np.array([0.3, 0.3]), "*"), "omega": Array(np.array([2.0, 0.1]), "*"), "v_max": Real(0.3),
        "w_max": Real(0.5)}),
    "robokit.controllers.path_following.PathFollower": Call({
        "path": Obj(visual_path), "alpha": Real(2.0), "v_max": Real(0.3), "w_max": Real(1.0), "xi": Real(0.7),
        "goal_tolerance": Real(0.1), "window": Real(1.0, optional=True)}),
    "robokit.controllers.path_following_loop.path_following_linearisation": Call({"alpha": Real(2.0), "v": Real(0.3),
                                                                                  "xi": Real(0.7)}),
    "robokit.controllers.path_following_loop.path_following_poles": Call({"alpha": Real(2.0), "v": Real(0.3), "xi": Real(0.7)}),
    "robokit.controllers.path_following_loop.path_following_damping": Call({"alpha": Real(2.0), "v": Real(0.3),
                                                                            "xi": Real(0.7)}),
    "robokit.controllers.path_following_loop.lateral_step_response": Call({
        "alpha": Real(2.0), "v": Real(0.3), "t": Array(np.linspace(0.0, 5.0, 11), "N", optional=True), "xi": Real(0.7),
        "offset": Real(0.1)}),
    "robokit.controllers.path_following_loop.simulate_path_following": Call({
        "path": Obj(visual_path), "start_pose": Array(np.array([0.0, 0.1, 0.0]), "3"), "alpha": Real(2.0),
        "v": Real(0.3), "duration": Real(2.0), "dt": Real(0.1), "w_max": Real(1.0, optional=True), "xi": Real(0.7)}),
    "robokit.localization.pose_ekf.unicycle_jacobian": Call({"x": Array(EKF_X, "5"), "dt": Real(0.1)}),
    "robokit.localization.pose_ekf.unicycle_process_noise": Call({
        "x": Array(EKF_X, "5"), "dt": Real(0.1), "sigma_accel": Real(0.5), "sigma_alpha": Real(1.0)}),
    "robokit.localization.pose_ekf.ekf_predict": Call({
        "x": Array(EKF_X, "5"), "P": Array(np.eye(5) * 0.01, "5,5"), "dt": Real(0.1),
        "Q": Array(np.eye(5) * 1e-4, "5,5")}),
    "robokit.localization.pose_ekf.ekf_update": Call({
        "x": Array(EKF_X, "N"), "P": Array(np.eye(5) * 0.01, "N,N"), "z": Array(np.array([0.1, 0.2, 3.1]), "N"),
        "H": Array(np.eye(3, 5), "N,N"), "R": Array(np.eye(3) * 0.01, "N,N"), "angles": Obj((2,))}),
    "robokit.localization.pose_ekf.nees": Call({"error": Array(np.array([0.1, -0.2]), "N|N,N"),
                                                "P": Array(np.diag([0.01, 0.04]), "N,N|N,N,N")}),
    "robokit.localization.pose_ekf.nees_bounds": Call({"dof": Int(5), "runs": Int(50), "confidence": Real(0.95)}),
    "robokit.localization.pose_ekf.UnicycleEKF": Call({
        "x0": Array(EKF_X, "5"), "P0": Array(np.eye(5) * 0.01, "5,5"), "sigma_accel": Real(0.5), "sigma_alpha": Real(1.0)}),
    "robokit.navigation.visual_path.gaussian_localizer": Call({
        "noise": Array(np.array([0.1, 0.15, 0.05]), "3"), "dropout": Real(0.1), "outlier_rate": Real(0.1),
        "outlier_offset": Real(2.0)}),
    "robokit.navigation.visual_path.perturbed_starts": Call({
        "path": Obj(visual_path), "n": Int(3), "offset": Real(0.3), "heading": Real(0.3), "rng": Rng(0)}),
    "robokit.navigation.visual_path.follow_path": Call({
        "path": Obj(visual_path), "start_pose": Array(np.array([0.0, 0.1, 0.0]), "3"), "localize": Func(localizer),
        "dt": Real(0.1), "fix_period": Real(0.5), "alpha": Real(2.0), "v_max": Real(0.3), "w_max": Real(1.0),
        "xi": Real(0.7), "goal_tolerance": Real(0.1), "odometry_noise": Array(np.array([0.01, 0.02]), "2"),
        "sigma_fix": Array(np.array([0.1, 0.15, 0.05]), "3"), "sigma_odometry": Array(np.array([0.01, 0.02]), "2", optional=True),
        "gate": Real(16.0, optional=True), "relocalize_after": Int(3), "max_time": Real(3.0, optional=True), "rng": Rng(0)}),
    # --- robokit.vision.colour (lesson 02: HSI hue histograms) --------------------------------
    "robokit.vision.colour.rgb_to_hsi": Call({"image": Array(image, "...,3|...,4")}),
    "robokit.vision.colour.hue_mask": Call({"image": Array(image, "N,N,3|N,N,4"), "min_saturation": Real(0.15),
                                            "min_intensity": Real(0.04), "max_intensity": Real(0.98)}),
    "robokit.vision.colour.hue_histogram": Call({"image": Array(image, "N,N,3|N,N,4"), "bins": Int(32),
                                                 "min_saturation": Real(0.15), "min_intensity": Real(0.04),
                                                 "max_intensity": Real(0.98),
                                                 "mask": Array(image_mask, "N,N", optional=True, accepts=("booleans",))}),
    "robokit.vision.colour.hue_histogram_opencv": Call({"image": Array(image, "N,N,3|N,N,4"), "bins": Int(32),
                                                        "min_saturation": Real(0.15), "min_intensity": Real(0.04),
                                                        "max_intensity": Real(0.98),
                                                        "mask": Array(image_mask, "N,N", optional=True,
                                                                      accepts=("booleans",))}),
    "robokit.vision.colour.histogram_distance": Call({"h": Array(np.full(8, 0.125), "N"),
                                                      "H": Array(np.eye(8)[:3], "N|N,N")}),
    "robokit.vision.colour.histogram_intersection": Call({"h": Array(np.full(8, 0.125), "N"),
                                                          "H": Array(np.eye(8)[:3], "N|N,N")}),
    # --- robokit.vision.omni_features, matching.DescriptorIndex, sim.view_matches (lesson 02) ---
    "robokit.vision.omni_features.omni_sift": Call({"image": Array(image, "N,N|N,N,3|N,N,4"),
                                                    "centre": Array(np.array([80.0, 60.0]), "2"),
                                                    "radii": Array(np.array([10.0, 55.0]), "2"), "orientation": Choice("radial"),
                                                    "n_features": Int(0), "mask": Array(image_mask, "N,N", optional=True,
                                                                                        accepts=("booleans",))}),
    "robokit.vision.omni_features.annulus_mask": Call({"shape": Array(np.array([120, 160]), "2"),
                                                       "centre": Array(np.array([80.0, 60.0]), "2"),
                                                       "radii": Array(np.array([10.0, 55.0]), "2")}),
    "robokit.vision.omni_features.radial_orientation": Call({"xy": Array(np.array([[90.0, 60.0], [80.0, 20.0]]), "N,2|2",
                                                                         min_rows=0),
                                                             "centre": Array(np.array([80.0, 60.0]), "2")}),
    "robokit.vision.matching.DescriptorIndex": Call({"descriptors": Array(lambda: features().descriptors[:40], "N,N",
                                                                          min_rows=0),
                                                     "method": Choice("flann"), "checks": Int(32), "trees": Int(2),
                                                     "seed": Int(0)}),
    "robokit.vision.matching.ratio_test": Call({"dist": Array(np.array([[0.1, 1.0], [0.5, np.inf]]), "N,2", inf_ok=True,
                                                              min_rows=0),
                                                "index": Array(np.array([[3, 1], [0, 2]]), "N,2", min_rows=0),
                                                "ratio": Real(0.8), "max_distance": Real(0.8, optional=True, inf_ok=True)}),
    "robokit.sim.view_matches.omni_ground_truth_inliers": Call({
        "camera": Obj(small_omni), "ranges": Array(lambda: np.full((120, 160), 2.0), "120,160", inf_ok=True),
        "T1": T_(lambda: small_omni().transform_at([2.0, 6.0, 0.0])), "T2": T_(lambda: small_omni().transform_at([2.2, 6.0, 0.3])),
        "uv1": Array(np.array([[120.0, 60.0], [40.0, 70.0]]), "N,2", min_rows=0),
        "uv2": Array(np.array([[118.0, 61.0], [45.0, 66.0]]), "N,2", min_rows=0), "tol": Real(3.0)}),
    "robokit.sim.view_matches.omni_view_pair": Call({
        "world": Obj(office), "camera": Obj(small_omni), "pose1": Array(np.array([12.0, 3.5, 0.0]), "3"),
        "pose2": Array(np.array([12.2, 3.5, 0.5]), "3"), "orientation": Choice("radial"), "ratio": Real(0.8),
        "tol": Real(3.0), "method": Choice("kdtree")}, cheap=False),
    # --- mapping: pose graphs (pose_graph, pose_graph_optimize, relaxation, g2o, manhattan) ------
    "robokit.mapping.pose_graph.PoseGraph": Call({
        "poses": Array(lambda: pose_graph().poses, "N,3"), "edges": Array(lambda: pose_graph().edges, "N,2", min_rows=0),
        "measurements": Array(lambda: pose_graph().measurements, "N,3"),
        "information": Array(lambda: pose_graph().information, "N,3,3", optional=True),
        "ids": Array(lambda: pose_graph().ids, "N", optional=True), "fixed": Int(0)}),
    "robokit.mapping.pose_graph.edge_variances": Call({"graph": Obj(pose_graph)}),
    "robokit.mapping.pose_graph.unreachable_nodes": Call({"graph": Obj(pose_graph)}),
    "robokit.mapping.pose_graph.is_connected": Call({"graph": Obj(pose_graph)}),
    "robokit.mapping.pose_graph.require_connected": Call({"graph": Obj(pose_graph)}),
    "robokit.mapping.pose_graph.pose_graph_from_odometry": Call({
        "odometry_poses": Array(lambda: pose_graph().poses[:6], "N,3"),
        "loop_edges": Array(np.array([[5, 0]]), "N,2", optional=True, min_rows=0),
        "loop_measurements": Array(np.array([[0.1, 0.0, 0.2]]), "N,3", optional=True),
        "sigma_odometry": Array(np.array([0.1, 0.1, 0.05]), "|3|N,3"), "sigma_loop": Array(np.array([0.2, 0.2, 0.1]), "|3|N,3")}),
    "robokit.mapping.pose_graph_optimize.pose_graph_residuals": Call({"graph": Obj(pose_graph),
                                                             "poses": Array(lambda: pose_graph().poses, "N,3", optional=True)}),
    "robokit.mapping.pose_graph_optimize.pose_graph_cost": Call({"graph": Obj(pose_graph),
                                                        "poses": Array(lambda: pose_graph().poses, "N,3", optional=True)}),
    "robokit.mapping.pose_graph_optimize.pose_graph_jacobian": Call({"graph": Obj(pose_graph),
                                                            "poses": Array(lambda: pose_graph().poses, "N,3", optional=True)}),
    "robokit.mapping.pose_graph_optimize.optimize_pose_graph": Call({
        "graph": Obj(pose_graph), "method": Choice("gauss-newton"), "max_iterations": Int(20), "tolerance": Real(1e-9),
        "linear_solver": Choice("auto")}),
    "robokit.mapping.relaxation.relax": Call({"graph": Obj(pose_graph), "max_iterations": Int(50), "tolerance": Real(1e-6),
                                              "variances": Array(lambda: np.full(30, 0.01), "N", optional=True)}),
    "robokit.mapping.relaxation.relax_sweep": Call({
        "poses": Array(lambda: pose_graph().poses, "N,3"), "variances": Array(lambda: np.full(30, 0.01), "N"),
        "edges": Array(lambda: pose_graph().edges, "N,2"), "measurements": Array(lambda: pose_graph().measurements, "N,3"),
        "edge_variances": Array(lambda: np.full(pose_graph().n_edges, 0.02), "N"), "fixed": Int(0)}),
    "robokit.mapping.relaxation.initial_variances": Call({"graph": Obj(pose_graph)}),
    "robokit.mapping.g2o.write_g2o": Call({"graph": Obj(pose_graph), "path": Text(None, optional=True)}),
    "robokit.mapping.manhattan.manhattan_world_graph": Call({
        "n_poses": Int(40), "seed": Int(0), "noise": Array(np.array([0.05, 0.05, 0.01]), "|3"), "extent": Int(5),
        "closure_probability": Real(0.6), "min_gap": Int(10)}),
    # --- lesson 02's topological map and hierarchical localization (helper D) -----------------
    "robokit.geometry.procrustes.fit_se2": Call({"source": Array(lambda: points(6)[:, :2], "N,2|N,N,2"),
                                             "target": Array(lambda: points(6)[:, :2] + 1.0, "N,2|N,N,2"),
                                             "weights": Array(np.ones(6), "N|N,N", optional=True), "validate": Flag(True)}),
    "robokit.vision.ransac.ransac_sample_count": Call({"contamination": Real(0.3), "sample_size": Int(2),
                                                       "confidence": Real(0.99)}),
    "robokit.vision.ransac.ransac_se2": Call({"source": Array(lambda: points(8)[:, :2], "N,2", min_rows=0),
                                              "target": Array(lambda: points(8)[:, :2] + 1.0, "N,2", min_rows=0),
                                              "threshold": Real(0.1), "confidence": Real(0.99), "min_inliers": Int(4),
                                              "max_iterations": Int(50), "rng": Rng(0)}),
    "robokit.vision.spherical.essential_from_bearings": Call({"b1": Array(bearings, "N,3"),
                                                              "b2": Array(moved_bearings, "N,3")}),
    "robokit.vision.spherical.epipolar_error": Call({"E": Array(essential, "3,3|N,3,3"), "b1": Array(bearings, "N,3"),
                                                     "b2": Array(moved_bearings, "N,3")}),
    "robokit.vision.spherical.ransac_essential": Call({"b1": Array(bearings, "N,3"), "b2": Array(moved_bearings, "N,3"),
                                                       "threshold": Real(0.01), "confidence": Real(0.99),
                                                       "min_inliers": Int(8), "max_iterations": Int(64), "rng": Rng(0)}),
    "robokit.vision.spherical.decompose_essential": Call({"E": Array(essential, "3,3"), "b1": Array(bearings, "N,3"),
                                                          "b2": Array(moved_bearings, "N,3")}),
    "robokit.vision.spherical.floor_points": Call({"bearings": Array(lambda: bearings() * [1, 1, -1] + [0, 0, 0.5], "N,3"),
                                                   "T_body_camera": T_(lambda: small_omni().mount),
                                                   "min_depression": Real(0.35)}),
    "robokit.sim.motion.office_tour": Call({"world": Obj(office), "speed": Real(0.3), "rate": Real(2.0)}),
    "robokit.sim.motion.increment_variances": Call({"delta": Array(np.array([[0.1, 1.0, -0.1]]), "3|N,3"),
                                                    "alphas": Array(np.array([0.01, 0.001, 0.01, 0.001]), "4")}),
    "robokit.sim.motion.odometry_covariance": Call({"odometry": Array(lambda: lap().poses[:20], "N,3"),
                                                    "alphas": Array(np.array([0.01, 0.001, 0.01, 0.001]), "4")}),
    "robokit.mapping.topological_build.appearance_changed": Call({"distance": Array(np.array([0.01, 0.3]), "|N"),
                                                                  "matches": Array(np.array([90, 10]), "|N"),
                                                                  "similarity": Real(0.05), "min_matches": Int(50)}),
    "robokit.mapping.topological_build.local_map_full": Call({"n_features": Array(np.array([100, 990]), "|N"),
                                                              "variance": Array(np.array([0.01, 0.2]), "|N"),
                                                              "max_features": Int(930), "max_variance": Real(0.1)}),
    "robokit.mapping.topological_build.select_key_frames": Call({
        "n_frames": Int(5), "compare": Func(lambda: (lambda key, k: __import__("robokit.mapping.topological_build", fromlist=["Comparison"]).Comparison(
            0.01, 100, 500, 0.0))),
        "similarity": Real(0.05), "min_matches": Int(50), "occlusion_frames": Int(3), "max_features": Int(930),
        "max_variance": Real(0.1)}),
    "robokit.mapping.topological_build.build_topological_map": Call({
        "images": Array(lambda: office_views()[0], "N,120,160,3"), "odometry": Array(lambda: office_views()[1], "N,3"),
        "camera": Obj(small_omni), "similarity": Real(0.05), "min_matches": Int(50), "occlusion_frames": Int(3),
        "max_features": Int(930), "max_variance": Real(0.1),
        "odometry_alphas": Array(np.array([0.01, 0.001, 0.01, 0.001]), "4"), "bins": Int(32), "n_features": Int(100),
        "ratio": Real(0.7), "loop_closure": Flag(True), "loop_top_k": Int(5), "loop_min_matches": Int(25),
        "loop_exclude": Int(5), "sigma_visual": Array(np.array([0.05, 0.05, 0.02]), "3"), "index": Choice("opencv"),
        "progress": Func(None, optional=True), "log": Func(None, optional=True)}, cheap=False),
    "robokit.mapping.omni_views.omni_view": Call({"image": Array(lambda: office_views()[0][0], "120,160,3"),
                                                  "camera": Obj(small_omni), "bins": Int(32), "n_features": Int(100),
                                                  "features": Flag(True), "times": Mapping(None, optional=True),
                                                  "histogram": Array(lambda: np.full(32, 1 / 32), "32", optional=True)}),
    "robokit.mapping.omni_views.as_omni_image": Call({"image": Array(lambda: office_views()[0][0], "120,160,3"),
                                                         "camera": Obj(small_omni), "name": Text("image")}),
    "robokit.mapping.omni_views.relative_pose": Call({
        "query": Obj(lambda: omni_views()[1]), "node": Obj(lambda: omni_views()[0]), "matches": Obj(omni_matches),
        "camera": Obj(small_omni), "threshold_epipolar": Real(0.01), "threshold_floor": Real(0.08),
        "min_epipolar": Int(12), "min_floor": Int(3), "min_depression": Real(0.35), "direction_tolerance": Real(0.35),
        "min_baseline": Real(0.1), "rng": Rng(0)}),
    "robokit.mapping.topological.TopologicalMap": Call({
        name: Array(lambda name=name: getattr(office_map(), name), shape, min_rows=rows)
        for name, shape, rows in [("poses", "N,3", 1), ("variances", "N", 1), ("histograms", "N,N", 1), ("frames", "N", 1),
                                  ("keypoints", "N,4", 0), ("bearings", "N,3", 0), ("descriptors", "N,N", 0),
                                  ("offsets", "N", 1), ("edges", "N,2", 0), ("measurements", "N,3", 0),
                                  ("covariances", "N,3,3", 0), ("kinds", "N", 0)]} | {"index": Choice("opencv")}),
    "robokit.localization.hierarchical.HierarchicalLocalizer": Call({
        "map": Obj(office_map), "camera": Obj(small_omni), "top_k": Int(2), "max_rounds": Int(2, optional=True),
        "ratio": Real(0.7), "min_matches": Int(25), "ambiguity": Real(0.8), "n_features": Int(100),
        "mode": Choice("hierarchical"), "min_crossing": Real(0.26), "max_range": Real(4.0)}),
    "robokit.localization.appearance_mcl.place_hypotheses": Call({
        "localizer": Obj(lambda: __import__("robokit.localization", fromlist=["x"]).HierarchicalLocalizer(
            office_map(), small_omni(), top_k=2, n_features=100)),
        "image": Array(lambda: office_views()[0][0], "120,160,3"), "max_hypotheses": Int(2)}),
    "robokit.localization.appearance_mcl.monte_carlo_check": Call({
        "localizer": Obj(lambda: __import__("robokit.localization", fromlist=["x"]).HierarchicalLocalizer(
            office_map(), small_omni(), top_k=2, n_features=100)),
        "image": Array(lambda: office_views()[0][0], "120,160,3"),
        "drive_images": Obj(lambda: [office_views()[0][1]]), "drive_odometry": Array(lambda: office_views()[1][:2], "2,3"),
        "max_hypotheses": Int(2), "n_particles": Int(20), "spread": Array(np.array([0.15, 0.15, 0.1]), "3"),
        "alphas": Array(np.array([0.01, 0.001, 0.01, 0.001]), "4"), "sigma": Real(0.3), "same_place": Real(0.5),
        "rng": Rng(0)}, cheap=False),
    "robokit.geometry.planar.intersect_lines": Call({"origins": Array(np.array([[0.0, 0.0], [4.0, 0.0]]), "N,2"),
                                                     "directions": Array(np.array([[1.0, 1.0], [-1.0, 1.0]]), "N,2")}),
    # --- robokit.localization.particle_filter, beam_models, mcl (lesson 03's Monte-Carlo localization) --
    "robokit.localization.particle_filter.normalise_log_weights": Call({
        "log_w": Array(np.array([0.0, -1.0, -np.inf]), "N", inf_ok=True)}),
    "robokit.localization.particle_filter.low_variance_resample": Call({
        "weights": Array(np.array([0.2, 0.5, 0.3]), "N"), "rng": Rng(0), "count": Int(4, optional=True),
        "start": Real(0.1, optional=True)}),
    "robokit.localization.particle_filter.kld_sample_count": Call({"k": Array(np.array([1, 5]), "|N"), "epsilon": Real(0.01), "z": Real(2.33)}),
    "robokit.localization.particle_filter.pose_bins": Call({
        "particles": Array(np.array([[0.2, 0.7, 0.0], [1.3, 0.6, 0.1]]), "N,3"),
        "bin_size": Array(np.array([0.5, 0.5, 0.17]), "3")}),
    "robokit.localization.particle_filter.kld_resample": Call({
        "particles": Array(np.array([[0.2, 0.7, 0.0], [1.3, 0.6, 0.1]]), "N,3"), "weights": Array(np.array([1.0, 2.0]), "N"),
        "rng": Rng(0), "min_count": Int(5), "max_count": Int(50), "epsilon": Real(0.05), "z": Real(0.99),
        "bin_size": Array(np.array([0.5, 0.5, 0.17]), "3"), "random_pose": Func(None, optional=True),
        "inject_probability": Real(0.0)}),
    "robokit.localization.particle_filter.weighted_pose_mean": Call({
        "particles": Array(np.array([[0.0, 0.0, 3.0], [2.0, 0.0, -3.0]]), "N,3"),
        "weights": Array(np.array([1.0, 3.0]), "N", optional=True)}),
    "robokit.localization.particle_filter.sample_ellipse_poses": Call({
        "pose": Array(np.array([5.0, 0.0, 0.3]), "3"), "sigma_x": Real(0.5), "sigma_y": Real(0.1), "n": Int(10),
        "nsigma": Real(2.0), "sigma_theta": Real(0.05), "rng": Rng(0)}),
    "robokit.localization.particle_filter.ellipse_weights": Call({
        "particles": Array(np.array([[5.0, 0.1, 0.0], [4.5, 0.0, 0.0]]), "N,3"), "pose": Array(np.array([5.0, 0.0, 0.3]), "3"),
        "sigma_x": Real(0.5), "sigma_y": Real(0.1), "normalise": Flag(True)}),
    "robokit.localization.beam_models.subsample_beams": Call({"count": Int(360), "max_beams": Int(30, optional=True)}),
    "robokit.localization.beam_models.valid_beams": Call({
        "ranges": Array(SCAN, "N", inf_ok=True), "angles": Array(SCAN_ANGLES, "N"), "r_max": Real(8.0),
        "max_beams": Int(3, optional=True)}),
    "robokit.localization.beam_models.likelihood_field_log_weights": Call({
        "particles": Array(np.array([[0.0, 0.0, 0.0], [0.2, 0.1, 0.5]]), "N,3"), "ranges": Array(SCAN, "N", inf_ok=True),
        "angles": Array(SCAN_ANGLES, "N"), "field": Obj(small_field), **beam_model_kinds()}),
    "robokit.localization.scan_matching.match_scan": Call({
        "pose": Array(np.array([0.2, 0.1, 0.5]), "3"), "ranges": Array(SCAN, "N", inf_ok=True),
        "angles": Array(SCAN_ANGLES, "N"), "field": Obj(small_field),
        "window": Array(np.array([0.1, 0.1, 0.05]), "3"), "steps": Int(5), "levels": Int(2),
        "sensor_offset": Array(np.zeros(3), "3"), "sigma_hit": Real(0.05), "r_max": Real(8.0)}),
    "robokit.localization.beam_models.likelihood_field_log_weight_readable": Call({
        "pose": Array(np.array([0.2, 0.1, 0.5]), "3"), "ranges": Array(SCAN, "N", inf_ok=True),
        "angles": Array(SCAN_ANGLES, "N"), "field": Obj(small_field), **beam_model_kinds()}),
    "robokit.localization.mcl.mcl_step": Call({
        "particles": Array(np.array([[0.0, 0.0, 0.0], [0.2, 0.1, 0.5]]), "N,3"), "weights": Array(np.array([0.5, 0.5]), "N"),
        "odom_prev": Array(np.zeros(3), "3"), "odom_now": Array(np.array([0.3, 0.0, 0.1]), "3"),
        "ranges": Array(SCAN, "N", inf_ok=True), "angles": Array(SCAN_ANGLES, "N"), "field": Obj(small_field),
        "alphas": Array(np.full(4, 0.05), "4"), "resample": Flag(True), "rng": Rng(0), "model": Given({})}),
    "robokit.localization.mcl.uniform_free_poses": Call({
        "free_cells": Array(np.array([[0.5, 0.5], [1.5, 0.5]]), "N,2"), "resolution": Real(1.0), "n": Int(3),
        "rng": Rng(0)}),
    "robokit.localization.mcl.MonteCarloLocalizer": Call({
        "grid": Obj(room_grid), "field": Obj(None, optional=True), "n_particles": Int(50),
        "alphas": Array(np.full(4, 0.2), "4"), "sigma_hit": Real(0.2), "z_hit": Real(0.95), "z_rand": Real(0.05),
        "r_max": Real(8.0), "max_beams": Int(30, optional=True), "combine": Choice("ros"),
        "sensor_offset": Array(np.zeros(3), "3"), "update_min_d": Real(0.2), "update_min_a": Real(0.5),
        "resample_interval": Int(2), "kld": Obj(None, optional=True), "alpha_slow": Real(0.0), "alpha_fast": Real(0.0),
        "rng": Rng(0)}),
    # --- robokit.mapping.occupancy_grid, grid_mapping, map_server (lesson 03's occupancy grid) --
    "robokit.mapping.occupancy_grid.log_odds": Call({"p": Array(np.array([0.3, 0.7]), "...")}),
    "robokit.mapping.occupancy_grid.probability": Call({"l": Array(np.array([-1.0, 2.0]), "...")}),
    "robokit.mapping.occupancy_grid.OccupancyGrid": Call({"log_odds": Array(np.zeros((3, 4)), "N,N"),
                                                          "resolution": Real(0.1), "origin": Array(np.zeros(2), "2")}),
    "robokit.mapping.occupancy_grid.OccupancyGrid.empty": Call({"bounds": Array(np.array([0.0, -1.0, 2.0, 1.0]), "4"),
                                                                "resolution": Real(0.1)}),
    "robokit.mapping.occupancy_grid.OccupancyGrid.from_probability": Call({
        "P": Array(np.array([[0.0, 1.0], [0.5, 0.2]]), "N,N"),
        "resolution": Real(0.1), "origin": Array(np.zeros(2), "2")}),
    "robokit.mapping.occupancy_grid.likelihood_field": Call({"grid": Obj(small_grid), "occupied_threshold": Real(0.65),
                                                             "max_distance": Real(2.0)}),
    "robokit.mapping.grid_mapping.inverse_range_sensor_model": Call({
        "xy": Array(np.array([[0.5, 0.0], [0.0, 0.7]]), "N,2", min_rows=0), "pose": Array(np.zeros(3), "3"),
        "ranges": Array(np.array([1.0, np.inf, 3.0, 0.5]), "N", inf_ok=True),
        "angles": Array(np.arange(4) * np.pi / 2, "N"), **grid_model_kinds()}),
    "robokit.mapping.grid_mapping.update_log_odds": Call({
        "grid": Obj(small_grid), "pose": Array(np.array([0.1, 0.0, 0.3]), "3"),
        "ranges": Array(np.array([1.0, np.inf, 3.0, 0.5]), "N", inf_ok=True),
        "angles": Array(np.arange(4) * np.pi / 2, "N"), **grid_model_kinds(),
        "clamp": Array(np.array([-2.0, 3.5]), "2")}),
    "robokit.mapping.grid_mapping.occupancy_grid_mapping": Call(grid_mapping_kinds()),
    "robokit.mapping.grid_mapping.occupancy_grid_mapping_readable": Call(grid_mapping_kinds()),
    "robokit.mapping.map_server.save_map": Call({"grid": Obj(small_grid), "stem": Text(lambda: str(map_folder() / "m")),
                                                 "occupied_thresh": Real(0.65), "free_thresh": Real(0.196),
                                                 "negate": Int(0), "mode": Choice("trinary")}),
    # robokit.mapping.corridor_scan / corridor_areas, controllers.corridor_centering, mapping.hybrid_map (lesson 03)
    **{f"robokit.mapping.corridor_scan.{n}": Call({"ranges": Array(corridor_ranges, "N", inf_ok=True),
                                                    "angles": Array(corridor_angles, "N")} | extra)
       for n, extra in [("corridor_axis", {}), ("wall_distances", {"heading": Real(0.0, optional=True)}),
                        ("door_sides", {"heading": Real(0.0, optional=True), "recess": Real(0.07)}),
                        ("corridor_state", {"width": Real(2.17), "r_max": Real(8.0), "bounds": Choice("paper"),
                                            "recess": Real(0.07), "tol": Real(0.04), "width_tol": Real(0.03),
                                            "validate": Flag(True)})]},
    **{f"robokit.mapping.corridor_areas.{n}": Call({"ranges": Array(corridor_ranges, "N", inf_ok=True),
                                                     "angles": Array(corridor_angles, "N")} | extra)
       for n, extra in [("as_scan", {}), ("invalid_areas", {"validate": Flag(True)})]},
    "robokit.mapping.corridor_areas.theta_limits": Call({"width": Real(2.17), "r_max": Real(8.0)}),
    "robokit.mapping.corridor_areas.theta_limits_geometric": Call({"width": Real(2.17), "r_max": Real(8.0),
                                                                   "recess": Real(0.07)}),
    "robokit.mapping.corridor_scan.width_condition": Call({"d_l": Real(1.085), "d_r": Real(1.155), "width": Real(2.17),
                                                           "recess": Real(0.07), "tol": Real(0.03)}),
    "robokit.mapping.corridor_scan.middle_line_condition": Call({
        "d_l": Real(1.085), "d_r": Real(1.155), "tol": Real(0.04), "width": Real(2.17, optional=True),
        "recess": Real(0.07), "width_tol": Real(0.03), "door": Choice("right", optional=True)}),
    "robokit.controllers.corridor_centering.centering_command": Call({
        "lateral_offset": Real(0.3), "heading_error": Real(0.2), "lookahead": Real(0.15), "k_omega": Real(1.5),
        "k_v": Real(0.5), "v_min": Real(0.02), "v_max": Real(0.15), "w_max": Real(0.6), "deadband": Real(0.01)}),
    "robokit.controllers.corridor_centering.move_to_middle_line": Call({
        "world": Obj(corridor_world), "pose": Array(np.array([14.5, 0.05, 0.1]), "3"), "lidar": Obj(corridor_lidar),
        "rng": Rng(0), "tol": Real(0.04), "heading_tol": Real(0.035), "max_steps": Int(40), "dt": Real(0.1),
        "direction": Choice("nearest", optional=True), "width": Real(2.17, optional=True),
        "recess": Real(0.07, optional=True), "settle": Int(3)}, cheap=False),
    "robokit.mapping.hybrid_map.geo_tag": Call({"keyframe_times": Array(np.array([0.5, 1.5]), "N"),
                                                "pose_times": Array(np.array([0.0, 1.0, 2.0]), "N"),
                                                "poses": Array(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 3.0],
                                                                         [2.0, 0.0, -3.0]]), "N,3")}),
    "robokit.mapping.hybrid_map.geo_index": Call({"keyframe_ids": Array(np.array([3, 8]), "N"),
                                                  "keyframe_times": Array(np.array([0.5, 1.5]), "N"),
                                                  "pose_times": Array(np.array([0.0, 1.0, 2.0]), "N"),
                                                  "poses": Array(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 3.0],
                                                                           [2.0, 0.0, -3.0]]), "N,3")}),
    # --- robokit.vision.orb, hamming, keyframes, bag_of_words, bow_database (lesson 03) ------------
    "robokit.vision.orb.detect_orb_features": Call({"image": Array(image, "N,N|N,N,3|N,N,4"), "n_features": Int(100),
                                                    "scale_factor": Real(1.2), "n_levels": Int(4),
                                                    "fast_threshold": Int(20),
                                                    "mask": Array(image_mask, "N,N", optional=True,
                                                                  accepts=("booleans",))}),
    "robokit.vision.hamming.hamming_distance": Call({"a": Array(orb_descriptors, "...,32"),
                                                     "b": Array(lambda: orb_descriptors(40, 1), "...,32"),
                                                     "validate": Flag(True)}),
    "robokit.vision.hamming.hamming_distances": Call({"a": Array(orb_descriptors, "N,32", min_rows=0),
                                                      "b": Array(lambda: orb_descriptors(30, 1), "N,32", min_rows=0)}),
    "robokit.vision.hamming.hamming_match": Call({"query": Array(orb_descriptors, "N,32", min_rows=0),
                                                  "train": Array(lambda: orb_descriptors(30, 1), "N,32", min_rows=0),
                                                  "ratio": Real(0.75), "max_distance": Real(50.0, optional=True, inf_ok=True),
                                                  "cross_check": Flag(False)}),
    "robokit.vision.keyframes.feature_threshold": Call({"counts": Array(np.array([400.0, 380.0, 100.0]), "N")}),
    "robokit.vision.keyframes.shared_fraction": Call({"desc_current": Array(orb_descriptors, "N,32", min_rows=0),
                                                      "desc_keyframe": Array(lambda: orb_descriptors(30), "N,32",
                                                                             min_rows=0),
                                                      "max_distance": Real(50.0)}),
    "robokit.vision.keyframes.tracked_matches": Call({"current": Obj(orb_features), "keyframe": Obj(orb_features),
                                                      "window": Real(15.0), "max_distance": Real(100.0),
                                                      "scale_factor": Real(1.2), "check_orientation": Flag(True)}),
    "robokit.vision.keyframes.matched_points": Call({"keyframe": Obj(orb_features),
                                                     "previous": Obj(orb_features, optional=True),
                                                     "following": Obj(orb_features, optional=True)}),
    "robokit.vision.keyframes.tracked_fraction": Call({"current": Obj(orb_features), "keyframe": Obj(orb_features),
                                                       "points": Array(np.array([0, 1, 2]), "N", min_rows=0,
                                                                       optional=True),
                                                       "window": Real(15.0), "max_distance": Real(100.0),
                                                       "scale_factor": Real(1.2), "check_orientation": Flag(True)}),
    "robokit.vision.keyframes.KeyframeSelector": Call({"f_min": Real(100.0), "min_frame_gap": Int(10),
                                                       "shared_range": Array(np.array([0.7, 0.9]), "2"),
                                                       "min_distance": Real(0.02), "max_distance": Real(50.0),
                                                       "matching": Choice("mutual"), "below_band": Choice("skip")}),
    "robokit.vision.keyframes.select_keyframes": Call({
        "descriptor_list": Obj(lambda: [orb_descriptors(40, 0)] * 3), "positions": Array(np.zeros((3, 2)), "N,2|N,3"),
        "f_min": Real(10.0), "kw": Options({"min_frame_gap": 1})}),
    "robokit.vision.keyframes.select_keyframes_orbslam": Call({
        "descriptor_list": Obj(lambda: [orb_descriptors(40, 0)] * 3),
        "positions": Array(np.zeros((3, 2)), "N,2|N,3", optional=True), "min_frame_gap": Int(1),
        "min_tracked": Int(10), "max_tracked_fraction": Real(0.9), "max_distance": Real(50.0),
        "matching": Choice("mutual")}),
    "robokit.vision.bag_of_words.tf_idf": Call({"word_ids": Array(np.array([0, 0, 1, 2]), "N", min_rows=0),
                                                "idf": Array(np.log2([3.0, 3.0, 1.5, 1.0]), "N")}),
    "robokit.vision.bag_of_words.l1_score": Call({"v_a": Obj(([0, 2], [0.5, 0.5])), "v_b": Obj(([0, 3], [0.2, 0.8]))}),
    "robokit.vision.bag_of_words.Vocabulary": Call({
        "children": Array(lambda: bow_vocabulary().children, "N,N"), "centres": Array(lambda: bow_vocabulary().centres, "N,N"),
        "idf": Array(lambda: bow_vocabulary().idf, "N"), "levels": Int(2)}),
    "robokit.vision.bag_of_words.Vocabulary.train": Call({
        "descriptors": Obj(lambda: [orb_descriptors(30, 0), orb_descriptors(30, 1)]), "branching": Int(3),
        "levels": Int(2), "iterations": Int(5), "rng": Rng(0)}),
    "robokit.vision.bow_database.BowDatabase": Call({"vocabulary": Obj(bow_vocabulary)}),
    # --- lesson 03: the assignment's plain-data references, the experiments, clusters, animation ---
    "robocourse.lessons.corridor_localization.exercises.cell_log_odds": Call({
        "probabilities": Array(np.array([0.7, 0.7, 0.4]), "N", min_rows=0), "prior": Real(0.5)}),
    "robocourse.lessons.corridor_localization.exercises.bow_similarity": Call({
        "words_a": Array(np.array([0, 1, 1]), "N", min_rows=0), "words_b": Array(np.array([1, 2]), "N", min_rows=0),
        "idf": Array(np.array([1.0, 1.0, 1.0]), "N")}),
    "robocourse.lessons.corridor_localization.exercises.likelihood_field_weight": Call({
        "pose": Array(np.array([0.55, 1.0, 0.0]), "3"), "ranges": Array(np.array([1.0, 0.8]), "N", inf_ok=True),
        "angles": Array(np.array([0.0, 1.5]), "N"), "distance": Array(distance_grid, "N,N"), "resolution": Real(0.1),
        "origin": Array(np.array([0.0, 0.0]), "2"), "sigma_hit": Real(0.2), "z_hit": Real(0.95), "z_rand": Real(0.05),
        "r_max": Real(8.0), "max_distance": Real(2.0)}),
    "robocourse.lessons.corridor_localization.exercises.mcl_track": Call({"run": Mapping(mcl_run)}),
    "robocourse.lessons.corridor_localization.exercises.resample_indices": Call({
        "weights": Array(np.array([0.1, 0.6, 0.3]), "N"), "r": Real(0.2)}),
    "robocourse.lessons.corridor_localization.exercises.ellipse_start_weights": Call({
        "points": Array(np.array([[0.0, 0.0], [1.0, 0.0]]), "N,2"), "centre": Array(np.array([0.0, 0.0]), "2"),
        "sigma_x": Real(1.0), "sigma_y": Real(1.0)}),
    "robocourse.lessons.corridor_localization.exercises.recognise_keyframe": Call({
        "query": Array(lambda: orb_descriptors(40, 2)[:10], "N,32"),
        "keyframes": Obj(lambda: [orb_descriptors(40, 1), orb_descriptors(40, 2)])}),
    # --- lesson 05: the open exercise's reference ---
    "robocourse.lessons.gps_sonar_truck.exercises.local_offset": Call({
        "origin": Array(np.array([6.45, 100.35]), "2"), "point": Array(np.array([6.46, 100.36]), "2")}),
    "robocourse.lessons.gps_sonar_truck.loop.drive_course": Call({
        "course": Mapping(lambda: truck_course()), "front": Real(1.2), "side": Real(0.8)}, cheap=False),
    "robocourse.lessons.gps_sonar_truck.exercises.compass_bias": Call({
        "fixes": Array(np.array([[0.0, 0.0], [0.7, 0.1], [1.4, 0.0]]), "N,2"),
        "compass_deg": Array(np.array([91.0, 92.0, 91.0]), "N")}),
    "robokit.localization.particle_clusters.pose_clusters": Call({
        "particles": Array(np.array([[0.1, 0.1, 0.0], [0.6, 0.1, 0.0], [5.0, 0.0, 0.0]]), "N,3"),
        "bin_size": Array(np.array([0.5, 0.5, 0.17]), "3")}),
    "robokit.localization.particle_clusters.largest_cluster_share": Call({
        "particles": Array(np.array([[0.1, 0.1, 0.0], [0.6, 0.1, 0.0], [5.0, 0.0, 0.0]]), "N,3"),
        "weights": Array(np.array([0.1, 0.1, 0.8]), "N", optional=True),
        "bin_size": Array(np.array([0.5, 0.5, 0.17]), "3"),
        "labels": Array(np.array([0, 0, 1]), "N", optional=True)}),
    "robokit.localization.particle_clusters.largest_cluster_mean": Call({
        "particles": Array(np.array([[10.0, 0.0, 0.0], [10.2, 0.0, 0.0], [30.0, 0.0, 0.0]]), "N,3"),
        "weights": Array(np.array([0.4, 0.4, 0.2]), "N", optional=True),
        "bin_size": Array(np.array([0.5, 0.5, 0.17]), "3"),
        "labels": Array(np.array([0, 0, 1]), "N", optional=True)}),
    "robocourse.lessons.corridor_localization.trials.corridor_localizer": Call({
        "setup": Obj(corridor_setup), "method": Choice("ours"), "rng": Rng(0), "amcl": Choice("turtlebot2")},
        cheap=False),
    "robocourse.lessons.corridor_localization.aliasing.aliasing_example": Call({"resolution": Real(0.5)}, cheap=False),
    "robocourse.lessons.corridor_localization.orb_realism.move_image": Call({
        "image": Array(image, "N,N|N,N,3|N,N,4"), "shift_x": Real(1.0), "shift_y": Real(0.0), "zoom": Real(1.01)}),
    "robocourse.lessons.corridor_localization.orb_realism.motion_shares": Call({
        "images": Mapping(lambda: {"photo": image()}), "motions": Mapping({"1 px": (1.0, 0.0, 1.0)}, optional=True),
        "n_features": Int(500), "matching": Choice("mutual")}),
    "robocourse.lessons.corridor_localization.orb_realism.feature_counts": Call({
        "spacing": Real(5.0), "section": Array(np.array([10.0, 20.0]), "2")}, cheap=False),
    "robocourse.lessons.corridor_localization.experiment.corridor_lidar": Call({}),
    "robocourse.lessons.corridor_localization.experiment.corridor_camera": Call({}),
    "robocourse.lessons.corridor_localization.experiment.calibration_run": Call({
        "fast": Flag(True, optional=True), "start": Real(12.0), "length": Real(10.0), "speed": Real(0.2),
        "frame_rate": Real(30.0), "progress": Func(None, optional=True)}, cheap=False),
    "robocourse.lessons.corridor_localization.experiment.keyframe_comparison": Call({
        "run": Obj(corridor_calibration), "min_frame_gap": Int(10), "shared_range": Array(np.array([0.7, 0.9]), "2"),
        "below_band": Choice("take"), "matching": Choice("mutual")}, cheap=False),
    "robocourse.lessons.corridor_localization.experiment.corridor_map": Call({
        "fast": Flag(True, optional=True), "resolution": Real(0.05), "clutter": Real(0.0),
        "progress": Func(None, optional=True)}, cheap=False),
    "robocourse.lessons.corridor_localization.trials.refine_pose": Call({
        "setup": Obj(corridor_setup), "pose": Array(np.array([12.03, 0.04, 0.02]), "3"),
        "scan": Array(lambda: np.full(360, 1.5), "360", inf_ok=True)}, cheap=False),
    "robocourse.lessons.corridor_localization.trials.retrieve_pose": Call({
        "setup": Obj(corridor_setup), "pose": Array(np.array([10.0, 0.0, 0.0]), "3"), "rng": Rng(0)}, cheap=False),
    "robocourse.lessons.corridor_localization.trials.localization_trial": Call({
        "setup": Obj(corridor_setup), "start": Array(np.array([12.0, 0.3, 0.4]), "3"), "method": Choice("ours"),
        "rng": Rng(1), "max_distance": Real(3.0), "share": Real(0.95), "sigma_x": Real(0.3), "sigma_y": Real(0.1),
        "settle": Int(1), "keep_particles": Flag(False), "amcl": Choice("defaults")}, cheap=False),
    "robocourse.lessons.corridor_localization.trials.localization_trials": Call({
        "setup": Obj(corridor_setup), "method": Choice("ours"), "trials": Int(1, optional=True),
        "positions": Given([0]), "seed": Int(0), "max_distance": Real(3.0), "amcl": Choice("defaults"),
        "cache": Flag(False), "progress": Func(None, optional=True), "workers": Int(1, optional=True)}, cheap=False),
    "robocourse.lessons.corridor_localization.real_map.willow_map": Call({}),
    "robocourse.lessons.corridor_localization.real_map.willow_section": Call({"name": Choice("rooms")}),
    "robocourse.lessons.corridor_localization.real_map.building_routes": Call({
        "grid": Obj(willow_section), "n": Int(1), "length": Real(3.0), "rng": Rng(0), "clearance": Real(0.35)},
        cheap=False),
    "robocourse.lessons.corridor_localization.real_map.global_localization_runs": Call({
        "grid": Obj(willow_section), "walls": Obj(willow_walls), "drives": Given(willow_drives), "particles": Int(200),
        "settings": Choice("defaults"), "seed": Int(0), "workers": Int(1, optional=True),
        "progress": Func(None, optional=True)}, cheap=False),
    "robokit.config.pad_heap": Call({"environ": Mapping({"ROBOKIT_HEAP_PAD_MB": "0"}, optional=True)}),
    "robocourse.lessons.corridor_localization.real_map.global_localization_batch": Call({
        "groups": Given(willow_groups), "workers": Int(1, optional=True), "progress": Func(None, optional=True)},
        cheap=False),
    "robocourse.lessons.corridor_localization.experiment.clutter_map": Call({
        "clutter": Real(0.5), "resolution": Real(0.1)}, cheap=False),
    "robocourse.lessons.corridor_localization.repetition.clutter_comparison": Call({
        "shares": Array(np.array([1.0]), "N", optional=True), "settings": Given(["defaults"]), "runs": Int(1, optional=True),
        "positions": Given([0]),
        "length": Real(1.0, optional=True), "seed": Int(0), "cache": Flag(False),
        "progress": Func(None, optional=True)}, cheap=False),
    "robocourse.lessons.corridor_localization.trials.amcl_localizer": Call({
        "grid": Obj(willow_section), "field": Obj(None, optional=True), "lidar": Obj(corridor_lidar),
        "settings": Choice("turtlebot2"), "particles": Int(600, optional=True), "rng": Rng(0)}),
    "robocourse.lessons.corridor_localization.experiment.mapping_grid": Call({
        "world": Obj(corridor_world), "lidar": Obj(corridor_lidar), "poses": Array(np.array([[5.0, 0.0, 0.0]]), "N,3"),
        "resolution": Real(0.1)}, cheap=False),
    "robocourse.lessons.corridor_localization.real_map.real_map_comparison": Call({
        "setup": Obj(corridor_setup), "runs": Int(1, optional=True), "length": Real(1.0, optional=True), "seed": Int(0),
        "cache": Flag(False), "progress": Func(None, optional=True)}, cheap=False),
    "robokit.sim.layout.Layout.from_cells": Call({
        # a boolean mask (Array's cases are numeric): its bad values are in test_sim_layout
        "occupied": Given(np.array([[True, False], [False, True]])), "resolution": Real(0.1),
        "origin": Array(np.zeros(2), "2")}),
    "robocourse.lessons.corridor_localization.kidnapping.kidnapping": Call({
        "setup": Obj(corridor_setup), "origin": Int(0), "destination": Int(2), "period": Real(5.0), "after": Real(3.0),
        "kidnap_distance": Real(1.0), "confirm": Int(2), "seed": Int(0)}, cheap=False),
    "robokit.viz.animation.animate_snapshots": Call({
        "scene": Obj(snapshot_scene), "paths": Given(["a", "b"]), "fps": Real(4.0), "repetitions": Int(1),
        "moving": Text("robot", optional=True),
        "transforms": Array(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), "N,3|N,4,4", optional=True)}),
    "robokit.viz.maps.plot_occupancy": Call({
        "grid": Array(np.array([[0.0, 1.0], [0.5, 0.2]]), "N,N"), "origin": Array(np.array([0.0, 0.0]), "2"),
        "resolution": Real(0.5), "ax": Given(axes), "cmap": Text("gray_r"), "colorbar": Flag(False)}),
    "robokit.viz.scene3d.add_particles": Call({
        "scene": Obj(scene), "path": Text("cloud"),
        "particles": Array(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.5]]), "N,3"),
        "weights": Array(np.array([0.5, 0.5]), "N", optional=True), "z": Real(0.03), "arrow": Real(0.15),
        "color": Given(0xAA2288), "size": Real(0.04)}),
    # --- robokit.geometry.procrustes / spatial.fit_se3, robokit.legged sensing (lesson 04) -----------
    "robokit.geometry.procrustes.fit_rigid": Call({
        "source": Array(lambda: points(6), "N,2|N,3|N,N,2|N,N,3"),
        "target": Array(lambda: points(6) @ np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]).T + 1.0,
                        "N,2|N,3|N,N,2|N,N,3"),
        "weights": Array(np.ones(6), "N|N,N", optional=True), "validate": Flag(True)}),
    "robokit.geometry.procrustes.fit_se3": Call({
        "source": Array(lambda: points(6), "N,3|N,N,3"), "target": Array(lambda: points(6) + 1.0, "N,3|N,N,3"),
        "weights": Array(np.ones(6), "N|N,N", optional=True)}),
    "robokit.legged.mocap.simulate_mocap": Call({
        "T_world_body": Array(sensing_T, "N,4,4|4,4"), "markers_body": Array(sensing_markers, "N,3|3"),
        "noise": Real(0.001), "dropout": Real(0.1), "rng": Rng(0), "bursts": Real(0.1), "burst_length": Int(2)}),
    "robokit.legged.mocap.fit_marker_pose": Call({
        "markers_body": Array(sensing_markers, "N,3|3"), "observed": Array(lambda: sensing_frames().positions[0], "N,3"),
        "visible": Array(np.ones(4, bool), "N", optional=True, accepts=("booleans",))}),
    "robokit.legged.mocap.mocap_body_poses": Call({
        "markers_body": Array(sensing_markers, "N,3|3"), "observed": Array(lambda: sensing_frames().positions, "N,N,3"),
        "visible": Array(lambda: sensing_frames().visible, "N,N", accepts=("booleans",))}),
    "robokit.legged.imu.simulate_imu": Call({
        "omega_body": Array(np.tile([0.0, 0.1, 0.3], (5, 1)), "N,3"),
        "specific_force_body": Array(np.tile([0.0, 0.0, 9.81], (5, 1)), "N,3"), "rng": Rng(0),
        "gyro_noise": Real(0.005), "acc_noise": Real(0.05), "gyro_bias": Array(np.array([0.02, 0.0, 0.0]), "3"),
        "acc_bias": Array(np.array([0.1, 0.0, 0.0]), "3")}),
    "robokit.legged.imu.integrate_gyro": Call({
        "R0": Array(np.eye(3), "3,3"), "gyro": Array(np.tile([0.0, 0.1, 0.3], (5, 1)), "N,3"), "dt": Real(0.01)}),
    "robokit.legged.imu.specific_force": Call({
        "acc_world": Array(np.array([[0.1, 0.0, 0.0], [0.0, 0.2, 0.0]]), "N,3"),
        "R_world_body": Array(lambda: sensing_T(2)[:, :3, :3], "N,3,3"), "g": Real(9.81)}),
    "robokit.legged.state_estimation.fuse_body_state": Call({
        "gyro": Array(np.tile([0.0, 0.0, 0.05], (5, 1)), "N,3"), "acc": Array(np.tile([0.0, 0.0, 9.81], (5, 1)), "N,3"),
        "dt": Real(0.01), "T_mocap": Array(sensing_T, "N,4,4"),
        "mocap_ok": Array(np.array([True, False, True, True, True]), "N", accepts=("booleans",)),
        "k_p": Real(2.0), "k_i": Real(0.5), "sigma_acc": Real(0.5), "sigma_mocap": Real(0.001),
        "R0": Array(np.eye(3), "3,3", optional=True), "p0": Array(np.array([0.0, 0.0, 0.13]), "3", optional=True),
        "g": Real(9.81)}),
    "robokit.legged.state_estimation.orientation_errors": Call({
        "R_est": Array(lambda: sensing_T(3)[:, :3, :3], "N,3,3|3,3"),
        "R_true": Array(lambda: sensing_T(3)[::-1, :3, :3], "N,3,3|3,3")}),
    "robokit.legged.state_estimation.position_errors": Call({
        "p_est": Array(np.array([[0.0, 0.0, 0.13], [0.1, 0.0, 0.13]]), "N,3"),
        "p_true": Array(np.array([[0.0, 0.01, 0.13], [0.1, 0.0, 0.12]]), "N,3")}),
    "robokit.legged.touchdown.detect_contacts": Call({
        "force": Array(np.array([0.0, 4.0, 6.0, 1.0, 6.0, 0.5]), "N|N,N", min_rows=0), "threshold_on": Real(3.0),
        "threshold_off": Real(1.0), "debounce": Int(2)}),
    "robokit.legged.touchdown.contact_events": Call({
        "contact": Array(walk_contacts, "N|N,N", min_rows=0, accepts=("booleans",))}),
    "robokit.legged.touchdown.event_precision_recall": Call({
        "detected": Array(lambda: np.roll(walk_contacts(), 1), "N|N,N", accepts=("booleans",)),
        "truth": Array(walk_contacts, "N|N,N", accepts=("booleans",)), "tolerance": Int(2)}),
    # --- robokit.legged.support, gait_schedule, gait (lesson 04's gaits) ----------------------------
    "robokit.legged.support.support_polygon": Call({"feet_xy": Array(lambda: unit_square(), "N,2")}),
    "robokit.legged.support.stability_margin": Call({"feet_xy": Array(lambda: unit_square(), "N,2"),
                                                     "com_xy": Array(np.array([0.5, 0.4]), "2")}),
    "robokit.legged.support.stability_margins": Call({
        "feet_xy": Array(lambda: np.stack([unit_square()] * 3), "N,N,2"),
        "stance": Array(np.array([[1, 1, 1, 1], [1, 1, 1, 0], [1, 0, 1, 0]], bool), "N,N", accepts=("booleans",)),
        "com_xy": Array(np.array([[0.5, 0.5], [0.6, 0.5], [0.5, 0.5]]), "N,2")}),
    "robokit.legged.gait_schedule.GaitSchedule": Call({
        "name": Text("crawl"), "period": Real(4.0), "duty_factor": Real(0.9),
        "phase_offsets": Array(np.array([0.25, 0.75, 0.0, 0.5]), "4"), "step_length": Real(0.08),
        "step_height": Real(0.03)}),
    "robokit.legged.gait_schedule.crawl_gait": Call({"period": Real(4.0), "step_length": Real(0.08),
                                                     "step_height": Real(0.03), "duty_factor": Real(0.9)}),
    "robokit.legged.gait_schedule.trot_gait": Call({"period": Real(0.5), "step_length": Real(0.06),
                                                    "step_height": Real(0.03), "duty_factor": Real(0.5)}),
    "robokit.legged.gait_schedule.as_gait_schedule": Call({"schedule": Obj(lambda: gait("crawl"))}),
    "robokit.legged.gait_schedule.stance_pattern": Call({"schedule": Obj(lambda: gait("trot")),
                                                         "t": Array(np.array([0.0, 0.3, 7.1]), "N|", min_rows=0)}),
    "robokit.legged.gait.swing_trajectory": Call({
        "p_start": Array(np.array([0.0, 0.08, 0.01]), "3|N,3"), "p_end": Array(np.array([0.08, 0.08, 0.01]), "3|N,3"),
        "phase": Array(np.array([0.0, 0.5, 1.0]), "N|", min_rows=0), "height": Real(0.03)}),
    "robokit.legged.gait.walking_plan": Call({
        "schedule": Obj(lambda: gait("crawl")), "distance": Real(0.1),
        "nominal_feet": Array(lambda: np.array([[0.16, 0.08, -0.1215], [0.16, -0.08, -0.1215],
                                                [-0.16, 0.08, -0.1215], [-0.16, -0.08, -0.1215]]), "4,3",
                              optional=True),
        "body_height": Real(0.1315), "dt": Real(0.01), "settle": Real(0.5), "margin": Real(0.02),
        "terrain": Obj(step_board, optional=True), "clearance": Real(0.025)}),
    # --- robokit.legged.terrain (lesson 04's terrain boards) -----------------------------------------
    "robokit.legged.terrain.Terrain": Call({
        "blocks": Array(np.array([[0.3, 0.5, -0.3, 0.3, 0.02]]), "N,5", min_rows=0),
        "markers": Array(np.array([[0.3, -0.3, 0.02], [0.3, 0.3, 0.02], [0.5, 0.0, 0.02]]), "N,3", min_rows=0),
        "pose": Array(np.array([0.1, 0.0, 0.05]), "3")}),
    "robokit.legged.terrain.height_at": Call({
        "terrain": Obj(step_board), "xy": Array(np.array([[0.0, 0.0], [0.4, 0.1], [0.6, 0.0]]), "...,2")}),
    "robokit.legged.terrain.edge_distance": Call({
        "terrain": Obj(step_board), "xy": Array(np.array([[0.0, 0.0], [0.4, 0.1], [0.6, 0.0]]), "...,2")}),
    "robokit.legged.terrain.step_terrain": Call({
        "rng": Rng(0), "start": Real(0.3), "length": Real(1.0), "heights": Array(np.array([0.01, 0.04]), "2"),
        "width": Real(0.6)}),
    "robokit.legged.terrain.locate_terrain": Call({
        "terrain": Obj(step_board), "observed": Array(board_markers_seen, "N,3|N,N,3"),
        "visible": Array(np.ones(4, bool), "N|N,N", optional=True, accepts=("booleans",))}),
    "robokit.legged.terrain.terrain_transform": Call({"terrain": Obj(step_board)}),
    # --- lesson 04's loops: controllers.servo_loop, dc_motor, joint_servo, host_link; legged.power ---
    "robokit.controllers.servo_loop.servo_plant": Call({"tau": Real(0.3), "gain": Real(1.0)}),
    "robokit.controllers.servo_loop.servo_closed_loop": Call({"kp": Real(2.0), "kd": Real(0.1), "tau": Real(0.3),
                                                              "gain": Real(1.0)}),
    "robokit.controllers.servo_loop.servo_loop_gain": Call({"kp": Real(2.0), "kd": Real(0.1), "tau": Real(0.3),
                                                            "gain": Real(1.0)}),
    "robokit.controllers.servo_loop.servo_step_response": Call({"kp": Real(2.0), "kd": Real(0.1), "tau": Real(0.3),
                                                                "gain": Real(1.0), "duration": Real(2.0), "n": Int(50)}),
    "robokit.controllers.servo_loop.servo_frequency_response": Call({
        "kp": Real(2.0), "kd": Real(0.1), "tau": Real(0.3), "omega": Array(np.array([0.1, 1.0, 10.0]), "N|"),
        "gain": Real(1.0)}),
    "robokit.controllers.servo_loop.discrete_servo_loop": Call({"kp": Real(96.0), "kd": Real(0.42), "tau": Real(0.011),
                                                                "rate_hz": Real(500.0), "gain": Real(0.98)}),
    "robokit.controllers.servo_loop.discrete_servo_analysis": Call({
        "kp": Real(96.0), "kd": Real(0.42), "tau": Real(0.011), "rate_hz": Real(500.0), "gain": Real(0.98),
        "duration": Real(0.1)}),
    "robokit.controllers.dc_motor.DCMotor": Call({
        "resistance": Real(3.0), "torque_constant": Real(0.0125), "back_emf_constant": Real(0.0125),
        "gear_ratio": Real(80.0), "efficiency": Real(0.75), "rotor_inertia": Real(4e-7), "viscous_friction": Real(0.005),
        "voltage_max": Real(14.8), "continuous_current": Real(1.2, inf_ok=True)}),
    **{f"robokit.controllers.dc_motor.{n}": Call({
        first: Array(np.array([1.0, -2.0, 20.0]), "*"), "joint_velocity": Array(np.array([0.5, 0.0, -3.0]), "*"),
        "motor": Obj(littledog_motor)} | ({"validate": Flag(True)} if n == "motor_current" else {}))
       for n, first in (("joint_torque", "voltage"), ("motor_current", "voltage"), ("electrical_power", "voltage"),
                        ("voltage_for_torque", "torque"))},
    "robokit.controllers.dc_motor.reflected_inertia": Call({"motor": Obj(littledog_motor)}),
    "robokit.controllers.joint_servo.joint_lag": Call({"motor": Obj(littledog_motor), "inertia": Real(2.76e-3)}),
    "robokit.controllers.joint_servo.joint_plant": Call({"motor": Obj(littledog_motor), "inertia": Real(2.76e-3)}),
    "robokit.controllers.joint_servo.design_servo_gains": Call({
        "motor": Obj(littledog_motor), "inertia": Real(2.76e-3), "bandwidth_hz": Real(15.0), "damping": Real(0.7)}),
    "robokit.controllers.joint_servo.servo_analysis": Call({
        "kp": Real(96.0), "kd": Real(0.42), "motor": Obj(littledog_motor), "inertia": Real(2.76e-3),
        "rate_hz": Real(500.0), "duration": Real(0.1)}),
    "robokit.controllers.joint_servo.pd_servo_step": Call({
        "q_ref": Array(np.array([0.1, 0.2, -0.3]), "|3"), "q": Array(np.array([0.0, 0.25, -0.3]), "3"),
        "q_prev": Array(np.array([0.0, 0.24, -0.31]), "3"), "kp": Array(np.array([96.0, 90.0, 80.0]), "|3"),
        "kd": Array(np.array(0.42), "|3"), "dt": Real(0.002), "voltage_max": Real(14.8), "validate": Flag(True)}),
    "robokit.controllers.joint_servo.discrete_servo_response": Call({
        "kp": Real(96.0), "kd": Real(0.42), "motor": Obj(littledog_motor), "inertia": Real(2.76e-3),
        "rate_hz": Real(500.0), "steps": Int(50), "q_ref": Real(0.1), "saturate": Flag(True)}),
    "robokit.controllers.host_link.SetpointChannel": Call({
        "period": Real(0.01), "latency": Real(0.004), "jitter": Real(0.002), "loss": Real(0.1), "rng": Rng(0)}),
    "robokit.legged.power.battery_energy": Call({"capacity_ah": Real(2.1), "voltage": Real(14.8)}),
    "robokit.legged.power.trial_power": Call({
        "voltage": Array(np.array([[1.6, 10.0, 2.0], [0.0, -3.0, 14.8]]), "N,N"),
        "joint_velocity": Array(np.array([[0.0, 5.0, 5.0], [1.0, -2.0, 0.0]]), "N,N"),
        "motor": Obj(littledog_motor), "regenerative": Flag(False)}),
    "robokit.legged.power.endurance": Call({"energy_j": Real(111888.0), "mean_power_w": Real(62.0)}),
    "robokit.legged.power.cost_of_transport": Call({"energy_j": Real(620.0), "mass": Real(3.0), "distance": Real(1.0),
                                                     "g": Real(9.81)}),
    # --- lesson 04: robokit.legged.trial_log, viz.legged, viz.legged_plots, viz.animation.animate_tracks ---
    "robokit.geometry.rotations.quat_to_matrix": Call({"quat": Array(np.array([0.9, 0.1, -0.2, 0.3]), "...,4"),
                                                       "validate": Flag(True)}),
    "robokit.legged.trial_log.TrialLog": Call({"streams": Mapping(trial_streams), "meta": Mapping(trial_meta_dict)}),
    "robokit.legged.trial_log.trial_meta": Call({
        "gait": Text("crawl"), "host_rate": Real(100.0), "servo_rate": Real(500.0), "physics_timestep": Real(0.001),
        "link_latency": Real(0.01), "link_jitter": Real(0.002), "link_loss": Real(0.01), "seed": Int(0, optional=True),
        "notes": Text(""), "extra": Given({})}),
    "robokit.legged.trial_log.empty_streams": Call({"n": Int(4), "host_rate": Real(100.0)}),
    "robokit.legged.trial_log.save_trial": Call({"path": Text(lambda: str(trial_folder() / "t.npz")),
                                                 "log": Obj(trial_log)}),
    "robokit.legged.trial_log.describe_layout": Call({}),
    "robokit.viz.animation.animate_tracks": Call({
        "scene": Obj(scene), "tracks": Mapping(lambda: {"a": {"position": np.zeros((3, 3)), "scale": np.ones((3, 3))}}),
        "fps": Real(10.0), "repetitions": Int(1), "validate": Flag(True)}),
    "robokit.viz.legged.add_terrain": Call({"scene": Obj(scene), "terrain": Obj(step_board), "path": Text("terrain")}),
    "robokit.viz.legged.joint_path": Call({"path": Text("littledog"), "leg": Choice("HL"), "joint": Choice("knee")}),
    "robokit.viz.legged.add_littledog": Call({"scene": Obj(scene), "path": Text("littledog"),
                                              "T_world_body": T_(lambda: np.eye(4), optional=True),
                                              "q": Array(stance_q, "12", optional=True)}),
    "robokit.viz.legged.pose_littledog": Call({"scene": Obj(scene), "path": Text("littledog"),
                                               "T_world_body": T_(lambda: np.eye(4)), "q": Array(stance_q, "12")}),
    "robokit.viz.legged.animate_trial": Call({
        "scene": Obj(scene), "log": Obj(trial_log), "path": Text("littledog"), "every": Int(2),
        "fps": Real(50.0, optional=True), "support": Flag(True), "com": Flag(True), "forces": Flag(True),
        "mocap": Flag(False), "force_scale": Real(0.004), "frame": Flag(True)}),
    "robokit.viz.legged_plots.support_outline": Call({
        "feet_xy": Array(np.array([[0.16, 0.08], [0.16, -0.08], [-0.16, 0.08], [-0.16, -0.08]]), "N,2", min_rows=0)}),
    "robokit.viz.legged_plots.plot_gait_diagram": Call({
        "t": Array(np.arange(4) * 0.01, "N"), "stance": Array(np.eye(4, dtype=bool) == 0, "N,4", accepts=("booleans",)),
        "ax": Given(axes), "legs": Given(("FL", "FR", "HL", "HR"))}),
    "robokit.viz.legged_plots.plot_joint_tracking": Call({"log": Obj(trial_log), "joints": Given(["FL_knee", 3]),
                                                          "ax": Given(axes)}),
    "robokit.viz.legged_plots.plot_foot_forces": Call({
        "log": Obj(trial_log), "ax": Given(axes),
        "detected": Array(lambda: trial_log().foot_force > 3.0, "N,4", optional=True, accepts=("booleans",)),
        "legs": Given(["HR"])}),
    "robokit.viz.legged_plots.plot_support": Call({
        "feet_xy": Array(np.array([[0.16, 0.08], [0.16, -0.08], [-0.16, 0.08], [-0.16, -0.08]]), "N,2|N,3"),
        "stance": Array(np.array([True, True, True, False]), "N", accepts=("booleans",)),
        "com_xy": Array(np.array([0.01, 0.0]), "2|3"), "ax": Given(axes), "legs": Given(("FL", "FR", "HL", "HR"))}),
    # --- assignment 04: robocourse.lessons.littledog.exercises, its data (lessons.littledog.data), touchdown scores
    #     and the leg kinematics its exercises answer with -------------------------------------------------
    "robokit.legged.leg_kinematics.foot_position": Call({
        "q_leg": Array(np.array([0.1, 0.6, -1.2]), "...,3"), "leg": Choice("FL")}),
    "robokit.legged.leg_kinematics.leg_ik": Call({
        "p_foot": Array(np.array([0.12, 0.07, -0.11]), "3"), "leg": Choice("FL"),
        "branch": Int(-1, optional=True, accepts=("a list",))}),
    "robokit.legged.touchdown.score_events": Call({
        "detected": Array(np.array([3, 5, 8]), "N", min_rows=0), "truth": Array(np.array([2, 8]), "N", min_rows=0),
        "tolerance": Int(2)}),
    "robocourse.lessons.littledog.data.model_facts": Call({}),
    "robocourse.lessons.littledog.data.crawl_touchdowns": Call({
        "gait": Mapping({"period": 2.4, "duty_factor": 0.92}, optional=True), "distance": Real(0.05),
        "latency": Real(0.02), "force_noise": Real(0.1), "seed": Int(0)}, cheap=False),
    "robocourse.lessons.littledog.data.mocap_frames": Call({"seed": Int(0), "n": Int(5), "noise": Real(0.001)}),
    "robocourse.lessons.littledog.exercises.battery_endurance": Call({
        "capacity_ah": Real(2.1), "voltage": Real(14.8), "mean_power_w": Real(62.0)}),
    "robocourse.lessons.littledog.exercises.detect_touchdowns": Call({
        "force": Array(lambda: np.column_stack([[9, 9, 0, 0, 0, 0, 0, 9, 9, 0.5, 9, 9]] + [np.full(12, 9.0)] * 3),
                       "N,4", min_rows=0),
        "planned_stance": Array(lambda: np.arange(12)[:, None] % 6 != np.array([2, 3, 4, 5]), "N,4", min_rows=0,
                                accepts=("booleans",)),
        "dt": Real(0.01)}),
    "robokit.legged.touchdown.score_leg_events": Call({
        "detected": Given([[3, 5, 8], [10]]), "truth": Given([[2, 8], [30]]), "tolerance": Int(2)}),
    # --- lesson 04: leg kinematics and statics, the MuJoCo model, the servo design (robokit.legged.leg_kinematics,
    #     littledog, servo_design) -------------------------------------------------------------------
    "robokit.legged.leg_kinematics.leg_points": Call({
        "q_leg": Array(np.array([0.1, 0.6, -1.2]), "...,3"), "leg": Choice("HR")}),
    "robokit.legged.leg_kinematics.foot_jacobian": Call({
        "q_leg": Array(np.array([0.1, 0.6, -1.2]), "...,3"), "leg": Choice("FL")}),
    "robokit.legged.leg_kinematics.leg_ik_batch": Call({
        "p_foot": Array(np.array([[0.12, 0.07, -0.11], [0.10, 0.06, -0.12]]), "N,3|3"), "leg": Choice("FL"),
        "branch": Int(-1, optional=True)}),
    "robokit.legged.leg_kinematics.within_limits": Call({
        "q": Array(np.array([0.0, 0.5, -1.5]), "...,3"), "leg": Choice("FL", optional=True)}),
    "robokit.legged.leg_kinematics.reachable_workspace": Call({
        "leg": Choice("FL"), "n": Int(200), "rng": Rng(0), "branch": Int(-1, optional=True, accepts=("a list",))}),
    "robokit.legged.leg_kinematics.torques_from_foot_force": Call({
        "q_leg": Array(np.array([0.0, 0.6, -1.2]), "...,3"), "force": Array(np.array([0.0, 0.0, -7.4]), "...,3"),
        "leg": Choice("FL")}),
    "robokit.legged.leg_kinematics.foot_force_from_torques": Call({
        "q_leg": Array(np.array([0.0, 0.6, -1.2]), "...,3"), "tau": Array(np.array([-0.175, 0.112, 0.426]), "...,3"),
        "leg": Choice("FL"), "gravity_torque": Array(np.array([0.0, 0.01, 0.02]), "...,3", optional=True)}),
    "robokit.legged.leg_kinematics.body_fk": Call({"q": Array(stance_q, "...,12")}),
    "robokit.legged.leg_kinematics.body_ik": Call({
        "feet": Array(lambda: np.array([[0.16, 0.08, -0.1215], [0.16, -0.08, -0.1215],
                                        [-0.16, 0.08, -0.1215], [-0.16, -0.08, -0.1215]]), "N,4,3|4,3"),
        "T_world_body": T_(lambda: np.eye(4), optional=True), "validate": Flag(True)}),
    "robokit.legged.littledog.littledog_mjcf": Call({
        "armature": Real(0.0), "damping": Real(0.0), "friction": Real(1.0), "timestep": Real(0.001),
        "motor": Obj(littledog_motor, optional=True), "terrain": Obj(step_board, optional=True)}),
    "robokit.legged.littledog.littledog_model": Call({
        "armature": Real(0.0), "damping": Real(0.0), "friction": Real(1.0), "timestep": Real(0.001),
        "motor": Obj(littledog_motor, optional=True), "terrain": Obj(step_board, optional=True)}),
    "robokit.legged.servo_design.link_inertias": Call({}),
    "robokit.legged.servo_design.servo_inertia": Call({"motor": Obj(littledog_motor)}),
    "robokit.legged.servo_design.littledog_servo_gains": Call({"bandwidth_hz": Real(15.0),
                                                               "motor": Obj(littledog_motor)}),
    # --- lesson 04: the walk in MuJoCo and its tables (robokit.legged.simulation, lessons.littledog.experiment); every
    #     invalid input is refused before MuJoCo runs, so only the cheap flag keeps huge values out ---------
    "robokit.legged.simulation.LoopSettings": Call({
        "servo_rate": Real(500.0), "latency": Real(0.01), "jitter": Real(0.002), "loss": Real(0.1),
        "gains": Obj((96.0, 0.42), optional=True)}),
    "robokit.legged.simulation.SensorSettings": Call({
        "mocap_noise": Real(0.0005), "mocap_dropout": Real(0.05), "mocap_bursts": Real(0.005),
        "mocap_burst_length": Int(20), "gyro_noise": Real(0.005), "acc_noise": Real(0.05),
        "gyro_bias": Array(np.array([0.02, -0.015, 0.01]), "3"), "acc_bias": Array(np.array([0.1, -0.05, 0.08]), "3"),
        "force_noise": Real(0.1)}),
    "robokit.legged.simulation.simulate_walk": Call({
        "plan": Obj(tiny_walk_plan), "loops": Obj(loop_settings), "sensors": Obj(sensor_settings),
        "motor": Obj(littledog_motor), "host": Obj(posture_feedback, optional=True), "rng": Rng(0),
        "terrain": Obj(step_board, optional=True)}, cheap=False),
    "robokit.legged.posture.PostureFeedback": Call({
        "gain": Real(20.0), "axes": Obj(("z", "roll", "pitch")), "limit": Obj((0.03, 0.2))}),
    "robokit.legged.posture.delay_gain_limit": Call({"delay_cycles": Int(3)}),
    "robocourse.lessons.littledog.experiment.lesson_plans": Call({"distance": Real(0.05)}),
    "robocourse.lessons.littledog.experiment.loop_table": Call({
        "plan": Obj(tiny_walk_plan), "servo_rates": Array(np.array([500.0]), "N"),
        "latencies": Array(np.array([0.0]), "N"), "bandwidths": Array(np.array([15.0]), "N"), "rng": Rng(0),
        "progress": Func(None, optional=True)}, cheap=False),
    "robocourse.lessons.littledog.experiment.host_table": Call({
        "plan": Obj(tiny_walk_plan), "gains": Array(np.array([20.0]), "N", min_rows=0),
        "latencies": Array(np.array([0.0]), "N"), "losses": Array(np.array([0.0]), "N"), "rng": Int(0),
        "progress": Func(None, optional=True)}, cheap=False),
    "robocourse.lessons.littledog.experiment.host_lag": Call({"step": Real(0.005), "latency": Real(0.0),
                                                             "dt": Real(0.01)}, cheap=False),
    "robocourse.lessons.littledog.experiment.posture_errors": Call({"log": Obj(trial_log), "plan": Obj(tiny_walk_plan)}),
    "robocourse.lessons.littledog.experiment.estimation_table": Call({"log": Obj(trial_log)}),
    "robocourse.lessons.littledog.experiment.imu_drift": Call({"log": Obj(trial_log),
                                                              "sensors": Obj(sensor_settings, optional=True)}),
    "robocourse.lessons.littledog.experiment.touchdown_table": Call({
        "log": Obj(trial_log), "detectors": Obj(touchdown_detectors, optional=True), "tolerance": Int(5),
        "plan": Obj(tiny_walk_plan, optional=True), "gate": Int(10)}),
    "robocourse.lessons.littledog.experiment.endurance_table": Call({"outcomes": Mapping(trial_outcomes)}),
    "robocourse.lessons.littledog.experiment.true_margins": Call({"log": Obj(trial_log)}),
    "robocourse.lessons.littledog.terrain.terrain_table": Call({
        "trials": Int(1), "distance": Real(0.05), "heights": Array(np.array([0.01, 0.02]), "2"),
        "gaits": Obj(("crawl",)), "modes": Obj(("blind",)), "seed": Int(0), "workers": Int(1, optional=True),
        "progress": Func(None, optional=True)}, cheap=False),
    "robokit.legged.touchdown.match_events": Call({
        "detected": Array(np.array([3, 5, 8]), "N", min_rows=0), "truth": Array(np.array([2, 8]), "N", min_rows=0),
        "tolerance": Int(2)}),
    "robokit.legged.support.nearest_boundary_point": Call({
        "polygon": Array(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]), "N,2"),
        "point": Array(np.array([0.5, 0.2]), "2"), "validate": Flag(True)}),
    "robokit.legged.touchdown.gate_touchdowns": Call({
        "detected": Array(np.array([3, 40, 52, 95]), "N", min_rows=0), "expected": Array(np.array([50, 100]), "N", min_rows=0),
        "window": Int(10)}),
}

#: Public functions a lesson uses that the fuzz leaves out, and why.
NOT_FUZZED: dict[str, str] = {
    "robokit.sim.motion.Trajectory": "a plain record (NamedTuple) of t and poses; the functions that take one validate it",
    "robokit.legged.gait.WalkPlan": "a plain record (NamedTuple) of a plan's arrays; walking_plan makes it",
    "robokit.legged.trial_log.TrialLogError": "an exception class (a ValueError) the lesson catches, not calls",
    "robocourse.grading.check.check": "the notebook's checker of a student's function (grading's own tests cover it)",
}
SPECS["robocourse.grading.data.assignment_data"] = Call({"slug": Choice("04_littledog")})
SPECS["robocourse.environment.check_environment"] = Call({})
SPECS["robocourse.environment.environment_table"] = Call(
    {"rows": Obj([{"package": "numpy", "version": "2.0", "status": "ok", "lessons": "all", "used_by": "robokit"}])})

#: Besides the lessons' API: the exercises' references (students reproduce their contracts) and
#: the functions the issue's fuzz named.
# --- file readers: hostile files (tests/fuzz_kinds.File) ------------------------------------

@functools.cache
def saved_g2o():
    from robokit.mapping import write_g2o
    path = fuzz_folder() / "graph.g2o"
    write_g2o(pose_graph(), path)
    return str(path)


@functools.cache
def saved_topological_map():
    from tests.test_mapping_topological import small_map
    return str(small_map().save(fuzz_folder() / "topological.npz"))


@functools.cache
def saved_vocabulary():
    return str(bow_vocabulary().save(fuzz_folder() / "vocabulary.npz"))


@functools.cache
def saved_database():
    from robokit.vision import BowDatabase
    db = BowDatabase(bow_vocabulary())
    db.add(orb_descriptors(30, 7))
    return str(db.save(fuzz_folder() / "database.npz"))


@functools.cache
def saved_run():
    from robokit.sim.runs import Run
    t, poses = np.arange(4.0), np.zeros((4, 3))
    run = Run(t, poses, poses.copy(), {}, {}, {"lidar": np.ones((4, 8))}, {"world": "test"})
    return str(run.save(fuzz_folder() / "run.npz"))


@functools.cache
def saved_arrays():
    from robokit.files import save_npz
    return str(save_npz(fuzz_folder() / "arrays.npz", {"a": np.arange(5.0), "b": np.eye(2)}))


def trial_extras(valid: bytes) -> dict:
    """npz_extras, and a log whose metadata nests 100,000 deep."""
    import io
    from robokit.files import save_npz
    with np.load(io.BytesIO(valid)) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["__meta__"] = np.array("[" * 100_000 + "]" * 100_000)
    return {**npz_extras(valid), "metadata nested 10^5 deep": save_npz(io.BytesIO(), arrays).getvalue()}


def map_extras(valid: bytes) -> dict:
    """YAML whose image is a device, a directory or missing; 10^4-deep origin; a key past the budget."""
    import re as _re

    def image(name: bytes) -> bytes:
        return _re.sub(rb"(?m)^image:.*$", b"image: " + name, valid)
    return {"an image that is a device": image(b"/dev/zero"), "an image that is a directory": image(b"/tmp"),
            "a missing image": image(b"no-such.pgm"),
            "an origin nested 10^4 deep": _re.sub(rb"(?m)^origin:.*$", b"origin: " + b"[" * 10_000 + b"]" * 10_000, valid),
            "a PGM header declaring 10^6 x 10^6 pixels": image(str(huge_pgm()).encode())}


@functools.cache
def huge_pgm():
    path = fuzz_folder() / "huge-header.pgm"
    path.write_bytes(b"P5\n1000000 1000000\n255\n" + bytes(16))
    return path


def _reader_specs() -> dict:
    from robokit.files import NpzFileError
    from robokit.legged.trial_log import MAX_LOG_BYTES, TrialLogError
    from robokit.mapping.g2o import MAX_G2O_BYTES, G2OFormatError
    from robokit.mapping.map_server import MAX_YAML_BYTES, MapFileError
    from robokit.mapping.topological import MAX_MAP_BYTES
    from robokit.sim.runs import MAX_RUN_BYTES
    from robokit.vision.bag_of_words import MAX_FILE_BYTES, VocabularyFileError
    from robokit.vision.bow_database import DatabaseFileError

    def npz(valid, budget, error):
        return File(valid, budget=budget, foreign=saved_g2o, error=error, extra=npz_extras)
    return {
        "robokit.files.read_npz": Call({"path": npz(saved_arrays, 1 << 30, NpzFileError), "max_bytes": Int(1 << 20),
                                        "max_arrays": Int(10), "max_values": Int(1000)}),
        "robokit.mapping.topological.TopologicalMap.load": Call({"path": npz(saved_topological_map, MAX_MAP_BYTES, ValueError)}),
        "robokit.vision.bag_of_words.Vocabulary.load": Call({"path": npz(saved_vocabulary, MAX_FILE_BYTES, VocabularyFileError)}),
        "robokit.vision.bow_database.BowDatabase.load": Call({"path": npz(saved_database, MAX_FILE_BYTES, DatabaseFileError)}),
        "robokit.sim.runs.Run.load": Call({"path": npz(saved_run, MAX_RUN_BYTES, ValueError)}),
        "robokit.legged.trial_log.load_trial": Call({"path": File(saved_trial, budget=MAX_LOG_BYTES, foreign=saved_g2o,
                                                                  error=TrialLogError, extra=trial_extras)}),
        "robokit.mapping.g2o.read_g2o": Call({"source": File(saved_g2o, budget=MAX_G2O_BYTES, foreign=saved_arrays,
                                                             error=G2OFormatError)}),
        "robokit.mapping.map_server.load_map": Call({"yaml_path": File(saved_map, budget=MAX_YAML_BYTES, foreign=saved_g2o,
                                                                       error=MapFileError, missing=MapFileError,
                                                                       extra=map_extras)}),
    }


SPECS.update(_reader_specs())

# --- public functions of lessons 02-04's modules that no lesson calls directly -------------------
SPECS.update({
    "robokit.sim.motion.corridor_path": Call({"world": Obj(corridor_world), "speed": Real(0.3), "rate": Real(10.0),
                                              "margin": Real(0.8)}),
    "robokit.sim.motion.odometry_increment": Call({"previous": Array(np.zeros(3), "3|N,3"),
                                                   "current": Array(np.array([1.0, 1.0, 0.2]), "3|N,3")}),
    "robokit.sim.motion.sample_motion_model_odometry": Call({
        "odom_prev": Array(np.zeros(3), "3"), "odom_now": Array(np.array([1.0, 0.0, 0.1]), "3"),
        "poses": Array(np.zeros((3, 3)), "N,3|3"), "alphas": Array(np.array([0.01, 0.001, 0.01, 0.001]), "4"),
        "rng": Rng(0)}),
    "robokit.sim.motion.waypoint_path": Call({"waypoints": Array(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), "N,2"),
                                              "speed": Real(0.5), "turn_rate": Real(0.6), "rate": Real(2.0)}),
    "robokit.sim.layout.Layout": Call({
        "segments": Array(np.array([[[0.0, 0.0], [4.0, 0.0]]]), "N,2,2", optional=True),
        "circles": Array(np.array([[4.0, 1.0, 1.0]]), "N,3", optional=True),
        "boxes": Array(np.array([[0.0, 5.0, 2.0, 2.0, 0.0]]), "N,5", optional=True)}),
    "robokit.sim.runs.describe_sensor": Call({"sensor": Obj(corridor_lidar)}),
})


#: Arguments whose last element is an angle (a heading, a joint or beam angle, a heading spread or
#: change): 1e300 there must be refused (robokit.validation.MAX_ANGLE), as a wrapped value means nothing.
HUGE_ANGLES: dict[str, tuple[str, ...]] = {
    "robokit.controllers.path_following_loop.simulate_path_following": ("start_pose",),
    "robokit.legged.leg_kinematics.body_fk": ("q",),
    "robokit.legged.leg_kinematics.foot_position": ("q_leg",),
    "robokit.legged.leg_kinematics.foot_jacobian": ("q_leg",),
    "robokit.legged.leg_kinematics.leg_points": ("q_leg",),
    "robokit.legged.leg_kinematics.foot_force_from_torques": ("q_leg",),
    "robokit.localization.mcl.mcl_step": ("particles", "odom_prev", "odom_now", "angles"),
    "robokit.localization.particle_filter.sample_ellipse_poses": ("pose", "sigma_theta"),
    "robokit.localization.particle_filter.weighted_pose_mean": ("particles",),
    "robokit.localization.pose_ekf.ekf_update": ("z", "H"),
    "robocourse.lessons.omni_localization.exercises.node_fix_update": ("node_pose", "z"),
    "robocourse.lessons.omni_localization.relaxation_runs.relax_map": ("poses", "measurements"),
    "robokit.localization.pose_ekf.unicycle_jacobian": ("x", "dt"),
    "robokit.mapping.hybrid_map.geo_tag": ("poses",),
    "robokit.mapping.hybrid_map.geo_index": ("poses",),
    "robokit.mapping.pose_graph.pose_graph_from_odometry": ("odometry_poses",),
    "robokit.mapping.pose_graph_optimize.pose_graph_residuals": ("poses",),
    "robokit.navigation.visual_path.follow_path": ("start_pose", "odometry_noise"),
    "robokit.navigation.visual_path.perturbed_starts": ("heading",),
    "robokit.sim.vehicle.unicycle_step": ("pose", "dt"),
}


EXTRA: tuple[str, ...] = (
    "robokit.config.pad_heap",                         # called by `import robokit`: the environment it reads
    "robokit.outdoor.navigator.avoidance_decision",   # the Navigator's rules; assignment 05's loop folds them in
    "robokit.legged.posture.PostureFeedback",          # lesson 04's reactive host, built by host_table and terrain_table
    "robocourse.lessons.littledog.experiment.posture_errors",   # host_table's tilt and sag
    "robokit.localization.appearance_mcl.place_hypotheses",      # lesson 02's Monte-Carlo check (checks)
    "robokit.localization.appearance_mcl.monte_carlo_check",
    "robocourse.lessons.omni_localization.checks.drive_on",      # the Monte-Carlo check's drives (check_trials)
    "robokit.localization.scan_matching.match_scan",   # lesson 03 refines Table 2's runs with it (trials)
    "robokit.sim.layout.Layout.from_cells",          # lesson 03's real map, through real_map
    "robocourse.lessons.corridor_localization.real_map.building_routes",
    "robocourse.lessons.corridor_localization.orb_realism.move_image",   # motion_shares moves the images with it
    "robocourse.lessons.corridor_localization.real_map.global_localization_runs",
    "robocourse.lessons.corridor_localization.real_map.global_localization_batch",
    "robokit.sim.vehicle.unicycle_step",
    "robokit.sim.runs.record_stream",     # lesson 02 builds its map from it, through office_setup
    "robokit.viz.framing.look_from",      # public; no lesson calls it since viz.fit_view
    "robokit.vision.plot_detector.scale_space_maxima",   # public since PLOT's search moved out
    "robokit.vision.matching.pair_distances",    # lesson 01's map association, through VisualSLAM
    # lesson 02's map alignment study (issue 35), fuzzed before the notebook calls it
    *(f"robocourse.lessons.omni_localization.alignment.{n}" for n in (
        "loop_rows", "loop_subsets", "held_share", "with_loops", "alignment_errors", "loop_edge_errors",
        "odometry_redraws")),
    # lesson 02 (path following, pose EKF, navigation), fuzzed before the lesson exists
    *(f"robokit.controllers.path_geometry.{n}" for n in ("VisualPath", "path_from_poses", "reference_point")),
    *(f"robokit.controllers.path_following.{n}" for n in (
        "path_following_gains", "path_following_command", "saturate_command", "PathFollower")),
    *(f"robokit.controllers.path_following_loop.{n}" for n in (
        "path_following_linearisation", "path_following_poles", "path_following_damping", "lateral_step_response",
        "simulate_path_following")),
    *(f"robokit.localization.pose_ekf.{n}" for n in (
        "unicycle_jacobian", "unicycle_process_noise", "ekf_predict", "ekf_update", "nees", "nees_bounds", "UnicycleEKF")),
    *(f"robokit.navigation.visual_path.{n}" for n in ("gaussian_localizer", "perturbed_starts", "follow_path")),
    # robokit.vision.colour (lesson 02)
    "robokit.vision.colour.rgb_to_hsi", "robokit.vision.colour.hue_mask",
    "robokit.vision.colour.hue_histogram", "robokit.vision.colour.hue_histogram_opencv",
    "robokit.vision.colour.histogram_distance", "robokit.vision.colour.histogram_intersection",
    # robokit.vision.omni_features, matching.DescriptorIndex, sim.view_matches (lesson 02)
    "robokit.vision.omni_features.omni_sift", "robokit.vision.omni_features.annulus_mask",
    "robokit.vision.omni_features.radial_orientation", "robokit.vision.matching.DescriptorIndex",
    "robokit.vision.matching.ratio_test", "robokit.vision.descriptors.detect_sift_features",
    "robokit.sim.view_matches.omni_ground_truth_inliers",
    "robokit.sim.view_matches.omni_view_pair",
    # robokit.mapping's pose graphs (lesson 02), fuzzed before the lesson exists
    "robokit.mapping.pose_graph.PoseGraph", "robokit.mapping.pose_graph.edge_variances",
    "robokit.mapping.pose_graph.unreachable_nodes", "robokit.mapping.pose_graph.is_connected",
    "robokit.mapping.pose_graph.require_connected", "robokit.mapping.pose_graph.pose_graph_from_odometry",
    "robokit.mapping.pose_graph_optimize.pose_graph_residuals", "robokit.mapping.pose_graph_optimize.pose_graph_cost",
    "robokit.mapping.pose_graph_optimize.pose_graph_jacobian",
    "robokit.mapping.pose_graph_optimize.optimize_pose_graph", "robokit.mapping.relaxation.relax",
    "robokit.mapping.relaxation.relax_sweep", "robokit.mapping.relaxation.initial_variances",
    "robokit.mapping.g2o.read_g2o", "robokit.mapping.g2o.write_g2o",
    # public, with a spec, but called by no lesson (lessons 02-04's modules, and readable references)
    "robokit.localization.particle_clusters.pose_clusters", "robokit.localization.particle_clusters.largest_cluster_mean",
    "robokit.legged.littledog.littledog_mjcf", "robokit.legged.leg_kinematics.torques_from_foot_force",
    "robokit.arm.arm_angle_intervals.split_points", "robokit.arm.arm_angle_intervals.ik_srs_readable",
    "robokit.vision.plot_readable.detect_plot_readable", "robokit.sim.motion.corridor_path",
    "robokit.sim.motion.odometry_increment", "robokit.sim.motion.sample_motion_model_odometry",
    "robokit.sim.motion.waypoint_path", "robokit.sim.layout.Layout", "robokit.sim.runs.describe_sensor",
    "robocourse.lessons.visual_slam.exercises.robust_pose_problems",
    "robocourse.lessons.corridor_localization.trials.corridor_localizer",
    "robocourse.lessons.corridor_localization.trials.amcl_localizer",
    "robocourse.lessons.corridor_localization.experiment.mapping_grid",
    "robocourse.lessons.corridor_localization.experiment.clutter_map",
    # every file reader (hostile files: tests/fuzz_kinds.File)
    "robokit.files.read_npz", "robokit.mapping.topological.TopologicalMap.load",
    "robokit.vision.bag_of_words.Vocabulary.load", "robokit.vision.bow_database.BowDatabase.load",
    "robokit.sim.runs.Run.load",
    "robokit.mapping.manhattan.manhattan_world_graph",
    # lesson 02's topological map and hierarchical localization (helper D)
    "robokit.geometry.procrustes.fit_se2", "robokit.geometry.planar.intersect_lines",
    "robokit.vision.ransac.ransac_sample_count",
    "robokit.vision.ransac.ransac_se2", "robokit.vision.spherical.essential_from_bearings",
    "robokit.vision.spherical.epipolar_error", "robokit.vision.spherical.ransac_essential",
    "robokit.vision.spherical.decompose_essential", "robokit.vision.spherical.floor_points",
    "robokit.sim.motion.office_tour", "robokit.sim.motion.increment_variances",
    "robokit.sim.motion.odometry_covariance",
    "robokit.mapping.topological_build.appearance_changed",
    "robokit.mapping.topological_build.local_map_full",
    "robokit.mapping.topological_build.select_key_frames",
    "robokit.mapping.topological_build.build_topological_map",
    "robokit.mapping.omni_views.omni_view", "robokit.mapping.omni_views.as_omni_image",
    "robokit.mapping.omni_views.relative_pose", "robokit.mapping.topological.TopologicalMap",
    "robokit.localization.hierarchical.HierarchicalLocalizer",
    # lesson 03's occupancy grid (robokit.mapping.occupancy_grid, grid_mapping, map_server)
    *(f"robokit.mapping.occupancy_grid.{n}" for n in (
        "log_odds", "probability", "OccupancyGrid", "OccupancyGrid.empty", "OccupancyGrid.from_probability",
        "likelihood_field")),
    *(f"robokit.mapping.grid_mapping.{n}" for n in (
        "inverse_range_sensor_model", "update_log_odds", "occupancy_grid_mapping", "occupancy_grid_mapping_readable")),
    "robokit.mapping.map_server.save_map", "robokit.mapping.map_server.load_map",
    # lesson 03's Monte-Carlo localization (robokit.localization.particle_filter, beam_models, mcl)
    *(f"robokit.localization.particle_filter.{n}" for n in (
        "normalise_log_weights", "low_variance_resample", "kld_sample_count", "pose_bins", "kld_resample",
        "weighted_pose_mean", "sample_ellipse_poses", "ellipse_weights")),
    *(f"robokit.localization.beam_models.{n}" for n in (
        "subsample_beams", "valid_beams", "likelihood_field_log_weights", "likelihood_field_log_weight_readable")),
    "robokit.localization.mcl.mcl_step", "robokit.localization.mcl.uniform_free_poses",
    "robokit.localization.mcl.MonteCarloLocalizer",
    # lesson 03's corridor scan, moving strategy and geo-tags, fuzzed before the lesson exists
    *(f"robokit.mapping.corridor_scan.{n}" for n in (
        "corridor_axis", "wall_distances", "door_sides", "corridor_state", "width_condition", "middle_line_condition")),
    *(f"robokit.mapping.corridor_areas.{n}" for n in ("as_scan", "invalid_areas", "theta_limits", "theta_limits_geometric")),
    "robokit.controllers.corridor_centering.centering_command",
    "robokit.controllers.corridor_centering.move_to_middle_line",
    "robokit.mapping.hybrid_map.geo_tag", "robokit.mapping.hybrid_map.geo_index",
    # robokit.vision lesson 03: ORB, Hamming matching, keyframes, bag of words (fuzzed before the lesson exists)
    *(f"robokit.vision.{n}" for n in (
        "orb.detect_orb_features", "hamming.hamming_distance",
        "hamming.hamming_distances", "hamming.hamming_match", "keyframes.feature_threshold",
        "keyframes.shared_fraction", "keyframes.tracked_matches", "keyframes.matched_points",
        "keyframes.tracked_fraction",
        "keyframes.KeyframeSelector", "keyframes.select_keyframes",
        "keyframes.select_keyframes_orbslam", "bag_of_words.tf_idf", "bag_of_words.l1_score",
        "bag_of_words.Vocabulary", "bag_of_words.Vocabulary.train",
        "bow_database.BowDatabase")),
    # lesson 04's sensing: the one rigid fit, MoCap, IMU, fusion, touchdowns
    "robokit.geometry.procrustes.fit_rigid", "robokit.geometry.procrustes.fit_se3",
    "robokit.legged.mocap.simulate_mocap",
    *(f"robokit.legged.mocap.{n}" for n in ("fit_marker_pose", "mocap_body_poses")),
    *(f"robokit.legged.imu.{n}" for n in ("simulate_imu", "integrate_gyro", "specific_force")),
    *(f"robokit.legged.state_estimation.{n}" for n in ("fuse_body_state", "orientation_errors", "position_errors")),
    "robokit.legged.touchdown.detect_contacts", "robokit.legged.touchdown.gate_touchdowns",
    "robokit.legged.support.nearest_boundary_point",
    "robokit.legged.simulation.SensorSettings",
    *(f"robokit.legged.touchdown.{n}" for n in ("contact_events", "event_precision_recall", "score_events",
                                                     "match_events")),
    # robokit.legged's gaits (lesson 04), fuzzed before the lesson exists
    *(f"robokit.legged.support.{n}" for n in ("support_polygon", "stability_margin", "stability_margins")),
    *(f"robokit.legged.gait_schedule.{n}" for n in (
        "GaitSchedule", "crawl_gait", "trot_gait", "as_gait_schedule", "stance_pattern")),
    "robokit.legged.gait.swing_trajectory", "robokit.legged.gait.walking_plan",
    # lesson 04's terrain boards and their table (issue 36), fuzzed before the notebook uses them
    *(f"robokit.legged.terrain.{n}" for n in (
        "Terrain", "height_at", "edge_distance", "step_terrain", "locate_terrain", "terrain_transform")),
    "robocourse.lessons.littledog.terrain.terrain_table",
    # lesson 04's loops (controllers.servo_loop, dc_motor, joint_servo, host_link; legged.power), before the lesson
    *(f"robokit.controllers.servo_loop.{n}" for n in (
        "servo_plant", "servo_closed_loop", "servo_loop_gain", "servo_step_response", "servo_frequency_response",
        "loop_metrics", "discrete_servo_loop", "discrete_servo_analysis")),
    *(f"robokit.controllers.dc_motor.{n}" for n in (
        "DCMotor", "joint_torque", "motor_current", "voltage_for_torque", "electrical_power", "reflected_inertia")),
    *(f"robokit.controllers.joint_servo.{n}" for n in (
        "joint_lag", "joint_plant", "design_servo_gains", "servo_analysis", "pd_servo_step", "discrete_servo_response")),
    "robokit.controllers.host_link.SetpointChannel",
    *(f"robokit.legged.power.{n}" for n in ("battery_energy", "trial_power", "endurance", "cost_of_transport")),
    # lesson 04's trial log, LittleDog scenes and figures (fuzzed before the lesson exists)
    "robokit.geometry.rotations.quat_to_matrix",
    *(f"robokit.legged.trial_log.{n}" for n in ("TrialLog", "trial_meta", "empty_streams")),
    *(f"robokit.legged.trial_log.{n}" for n in ("save_trial", "load_trial", "describe_layout")),
    "robokit.viz.animation.animate_tracks",
    *(f"robokit.viz.legged.{n}" for n in ("joint_path", "add_littledog", "pose_littledog", "animate_trial")),
    *(f"robokit.viz.legged_plots.{n}" for n in (
        "support_outline", "plot_gait_diagram", "plot_joint_tracking", "plot_foot_forces", "plot_support")),
    # assignment 04's exercises and helpers
    "robokit.legged.leg_kinematics.foot_position", "robokit.legged.leg_kinematics.leg_ik",
    *(f"robocourse.lessons.littledog.data.{n}" for n in ("model_facts", "crawl_touchdowns", "mocap_frames")),
    "robocourse.lessons.littledog.exercises.battery_endurance", "robocourse.lessons.littledog.exercises.detect_touchdowns",
)


def resolve(dotted: str) -> Callable[..., Any]:
    """The function or class a dotted name means."""
    import importlib
    module, _, name = dotted.rpartition(".")
    try:
        return getattr(importlib.import_module(module), name)
    except ImportError:
        outer, _, cls = module.rpartition(".")
        return getattr(getattr(importlib.import_module(outer), cls), name)
