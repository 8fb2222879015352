"""Numerical inverse kinematics for any chain: damped least squares and redundancy resolution.

Three update rules share one vectorised iteration (many targets at once):

* ``"dls"``: damped least squares, ``dq = J^T (J J^T + lambda^2 I)^-1 e``;
* ``"gradient_projection"``: DLS plus the gradient of a joint-range criterion projected into the
  Jacobian's null space (Liégeois 1977; Dubey, Euler & Babcock 1988);
* ``"wln"``: weighted least norm, ``dq = W^-1 J^T (J W^-1 J^T + lambda^2 I)^-1 e`` with Chan &
  Dubey's (1995) joint-limit weights.

Random restarts from configurations drawn inside the limits handle local minima. Success is decided
by FK verification: pose error below tolerance AND every joint within limits.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, as_rng, check_choice, check_int, check_positive
from .chain import Chain
from .jacobian import _jacobian_from_frames
from .limits import _limit_gradient, _wln
from .result import IKBatchResult, IKResult, _verify
from .se3 import _pose_error, as_se3

__all__ = ["METHODS", "dls_step", "null_space_step", "ik_numeric", "ik_numeric_batch"]

METHODS = ("dls", "gradient_projection", "wln")
_EYE6 = np.eye(6)


def _jacobian_and_error(J: Any, e: Any):
    J = as_array(J, "J")
    if J.ndim not in (2, 3) or J.shape[-2] != 6:
        raise ValueError(f"J: expected a Jacobian of shape (6, n) or (N, 6, n), got shape {J.shape}")
    e = as_array(e, "e", shape=J.shape[:-2] + (6,))
    return J, e


def dls_step(J: Any, e: Any, damping: float = 1e-2, weights: Any = None) -> np.ndarray:
    """One damped-least-squares (optionally weighted) joint update.

    Parameters
    ----------
    J : array_like, shape (6, n) or (N, 6, n)
        Geometric Jacobian(s).
    e : array_like, shape (6,) or (N, 6)
        Pose error ``[dp; dtheta]`` (see :func:`robokit.arm.pose_error`).
    damping : float, default 1e-2
        Damping factor ``lambda`` (>= 0).
    weights : array_like, shape (n,) or (N, n), optional
        Positive joint weights ``W = diag(w)`` (weighted least norm); identity by default.

    Returns
    -------
    numpy.ndarray, shape (n,) or (N, n)
        ``dq = W^-1 J^T (J W^-1 J^T + lambda^2 I)^-1 e``.

    Raises
    ------
    ValueError
        On wrong shapes, NaN, a negative damping or non-positive weights.

    Notes
    -----
    Wampler, "Manipulator inverse kinematic solutions based on vector formulations and damped
    least-squares methods", IEEE T-SMC 16(1), 1986, Eq. (11); Nakamura & Hanafusa (1986). The
    weighted form is Chan & Dubey (1995), Eq. (7), damped.
    """
    J, e = _jacobian_and_error(J, e)
    lam = check_positive(damping, "damping", allow_zero=True)
    winv = None
    if weights is not None:
        w = as_array(weights, "weights", shape=J.shape[:-2] + (J.shape[-1],))
        if np.any(w <= 0):
            raise ValueError("weights: expected positive joint weights")
        winv = 1.0 / w
    return _dls(J, e, np.full(J.shape[:-2], lam**2), winv)


def _dls(J, e, lam2, winv=None):
    """Unchecked kernel: ``W^-1 J^T (J W^-1 J^T + lam2 I)^-1 e`` for stacked inputs."""
    JW = J if winv is None else J * winv[..., None, :]
    A = JW @ np.swapaxes(J, -1, -2) + lam2[..., None, None] * _EYE6
    y = np.linalg.solve(A, e[..., None])
    return (np.swapaxes(JW, -1, -2) @ y)[..., 0]


def null_space_step(J: Any, e: Any, gradient: Any, damping: float = 1e-2, gain: float = 1.0) -> np.ndarray:
    """DLS step plus a secondary-task gradient projected into the Jacobian's null space.

    Parameters
    ----------
    J : array_like, shape (6, n) or (N, 6, n)
    e : array_like, shape (6,) or (N, 6)
        Pose error.
    gradient : array_like, shape (n,) or (N, n)
        Gradient of the criterion to *increase* (e.g. :func:`~robokit.arm.limit_distance_gradient`).
    damping : float, default 1e-2
    gain : float, default 1.0
        Step along the projected gradient (>= 0).

    Returns
    -------
    numpy.ndarray, shape (n,) or (N, n)
        ``dq = J# e + gain (I - J# J) gradient`` with the damped pseudo-inverse
        ``J# = J^T (J J^T + lambda^2 I)^-1``.

    Raises
    ------
    ValueError
        On wrong shapes, NaN or negative damping/gain.

    Notes
    -----
    Liégeois (1977), Eq. (9); Dubey, Euler & Babcock (ICRA 1988), Sec. 2 (gradient projection).
    """
    J, e = _jacobian_and_error(J, e)
    g = as_array(gradient, "gradient", shape=J.shape[:-2] + (J.shape[-1],))
    lam = check_positive(damping, "damping", allow_zero=True)
    k = check_positive(gain, "gain", allow_zero=True)
    return _gp(J, e, g, np.full(J.shape[:-2], lam**2), k)


#: Regularisation of the null-space projector: ``J^T (J J^T + eps I)^-1 J`` has eigenvalues
#: ``s^2 / (s^2 + eps)`` in [0, 1], so the projector stays bounded at singularities while leaking
#: almost nothing of the secondary motion into the hand elsewhere.
_PROJ_EPS = 1e-9
#: Pose-error norm below which the null-space gain fades linearly to zero.
_FADE = 1e-2


def _gp(J, e, g, lam2, k):
    """Unchecked kernel of :func:`null_space_step`."""
    Jt = np.swapaxes(J, -1, -2)
    JJt = J @ Jt
    primary = (Jt @ np.linalg.solve(JJt + lam2[..., None, None] * _EYE6, e[..., None]))[..., 0]
    Jg = (J @ g[..., None])
    leak = (Jt @ np.linalg.solve(JJt + _PROJ_EPS * _EYE6, Jg))[..., 0]
    return primary + k[..., None] * (g - leak) if np.ndim(k) else primary + k * (g - leak)


def ik_numeric(chain: Chain, T: Any, q0: Any = None, **options: Any) -> IKResult:
    """Numerical IK of one target; see :func:`ik_numeric_batch` for the parameters.

    Runs ``parallel=16`` attempts side by side unless told otherwise (one from ``q0``): vectorised,
    they cost little more than one and make the time to a solution far more predictable.
    """
    if np.ndim(T) != 2:
        raise ValueError(f"T: expected one pose of shape (4, 4), got shape {np.shape(T)}")
    if q0 is not None and np.ndim(q0) != 1:
        raise ValueError(f"q0: expected one joint vector, got shape {np.shape(q0)}")
    options.setdefault("parallel", 16)
    return ik_numeric_batch(chain, T, q0, **options)[0]


def ik_numeric_batch(chain: Chain, T: Any, q0: Any = None, *, method: str = "wln", tol: float = 1e-6,
                     max_iter: int = 60, restarts: int = 40, damping: float = 1e-3, gain: float = 0.5,
                     clamp: bool = True, max_step: float = 0.5, patience: int = 15, parallel: int = 1,
                     rng: Any = None,
                     history: bool = False) -> IKBatchResult:
    """Numerical IK for many targets at once, with joint limits and random restarts.

    Parameters
    ----------
    chain : Chain
        Any serial chain (e.g. :func:`~robokit.arm.panda`).
    T : array_like, shape (N, 4, 4) or (4, 4)
        Target flange poses.
    q0 : array_like, shape (N, n) or (n,), optional
        Initial guesses; the middle of the joint ranges by default.
    method : {"wln", "dls", "gradient_projection"}, default "wln"
        Update rule (module docstring).
    tol : float, default 1e-6
        Tolerance on the position error [m] and the orientation error [rad].
    max_iter : int, default 60
        Iterations per attempt.
    restarts : int, default 40
        Extra attempts from random configurations inside the limits when an attempt fails.
    damping : float, default 1e-3
        Base damping ``lambda``; the damping used is ``lambda^2 + |e|^2 / 2`` (Sugihara 2011).
    gain : float, default 0.5
        Gain of the projected joint-range gradient (``"gradient_projection"`` only).
    clamp : bool, default True
        Clip every iterate to the joint limits. With ``False`` the solver may leave the limits,
        and such results count as failures.
    max_step : float, default 0.5
        Largest joint step per iteration [rad] (the step is scaled down, not clipped per joint).
    patience : int, default 15
        An attempt is abandoned (and restarted) when its pose error has not halved for this many
        iterations.
    parallel : int, default 1
        Attempts run side by side for each target (the first starts at ``q0``, the others at
        random configurations); the first to succeed wins. Vectorised, so for a single target a
        few parallel attempts cost little more than one and cut the time to a solution.
    rng : numpy.random.Generator or int, optional
        Source of the restart configurations.
    history : bool, default False
        Also return the iterates of the first attempt as ``result.history`` (shape
        ``(iterations + 1, N, n)``), for plotting joint trajectories.

    Returns
    -------
    IKBatchResult

    Raises
    ------
    ValueError
        On non-SE(3) targets, bad initial guesses, an unknown method or bad numbers.

    Notes
    -----
    The damping ``lambda^2 + |e|^2 / 2`` follows Sugihara, "Solvability-unconcerned inverse
    kinematics by the Levenberg-Marquardt method", IEEE T-RO 27(5), 2011, Eq. (13): large steps far
    away, Gauss-Newton speed near a solution, and bounded steps at unreachable targets.
    Random restarts are the remedy of TRAC-IK's KDL-RR variant (Beeson & Ames, Humanoids 2015).
    """
    if not isinstance(chain, Chain):
        raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
    Tt = as_se3(T, "T", batch=True)
    N, n = Tt.shape[0], chain.n
    method = check_choice(method, "method", METHODS)
    tol = check_positive(tol, "tol")
    max_iter = check_int(max_iter, "max_iter", minimum=1)
    restarts = check_int(restarts, "restarts", minimum=0)
    lam2_0 = check_positive(damping, "damping", allow_zero=True) ** 2
    gain = check_positive(gain, "gain", allow_zero=True)
    max_step = check_positive(max_step, "max_step")
    patience = check_int(patience, "patience", minimum=1)
    parallel = check_int(parallel, "parallel", minimum=1)
    gen = as_rng(rng)
    if q0 is None:
        q = np.tile(0.5 * (chain.qmin + chain.qmax), (N, 1))
    else:
        q = chain.check_q(q0, "q0", batch=True).copy()
        if q.shape[0] == 1 and N > 1:
            q = np.tile(q, (N, 1))
        elif q.shape[0] != N:
            raise ValueError(f"q0: expected one guess or {N} guesses (one per target), got {q.shape[0]}")

    dist = np.linalg.norm(Tt[:, :3, 3] - chain.base[:3, 3], axis=1)
    too_far = dist > chain.reach()
    # P parallel attempts per target: row r works on target r // P; row r % P == 0 starts at q0
    P = parallel
    R = N * P
    tgt = np.repeat(np.arange(N), P)
    qr = np.repeat(q, P, axis=0)
    if P > 1:
        extra = np.arange(R) % P != 0
        qr[extra] = gen.uniform(chain.qmin, chain.qmax, size=(int(extra.sum()), n))
    Tr = Tt[tgt]
    t_done = too_far.copy()
    alive = ~too_far[tgt]
    winner = np.full(N, -1)
    iters = np.zeros(N, int)
    tries = np.zeros(N, int)          # restarts used per target
    steps = np.zeros(R, int)
    best = np.full(R, np.inf)
    stall = np.zeros(R, int)
    prev_w = np.full((R, n), np.nan) if method == "wln" else None
    trail = [q.copy()] if history else None
    active = np.flatnonzero(alive)
    tol2 = tol * tol
    while active.size:
        full = active.size == R
        sel = slice(None) if full else active        # common case: views, no fancy-index copies
        qa = qr[sel]
        frames = chain._frames(qa)
        e = _pose_error(Tr[sel], chain._flange(frames))
        e2 = e * e
        pos2, rot2 = e2[:, :3].sum(1), e2[:, 3:].sum(1)
        e2s = pos2 + rot2
        conv = np.maximum(pos2, rot2) < tol2
        any_conv = bool(conv.any())
        finished = conv
        if any_conv:
            finished = conv.copy()
            qc = qa[conv]
            finished[conv] = np.all((qc >= chain.qmin) & (qc <= chain.qmax), axis=1)
            if finished.any():
                rows = active[finished]
                t = tgt[rows]
                first = np.unique(t, return_index=True)[1]
                winner[t[first]] = rows[first]
                t_done[t] = True
        err = np.sqrt(e2s)
        b = best[sel]
        improved = err < 0.5 * b
        best[sel] = np.where(improved, err, b)
        stall_a = np.where(improved, 0, stall[sel] + 1)
        stall[sel] = stall_a
        # an attempt ends after max_iter steps or when its error has not halved for `patience` steps;
        # a pose reached outside the limits (clamp=False) also ends it
        ended = (steps[sel] >= max_iter) | (stall_a >= patience)
        if any_conv:
            ended = ~finished & (ended | conv)
        any_ended = bool(ended.any())
        if any_ended:
            for r in active[ended]:
                t = tgt[r]
                if tries[t] < restarts:
                    qr[r] = gen.uniform(chain.qmin, chain.qmax)
                    tries[t] += 1
                    steps[r], best[r], stall[r] = 0, np.inf, 0
                    if prev_w is not None:
                        prev_w[r] = np.nan
                else:
                    alive[r] = False
        everyone = not (any_conv or any_ended)
        if not everyone:
            stepping = ~(finished | ended)
            if P > 1 and any_conv:
                stepping &= ~t_done[tgt[active]]
            everyone = bool(stepping.all())
        rows = sel if everyone else active[stepping]
        if everyone or rows.size:
            if everyone:
                fr, es, qs = frames, e, qa
            else:
                fr, es, qs, e2s = frames[stepping], e[stepping], qa[stepping], e2s[stepping]
            J = _jacobian_from_frames(chain, fr)
            lam2 = lam2_0 + 0.5 * e2s
            if method == "dls":
                dq = _dls(J, es, lam2)
            elif method == "gradient_projection":
                # the null-space motion is exact only to first order: fade it out near the target
                fade = np.minimum(1.0, np.sqrt(e2s) / _FADE)
                dq = _gp(J, es, _limit_gradient(chain, qs), lam2, gain * fade)
            else:
                w, grad = _wln(chain, qs, prev_w[rows])
                prev_w[rows] = grad
                dq = _dls(J, es, lam2, 1.0 / w)
            big = np.sqrt(np.einsum("ij,ij->i", dq, dq))
            over = big > max_step
            if over.any():
                dq[over] *= (max_step / big[over])[:, None]
            qs = qs + dq
            if clamp:
                qs = np.minimum(np.maximum(qs, chain.qmin), chain.qmax)
            qr[rows] = qs
            steps[rows] += 1
            if full and everyone:
                iters += P
            elif P == 1:
                iters[tgt[rows]] += 1
            else:
                iters += np.bincount(tgt[rows], minlength=N)
        if history and tries.max() == 0:
            trail.append(qr[::P].copy())
        if not everyone:
            active = np.flatnonzero(alive & ~t_done[tgt])

    # failed targets report their attempt with the smallest error
    q = qr[::P].copy()
    ok = winner >= 0
    q[ok] = qr[winner[ok]]
    for t in np.flatnonzero(~ok & ~too_far):
        rows_t = np.arange(t * P, (t + 1) * P)
        q[t] = qr[rows_t[np.argmin(best[rows_t])]]
    success, reasons, residual, pos, rot = _verify(chain, Tt, q, tol, tol)
    for i in np.flatnonzero(too_far):
        reasons[i] = (f"out of reach: target {dist[i]:.3f} m from the base, beyond the arm's reach "
                      f"bound {chain.reach():.3f} m")
    for i in np.flatnonzero(~success & ~too_far):
        reasons[i] += f" after {tries[i] + parallel} attempts of up to {max_iter} iterations"
        if reasons[i].startswith("pose error"):
            reasons[i] += " (target may be unreachable)"
    out = IKBatchResult(q=q, success=success, reason=reasons, residual=residual, iterations=iters,
                        position_error=pos, orientation_error=rot, restarts=tries)
    if history:
        out.history = np.array(trail)
    return out
