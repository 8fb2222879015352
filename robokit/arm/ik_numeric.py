"""Numerical inverse kinematics for any chain: one search loop over the step rules of
:mod:`robokit.arm.ik_steps` (``"dls"``, ``"gradient_projection"``, ``"wln"``).

The search (:func:`ik_numeric_batch`) runs many attempts side by side (vectorised over targets and
parallel attempts): each pass evaluates the pose error of every live attempt, ends those that
converged (pose within tolerance and every joint within its limits), restarts those that stalled
from a random configuration, and moves the others by one step of the chosen rule. Random restarts
from configurations drawn inside the limits handle local minima. Success is decided by FK
verification (:func:`robokit.arm.result.verify`). :mod:`robokit.arm.ik_readable` is the same
algorithm for one target as a plain loop; the tests compare the two iterate by iterate.

References
----------
.. [1] T. Sugihara, "Solvability-unconcerned inverse kinematics by the Levenberg-Marquardt method",
   *IEEE Transactions on Robotics* 27(5), 984-991, 2011.
.. [2] P. Beeson and B. Ames, "TRAC-IK: an open-source library for improved solving of generic
   inverse kinematics", *Proc. IEEE-RAS International Conference on Humanoid Robots*, 2015.
"""
from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from ..geometry import as_se3, pose_error
from ..geometry.rotations import ROTATION_TOL
from ..validation import array_ndim, as_rng, as_choice, as_int, as_positive
from .chain import Chain
from .ik_steps import PROJECTION_EPS, METHODS, NULL_SPACE_FADE, STEP_RULES
from .jacobian import jacobian_from_frames
from .result import IKBatchResult, IKResult, verify

__all__ = ["ik_numeric", "ik_numeric_batch"]


# --- the search -----------------------------------------------------------------------------------
class _Attempts:
    """Unchecked: the search's bookkeeping, ``parallel`` attempts (rows) per target side by side.

    Row ``r`` works on target ``r // parallel``; row ``r % parallel == 0`` starts at ``q0``, the
    others at random configurations. Per row: the joints ``q``, ``steps`` taken, the ``best`` error
    so far, the steps since it last halved (``stall``) and whether it is ``alive``. Per target: the
    winning row (``winner``, -1 while none), ``iterations``, ``restarts`` used and ``done``.
    """

    def __init__(self, chain: Chain, q0: np.ndarray, skip: np.ndarray, parallel: int, gen):
        N, n = q0.shape
        self.chain, self.gen, self.P, self.N = chain, gen, parallel, N
        self.rows = N * parallel
        self.target = np.repeat(np.arange(N), parallel)
        self.q = np.repeat(q0, parallel, axis=0)
        if parallel > 1:
            extra = np.arange(self.rows) % parallel != 0
            self.q[extra] = gen.uniform(chain.qmin, chain.qmax, size=(int(extra.sum()), n))
        self.steps = np.zeros(self.rows, int)
        self.best = np.full(self.rows, np.inf)
        self.stall = np.zeros(self.rows, int)
        self.alive = ~skip[self.target]
        self.skip = skip
        self.done = skip.copy()
        self.winner = np.full(N, -1)
        self.iterations = np.zeros(N, int)
        self.restarts = np.zeros(N, int)

    def live(self) -> np.ndarray:
        """Rows still searching: alive, on a target nobody has won."""
        return np.flatnonzero(self.alive & ~self.done[self.target])

    def claim(self, active: np.ndarray, q: np.ndarray, converged: np.ndarray) -> np.ndarray:
        """Converged attempts (mask over ``active``) at joints ``q`` finish if within the limits; the
        first of them per target wins it. Returns the finished mask over ``active``."""
        finished = converged.copy()
        qc = q[converged]
        finished[converged] = np.all((qc >= self.chain.qmin) & (qc <= self.chain.qmax), axis=1)
        if finished.any():
            rows = active[finished]
            t = self.target[rows]
            first = np.unique(t, return_index=True)[1]
            self.winner[t[first]] = rows[first]
            self.done[t] = True
        return finished

    def ended(self, sel, err: np.ndarray, max_iter: int, patience: int) -> np.ndarray:
        """Record the errors ``err`` of rows ``sel``; True where an attempt has taken ``max_iter``
        steps or its error has not halved for ``patience`` steps."""
        b = self.best[sel]
        improved = err < 0.5 * b
        self.best[sel] = np.where(improved, err, b)
        stall = np.where(improved, 0, self.stall[sel] + 1)
        self.stall[sel] = stall
        return (self.steps[sel] >= max_iter) | (stall >= patience)

    def restart_or_retire(self, rows: np.ndarray, restarts: int, step) -> None:
        """Restart ended attempts from random configurations while their target has restarts left
        (in row order, which fixes the random draws), retire them otherwise. Random restarts are
        TRAC-IK's KDL-RR remedy for local minima (Beeson & Ames 2015)."""
        for r in rows:
            t = self.target[r]
            if self.restarts[t] < restarts:
                self.q[r] = self.gen.uniform(self.chain.qmin, self.chain.qmax)
                self.restarts[t] += 1
                self.steps[r], self.best[r], self.stall[r] = 0, np.inf, 0
                step.restart(r)
            else:
                self.alive[r] = False

    def moved(self, rows, q: np.ndarray, everyone: bool) -> None:
        """Store the new joints ``q`` of ``rows`` and count the step."""
        self.q[rows] = q
        self.steps[rows] += 1
        if everyone:
            self.iterations += self.P
        elif self.P == 1:
            self.iterations[self.target[rows]] += 1
        else:
            self.iterations += np.bincount(self.target[rows], minlength=self.N)

    def answers(self) -> np.ndarray:
        """Per target the winning joints or, failing that, the attempt with the smallest error."""
        P = self.P
        q = self.q[::P].copy()
        ok = self.winner >= 0
        q[ok] = self.q[self.winner[ok]]
        for t in np.flatnonzero(~ok & ~self.skip):
            rows = np.arange(t * P, (t + 1) * P)
            q[t] = self.q[rows[np.argmin(self.best[rows])]]
        return q


