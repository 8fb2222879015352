"""Assignment 06's loop exercise: follow a short path with damped least squares and a null-space task.

The reference loop (:func:`track_path`), the cases (short arcs from postures far from mid-range, kept
only where the secondary task shows), the comparison that judges a student's run by what it reaches
(every waypoint, the limits, the step size, the joint-range cost) and the known shortcuts.

References
----------
.. [1] A. Liégeois, "Automatic supervisory control of the configuration and behavior of multibody
   mechanisms", *IEEE Transactions on Systems, Man, and Cybernetics* 7(12), 868-871, 1977.
.. [2] C. W. Wampler, "Manipulator inverse kinematic solutions based on vector formulations and
   damped least-squares methods", *IEEE Transactions on Systems, Man, and Cybernetics* 16(1),
   93-101, 1986.
.. [3] B. Siciliano, L. Sciavicco, L. Villani and G. Oriolo, *Robotics: Modelling, Planning and
   Control*, Springer, 2009 (Sec. 3.7).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from robokit.arm import LIMIT_TOL, Chain, chain_from_table, iiwa14
from robokit.arm.jacobian import jacobian_from_frames
from robokit.geometry import as_se3, pose_error, so3_exp
from robokit.validation import as_array
from robocourse.exercises.plain import numeric_array, summarize
from robocourse.exercises.spec import Case

__all__ = ["ARM", "IIWA_DH", "TRACK", "TRACK_MARGIN", "TRACK_SHORTCUTS", "TRACK_WAYPOINTS", "judge_track", "track_cases",
           "track_path"]

#: The arm of the cases (the lesson's iiwa) and its DH rows ``[d, a, alpha]``.
ARM = iiwa14()
IIWA_DH = np.stack([ARM.d, ARM.a, ARM.alpha], 1).tolist()
#: The tracking loop's settings (:func:`track_path`): iterations per waypoint, the pose error [m and
#: rad] each waypoint must be reached to by the end of its iterations, the largest joint move per
#: iteration [rad], the DLS damping and the null-space gain of the joint-range criterion.
TRACK = {"steps": 30, "tol": 1e-3, "max_step": 0.1, "damping": 0.02, "gain": 1.0}


def _flange(chain: Chain, q: np.ndarray) -> np.ndarray:
    """The flange transform(s) of ``q`` ((n,) or (N, n)), unchecked."""
    return chain.flange_transform(chain.frames(q, validate=False), validate=False)


def _joint_range_cost(q: Any, qmin: Any, qmax: Any) -> np.ndarray:
    """Liégeois's joint-range criterion as a cost, ``1/2 sum(((q - mid) / half)^2)`` (per row of ``q``)."""
    q, qmin, qmax = (np.asarray(x, dtype=float) for x in (q, qmin, qmax))
    return 0.5 * np.sum(((q - 0.5 * (qmin + qmax)) / (0.5 * (qmax - qmin))) ** 2, axis=-1)


def _run(dh, qmin, qmax, q_start, targets, steps, max_step, damping, gain) -> np.ndarray:
    """The loop, unchecked: ``steps`` iterations per target of the damped least-squares step plus the
    joint-range gradient projected into the null space, scaled so that no joint moves more than
    ``max_step``."""
    chain = chain_from_table(dh)
    qmin, qmax = (np.asarray(x, dtype=float) for x in (qmin, qmax))
    mid, half = 0.5 * (qmin + qmax), 0.5 * (qmax - qmin)
    q, out, eye = np.array(q_start, dtype=float), [], np.eye(6)
    for T in np.asarray(targets, dtype=float):
        for _ in range(steps):
            F = chain.frames(q, validate=False)
            e = pose_error(T, chain.flange_transform(F, validate=False), validate=False)
            J = jacobian_from_frames(chain, F, validate=False)
            JJt = J @ J.T
            dq = J.T @ np.linalg.solve(JJt + damping ** 2 * eye, e)                       # Wampler (1986)
            if gain:
                g = -(q - mid) / half ** 2                                                # Liégeois (1977), Eq. 14
                dq = dq + gain * (g - J.T @ np.linalg.solve(JJt, J @ g))                  # Liégeois (1977), Eq. 9
            biggest = np.abs(dq).max()
            if biggest > max_step:
                dq = dq * (max_step / biggest)
            q = q + dq
            out.append(q)
    return np.array(out)


