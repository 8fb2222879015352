"""Exercises of assignment 02 (omnidirectional hierarchical localization and visual path following)."""
from __future__ import annotations

import numpy as np

from robokit.controllers.path_following import path_following_command
from robokit.localization.hierarchical import TOP_K
from robokit.localization.pose_ekf import ekf_update
from robokit.mapping.relaxation import relax_sweep
from robokit.mapping.topological import OMNI_RATIO
from robokit.vision.colour import histogram_distance, hue_histogram, rgb_to_hsi
from robokit.vision.matching import DescriptorIndex
from robokit.vision.matching import as_ratio
from robokit.validation import as_array, as_int
from robocourse.exercises.compare import close, exact
from robocourse.exercises.spec import Case, Exercise

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
        Case((r(query), [r(n) for n in nodes], [7]), raises="ValueError", label="a candidate that does not exist"),
        Case((r(query), [r(n) for n in nodes[:2]] + [r(nodes[2][:1])], [2]), raises="ValueError",
             label="a node with one descriptor (no second neighbour)"),
        Case((r(query[:3]), [r(n[:, :8]) for n in nodes], [0]), raises="ValueError",
             label="descriptors of different lengths"),
    ]


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
    square = [[0, 0, 0], [1, 0, np.pi / 2], [1, 1, np.pi], [0, 1, -np.pi / 2]]
    meas = [[1, 0, np.pi / 2]] * 4
    noisy = (np.array(square, float) + rng.normal(0, [0.1, 0.1, 0.05], (4, 3))).round(4)
    noisy[0] = 0
    chain = np.cumsum(rng.uniform(0.5, 1, (5, 3)) * [1, 0.2, 0.1], axis=0).round(4)
    chain[0] = 0
    chain_meas = rng.normal([1, 0, 0.1], 0.05, (5, 3)).round(4)
    edges5 = [[0, 1], [1, 2], [2, 3], [3, 4], [4, 0]]
    return [
        Case((noisy.tolist(), [0.0, 0.1, 0.2, 0.3], [[0, 1], [1, 2], [2, 3], [3, 0]], meas, [0.1] * 4),
             label="a square loop, odometry drifted"),
        Case((chain.tolist(), [0.0, 0.05, 0.1, 0.15, 0.2], edges5, chain_meas.tolist(), [0.05, 0.05, 0.05, 0.05, 0.5]),
             label="a loop closed by one uncertain edge"),
        Case((chain.tolist(), [0.0, 0.05, 0.1, 0.15, 0.2], edges5, chain_meas.tolist(), [0.05] * 5), {"fixed": 2},
             label="node 2 fixed"),
        Case((noisy.tolist(), [0.0, 0.1, 0.2, 0.3], [[0, 1]], [[1, 0, 0]], [-0.1]), raises="ValueError",
             label="a negative edge variance"),
        Case((noisy.tolist(), [0.0, 0.1, 0.2, 0.3], [[0, 9]], [[1, 0, 0]], [0.1]), raises="ValueError",
             label="an edge to a node that does not exist"),
    ]


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
    x = [1.0, 2.0, 0.3, 0.3, 0.1]
    A = rng.normal(0, 0.1, (5, 5))
    P = (A @ A.T + np.diag([0.04, 0.04, 0.01, 0.01, 0.01])).round(6)
    P = (P + P.T) / 2
    H = np.hstack([np.eye(3), np.zeros((3, 2))])
    R = np.diag([0.01, 0.0225, 0.0025])
    z = (np.array(x[:3]) + rng.normal(0, [0.1, 0.15, 0.05])).round(4)
    return [
        Case((x, P.tolist(), z.tolist(), H.tolist(), R.tolist()), label="a visual fix [x, y, theta]"),
        Case((x, P.tolist(), [1.05, 2.1, 0.3 - 2 * np.pi], H.tolist(), R.tolist()), {"angles": [2]},
             label="the fix's heading wrapped by 2 pi"),
        Case(([0.0, 0.0, 0.0, 0.5, 0.0], np.eye(5).tolist(), [0.4, 0.0], [[0, 0, 0, 1, 0], [0, 0, 0, 0, 1]],
              np.diag([0.01, 0.01]).tolist()), label="an odometry update of (v, omega)"),
        Case((x, P.tolist(), z.tolist(), H.tolist(), (-R).tolist()), raises="ValueError",
             label="a negative measurement covariance"),
        Case((x, P.tolist(), z[:2].tolist(), H.tolist(), R.tolist()), raises="ValueError",
             label="z and H do not agree"),
    ]


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
        points=2, cases=_histogram_cases, answer=hue_histogram, compare=close(rtol=1e-9, atol=1e-12),
        kind="transcription",
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
        points=2, cases=_fine_cases, answer=fine_stage_counts, compare=exact(),
        kind="transcription",
        description="For each candidate node, how many query descriptors pass the nearest/second-nearest "
                    "distance-ratio test against that node's descriptors (the fine stage); ValueError for an "
                    "unknown candidate or descriptors of different lengths."),
    Exercise(
        id="02.relax_sweep", function="relax_sweep",
        signature="relax_sweep(poses: (N, 3), variances: (N,), edges: (M, 2), measurements: (M, 3), "
                  "edge_variances: (M,), fixed=0) -> (poses (N, 3), variances (N,))",
        points=3, cases=_relax_cases, answer=relax_sweep, compare=close(rtol=1e-7, atol=1e-9),
        kind="transcription",
        description="One sweep of the paper's Eqs. (1)-(3) (Jacobi: every node from the input values), the "
                    "fixed node unchanged; ValueError for a negative variance or an edge to a missing node."),
    Exercise(
        id="02.path_following_command", function="path_following_command",
        signature="path_following_command(d, theta_tilde, curvature, v, k2, k3) -> float  # omega",
        points=1, cases=_command_cases, answer=path_following_command, compare=close(rtol=1e-9, atol=1e-12),
        kind="warm-up",
        description="The paper's Eq. (8); ValueError for negative gains or 1 - c d <= 0."),
    Exercise(
        id="02.ekf_update", function="ekf_update",
        signature="ekf_update(x: (n,), P: (n, n), z: (m,), H: (m, n), R: (m, m), angles=()) -> (x, P)",
        points=2, cases=_ekf_cases, answer=ekf_update, compare=close(rtol=1e-7, atol=1e-10),
        kind="transcription",
        description="Kalman update with the innovation's angle components wrapped and the Joseph-form "
                    "covariance; ValueError for a covariance that is not positive definite or shapes that "
                    "disagree."),
    Exercise(
        id="02.recognise_node", function="recognise_node",
        signature="recognise_node(query_histogram, query_descriptors, node_histograms, node_descriptors) -> int",
        points=3, cases=_recognise_cases, answer=recognise_node, compare=exact(),
        kind="open",
        description="Open: the index of the node the query was taken at, by any method; ValueError for a map "
                    "with no nodes."),
]