def _step(chain: Chain, step, frames, e, err2, q, rows, max_step: float, clamp: bool) -> np.ndarray:
    """Unchecked: the joints after one step of the rule ``step``, scaled down to ``max_step`` (as a
    whole, not per joint) and clipped to the limits with ``clamp``."""
    dq = step(jacobian_from_frames(chain, frames, validate=False), e, err2, q, rows)
    big = np.sqrt(np.einsum("ij,ij->i", dq, dq))
    over = big > max_step
    if over.any():
        dq[over] *= (max_step / big[over])[:, None]
    q = q + dq
    return np.minimum(np.maximum(q, chain.qmin), chain.qmax) if clamp else q


def _search(chain: Chain, T: np.ndarray, q0: np.ndarray, skip: np.ndarray, step, *, tol: float, max_iter: int,
            restarts: int, patience: int, parallel: int, clamp: bool, max_step: float, gen, history: bool):
    """Unchecked: run the attempts of every target (see :class:`_Attempts`) until one converges or
    all are used up; targets marked ``skip`` are not attempted. Returns the :class:`_Attempts` and
    the first attempts' iterates (with ``history``)."""
    att = _Attempts(chain, q0, skip, parallel, gen)
    Tr = T[att.target]
    trail = [q0.copy()] if history else None
    active = att.live()
    while active.size:
        full = active.size == att.rows
        sel = slice(None) if full else active            # common case: views, no fancy-index copies
        q = att.q[sel]
        # 1. pose error of every live attempt
        frames = chain.frames(q, validate=False)
        e = pose_error(Tr[sel], chain.flange_transform(frames, validate=False), validate=False)
        e2 = e * e
        pos2, rot2 = e2[:, :3].sum(1), e2[:, 3:].sum(1)
        err2 = pos2 + rot2
        # 2. converged attempts (position and orientation within tol) claim their targets
        conv = np.maximum(pos2, rot2) < tol * tol
        any_conv = bool(conv.any())
        finished = att.claim(active, q, conv) if any_conv else conv
        # 3. ended attempts (out of steps, stalled, or converged outside the limits) restart or retire
        ended = att.ended(sel, np.sqrt(err2), max_iter, patience)
        if any_conv:
            ended = ~finished & (ended | conv)
        any_ended = bool(ended.any())
        if any_ended:
            att.restart_or_retire(active[ended], restarts, step)
        # 4. the others (of targets still open) take one step of the rule
        everyone = not (any_conv or any_ended)
        if not everyone:
            going = ~(finished | ended)
            if parallel > 1 and any_conv:
                going &= ~att.done[att.target[active]]
            everyone = bool(going.all())
        if everyone:
            att.moved(sel, _step(chain, step, frames, e, err2, q, sel, max_step, clamp), full)
        elif going.any():
            rows = active[going]
            att.moved(rows, _step(chain, step, frames[going], e[going], err2[going], q[going], rows, max_step, clamp),
                      False)
        if history and att.restarts.max() == 0:
            trail.append(att.q[::parallel].copy())
        if not everyone:
            active = att.live()
    return att, trail


