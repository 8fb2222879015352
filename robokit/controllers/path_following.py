"""Visual-path following: the unicycle (Eq. (6)), the reference point (Eq. (7)) and the law of Eq. (8).

Source: "Robust omnidirectional vision based mobile robot hierarchical localization and autonomous
navigation", Sec. 'Visual-servoing for navigation'. The paper writes poses as ``(x, y, theta)``
in this section; robokit's ``pose`` is the same ``[x, y, theta]`` (theta counter-clockwise from +x).

The path. The robot recorded key poses while it was driven (the topological nodes); the law needs
the path's curvature ``c(s) = dtheta/ds``, and "it is therefore important to have smooth
trajectories". :func:`path_from_poses` passes a cubic spline through the key positions (C2, so
``c(s)`` is continuous) and samples it every ``spacing`` metres of arc length: a
:class:`VisualPath` of dense poses ``[x, y, theta]`` with their arc length ``s`` and curvature.

Errors (Eq. (8), second line). The reference point is the nearest point of the path (Eq. (7)),
the unit normal ``n = (-sin theta_p, cos theta_p)`` points to the LEFT of the direction of travel,
``d = (p - p_ref) . n`` is positive when the robot is left of the path and
``theta_tilde = wrap(theta - theta_p)`` positive when it heads to the left of the path. With these
signs the robot's motion relative to the path (Samson's path coordinates) is::

    ds/dt = v cos(theta_tilde) / (1 - c d),   dd/dt = v sin(theta_tilde),
    dtheta_tilde/dt = omega - c v cos(theta_tilde) / (1 - c d)

and Eq. (8) cancels the last term exactly, leaving
``dtheta_tilde/dt = -k3 |v| theta_tilde - k2 v d sin(theta_tilde)/theta_tilde``. Then
``V = k2 d^2 / 2 + theta_tilde^2 / 2`` has ``dV/dt = -k3 |v| theta_tilde^2 <= 0``: this is why
the law carries ``sin(theta_tilde)/theta_tilde``. (With the normal pointing right instead, the
same law drives the robot away from the path: tests/test_controllers_path_following.py checks the
convention in simulation.) Near the path (``d``, ``theta_tilde`` small, ``v > 0``) and written in
the distance travelled ``ds = v dt``::

    d'' + k3 d' + k2 d = 0,

a second-order system with natural frequency ``alpha`` (rad per metre) and damping ``xi`` when
``k2 = alpha^2`` and ``k3 = 2 xi alpha``: poles ``-alpha (xi +- j sqrt(1 - xi^2))`` per metre
of path, or ``v`` times that per second. The printed paper's "k3 = 2 epsilon alpha" means
``2 xi alpha`` (``xi`` is the damping it names) and its "alpha-dot" is the natural frequency
``alpha``. The loop's transfer functions are in :mod:`robokit.controllers.path_following_loop`.

Saturation. "We saturate omega and reduce v to Vmax Wmax / |omega|": because Eq. (8) is
homogeneous of degree one in ``v`` (for ``v >= 0``), scaling ``v`` and ``omega`` by the same
factor keeps the curvature ``omega / v`` the law asked for (:func:`saturate_command`).

Eq. (8) is the path-following law for the unicycle of Canudas de Wit, Khennouf, Samson and
Sordalen (1993); Samson (1995) gives the chained-form design it belongs to.

References
----------
.. [1] C. Canudas de Wit, H. Khennouf, C. Samson and O. J. Sordalen, "Nonlinear control design for
   mobile robots", in Y. F. Zheng (ed.), *Recent Trends in Mobile Robots*, World Scientific Series
   in Robotics and Automated Systems vol. 11, World Scientific, 1993, pp. 121-156.
.. [2] C. Samson, "Control of chained systems: application to path following and time-varying
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

from ..geometry import as_planar, wrap_angle
from ..validation import as_array, check_finite_result, check_positive, check_sample_count, describe

__all__ = ["VisualPath", "path_from_poses", "ReferencePoint", "reference_point", "path_following_gains",
           "PathSingularityError", "path_following_command", "saturate_command", "PathFollower"]

XI = 1 / math.sqrt(2)   # the paper's damping: "a small overshoot" (4.3 %)


class PathSingularityError(ValueError):
    """``1 - c(s) d <= 0`` in Eq. (8): the robot is at (or beyond) the path's centre of curvature."""


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
    h = check_positive(spacing, "spacing")
    xy = key[:, :2]
    keep = np.concatenate([[True], np.linalg.norm(np.diff(xy, axis=0), axis=1) > 1e-9])
    xy = xy[keep]
    if len(xy) < 2:
        raise ValueError(f"poses: expected at least two distinct positions, got {len(xy)} ({describe(poses)})")
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    check_finite_result("poses", u)
    check_sample_count(8 * u[-1] / h, "poses, spacing")
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
    check_finite_result("poses, spacing", curvature)
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
                    window: float | None = None) -> ReferencePoint:
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
    if not isinstance(path, VisualPath):
        raise TypeError(f"path: expected a VisualPath, got {describe(path)}")
    p = as_array(pose, "pose", shape=(3,))
    n = len(path.poses)
    lo, hi = 0, n - 1
    if previous is not None:
        if isinstance(previous, bool) or not isinstance(previous, (int, np.integer)) or not 0 <= previous < n:
            raise ValueError(f"previous: expected a path index in [0, {n - 1}], got {describe(previous)}")
        if window is not None:
            w = check_positive(window, "window")
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
    check_finite_result("pose", s, d)
    return ReferencePoint(i + int(tk > 0.5), point, heading, curvature, normal, s, d, theta_tilde)


