"""Compiled (numba) numerical IK of one target: the search of :mod:`robokit.arm.ik_numeric` in one call.

Unchecked kernel of :func:`robokit.arm.ik_numeric`, imported on its first solve (see
:mod:`robokit.arm.jit`). It runs the same attempts as :func:`robokit.arm.ik_numeric_batch` for one
target, pass by pass (``parallel`` attempts side by side, the first to converge inside the limits
wins, stalled attempts restart from random configurations in row order), with the same step rules
(:mod:`robokit.arm.ik_steps`: ``0`` DLS, ``1`` gradient projection, ``2`` weighted least norm). The
random configurations are drawn by the caller, in the order the batch search draws them. The
tests compare the iterates and answers with :func:`~robokit.arm.ik_numeric_batch` and
:func:`~robokit.arm.ik_readable.ik_numeric_readable`.

References
----------
.. [1] C. W. Wampler, "Manipulator inverse kinematic solutions based on vector formulations and
   damped least-squares methods", *IEEE Transactions on Systems, Man, and Cybernetics* 16(1),
   93-101, 1986.
.. [2] A. Liégeois, "Automatic supervisory control of the configuration and behavior of multibody
   mechanisms", *IEEE Transactions on Systems, Man, and Cybernetics* 7(12), 868-871, 1977.
.. [3] T. F. Chan and R. V. Dubey, "A weighted least-norm solution based scheme for avoiding joint
   limits for redundant joint manipulators", *IEEE Transactions on Robotics and Automation* 11(2),
   286-292, 1995.
.. [4] T. Sugihara, "Solvability-unconcerned inverse kinematics by the Levenberg-Marquardt method",
   *IEEE Transactions on Robotics* 27(5), 984-991, 2011.
"""
from __future__ import annotations

import math

import numpy as np

from .chain_kernels import se3_defect, frames, jacobian, pose_error
from .jit import njit

__all__ = ["search", "step", "solve6", "se3_defect", "DLS", "GRADIENT_PROJECTION", "WLN"]

#: Method codes of the kernel.
DLS, GRADIENT_PROJECTION, WLN = 0, 1, 2


@njit
def solve6(A, b, x):
    """``x = A^-1 b`` for a 6 x 6 system by Gaussian elimination with partial pivoting (``A``, ``b`` overwritten)."""
    n = 6
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(A[i, k]) > abs(A[p, k]):
                p = i
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
            b[k], b[p] = b[p], b[k]
        for i in range(k + 1, n):
            f = A[i, k] / A[k, k]
            for j in range(k, n):
                A[i, j] -= f * A[k, j]
            b[i] -= f * b[k]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= A[i, j] * x[j]
        x[i] = s / A[i, i]


@njit
def _damped_solve(J, winv, lam2, rhs, y):
    """``y = (J W^-1 J^T + lam2 I)^-1 rhs``."""
    n = J.shape[1]
    A = np.empty((6, 6))
    for i in range(6):
        for j in range(6):
            s = 0.0
            for k in range(n):
                s += J[i, k] * winv[k] * J[j, k]
            A[i, j] = s + (lam2 if i == j else 0.0)
    solve6(A, rhs.copy(), y)


@njit
def step(method, J, e, err2, q, previous, lo, hi, lam2_0, gain, fade_at, proj_eps, dq):
    """One step of the rule ``method`` into ``dq`` (``previous``: WLN's ``|dH/dq|``, updated)."""
    n = q.shape[0]
    lam2 = lam2_0 + 0.5 * err2                                  # Sugihara Eq. (13)
    winv = np.ones(n)
    if method == WLN:                                           # Chan & Dubey Eqs. (11), (13)
        for j in range(n):
            span = hi[j] - lo[j]
            eps = 1e-9 * max(span, 1e-9)
            qc = min(max(q[j], lo[j] + eps), hi[j] - eps)
            grad = abs(span * span * (2 * qc - hi[j] - lo[j]) / (4 * (hi[j] - qc) ** 2 * (qc - lo[j]) ** 2))
            winv[j] = 1.0 / (1.0 + grad) if grad >= previous[j] else 1.0
            previous[j] = grad
    y = np.empty(6)
    _damped_solve(J, winv, lam2, e, y)
    for j in range(n):
        s = 0.0
        for i in range(6):
            s += J[i, j] * y[i]
        dq[j] = winv[j] * s                                     # Wampler Eq. (11), Chan & Dubey Eq. (7)
    if method == GRADIENT_PROJECTION:                           # Liégeois Eqs. (9), (14)
        k = gain * min(1.0, math.sqrt(err2) / fade_at)
        g = np.empty(n)
        for j in range(n):
            half = max(0.5 * (hi[j] - lo[j]), 1e-9)
            g[j] = -(q[j] - 0.5 * (lo[j] + hi[j])) / half ** 2
        Jg = np.empty(6)
        for i in range(6):
            s = 0.0
            for j in range(n):
                s += J[i, j] * g[j]
            Jg[i] = s
        _damped_solve(J, np.ones(n), proj_eps, Jg, y)
        for j in range(n):
            s = 0.0
            for i in range(6):
                s += J[i, j] * y[i]
            dq[j] += k * (g[j] - s)


