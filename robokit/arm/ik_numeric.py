"""Numerical inverse kinematics for any chain: one search loop over the step rules of
:mod:`robokit.arm.ik_steps` (``"dls"``, ``"gradient_projection"``, ``"wln"``).

The search (:func:`ik_numeric_batch`) runs many attempts side by side (vectorised over targets and
parallel attempts): each pass evaluates the pose error of every live attempt, ends those that
converged (pose within tolerance and every joint within its limits), restarts those that stalled
from a random configuration, and moves the others by one step of the chosen rule. Random restarts
from configurations drawn inside the limits handle local minima. Success is decided by FK
verification (:func:`robokit.arm.result.verify`). :mod:`robokit.arm.ik_reference` is the same
algorithm for one target as a plain loop; the tests compare the two iterate by iterate.

References
----------
.. [1] T. Sugihara, "Solvability-unconcerned inverse kinematics by the Levenberg-Marquardt method",
   *IEEE Transactions on Robotics* 27(5), 984-991, 2011.
.. [2] P. Beeson and B. Ames, "TRAC-IK: an open-source library for improved solving of generic
   inverse kinematics", *Proc. IEEE-RAS International Conference on Humanoid Robots*, 2015.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..geometry import as_se3, pose_error
from ..validation import as_rng, check_choice, check_int, check_positive
from .chain import Chain
from .ik_steps import METHODS, STEP_RULES
from .jacobian import jacobian_from_frames
from .result import IKBatchResult, IKResult, verify

__all__ = ["ik_numeric", "ik_numeric_batch"]


# --- the search -----------------------------------------------------------------------------------
def _claim_targets(chain: Chain, qa, conv, active, tgt, winner, t_done) -> np.ndarray:
    """Unchecked: which converged attempts are also within the limits; the first of them per target
    becomes its winner (``winner``, ``t_done`` updated in place). Returns that mask over ``active``."""
    finished = conv.copy()
    qc = qa[conv]
    finished[conv] = np.all((qc >= chain.qmin) & (qc <= chain.qmax), axis=1)
    if finished.any():
        rows = active[finished]
        t = tgt[rows]
        first = np.unique(t, return_index=True)[1]
        winner[t[first]] = rows[first]
        t_done[t] = True
    return finished


def _restart_or_retire(chain: Chain, rows, tgt, tries, restarts, qr, steps, best, stall, alive, step, gen) -> None:
    """Unchecked: restart ended attempts ``rows`` from random configurations while their target has
    restarts left (in row order, which fixes the random draws), retire them otherwise. Random
    restarts are TRAC-IK's KDL-RR remedy for local minima (Beeson & Ames 2015)."""
    for r in rows:
        t = tgt[r]
        if tries[t] < restarts:
            qr[r] = gen.uniform(chain.qmin, chain.qmax)
            tries[t] += 1
            steps[r], best[r], stall[r] = 0, np.inf, 0
            step.restart(r)
        else:
            alive[r] = False


def _search(chain: Chain, T: np.ndarray, q0: np.ndarray, skip: np.ndarray, step, *, tol: float, max_iter: int,
            restarts: int, patience: int, parallel: int, clamp: bool, max_step: float, gen, history: bool):
    """Unchecked: run the attempts of every target until one converges or all are used up.

    ``parallel`` attempts per target run side by side: row ``r`` works on target ``r // parallel``
    and row ``r % parallel == 0`` starts at ``q0``, the others at random configurations. Targets
    marked ``skip`` are not attempted. Returns ``(q, iterations, restarts, trail)``: per target the
    winning attempt's joints or, failing that, the attempt with the smallest error; ``trail`` holds
    the first attempts' iterates (with ``history``).
    """
    N, n = q0.shape
    P, R = parallel, N * parallel
    tgt = np.repeat(np.arange(N), P)
    qr = np.repeat(q0, P, axis=0)
    if P > 1:
        extra = np.arange(R) % P != 0
        qr[extra] = gen.uniform(chain.qmin, chain.qmax, size=(int(extra.sum()), n))
    Tr = T[tgt]
    t_done = skip.copy()
    alive = ~skip[tgt]
    winner = np.full(N, -1)
    iters = np.zeros(N, int)
    tries = np.zeros(N, int)          # restarts used per target
    steps = np.zeros(R, int)
    best = np.full(R, np.inf)
    stall = np.zeros(R, int)
    trail = [q0.copy()] if history else None
    active = np.flatnonzero(alive)
    tol2 = tol * tol
    while active.size:
        full = active.size == R
        sel = slice(None) if full else active        # common case: views, no fancy-index copies
        qa = qr[sel]
        # 1. pose error of every live attempt
        frames = chain.frames(qa, check=False)
        e = pose_error(Tr[sel], chain.flange_transform(frames, check=False), check=False)
        e2 = e * e
        pos2, rot2 = e2[:, :3].sum(1), e2[:, 3:].sum(1)
        e2s = pos2 + rot2
        # 2. converged: within tolerance; it wins its target if also within the limits
        conv = np.maximum(pos2, rot2) < tol2
        any_conv = bool(conv.any())
        finished = _claim_targets(chain, qa, conv, active, tgt, winner, t_done) if any_conv else conv
        # 3. an attempt ends after max_iter steps or when its error has not halved for `patience`
        #    steps; a pose reached outside the limits (clamp=False) also ends it
        err = np.sqrt(e2s)
        b = best[sel]
        improved = err < 0.5 * b
        best[sel] = np.where(improved, err, b)
        stall_a = np.where(improved, 0, stall[sel] + 1)
        stall[sel] = stall_a
        ended = (steps[sel] >= max_iter) | (stall_a >= patience)
        if any_conv:
            ended = ~finished & (ended | conv)
        any_ended = bool(ended.any())
        if any_ended:
            _restart_or_retire(chain, active[ended], tgt, tries, restarts, qr, steps, best, stall, alive, step, gen)
        # 4. one step of the method for every attempt still going
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
            dq = step(jacobian_from_frames(chain, fr, check=False), es, e2s, qs, rows)
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
    for t in np.flatnonzero(~ok & ~skip):
        rows_t = np.arange(t * P, (t + 1) * P)
        q[t] = qr[rows_t[np.argmin(best[rows_t])]]
    return q, iters, tries, trail