def path_following_gains(alpha: float, xi: float = XI) -> tuple[float, float]:
    """Gains ``(k2, k3) = (alpha^2, 2 xi alpha)`` of Eq. (8).

    Parameters
    ----------
    alpha : float
        Natural frequency (rad per metre of path, > 0); ``alpha v`` rad/s at speed ``v``.
    xi : float, default 1/sqrt(2)
        Damping ratio (> 0); the paper's choice, "meaning a small overshoot".

    Returns
    -------
    (k2, k3) : tuple of float

    Raises
    ------
    ValueError
        For non-positive or non-finite values, or values whose gains overflow.

    Notes
    -----
    Sec. 'Visual-servoing for navigation', unnumbered ("k2 = alpha^2, k3 = 2 epsilon alpha" in
    the printed paper: ``epsilon`` is the damping ``xi``). They make ``d'' + k3 d' + k2 d = 0``
    (module docstring) the standard second-order system ``s^2 + 2 xi alpha s + alpha^2``.

    Examples
    --------
    >>> k2, k3 = path_following_gains(2.0)
    >>> round(k2, 4), round(k3, 4)
    (4.0, 2.8284)
    """
    a = check_positive(alpha, "alpha")
    z = check_positive(xi, "xi")
    k2, k3 = a * a, 2.0 * z * a
    check_finite_result("alpha, xi", k2, k3)
    return k2, k3


