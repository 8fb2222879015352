"""Mapping: landmark databases, pose graphs, topological maps, occupancy grids, the corridor on one scan.

landmarks            Se et al.'s landmark database: backward transformation with first-order covariance
                     (Sec. 3.4) and the Kalman fusion of re-observed landmarks (Sec. 3.5)
pose_graph           planar pose graphs: nodes, edges, connectivity, a graph from odometry
pose_graph_optimize  g2o's SE(2) error, cost and sparse Jacobian; Gauss-Newton and scipy least squares
relaxation           lesson 02's relaxation of a pose graph (Duckett et al., Eqs. (1)-(3))
g2o                  the g2o file format, read and written
manhattan            generated Manhattan-world pose graphs with ground truth
omni_views           an omni image's hue histogram, SIFT features and bearings; two views' relative pose
topological          the topological map: nodes, edges, a descriptor index per node, coarse and fine search
topological_build    the map from a recorded run: where nodes start (local maps) and loop closure
occupancy_grid       log odds per cell, map_server's thresholds, the likelihood field of a range finder
grid_mapping         Thrun et al.'s mapping with known poses (Tables 9.1-9.2) beside its readable version
map_server           ROS map_server's PGM + YAML files
corridor_areas       one scan's invalid areas and their angle bounds (Ge et al. 2023, Eqs. (6)-(9))
corridor_scan        wall distances, the corridor axis, width and middle-line conditions (Eqs. (1)-(4))
hybrid_map           keyframes geo-tagged with the grid pose by time (Eq. (18))
"""
from .landmarks import LandmarkMap, kalman_fuse, transform_covariance
from .pose_graph import DisconnectedGraphError, PoseGraph, pose_graph_from_odometry
from .pose_graph_optimize import PoseGraphResult, optimize_pose_graph, pose_graph_cost
from .relaxation import RelaxationResult, relax, relax_sweep
from .g2o import G2OFormatError, read_g2o, write_g2o
from .manhattan import manhattan_world_graph
from .omni_views import OmniView, RelativePose, omni_view, relative_pose
from .topological import EmptyMapError, LOOP_EDGE, OMNI_RATIO, TopologicalMap
from .topological_build import build_topological_map
from .occupancy_grid import (LikelihoodField, LOG_ODDS_MAX, LOG_ODDS_MIN, OccupancyGrid, likelihood_field, log_odds,
                             probability)
from .grid_mapping import (L_FREE, L_OCC, inverse_range_sensor_model, occupancy_grid_mapping,
                           occupancy_grid_mapping_readable, update_log_odds)
from .map_server import MapFileError, load_map, save_map
from .corridor_areas import EmptyScanError, invalid_areas, theta_limits, theta_limits_geometric
from .corridor_scan import (CorridorState, NoWallError, corridor_axis, corridor_axis_readable, corridor_state, middle_line_condition,
                            wall_distances, width_condition)
from .hybrid_map import geo_index, geo_tag

__all__ = ["LandmarkMap", "kalman_fuse", "transform_covariance", "DisconnectedGraphError", "PoseGraph",
           "pose_graph_from_odometry", "PoseGraphResult", "optimize_pose_graph", "pose_graph_cost",
           "RelaxationResult", "relax", "relax_sweep", "G2OFormatError", "read_g2o", "write_g2o",
           "manhattan_world_graph", "OmniView", "RelativePose", "omni_view", "relative_pose", "EmptyMapError",
           "LOOP_EDGE", "OMNI_RATIO", "TopologicalMap", "build_topological_map", "LikelihoodField", "LOG_ODDS_MAX",
           "LOG_ODDS_MIN",
           "OccupancyGrid", "likelihood_field", "log_odds", "probability", "L_FREE", "L_OCC",
           "inverse_range_sensor_model", "occupancy_grid_mapping", "occupancy_grid_mapping_readable",
           "update_log_odds", "MapFileError", "load_map", "save_map", "EmptyScanError", "invalid_areas",
           "theta_limits", "theta_limits_geometric", "CorridorState", "NoWallError", "corridor_axis", "corridor_axis_readable",
           "corridor_state", "middle_line_condition", "wall_distances", "width_condition", "geo_index", "geo_tag"]
