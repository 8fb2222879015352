"""LittleDog quadruped: model, kinematics, gaits, sensing, simulation, trial logs, power (lesson 04)."""
from .littledog import (FOOT_RADIUS, GUIDE, HIP_OFFSET, HIP_POSITIONS, JOINT_LIMITS, JOINT_NAMES, JOINTS,
                        LEG_MASSES, LEGS, LOWER_LEG, MARKERS, STANCE_FEET, STANDING_HEIGHT, TIMESTEP,
                        TOTAL_MASS, TRUNK_MASS, TRUNK_SIZE, UPPER_LEG, littledog_mjcf, littledog_model)
# the trial log
from .trial_log import (LOG_FORMAT, LOG_LAYOUT, LOG_VERSION, META_KEYS, TrialLog, TrialLogError, describe_layout,
                        empty_streams, load_trial, save_trial, trial_meta)

__all__ = ["FOOT_RADIUS", "GUIDE", "HIP_OFFSET", "HIP_POSITIONS", "JOINT_LIMITS", "JOINT_NAMES", "JOINTS",
           "LEG_MASSES", "LEGS", "LOWER_LEG", "MARKERS", "STANCE_FEET", "STANDING_HEIGHT", "TIMESTEP",
           "TOTAL_MASS", "TRUNK_MASS", "TRUNK_SIZE", "UPPER_LEG", "littledog_mjcf", "littledog_model",
           # the trial log
           "LOG_FORMAT", "LOG_LAYOUT", "LOG_VERSION", "META_KEYS", "TrialLog", "TrialLogError", "describe_layout",
           "empty_streams", "load_trial", "save_trial", "trial_meta"]
