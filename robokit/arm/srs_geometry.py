"""Per-target geometry of S-R-S arms, written once for one target (floats) or many (arrays).

The arm angle of a configuration and Shimizu's coefficients of a target are short sums of products.
They are written here in plain arithmetic on 3-vectors held as triples, so the same code runs on
Python floats (one target: no numpy call overhead, which dominates at that size) and on numpy
arrays of shape (N,) (many targets). ``xp`` selects the elementary functions: :data:`SCALAR` or
:data:`ARRAY`. Every function here is an unchecked kernel of :mod:`robokit.arm.srs` and
:mod:`robokit.arm.ik_analytic`, which validate their inputs.

Frames and conventions are those of :mod:`robokit.arm.srs`: ``Rz(q1) Ry(q2) Rz(q3)`` is the
shoulder rotation ``M``, ``v = (-d_ew sin q4, 0, d_se + d_ew cos q4)`` the shoulder-wrist vector in
the frame of ``M`` and ``R_4^7 = Ry(q4) M^T R_0^7`` the wrist rotation.

References
----------
.. [1] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
.. [2] J. J. Craig, *Introduction to Robotics: Mechanics and Control*, 3rd ed., Pearson, 2005.
"""
from __future__ import annotations

import math
import types

import numpy as np

SCALAR = types.SimpleNamespace(cos=math.cos, sin=math.sin, sqrt=math.sqrt, atan2=math.atan2,
                               hypot=math.hypot, acos=math.acos,
                               where=lambda c, a, b: a if c else b,
                               clip1=lambda x: min(1.0, max(-1.0, x)))
ARRAY = types.SimpleNamespace(cos=np.cos, sin=np.sin, sqrt=np.sqrt, atan2=np.arctan2, hypot=np.hypot,
                              acos=np.arccos, where=np.where,
                              clip1=lambda x: np.minimum(1.0, np.maximum(-1.0, x)))


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _plane_normal(x, y, xp):
    """``Rz(atan2(y, x)) e_y``, the normal of the vertical plane through ``(x, y, .)`` (``e_y`` if x = y = 0)."""
    h = xp.hypot(x, y)
    flat = h == 0
    h = xp.where(flat, 1.0, h)
    return (-y / h, xp.where(flat, 1.0, x / h), 0.0 * h)


def arm_angle_terms(q1, q2, q3, q4, d_se: float, d_ew: float, xp=ARRAY):
    """Unchecked: the arm angle ``psi`` of joint values (floats or arrays of equal shape).

    ``psi`` is the angle about the unit shoulder-wrist vector ``u`` of ``M R_ref^T`` (Shimizu et
    al. 2008, Eq. (9)). That rotation carries the reference plane's normal ``n_ref = R_ref e_y``,
    which is perpendicular to ``u``, to ``n = M e_y``, so ``psi = atan2(u . (n_ref x n), n_ref . n)``.
    """
    c1, s1, c2, s2, c3, s3 = xp.cos(q1), xp.sin(q1), xp.cos(q2), xp.sin(q2), xp.cos(q3), xp.sin(q3)
    vx, vz = -d_ew * xp.sin(q4), d_se + d_ew * xp.cos(q4)
    x, y = c2 * c3 * vx + s2 * vz, s3 * vx                       # Ry(q2) Rz(q3) v
    sw = (c1 * x - s1 * y, s1 * x + c1 * y, c2 * vz - s2 * c3 * vx)
    n = (-c1 * c2 * s3 - s1 * c3, c1 * c3 - s1 * c2 * s3, s2 * s3)
    n_ref = _plane_normal(sw[0], sw[1], xp)
    L2 = _dot(sw, sw)
    return xp.atan2(_dot(sw, _cross(n_ref, n)) / xp.sqrt(xp.where(L2 > 0, L2, 1.0)), _dot(n_ref, n))


def mirror_angle(x):
    """Unchecked: ``x + pi`` wrapped to (-pi, pi] for ``x`` in (-pi, pi]: the ZYZ mirror branch.

    ``Rz(a) Ry(b) Rz(c) = Rz(a + pi) Ry(-b) Rz(c + pi)`` (Craig 2005, Sec. 2.8).

    Examples
    --------
    >>> print(np.round(mirror_angle(np.array([0.5, -0.5])), 6))
    [-2.641593  2.641593]
    """
    return np.where(x > 0, x - np.pi, x + np.pi)


