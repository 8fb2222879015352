"""Robot-arm kinematics: DH chains, Jacobians, analytic and numerical inverse kinematics.

Lesson 06 (redundant 7-DOF arms; Huang & Jiang 2013: separation of position and posture). Rigid
transforms, rotations and the pose error come from :mod:`robokit.geometry`.

* :class:`Chain`, :func:`dh_transform`, :func:`mdh_transform` - DH / modified-DH forward kinematics.
* :func:`iiwa14`, :func:`panda` - two real arms with their published parameters.
* :func:`geometric_jacobian`, :func:`manipulability`.
* :func:`wrist_centre`, :func:`elbow_angle`, :func:`shoulder_angles` - the S-R-S decomposition
  step by step; :func:`dh_fk`, :func:`dh_jacobian` - the same for a plain DH table.
* :func:`ik_srs`, :func:`ik_srs_batch`, :func:`ik_srs_branches`, :func:`arm_angle` - the analytic
  arm-angle IK of S-R-S arms (KUKA LBR iiwa); :func:`feasible_arm_angles`, :func:`split_points` -
  Shimizu's exact feasible arm-angle intervals; :func:`ik_srs_readable` - the same search step by step.
* :func:`ik_position_posture` - Huang & Jiang's reduction worked through, in two readings: Newton
  iteration on joints 1-4 for the wrist centre, or ``q3`` as the parameter with ``q1, q2, q4`` in
  closed form; joints 5-7 in closed form.
* :func:`ik_numeric`, :func:`ik_numeric_batch` - damped least squares with null-space gradient
  projection (Dubey) or weighted least norm (Chan), random restarts; any chain.
  :func:`ik_numeric_readable` is the same for one target as a plain loop.
* :func:`pose_error` - :func:`robokit.geometry.pose_error`, re-exported for the lesson.
"""
from ..geometry import pose_error
from .chain import LIMIT_TOL, Chain, chain_from_table, dh_fk
from .arm_angle_intervals import feasible_arm_angles, ik_srs_readable, split_points
from .dh import dh_transform, mdh_transform
from .ik_analytic import SRSArm, arm_angle, ik_srs, ik_srs_batch, ik_srs_branches
from .ik_numeric import ik_numeric, ik_numeric_batch
from .ik_readable import ik_numeric_readable
from .ik_steps import METHODS, dls_step, null_space_step
from .position_posture import ik_position_posture
from .jacobian import dh_jacobian, geometric_jacobian, jacobian_from_frames, manipulability
from .limits import limit_distance_gradient, wln_weights
from .result import IKBatchResult, IKResult, verify
from .robots import iiwa14, panda
from .srs import elbow_angle, shoulder_angles, wrist_centre

__all__ = ["Chain", "dh_transform", "mdh_transform", "iiwa14", "panda", "geometric_jacobian",
           "jacobian_from_frames", "manipulability", "SRSArm", "arm_angle", "ik_srs", "ik_srs_batch",
           "ik_srs_branches", "IKResult", "IKBatchResult", "verify", "pose_error", "METHODS", "dls_step",
           "null_space_step", "ik_numeric", "ik_numeric_batch", "ik_numeric_readable",
           "limit_distance_gradient", "wln_weights", "chain_from_table", "dh_fk", "dh_jacobian", "elbow_angle",
           "shoulder_angles", "wrist_centre", "LIMIT_TOL", "feasible_arm_angles", "split_points",
           "ik_srs_readable", "ik_position_posture"]