# --- the solvers ----------------------------------------------------------------------------------
def ik_numeric(chain: Chain, T: Any, q0: Any = None, **options: Any) -> IKResult:
    """Numerical IK of one target; see :func:`ik_numeric_batch` for the parameters.

    Runs ``parallel=16`` attempts side by side unless told otherwise (one from ``q0``): vectorised,
    they cost little more than one and make the time to a solution far more predictable.

    Raises
    ------
    ValueError
        As :func:`ik_numeric_batch`, or if ``T`` is not one (4, 4) transform or ``q0`` not one
        joint vector.

    Notes
    -----
    Sugihara (2011) damping; random restarts as in Beeson & Ames (2015).

    Examples
    --------
    >>> from robokit.arm import panda
    >>> arm = panda()
    >>> T = arm.fk(arm.random_q(rng=3))
    >>> r = ik_numeric(arm, T, arm.random_q(rng=4), rng=1)
    >>> r.success, r.reason, bool(r.position_error < 1e-6)
    (True, 'converged', True)
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
                     rng: Any = None, history: bool = False) -> IKBatchResult:
    """Numerical IK for many targets at once, with joint limits and random restarts.

    Parameters
    ----------
    chain : Chain
        Any serial chain (e.g. :func:`~robokit.arm.panda`).
    T : array_like, shape (N, 4, 4) or (4, 4)
        Target flange transforms.
    q0 : array_like, shape (N, n) or (n,), optional
        Initial guesses; the middle of the joint ranges by default.
    method : {"wln", "dls", "gradient_projection"}, default "wln"
        Step rule (:mod:`robokit.arm.ik_steps`).
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
    The damping ``lambda^2 + |e|^2 / 2`` follows Sugihara (2011), Eq. (13): large steps far away,
    Gauss-Newton speed near a solution, and bounded steps at unreachable targets. Random restarts
    are the remedy of TRAC-IK's KDL-RR variant (Beeson & Ames 2015).

    Examples
    --------
    >>> from robokit.arm import panda
    >>> arm = panda()
    >>> T = arm.fk(arm.random_q(20, rng=5))
    >>> res = ik_numeric_batch(arm, T, arm.random_q(20, rng=6), method="dls", rng=1)
    >>> res.success_rate, bool(res.orientation_error[res.success].max() < 1e-6)
    (1.0, True)
    """
    if not isinstance(chain, Chain):
        raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
    Tt = as_se3(T, "T", batch=True)
    N = Tt.shape[0]
    method = check_choice(method, "method", METHODS)
    tol = check_positive(tol, "tol")
    max_iter = check_int(max_iter, "max_iter", minimum=1)
    restarts = check_int(restarts, "restarts", minimum=0)
    damping = check_positive(damping, "damping", allow_zero=True)
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
    step = STEP_RULES[method](chain, N * parallel, damping, gain)
    q, iters, tries, trail = _search(chain, Tt, q, too_far, step, tol=tol, max_iter=max_iter, restarts=restarts,
                                     patience=patience, parallel=parallel, clamp=bool(clamp), max_step=max_step,
                                     gen=gen, history=history)
    out = verify(chain, Tt, q, tol, check=False)
    for i in np.flatnonzero(too_far):
        out.reason[i] = (f"out of reach: target {dist[i]:.3f} m from the base, beyond the arm's reach "
                         f"bound {chain.reach():.3f} m")
    for i in np.flatnonzero(~out.success & ~too_far):
        out.reason[i] += f" after {tries[i] + parallel} attempts of up to {max_iter} iterations"
        if out.reason[i].startswith("pose error"):
            out.reason[i] += " (target may be unreachable)"
    out.iterations, out.restarts = iters, tries
    if history:
        out.history = np.array(trail)
    return out
