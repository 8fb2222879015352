"""Visualisation: meshcat 3D scenes that work live and as static offline HTML, and matplotlib maps.

* :class:`Scene` - records meshcat commands; ``show()`` / ``save_html()`` with no server.
* :mod:`robokit.viz.scene3d` - ``add_world`` (textured), ``add_camera`` (frustum),
  ``add_trajectory``, ``add_graph``, ``add_image``, ``add_particles``, ``add_landmarks`` (covariance ellipsoids).
* :mod:`robokit.viz.framing` - the viewer's camera: ``frame`` (look at the box around the objects,
  ``Scene.bounding_box``, from a direction, filling the view), ``look_from`` (from a given point).
* :mod:`robokit.viz.animation` - ``animate_tracks`` (the one player: positions, turns and scales per
  frame), ``animate_poses`` (one object moving), ``animate_snapshots`` (objects shown in turn, e.g. a
  particle cloud after each update).
* :mod:`robokit.viz.legged` - LittleDog: ``add_littledog``, ``pose_littledog``, ``joint_path``,
  ``animate_trial`` (a trial log replayed with support polygon, centre of mass and foot forces).
* :mod:`robokit.viz.legged_plots` - ``plot_gait_diagram``, ``plot_joint_tracking``,
  ``plot_foot_forces``, ``plot_support``, ``support_outline``.
* :mod:`robokit.viz.maps` - bird's-eye matplotlib figures: ``plot_footprint``, ``plot_scan``,
  ``plot_trajectory``, ``plot_graph``, ``plot_occupancy``, ``plot_covariance``.
* :mod:`robokit.viz.widgets` - ``slider``: a live ipywidgets slider, pre-computed when headless.
"""
from .maps import map_axes, plot_covariance, plot_footprint, plot_graph, plot_occupancy, plot_scan, plot_trajectory
from .scene import Scene, viewer_javascript
from .animation import animate_poses, animate_snapshots, animate_tracks
from .scene3d import add_camera, add_graph, add_image, add_landmarks, add_particles, add_trajectory, add_world
from .framing import fit_view, look_from
from .widgets import slider, static_slider_html
from .legged_plots import plot_foot_forces, plot_gait_diagram, plot_joint_tracking, plot_support, support_outline
from .legged import add_littledog, animate_trial, joint_path, pose_littledog

__all__ = ["Scene", "viewer_javascript", "add_world", "add_camera", "add_trajectory", "add_particles",
           "add_landmarks", "animate_poses", "animate_snapshots", "look_from", "fit_view", "add_graph", "add_image", "plot_graph", "map_axes", "plot_footprint", "plot_scan", "plot_trajectory",
           "plot_occupancy", "plot_covariance", "slider", "static_slider_html", "animate_tracks",
           "add_littledog", "pose_littledog", "joint_path", "animate_trial", "plot_gait_diagram", "plot_joint_tracking",
           "plot_foot_forces", "plot_support", "support_outline"]