def path_following_command(d: Any, theta_tilde: Any, curvature: Any, v: Any, k2: float, k3: float) -> Any:
    """Turn rate ``omega`` of the path-following law, Eq. (8).

    ``omega = -k3 |v| theta_tilde - k2 v d sin(theta_tilde)/theta_tilde + v cos(theta_tilde) c / (1 - c d)``

    Parameters
    ----------
    d : float or array_like
        Distance to the path (m), positive when the robot is left of it.
    theta_tilde : float or array_like
        Heading error (rad), positive when the robot heads left of the path.
    curvature : float or array_like
        Path curvature ``c(s)`` at the reference point (1/m).
    v : float or array_like
        Forward speed (m/s).
    k2, k3 : float
        Gains (>= 0), e.g. from :func:`path_following_gains`.

    Returns
    -------
    float or numpy.ndarray
        ``omega`` (rad/s), broadcast over the array inputs; a float when all are scalars.

    Raises
    ------
    PathSingularityError
        Where ``1 - c d <= 0``: the robot is at or beyond the centre of curvature, where the
        nearest point of the path is not unique and Eq. (8) is undefined. (A nearest point of a
        smooth path always has ``1 - c d >= 0``; equality is the centre of a circle.)
    ValueError, TypeError
        For non-finite or non-numeric inputs, negative gains, shapes that do not broadcast, or a
        result that overflows.

    Notes
    -----
    Eq. (8) (Canudas de Wit et al. 1993). ``sin(x)/x`` is ``numpy.sinc(x / pi)``, which is 1 at
    ``x = 0``. The third term keeps the robot on the path: on a circle (``d = theta_tilde = 0``)
    ``omega = v c``, "a constant angular velocity".

    Examples
    --------
    >>> round(path_following_command(0.2, 0.0, 0.0, 0.3, k2=4.0, k3=2.83), 4)     # 0.2 m left: turn right
    -0.24
    >>> round(path_following_command(0.0, 0.0, 0.5, 0.3, k2=4.0, k3=2.83), 4)     # on a circle: v c
    0.15
    """
    dd, th, c, vv = (as_array(x, n) for x, n in ((d, "d"), (theta_tilde, "theta_tilde"), (curvature, "curvature"),
                                               (v, "v")))
    g2, g3 = check_positive(k2, "k2", allow_zero=True), check_positive(k3, "k3", allow_zero=True)
    try:
        shape = np.broadcast_shapes(dd.shape, th.shape, c.shape, vv.shape)
    except ValueError:
        raise ValueError(f"d, theta_tilde, curvature, v: expected shapes that broadcast, got {dd.shape}, "
                         f"{th.shape}, {c.shape} and {vv.shape}") from None
    den = 1.0 - c * dd
    if np.any(den <= 0):
        raise PathSingularityError("d, curvature: expected 1 - curvature * d > 0 (the robot on the near side of "
                                   "the path's centre of curvature), got 1 - c d <= 0")
    with np.errstate(over="ignore", invalid="ignore"):
        omega = -g3 * np.abs(vv) * th - g2 * vv * dd * np.sinc(th / np.pi) + vv * np.cos(th) * c / den   # Eq. (8)
    check_finite_result("d, theta_tilde, curvature, v, k2, k3", omega)
    omega = np.broadcast_to(omega, shape)
    return float(omega) if omega.ndim == 0 else np.array(omega)


def saturate_command(v: Any, omega: Any, v_max: float, w_max: float) -> tuple[Any, Any]:
    """Limit ``|v| <= v_max`` and ``|omega| <= w_max`` keeping the curvature ``omega / v``.

    Parameters
    ----------
    v, omega : float or array_like
        Commanded forward speed (m/s) and turn rate (rad/s).
    v_max, w_max : float
        Limits (> 0).

    Returns
    -------
    (v, omega)
        Both scaled by the same factor ``min(1, v_max / |v|, w_max / |omega|)``; floats for scalar
        inputs.

    Raises
    ------
    ValueError, TypeError
        For non-finite inputs, non-positive limits or shapes that do not broadcast.

    Notes
    -----
    Sec. 'Visual-servoing for navigation', unnumbered: "when this value is achieved, we saturate
    omega and reduce v to Vmax Wmax / |omega|, in order to avoid large lags in narrow turns". With
    ``v = v_max`` the common factor gives exactly that ``v``; it is the same rule for any ``v``.

    Examples
    --------
    >>> v, w = saturate_command(0.3, 2.0, v_max=0.3, w_max=0.5)     # too sharp: slow down
    >>> round(v, 4), round(w, 4), round(w / v, 4)                   # curvature 2 / 0.3 kept
    (0.075, 0.5, 6.6667)
    """
    vv, ww = as_array(v, "v"), as_array(omega, "omega")
    vm, wm = check_positive(v_max, "v_max"), check_positive(w_max, "w_max")
    try:
        vv, ww = np.broadcast_arrays(vv, ww)
    except ValueError:
        raise ValueError(f"v, omega: expected shapes that broadcast, got {vv.shape} and {ww.shape}") from None
    with np.errstate(divide="ignore"):
        scale = np.minimum(1.0, np.minimum(vm / np.abs(vv), wm / np.abs(ww)))
    vs, ws = vv * scale, ww * scale
    return (float(vs), float(ws)) if vs.ndim == 0 else (vs, ws)