def track_path(dh: Any, qmin: Any, qmax: Any, q_start: Any, targets: Any, settings: dict) -> np.ndarray:
    """Follow a path of flange poses with damped least squares and a joint-range secondary task (the
    loop exercise's reference).

    For each target in turn, ``settings["steps"]`` iterations of ``dq = J# e + k (I - J+ J) g`` with the
    damped pseudo-inverse ``J# = J^T (J J^T + lambda^2 I)^-1`` (Wampler 1986), the exact pseudo-inverse
    ``J+`` in the projector and ``g`` the gradient of Liégeois's joint-range criterion
    ``H = -1/2 sum(((q - mid) / half)^2)`` (Liégeois 1977, Eqs. 9 and 14); each step is scaled down so
    that no joint moves more than ``settings["max_step"]``. The lesson's Sec. 7 tracks a circle with the
    same feedback; Siciliano et al. (2009), Sec. 3.7, describe the scheme.

    Parameters
    ----------
    dh : array_like, shape (n, 3)
        Standard-DH rows ``[d, a, alpha]``.
    qmin, qmax : array_like, shape (n,)
        Joint limits [rad].
    q_start : array_like, shape (n,)
        Start posture, inside the limits.
    targets : array_like, shape (K, 4, 4)
        The path's flange poses, in order.
    settings : dict
        ``steps`` (int >= 1), ``max_step`` (rad, > 0), ``damping`` (>= 0) and ``gain`` (>= 0); ``tol``
        is the grader's and is not used here.

    Returns
    -------
    numpy.ndarray, shape (K * steps, n)
        The posture after every iteration.

    Raises
    ------
    ValueError
        For shapes that do not match, a start outside the limits, a target that is not a rigid
        transform, or settings missing or out of range.

    Examples
    --------
    >>> from robokit.arm import dh_fk
    >>> q0 = np.radians([10, 40, 0, -70, 0, 50, 0])
    >>> T = np.array(dh_fk(IIWA_DH, q0 + 0.1))
    >>> run = track_path(IIWA_DH, ARM.qmin, ARM.qmax, q0, [T], TRACK)
    >>> run.shape, bool(np.abs(pose_error(T, dh_fk(IIWA_DH, run[-1]))).max() < 1e-6)
    ((30, 7), True)
    """
    dh = as_array(dh, "dh", shape=(None, 3), min_size=3)
    n = len(dh)
    qmin, qmax, q0 = (as_array(x, name, shape=(n,)) for x, name in ((qmin, "qmin"), (qmax, "qmax"), (q_start, "q_start")))
    if np.any(qmin >= qmax):
        raise ValueError("qmin, qmax: expected qmin < qmax for every joint")
    if np.any((q0 < qmin - LIMIT_TOL) | (q0 > qmax + LIMIT_TOL)):
        raise ValueError("q_start: expected a posture inside the joint limits")
    T = as_array(targets, "targets", shape=(None, 4, 4))
    if not len(T):
        raise ValueError("targets: expected at least one pose")
    for Ti in T:
        as_se3(Ti, "targets")
    if not isinstance(settings, dict) or not {"steps", "max_step", "damping", "gain"} <= set(settings):
        raise ValueError("settings: expected a dict with steps, max_step, damping and gain")
    steps, max_step, damping, gain = (settings[k] for k in ("steps", "max_step", "damping", "gain"))
    if int(steps) != steps or steps < 1 or not max_step > 0 or not damping >= 0 or not gain >= 0:
        raise ValueError(f"settings: expected steps >= 1, max_step > 0, damping >= 0, gain >= 0, got {settings}")
    return _run(dh, qmin, qmax, q0, T, int(steps), float(max_step), float(damping), float(gain))


def _slot_errors(dh, run: np.ndarray, targets: np.ndarray, steps: int) -> np.ndarray:
    """Pose error (the larger of position [m] and rotation [rad]) of every iterate against its target."""
    T = np.repeat(np.asarray(targets, dtype=float), steps, axis=0)
    e = pose_error(T, _flange(chain_from_table(dh), np.asarray(run, dtype=float)), validate=False)
    return np.maximum(np.linalg.norm(e[:, :3], axis=1), np.linalg.norm(e[:, 3:], axis=1))


