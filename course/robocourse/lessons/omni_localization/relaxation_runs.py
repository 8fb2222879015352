"""The relaxation loop of assignment 02: office-tour pose graphs, the reference loop and its outcome check.

Lesson 02 aligns its topological map after loop closure by repeating the paper's relaxation sweep
(Sec. "Loop closure alignment", Eqs. (1)-(3), after Duckett et al. 2000) until the map stops
moving. Exercise ``02.relax_map`` asks the student to assemble that loop: start the node
variances, sweep, measure each sweep's change, stop at a tolerance or a cap of sweeps. This
module makes its cases from the lesson's own tour and judges the outcome:

* :func:`tour_graph` places map nodes along the office tour (:data:`robokit.sim.motion.OFFICE_TOUR`,
  the drive :func:`robokit.sim.office_tour` samples), drifts the odometry between them and closes
  the loops where the tour comes back to a place, as the lesson's map builder does;
* :func:`relax_map` is the reference loop (robokit's :func:`~robokit.mapping.relax`, started from
  the paper's chain of variances);
* :func:`map_outcome` accepts a run whose map lies within :data:`POSITION_TOLERANCE` of the
  reference's (up to the gauge: a rotation and a shift of the whole map), whose flag says whether it
  converged, and whose sweep count is within :data:`SWEEP_RANGE` of the reference's; its message
  shows the run (the change at a few sweeps, beside the reference's) and where it left the
  reference.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] T. Duckett, S. Marsland and J. Shapiro, "Learning globally consistent maps by relaxation",
   Proc. IEEE Int. Conf. on Robotics and Automation (ICRA), 3841-3846, 2000.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from robokit.geometry import se2_between, se2_compose, wrap_angle
from robokit.geometry.planar import as_planar
from robokit.mapping import PoseGraph, relax
from robokit.sim.motion import OFFICE_TOUR, waypoint_path
from robokit.validation import as_array, as_int, as_positive, as_rng
from robocourse.exercises.plain import summarize

__all__ = ["POSITION_TOLERANCE", "HEADING_TOLERANCE", "SWEEP_RANGE", "TOLERANCE", "tour_graph", "chain_variances",
           "relax_map", "map_outcome"]

#: How far (m) a node of the student's map may lie from the reference's once the two maps are
#: aligned by one rotation and shift: stopping at the tolerance leaves a map 1-2 cm from where the
#: sweeps converge, and stopping a third of the way leaves one 0.3-1 m off (measured on the cases).
POSITION_TOLERANCE = 0.05
#: The same for the headings (rad).
HEADING_TOLERANCE = 0.02
#: The student's sweep count over the reference's must lie in this range: starting the variances
#: another reasonable way (the cheapest path instead of the chain) changes it by under 10 %.
SWEEP_RANGE = (0.8, 1.25)
#: The stopping tolerance of the cases: the total change of a sweep, metres plus radians.
TOLERANCE = 1e-3


def tour_graph(rng: Any, spacing: float = 2.5, loops: str = "all") -> dict:
    """A pose graph of the office tour with drifted odometry, as plain data for ``relax_map``.

    Parameters
    ----------
    rng : numpy.random.Generator or int
    spacing : float, default 2.5
        Metres driven between map nodes (the tour's on-the-spot turns add none).
    loops : {"all", "last"}, default "all"
        Close every return to a place (a node within 1 m of an earlier one at least 8 nodes before,
        joined to the nearest such), or only the last one; the tour's last node always closes the
        whole-floor loop.

    Returns
    -------
    dict
        ``poses`` (dead reckoning, (N, 3)), ``edges`` (the chain ``(k, k + 1)`` first, then the
        loops), ``measurements`` (pose of the second node in the first's frame) and
        ``edge_variances`` (scalar, m^2), all lists; ``truth`` the true node poses (N, 3).

    Notes
    -----
    The odometry of an edge of length ``d`` errs by ``0.02 + 0.03 d`` m sideways and along, and
    ``0.01 + 0.02 d`` rad in heading (one standard deviation); a loop edge (the localizer's relative
    pose) by 3 cm and 0.01 rad. The scalar variance of an edge is the mean of its two position
    variances (:func:`robokit.mapping.pose_graph.edge_variances`).

    Examples
    --------
    >>> g = tour_graph(0)
    >>> len(g["poses"]), len(g["edges"]) - len(g["poses"]) + 1     # nodes, loop edges
    (40, 6)
    """
    rng = as_rng(rng)
    spacing = as_positive(spacing, "spacing")
    P = waypoint_path(OFFICE_TOUR, 0.3, rate=10.0).poses
    step = np.r_[0.0, np.hypot(*np.diff(P[:, :2], axis=0).T)]
    start = rng.uniform(0, spacing)        # where along the tour the first node falls after the start
    travelled = np.cumsum(step) + start
    keep = np.r_[0, np.flatnonzero(np.diff(np.floor(travelled / spacing)) > 0) + 1]
    truth = P[keep]
    n = len(truth)
    rel = se2_between(truth[:-1], truth[1:])
    d = np.hypot(rel[:, 0], rel[:, 1])
    sigma = np.column_stack([0.02 + 0.03 * d, 0.02 + 0.03 * d, 0.01 + 0.02 * d])
    odometry = se2_compose(rel, rng.normal(0, 1, (n - 1, 3)) * sigma)
    poses = [truth[0]]
    for z in odometry:
        poses.append(se2_compose(poses[-1], z))
    dist = np.hypot(*(truth[:, None, :2] - truth[None, :, :2]).transpose(2, 0, 1))
    dist[np.tril_indices(n, 7)] = np.inf             # a loop joins nodes at least 8 apart, earlier to later
    dist[:, -1] = np.minimum(dist[:, -1], np.where(dist[:, -1] == dist[:, -1].min(), 0.0, np.inf))  # tour's end
    later = np.flatnonzero(dist.min(axis=0) < 1.0)   # one loop per return: to the nearest earlier node
    pairs = np.column_stack([dist[:, later].argmin(axis=0), later]).reshape(-1, 2)
    pairs = pairs[-1:] if loops == "last" else pairs
    loop_z = se2_compose(se2_between(truth[pairs[:, 0]], truth[pairs[:, 1]]),
                         rng.normal(0, [0.03, 0.03, 0.01], (len(pairs), 3)))
    variances = np.r_[sigma[:, 0] ** 2, np.full(len(pairs), 0.03 ** 2)]
    r = lambda a: np.round(np.asarray(a, float), 6).tolist()   # noqa: E731
    return {"poses": r(poses), "edges": np.r_[np.column_stack([np.arange(n - 1), np.arange(1, n)]), pairs].tolist(),
            "measurements": r(np.r_[odometry, loop_z]), "edge_variances": r(variances), "truth": r(truth)}


def chain_variances(edge_variances: Any, n: int) -> np.ndarray:
    """Starting node variances: 0 at node 0, then each node the previous one's plus its chain edge's.

    The paper's rule (Sec. "Loop closure alignment", unnumbered): a new node starts with the
    variance of the previous node; adding the edge's (Eq. (1)'s ``omega_j + omega_ij``) gives the
    variance of dead reckoning along the chain ``(k, k + 1)``, the first ``n - 1`` edges.

    Examples
    --------
    >>> chain_variances([0.01, 0.02, 0.5], 3).tolist()
    [0.0, 0.01, 0.03]
    """
    w = as_array(edge_variances, "edge_variances", ndim=1)
    return np.r_[0.0, np.cumsum(w[: as_int(n, "n", minimum=1) - 1])]


def _graph(poses: Any, edges: Any, measurements: Any, edge_variances: Any) -> PoseGraph:
    p = as_planar(poses, "poses", shape=(None, 3))
    n = len(p)
    if n < 2:
        raise ValueError(f"poses: expected at least two nodes, got {n}")
    e = as_array(edges, "edges", shape=(None, 2), dtype=np.int64)
    if len(e) < n - 1 or np.any(e[: n - 1] != np.column_stack([np.arange(n - 1), np.arange(1, n)])):
        raise ValueError(f"edges: expected the odometry chain (0, 1), ..., ({n - 2}, {n - 1}) as the first {n - 1} "
                         "edges")
    if ((e < 0) | (e >= n)).any() or (e[:, 0] == e[:, 1]).any():
        raise ValueError(f"edges: expected pairs of two different node indices in 0..{n - 1}")
    z = as_planar(measurements, "measurements", shape=(len(e), 3))
    w = as_array(edge_variances, "edge_variances", shape=(len(e),))
    if np.any(w <= 0):
        raise ValueError(f"edge_variances: expected positive variances, got {float(w[w <= 0][0])}")
    return PoseGraph(p, e, z, information=np.eye(3)[None] / w[:, None, None])


def relax_map(poses: Any, edges: Any, measurements: Any, edge_variances: Any, tolerance: float = TOLERANCE,
              max_sweeps: int = 5000) -> dict:
    """Align a map by relaxation: sweeps of Eqs. (1)-(3) until a sweep's change is under ``tolerance``.

    The reference answer of the loop exercise (``02.relax_map``).

    Parameters
    ----------
    poses : array_like, shape (N, 3), N >= 2
        Starting estimates ``[x, y, theta]`` (dead reckoning); node 0 is fixed.
    edges : array_like of int, shape (M, 2)
        The chain ``(k, k + 1)`` for ``k < N - 1`` first, then any loop edges.
    measurements : array_like, shape (M, 3)
        Pose of each edge's second node in its first node's frame.
    edge_variances : array_like, shape (M,)
        Scalar edge variances (> 0).
    tolerance : float, default TOLERANCE
        Stop after the first sweep whose total change ``sum_i |(dx_i, dy_i)| + |wrap(dtheta_i)|`` is
        below it (> 0).
    max_sweeps : int, default 5000
        Most sweeps (>= 1).

    Returns
    -------
    dict
        ``poses`` (N, 3), ``sweeps`` (int), ``converged`` (bool) and ``changes`` (each sweep's total
        change), as plain data.

    Raises
    ------
    ValueError
        For shapes that disagree, a first ``N - 1`` edges that are not the chain, an edge to a
        missing node, a non-positive variance or tolerance, or ``max_sweeps < 1``.

    Notes
    -----
    Jacobi sweeps (:func:`robokit.mapping.relax`) started from :func:`chain_variances`.

    Examples
    --------
    A square whose odometry over-turns each corner, closed by recognising the start:

    >>> odo = [[0, 0, 0], [1, 0, 1.67], [0.9, 1, 3.24], [-0.1, 0.93, 4.81]]
    >>> z = [[1, 0, 1.67], [1, 0, 1.57], [1, 0, 1.57], [1, 0, 1.57]]
    >>> out = relax_map(odo, [[0, 1], [1, 2], [2, 3], [3, 0]], z, [0.01] * 4)
    >>> out["converged"], out["sweeps"]
    (True, 8)
    """
    graph = _graph(poses, edges, measurements, edge_variances)
    tol = as_positive(tolerance, "tolerance")
    cap = as_int(max_sweeps, "max_sweeps", minimum=1)
    result = relax(graph, max_iterations=cap, tolerance=tol,
                   variances=chain_variances(edge_variances, graph.n_poses))
    return {"poses": result.poses.tolist(), "sweeps": int(result.iterations), "converged": bool(result.converged),
            "changes": result.changes.tolist()}


def _aligned(expected: np.ndarray, got: np.ndarray) -> tuple[np.ndarray, float]:
    """``got`` turned and shifted onto ``expected`` (least squares on the positions), and the turn."""
    a, b = got[:, :2] - got[:, :2].mean(0), expected[:, :2] - expected[:, :2].mean(0)
    turn = float(np.arctan2(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]), np.sum(a * b)))
    c, s = np.cos(turn), np.sin(turn)
    out = got.copy()
    out[:, :2] = a @ np.array([[c, s], [-s, c]]) + expected[:, :2].mean(0)
    out[:, 2] = got[:, 2] + turn
    return out, turn


def _run_story(expected: dict, changes: list) -> str:
    """The change at a few sweeps, the student's beside the reference's, and where they part."""
    ref = np.asarray(expected["changes"], float)
    mine = np.asarray(changes, float) if changes else np.zeros(0)
    marks = sorted({k for k in (1, 10, 100, 1000, len(ref)) if k <= max(len(ref), len(mine))})
    show = lambda v, k: f"{v[k - 1]:.3g}" if k <= len(v) else "-"   # noqa: E731
    story = ", ".join(f"sweep {k}: {show(mine, k)} (reference {show(ref, k)})" for k in marks)
    m = min(len(ref), len(mine))
    apart = np.flatnonzero(np.abs(mine[:m] - ref[:m]) > 0.05 * ref[:m] + 1e-9)
    hint = " (the first sweep already differs: check the starting variances and the sweep itself)" \
        if len(apart) and apart[0] == 0 else ""
    where = (f"; your changes leave the reference's at sweep {int(apart[0]) + 1}{hint}" if len(apart)
             else "; your changes follow the reference's" if m else "")
    return f"change per sweep, yours and the reference's: {story}{where}"


def _fields(got: Any, n: int) -> tuple | str:
    if not isinstance(got, dict) or not {"poses", "sweeps", "converged", "changes"} <= set(got):
        return f"expected a dict with keys 'poses', 'sweeps', 'converged' and 'changes', got {summarize(got)}"
    try:
        poses = np.asarray(got["poses"], float)
        changes = [float(c) for c in np.asarray(got["changes"], float).ravel()]
    except (TypeError, ValueError, OverflowError):
        return f"'poses' and 'changes': expected numbers, got {summarize(got['poses'])}, {summarize(got['changes'])}"
    if poses.shape != (n, 3) or not np.isfinite(poses).all():
        return f"'poses': expected a finite ({n}, 3) array, got shape {poses.shape}"
    sweeps = got["sweeps"]
    if type(sweeps) not in (int, float) or (type(sweeps) is float and not np.isfinite(sweeps)) or sweeps != int(sweeps):
        return f"'sweeps': expected a whole number, got {summarize(got['sweeps'])}"
    if type(got["converged"]) is not bool:
        return f"'converged': expected True or False, got {summarize(got['converged'])}"
    return poses, int(got["sweeps"]), got["converged"], changes


def map_outcome(expected: Any, got: Any) -> str | None:
    """Accept a relaxation run whose map, flag and sweep count agree with the reference run's.

    The map must lie within :data:`POSITION_TOLERANCE` (positions) and :data:`HEADING_TOLERANCE`
    (headings) of the reference's after one rotation and shift of the whole map (the gauge), the
    ``converged`` flag must be the reference's, the sweep count within :data:`SWEEP_RANGE` of the
    reference's (the cap itself when the reference hit it), and ``changes`` must hold one value per
    sweep. The message shows the run beside the reference's.

    Examples
    --------
    >>> ref = {"poses": [[0, 0, 0], [1, 0, 0]], "sweeps": 10, "converged": True, "changes": [0.1] * 10}
    >>> map_outcome(ref, dict(ref, poses=[[5, 5, 1], [5 + np.cos(1), 5 + np.sin(1), 1]])) is None   # turned, shifted
    True
    >>> map_outcome(ref, dict(ref, sweeps=2, changes=[0.1, 0.1]))[:46]
    "you stopped after 2 sweeps, the reference's 10"
    """
    n = len(expected["poses"])
    fields = _fields(got, n)
    if isinstance(fields, str):
        return fields
    poses, sweeps, converged, changes = fields
    ref = np.asarray(expected["poses"], float)
    story = _run_story(expected, changes)
    if len(changes) != sweeps:
        return f"'changes' holds {len(changes)} values for {sweeps} sweeps: one per sweep, please"
    aligned, _ = _aligned(ref, poses)
    off = np.hypot(*(aligned[:, :2] - ref[:, :2]).T)
    turn_off = np.abs(wrap_angle(aligned[:, 2] - ref[:, 2]))
    if off.max() > POSITION_TOLERANCE or turn_off.max() > HEADING_TOLERANCE:
        k = int(np.argmax(off)) if off.max() > POSITION_TOLERANCE else int(np.argmax(turn_off))
        return (f"your map is not the relaxed one: node {k} lies {off[k]:.3f} m and {turn_off[k]:.3f} rad from the "
                f"reference's (allowed {POSITION_TOLERANCE} m, {HEADING_TOLERANCE} rad, after turning and shifting "
                f"your whole map onto it); {story}")
    if converged != expected["converged"]:
        return f"'converged' is {converged}, the reference's {expected['converged']}; {story}"
    low, high = SWEEP_RANGE
    ok = sweeps == expected["sweeps"] if not expected["converged"] else \
        low * expected["sweeps"] <= sweeps <= high * expected["sweeps"]
    if not ok:
        return f"you stopped after {sweeps} sweeps, the reference's {expected['sweeps']}; {story}"
    return None
