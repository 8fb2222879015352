"""LittleDog quadruped: model, kinematics, gaits, sensing, simulation, trial logs, power (lesson 04)."""
from .littledog import (FOOT_RADIUS, GUIDE, HIP_OFFSET, HIP_POSITIONS, JOINT_LIMITS, JOINT_NAMES, JOINTS,
                        LEG_MASSES, LEGS, LOWER_LEG, MARKERS, STANCE_FEET, STANDING_HEIGHT, TIMESTEP,
                        TOTAL_MASS, TRUNK_MASS, TRUNK_SIZE, UPPER_LEG, littledog_mjcf, littledog_model)
# sensing and estimation (MoCap, IMU, fusion, touchdowns)
from .imu import GRAVITY, ImuReadings, integrate_gyro, simulate_imu, specific_force
from .mocap import MocapFrames, MocapPoses, TooFewMarkersError, fit_marker_pose, mocap_body_poses, simulate_mocap
from .state_estimation import BodyState, fuse_body_state, orientation_errors, position_errors
from .touchdown import EventScore, contact_events, detect_contacts, event_precision_recall, score_events
# gaits: support polygon and stability margin, gait schedules, crawl and trot plans
from .gait import WalkPlan, swing_trajectory, walking_plan
from .gait_schedule import CRAWL_SEQUENCE, TROT_PAIRS, GaitSchedule, crawl_gait, stance_pattern, trot_gait
from .support import SupportPolygonError, stability_margin, stability_margins, support_polygon
# the servo on the model, and walking in MuJoCo with both loops
from .servo_design import SERVO_BANDWIDTH, link_inertias, littledog_servo_gains, servo_inertia
from .simulation import FALL_HEIGHT, LoopSettings, SensorSettings, TrialOutcome, simulate_walk
# power and endurance
from .power import battery_energy, cost_of_transport, endurance, trial_power
# the trial log
from .trial_log import LOG_FORMAT, LOG_LAYOUT, LOG_VERSION, META_KEYS, TrialLog, TrialLogError, empty_streams, trial_meta
from .trial_log import describe_layout, load_trial, save_trial

__all__ = ["FOOT_RADIUS", "GUIDE", "HIP_OFFSET", "HIP_POSITIONS", "JOINT_LIMITS", "JOINT_NAMES", "JOINTS",
           "LEG_MASSES", "LEGS", "LOWER_LEG", "MARKERS", "STANCE_FEET", "STANDING_HEIGHT", "TIMESTEP",
           "TOTAL_MASS", "TRUNK_MASS", "TRUNK_SIZE", "UPPER_LEG", "littledog_mjcf", "littledog_model",
           # sensing and estimation
           "GRAVITY", "ImuReadings", "simulate_imu", "integrate_gyro", "specific_force",
           "MocapFrames", "MocapPoses", "TooFewMarkersError", "simulate_mocap", "fit_marker_pose", "mocap_body_poses",
           "BodyState", "fuse_body_state", "orientation_errors", "position_errors",
           "EventScore", "detect_contacts", "contact_events", "event_precision_recall", "score_events",
           # gaits
           "SupportPolygonError", "support_polygon", "stability_margin", "stability_margins", "GaitSchedule", "crawl_gait",
           "trot_gait", "stance_pattern", "swing_trajectory", "WalkPlan", "walking_plan", "CRAWL_SEQUENCE", "TROT_PAIRS",
           # servo design and simulation
           "SERVO_BANDWIDTH", "link_inertias", "littledog_servo_gains", "servo_inertia",
           "FALL_HEIGHT", "LoopSettings", "SensorSettings", "TrialOutcome", "simulate_walk",
           # power
           "battery_energy", "cost_of_transport", "endurance", "trial_power",
           # the trial log
           "LOG_FORMAT", "LOG_LAYOUT", "LOG_VERSION", "META_KEYS", "TrialLog", "TrialLogError", "describe_layout",
           "empty_streams", "load_trial", "save_trial", "trial_meta"]