# --- the solvers ----------------------------------------------------------------------------------
_KERNELS = None
#: Defaults of the solvers' options (:func:`ik_numeric_batch`); :func:`ik_numeric` runs one attempt
#: at a time (``parallel=1``) since its compiled search pays for every attempt it runs.
DEFAULTS = {"method": "wln", "tol": 1e-6, "max_iter": 60, "restarts": 40, "damping": 1e-3, "gain": 0.5,
            "clamp": True, "max_step": 0.5, "patience": 15, "parallel": 1, "rng": None, "history": False}


#: True until the first single solve of this process (its first call may compile, and says so).
_FIRST = [True]


def _kernels():
    """The compiled search, imported (and numba loaded) on the first solve, never by ``import robokit``."""
    global _KERNELS
    if _KERNELS is None:
        from . import numeric_kernels
        _KERNELS = numeric_kernels
    return _KERNELS


def _settings(method, tol, max_iter, restarts, damping, gain, clamp, max_step, patience, parallel):
    """The checked options of the solvers."""
    return (as_choice(method, "method", METHODS), as_positive(tol, "tol"),
            as_int(max_iter, "max_iter", minimum=1), as_int(restarts, "restarts", minimum=0),
            as_positive(damping, "damping", allow_zero=True), as_positive(gain, "gain", allow_zero=True),
            bool(clamp), as_positive(max_step, "max_step"), as_int(patience, "patience", minimum=1),
            as_int(parallel, "parallel", minimum=1))


