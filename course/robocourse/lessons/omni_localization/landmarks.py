"""The bird's-eye view of the map's landmarks (lesson 02's paper, Fig. 8).

Li et al. (2011), Sec. "Experimental results": "the points in the map denotes bird's-eye view of the
landmarks, which represent occupied regions corresponding to objects such as chairs, shelves, desks
and computers in the scene". The paper does not say how the points were placed. Our map keeps each
node's SIFT features as bearings (unit rays from the omni camera), without depth; two nodes that see
the same feature fix it where their rays cross. :func:`landmark_map` matches every node with the next
one along the tour (the ratio test of the fine stage), turns each matched pair of bearings into two
rays in the map's frame and keeps their crossing when the rays meet ahead of both nodes at a clear
angle.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] R. Hartley and A. Zisserman, *Multiple View Geometry in Computer Vision*, 2nd ed., Cambridge
   University Press, 2004 (Sec. 12.2, triangulation from two rays).
"""
from __future__ import annotations

import numpy as np

from robokit.geometry.planar import cross_rays
from robokit.mapping import OMNI_RATIO, TopologicalMap
from robokit.sim import OmniCamera
from robokit.sim.omni import as_omni_camera
from robokit.validation import as_positive, describe

__all__ = ["landmark_map"]


def _world_azimuths(tmap: TopologicalMap, camera: OmniCamera, node: int, rows: np.ndarray) -> np.ndarray:
    """Azimuths in the map's frame of node ``node``'s feature bearings ``rows`` (body frame via the mount)."""
    a = tmap.offsets[node]
    body = tmap.bearings[a + rows] @ camera.mount[:3, :3].T
    return tmap.poses[node, 2] + np.arctan2(body[:, 1], body[:, 0])


def landmark_map(tmap: TopologicalMap, camera: OmniCamera, *, ratio: float = OMNI_RATIO, min_angle: float = 0.26,
                 max_range: float = 6.0) -> tuple[np.ndarray, np.ndarray]:
    """Landmark positions (x, y) from the bearings two consecutive nodes share.

    Parameters
    ----------
    tmap : robokit.mapping.TopologicalMap
        With at least two nodes; its poses place the rays (e.g. the relaxed map).
    camera : robokit.sim.OmniCamera
        The camera of the map's images (its mount turns the bearings into the robot's frame).
    ratio : float, default 0.7
        The SIFT distance-ratio bound (as the fine stage).
    min_angle : float, default 0.26
        Radians (15 deg): the narrowest angle between two rays whose crossing is kept.
    max_range : float, default 6.0
        Metres: the farthest a crossing may lie from either node.

    Returns
    -------
    points : numpy.ndarray, shape (M, 2)
        Landmarks in the map's frame.
    pairs : numpy.ndarray of int, shape (M, 2)
        The two nodes that fixed each one.

    Raises
    ------
    TypeError, ValueError
        For a bad map, camera or bound (the error names it).

    Notes
    -----
    Li et al. (2011), Fig. 8 (the landmarks drawn from above); the crossing of two rays as in
    Hartley and Zisserman (2004), Sec. 12.2, here in the plane: the height of a feature is not used.

    Examples
    --------
    >>> from robocourse.lessons.omni_localization.experiment import office_setup
    >>> setup = office_setup(fast=True)
    >>> points, pairs = landmark_map(setup.relaxed, setup.camera)
    >>> points.shape[1], bool(np.all(pairs[:, 1] == pairs[:, 0] + 1))
    (2, True)
    """
    if not isinstance(tmap, TopologicalMap):
        raise TypeError(f"tmap: expected a robokit.mapping.TopologicalMap, got {describe(tmap)}")
    if len(tmap) < 2:
        raise ValueError(f"tmap: expected a map with at least two nodes, got {len(tmap)}")
    camera = as_omni_camera(camera)
    ratio = as_positive(ratio, "ratio")
    if ratio > 1:
        raise ValueError(f"ratio: expected a value in (0, 1], got {ratio}")
    min_angle = as_positive(min_angle, "min_angle")
    if min_angle >= np.pi / 2:
        raise ValueError(f"min_angle: expected an angle in (0, pi/2), got {min_angle}")
    max_range = as_positive(max_range, "max_range")
    points, pairs = [], []
    for i in range(len(tmap) - 1):
        _, found = tmap.match_counts(tmap.node_features(i + 1).descriptors, [i], ratio=ratio)
        m = found[0]
        if len(m) == 0:
            continue
        th_i = _world_azimuths(tmap, camera, i, m.train)          # the node matched against (train side)
        th_j = _world_azimuths(tmap, camera, i + 1, m.query)
        p_i, p_j = tmap.poses[i, :2], tmap.poses[i + 1, :2]
        d_i = np.column_stack([np.cos(th_i), np.sin(th_i)])
        d_j = np.column_stack([np.cos(th_j), np.sin(th_j)])
        s, t, cross = cross_rays(p_i, d_i, p_j, d_j)             # along each node's ray; sin of their angle
        keep = (np.abs(cross) >= np.sin(min_angle)) & (s > 0) & (t > 0) & (s <= max_range) & (t <= max_range)
        points.append(p_i + s[keep, None] * d_i[keep])
        pairs.append(np.tile([i, i + 1], (int(keep.sum()), 1)))
    if not points:
        return np.zeros((0, 2)), np.zeros((0, 2), int)
    return np.vstack(points), np.vstack(pairs).astype(int)