@njit
def search(Tt, q0, pool, K, U, V, offset, base, tool, first, lo, hi, method, tol, max_iter, restarts, lam2_0, gain,
           clamp, max_step, patience, P, fade_at, proj_eps, q_out, info):
    """The attempts of one target until one converges inside the limits or all are used up.

    ``pool`` (P - 1 + restarts, n): the random configurations of the extra attempts, then of the
    restarts, in the batch search's order. Returns the winning row (-1: none); ``q_out`` gets the
    answer (the winner, or the attempt with the smallest error) and ``info`` = (position error,
    orientation error, iterations, restarts) of the answer.
    """
    n = q0.shape[0]
    q = np.empty((P, n))                                        # element copies, not array assignment
    for j in range(n):                                          # (see chain_kernels.frames)
        q[0, j] = q0[j]
    for r in range(1, P):
        for j in range(n):
            q[r, j] = pool[r - 1, j]
    drawn = P - 1
    steps, stall = np.zeros(P, np.int64), np.zeros(P, np.int64)
    best = np.full(P, np.inf)
    alive = np.ones(P, np.bool_)
    previous = np.full((P, n), np.nan)
    F = np.empty((P, n + 1, 4, 4))
    flange = np.empty((P, 4, 4))
    e = np.empty((P, 6))
    err2 = np.empty(P)
    conv, finished, ended = np.zeros(P, np.bool_), np.zeros(P, np.bool_), np.zeros(P, np.bool_)
    J, dq = np.empty((6, n)), np.empty(n)
    winner, iterations, used = -1, 0, 0
    while True:
        any_conv = any_ended = False
        n_active = 0
        for r in range(P):                                      # 1. pose errors; 2. converged rows claim
            if not alive[r]:
                continue
            n_active += 1
            out = frames(q[r], K, U, V, offset, base, tool, F[r])
            for i in range(4):
                for k in range(4):
                    flange[r, i, k] = out[i, k]
            pos2, rot2 = pose_error(Tt, flange[r], e[r])
            err2[r] = pos2 + rot2
            conv[r] = max(pos2, rot2) < tol * tol
            finished[r] = False
            if conv[r]:
                any_conv = True
                inside = True
                for j in range(n):
                    if q[r, j] < lo[j] or q[r, j] > hi[j]:
                        inside = False
                finished[r] = inside
                if inside and winner < 0:
                    winner = r
        if n_active == 0:
            break
        for r in range(P):                                      # 3. ended rows restart or retire
            if not alive[r]:
                continue
            err = math.sqrt(err2[r])
            if err < 0.5 * best[r]:
                best[r], stall[r] = err, 0
            else:
                stall[r] += 1
            ended[r] = steps[r] >= max_iter or stall[r] >= patience
            if any_conv:
                ended[r] = not finished[r] and (ended[r] or conv[r])
            any_ended = any_ended or ended[r]
        if winner >= 0 and P == 1:
            break
        for r in range(P):
            if alive[r] and ended[r]:
                if used < restarts:
                    for j in range(n):
                        q[r, j] = pool[drawn, j]
                    drawn += 1
                    used += 1
                    steps[r], best[r], stall[r] = 0, np.inf, 0
                    previous[r, :] = np.nan
                else:
                    alive[r] = False
        if winner >= 0:
            break
        for r in range(P):                                      # 4. the others take one step
            if not alive[r] or ended[r] or finished[r]:
                continue
            jacobian(F[r], flange[r], first, J)
            step(method, J, e[r], err2[r], q[r], previous[r], lo, hi, lam2_0, gain, fade_at, proj_eps, dq)
            big = 0.0
            for j in range(n):
                big += dq[j] * dq[j]
            big = math.sqrt(big)
            if big > max_step:
                dq *= max_step / big
            for j in range(n):
                x = q[r, j] + dq[j]
                q[r, j] = min(max(x, lo[j]), hi[j]) if clamp else x
            steps[r] += 1
            iterations += 1
    if winner < 0:
        winner_row = 0
        for r in range(1, P):
            if best[r] < best[winner_row]:
                winner_row = r
    else:
        winner_row = winner
    for j in range(n):
        q_out[j] = q[winner_row, j]
    fl = frames(q_out, K, U, V, offset, base, tool, F[0])
    pos2, rot2 = pose_error(Tt, fl, e[0])
    info[0], info[1], info[2], info[3] = math.sqrt(pos2), math.sqrt(rot2), iterations, used
    return winner