def ik_numeric(chain: Chain, T: Any, q0: Any = None, **options: Any) -> IKResult:
    """Numerical IK of one target; see :func:`ik_numeric_batch` for the parameters.

    The same search as :func:`ik_numeric_batch` (same attempts, steps, restarts and answer), run
    as one compiled call (:mod:`robokit.arm.numeric_kernels`, numba, compiled on the first solve
    and cached on disk); ``history=True`` runs the vectorised search instead. One attempt at a time
    (``parallel=1``) unless told otherwise: compiled, every attempt side by side costs as much as
    one in turn. The restart configurations are drawn from ``rng`` before the search, all at once.

    Raises
    ------
    ValueError
        As :func:`ik_numeric_batch`, or if ``T`` is not one (4, 4) transform or ``q0`` not one
        joint vector.
    TypeError
        On an unknown option.

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
    if array_ndim(T, "T") != 2:
        raise ValueError(f"T: expected one pose of shape (4, 4), got shape {np.shape(T)}")
    if q0 is not None and array_ndim(q0, "q0") != 1:
        raise ValueError(f"q0: expected one joint vector, got shape {np.shape(q0)}")
    unknown = sorted(set(options) - set(DEFAULTS))
    if unknown:
        raise TypeError(f"options: expected some of {sorted(DEFAULTS)}, got unknown {unknown}")
    opts = {**DEFAULTS, **options}
    if opts["history"]:
        return ik_numeric_batch(chain, T, q0, **opts)[0]
    if not isinstance(chain, Chain):
        raise TypeError(f"chain: expected a robokit.arm.Chain, got {type(chain).__name__}")
    if options.keys() <= {"rng"}:
        settings = _DEFAULT_SETTINGS
    else:
        settings = _settings(*(opts[k] for k in _SETTINGS))
    method, tol, max_iter, restarts, damping, gain, clamp, max_step, patience, P = settings
    K = _kernels()
    if not (type(T) is np.ndarray and T.dtype == np.float64 and T.shape == (4, 4) and T.flags.c_contiguous
            and K.se3_defect(T, ROTATION_TOL) == 0):
        T = np.ascontiguousarray(as_se3(T, "T"))
    q = 0.5 * (chain.qmin + chain.qmax) if q0 is None else np.ascontiguousarray(chain.as_q(q0, "q0"))
    args, reach, base_p, lo, hi = _chain_data(chain)
    if math.dist(T[:3, 3], base_p) > reach:                          # the batch says why
        return ik_numeric_batch(chain, T, q, **opts)[0]
    seed = opts["rng"]
    if type(seed) is int and seed >= 0:                               # an integer seed draws the same every call: kept
        pool = _pool(chain, seed, P - 1 + restarts)
    else:
        pool = as_rng(seed).uniform(chain.qmin, chain.qmax, size=(P - 1 + restarts, chain.n))
    q_out, info = np.empty(chain.n), np.zeros(4)
    record = None
    if _FIRST:            # here, not earlier: a call that returns before the search compiles nothing
        _FIRST.clear()
        from .jit import compile_notice
        record = compile_notice("numeric_search", "the numerical IK solver")
    winner = K.search(T, q, pool, *args, lo, hi, _METHOD_CODE[method], tol, max_iter, restarts, damping**2, gain,
                      clamp, max_step, patience, P, NULL_SPACE_FADE, PROJECTION_EPS, q_out, info)
    if record is not None:
        from .jit import compiled
        compiled(record)
    pos, rot = float(info[0]), float(info[1])
    iterations, used = int(info[2]), int(info[3])
    if winner >= 0 and pos < tol and rot < tol:          # converged strictly inside the limits
        return IKResult(q=q_out, success=True, reason="converged", residual=math.hypot(pos, rot),
                        iterations=iterations, position_error=pos, orientation_error=rot, restarts=used)
    out = verify(chain, T[None], q_out[None], tol, validate=False)[0]
    out.reason += f" after {used + P} attempts of up to {max_iter} iterations"
    if out.reason.startswith("pose error"):
        out.reason += " (target may be unreachable)"
    out.iterations, out.restarts = iterations, used
    return out


_METHOD_CODE = {"dls": 0, "gradient_projection": 1, "wln": 2}


_SETTINGS = ("method", "tol", "max_iter", "restarts", "damping", "gain", "clamp", "max_step", "patience", "parallel")
_DEFAULT_SETTINGS = _settings(*(DEFAULTS[k] for k in _SETTINGS))


@functools.lru_cache(maxsize=16)
def _chain_data(chain: Chain) -> tuple:
    """The chain's arrays as the compiled kernels take them, its reach bound and base position, and
    its limits (built once per chain object)."""
    from .chain_kernels import chain_arrays
    return chain_arrays(chain), chain.reach(), chain.base[:3, 3].copy(), chain.qmin.copy(), chain.qmax.copy()


@functools.lru_cache(maxsize=64)
def _pool(chain: Chain, seed, rows: int) -> np.ndarray:
    """The random configurations an integer seed gives, drawn as the batch search draws them (shared
    between calls: the kernel never writes to it). ``rng=None`` draws fresh ones on every call."""
    return as_rng(seed).uniform(chain.qmin, chain.qmax, size=(rows, chain.n))


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
    method, tol, max_iter, restarts, damping, gain, clamp, max_step, patience, parallel = _settings(
        method, tol, max_iter, restarts, damping, gain, clamp, max_step, patience, parallel)
    gen = as_rng(rng)
    if q0 is None:
        q = np.tile(0.5 * (chain.qmin + chain.qmax), (N, 1))
    else:
        q = chain.as_q(q0, "q0", batch=True).copy()
        if q.shape[0] == 1 and N > 1:
            q = np.tile(q, (N, 1))
        elif q.shape[0] != N:
            raise ValueError(f"q0: expected one guess or {N} guesses (one per target), got {q.shape[0]}")

    dist = np.linalg.norm(Tt[:, :3, 3] - chain.base[:3, 3], axis=1)
    too_far = dist > chain.reach()
    step = STEP_RULES[method](chain, N * parallel, damping, gain)
    att, trail = _search(chain, Tt, q, too_far, step, tol=tol, max_iter=max_iter, restarts=restarts,
                         patience=patience, parallel=parallel, clamp=bool(clamp), max_step=max_step, gen=gen,
                         history=history)
    out = verify(chain, Tt, att.answers(), tol, validate=False)
    for i in np.flatnonzero(too_far):
        out.reason[i] = (f"out of reach: target {dist[i]:.3f} m from the base, beyond the arm's reach "
                         f"bound {chain.reach():.3f} m")
    for i in np.flatnonzero(~out.success & ~too_far):
        out.reason[i] += f" after {att.restarts[i] + parallel} attempts of up to {max_iter} iterations"
        if out.reason[i].startswith("pose error"):
            out.reason[i] += " (target may be unreachable)"
    out.iterations, out.restarts = att.iterations, att.restarts
    if history:
        out.history = np.array(trail)
    return out
