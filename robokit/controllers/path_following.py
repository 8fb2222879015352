"""Visual-path following: the unicycle (Eq. (6)) steered onto the path by the law of Eq. (8).

Source: "Robust omnidirectional vision based mobile robot hierarchical localization and autonomous
navigation", Sec. 'Visual-servoing for navigation'. The path, its reference point (Eq. (7)) and
the errors ``d`` and ``theta_tilde`` (normal to the LEFT of the path) are in
:mod:`robokit.controllers.path_geometry`; robokit's ``pose`` is the paper's ``(x, y, theta)``.

The law. With the unicycle of Eq. (6) the robot's motion relative to the path (Samson's path
coordinates, ``s`` the arc length of the reference point) is::

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

import math
from typing import Any

import numpy as np

from ..geometry.planar import as_planar
from ..validation import as_array, as_positive, describe, require_finite_result
from .path_geometry import ReferencePoint, VisualPath, path_from_poses, reference_point

# the path's names are re-exported: the lesson's API reaches them through this module too
__all__ = ["reference_command", "path_following_gains", "PathSingularityError", "path_following_command", "saturate_command",
           "PathFollower", "VisualPath", "path_from_poses", "ReferencePoint", "reference_point"]

XI = 1 / math.sqrt(2)   # the paper's damping: "a small overshoot" (4.3 %)


class PathSingularityError(ValueError):
    """``1 - c(s) d <= 0`` in Eq. (8): the robot is at (or beyond) the path's centre of curvature."""


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
    a = as_positive(alpha, "alpha")
    z = as_positive(xi, "xi")
    k2, k3 = a * a, 2.0 * z * a
    require_finite_result("alpha, xi", k2, k3)
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
    dd, th, c, vv = (as_array(x, n) for x, n in ((d, "d"), (theta_tilde, "theta_tilde"),
                                               (curvature, "curvature"), (v, "v")))
    g2, g3 = as_positive(k2, "k2", allow_zero=True), as_positive(k3, "k3", allow_zero=True)
    try:
        shape = np.broadcast_shapes(dd.shape, th.shape, c.shape, vv.shape)
    except ValueError:
        raise ValueError(f"d, theta_tilde, curvature, v: expected shapes that broadcast, got {dd.shape}, "
                         f"{th.shape}, {c.shape} and {vv.shape}") from None
    omega = _command(dd, th, c, vv, g2, g3)
    require_finite_result("d, theta_tilde, curvature, v, k2, k3", omega)
    omega = np.broadcast_to(omega, shape)
    return float(omega) if omega.ndim == 0 else np.array(omega)