def _arc_path(rng: np.random.Generator, T0: np.ndarray, k: int) -> np.ndarray:
    """``k`` flange poses along a circular arc from ``T0``'s origin (radius 4-8 cm, a quarter to a half
    turn, in a random plane), the orientation turning by up to 0.2 rad about a random axis: a short
    stretch of the lesson's Sec. 7 circle."""
    r, turn = rng.uniform(0.04, 0.08), rng.uniform(0.5, 1.0) * np.pi
    a, b = np.linalg.qr(rng.normal(size=(3, 2)))[0].T
    w = rng.normal(size=3)
    w *= rng.uniform(0.05, 0.2) / np.linalg.norm(w)
    out = np.repeat(T0[None], k, axis=0)
    for i in range(k):
        t = turn * (i + 1) / k
        out[i, :3, 3] = T0[:3, 3] + r * (np.sin(t) * a + (1 - np.cos(t)) * b)
        out[i, :3, :3] = so3_exp(w * (i + 1) / k) @ T0[:3, :3]
    return out


#: The tracking cases: waypoints per path, and how much lower (in joint-range cost) the reference's
#: final posture must be than plain DLS's for a run to be a case (so the secondary task shows).
TRACK_WAYPOINTS = 4
TRACK_MARGIN = 0.3


def _track_run(rng: np.random.Generator, label: str) -> Case:
    """A start posture with joints far from the middle of their ranges and a short arc from its pose; drawn
    until the reference reaches every waypoint (to a third of the tolerance) inside the limits and ends
    at least :data:`TRACK_MARGIN` lower in joint-range cost than plain DLS."""
    s, qmin, qmax = TRACK, ARM.qmin, ARM.qmax
    for _ in range(2000):
        q0 = rng.uniform(0.85 * qmin, 0.85 * qmax).round(4)
        if _joint_range_cost(q0, qmin, qmax) < 1.2:
            continue
        targets = _arc_path(rng, _flange(chain_from_table(IIWA_DH), q0), TRACK_WAYPOINTS).round(10)
        ref = _run(IIWA_DH, qmin, qmax, q0, targets, s["steps"], s["max_step"], s["damping"], s["gain"])
        err = _slot_errors(IIWA_DH, ref, targets, s["steps"])[s["steps"] - 1::s["steps"]]
        if err.max() > s["tol"] / 3 or np.any((ref < qmin + 0.01) | (ref > qmax - 0.01)):
            continue
        dls = _run(IIWA_DH, qmin, qmax, q0, targets, s["steps"], s["max_step"], s["damping"], 0.0)
        cost = _joint_range_cost([q0, dls[-1], ref[-1]], qmin, qmax)
        if cost[1] - cost[2] < TRACK_MARGIN:
            continue
        args = (IIWA_DH, qmin.tolist(), qmax.tolist(), q0.tolist(), targets.tolist(), dict(s))
        return Case(args, label=label, expected={
            "dh": IIWA_DH, "qmin": qmin.tolist(), "qmax": qmax.tolist(), "q_start": q0.tolist(),
            "targets": targets.tolist(), "settings": dict(s), "cost_start": float(cost[0]),
            "cost_dls": float(cost[1]), "cost_reference": float(cost[2])})
    raise RuntimeError("no tracking case in 2000 draws")  # pragma: no cover


def track_cases(rng: np.random.Generator) -> list[Case]:
    """The loop exercise's cases: two runs (short arcs from postures far from mid-range, kept only
    where the reference beats plain DLS's joint-range cost by :data:`TRACK_MARGIN`) and two bad inputs.

    The expected answer of a run is what :func:`judge_track` needs (the arm, the targets, the settings
    and the reference's and plain DLS's costs), never sent to the grading worker.
    """
    runs = [_track_run(rng, f"a {TRACK_WAYPOINTS}-waypoint arc from a posture far from mid-range ({k})")
            for k in ("run 1", "run 2")]
    dh, qmin, qmax, q0, targets, settings = runs[0].args
    outside = list(q0)
    outside[1] = qmax[1] + 0.1
    return runs + [
        Case((dh, qmin, qmax, outside, targets, settings), raises="ValueError",
             label="a start posture outside the joint limits"),
        Case((dh, qmin, qmax, q0[:6], targets, settings), raises="ValueError", label="6 start angles for 7 joints"),
    ]


def _show_errors(err: np.ndarray, first: int, steps: int) -> str:
    at = [i for i in (1, 2, 5, 10, 20, steps) if i <= steps]
    return ", ".join(f"{i}: {err[first + i - 1]:.2g}" for i in at)


