"""Simulation: textured worlds, cameras (pinhole, stereo, omnidirectional), 2D LiDAR, motion, recorded runs.

Everything a lesson needs to produce images, depth, scans and ground truth without a dataset. A
world is textured planar rectangles plus its 2D footprint (right-handed, z up, floor at z = 0);
robot poses are ``[x, y, theta]`` and sensors are placed by a 4x4 ``T_world_cam`` (optical frame).

world           World: surfaces, footprint, free space, the 2D layout at a height
build           the builder that makes a world's walls, doors, furniture and posters
textures        procedural and photographic textures, lighting changes
textures_outdoor  grass, gravel, bark and sky for the outdoor field
worlds          the papers' worlds: box_room, lab_room (Se et al.), long_corridor (Ge et al.), office_floor
worlds_outdoor  the outdoor field of lesson 05 (Hamid et al.) and any 2D obstacle layout as a world
layout          Layout: walls, circles and boxes in 2D with the course's one ray caster
camera          PinholeCamera and StereoRig: projection, back-projection, rendering, mounts
omni            OmniCamera: the unified catadioptric model of lesson 02
render          the z-buffered renderer of textured rectangles
lidar           Lidar: a 2D laser scanner on the world's layout
vehicle         unicycle arcs, differential drive, skid steer and its inverse
motion          trajectories (the papers' laps, tours and corridor drives) and odometry noise
runs            record / record_stream: a trajectory driven and every sensor logged (cached)
view_matches    the check that rendered views give true SIFT matches (pinhole and omni)
"""
from .world import World
from .textures import illuminate, photo
from .worlds import box_room, lab_room, long_corridor, office_floor
from .worlds_outdoor import field_world, open_field
from .layout import Layout
from .camera import Frame, PinholeCamera, StereoRig, camera_mount
from .omni import OmniCamera
from .lidar import Lidar
from .vehicle import diff_drive_velocities, skid_steer_velocities, skid_steer_wheel_speeds, unicycle_step
from .motion import (OFFICE_TEST_POSES, Trajectory, corridor_path, lab_lap, noisy_odometry, odometry_covariance,
                     odometry_increment, office_tour, sample_motion_model_odometry, waypoint_path)
from .runs import Run, describe_sensor, record, record_stream
from .view_matches import omni_ground_truth_inliers, omni_view_pair, sift_view_pair

__all__ = ["World", "illuminate", "photo", "box_room", "lab_room", "long_corridor", "office_floor", "field_world",
           "open_field", "Layout", "Frame", "PinholeCamera", "StereoRig", "camera_mount", "OmniCamera", "Lidar",
           "diff_drive_velocities", "skid_steer_velocities", "skid_steer_wheel_speeds", "unicycle_step",
           "OFFICE_TEST_POSES", "Trajectory", "corridor_path", "lab_lap", "noisy_odometry", "odometry_covariance",
           "odometry_increment", "office_tour", "sample_motion_model_odometry", "waypoint_path", "Run",
           "describe_sensor", "record", "record_stream", "omni_ground_truth_inliers", "omni_view_pair",
           "sift_view_pair"]