def _command(dd: Any, th: Any, c: Any, vv: Any, g2: float, g3: float) -> Any:
    """Unchecked Eq. (8) of :func:`path_following_command` (the singularity is still refused)."""
    den = 1.0 - c * dd
    if np.any(den <= 0):
        raise PathSingularityError("d, curvature: expected 1 - curvature * d > 0 (the robot on the near side of "
                                   "the path's centre of curvature), got 1 - c d <= 0")
    with np.errstate(over="ignore", invalid="ignore"):
        omega = -g3 * np.abs(vv) * th - g2 * vv * dd * np.sinc(th / np.pi) + vv * np.cos(th) * c / den   # Eq. (8)
    return float(omega) if np.ndim(omega) == 0 else omega


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
    omega and reduce v to Vmax Wmax / abs(omega), in order to avoid large lags in narrow turns". With
    ``v = v_max`` the common factor gives exactly that ``v``; it is the same rule for any ``v``.

    Examples
    --------
    >>> v, w = saturate_command(0.3, 2.0, v_max=0.3, w_max=0.5)     # too sharp: slow down
    >>> round(v, 4), round(w, 4), round(w / v, 4)                   # curvature 2 / 0.3 kept
    (0.075, 0.5, 6.6667)
    """
    vv, ww = as_array(v, "v"), as_array(omega, "omega")
    vm, wm = as_positive(v_max, "v_max"), as_positive(w_max, "w_max")
    try:
        vv, ww = np.broadcast_arrays(vv, ww)
    except ValueError:
        raise ValueError(f"v, omega: expected shapes that broadcast, got {vv.shape} and {ww.shape}") from None
    with np.errstate(divide="ignore"):
        scale = np.minimum(1.0, np.minimum(vm / np.abs(vv), wm / np.abs(ww)))
    vs, ws = vv * scale, ww * scale
    return (float(vs), float(ws)) if vs.ndim == 0 else (vs, ws)


def _saturate(v: float, omega: float, v_max: float, w_max: float) -> tuple[float, float]:
    """:func:`saturate_command` on floats a control loop computed itself (unchecked)."""
    scale = min(1.0, v_max / abs(v) if v else 1.0, w_max / abs(omega) if omega else 1.0)
    return v * scale, omega * scale


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

    Two guards for estimates that jump (a false fix): the windowed reference is replaced by the
    nearest point of the whole path when the pose is more than half a window from it or more
    than half-way to its centre of curvature (``1 - c d < 0.5``); and where even that leaves
    ``1 - c d < 0.1`` (the pose near a centre of curvature, or off an end of the path) the
    curvature term of Eq. (8) is dropped, so the command stays finite (:class:`PathSingularityError`
    is for direct calls of :func:`path_following_command`).

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
        self.v_max = as_positive(v_max, "v_max")
        self.w_max = as_positive(w_max, "w_max")
        self.goal_tolerance = as_positive(goal_tolerance, "goal_tolerance")
        self.window = None if window is None else as_positive(window, "window")
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
        p = as_planar(pose, "pose", shape=(3,))
        previous = None if self.reference is None else self.reference.index
        ref = reference_point(self.path, p, previous=previous, window=self.window, validate=False)
        if previous is not None and self.window is not None and (
                abs(ref.d) > self.window / 2 or 1 - ref.curvature * ref.d < 0.5):
            ref = reference_point(self.path, p, validate=False)           # lost the thread: search it all
        self.reference = ref
        self.reached = bool(math.hypot(*(p[:2] - self.path.poses[-1, :2])) < self.goal_tolerance)
        self.done = self.reached or ref.s >= self.path.length
        if self.done:
            return 0.0, 0.0
        return reference_command(ref, self.v_max, self.k2, self.k3, self.w_max)


def reference_command(ref: ReferencePoint, v: float, k2: float, k3: float, w_max: float | None = None
                      ) -> tuple[float, float]:
    """``(v, omega)`` at a reference point: Eq. (8), then the paper's saturation.

    The one step every follower takes (:class:`PathFollower`, the nonlinear simulation beside the
    linearised loop). Near the path's centre of curvature (``1 - c d < 0.1``, where Eq. (8)'s third
    term blows up) the curvature term is dropped rather than the robot stopped.

    Parameters
    ----------
    ref : ReferencePoint
        From :func:`reference_point` (its ``d``, ``theta_tilde`` and ``curvature``).
    v : float
        Forward speed (m/s), also the saturation's ``V_max``.
    k2, k3 : float
        Gains of Eq. (8).
    w_max : float, optional
        Turn-rate bound ``W_max`` (rad/s); ``None``: no saturation.

    Returns
    -------
    (v, omega) : float, float

    Notes
    -----
    Eq. (8) and Sec. "Visual-servoing for navigation" (saturation keeping the curvature); inputs
    are trusted (the callers validated them).

    Examples
    --------
    >>> from robokit.controllers import path_from_poses, reference_point
    >>> line = path_from_poses([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    >>> v, omega = reference_command(reference_point(line, [0.5, 0.2, 0.0]), 0.3, 4.0, 2.83, w_max=0.2)
    >>> round(v, 3), round(omega, 3)                 # omega -0.24 saturated to -0.2, v scaled with it
    (0.25, -0.2)
    """
    c = ref.curvature if 1 - ref.curvature * ref.d >= 0.1 else 0.0
    omega = _command(ref.d, ref.theta_tilde, c, v, k2, k3)
    if w_max is None:
        return float(v), float(omega)
    return _saturate(v, omega, v, w_max)