def judge_track(expected: Any, got: Any) -> str | None:
    """Judge a tracking run by its outcome: step sizes, the limits, every waypoint reached by the end of its
    iterations, and the joint-range cost at the end well below plain DLS's; show the run where it fails."""
    s = expected["settings"]
    steps, K = s["steps"], len(expected["targets"])
    qmin, qmax = np.asarray(expected["qmin"], float), np.asarray(expected["qmax"], float)
    run = numeric_array(got)
    if run is None or run.dtype.kind == "b" or run.shape != (K * steps, len(qmin)):
        return (f"expected the posture after every iteration, shape ({K * steps}, {len(qmin)}) "
                f"({steps} iterations for each of the {K} targets), got {summarize(got)}")
    run = run.astype(float)
    if not np.all(np.isfinite(run)):
        i = int(np.flatnonzero(~np.isfinite(run).all(axis=1))[0])
        return f"your run holds NaN or inf from iteration {i + 1} on (the loop diverged)"
    moves = np.abs(np.diff(np.vstack([expected["q_start"], run]), axis=0))
    if moves.max() > s["max_step"] + 1e-9:
        i, j = np.unravel_index(int(np.argmax(moves)), moves.shape)
        return (f"iteration {i + 1} moves joint {j + 1} by {moves[i, j]:.3g} rad, more than max_step = "
                f"{s['max_step']:g} rad: scale the step down")
    over = np.maximum(qmin - run, run - qmax)
    if over.max() > LIMIT_TOL:
        i, j = np.unravel_index(int(np.argmax(over > LIMIT_TOL)), over.shape)
        return (f"iteration {i + 1} puts joint {j + 1} at {np.degrees(run[i, j]):.2f} deg, beyond its limits "
                f"[{np.degrees(qmin[j]):.0f}, {np.degrees(qmax[j]):.0f}] deg")
    err = _slot_errors(expected["dh"], run, expected["targets"], steps)
    for k in range(K):
        if err[(k + 1) * steps - 1] > s["tol"]:
            trend = "it diverged" if err[(k + 1) * steps - 1] > err[k * steps] else "it did not get close enough"
            return (f"target {k + 1} of {K} not reached: pose error {err[(k + 1) * steps - 1]:.3g} after its {steps} "
                    f"iterations (tolerance {s['tol']:g} m and rad; {trend}). The error at its iterations "
                    f"{_show_errors(err, k * steps, steps)}")
    cost = float(_joint_range_cost(run[-1], qmin, qmax))
    dls, ref = expected["cost_dls"], expected["cost_reference"]
    bound = dls - 0.5 * (dls - ref)
    if cost > bound:
        return (f"every target reached, but the secondary task did little: the joint-range cost "
                f"1/2 sum(((q - mid) / half)^2) is {expected['cost_start']:.3f} at the start and {cost:.3f} at your "
                f"end; plain DLS ends at {dls:.3f}, DLS with the projected gradient at {ref:.3f}; at most {bound:.3f} "
                f"passes")
    return None


def _start_repeated(dh, qmin, qmax, q_start, targets, settings):
    """Shortcut: never move."""
    return [q_start] * (len(targets) * settings["steps"])


def _dls_only(dh, qmin, qmax, q_start, targets, settings):
    """Shortcut: the loop without its secondary task (plain DLS)."""
    return track_path(dh, qmin, qmax, q_start, targets, {**settings, "gain": 0.0})


def _dls_clamped(dh, qmin, qmax, q_start, targets, settings):
    """Shortcut: plain DLS, every posture clipped into the limits."""
    return np.clip(_dls_only(dh, qmin, qmax, q_start, targets, settings), qmin, qmax)


def _last_target_only(dh, qmin, qmax, q_start, targets, settings):
    """Shortcut: the loop aimed at the last waypoint throughout."""
    return track_path(dh, qmin, qmax, q_start, [targets[-1]] * len(targets), settings)


#: Ways to produce a run without the loop the exercise asks for.
TRACK_SHORTCUTS = {"the start posture, repeated": _start_repeated, "plain DLS (no secondary task)": _dls_only,
                   "plain DLS clipped into the limits": _dls_clamped,
                   "the loop aimed at the last waypoint only": _last_target_only}
