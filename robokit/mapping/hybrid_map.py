"""Geo-tags of the hybrid map: each keyframe gets the grid-map pose at its timestamp (Eq. (18)).

Ge et al. (2023), Sec. 3.4: the image map (keyframes, visual words) and the occupancy grid map are
linked by timestamps; "through time alignment, a keyframe can be associated with the pose
coordinates of the robot", ``GeoIndex_id = {KF_id, Pose_id = (x_k, y_k, theta_k)}`` (Eq. (18)).
The SLAM pose log and the camera are not sampled at the same instants, so the pose at a
keyframe's time is interpolated between the two log entries around it: linearly in ``x, y``, and
along the shorter arc in ``theta`` (ours; the paper leaves the alignment to ROS). Robokit poses are
``[x, y, theta]`` where the paper writes ``(x, z, theta)``.

References
----------
.. [1] Ge, Zhang, Wang, Hu, Wang and Jiang, "Visual-feature-assisted mobile robot localization in
   a long corridor environment", *Frontiers of Information Technology & Electronic Engineering*
   24(6), 2023, doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..geometry import wrap_angle
from ..geometry.planar import as_planar
from ..validation import as_array

__all__ = ["GeoIndex", "geo_tag", "geo_index"]


def _times(value: Any, name: str) -> np.ndarray:
    t = as_array(value, name, ndim=1, min_size=1)
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise ValueError(f"{name}: expected strictly increasing times, got {t[k]} then {t[k + 1]} at index {k + 1}")
    return t


def geo_tag(keyframe_times: Any, pose_times: Any, poses: Any) -> np.ndarray:
    """Poses ``[x, y, theta]`` at the keyframes' times, interpolated in the pose log (Eq. (18)).

    Parameters
    ----------
    keyframe_times : array_like, shape (K,)
        Keyframe timestamps (s), strictly increasing.
    pose_times : array_like, shape (M,)
        Timestamps of the pose log (s), strictly increasing, ``M >= 1``.
    poses : array_like, shape (M, 3)
        The grid-map (SLAM) poses ``[x, y, theta]`` at ``pose_times``.

    Returns
    -------
    numpy.ndarray, shape (K, 3)
        Heading wrapped to ``[-pi, pi)``.

    Raises
    ------
    ValueError
        For NaN or infinite values, times that do not strictly increase, mismatched lengths, or
        a keyframe time outside ``[pose_times[0], pose_times[-1]]`` (no extrapolation).

    Notes
    -----
    Ge et al. (2023), Sec. 3.4, Eq. (18). Between log entries ``i`` and ``i + 1``, with ``f = (t -
    t_i) / (t_{i+1} - t_i)``: ``x = x_i + f (x_{i+1} - x_i)`` (so ``y``), and ``theta = wrap(theta_i
    + f wrap(theta_{i+1} - theta_i))``, the shorter way round.

    Examples
    --------
    >>> geo_tag([0.5, 1.25], [0.0, 1.0, 2.0], [[0, 0, 3.0], [1, 0, -3.0], [1, 2, -3.0]]).round(4).tolist()
    [[0.5, 0.0, -3.1416], [1.0, 0.5, -3.0]]
    """
    tk = _times(keyframe_times, "keyframe_times")
    tp = _times(pose_times, "pose_times")
    P = as_planar(poses, "poses")
    if P.ndim != 2 or len(P) != len(tp):
        raise ValueError(f"poses: expected shape ({len(tp)}, 3), one per pose time, got shape {P.shape}")
    out = (tk < tp[0]) | (tk > tp[-1])
    if out.any():
        raise ValueError(f"keyframe_times: expected times within the pose log [{tp[0]}, {tp[-1]}], "
                         f"got {tk[out][0]}")
    if len(tp) == 1:
        return np.repeat(P, len(tk), axis=0)
    i = np.clip(np.searchsorted(tp, tk, side="right") - 1, 0, len(tp) - 2)
    f = (tk - tp[i]) / (tp[i + 1] - tp[i])
    xy = P[i, :2] + f[:, None] * (P[i + 1, :2] - P[i, :2])
    theta = wrap_angle(P[i, 2] + f * wrap_angle(P[i + 1, 2] - P[i, 2]))    # Eq. (18), shorter arc
    return np.column_stack([xy, theta])


@dataclasses.dataclass(frozen=True)
class GeoIndex:
    """One geo-tag of the hybrid map, ``GeoIndex_id = {KF_id, Pose_id}`` (Ge et al. 2023, Eq. (18)).

    Attributes
    ----------
    keyframe_id : int
        The keyframe's id in the image map.
    pose : numpy.ndarray, shape (3,)
        The grid-map pose ``[x, y, theta]`` at the keyframe's time.
    """

    keyframe_id: int
    pose: np.ndarray


def geo_index(keyframe_ids: Any, keyframe_times: Any, pose_times: Any, poses: Any) -> list[GeoIndex]:
    """The geo-tagged index of Eq. (18): one :class:`GeoIndex` per keyframe.

    Parameters
    ----------
    keyframe_ids : array_like of int, shape (K,)
        Distinct keyframe ids.
    keyframe_times, pose_times, poses
        As :func:`geo_tag`.

    Returns
    -------
    list of GeoIndex

    Raises
    ------
    ValueError
        As :func:`geo_tag`, and for ids that repeat or do not match the times in number.

    Notes
    -----
    Ge et al. (2023), Sec. 3.4, Eq. (18); poses from :func:`geo_tag`.

    Examples
    --------
    >>> tags = geo_index([7, 9], [0.5, 1.0], [0.0, 1.0], [[0, 0, 0], [2, 0, 0]])
    >>> [(g.keyframe_id, g.pose.tolist()) for g in tags]
    [(7, [1.0, 0.0, 0.0]), (9, [2.0, 0.0, 0.0])]
    """
    ids = as_array(keyframe_ids, "keyframe_ids", ndim=1, dtype=np.int64)
    poses_k = geo_tag(keyframe_times, pose_times, poses)
    if len(ids) != len(poses_k):
        raise ValueError(f"keyframe_ids: expected {len(poses_k)} ids, one per keyframe time, got {len(ids)}")
    if len(np.unique(ids)) != len(ids):
        raise ValueError("keyframe_ids: expected distinct ids, got a repeated id")
    return [GeoIndex(int(k), p) for k, p in zip(ids, poses_k)]
