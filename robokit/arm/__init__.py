"""Robot-arm kinematics (lesson 06): DH chains, Jacobians, analytic and numerical IK of redundant arms.

Rigid transforms, rotations and the pose error come from :mod:`robokit.geometry`.

dh                    DH and modified-DH link transforms
chain                 Chain: forward kinematics of a DH table, one configuration or a batch; limits
robots                two real arms with their published parameters (KUKA iiwa14, Franka Panda)
jacobian              the geometric Jacobian, manipulability, a plain DH table's FK and Jacobian
limits                joint-limit distance, its gradient, weighted-least-norm weights
result                IK results and their FK check
srs                   the S-R-S decomposition step by step: wrist centre, elbow, shoulder
srs_geometry          the arm angle and Shimizu's coefficients, on triples
arm_angle_intervals   Shimizu's exact feasible arm-angle intervals, and the analytic IK step by step
ik_analytic           the analytic arm-angle IK of S-R-S arms, one target or a batch
ik_steps              the numeric IK's step rules: damped least squares, gradient projection (Dubey),
                      weighted least norm (Chan)
ik_numeric            numeric IK on any chain, with random restarts, one target or a batch
ik_readable           the numeric IK for one target as a plain loop
position_posture      Huang & Jiang's position-posture reduction worked through, two readings
jit                   numba, and the on-disk cache of the compiled kernels
chain_kernels         compiled FK, Jacobian and pose error of one configuration
srs_kernels           compiled analytic IK: the arm-angle intervals, the search, the solve
numeric_kernels       compiled numeric IK search
"""
from .dh import dh_transform, mdh_transform
from .chain import Chain, LIMIT_TOL, chain_from_table, dh_fk
from .robots import iiwa14, panda
from .jacobian import dh_jacobian, geometric_jacobian, manipulability
from .limits import limit_distance_gradient
from .result import IKBatchResult, IKResult
from .srs import elbow_angle, shoulder_angles, wrist_centre
from .arm_angle_intervals import feasible_arm_angles, ik_srs_readable
from .ik_analytic import SRSArm, arm_angle, ik_srs, ik_srs_batch, ik_srs_branches
from .ik_steps import null_space_step
from .ik_numeric import ik_numeric, ik_numeric_batch
from .position_posture import ik_position_posture

__all__ = ["dh_transform", "mdh_transform", "Chain", "LIMIT_TOL", "chain_from_table", "dh_fk", "iiwa14", "panda",
           "dh_jacobian", "geometric_jacobian", "manipulability", "limit_distance_gradient", "IKBatchResult",
           "IKResult", "elbow_angle", "shoulder_angles", "wrist_centre", "feasible_arm_angles", "ik_srs_readable",
           "SRSArm", "arm_angle", "ik_srs", "ik_srs_batch", "ik_srs_branches", "null_space_step", "ik_numeric",
           "ik_numeric_batch", "ik_position_posture"]
