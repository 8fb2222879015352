"""Planar poses (SE(2)): angle wrapping, composition, inverse, relative pose, matrices.

Planar poses are ``[x, y, theta]`` with ``theta`` the heading measured counter-clockwise from
the x axis (robokit's world is right-handed with z up).

References
----------
.. [1] R. Smith, M. Self and P. Cheeseman, "Estimating uncertain spatial relationships in
   robotics", in *Autonomous Robot Vehicles*, I. J. Cox and G. T. Wilfong (eds.), Springer,
   167-193, 1990.
.. [2] K. M. Lynch and F. C. Park, *Modern Robotics: Mechanics, Planning, and Control*, Cambridge
   University Press, 2017.
.. [3] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [4] F. Lu and E. Milios, "Globally consistent range scan alignment for environment mapping",
   *Autonomous Robots* 4(4), 333-349, 1997.
.. [5] S. Umeyama, "Least-squares estimation of transformation parameters between two point
   patterns", IEEE Trans. Pattern Analysis and Machine Intelligence 13(4), 376-380, 1991.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, require_angles
from .rotations import as_rotation

__all__ = ["as_planar", "wrap_angle", "se2_compose", "se2_inverse", "se2_between", "se2_to_matrix", "matrix_to_se2",
           "intersect_lines", "cross_rays"]


def as_planar(value: Any, name: str, *, shape: Any = None, min_count: int = 0) -> np.ndarray:
    """Validate one planar pose or a stack of them: shape (3,) or (N, 3), finite, headings in range.

    For robokit's ``[x, y, theta]`` and the papers' ``[p, q, theta]`` alike. The headings must lie
    within ``robokit.validation.MAX_ANGLE`` rad (:func:`robokit.validation.require_angles`): a larger
    finite one wraps to an arbitrary angle.

    Parameters
    ----------
    value : array_like
    name : str
        The argument's name, for errors.
    shape : tuple, optional
        A required shape such as ``(3,)``, ``(None, 3)`` or ``(n, 3)``; default: (3,) or (N, 3).
    min_count : int, default 0
        Fewest poses a stack must hold.

    Raises
    ------
    ValueError
        If the shape is not as required, a value is not finite or a heading is beyond ``MAX_ANGLE``.

    Notes
    -----
    Validation only (DESIGN.md, "Errors"); not from a paper.

    Examples
    --------
    >>> as_planar([[0, 0, 0], [1, 2, 3]], "poses").shape
    (2, 3)
    >>> as_planar([0, 0, 1e300], "pose")
    Traceback (most recent call last):
    ...
    ValueError: pose: expected heading (element 2) in radians within +-1e+06, got 1e+300
    """
    p = as_array(value, name, shape=shape)
    if p.shape[-1:] != (3,) or p.ndim > 2:
        raise ValueError(f"{name}: expected shape (3,) or (N, 3), got shape {p.shape}")
    if p.ndim == 2 and p.shape[0] < min_count:
        raise ValueError(f"{name}: expected at least {min_count} poses, got {p.shape[0]}")
    require_angles(p[..., 2], name, "heading (element 2)" if p.ndim == 1 else "headings (column 2)")
    return p


def wrap_angle(angle: Any, *, validate: bool = True) -> Any:
    """Wrap angles to the interval [-pi, pi).

    Parameters
    ----------
    angle : float or array_like
        Angles in radians (finite).
    validate : bool, default True
        Validate ``angle``; ``False`` is the fast path for inner loops whose angles are already
        finite floats (a non-finite angle then comes back NaN instead of raising).

    Returns
    -------
    float or numpy.ndarray
        Same shape as the input; a float for scalar input.

    Raises
    ------
    ValueError
        If any angle is NaN or infinite.

    Notes
    -----
    Standard identity ``(a + pi) mod 2 pi - pi`` (e.g. Thrun, Burgard & Fox, *Probabilistic
    Robotics*, 2005, Sec. 5.4); used by every heading computation in the course.

    Examples
    --------
    >>> print(round(wrap_angle(3 * np.pi / 2), 6))
    -1.570796
    """
    a = as_array(angle, "angle") if validate else np.asarray(angle, float)
    out = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return float(out) if out.ndim == 0 else out


def _pair(a: Any, b: Any) -> tuple[np.ndarray, np.ndarray]:
    pa, pb = as_planar(a, "a"), as_planar(b, "b")
    if pa.ndim == pb.ndim == 2 and len(pa) != len(pb) and 1 not in (len(pa), len(pb)):
        raise ValueError(f"a, b: expected one pose or stacks of equal length, got {len(pa)} and {len(pb)} poses")
    return pa, pb


def se2_compose(a: Any, b: Any, *, validate: bool = True) -> np.ndarray:
    """Compose planar poses: the pose ``b`` expressed in frame ``a``, mapped to the world.

    Parameters
    ----------
    a, b : array_like, shape (3,) or (N, 3)
        Poses ``[x, y, theta]``; a single pose broadcasts against a stack.
    validate : bool, default True
        Validate both; ``False`` skips it (float arrays only).

    Returns
    -------
    numpy.ndarray, shape (3,) or (N, 3)
        ``a ⊕ b = [x_a + cos(t_a) x_b - sin(t_a) y_b, y_a + sin(t_a) x_b + cos(t_a) y_b,
        wrap(t_a + t_b)]``.

    Raises
    ------
    ValueError
        If a pose does not have shape (3,) or (N, 3), the stacks differ in length or a value is
        not finite.

    Notes
    -----
    The compounding operation ``⊕`` of Smith, Self & Cheeseman (1990).

    Examples
    --------
    >>> print(np.round(se2_compose([1.0, 2.0, np.pi / 2], [1.0, 0.0, 0.0]), 6))
    [1.       3.       1.570796]
    >>> mounts = [[0.2, 0.1, 0.5], [0.2, -0.1, -0.5]]                  # two sensors on a robot
    >>> print(np.round(se2_compose([1.0, 2.0, np.pi / 2], mounts), 6))
    [[0.9      2.2      2.070796]
     [1.1      2.2      1.070796]]
    """
    pa, pb = _pair(a, b) if validate else (a, b)
    c, s = np.cos(pa[..., 2]), np.sin(pa[..., 2])
    return np.stack([pa[..., 0] + c * pb[..., 0] - s * pb[..., 1], pa[..., 1] + s * pb[..., 0] + c * pb[..., 1],
                     wrap_angle(pa[..., 2] + pb[..., 2])], axis=-1)


def se2_inverse(a: Any) -> np.ndarray:
    """Invert planar poses: the world origin expressed in the frame ``a``.

    Parameters
    ----------
    a : array_like, shape (3,) or (N, 3)
        Poses ``[x, y, theta]``.

    Returns
    -------
    numpy.ndarray, shape (3,) or (N, 3)
        ``⊖a = [-x cos t - y sin t, x sin t - y cos t, -t]`` so that ``se2_compose(a, ⊖a) = 0``.

    Raises
    ------
    ValueError
        If the poses do not have shape (3,) or (N, 3) or are not finite.

    Notes
    -----
    The inverse relationship ``⊖`` of Smith, Self & Cheeseman (1990).

    Examples
    --------
    >>> a = [1.0, 2.0, 0.5]
    >>> print(np.round(se2_inverse(a), 6))
    [-1.836434 -1.27574  -0.5     ]
    >>> print(np.round(se2_compose(a, se2_inverse(a)), 12) + 0.0)
    [0. 0. 0.]
    """
    p = as_planar(a, "a")
    c, s = np.cos(p[..., 2]), np.sin(p[..., 2])
    return np.stack([-c * p[..., 0] - s * p[..., 1], s * p[..., 0] - c * p[..., 1],
                     wrap_angle(-p[..., 2])], axis=-1)


def se2_between(a: Any, b: Any) -> np.ndarray:
    """Return the pose of ``b`` relative to ``a``: ``⊖a ⊕ b`` (e.g. an odometry increment).

    Parameters
    ----------
    a, b : array_like, shape (3,) or (N, 3)
        Poses ``[x, y, theta]`` in the same frame; a single pose broadcasts against a stack.

    Returns
    -------
    numpy.ndarray, shape (3,) or (N, 3)

    Raises
    ------
    ValueError
        As :func:`se2_compose`.

    Notes
    -----
    ``⊖a ⊕ b`` in the notation of Smith, Self & Cheeseman (1990); Lu & Milios (1997) call it the
    relative pose constraint of a pose graph.

    Examples
    --------
    >>> print(np.round(se2_between([1.0, 0.0, np.pi / 2], [1.0, 1.0, np.pi / 2]), 6) + 0.0)
    [1. 0. 0.]
    >>> path = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [2.0, 0.1, 0.2]])
    >>> print(np.round(se2_between(path[:-1], path[1:]), 3) + 0.0)    # odometry increments
    [[1.    0.    0.1  ]
     [1.005 0.    0.1  ]]
    """
    pa, pb = _pair(a, b)
    return se2_compose(se2_inverse(pa), pb, validate=False)


def se2_to_matrix(pose: Any) -> np.ndarray:
    """Return the 3x3 homogeneous matrix of a planar pose ``[x, y, theta]``.

    Parameters
    ----------
    pose : array_like, shape (3,)

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        ``[[cos t, -sin t, x], [sin t, cos t, y], [0, 0, 1]]``.

    Raises
    ------
    ValueError
        If the pose does not have shape (3,) or is not finite.

    Notes
    -----
    Lynch & Park (2017), Sec. 3.3.1 (SE(2) as a matrix group).

    Examples
    --------
    >>> print(np.round(se2_to_matrix([1.0, 2.0, 0.0]), 3) + 0.0)
    [[1. 0. 1.]
     [0. 1. 2.]
     [0. 0. 1.]]
    """
    p = as_array(pose, "pose", shape=(3,))
    c, s = np.cos(p[2]), np.sin(p[2])
    return np.array([[c, -s, p[0]], [s, c, p[1]], [0.0, 0.0, 1.0]])


def matrix_to_se2(matrix: Any) -> np.ndarray:
    """Return ``[x, y, theta]`` from a 3x3 homogeneous planar transform (inverse of :func:`se2_to_matrix`).

    Parameters
    ----------
    matrix : array_like, shape (3, 3)
        A rigid planar transform (rotation block orthonormal within 1e-6).

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    ValueError
        If the shape is wrong or the rotation block is not a rotation.

    Notes
    -----
    Lynch & Park (2017), Sec. 3.3.1.

    Examples
    --------
    >>> print(np.round(matrix_to_se2(se2_to_matrix([1.0, 2.0, 0.3])), 6))
    [1.  2.  0.3]
    """
    T = as_array(matrix, "matrix", shape=(3, 3))
    as_rotation(T[:2, :2], "matrix", dim=2)
    return np.array([T[0, 2], T[1, 2], float(np.arctan2(T[1, 0], T[0, 0]))])



def intersect_lines(origins: Any, directions: Any) -> tuple[np.ndarray, np.ndarray]:
    """The point nearest (least squares) to N >= 2 lines in the plane, and where it lies along each.

    Parameters
    ----------
    origins : array_like, shape (N, 2)
        A point of each line.
    directions : array_like, shape (N, 2)
        Each line's direction (any non-zero length).

    Returns
    -------
    point : numpy.ndarray, shape (2,)
        Minimises the sum of squared perpendicular distances to the lines.
    along : numpy.ndarray, shape (N,)
        Signed distance from each origin to the point's foot along its unit direction (negative:
        behind the origin, so a ray from it would miss).

    Raises
    ------
    ValueError
        For shapes that differ, fewer than two lines, zero directions, or lines that are all
        parallel (within 1e-9), which leave the point undetermined.

    Notes
    -----
    ``sum_i (I - u_i u_i^T) (p - o_i) = 0`` with ``u_i`` the unit directions: the normal equations
    of the perpendicular distances (Hartley & Zisserman's mid-point triangulation, in 2-D).
    Lesson 02 intersects the directions of travel that two map nodes' essential matrices give.

    Examples
    --------
    >>> p, along = intersect_lines([[0.0, 0.0], [4.0, 0.0]], [[1.0, 1.0], [-1.0, 1.0]])
    >>> print(np.round(p, 6) + 0.0, np.round(along, 6))
    [2. 2.] [2.828427 2.828427]
    """
    o = as_array(origins, "origins", shape=(None, 2))
    d = as_array(directions, "directions", shape=(len(o), 2))
    if len(o) < 2:
        raise ValueError(f"origins: expected at least two lines, got {len(o)}")
    norm = np.linalg.norm(d, axis=1)
    if np.any(norm < 1e-12):
        raise ValueError("directions: expected non-zero directions, got a zero vector")
    u = d / norm[:, None]
    P = np.eye(2) - u[:, :, None] * u[:, None, :]                  # projections off each line
    A, b = P.sum(0), np.einsum("nij,nj->i", P, o)
    if np.linalg.det(A) < 1e-9 * len(o):
        raise ValueError("directions: expected lines that are not all parallel, got parallel ones")
    point = np.linalg.solve(A, b)
    return point, ((point - o) * u).sum(1)


def cross_rays(p: Any, d: Any, q: Any, e: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where pairs of lines in the plane cross: ``p + s d = q + t e``, for N pairs at once.

    Parameters
    ----------
    p, q : array_like, shape (N, 2) or (2,)
        A point of each first and each second line (a single point is shared by all pairs).
    d, e : array_like, shape (N, 2)
        Their unit directions.

    Returns
    -------
    s, t : numpy.ndarray, shape (N,)
        Distances along ``d`` from ``p`` and along ``e`` from ``q`` to the crossing (negative:
        behind the point; NaN or inf for parallel lines).
    sin : numpy.ndarray, shape (N,)
        ``d x e``, the sine of the angle from ``d`` to ``e`` (0 for parallel lines).

    Raises
    ------
    ValueError
        For shapes that do not broadcast to (N, 2), or NaN or inf entries.

    Notes
    -----
    Cramer's rule on ``[d, -e] [s, t]^T = q - p``; with unit directions the determinant is the
    sine of the angle between the rays (Hartley & Zisserman 2004, Sec. 12.2, two-view triangulation
    in the plane). Lesson 02 places landmarks where two nodes' feature rays cross.

    Examples
    --------
    >>> s, t, sin = cross_rays([0.0, 0.0], [[1.0, 0.0]], [[2.0, -1.0]], [[0.0, 1.0]])
    >>> s.tolist(), t.tolist(), sin.tolist()          # they cross at (2, 0)
    ([2.0], [1.0], [1.0])
    """
    P, D, Q, E = (np.atleast_2d(as_array(v, name)) for v, name in ((p, "p"), (d, "d"), (q, "q"), (e, "e")))
    try:
        P, D, Q, E = np.broadcast_arrays(P, D, Q, E)
    except ValueError:
        raise ValueError(f"p, d, q, e: expected shapes that broadcast to (N, 2), got {P.shape}, {D.shape}, "
                         f"{Q.shape}, {E.shape}") from None
    if P.ndim != 2 or P.shape[1] != 2:
        raise ValueError(f"p, d, q, e: expected shapes that broadcast to (N, 2), got {P.shape}")
    b = Q - P
    sin = D[:, 0] * E[:, 1] - D[:, 1] * E[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (b[:, 0] * E[:, 1] - b[:, 1] * E[:, 0]) / sin
        t = (b[:, 0] * D[:, 1] - b[:, 1] * D[:, 0]) / sin
    return s, t, sin
