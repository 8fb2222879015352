"""Exercises of assignment 03 (coarse-to-fine localization in a long corridor, Ge et al. 2023).

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

import numpy as np

from robokit.geometry.planar import as_planar
from robokit.localization.beam_models import likelihood_field_log_weights
from robokit.localization.particle_filter import ellipse_weights, low_variance_resample
from robokit.mapping.corridor_areas import invalid_areas
from robokit.mapping.corridor_scan import width_condition
from robokit.mapping.occupancy_grid import LikelihoodField, log_odds
from robokit.validation import as_array, as_finite_scalar, as_positive
from robokit.vision.bag_of_words import l1_score, tf_idf
from robokit.vision.hamming import as_binary_descriptors, hamming_match
from robocourse.exercises.compare import close, exact
from robocourse.exercises.spec import Case, Exercise

ASSIGNMENT = "03_corridor_localization"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"03.laser_aliasing": 2, "03.ellipse_start": 2, "03.moving_strategy": 2}


def cell_log_odds(probabilities, prior: float = 0.5) -> float:
    """Log odds of one grid cell after a sequence of inverse-sensor-model readings.

    Thrun et al. (2005), Table 9.1, line 4: ``l_t = l_{t-1} + log(p / (1 - p)) - l_0`` with
    ``l_0 = log(prior / (1 - prior))``, starting from ``l_0``; no clamping.

    Parameters
    ----------
    probabilities : array_like, shape (T,)
        ``p(m | z_t, x_t)`` of each reading that covered the cell, each strictly in (0, 1).
    prior : float, default 0.5
        ``p(m)`` before any reading, strictly in (0, 1).

    Returns
    -------
    float

    Raises
    ------
    ValueError
        For a probability of 0 or 1 (infinite log odds), outside [0, 1], or NaN.

    Examples
    --------
    >>> round(cell_log_odds([0.7, 0.7, 0.4]), 6)       # two hits and a pass: 2 log(7/3) + log(2/3)
    1.289131
    """
    p = as_array(probabilities, "probabilities", ndim=1, min_size=0)
    if np.any((p <= 0) | (p >= 1)):
        raise ValueError(f"probabilities: expected readings strictly between 0 and 1, got {p.tolist()}")
    prior = as_finite_scalar(prior, "prior")
    if not 0 < prior < 1:
        raise ValueError(f"prior: expected a probability strictly between 0 and 1, got {prior}")
    l0 = float(log_odds(prior))
    return float(l0 + np.sum(log_odds(p) - l0)) if p.size else l0


def bow_similarity(words_a, words_b, idf) -> float:
    """The L1 score, Eq. (17), of two images given the vocabulary word of each of their features.

    Each image's vector is its TF-IDF weights, Eq. (16) (``TF = n_ik / n_k``, ``IDF = idf[word]``),
    then Eq. (17) on the L1-normalised vectors. Words with zero IDF drop out.

    Parameters
    ----------
    words_a, words_b : array_like of int
        The word of each feature of image A and of image B (repeats allowed).
    idf : array_like, shape (m,)
        Non-negative IDF per word.

    Returns
    -------
    float
        In [0, 1]; 0 when either image has no weighted word.

    Raises
    ------
    ValueError
        For word ids outside ``[0, m)``, negative or non-finite IDF.

    Examples
    --------
    >>> round(bow_similarity([0, 1, 1], [1, 2], [1.0, 1.0, 1.0]), 6)    # min(2/3, 1/2) = 1/2
    0.5
    """
    weights = as_array(idf, "idf", ndim=1, min_size=1)
    vectors = []
    for name, words in (("words_a", words_a), ("words_b", words_b)):
        w = as_array(words, name, ndim=1, min_size=0)
        if np.any(w != np.round(w)) or np.any((w < 0) | (w >= len(weights))):
            raise ValueError(f"{name}: expected word ids in [0, {len(weights)}), got {w.tolist()[:8]}")
        vectors.append(tf_idf(w.astype(np.int64), weights))
    return l1_score(*vectors)


def likelihood_field_weight(pose, ranges, angles, distance, resolution, origin, *, sigma_hit: float = 0.2,
                            z_hit: float = 0.95, z_rand: float = 0.05, r_max: float = 8.0,
                            max_distance: float = 2.0) -> float:
    """The log of Table 6.3's ``q`` for one pose: the likelihood-field model of a scan.

    Parameters
    ----------
    pose : array_like, shape (3,)
        ``[x, y, theta]``; the sensor sits at the robot's centre, facing forward.
    ranges, angles : array_like, shape (B,)
        The scan; returns of ``inf`` or at least ``r_max`` are skipped.
    distance : array_like, shape (H, W)
        Distance (m) from each cell to the nearest obstacle; cell ``[i, j]`` covers
        ``origin + ([j, j+1), [i, i+1)) * resolution``. An end point off the grid has ``max_distance``.
    resolution : float
    origin : array_like, shape (2,)
    sigma_hit, z_hit, z_rand, r_max, max_distance : float

    Returns
    -------
    float
        ``sum_k log(z_hit N(dist_k; 0, sigma_hit^2) + z_rand / r_max)``.

    Raises
    ------
    ValueError
        For NaN ranges, bad shapes or non-positive parameters.

    Examples
    --------
    >>> d = np.abs(np.arange(20)[None, :] * 0.1 + 0.05 - 1.55) * np.ones((20, 1))   # a wall at x = 1.55 m
    >>> round(likelihood_field_weight([0.55, 1.0, 0.0], [1.0], [0.0], d, 0.1, [0.0, 0.0]), 3)
    0.642
    """
    field = LikelihoodField(as_array(distance, "distance", ndim=2), as_positive(resolution, "resolution"),
                            as_array(origin, "origin", shape=(2,)), as_positive(max_distance, "max_distance"))
    return float(likelihood_field_log_weights([as_planar(pose, "pose", shape=(3,))], ranges, angles, field,
                                              sigma_hit=sigma_hit, z_hit=z_hit, z_rand=z_rand, r_max=r_max,
                                              combine="product")[0])


def resample_indices(weights, r: float) -> list:
    """Low-variance resampling (Thrun et al. 2005, Table 4.4) given its one random number ``r``.

    Examples
    --------
    >>> resample_indices([0.1, 0.6, 0.3], 0.2)
    [1, 1, 2]
    """
    w = as_array(weights, "weights", ndim=1, min_size=1)
    r = as_finite_scalar(r, "r")
    if not 0 <= r < 1 / len(w):
        raise ValueError(f"r: expected a number in [0, 1/M) = [0, {1 / len(w):.6g}), got {r}")
    return low_variance_resample(w, start=r).tolist()


def ellipse_start_weights(points, centre, sigma_x: float, sigma_y: float) -> np.ndarray:
    """Eq. (19): the Gaussian initial weight of particles at ``points`` around ``centre = (x_k, y_k)``.

    Examples
    --------
    >>> np.round(ellipse_start_weights([[0.0, 0.0], [1.0, 0.0]], [0.0, 0.0], 1.0, 1.0), 6).tolist()
    [0.159155, 0.096532]
    """
    P = as_array(points, "points", ndim=2)
    if P.shape[1] != 2:
        raise ValueError(f"points: expected shape (N, 2), got {P.shape}")
    c = as_array(centre, "centre", shape=(2,))
    try:
        return ellipse_weights(np.column_stack([P, np.zeros(len(P))]), [c[0], c[1], 0.0], sigma_x, sigma_y,
                               normalise=False)
    except ValueError as exc:   # say it in this function's names
        raise ValueError(str(exc).replace("particles, pose", "points, centre")) from None


def recognise_keyframe(query, keyframes) -> int:
    """The keyframe a query image was taken at, from binary descriptors (the open exercise's answer).

    Counts, for each keyframe, the query descriptors whose nearest keyframe descriptor is within 50
    bits and passes the ratio test (:func:`robokit.vision.hamming_match`), and returns the keyframe
    with the most.

    Parameters
    ----------
    query : array_like of uint8, shape (N, 32)
    keyframes : list of array_like of uint8, each (M_k, 32)

    Returns
    -------
    int

    Raises
    ------
    ValueError, TypeError
        For an empty list of keyframes or descriptors that are not 32-byte rows.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> kfs = [rng.integers(0, 256, (30, 32), dtype=np.uint8) for _ in range(3)]
    >>> recognise_keyframe(kfs[2][:10], kfs)
    2
    """
    q = as_binary_descriptors(query, "query")
    if not isinstance(keyframes, (list, tuple)) or not keyframes:
        raise ValueError("keyframes: expected a non-empty list of (M_k, 32) descriptor arrays")
    counts = [len(hamming_match(q, as_binary_descriptors(k, f"keyframes[{i}]")).query)
              for i, k in enumerate(keyframes)]
    return int(np.argmax(counts))


# --- cases ------------------------------------------------------------------------------------

def _two_walls(d_left: float, d_right: float, beams: int = 360, r_max: float = 8.0, turn: float = 0.0):
    """A scan between two parallel walls along the robot's heading (turned by ``turn``)."""
    a = 2 * np.pi * np.arange(beams) / beams
    s = np.sin(a + turn)
    with np.errstate(divide="ignore"):
        r = np.where(s > 0, d_left / s, np.where(s < 0, -d_right / s, np.inf))
    r[r > r_max] = np.inf
    return r.round(6).tolist(), a.round(9).tolist()


def _width_cases(rng: np.random.Generator) -> list[Case]:
    w, dda = 2.17, 0.07
    y = float(rng.uniform(-0.3, 0.3))
    return [
        Case((w / 2 - y, w / 2 + y, w), label="a plain stretch, off the middle line: Eq. (1)"),
        Case((w / 2 + dda, w / 2 + dda, w), label="doors face each other: Eq. (2)"),
        Case((w / 2 + dda, w / 2, w), label="one door, staggered: Eq. (3)"),
        Case((w / 2 + 0.02, w / 2 - 0.01, w), {"tol": 0.03}, label="noisy, within tolerance"),
        Case((1.6, 1.5, w), label="far too wide: not a corridor (None)"),
        Case((w / 2, -0.2, w), raises="ValueError", label="a negative distance"),
    ]


def _invalid_cases(rng: np.random.Generator) -> list[Case]:
    r, a = _two_walls(1.085, 1.085)
    r2, a2 = _two_walls(0.4, 1.77, turn=float(rng.uniform(-0.3, 0.3)))
    r3, a3 = _two_walls(1.085, 1.085, turn=0.5)
    return [
        Case((r, a), label="on the middle line: two areas, one ahead and one behind (wrapping past 0)"),
        Case((r2, a2), label="near a wall, turned"),
        Case((r3, a3), label="turned 0.5 rad: no area crosses 0"),
        Case(([1.0, 2.0, 1.5, 3.0], [0.0, 1.5, 3.0, 4.5]), label="no invalid return: no area"),
        Case(([float("inf")] * 4, [0.0, 1.5, 3.0, 4.5]), label="nothing valid: one area, first to last beam"),
        Case(([1.0, float("nan"), 1.0], [0.0, 2.0, 4.0]), raises="ValueError", label="a NaN range"),
    ]


def _log_odds_cases(rng: np.random.Generator) -> list[Case]:
    hits = rng.uniform(0.55, 0.9, 6).round(3)
    return [
        Case(([0.7, 0.7, 0.4],), label="two hits and a pass"),
        Case((hits.tolist(),), label="six readings"),
        Case(([0.7, 0.4],), {"prior": 0.3}, label="an informative prior"),
        Case(([],), label="no reading: the prior's log odds"),
        Case(([0.7, 1.0],), raises="ValueError", label="a certain reading (infinite log odds)"),
    ]


def _bow_cases(rng: np.random.Generator) -> list[Case]:
    idf = rng.uniform(0.2, 3.0, 12).round(4)
    idf[5] = 0.0
    a = rng.integers(0, 12, 40)
    b = np.concatenate([a[:25], rng.integers(0, 12, 15)])
    return [
        Case((a.tolist(), a.tolist(), idf.tolist()), label="an image against itself: 1"),
        Case((a.tolist(), b.tolist(), idf.tolist()), label="two views sharing most words"),
        Case(([0, 1, 1], [2, 3], idf.tolist()), label="no shared word: 0"),
        Case(([5, 5], [5, 1], idf.tolist()), label="a word with zero IDF carries nothing"),
        Case(([0, 13], [1], idf.tolist()), raises="ValueError", label="a word the vocabulary does not have"),
    ]


def _heaviest_repeated(weights: list, r: float) -> list[int]:
    """A shortcut that passes the case where one particle holds all the weight: that particle, M times."""
    return [int(np.argmax(weights))] * len(weights)


def _resample_cases(rng: np.random.Generator) -> list[Case]:
    w = rng.dirichlet(np.ones(8))
    return [
        Case(([0.1, 0.6, 0.3], 0.2), label="three particles"),
        Case((w.round(6).tolist(), float(rng.uniform(0, 1 / 8))), label="eight particles"),
        Case(([2.0, 1.0, 1.0], 0.1), label="weights that do not sum to one"),
        Case(([0.0, 0.0, 1.0], 0.3), label="one particle holds all the weight"),
        Case(([0.5, 0.5], 0.7), raises="ValueError", label="r outside [0, 1/M)"),
        Case(([0.5, -0.5], 0.1), raises="ValueError", label="a negative weight"),
    ]


def _field_cases(rng: np.random.Generator) -> list[Case]:
    res = 0.1
    cols = np.arange(40) * res + res / 2
    rows = np.arange(20) * res + res / 2
    # two walls, x = 3.45 m and y = 1.85 m: distance to the nearer
    d = np.minimum(np.abs(cols[None, :] - 3.45), np.abs(rows[:, None] - 1.85)).round(6)
    angles = np.deg2rad([0.0, 45.0, 90.0, 180.0]).round(9)
    pose = [1.0, 0.6, 0.0]
    ranges = [2.45, 1.8, 1.25, float("inf")]
    noisy = (np.array(ranges[:3]) + rng.normal(0, 0.05, 3)).round(4).tolist() + [float("inf")]
    return [
        Case((pose, ranges, angles.tolist(), d.tolist(), res, [0.0, 0.0]), label="end points on the walls"),
        Case((pose, noisy, angles.tolist(), d.tolist(), res, [0.0, 0.0]), label="a noisy scan"),
        Case(([1.3, 0.6, 0.1], ranges, angles.tolist(), d.tolist(), res, [0.0, 0.0]), label="the wrong pose"),
        Case((pose, ranges, angles.tolist(), d.tolist(), res, [-1.0, 0.0]), label="a shifted origin: some end points "
             "off the grid"),
        Case((pose, [2.45, float("nan"), 1.0, 1.0], angles.tolist(), d.tolist(), res, [0.0, 0.0]),
             raises="ValueError", label="a NaN range"),
    ]


def _ellipse_cases(rng: np.random.Generator) -> list[Case]:
    pts = rng.uniform([9.0, -0.3], [11.0, 0.3], (6, 2)).round(4)
    return [
        Case(([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], [0.0, 0.0], 1.0, 1.0), label="a unit circle"),
        Case((pts.tolist(), [10.0, 0.0], 0.3, 0.1), label="along a corridor: wide in x, narrow in y"),
        Case(([[10.0, 0.0]], [10.0, 0.0], 0.5, 0.2), label="the centre: 1 / (2 pi sigma_x sigma_y)"),
        Case(([[0.0, 0.0]], [0.0, 0.0], -0.3, 0.1), raises="ValueError", label="a negative sigma"),
    ]


def _keyframe_cases(rng: np.random.Generator) -> list[Case]:
    """Keyframes with look-alikes (half their descriptors shared); queries seen again with flipped bits."""
    cases = []
    n_kf = 6
    trues = rng.choice(n_kf, 4, replace=False)    # four different answers: no constant index passes them all
    for k in range(4):
        base = rng.integers(0, 256, (n_kf, 40, 32), dtype=np.uint8)
        true = int(trues[k])
        decoy = (true + 1 + int(rng.integers(n_kf - 1))) % n_kf
        base[decoy, :20] = base[true, :20]              # a look-alike keyframe shares half its features
        seen = base[true, rng.choice(40, 24, replace=False)].copy()
        bits = np.unpackbits(seen, axis=1)
        flip = rng.random(bits.shape) < 0.04            # about 10 of 256 bits change between views
        query = np.vstack([np.packbits(bits ^ flip, axis=1), rng.integers(0, 256, (10, 32), dtype=np.uint8)])
        cases.append(Case((query[rng.permutation(len(query))].tolist(), [kf.tolist() for kf in base]),
                          label="a look-alike keyframe shares half the true one's features" if k % 2 == 0
                          else "a query seen again with a few bits flipped"))
    cases.append(Case(([[0] * 32], []), raises="ValueError", label="no keyframes"))
    return cases


EXERCISES = [
    Exercise(
        id="03.width_case", function="width_case",
        signature="width_case(d_l, d_r, width, recess=0.07, tol=0.03) -> str or None",
        points=1, cases=_width_cases, answer=width_condition, compare=exact(),
        kind="warm-up",
        description="Which of Eqs. (1), (2), (3) the wall distances satisfy ('corridor', 'facing doors', "
                    "'staggered doors'; the one with the smallest error), or None; ValueError for a negative "
                    "distance."),
    Exercise(
        id="03.invalid_areas", function="invalid_areas",
        signature="invalid_areas(ranges: (B,), angles: (B,) increasing in [0, 2 pi)) -> numpy.ndarray (K, 3)",
        points=2, cases=_invalid_cases, answer=invalid_areas, compare=close(rtol=1e-9, atol=1e-9),
        kind="derivation",
        description="Eq. (9): (first angle, last angle, theta_null) of each run of invalid (inf) returns, a run "
                    "wrapping past the last beam counted once, rows ordered by first angle; ValueError for NaN."),
    Exercise(
        id="03.cell_log_odds", function="cell_log_odds",
        signature="cell_log_odds(probabilities: (T,), prior=0.5) -> float",
        points=1, cases=_log_odds_cases, answer=cell_log_odds, compare=close(rtol=1e-9, atol=1e-12),
        kind="warm-up",
        description="Thrun et al. Table 9.1 line 4 for one cell over a sequence of readings (no clamping); "
                    "ValueError for a reading of 0 or 1."),
    Exercise(
        id="03.bow_similarity", function="bow_similarity",
        signature="bow_similarity(words_a: list of int, words_b: list of int, idf: (m,)) -> float",
        points=2, cases=_bow_cases, answer=bow_similarity, compare=close(rtol=1e-9, atol=1e-12),
        kind="transcription",
        description="TF-IDF vectors, Eq. (16), of two images' words, then the L1 score, Eq. (17); ValueError for "
                    "a word outside the vocabulary."),
    Exercise(
        id="03.resample_indices", function="resample_indices",
        signature="resample_indices(weights: (M,), r: float in [0, 1/M)) -> list of int",
        points=1, cases=_resample_cases, answer=resample_indices, compare=exact(),
        kind="warm-up",
        description="Thrun et al. Table 4.4 with its random number given (weights normalised first); "
                    "ValueError for r outside [0, 1/M) or a negative weight.",
        shortcuts={"the heaviest particle, repeated": _heaviest_repeated}),
    Exercise(
        id="03.likelihood_field_weight", function="likelihood_field_weight",
        signature="likelihood_field_weight(pose, ranges, angles, distance: (H, W), resolution, origin, "
                  "sigma_hit=0.2, z_hit=0.95, z_rand=0.05, r_max=8.0, max_distance=2.0) -> float",
        points=2, cases=_field_cases, answer=likelihood_field_weight, compare=close(rtol=1e-7, atol=1e-9),
        kind="transcription",
        description="The log of Thrun et al. Table 6.3's q for one pose (end points looked up in the distance "
                    "grid, max_distance off it, inf returns skipped); ValueError for NaN ranges."),
    Exercise(
        id="03.ellipse_start_weights", function="ellipse_start_weights",
        signature="ellipse_start_weights(points: (N, 2), centre: (2,), sigma_x, sigma_y) -> numpy.ndarray (N,)",
        points=1, cases=_ellipse_cases, answer=ellipse_start_weights, compare=close(rtol=1e-9, atol=1e-12),
        kind="warm-up",
        description="Eq. (19), unnormalised; ValueError for a non-positive sigma."),
    Exercise(
        id="03.recognise_keyframe", function="recognise_keyframe",
        signature="recognise_keyframe(query: (N, 32) uint8, keyframes: list of (M_k, 32) uint8) -> int",
        points=3, cases=_keyframe_cases, answer=recognise_keyframe, compare=exact(),
        kind="open",
        description="Open: the index of the keyframe the query was taken at, by any method; ValueError for no "
                    "keyframes."),
]
