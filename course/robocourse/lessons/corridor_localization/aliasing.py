"""Plain data for lesson 03's question on LiDAR aliasing: one scan, the corridor's distance grid, three poses.

Assignment 03's written question on laser aliasing runs the student's likelihood field on it (a
cell the grader skips); the distance grid is the true walls' distance from the simulator.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

from robokit.sim.lidar import Lidar
from robokit.sim.worlds import long_corridor
from robocourse.lessons.corridor_localization.mcl_runs import corridor_distance

__all__ = ["aliasing_example"]


def aliasing_example(resolution: float = 0.1) -> dict:
    """A scan at position #6 of lesson 03 and the poses a laser-only filter would confuse it with.

    Parameters
    ----------
    resolution : float, default 0.1
        Cell size (m) of the distance grid.

    Returns
    -------
    dict
        ``ranges``, ``angles`` (360 beams, noise-free, ``inf`` beyond 8 m), ``distance`` (H, W) the
        distance (m) from each cell centre to the nearest wall, clipped at 2 m, ``resolution``,
        ``origin`` (the grid's lower-left corner), and poses ``true`` (where the scan was taken,
        x = 23.0 m on the middle line facing +x), ``look_alike`` (4.5 m further on, where the doors
        repeat) and ``elsewhere`` (x = 14.0 m); all plain lists and floats.

    Raises
    ------
    ValueError
        For a resolution outside [0.01, 1] m.

    Notes
    -----
    Ge et al. (2023), Sec. 4.2 and Fig. 12: geometrically similar areas of the corridor (their #6
    and #7) defeat a LiDAR-only particle filter.

    Examples
    --------
    >>> data = aliasing_example(0.1)
    >>> len(data["ranges"]), len(data["distance"][0]), data["look_alike"][0] - data["true"][0]
    (360, 371, 4.5)
    """
    if isinstance(resolution, bool) or not isinstance(resolution, (int, float)) or not 0.01 <= resolution <= 1.0:
        raise ValueError(f"resolution: expected a cell size between 0.01 and 1 m, got {resolution!r}")
    world, lidar = long_corridor(), Lidar(height=0.45)
    true, look_alike, elsewhere = [23.0, 0.0, 0.0], [27.5, 0.0, 0.0], [14.0, 0.0, 0.0]
    ranges = lidar.scan(world, true)
    distance, (x0, y0) = corridor_distance(resolution)
    return {"ranges": ranges.tolist(), "angles": lidar.angles.tolist(), "distance": distance.round(6).tolist(),
            "resolution": float(resolution), "origin": [float(x0), float(y0)], "true": true, "look_alike": look_alike,
            "elsewhere": elsewhere}
