"""Compiled (numba) forward kinematics, Jacobian and pose error of one configuration.

Unchecked kernels of the IK solvers' single-target paths, imported on their first solve (see
:mod:`robokit.arm.jit`). They compute what :meth:`robokit.arm.Chain.frames`,
:func:`robokit.arm.jacobian.jacobian_from_frames` and :func:`robokit.geometry.pose_error` compute, with
the same formulas (the tests compare them): link ``i`` is ``K_i + cos(theta_i) U_i + sin(theta_i)
V_i`` with the chain's precomputed ``K, U, V``.

References
----------
.. [1] B. Siciliano, L. Sciavicco, L. Villani and G. Oriolo, *Robotics: Modelling, Planning and
   Control*, Springer, 2009, Eq. (3.30) (geometric Jacobian) and Sec. 3.7.3 (orientation error).
.. [2] K. M. Lynch and F. C. Park, *Modern Robotics*, Cambridge University Press, 2017, Sec. 3.2.3.3
   (matrix logarithm of a rotation).
"""
from __future__ import annotations

import math

import numpy as np

from .jit import njit


def chain_arrays(chain):
    """The arrays the kernels take for ``chain``: ``(K, U, V, offset, base, tool, first_axis_frame)``."""
    copies = tuple(np.array(x, dtype=float) for x in (*chain.link_terms, chain.offset, chain.base, chain.tool))
    return copies + (1 if chain.modified else 0,)


@njit
def se3_defect(T, tol):
    """0 if ``T`` (4, 4) is a finite SE(3) matrix within ``tol`` (as :func:`robokit.geometry.as_se3`), else 1."""
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[i, j]):
                return 1
    last = (0.0, 0.0, 0.0, 1.0)
    for j in range(4):
        if abs(T[3, j] - last[j]) > tol:
            return 1
    for i in range(3):
        for j in range(3):
            s = T[0, i] * T[0, j] + T[1, i] * T[1, j] + T[2, i] * T[2, j]
            if abs(s - (1.0 if i == j else 0.0)) > tol:
                return 1
    det = (T[0, 0] * (T[1, 1] * T[2, 2] - T[1, 2] * T[2, 1]) - T[0, 1] * (T[1, 0] * T[2, 2] - T[1, 2] * T[2, 0])
           + T[0, 2] * (T[1, 0] * T[2, 1] - T[1, 1] * T[2, 0]))
    return 0 if abs(det - 1.0) <= tol else 1


@njit
def frames(q, K, U, V, offset, base, tool, F):
    """Frames 0..n into ``F`` (n + 1, 4, 4); returns the flange transform (frame n times the tool)."""
    n = q.shape[0]
    for r in range(4):                          # element loops, not array assignment: numba compiles
        for k in range(4):                      # the latter with its shape-mismatch message (seconds)
            F[0, r, k] = base[r, k]
    A = np.empty((4, 4))
    for i in range(n):
        th = q[i] + offset[i]
        c, s = math.cos(th), math.sin(th)
        for r in range(4):
            for k in range(4):
                A[r, k] = K[i, r, k] + c * U[i, r, k] + s * V[i, r, k]
        matmul4(F[i], A, F[i + 1])
    return matmul4(F[n], tool, np.empty((4, 4)))


@njit
def matmul4(A, B, out):
    """``out = A @ B`` for 4 x 4 matrices (element loops; ``out`` must not be ``A`` or ``B``); returns ``out``."""
    for r in range(4):
        for k in range(4):
            out[r, k] = A[r, 0] * B[0, k] + A[r, 1] * B[1, k] + A[r, 2] * B[2, k] + A[r, 3] * B[3, k]
    return out


@njit
def pose_error(Tt, T, e):
    """``e`` (6,) = ``[p_t - p; log(R_t R^T)]`` as :func:`robokit.geometry.pose_error`; returns
    ``(|dp|^2, |dtheta|^2)``."""
    for i in range(3):
        e[i] = Tt[i, 3] - T[i, 3]
    R = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            R[i, j] = Tt[i, 0] * T[j, 0] + Tt[i, 1] * T[j, 1] + Tt[i, 2] * T[j, 2]
    v0, v1, v2 = 0.5 * (R[2, 1] - R[1, 2]), 0.5 * (R[0, 2] - R[2, 0]), 0.5 * (R[1, 0] - R[0, 1])
    cos = 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0)
    sin = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    theta = math.atan2(sin, cos)
    if cos < -0.99:                          # axis from the symmetric part, sign from the antisymmetric
        k = 0
        for i in range(1, 3):
            if R[i, i] - cos > R[k, k] - cos:
                k = i
        w = np.empty(3)
        for i in range(3):
            w[i] = 0.5 * (R[i, k] + R[k, i]) - (cos if i == k else 0.0)
        nw = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
        sign = -1.0 if (w[0] * v0 + w[1] * v1 + w[2] * v2) < 0 else 1.0
        for i in range(3):
            e[3 + i] = w[i] / nw * (sign * theta)
    else:
        f = theta / (sin + 1e-300)
        e[3], e[4], e[5] = v0 * f, v1 * f, v2 * f
    return e[0] ** 2 + e[1] ** 2 + e[2] ** 2, e[3] ** 2 + e[4] ** 2 + e[5] ** 2


@njit
def jacobian(F, flange, first, J):
    """Geometric Jacobian (6, n) into ``J`` from frames ``F``; joint ``i``'s axis is frame ``i + first``."""
    n = J.shape[1]
    for i in range(n):
        P = F[i + first]
        z0, z1, z2 = P[0, 2], P[1, 2], P[2, 2]
        r0, r1, r2 = flange[0, 3] - P[0, 3], flange[1, 3] - P[1, 3], flange[2, 3] - P[2, 3]
        J[0, i] = z1 * r2 - z2 * r1
        J[1, i] = z2 * r0 - z0 * r2
        J[2, i] = z0 * r1 - z1 * r0
        J[3, i], J[4, i], J[5, i] = z0, z1, z2
