"""Mapping: the Kalman-filtered landmark database of Se, Lowe & Little (Sec. 3), and planar pose graphs.

:mod:`.landmarks` holds the backward transformation with first-order covariance
(:func:`transform_covariance`) and the database (:class:`LandmarkMap`). The papers' pose
``[p, q, theta]`` acting on points (``pqt_robot_to_world``, ``pqt_transform_xz`` ...) is in
:mod:`robokit.geometry`. Never imports ``viz``; only the topological map uses ``sim`` (below).

Pose graphs (lesson 02's loop-closure alignment): :mod:`.pose_graph` (the graph, its connectivity,
a builder from odometry), :mod:`.pose_graph_optimize` (g2o's error, cost and Jacobian; least squares),
:mod:`.relaxation` (the paper's relaxation, after Duckett et al.), :mod:`.g2o` (the g2o file format)
and :mod:`.manhattan` (generated graphs with ground truth).

Topological maps (lesson 02's environment map): :mod:`.omni_views` (an image's hue histogram, SIFT
features and bearings; the relative pose of two views), :mod:`.topological` (the map: nodes, edges,
KD-trees, the coarse and fine searches), :mod:`.local_maps` (when a key image starts a node: the
paper's local-map partitioning) and :mod:`.topological_build` (the map from a recorded run, loop
closure). Unlike the rest of mapping they use
:mod:`robokit.sim`'s omni camera model (its rays and mount) and odometry noise model, never its
renderer.

Occupancy grids (lesson 03's corridor map): :mod:`.occupancy_grid` (log odds per cell, the
free/occupied/unknown reading with map_server's thresholds, the likelihood field of a range finder).

Lesson 03's corridor (Ge et al. 2023): :mod:`.corridor_areas` (a scan's invalid areas, Eq. (9), and
the bounds of Eqs. (6)-(8)), :mod:`.corridor_scan` (wall distances, the corridor axis, the width and
middle-line conditions, Eqs. (1)-(4), and one scan's :class:`CorridorState`) and :mod:`.hybrid_map`
(keyframes geo-tagged with the grid-map pose by time, Eq. (18)).
"""
from .corridor_areas import EmptyScanError, as_scan, invalid_areas, theta_limits, theta_limits_geometric
from .corridor_scan import (CorridorState, NoWallError, corridor_axis, corridor_state, door_sides,
                            middle_line_condition, wall_distances, width_condition)
from .hybrid_map import GeoIndex, geo_index, geo_tag
from .g2o import G2OFormatError, read_g2o, write_g2o
from .grid_mapping import (L_FREE, L_OCC, inverse_range_sensor_model, occupancy_grid_mapping,
                           occupancy_grid_mapping_readable, update_log_odds)
from .landmarks import LandmarkMap, kalman_fuse, transform_covariance
from .map_server import FREE_VALUE, OCCUPIED_VALUE, UNKNOWN_VALUE, MapFileError, load_map, save_map
from .manhattan import manhattan_world_graph
from .pose_graph import (DisconnectedGraphError, PoseGraph, as_pose_graph, require_connected, edge_variances, is_connected,
                         pose_graph_from_odometry, positive_definite, unreachable_nodes,
                         information_from_covariance, position_variance)
from .pose_graph_optimize import (PoseGraphResult, optimize_pose_graph, pose_graph_cost, pose_graph_jacobian,
                                  pose_graph_residuals)
from .occupancy_grid import (FREE_THRESHOLD, LOG_ODDS_MAX, LOG_ODDS_MIN, OCCUPIED_THRESHOLD, LikelihoodField,
                             OccupancyGrid, likelihood_field, log_odds, probability)
from .omni_views import OmniView, RelativePose, as_omni_image, omni_view, relative_pose
from .relaxation import RelaxationResult, initial_variances, relax, relax_sweep
from .topological import LOOP_EDGE, ODOMETRY_EDGE, EmptyMapError, TopologicalMap
from .topological_build import Comparison, appearance_changed, local_map_full, select_key_frames
from .topological_build import build_topological_map

__all__ = ["transform_covariance", "LandmarkMap", "kalman_fuse",
           "PoseGraph", "DisconnectedGraphError", "as_pose_graph", "positive_definite", "edge_variances", "unreachable_nodes",
           "is_connected", "require_connected", "pose_graph_from_odometry", "information_from_covariance", "position_variance",
           "pose_graph_residuals", "pose_graph_cost", "pose_graph_jacobian", "PoseGraphResult", "optimize_pose_graph",
           "RelaxationResult", "relax", "relax_sweep", "initial_variances",
           "G2OFormatError", "read_g2o", "write_g2o", "manhattan_world_graph",
           "OmniView", "RelativePose", "as_omni_image", "omni_view", "relative_pose",
           "LOOP_EDGE", "ODOMETRY_EDGE", "EmptyMapError", "TopologicalMap", "Comparison", "appearance_changed",
           "build_topological_map", "local_map_full", "select_key_frames",
           "FREE_THRESHOLD", "OCCUPIED_THRESHOLD", "LOG_ODDS_MIN", "LOG_ODDS_MAX", "log_odds", "probability",
           "OccupancyGrid", "LikelihoodField", "likelihood_field",
           "L_OCC", "L_FREE", "inverse_range_sensor_model", "update_log_odds", "occupancy_grid_mapping",
           "occupancy_grid_mapping_readable", "MapFileError", "save_map", "load_map", "OCCUPIED_VALUE", "FREE_VALUE",
           "UNKNOWN_VALUE",
           "EmptyScanError", "as_scan", "invalid_areas", "theta_limits", "theta_limits_geometric",
           "CorridorState", "NoWallError", "corridor_axis", "corridor_state", "door_sides", "middle_line_condition",
           "wall_distances", "width_condition", "GeoIndex", "geo_index", "geo_tag"]