def coefficient_terms(R, sw, d_se: float, d_ew: float, xp=ARRAY):
    """Unchecked: Shimizu's ``A, B, C`` coefficients of one target (floats) or many (arrays).

    Parameters
    ----------
    R : 3 x 3 nested sequence
        Rotation of link 7 in frame 0, ``R[i][j]`` a float or an (N,) array.
    sw : triple
        Shoulder-to-wrist-centre vector.

    Returns
    -------
    terms : list of 108
        Coefficient (``A``, ``B``, ``C``), elbow sign (+, -), group (shoulder, wrist), entry of the
        group's 3 x 3 rotation (row-major), in that nesting order; entry
        ``= A sin psi + B cos psi + C``.
    q4 : tuple
        Elbow angles ``(+acos c4, -acos c4)``.
    c4 : float or array
        ``cos q4`` by the law of cosines; ``|c4| > 1`` means out of reach.

    Notes
    -----
    Shimizu et al. (2008), Eqs. (13)-(17) and (20)-(22): ``M(psi) = R_psi M_ref`` with
    ``R_psi = I + sin psi [u]x + (1 - cos psi) [u]x^2``, so ``A = [u]x M_ref``,
    ``B = (I - u u^T) M_ref`` and ``C = u u^T M_ref``; the wrist terms are ``Ry(q4) X^T R`` for
    ``X`` in ``A, B, C``. The reference ``M_ref = Rz(q1) Ry(q2)`` has ``q1`` the azimuth of ``sw``
    and ``q2 = phi -+ beta`` (elevation of ``sw`` from the vertical, minus the angle between
    ``v`` and the upper arm), both from the triangle without trigonometry.
    """
    L2 = _dot(sw, sw)
    L = xp.sqrt(xp.where(L2 > 0, L2, 1.0))                        # L = 0 is out of reach anyway
    c4 = (L2 - (d_se * d_se + d_ew * d_ew)) / (2.0 * d_se * d_ew)
    cc = xp.clip1(c4)
    s4 = xp.sqrt(1.0 - cc * cc)
    a4 = xp.acos(cc)
    u = (sw[0] / L, sw[1] / L, sw[2] / L)
    m1 = _plane_normal(sw[0], sw[1], xp)                           # M_ref e_y = (-s1, c1, 0)
    c1, s1 = m1[1], -m1[0]
    cphi, sphi = sw[2] / L, xp.hypot(sw[0], sw[1]) / L
    cb, sb = (d_se + d_ew * cc) / L, d_ew * s4 / L                 # angle between v and e_z
    Rc = [(R[0][j], R[1][j], R[2][j]) for j in range(3)]           # columns of R
    out = [[], [], []]
    for sign in (1.0, -1.0):                                       # elbow q4 = +a4, then -a4
        c2, s2 = cphi * cb - sign * sphi * sb, sphi * cb + sign * cphi * sb
        cols = ((c1 * c2, s1 * c2, -s2), m1, (c1 * s2, s1 * s2, c2))  # columns of M_ref
        A = [_cross(u, m) for m in cols]
        C = [(u[0] * k, u[1] * k, u[2] * k) for k in (_dot(u, m) for m in cols)]
        B = [(m[0] - c[0], m[1] - c[1], m[2] - c[2]) for m, c in zip(cols, C)]
        ce, se = cc, sign * s4                                       # cos, sin of this q4
        for k, X in enumerate((A, B, C)):
            for row in zip(*X):                                      # shoulder (X holds columns)
                out[k].extend(row)
            P = [[_dot(X[i], Rc[j]) for j in range(3)] for i in range(3)]   # X^T R
            out[k].extend([ce * P[0][j] + se * P[2][j] for j in range(3)])  # Ry(q4) X^T R, row by row
            out[k].extend(P[1])
            out[k].extend([ce * P[2][j] - se * P[0][j] for j in range(3)])
    return out[0] + out[1] + out[2], (a4, -a4), c4
