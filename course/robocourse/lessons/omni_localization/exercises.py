"""Exercises of assignment 02 (omnidirectional hierarchical localization and visual path following).

The relaxation loop's cases and outcome check live in :mod:`.relaxation_runs`; the EKF's fix model
(a pose measured in the recognised node's frame) and the fine stage's count are here.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

import numpy as np

from robokit.controllers.path_following import path_following_command
from robokit.localization.hierarchical import TOP_K
from robokit.geometry import se2_between, wrap_angle
from robokit.geometry.planar import as_planar
from robokit.localization.pose_ekf import ekf_update
from robokit.mapping.topological import OMNI_RATIO
from robokit.vision.colour import histogram_distance, hue_histogram, rgb_to_hsi
from robokit.vision.matching import DescriptorIndex
from robokit.vision.matching import as_ratio
from robokit.validation import as_array, as_covariance, as_int, require_angles
from robocourse.exercises.compare import close, exact
from robocourse.exercises.plain import summarize
from robocourse.exercises.spec import Case, Exercise
from robocourse.lessons.omni_localization.relaxation_runs import TOLERANCE, map_outcome, relax_map, tour_graph

ASSIGNMENT = "02_omni_localization"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"02.coarse_versus_fine": 2, "02.relaxation_versus_least_squares": 2, "02.hierarchy_design": 2}

#: The fine stage's distance-ratio bound, with ``TOP_K`` (the coarse stage's candidates) the lesson's
#: own: the map builder's and ``HierarchicalLocalizer``'s defaults, so lesson, solution and assignment
#: use one pair of values. The notebook reads both from the assignment's data (:func:`data`).
RATIO = OMNI_RATIO


def data() -> dict:
    """What the notebook works with: the lesson's ratio and top k (the grading worker has no robokit).

    Examples
    --------
    >>> data()
    {'ratio': 0.7, 'top_k': 5}
    """
    return {"ratio": RATIO, "top_k": TOP_K}


def _node_list(node_descriptors, dim: int | None) -> list[np.ndarray]:
    if isinstance(node_descriptors, np.ndarray) and node_descriptors.ndim == 3:
        node_descriptors = list(node_descriptors)
    if not isinstance(node_descriptors, (list, tuple)):
        raise TypeError(f"node_descriptors: expected a list of (M_k, D) descriptor arrays, got "
                        f"{type(node_descriptors).__name__}")
    nodes = []
    for k, d in enumerate(node_descriptors):
        arr = as_array(d, f"node_descriptors[{k}]", ndim=2)
        if dim is not None and arr.shape[1] != dim:
            raise ValueError(f"node_descriptors[{k}]: expected descriptors of length {dim} like the query's, "
                             f"got {arr.shape[1]}")
        if len(arr) < 2:
            raise ValueError(f"node_descriptors[{k}]: expected at least 2 descriptors (the ratio test needs a "
                             f"second neighbour), got {len(arr)}")
        nodes.append(arr)
    return nodes


def fine_stage_counts(query, node_descriptors, candidates, ratio: float = RATIO) -> np.ndarray:
    """Ratio-test match counts of ``query`` against each candidate node (the fine stage).

    Plain-data wrapper of :meth:`robokit.vision.DescriptorIndex.count_matches` (the paper's Sec.
    "Hierarchical localization": "the correct position is the one getting the largest number of
    matches"; nearest neighbours by KD-tree, Sec. "Local image features").

    Parameters
    ----------
    query : array_like, shape (N, D)
    node_descriptors : list of array_like, each (M_k, D) with M_k >= 2
    candidates : array_like of int, shape (K,)
        Indices into ``node_descriptors``.
    ratio : float, default RATIO
        In (0, 1].

    Returns
    -------
    numpy.ndarray of int, shape (K,)

    Raises
    ------
    ValueError, TypeError
        For a candidate index out of range, descriptors of different lengths, a node with fewer than
        two descriptors, NaN/inf, or a ratio outside (0, 1].

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> nodes = [rng.normal(size=(20, 8)) for _ in range(3)]
    >>> fine_stage_counts(nodes[1][:6] + 0.01, nodes, [0, 1, 2]).tolist()   # node 1, and chance matches
    [0, 6, 2]
    """
    q = as_array(query, "query", ndim=2)
    nodes = _node_list(node_descriptors, q.shape[1])
    cand = as_array(candidates, "candidates", ndim=1)
    if cand.size and (np.any(cand != np.round(cand)) or cand.min() < 0 or cand.max() >= len(nodes)):
        raise ValueError(f"candidates: expected node indices in [0, {len(nodes)}), got {cand.tolist()}")
    return _counts(q, nodes, cand, as_ratio(ratio), "query")


def _counts(q: np.ndarray, nodes: list, cand: np.ndarray, ratio: float, qname: str) -> np.ndarray:
    biggest = max([np.abs(q).max(initial=0.0)] + [np.abs(n).max() for n in nodes])
    if biggest > 1e150:   # squared distances would overflow
        raise ValueError(f"{qname}, node_descriptors: expected descriptor values below 1e150, got {biggest:.3g}")
    return np.array([DescriptorIndex(nodes[int(c)]).count_matches(q, ratio=ratio) if len(q) else 0 for c in cand],
                    int)


def recognise_node(query_histogram, query_descriptors, node_histograms, node_descriptors, top_k: int = TOP_K,
                   ratio: float = RATIO) -> int:
    """The node a query was taken at: coarse ranking by Eq. (5), then the most matches among the top k.

    The expected answer of the open exercise (any method that finds the right node passes).

    Parameters
    ----------
    query_histogram : array_like, shape (m,)
    query_descriptors : array_like, shape (N, D)
    node_histograms : array_like, shape (n, m), n >= 1
    node_descriptors : list of n array_like, each (M_k, D)
    top_k : int, default TOP_K
        Candidates the coarse stage keeps.
    ratio : float, default RATIO

    Returns
    -------
    int

    Raises
    ------
    ValueError, TypeError
        For an empty map, histograms of different lengths or negative bins, one descriptor array per
        node missing, ``top_k < 1`` or bad descriptors.

    Notes
    -----
    The paper's Sec. "Hierarchical localization" (Fig. 5) with Eq. (5) for the coarse stage.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> nodes = [rng.normal(size=(20, 8)) for _ in range(3)]
    >>> hists = np.eye(3)
    >>> recognise_node([0.1, 0.9, 0.0], nodes[1][:6] + 0.01, hists, nodes)
    1
    """
    h = as_array(query_histogram, "query_histogram", ndim=1, min_size=1)
    q = as_array(query_descriptors, "query_descriptors", ndim=2)
    H = as_array(node_histograms, "node_histograms", ndim=2)
    if len(H) == 0:
        raise ValueError("node_histograms: expected a map with at least one node, got none")
    if H.shape[1] != h.size:
        raise ValueError(f"node_histograms: expected {h.size} bins like query_histogram, got {H.shape[1]}")
    if h.min() < 0 or H.min() < 0:
        raise ValueError("query_histogram, node_histograms: expected non-negative bins")
    nodes = _node_list(node_descriptors, q.shape[1])
    if len(nodes) != len(H):
        raise ValueError(f"node_descriptors: expected one array per node ({len(H)}), got {len(nodes)}")
    k = as_int(top_k, "top_k", minimum=1)
    coarse = np.argsort(histogram_distance(h, H), kind="stable")[:k]
    counts = _counts(q, nodes, coarse, as_ratio(ratio), "query_descriptors")
    return int(coarse[int(np.argmax(counts))])


#: The names of the entries of the fix's Jacobian: the fix is ``[a, b, phi]``, the robot's position along
#: the node's heading, to its left and its heading relative to the node's; the state ``[x, y, theta, v, omega]``.
JACOBIAN_TERMS = [[f"d{z}/d{s}" for s in ("x", "y", "theta", "v", "omega")] for z in ("a", "b", "phi")]


def node_fix_jacobian(node_pose) -> np.ndarray:
    """The Jacobian ``H = dh/dx`` of the node-relative fix ``h(x) = se2_between(node_pose, x[:3])``.

    Parameters
    ----------
    node_pose : array_like, shape (3,)
        The recognised node's pose ``[x_n, y_n, theta_n]`` in the map.

    Returns
    -------
    numpy.ndarray, shape (3, 5)
        ``[[c, s, 0, 0, 0], [-s, c, 0, 0, 0], [0, 0, 1, 0, 0]]`` with ``c, s = cos, sin theta_n``: the
        position rotated into the node's frame, the heading less the node's; the velocities unseen.

    Examples
    --------
    >>> node_fix_jacobian([2.0, 1.0, np.pi / 2]).round(6).tolist()[:2]
    [[0.0, 1.0, 0.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0, 0.0]]
    """
    n = as_planar(node_pose, "node_pose", shape=(3,))
    c, s = np.cos(n[2]), np.sin(n[2])
    return np.array([[c, s, 0, 0, 0], [-s, c, 0, 0, 0], [0, 0, 1, 0, 0]], float)


def node_fix_update(x, P, node_pose, z, R) -> dict:
    """EKF update of ``[x, y, theta, v, omega]`` with a fix measured relative to the recognised node.

    The derivation exercise's reference: the hierarchical localizer recognises a node and measures the
    robot's pose in that node's frame, ``z = h(x) + noise`` with ``h(x) = se2_between(node_pose, x[:3])``
    (Sec. "Visual-servoing for navigation": the EKF's outputs are poses; the fix comes from the
    localizer of Sec. "Hierarchical localization"). The update linearises ``h`` at ``x``
    (:func:`node_fix_jacobian`) and uses the innovation ``z - h(x)``, its heading wrapped.

    Parameters
    ----------
    x : array_like, shape (5,)
    P : array_like, shape (5, 5)
        Positive definite.
    node_pose : array_like, shape (3,)
    z : array_like, shape (3,)
        ``[a, b, phi]``: the robot ahead of the node, to its left, and its heading relative to the node's.
    R : array_like, shape (3, 3)
        Positive definite.

    Returns
    -------
    dict
        ``H`` (3, 5), ``x`` (5,), ``P`` (5, 5) as lists, and ``mistakes``: what two common slips give
        (the linear innovation ``z - H x``; the heading innovation not wrapped), for the feedback.

    Raises
    ------
    ValueError
        For wrong shapes, NaN or infinity, or covariances that are not symmetric positive definite.

    Notes
    -----
    Thrun et al. (2005), Table 3.3 (the EKF), with :func:`robokit.localization.pose_ekf.ekf_update`
    given the linearised measurement ``z - h(x) + H x``.

    Examples
    --------
    >>> out = node_fix_update([1, 1, 0, 0.3, 0], np.eye(5), [0, 0, 0], [1.2, 1, 0], np.eye(3))
    >>> np.round(out["x"], 3).tolist()        # halfway to the fix, the velocities untouched
    [1.1, 1.0, 0.0, 0.3, 0.0]
    """
    state = as_array(x, "x", shape=(5,))
    require_angles(state[2], "x", "heading (element 2)")
    cov = as_covariance(P, "P", 5)
    node = as_planar(node_pose, "node_pose", shape=(3,))
    fix = as_planar(z, "z", shape=(3,))
    noise = as_covariance(R, "R", 3)
    H = node_fix_jacobian(node)
    predicted = se2_between(node, state[:3])                 # h(x)
    unwrapped = fix - np.r_[predicted[:2], state[2] - node[2]]
    wrapped, linear = unwrapped.copy(), fix - H @ state
    wrapped[2], linear[2] = wrap_angle(wrapped[2]), wrap_angle(linear[2])
    out = {}
    for name, innovation in (("right", wrapped), ("linear", linear), ("unwrapped", unwrapped)):
        new_x, new_P = ekf_update(state, cov, innovation + H @ state, H, noise)
        out[name] = (new_x.tolist(), new_P.tolist())
    return {"H": H.tolist(), "x": out["right"][0], "P": out["right"][1],
            "mistakes": {"the innovation z - H x: the predicted fix is h(x), the robot's pose in the node's frame":
                         out["linear"][0],
                         "the heading innovation not wrapped to [-pi, pi)": out["unwrapped"][0]}}


def _fix_update_checked(expected, got):
    """Judge ``H`` term by term (naming the wrong partial derivatives), then ``x`` and ``P``."""
    if not isinstance(got, dict) or not {"H", "x", "P"} <= set(got):
        return f"expected a dict with keys 'H', 'x' and 'P', got {summarize(got)}"
    try:
        H, new_x, new_P = (np.asarray(got[k], float) for k in ("H", "x", "P"))
    except (TypeError, ValueError):
        return "'H', 'x', 'P': expected arrays of numbers"
    E = np.asarray(expected["H"])
    if H.shape != E.shape:
        return f"'H': expected shape {E.shape} (3 fix components by 5 state components), got shape {H.shape}"
    wrong = np.argwhere(~np.isclose(H, E, rtol=1e-6, atol=1e-9))
    if len(wrong):
        terms = "; ".join(f"H[{r}, {c}] = {JACOBIAN_TERMS[r][c]}: expected {E[r, c]:.4g}, got {H[r, c]:.4g}"
                          for r, c in wrong[:3])
        return f"'H': {len(wrong)} of 15 partial derivatives are wrong: {terms}"
    ex = np.asarray(expected["x"])
    miss = new_x - ex if new_x.shape == ex.shape else None
    if miss is not None:
        miss[2] = wrap_angle(miss[2])                       # a heading 2 pi off is the same heading
    if miss is None or not np.allclose(ex + miss, ex, rtol=1e-7, atol=1e-9):      # close()'s tolerance, below
        for slip, value in expected["mistakes"].items():
            if miss is not None and np.allclose(new_x, value, rtol=1e-6, atol=1e-8):
                return f"'x': H is right, but your update uses {slip}"
        return "'x': H is right, but the updated state is not: " + str(close(1e-7, 1e-9)(expected["x"], got["x"]))
    message = close(1e-7, 1e-9)(expected["P"], new_P.tolist())
    return message and f"'P': H and x are right, the covariance is not: {message}"


# --- cases ------------------------------------------------------------------------------------

def _rgb_cases(rng: np.random.Generator) -> list[Case]:
    primaries = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [0, 1, 1], [1, 0, 1]]
    greys = [[0.5, 0.5, 0.5], [0, 0, 0], [1, 1, 1]]
    pixels = rng.uniform(0.05, 0.95, (6, 3)).round(4)
    return [
        Case((primaries,), label="primaries and secondaries"),
        Case((greys,), label="greys: hue undefined, reported as 0"),
        Case((pixels.tolist(),), label="random colours (both sides of B = G)"),
        Case((pixels[:1].tolist(),), label="one pixel"),
        Case(([[0.2, 0.4]],), raises="ValueError", label="two channels"),
        Case(([[0.2, 1.4, 0.1]],), raises="ValueError", label="a value above 1"),
        Case(([[0.2, float("nan"), 0.1]],), raises="ValueError", label="NaN"),
    ]


def _safe_image(rng: np.random.Generator, shape: tuple, bins: int, low: float = 0.0, high: float = 1.0,
                min_saturation: float = 0.15) -> np.ndarray:
    """A float image none of whose pixels sits within rounding of a bin edge or a mask threshold."""
    draw = lambda k: rng.uniform(low, high, (k, 3)).round(3)  # noqa: E731
    img = draw(int(np.prod(shape[:2]))).reshape(shape)
    for _ in range(100):
        hsi = rgb_to_hsi(img).astype(float)
        edge = hsi[..., 0] * bins / (2 * np.pi)
        near = (np.abs(edge - np.round(edge)) < 1e-3) | (np.abs(hsi[..., 1] - min_saturation) < 1e-3) | \
            (np.abs(hsi[..., 2] - 0.04) < 1e-3) | (np.abs(hsi[..., 2] - 0.98) < 1e-3)
        if not near.any():
            return img
        img[near] = draw(int(near.sum()))
    raise RuntimeError("could not draw a safe image")  # pragma: no cover


def _histogram_cases(rng: np.random.Generator) -> list[Case]:
    img = _safe_image(rng, (6, 8, 3), 8)
    img32 = _safe_image(rng, (6, 8, 3), 32)
    pale = _safe_image(rng, (4, 5, 3), 16, low=0.35, high=0.65, min_saturation=0.1)
    grey = np.full((3, 4, 3), 0.5)
    # saturated enough for a loose mask, but too dark (I < 0.04) or too bright (I > 0.98) to count
    extremes = _safe_image(rng, (3, 4, 3), 8, min_saturation=0.02)
    extremes[0, :2] = [[0.09, 0.0, 0.01], [0.0, 0.08, 0.02]]
    extremes[1, :2] = [[1.0, 0.97, 0.99], [0.99, 1.0, 0.97]]
    return [
        Case((extremes.tolist(),), {"bins": 8, "min_saturation": 0.02},
             label="dark and bright pixels: outside [min_intensity, max_intensity]"),
        Case((img.tolist(),), {"bins": 8}, label="8 bins of 45 degrees"),
        Case((img32.tolist(),), {"bins": 32}, label="32 bins"),
        Case((pale.tolist(),), {"bins": 16, "min_saturation": 0.1}, label="pale colours, a looser mask"),
        Case((grey.tolist(),), {"bins": 4}, label="a grey image: all zeros"),
        Case((img.tolist(),), {"bins": 0}, raises="ValueError", label="zero bins"),
        Case((img[:, :, :2].tolist(),), {"bins": 8}, raises="ValueError", label="two channels"),
    ]


def _distance_cases(rng: np.random.Generator) -> list[Case]:
    h = rng.dirichlet(np.ones(16))
    H = rng.dirichlet(np.ones(16), 5)
    return [
        Case((h.tolist(), H.tolist()), label="one query against five nodes"),
        Case((h.tolist(), h.tolist()), label="identical histograms: 0"),
        Case((h.tolist(), [h.tolist(), np.roll(h, 1).tolist()]), label="itself and a shifted copy"),
        Case((np.zeros(16).tolist(), H[:2].tolist()), label="a grey query (all zeros)"),
        Case((h.tolist(), H[:, :8].tolist()), raises="ValueError", label="different bin counts"),
    ]


def _clustered_nodes(rng: np.random.Generator, n_nodes: int, per_node: int, dim: int) -> list[np.ndarray]:
    return [rng.normal(0, 1, (per_node, dim)) for _ in range(n_nodes)]


def _query_from(rng: np.random.Generator, node: np.ndarray, keep: int, clutter: int, noise: float) -> np.ndarray:
    rows = rng.choice(len(node), keep, replace=False)
    seen = node[rows] + rng.normal(0, noise, (keep, node.shape[1]))
    return np.vstack([seen, rng.normal(0, 1, (clutter, node.shape[1]))])[rng.permutation(keep + clutter)]


def _fine_cases(rng: np.random.Generator) -> list[Case]:
    nodes = _clustered_nodes(rng, 5, 30, 16)
    query = _query_from(rng, nodes[2], 18, 10, 0.05)
    r = lambda a: np.round(a, 4).tolist()  # noqa: E731
    return [
        Case((r(query), [r(n) for n in nodes], [0, 1, 2, 3, 4]), label="every node a candidate"),
        Case((r(query), [r(n) for n in nodes], [4, 2]), label="two candidates, in the coarse stage's order"),
        Case((r(query), [r(n) for n in nodes], [1, 3]), {"ratio": 0.6}, label="the right node not among them"),
        Case((r(query), [r(n) for n in nodes[:2]] + [r(np.vstack([nodes[2], nodes[2][:10]]))] + [r(n) for n in nodes[3:]],
              [2, 0]), label="node 2 stores ten descriptors twice: a match to one of them is ambiguous"),
        Case((r(query), [r(n) for n in nodes], [7]), raises="ValueError", label="a candidate that does not exist"),
        Case((r(query), [r(n) for n in nodes[:2]] + [r(nodes[2][:1])], [2]), raises="ValueError",
             label="a node with one descriptor (no second neighbour)"),
        Case((r(query[:3]), [r(n[:, :8]) for n in nodes], [0]), raises="ValueError",
             label="descriptors of different lengths"),
    ]


def _counts_checked(expected, got):
    """:func:`exact`, and which way a count is off: too many means ambiguous matches were counted."""
    message = exact()(expected, got)
    if message is None:
        return None
    try:
        more = np.asarray(got, float).ravel() - np.asarray(expected, float).ravel()
    except (TypeError, ValueError):
        return message
    if more.shape != np.shape(expected) or not np.isfinite(more).all():
        return message
    hints = []
    if (more > 0).any():
        hints.append(f"at candidate position(s) {np.flatnonzero(more > 0).tolist()} you count more than the "
                     "unambiguous matches: a descriptor counts only when one node descriptor beats every other by the "
                     "ratio")
    if (more < 0).any():
        hints.append(f"at candidate position(s) {np.flatnonzero(more < 0).tolist()} you count fewer: check the "
                     "distance you compare and the ratio you use")
    return f"{message}; {'; '.join(hints)}"


def _recognise_cases(rng: np.random.Generator) -> list[Case]:
    """Maps where the colour histogram alone picks a wrong node in some cases (a corridor look-alike)."""
    cases = []
    n, bins = 6, 16
    trues = rng.choice(n, 4, replace=False)    # four different answers: no constant index passes them all
    for k in range(4):
        hist = rng.dirichlet(np.ones(bins) * 2, n)
        nodes = _clustered_nodes(rng, n, 30, 16)
        true = int(trues[k])
        decoy = (true + 1 + int(rng.integers(n - 1))) % n
        q_hist = np.clip(hist[true] + rng.normal(0, 0.004, bins), 0, None)
        q_hist /= q_hist.sum()
        if k % 2 == 0:  # a look-alike: the decoy's histogram is closer to the query than the true node's
            look_alike = np.clip(q_hist + rng.normal(0, 0.001, bins), 0, None)
            hist[decoy] = look_alike / look_alike.sum()
        query = _query_from(rng, nodes[true], 16, 12, 0.05)
        label = "a look-alike node has the closer histogram" if k % 2 == 0 else "an unambiguous place"
        cases.append(Case((np.round(q_hist, 6).tolist(), np.round(query, 4).tolist(), np.round(hist, 6).tolist(),
                           [np.round(d, 4).tolist() for d in nodes]), label=label))
    cases.append(Case(([0.5, 0.5], [[0.0] * 16], [], []), raises="ValueError", label="a map with no nodes"))
    return cases


def _relax_cases(rng: np.random.Generator) -> list[Case]:
    """Maps of the lesson's office tour: every return closed, one long loop, a cap that stops the loop early."""
    def case(graph, label, raises=None, **kwargs):
        args = (graph["poses"], graph["edges"], graph["measurements"], graph["edge_variances"])
        return Case(args, {"tolerance": TOLERANCE, **kwargs}, raises=raises, label=label)
    every, one, capped = (tour_graph(rng, 2.5, "all"), tour_graph(rng, 2.0, "last"), tour_graph(rng, 2.5, "all"))
    bad = dict(every, edge_variances=[-0.01] + every["edge_variances"][1:])
    stray = dict(every, edges=every["edges"][:-1] + [[0, len(every["poses"]) + 3]])
    return [
        case(every, "the office tour, every return to a place closed"),
        case(one, "the office tour, only its last return to R1 closed: one long loop"),
        case(capped, "a cap of 40 sweeps: the loop stops before it converges", max_sweeps=40),
        case(bad, "a negative edge variance", raises="ValueError"),
        case(stray, "a loop edge to a node that does not exist", raises="ValueError"),
    ]


def _odometry_unchanged(poses, edges, measurements, edge_variances, tolerance=TOLERANCE, max_sweeps=5000):
    return {"poses": poses, "sweeps": 1, "converged": True, "changes": [0.0]}


def _fixed_sweeps(k: int):
    def shortcut(poses, edges, measurements, edge_variances, tolerance=TOLERANCE, max_sweeps=5000):
        out = relax_map(poses, edges, measurements, edge_variances, tolerance=1e-12, max_sweeps=min(k, max_sweeps))
        return dict(out, converged=True)
    return shortcut


#: Ways to pass some relaxation cases without the loop: no sweep at all, one, or a fixed number.
RELAX_SHORTCUTS = {"the odometry, unchanged": _odometry_unchanged, "one sweep": _fixed_sweeps(1),
                   "a fixed 100 sweeps, called converged": _fixed_sweeps(100)}


def _command_cases(rng: np.random.Generator) -> list[Case]:
    k2, k3 = 4.0, 2 * 2 / np.sqrt(2)
    d, th, c = rng.uniform(-0.4, 0.4), rng.uniform(-0.5, 0.5), rng.uniform(-0.8, 0.8)
    return [
        Case((0.2, 0.0, 0.0, 0.3, k2, k3), label="left of a straight line: turn right"),
        Case((0.0, 0.3, 0.0, 0.3, k2, k3), label="heading left of the line"),
        Case((0.0, 0.0, 0.5, 0.3, k2, k3), label="on a circle: omega = v c"),
        Case((float(d), float(th), float(c), 0.4, k2, k3), label="general case"),
        Case((float(d), float(th), float(c), -0.3, k2, k3), label="reversing: |v| in the first term"),
        Case((0.2, 0.0, 0.0, 0.3, -1.0, k3), raises="ValueError", label="a negative gain"),
        Case((2.5, 0.0, 0.5, 0.3, k2, k3), raises="ValueError", label="beyond the centre of curvature: 1 - c d < 0"),
    ]


def _ekf_cases(rng: np.random.Generator) -> list[Case]:
    """Fixes relative to nodes facing every way, one across the +-pi seam, with correlated covariances."""
    A = rng.normal(0, 0.1, (5, 5))
    P = (A @ A.T + np.diag([0.04, 0.04, 0.01, 0.01, 0.01])).round(6)
    P = ((P + P.T) / 2).tolist()
    R = np.diag([0.01, 0.0225, 0.0025]).tolist()
    cases = []
    for label, node_heading, robot_heading in (("a node facing north-east", rng.uniform(0.5, 1.2), 0.3),
                                               ("a node facing south-west, the robot ahead of it",
                                                rng.uniform(-2.6, -2.0), -2.0),
                                               ("node and robot facing west: the relative heading crosses +-pi",
                                                rng.uniform(3.0, 3.1), -3.0)):
        node = [float(rng.uniform(2, 12)), float(rng.uniform(1, 10)), float(node_heading)]
        offset = rng.uniform(-0.6, 0.6, 2)
        c, s = np.cos(node[2]), np.sin(node[2])
        x = [node[0] + c * offset[0] - s * offset[1], node[1] + s * offset[0] + c * offset[1], robot_heading,
             float(rng.uniform(0.1, 0.4)), float(rng.uniform(-0.3, 0.3))]
        true = se2_between(node, x[:3]) + rng.normal(0, [0.15, 0.15, 0.08])
        true[2] = wrap_angle(true[2])
        cases.append(Case((np.round(x, 4).tolist(), P, node, np.round(true, 4).tolist(), R), label=label))
    x, node, z = cases[0].args[0], cases[0].args[2], cases[0].args[3]
    cases += [
        Case((x, P, node, z, (-np.asarray(R)).tolist()), raises="ValueError", label="a negative measurement covariance"),
        Case((x, P, node[:2], z, R), raises="ValueError", label="a node pose without its heading"),
    ]
    return cases


EXERCISES = [
    Exercise(
        id="02.rgb_to_hsi", function="rgb_to_hsi",
        signature="rgb_to_hsi(pixels: (N, 3) floats in [0, 1]) -> numpy.ndarray (N, 3)  # [H, S, I]",
        points=1, cases=_rgb_cases, answer=rgb_to_hsi, compare=close(rtol=1e-5, atol=1e-5),
        kind="warm-up",
        description="The paper's Eq. (4): H in [0, 2 pi) (2 pi - theta when B > G), S = max - min, I = mean; "
                    "H = 0 where R = G = B; ValueError for a wrong shape, NaN or values outside [0, 1]."),
    Exercise(
        id="02.hue_histogram", function="hue_histogram",
        signature="hue_histogram(image: (H, W, 3) floats, bins=32, min_saturation=0.15, min_intensity=0.04, "
                  "max_intensity=0.98) -> numpy.ndarray (bins,)",
        points=1, cases=_histogram_cases, answer=hue_histogram, compare=close(rtol=1e-9, atol=1e-12),
        kind="warm-up",
        description="Normalised histogram of the hue of pixels with S >= min_saturation and min_intensity <= I "
                    "<= max_intensity; all zeros when none qualifies; ValueError for bins < 1 or a bad image."),
    Exercise(
        id="02.histogram_distance", function="histogram_distance",
        signature="histogram_distance(h: (m,), H: (m,) or (n, m)) -> float or numpy.ndarray (n,)",
        points=1, cases=_distance_cases, answer=histogram_distance, compare=close(rtol=1e-9, atol=1e-12),
        kind="warm-up",
        description="The paper's Eq. (5), the Euclidean distance, against one histogram or each row of a stack; "
                    "ValueError for different bin counts."),
    Exercise(
        id="02.fine_stage_counts", function="fine_stage_counts",
        signature="fine_stage_counts(query: (N, D), node_descriptors: list of (M_k, D), candidates: list of int, "
                  f"ratio={RATIO}) -> numpy.ndarray of int",
        points=2, cases=_fine_cases, answer=fine_stage_counts, compare=_counts_checked,
        kind="derivation",
        description="For each candidate node, how many query descriptors have an unambiguous match there (one node "
                    "descriptor closer than ratio times every other: the task states the goal, the student works "
                    "out the test, duplicates included); ValueError for an unknown candidate or descriptors of "
                    "different lengths."),
    Exercise(
        id="02.relax_map", function="relax_map",
        signature="relax_map(poses: (N, 3), edges: (M, 2), measurements: (M, 3), edge_variances: (M,), "
                  f"tolerance={TOLERANCE}, max_sweeps=5000) -> dict(poses, sweeps, converged, changes)",
        points=4, cases=_relax_cases, answer=relax_map, compare=map_outcome, shortcuts=RELAX_SHORTCUTS,
        kind="loop",
        description="Loop: align the office tour's drifted map by relaxation (start the variances along the chain, "
                    "sweep Eqs. (1)-(3) until a sweep's total change is under the tolerance or the cap); graded "
                    "on the map (within 5 cm of the reference's up to the gauge), the converged flag and the "
                    "sweep count; ValueError for a negative variance or an edge to a missing node."),
    Exercise(
        id="02.path_following_command", function="path_following_command",
        signature="path_following_command(d, theta_tilde, curvature, v, k2, k3) -> float  # omega",
        points=1, cases=_command_cases, answer=path_following_command, compare=close(rtol=1e-9, atol=1e-12),
        kind="warm-up",
        description="The paper's Eq. (8); ValueError for negative gains or 1 - c d <= 0."),
    Exercise(
        id="02.node_fix_update", function="node_fix_update",
        signature="node_fix_update(x: (5,), P: (5, 5), node_pose: (3,), z: (3,), R: (3, 3)) -> dict(H, x, P)",
        points=2, cases=_ekf_cases, answer=node_fix_update, compare=_fix_update_checked,
        kind="derivation",
        description="EKF update with a fix measured in the recognised node's frame: the student derives h(x) and "
                    "its Jacobian H (checked entry by entry, the wrong partial derivatives named), wraps the "
                    "heading innovation and updates; ValueError for a covariance that is not positive definite "
                    "or a node pose without its heading."),
    Exercise(
        id="02.recognise_node", function="recognise_node",
        signature="recognise_node(query_histogram, query_descriptors, node_histograms, node_descriptors) -> int",
        points=3, cases=_recognise_cases, answer=recognise_node, compare=exact(),
        kind="open",
        description="Open: the index of the node the query was taken at, by any method; ValueError for a map "
                    "with no nodes."),
]
