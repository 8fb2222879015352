"""Control loops designed and checked with python-control (named so it never shadows ``control``).

Layer: below the system lessons (``outdoor``, ``legged``) and ``navigation``; imports ``geometry``,
``validation``, ``sim`` (the one unicycle model), ``mapping`` (the corridor scan analysis) and python-control.

heading              the heading servo of a skid-steer vehicle: the loop as transfer functions in
                     lesson 05's names (servo_loop's), pole-placement gains for an overshoot and
                     settling time, and the discrete controller (re-exported by :mod:`robokit.outdoor`)
servo_loop           an integrator plus a first-order lag under PD with rate feedback, continuous and
                     sampled: plant, closed loop, loop gain, step and frequency response, margins,
                     the ZOH loop's poles and bandwidth
dc_motor             a geared DC motor per joint (lesson 04): torque from voltage and speed, current,
                     copper and mechanical power, reflected inertia; LittleDog's assumed motor
joint_servo          lesson 04's 500 Hz joint servo: the joint plant, gains by pole placement, the
                     sampled loop analysed with python-control, the PD step the robot runs each tick
host_link            lesson 04's 100 Hz host link: set-points over a lossy, late, jittery channel
path_geometry        lesson 02's path: a smooth curve through recorded key poses with continuous
                     curvature, its nearest point (Eq. (7)) and the errors d, theta_tilde
path_following       the law of Eq. (8), its gains, saturation keeping the curvature, the follower
path_following_loop  Eq. (8) linearised about the path: poles, damping, step response (python-control),
                     and the nonlinear simulation beside it
corridor_centering   lesson 03's moving strategy (Ge et al. 2023, Sec. 3.1): a law that brings the robot
                     onto the corridor's middle line facing along it, and the closed loop on LiDAR scans
                     (reads them with robokit.mapping.corridor_scan)
"""
from .corridor_centering import CenteringResult, centering_command, move_to_middle_line
from .dc_motor import (LITTLEDOG_MOTOR, DCMotor, MotorPower, electrical_power, joint_torque, motor_current,
                       reflected_inertia, voltage_for_torque)
from .heading import (HeadingController, design_heading_gains, heading_closed_loop, heading_frequency_response,
                      heading_loop_gain, heading_plant, heading_step_response, loop_metrics)
from .host_link import SetpointChannel
from .joint_servo import (JointLag, ServoResponse, design_servo_gains, discrete_servo_response,
                          joint_lag, joint_plant, pd_servo_step, servo_analysis)
from .path_following import (PathFollower, PathSingularityError, path_following_command, path_following_gains,
                             reference_command, saturate_command)
from .path_geometry import ReferencePoint, VisualPath, path_from_poses, reference_point
from .path_following_loop import (FollowTrace, lateral_step_response, path_following_damping,
                                  path_following_linearisation, path_following_poles, simulate_path_following)
from .servo_loop import (DiscreteServoLoop, ServoAnalysis, discrete_servo_analysis, discrete_servo_loop,
                         servo_closed_loop, servo_frequency_response, servo_loop_gain, servo_plant, servo_step_response)

__all__ = ["HeadingController", "design_heading_gains", "heading_closed_loop", "heading_frequency_response",
           "heading_loop_gain", "heading_plant", "heading_step_response", "loop_metrics",
           "PathFollower", "PathSingularityError", "ReferencePoint", "VisualPath", "path_following_command",
           "path_following_gains", "path_from_poses", "reference_point", "reference_command", "saturate_command",
           "FollowTrace", "lateral_step_response", "path_following_damping", "path_following_linearisation",
           "path_following_poles", "simulate_path_following", "CenteringResult", "centering_command",
           "move_to_middle_line",
           "DiscreteServoLoop", "ServoAnalysis", "discrete_servo_analysis", "discrete_servo_loop", "servo_closed_loop",
           "servo_frequency_response", "servo_loop_gain", "servo_plant", "servo_step_response",
           "LITTLEDOG_MOTOR", "DCMotor", "MotorPower", "electrical_power", "joint_torque", "motor_current",
           "reflected_inertia", "voltage_for_torque",
           "JointLag", "ServoResponse", "design_servo_gains", "discrete_servo_response",
           "joint_lag", "joint_plant", "pd_servo_step", "servo_analysis", "SetpointChannel"]
