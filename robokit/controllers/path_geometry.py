"""The path a robot follows: a smooth curve through recorded key poses, and its nearest point (Eq. (7)).

Source: "Robust omnidirectional vision based mobile robot hierarchical localization and autonomous
navigation", Sec. 'Visual-servoing for navigation'. The paper writes poses as ``(x, y, theta)``
in this section; robokit's ``pose`` is the same ``[x, y, theta]`` (theta counter-clockwise from +x).

The path. The robot recorded key poses while it was driven (the topological nodes); the law of
Eq. (8) needs the path's curvature ``c(s) = dtheta/ds``, and "it is therefore important to have
smooth trajectories". :func:`path_from_poses` passes a cubic spline through the key positions (C2,
so ``c(s)`` is continuous) and samples it every ``spacing`` metres of arc length: a
:class:`VisualPath` of dense poses ``[x, y, theta]`` with their arc length ``s`` and curvature.

Errors (Eq. (8), second line). The reference point is the nearest point of the path (Eq. (7)),
the unit normal ``n = (-sin theta_p, cos theta_p)`` points to the LEFT of the direction of travel,
``d = (p - p_ref) . n`` is positive when the robot is left of the path and
``theta_tilde = wrap(theta - theta_p)`` positive when it heads to the left of the path (the path
coordinates of Samson 1995, with ``s`` the arc length of the reference point): the signs with
which Eq. (8) stabilises the path (:mod:`robokit.controllers.path_following`). At a
nearest point of a smooth path ``1 - c d >= 0`` (the second-order condition of the minimum of
Eq. (7)); equality is the centre of curvature, where Eq. (8) is undefined.

References
----------
.. [1] C. Samson, "Control of chained systems: application to path following and time-varying
   point-stabilization of mobile robots", *IEEE Transactions on Automatic Control* 40(1), 64-77,
   1995.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any, NamedTuple

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import CubicSpline

from ..geometry import wrap_angle
from ..geometry.planar import as_planar
from ..validation import as_array, as_positive, describe, require_finite_result, require_sample_count

__all__ = ["VisualPath", "path_from_poses", "ReferencePoint", "reference_point"]


@dataclasses.dataclass(frozen=True, eq=False)
class VisualPath:
    """A smooth path sampled densely: poses, arc length and curvature (Sec. 'Visual-servoing for navigation').

    Usually made by :func:`path_from_poses` from recorded key poses; it can be built directly from
    exact samples (a line, a circle) for analysis.

    Attributes
    ----------
    poses : numpy.ndarray, shape (N, 3)
        ``[x, y, theta]`` along the path, ``theta`` its tangent direction (N >= 2).
    s : numpy.ndarray, shape (N,)
        Arc length (m) from the first pose, strictly increasing.
    curvature : numpy.ndarray, shape (N,)
        ``c(s) = dtheta/ds`` (1/m; positive when the path turns left).
    key_poses : numpy.ndarray, shape (M, 3)
        The poses it was made from (``poses`` itself when built directly).

    Raises
    ------
    ValueError
        For shapes that disagree, fewer than two poses, or ``s`` not strictly increasing.

    Notes
    -----
    ``c(s) = dtheta/ds`` as the paper defines it; the samples are the set ``xP`` of Eq. (7).

    Examples
    --------
    >>> s = np.linspace(0.0, 2.0, 5)
    >>> line = VisualPath(np.column_stack([s, 0 * s, 0 * s]), s, 0 * s)
    >>> line.length, line.poses.shape
    (2.0, (5, 3))
    """

    poses: np.ndarray
    s: np.ndarray
    curvature: np.ndarray
    key_poses: np.ndarray | None = None

    def __post_init__(self) -> None:
        poses = as_planar(self.poses, "poses")
        if poses.ndim != 2 or len(poses) < 2:
            raise ValueError(f"poses: expected shape (N, 3) with N >= 2, got shape {poses.shape}")
        s = as_array(self.s, "s", shape=(len(poses),))
        c = as_array(self.curvature, "curvature", shape=(len(poses),))
        if not np.all(np.diff(s) > 0):
            raise ValueError("s: expected a strictly increasing arc length, got repeated or decreasing values")
        key = poses if self.key_poses is None else as_planar(self.key_poses, "key_poses").reshape(-1, 3)
        for name, value in (("poses", poses), ("s", s), ("curvature", c), ("key_poses", key)):
            object.__setattr__(self, name, value)

    @property
    def length(self) -> float:
        """Arc length (m) from the first to the last pose."""
        return float(self.s[-1] - self.s[0])

    @property
    def goal(self) -> np.ndarray:
        """The last pose ``[x, y, theta]``."""
        return self.poses[-1].copy()


def path_from_poses(poses: Any, *, spacing: float = 0.05) -> VisualPath:
    """A smooth :class:`VisualPath` through recorded key poses (cubic spline over arc length).

    Parameters
    ----------
    poses : array_like, shape (M, 3)
        Key poses ``[x, y, theta]`` in the order driven (M >= 2). Their positions are
        interpolated; their headings are not used (the tangent of the spline replaces them, as it
        did the recorded heading when the robot drove forward). Consecutive repeats are dropped.
    spacing : float, default 0.05
        Arc length (m) between the returned samples.

    Returns
    -------
    VisualPath

    Raises
    ------
    ValueError
        For fewer than two distinct positions, a non-positive spacing, too many samples, or key
        positions that make the spline stop or turn back (a cusp: curvature without bound).

    Notes
    -----
    The paper asks for smooth trajectories because ``c(s) = dtheta/ds`` enters Eq. (8) (Sec.
    'Visual-servoing for navigation', unnumbered). ``scipy.interpolate.CubicSpline`` (not-a-knot)
    through the positions, parametrised by chord length, is C2, so ``c(s) = (x' y'' - y' x'') /
    |r'|^3`` is continuous; the arc length is integrated on a grid 8 times finer than ``spacing``.
    Two key poses give a straight line.

    Examples
    --------
    >>> path = path_from_poses([[0, 0, 0], [1, 0, 0], [2, 1, 0], [2, 2, 0]], spacing=0.1)
    >>> round(path.length, 3), len(path.poses), round(float(path.curvature.max()), 3)
    (3.505, 37, 0.789)
    """
    key = as_planar(poses, "poses")
    if key.ndim != 2:
        raise ValueError(f"poses: expected shape (M, 3) with M >= 2, got shape {key.shape}")
    h = as_positive(spacing, "spacing")
    xy = key[:, :2]
    keep = np.concatenate([[True], np.linalg.norm(np.diff(xy, axis=0), axis=1) > 1e-9])
    xy = xy[keep]
    if len(xy) < 2:
        raise ValueError(f"poses: expected at least two distinct positions, got {len(xy)} ({describe(poses)})")
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    require_finite_result("poses", u)
    require_sample_count(8 * u[-1] / h, "poses, spacing")
    spline = CubicSpline(u, xy, axis=0)
    fine = np.linspace(0.0, u[-1], max(int(math.ceil(8 * u[-1] / h)), 16) + 1)
    speed = np.linalg.norm(spline(fine, 1), axis=1)
    if speed.min() <= 1e-6 * speed.mean():
        raise ValueError("poses: expected key positions a smooth curve passes forward through, got a cusp "
                         "(the spline stops or turns back); drop or re-space the key poses")
    s_fine = cumulative_trapezoid(speed, fine, initial=0.0)
    s = np.linspace(0.0, s_fine[-1], max(int(math.ceil(s_fine[-1] / h)), 1) + 1)
    uu = np.interp(s, s_fine, fine)
    r, r1, r2 = spline(uu), spline(uu, 1), spline(uu, 2)
    theta = np.arctan2(r1[:, 1], r1[:, 0])
    curvature = (r1[:, 0] * r2[:, 1] - r1[:, 1] * r2[:, 0]) / np.linalg.norm(r1, axis=1) ** 3   # c = dtheta/ds
    require_finite_result("poses, spacing", curvature)
    return VisualPath(np.column_stack([r, theta]), s, curvature, key)


class ReferencePoint(NamedTuple):
    """The reference point of Eq. (7) and the errors of Eq. (8) (see :func:`reference_point`)."""

    index: int             #: nearest path sample
    point: np.ndarray      #: ``(x_p^ref, y_p^ref)``
    heading: float         #: ``theta_p^ref`` (rad)
    curvature: float       #: ``c(s)`` at the reference point (1/m)
    normal: np.ndarray     #: unit normal ``(n_x, n_y)``, to the left of the path
    s: float               #: arc length of the reference point; beyond the ends, along the end tangents
    d: float               #: distance to the path (m), positive to the left
    theta_tilde: float     #: heading error ``wrap(theta - theta_p^ref)`` (rad)


def reference_point(path: VisualPath, pose: Any, *, previous: int | None = None,
                    window: float | None = None, validate: bool = True) -> ReferencePoint:
    """The nearest point of the path (Eq. (7)) and the distance and heading errors of Eq. (8).

    Parameters
    ----------
    path : VisualPath
    pose : array_like, shape (3,)
        Robot pose ``[x, y, theta]``.
    previous : int, optional
        Index of the previous reference point; with ``window``, only the samples within
        ``window`` metres of arc length of it are searched (a path that passes near itself, e.g.
        back through a doorway, is not mistaken for its other pass).
    window : float, optional
        Half-width (m) of that search window; ignored without ``previous``.
    validate : bool, default True
        Validate the inputs; ``False`` is the fast path for a control loop that already did.

    Returns
    -------
    ReferencePoint
        ``index``, ``point``, ``heading``, ``curvature``, ``normal``, ``s``, ``d``, ``theta_tilde``.

    Raises
    ------
    TypeError
        If ``path`` is not a :class:`VisualPath`.
    ValueError
        For a badly shaped or non-finite pose, or a window or index out of range.

    Notes
    -----
    Eq. (7) minimises the distance over the path; here over the dense polyline (every segment at
    once, vectorised), the heading, curvature and ``s`` interpolated linearly on the nearest
    segment. ``d = [x - x_ref, y - y_ref] [n_x, n_y]^T`` and ``theta_tilde = theta - theta_ref``
    (Eq. (8), second line), with ``n`` to the left of the path (module docstring). A robot beyond
    the last sample gets the last sample as its reference and ``s > path.length``.

    Examples
    --------
    >>> s = np.linspace(0.0, 2.0, 5)
    >>> line = VisualPath(np.column_stack([s, 0 * s, 0 * s]), s, 0 * s)
    >>> ref = reference_point(line, [1.2, 0.3, 0.1])     # 0.3 m to the left, heading 0.1 rad left
    >>> round(ref.s, 3), round(ref.d, 3), round(ref.theta_tilde, 3)
    (1.2, 0.3, 0.1)
    """
    if validate and not isinstance(path, VisualPath):
        raise TypeError(f"path: expected a VisualPath, got {describe(path)}")
    n = len(path.poses)
    if validate:
        p = as_planar(pose, "pose", shape=(3,))
        if previous is not None and (isinstance(previous, bool) or not isinstance(previous, (int, np.integer))
                                     or not 0 <= previous < n):
            raise ValueError(f"previous: expected a path index in [0, {n - 1}], got {describe(previous)}")
        w = None if window is None else as_positive(window, "window")
    else:
        p, w = pose, window
    lo, hi = 0, n - 1
    if previous is not None:
        if w is not None:
            lo = int(np.searchsorted(path.s, path.s[previous] - w, side="left"))
            hi = int(np.searchsorted(path.s, path.s[previous] + w, side="right")) - 1
            lo, hi = min(lo, previous, n - 2), max(hi, previous + 1 if previous < n - 1 else previous)
    a, b = path.poses[lo:hi, :2], path.poses[lo + 1:hi + 1, :2]
    ab = b - a
    seg2 = np.einsum("ij,ij->i", ab, ab)
    t = np.clip(np.einsum("ij,ij->i", p[:2] - a, ab) / np.maximum(seg2, 1e-300), 0.0, 1.0)
    proj = a + t[:, None] * ab
    k = int(np.argmin(np.einsum("ij,ij->i", p[:2] - proj, p[:2] - proj)))   # Eq. (7)
    tk, i = float(t[k]), lo + k
    heading = float(wrap_angle(path.poses[i, 2] + tk * wrap_angle(path.poses[i + 1, 2] - path.poses[i, 2])))
    curvature = float(path.curvature[i] + tk * (path.curvature[i + 1] - path.curvature[i]))
    s = float(path.s[i] + tk * (path.s[i + 1] - path.s[i]))
    point = proj[k]
    tangent = np.array([math.cos(heading), math.sin(heading)])
    normal = np.array([-tangent[1], tangent[0]])
    if (i == n - 2 and tk == 1.0) or (i == 0 and tk == 0.0):    # beyond an end: along its tangent
        s += float((p[:2] - point) @ tangent)
    d = float((p[:2] - point) @ normal)                            # Eq. (8): d = [x - x_ref, y - y_ref] n
    theta_tilde = float(wrap_angle(p[2] - heading))                # Eq. (8): theta - theta_ref
    if validate:
        require_finite_result("pose", s, d)
    return ReferencePoint(i + int(tk > 0.5), point, heading, curvature, normal, s, d, theta_tilde)
