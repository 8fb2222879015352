"""Simulation: textured worlds, cameras (pinhole, stereo, omnidirectional), 2D LiDAR, motion, runs.

Everything a lesson needs to produce images, depth, scans and ground truth without any dataset:

Worlds (textured planar rectangles + 2D footprint; world frame right-handed, z up, floor z = 0)
    ``lab_room()``       10 m x 10 m lab with furniture and posters (Se, Lowe & Little 2002)
    ``long_corridor()``  36.10 m x 2.17 m corridor, 0.07 m door recesses (Ge et al. 2023)
    ``office_floor()``   four rooms R1-R4 and a corridor (the environment of lesson 02's paper)
    ``box_room()``       a plain rectangular room
    ``open_field()``     100 m x 60 m grass field with obstacles, a shed, a hedge and a skybox
                         (Hamid et al. 2009); ``field_world(size, circles, boxes)`` builds
                         any 2D obstacle layout, ``scatter_obstacles`` draws one
                         (:mod:`robokit.sim.worlds_outdoor`)
    A :class:`World` has ``surfaces``, ``segments`` (the footprint at ``footprint_height``),
    ``slice(z)``, ``layout(z)``, ``free_space()``, ``is_free(xy)`` and ``info`` (builder facts).

The 2D world (:mod:`robokit.sim.layout`)
    ``Layout(segments, circles, boxes)``: walls, circles ``[x, y, r]`` and rotated boxes
    ``[cx, cy, length, width, yaw]``, with the course's one ray caster ``.raycast(origins, angles,
    max_range, validate=True)`` (one documented tie rule), ``.contains``, ``.clearance`` and
    ``.collides(pose, length, width)``; ``obstacle_array`` checks obstacle arrays, ``box_corners``.
    The LiDAR, lesson 05's field (``robokit.outdoor.Field`` is a Layout) and its sonars use it.

Cameras (placed by a 4x4 ``T_world_cam``; optical frame x right, y down, z forward)
    ``PinholeCamera.from_fov(hfov, width, height)``; ``.K``, ``.project(points, T_world_cam)``,
    ``.backproject(pixels, depth, T_world_cam)``, ``.render(world, T_world_cam) -> Frame(image, depth)``,
    ``.observe(world, robot_pose)`` and ``.transform_at(robot_pose)`` (use ``.mount``, by default
    :func:`camera_mount` 0.8 m high, level).
    ``StereoRig(camera, baseline, trinocular=False)``: ``.render``/``.observe`` return
    ``{"left", "right"[, "top"]}`` frames; ``.disparity(Z) = f B / Z``.
    ``OmniCamera()``: 640x480 unified-model catadioptric camera; ``.project``, ``.rays``,
    ``.backproject``, ``.render`` (depth = range). See :mod:`robokit.sim.omni` for the model.
    ``illuminate(image, gain, offset, gradient)`` or ``render(..., lighting={...})`` for
    lighting changes; ``render(..., noise=2.0, rng=0)`` for pixel noise (grey levels).

LiDAR, vehicles and motion
    ``Lidar(beams=360, r_min=0.15, r_max=8.0, noise=0.0).scan(world, robot_pose)``;
    vehicle kinematics (:mod:`robokit.sim.vehicle`): ``unicycle_step`` (exact arcs),
    ``diff_drive_velocities``, ``skid_steer_velocities`` (ICR expansion ``icr_factor``, Mandow et
    al. 2007, and our slip ratio) and its saturating inverse ``skid_steer_wheel_speeds``; odometry noise
    (:mod:`robokit.sim.motion`, Thrun et al. 2005, Tables 5.5-5.6): ``odometry_increment``,
    ``sample_motion_model_odometry``, ``noisy_odometry``, ``odometry_covariance``; paths
    ``waypoint_path``, ``corridor_path``, ``lab_lap``, ``office_tour`` (and ``OFFICE_TEST_POSES``).

Recorded runs
    ``record(world, path, sensors={"cam": cam, "laser": lidar}, rate=5)`` -> :class:`Run`
    (``t``, ``poses``, ``odometry``, ``images``, ``depths``, ``scans``), cached as ``.npz``; every
    sensor is driven through ``observe(world, robot_pose, rng=...)``; ``record_stream(world, path,
    camera, rate)`` -> :class:`FrameStream`, the same drive with one camera whose images arrive
    as worker processes render them.

Checks
    ``sift_view_pair(world, camera, robot_pose)``: OpenCV SIFT between two views, matches judged
    against the rendered depth (``ground_truth_inliers``); ``omni_view_pair(world, omni, pose1,
    pose2)`` the same for omni views (``omni_ground_truth_inliers``, lesson 02's "matched accurate
    rate").

Example
-------
>>> from robokit.sim import lab_room, PinholeCamera, StereoRig
>>> world = lab_room()
>>> rig = StereoRig(PinholeCamera.from_fov(), baseline=0.12)
>>> views = rig.observe(world, [5.0, 2.0, 1.57])   # robot pose [x, y, theta]
>>> views["left"].image.shape, views["left"].depth.dtype
((480, 640, 3), dtype('float32'))
"""
from .camera import Frame, PinholeCamera, StereoRig, camera_mount
from .view_matches import ViewPairMatches, ground_truth_inliers, omni_ground_truth_inliers, omni_view_pair, sift_view_pair
from .layout import Layout, box_corners, obstacle_array
from .lidar import Lidar, scan_points
from .motion import (OFFICE_TEST_POSES, Trajectory, corridor_path, increment_variances, lab_lap, noisy_odometry,
                     odometry_covariance, odometry_increment, office_tour, sample_motion_model_odometry, waypoint_path)
from .omni import OmniCamera, as_omni_camera, omni_mount
from .runs import FrameStream, Run, describe_sensor, record, record_stream
from .textures import illuminate, photo
from .vehicle import diff_drive_velocities, skid_steer_velocities, skid_steer_wheel_speeds, unicycle_step
from .world import FreeSpace, Surface, World
from .worlds import box_room, lab_room, long_corridor, office_floor
from .worlds_outdoor import field_world, open_field, scatter_obstacles

__all__ = [
    "World", "Surface", "FreeSpace", "box_room", "lab_room", "long_corridor", "office_floor",
    "open_field", "field_world", "scatter_obstacles",
    "Frame", "PinholeCamera", "StereoRig", "camera_mount", "OmniCamera", "omni_mount", "as_omni_camera", "illuminate", "photo",
    "Layout", "box_corners", "obstacle_array", "Lidar", "scan_points",
    "Trajectory", "unicycle_step", "diff_drive_velocities", "skid_steer_velocities", "skid_steer_wheel_speeds",
    "odometry_increment",
    "sample_motion_model_odometry", "noisy_odometry", "waypoint_path", "corridor_path", "lab_lap", "office_tour",
    "OFFICE_TEST_POSES", "increment_variances", "odometry_covariance",
    "Run", "record", "record_stream", "FrameStream", "describe_sensor", "ViewPairMatches", "ground_truth_inliers", "sift_view_pair", "omni_ground_truth_inliers",
    "omni_view_pair",
]
