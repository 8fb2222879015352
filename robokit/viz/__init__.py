"""Visualisation: meshcat 3D scenes that work live and as static offline HTML, and matplotlib figures.

scene         Scene: meshcat commands recorded; show() and save_html() with no server
scene3d       what a scene draws: textured worlds, camera frustums, trajectories, graphs, images,
              particles, landmark ellipsoids
framing       the viewer's camera: fit_view on the box around what the text talks about, look_from
animation     the one animation player: poses, snapshots (a particle cloud after each update)
legged        the LittleDog in a scene, a trial log replayed, terrain boards
legged_plots  gait diagram, joint tracking, foot forces, the support polygon
maps          bird's-eye figures: footprints, scans, trajectories, graphs, grids, covariance ellipses
widgets       slider: live in JupyterLab, pre-computed figures when headless
"""
from .scene import Scene
from .scene3d import add_camera, add_graph, add_image, add_landmarks, add_particles, add_trajectory, add_world
from .framing import fit_view, look_from
from .animation import animate_poses, animate_snapshots, animate_tracks
from .legged import add_littledog, add_terrain, animate_trial
from .legged_plots import plot_foot_forces, plot_gait_diagram, plot_joint_tracking, plot_support
from .maps import plot_covariance, plot_footprint, plot_graph, plot_occupancy, plot_scan, plot_trajectory
from .widgets import slider

__all__ = ["Scene", "add_camera", "add_graph", "add_image", "add_landmarks", "add_particles", "add_trajectory",
           "add_world", "fit_view", "look_from", "animate_poses", "animate_snapshots", "animate_tracks",
           "add_littledog", "add_terrain", "animate_trial", "plot_foot_forces", "plot_gait_diagram", "plot_joint_tracking",
           "plot_support", "plot_covariance", "plot_footprint", "plot_graph", "plot_occupancy", "plot_scan",
           "plot_trajectory", "slider"]
