"""The LittleDog quadruped (lesson 04): model, kinematics, gaits, sensing, simulation, trial logs, power.

littledog         the guide's facts and the MuJoCo model written from them (one set of constants)
terrain           step boards on the floor: their height map, edges, and their pose from MoCap markers
leg_kinematics    one leg's FK, closed-form IK on both knee branches, Jacobian and statics (J^T f)
support           the support polygon and the static stability margin
gait_schedule     crawl and trot schedules
gait              walking plans: body and feet along a crawl or a trot
servo_design      the joint servo designed on the model's inertia
posture           a reactive host: the trunk's pose from MoCap fed back into the set-points
simulation        a walk in MuJoCo under the 500 Hz servo and the 100 Hz host over the link
imu               the body's IMU: gyro and accelerometer readings, gyro integration
mocap             the Vicon markers a trial reports, and the body pose fitted back from them
state_estimation  MoCap and IMU fused into the body state; its errors
touchdown         touchdowns from the foot force sensors, and their score against the truth
trial_log         the checked trial log and its .npz file
power             electrical power, cost of transport, the battery's endurance
"""
from .littledog import (FOOT_RADIUS, GUIDE, HIP_OFFSETS, HIP_POSITIONS, JOINT_LIMITS, JOINT_NAMES, JOINTS, KNEE_SHIFT,
                        KNEE_ZERO, LEG_MASSES, LEGS, LOWER_LEG, MARKERS, SHANK, SOURCE_JOINT_LIMITS, STANCE_FEET,
                        STANDING_HEIGHT, TRUNK_MASS, TRUNK_SIZE, UPPER_LEG, littledog_mjcf, littledog_model)
from .terrain import Terrain, edge_distance, height_at, locate_terrain, step_terrain, terrain_transform
from .support import SupportPolygonError, stability_margin, stability_margins, support_polygon
from .gait_schedule import GaitSchedule, crawl_gait, trot_gait
from .gait import FOOTHOLD_CLEARANCE, WalkPlan, walking_plan
from .servo_design import SERVO_BANDWIDTH, link_inertias, littledog_servo_gains, servo_inertia
from .posture import POSTURE_AXES, PostureFeedback, delay_gain_limit
from .simulation import LoopSettings, SensorSettings, TrialOutcome, simulate_walk
from .imu import ImuReadings, integrate_gyro, simulate_imu
from .mocap import MocapFrames, MocapPoses, TooFewMarkersError, fit_marker_pose, mocap_body_poses, simulate_mocap
from .state_estimation import BodyState, fuse_body_state, orientation_errors, position_errors
from .touchdown import EventScore, contact_events, detect_contacts, event_precision_recall, score_events
from .trial_log import LOG_LAYOUT, TrialLog, TrialLogError, describe_layout, load_trial, save_trial
from .power import battery_energy, cost_of_transport, endurance, trial_power

__all__ = ["FOOT_RADIUS", "GUIDE", "HIP_OFFSETS", "HIP_POSITIONS", "JOINT_LIMITS", "JOINT_NAMES", "JOINTS",
           "KNEE_SHIFT", "KNEE_ZERO", "SHANK", "SOURCE_JOINT_LIMITS", "LEG_MASSES", "LEGS", "LOWER_LEG", "MARKERS",
           "STANCE_FEET", "STANDING_HEIGHT", "TRUNK_MASS",
           "TRUNK_SIZE", "UPPER_LEG", "littledog_mjcf", "littledog_model", "Terrain", "edge_distance", "height_at",
           "locate_terrain", "step_terrain", "terrain_transform", "SupportPolygonError", "stability_margin",
           "stability_margins", "support_polygon", "GaitSchedule", "crawl_gait", "trot_gait", "WalkPlan", "FOOTHOLD_CLEARANCE",
           "walking_plan", "SERVO_BANDWIDTH", "link_inertias", "littledog_servo_gains", "servo_inertia",
           "POSTURE_AXES", "PostureFeedback", "delay_gain_limit", "LoopSettings", "SensorSettings", "TrialOutcome", "simulate_walk", "ImuReadings", "integrate_gyro",
           "simulate_imu", "MocapFrames", "MocapPoses", "TooFewMarkersError", "fit_marker_pose", "mocap_body_poses",
           "simulate_mocap", "BodyState", "fuse_body_state", "orientation_errors", "position_errors", "EventScore",
           "contact_events", "detect_contacts", "event_precision_recall", "score_events", "LOG_LAYOUT", "TrialLog",
           "TrialLogError", "describe_layout", "load_trial", "save_trial", "battery_energy", "cost_of_transport",
           "endurance", "trial_power"]
