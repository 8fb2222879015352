"""Mapping: the Kalman-filtered landmark database of Se, Lowe & Little (Sec. 3), and planar pose graphs.

:mod:`.landmarks` holds the backward transformation with first-order covariance
(:func:`transform_covariance`) and the database (:class:`LandmarkMap`). The papers' pose
``[p, q, theta]`` acting on points (``pqt_robot_to_world``, ``pqt_transform_xz`` ...) is in
:mod:`robokit.geometry`. Never imports ``viz`` or ``sim``.

Pose graphs (lesson 02's loop-closure alignment): :mod:`.pose_graph` (the graph, its connectivity,
a builder from odometry), :mod:`.pose_graph_optimize` (g2o's error, cost and Jacobian; least squares),
:mod:`.relaxation` (the paper's relaxation, after Duckett et al.), :mod:`.g2o` (the g2o file format)
and :mod:`.manhattan` (generated graphs with ground truth).
"""
from .g2o import G2OFormatError, read_g2o, write_g2o
from .landmarks import LandmarkMap, kalman_fuse, transform_covariance
from .manhattan import manhattan_world_graph
from .pose_graph import (DisconnectedGraphError, PoseGraph, as_pose_graph, check_connected, edge_variances, is_connected,
                         pose_graph_from_odometry, positive_definite, unreachable_nodes)
from .pose_graph_optimize import (PoseGraphResult, optimize_pose_graph, pose_graph_cost, pose_graph_jacobian,
                                  pose_graph_residuals)
from .relaxation import RelaxationResult, initial_variances, relax, relax_sweep

__all__ = ["transform_covariance", "LandmarkMap", "kalman_fuse",
           "PoseGraph", "DisconnectedGraphError", "as_pose_graph", "positive_definite", "edge_variances", "unreachable_nodes",
           "is_connected", "check_connected", "pose_graph_from_odometry",
           "pose_graph_residuals", "pose_graph_cost", "pose_graph_jacobian", "PoseGraphResult", "optimize_pose_graph",
           "RelaxationResult", "relax", "relax_sweep", "initial_variances",
           "G2OFormatError", "read_g2o", "write_g2o", "manhattan_world_graph"]
