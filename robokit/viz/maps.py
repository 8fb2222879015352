"""Matplotlib helpers for bird's-eye maps: footprints, scans, trajectories, occupancy grids.

Every helper draws on a given ``matplotlib.axes.Axes`` (or a new one), labels the axes in metres
and keeps the aspect ratio equal, so maps from different lessons look alike.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..sim.lidar import scan_points
from ..sim.world import World
from ..validation import as_array, as_points, as_int, as_positive, as_text

__all__ = ["map_axes", "plot_footprint", "plot_scan", "plot_trajectory", "plot_graph", "as_graph", "plot_occupancy",
           "plot_covariance"]


def map_axes(ax: Any = None, title: str | None = None, figsize: tuple = (7, 5)):
    """Return ``ax`` (or a new one) set up for a map: equal aspect, x/y labels in metres.

    Parameters
    ----------
    ax : matplotlib.axes.Axes, optional
    title : str, optional
    figsize : tuple, default (7, 5)
        Size of a new figure (inches).

    Returns
    -------
    matplotlib.axes.Axes

    Notes
    -----
    Course convention (LESSON_GUIDE.md: "every figure has labelled axes and units").
    """
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=figsize)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if title:
        ax.set_title(title)
    return ax


def plot_footprint(world: World, ax: Any = None, color: str = "k", **kwargs: Any):
    """Draw a world's wall segments (its 2D footprint) from above.

    Returns
    -------
    matplotlib.axes.Axes

    Notes
    -----
    The footprint is the world sliced at the LiDAR height (:meth:`robokit.sim.World.slice`).

    Examples
    --------
    >>> from robokit import sim
    >>> from robokit.viz import plot_footprint
    >>> ax = plot_footprint(sim.box_room())          # a 6 m x 4 m room seen from above
    >>> ax.get_title(), ax.get_xlabel(), bool(ax.get_xlim()[1] > 6)
    ('box_room: footprint', 'x [m]', True)
    """
    from matplotlib.collections import LineCollection

    if not isinstance(world, World):
        raise TypeError(f"world: expected a robokit.sim World, got {type(world).__name__}")
    ax = map_axes(ax, kwargs.pop("title", f"{world.name}: footprint"))
    ax.add_collection(LineCollection(world.segments, colors=color, linewidths=kwargs.pop("linewidth", 1.5), **kwargs))
    x0, y0, x1, y1 = world.bounds
    pad = 0.03 * max(x1 - x0, y1 - y0)
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad, y1 + pad)
    return ax


def plot_scan(ranges: Any, sensor_pose: Any, angles: Any, ax: Any = None, color: str = "tab:red",
              rays: bool = False):
    """Draw a LiDAR scan's end points (and optionally its rays) in the world frame.

    Parameters
    ----------
    ranges : array_like (B,)
        Ranges; ``inf`` returns are skipped.
    sensor_pose : array_like (3,)
        Sensor pose ``[x, y, theta]``.
    angles : array_like (B,)
        Beam angles in the sensor frame (``Lidar.angles``).

    Returns
    -------
    matplotlib.axes.Axes

    Examples
    --------
    >>> from robokit import sim
    >>> from robokit.viz import plot_scan
    >>> lidar, world, pose = sim.Lidar(beams=90), sim.box_room(), [2.0, 1.5, 0.0]
    >>> ax = plot_scan(lidar.scan(world, pose), lidar.sensor_pose(pose), lidar.angles)
    >>> len(ax.lines[0].get_xdata())                # every beam hits a wall of the closed room
    90
    """
    p = as_array(sensor_pose, "sensor_pose", shape=(3,))
    pts = scan_points(ranges, p, angles)
    ax = map_axes(ax)
    if rays and len(pts):
        from matplotlib.collections import LineCollection

        ax.add_collection(LineCollection([[p[:2], q] for q in pts], colors=color, alpha=0.15, linewidths=0.5))
    ax.plot(pts[:, 0], pts[:, 1], ".", ms=3, color=color, label="scan")
    ax.plot(p[0], p[1], "o", color=color)
    ax.arrow(p[0], p[1], 0.4 * np.cos(p[2]), 0.4 * np.sin(p[2]), width=0.03, color=color)
    return ax


def plot_trajectory(poses: Any, ax: Any = None, label: str | None = None, every: int = 0, **kwargs: Any):
    """Draw a planar trajectory ``(N, 3)``; with ``every > 0`` also heading arrows every ``every`` poses.

    Parameters
    ----------
    poses : array_like (N, 3)
    ax : matplotlib.axes.Axes, optional
    label : str, optional
    every : int, default 0
    **kwargs
        Passed to ``Axes.plot`` (colour, line width, ...).

    Returns
    -------
    matplotlib.axes.Axes

    Notes
    -----
    Bird's-eye trajectory plots as in Se, Lowe & Little (2002), Fig. 2.

    Examples
    --------
    >>> from robokit.viz import plot_trajectory
    >>> ax = plot_trajectory([[0.0, 0.0, 0.0], [1.0, 0.0, 0.5], [2.0, 1.0, 1.0]], label="truth", every=1)
    >>> ax.lines[0].get_label(), ax.get_aspect()
    ('truth', 1.0)
    """
    P = as_points(poses, "poses", 3, min_count=1)
    label = None if label is None else as_text(label, "label")
    every = as_int(every, "every", minimum=0)
    ax = map_axes(ax)
    line, = ax.plot(P[:, 0], P[:, 1], label=label, **kwargs)
    if every:
        sel = P[::every]
        ax.quiver(sel[:, 0], sel[:, 1], np.cos(sel[:, 2]), np.sin(sel[:, 2]), color=line.get_color(),
                  angles="xy", scale_units="xy", scale=4, width=0.004)
    return ax


def as_graph(poses: Any, edges: Any) -> tuple[np.ndarray, np.ndarray]:
    """``poses`` (N, 3) and ``edges`` (M, 2) node indices, checked (errors name both)."""
    P = as_points(poses, "poses", 3, min_count=1)
    E = as_array(edges, "edges", dtype=np.int64)
    E = E.reshape(0, 2) if E.size == 0 else as_array(E, "edges", shape=(None, 2), dtype=np.int64)
    if E.size and (E.min() < 0 or E.max() >= len(P)):
        raise ValueError(f"poses, edges: expected edges between the {len(P)} poses (indices in [0, {len(P)})), "
                         f"got indices {E.min()}..{E.max()}")
    return P, E


def plot_graph(poses: Any, edges: Any, ax: Any = None, label: str | None = None, highlight: Any = None,
               **kwargs: Any):
    """Draw a pose graph: nodes as dots, edges as lines; ``highlight`` edges (bool mask) drawn dashed.

    Parameters
    ----------
    poses : array_like (N, 3)
        Node poses ``[x, y, theta]``.
    edges : array_like of int (M, 2)
        Node index pairs.
    ax : matplotlib.axes.Axes, optional
    label : str, optional
    highlight : array_like of bool (M,), optional
        Edges to draw dashed (e.g. loop closures).
    **kwargs
        Passed to ``Axes.plot`` for the nodes and edges (colour, ...).

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    ValueError, TypeError
        For malformed poses, edges to missing nodes or a mask of another length.

    Notes
    -----
    The topological map as a graph of places and relations (lesson 02's paper, Sec. "Environment
    map", Fig. 1 and Fig. 8).

    Examples
    --------
    >>> from robokit.viz import plot_graph
    >>> ax = plot_graph([[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 1], [1, 2], [2, 0]], label="map",
    ...                 highlight=[False, False, True])
    >>> len(ax.lines), ax.lines[0].get_label()
    (3, 'map')
    """
    P, E = as_graph(poses, edges)
    mask = np.zeros(len(E), bool) if highlight is None else as_array(highlight, "highlight", shape=(len(E),),
                                                                     dtype=bool)
    label = None if label is None else as_text(label, "label")
    ax = map_axes(ax)
    nodes, = ax.plot(P[:, 0], P[:, 1], "o", ms=3, label=label, **kwargs)
    for dashed in (False, True):
        sel = E[mask == dashed]
        if len(sel):
            xy = np.full((3 * len(sel), 2), np.nan)
            xy[0::3], xy[1::3] = P[sel[:, 0], :2], P[sel[:, 1], :2]
            ax.plot(xy[:, 0], xy[:, 1], "--" if dashed else "-", lw=0.8, color=nodes.get_color())
    return ax


def plot_occupancy(grid: Any, origin: Any, resolution: float, ax: Any = None, cmap: str = "gray_r",
                   colorbar: bool = True):
    """Show an occupancy grid: ``grid[i, j]`` is P(occupied) of the cell at ``origin + (j, i) * resolution``.

    Parameters
    ----------
    grid : array_like (rows, cols)
        Probabilities in [0, 1] (e.g. :attr:`robokit.mapping.OccupancyGrid.probability`, where an
        unknown cell is 0.5).
    origin : array_like (2,)
        World (x, y) of the lower-left corner of cell (0, 0).
    resolution : float
        Cell size in metres.

    Returns
    -------
    matplotlib.axes.Axes

    Notes
    -----
    Occupancy grid maps: Thrun, Burgard & Fox (2005), Ch. 9; row 0 is drawn at the bottom
    (``origin="lower"``) so the map is not upside down.

    Examples
    --------
    >>> from robokit.viz import plot_occupancy
    >>> ax = plot_occupancy([[0.0, 1.0, 0.5], [0.2, 0.9, 0.5]], (-1.0, 0.0), 0.5, colorbar=False)
    >>> [float(e) for e in ax.images[0].get_extent()]      # x from -1 m, 3 cells of 0.5 m; y 2 rows
    [-1.0, 0.5, 0.0, 1.0]
    """
    import matplotlib as mpl

    G = as_array(grid, "grid", ndim=2, min_size=1)
    if np.any((G < 0) | (G > 1)):
        raise ValueError(f"grid: expected probabilities in [0, 1], got values in [{G.min():.3g}, {G.max():.3g}]")
    o = as_array(origin, "origin", shape=(2,))
    r = as_positive(resolution, "resolution")
    ax = map_axes(ax)
    if not isinstance(cmap, str) or cmap not in mpl.colormaps:
        raise ValueError(f"cmap: expected a matplotlib colormap name, got {cmap!r}")
    cm = mpl.colormaps[cmap]
    extent = (o[0], o[0] + G.shape[1] * r, o[1], o[1] + G.shape[0] * r)
    im = ax.imshow(G, origin="lower", extent=extent, cmap=cm, vmin=0, vmax=1,
                   interpolation="nearest")
    if colorbar:
        ax.figure.colorbar(im, ax=ax, label="P(occupied)")
    return ax


def plot_covariance(mean: Any, cov: Any, ax: Any = None, nsigma: float = 1.0, **kwargs: Any):
    """Draw the ``nsigma`` ellipse of a 2x2 covariance around ``mean`` (e.g. a landmark's X-Z uncertainty).

    Parameters
    ----------
    mean : array_like, shape (2,)
    cov : array_like, shape (2, 2)
        Symmetric positive semi-definite.
    ax : matplotlib.axes.Axes, optional
    nsigma : float, default 1
        Ellipse size in standard deviations.
    **kwargs
        Passed to ``matplotlib.patches.Ellipse`` (colour, line width, ...).

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    ValueError
        For wrong shapes, non-finite values or a covariance with a negative eigenvalue.

    Notes
    -----
    Se, Lowe & Little (2002), Sec. 3.6, Fig. 2: one-standard-deviation ellipses in the bird's-eye view.

    Examples
    --------
    >>> from robokit.viz import plot_covariance
    >>> ax = plot_covariance([1.0, 2.0], [[0.04, 0.0], [0.0, 0.01]], nsigma=2)
    >>> ellipse = ax.patches[0]                      # full axes 2 * 2 sigma: 0.8 m by 0.4 m
    >>> round(float(ellipse.width), 3), round(float(ellipse.height), 3)
    (0.8, 0.4)
    """
    from matplotlib.patches import Ellipse

    m = as_array(mean, "mean", shape=(2,))
    C = as_array(cov, "cov", shape=(2, 2))
    lam, V = np.linalg.eigh((C + C.T) / 2)
    if lam.min() < -1e-12:
        raise ValueError("cov: expected a positive semi-definite matrix")
    s = as_positive(nsigma, "nsigma")
    w, h = 2 * s * np.sqrt(np.clip(lam[::-1], 0, None))
    angle = np.degrees(np.arctan2(V[1, 1], V[0, 1]))
    ax = map_axes(ax)
    ax.add_patch(Ellipse(m, w, h, angle=angle, fill=False, **kwargs))
    return ax
