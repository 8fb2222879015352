"""Control loops designed and checked with python-control (named so it never shadows ``control``).

servo_loop           an integrator plus a first-order lag under PD with rate feedback, continuous and
                     sampled: plant, closed loop, responses, margins, the ZOH loop
heading              the heading servo of a skid-steer truck (lesson 05): the loop in its names,
                     gains by pole placement, the discrete controller
dc_motor             a geared DC motor per joint (lesson 04): torque, current, power, reflected inertia
joint_servo          lesson 04's 500 Hz joint servo: gains, the sampled loop, the PD step a tick runs
host_link            lesson 04's 100 Hz host link: set-points over a late, jittery, lossy channel
path_geometry        lesson 02's path: a smooth curve through key poses, its nearest point (Eq. (7))
path_following       the path-following law (Eq. (8)), its gains and saturation, the follower
path_following_loop  Eq. (8) linearised (poles, damping, step response) and simulated
corridor_centering   lesson 03's moving strategy onto the corridor's middle line (Ge et al. Sec. 3.1)
"""
from .servo_loop import ServoAnalysis, discrete_servo_analysis, servo_closed_loop, servo_plant, servo_step_response
from .heading import (HeadingController, design_heading_gains, heading_closed_loop, heading_frequency_response,
                      heading_loop_gain, heading_plant, heading_step_response, loop_metrics)
from .dc_motor import (DCMotor, LITTLEDOG_MOTOR, MotorPower, electrical_power, joint_torque, motor_current,
                       reflected_inertia, voltage_for_torque)
from .joint_servo import ServoResponse, design_servo_gains, joint_plant, pd_servo_step, servo_analysis
from .host_link import SetpointChannel
from .path_geometry import ReferencePoint, VisualPath, path_from_poses, reference_point
from .path_following import PathFollower, PathSingularityError, path_following_command, path_following_gains
from .path_following_loop import (lateral_step_response, path_following_damping, path_following_poles,
                                  simulate_path_following)
from .corridor_centering import CenteringResult, move_to_middle_line

__all__ = ["ServoAnalysis", "discrete_servo_analysis", "servo_closed_loop", "servo_plant", "servo_step_response",
           "HeadingController", "design_heading_gains", "heading_closed_loop", "heading_frequency_response",
           "heading_loop_gain", "heading_plant", "heading_step_response", "loop_metrics", "DCMotor",
           "LITTLEDOG_MOTOR", "MotorPower", "electrical_power", "joint_torque", "motor_current", "reflected_inertia",
           "voltage_for_torque", "ServoResponse", "design_servo_gains", "joint_plant", "pd_servo_step",
           "servo_analysis", "SetpointChannel", "ReferencePoint", "VisualPath", "path_from_poses", "reference_point",
           "PathFollower", "PathSingularityError", "path_following_command", "path_following_gains",
           "lateral_step_response", "path_following_damping", "path_following_poles", "simulate_path_following",
           "CenteringResult", "move_to_middle_line"]