class PathFollower:
    """Follow a :class:`VisualPath` with Eq. (8) at ``v_max``, saturated, until the goal.

    Parameters
    ----------
    path : VisualPath
    alpha : float
        Natural frequency (rad per metre of path) of the law's linearisation.
    v_max, w_max : float
        Forward speed (m/s) and turn-rate limit (rad/s).
    xi : float, default 1/sqrt(2)
        Damping ratio.
    goal_tolerance : float, default 0.1
        The goal is reached when the pose is within this distance (m) of the last path point.
    window : float or None, default 1.0
        Half-width (m of arc length) of the reference point's search around the previous one
        (:func:`reference_point`); ``None`` searches the whole path every time.

    Attributes
    ----------
    reference : ReferencePoint or None
        The last reference point.
    done : bool
        The goal is reached, or the reference point has passed the end of the path.
    reached : bool
        Within ``goal_tolerance`` of the goal at the last command.
    progress : float
        Fraction of the path's length behind the reference point, in [0, 1].

    Notes
    -----
    Sec. 'Visual-servoing for navigation': "the forward velocity v is equal to the maximum
    V_max", Eq. (8) for ``omega`` and :func:`saturate_command`. Once done, the command is (0, 0).

    Examples
    --------
    >>> path = path_from_poses([[0, 0, 0], [2, 0, 0]])
    >>> follower = PathFollower(path, alpha=2.0, v_max=0.3, w_max=1.0)
    >>> v, w = follower.command([0.0, 0.2, 0.0])        # 0.2 m left of the path: turn right
    >>> round(v, 3), round(w, 3), follower.done
    (0.3, -0.24, False)
    >>> follower.command([1.95, 0.0, 0.0]), follower.done, follower.reached
    ((0.0, 0.0), True, True)
    """

    def __init__(self, path: VisualPath, alpha: float, v_max: float, w_max: float, xi: float = XI, *,
                 goal_tolerance: float = 0.1, window: float | None = 1.0) -> None:
        if not isinstance(path, VisualPath):
            raise TypeError(f"path: expected a VisualPath, got {describe(path)}")
        self.path = path
        self.k2, self.k3 = path_following_gains(alpha, xi)
        self.v_max = check_positive(v_max, "v_max")
        self.w_max = check_positive(w_max, "w_max")
        self.goal_tolerance = check_positive(goal_tolerance, "goal_tolerance")
        self.window = None if window is None else check_positive(window, "window")
        self.reference: ReferencePoint | None = None
        self.done = self.reached = False

    @property
    def progress(self) -> float:
        """Fraction of the path behind the last reference point."""
        if self.reference is None:
            return 0.0
        return float(min(max(self.reference.s / self.path.length, 0.0), 1.0))

    def command(self, pose: Any) -> tuple[float, float]:
        """``(v, omega)`` for the robot at ``pose`` (its best estimate), Eq. (8) then saturation."""
        previous = None if self.reference is None else self.reference.index
        ref = reference_point(self.path, pose, previous=previous, window=self.window)
        self.reference = ref
        self.reached = bool(np.hypot(*(np.asarray(pose, float)[:2] - self.path.poses[-1, :2])) < self.goal_tolerance)
        self.done = self.reached or ref.s >= self.path.length
        if self.done:
            return 0.0, 0.0
        omega = path_following_command(ref.d, ref.theta_tilde, ref.curvature, self.v_max, self.k2, self.k3)
        return saturate_command(self.v_max, omega, self.v_max, self.w_max)
