"""Exercises of assignment 03 (coarse-to-fine localization in a long corridor, Ge et al. 2023).

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 876-889, 2023, doi:10.1631/FITEE.2200208.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from robokit.geometry import se2_compose
from robokit.geometry.planar import as_planar
from robokit.localization.beam_models import likelihood_field_log_weights
from robokit.localization.particle_filter import ellipse_weights, low_variance_resample, weighted_pose_mean
from robokit.mapping.corridor_areas import invalid_areas
from robokit.mapping.corridor_scan import width_condition
from robokit.mapping.occupancy_grid import LikelihoodField, log_odds
from robokit.validation import as_array, as_finite_scalar, as_positive
from robokit.vision.bag_of_words import l1_score, tf_idf
from robokit.vision.hamming import as_binary_descriptors, hamming_match
from robocourse.exercises.compare import close, exact
from robocourse.exercises.plain import summarize
from robocourse.exercises.spec import Case, Exercise
from robocourse.lessons.corridor_localization.mcl_runs import (SETTLED, TOLERANCE, dead_reckoning, one_shot,
                                                               simulate_run,
                                                               track, track_errors)

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


def bow_similarity(words_a, words_b, idf) -> dict:
    """Two images' bag-of-words vectors and their L1 score, Eqs. (16)-(17), term by term.

    Each image's vector weighs word ``i`` by its term frequency (its share of the image's features)
    times ``idf[i]``, Eq. (16), scaled to sum to 1; the score, Eq. (17), is
    ``1 - |v_a - v_b|_1 / 2``: 1 for identical vectors, 0 for vectors with no word in common (the
    L1 distance of two non-negative unit-sum vectors is at most 2, reached exactly then).

    Parameters
    ----------
    words_a, words_b : array_like of int
        The word of each feature of image A and of image B (repeats allowed).
    idf : array_like, shape (m,)
        Non-negative IDF per word.

    Returns
    -------
    dict
        ``a``, ``b``: the two unit-sum vectors (m,) (all zeros for an image with no weighted word);
        ``score``: Eq. (17) in [0, 1], 0 when either image has no weighted word.

    Raises
    ------
    ValueError
        For word ids outside ``[0, m)``, negative or non-finite IDF.

    Examples
    --------
    >>> out = bow_similarity([0, 1, 1], [1, 2], [1.0, 1.0, 1.0])
    >>> np.round(out["a"], 4).tolist(), round(out["score"], 6)          # min(2/3, 1/2) = 1/2
    ([0.3333, 0.6667, 0.0], 0.5)
    """
    weights = as_array(idf, "idf", ndim=1, min_size=1)
    vectors = []
    for name, words in (("words_a", words_a), ("words_b", words_b)):
        w = as_array(words, name, ndim=1, min_size=0)
        if np.any(w != np.round(w)) or np.any((w < 0) | (w >= len(weights))):
            raise ValueError(f"{name}: expected word ids in [0, {len(weights)}), got {w.tolist()[:8]}")
        vectors.append(tf_idf(w.astype(np.int64), weights))
    dense = []
    for v in vectors:
        full = np.zeros(len(weights))
        full[v.words] = v.weights
        dense.append(full / full.sum() if full.sum() > 0 else full)
    return {"a": dense[0], "b": dense[1], "score": l1_score(*vectors)}


#: What each term of :func:`likelihood_field_weight`'s answer stands for, for the feedback.
FIELD_TERMS = {
    "distance": "d_k, the distance from each used beam's end point to the nearest obstacle (the end point's "
                "position, its grid cell, max_distance off the grid, and which beams are skipped)",
    "hit": "z_hit times the hit model's density at d_k",
    "rand": "z_rand times the density of a random return",
    "log_q": "the log of the scan's likelihood, from the per-beam likelihoods hit + rand",
}
#: What each term of :func:`bow_similarity`'s answer stands for, for the feedback.
BOW_TERMS = {
    "a": "image A's vector (term frequency times IDF per word, scaled to sum to 1)",
    "b": "image B's vector (term frequency times IDF per word, scaled to sum to 1)",
    "score": "the score from the two vectors' L1 distance (1 for identical images, 0 for no shared word)",
}


def likelihood_field_weight(pose, ranges, angles, distance, resolution, origin, *, sigma_hit: float = 0.2,
                            z_hit: float = 0.95, z_rand: float = 0.05, r_max: float = 8.0,
                            max_distance: float = 2.0) -> dict:
    """The likelihood-field model of a scan for one pose (Thrun et al. 2005, Table 6.3), term by term.

    Each beam's likelihood mixes a hit, whose end point's distance ``d`` to the nearest obstacle is
    normal with mean 0 and standard deviation ``sigma_hit``, and a random return, uniform over
    ``[0, r_max)``: ``p_k = z_hit N(d_k; 0, sigma_hit^2) + z_rand / r_max``; the beams are
    independent, so ``log q = sum_k log p_k``.

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
    dict
        ``distance``: ``d_k`` of each used beam, in scan order; ``hit``: ``z_hit N(d_k; 0, sigma_hit^2)``
        of each; ``rand``: ``z_rand / r_max``; ``log_q``: ``sum_k log(hit_k + rand)``.

    Raises
    ------
    ValueError
        For NaN ranges, bad shapes or non-positive parameters.

    Examples
    --------
    >>> d = np.abs(np.arange(20)[None, :] * 0.1 + 0.05 - 1.55) * np.ones((20, 1))   # a wall at x = 1.55 m
    >>> out = likelihood_field_weight([0.55, 1.0, 0.0], [1.0], [0.0], d, 0.1, [0.0, 0.0])
    >>> out["distance"].tolist(), round(out["rand"], 6), round(out["log_q"], 3)
    ([0.0], 0.00625, 0.642)
    """
    field = LikelihoodField(as_array(distance, "distance", ndim=2), as_positive(resolution, "resolution"),
                            as_array(origin, "origin", shape=(2,)), as_positive(max_distance, "max_distance"))
    p = as_planar(pose, "pose", shape=(3,))
    r = as_array(ranges, "ranges", ndim=1, finite=False)
    a = as_array(angles, "angles", shape=r.shape)
    if np.isnan(r).any():
        raise ValueError("ranges: expected numbers or inf, got NaN")
    sigma_hit, r_max = as_positive(sigma_hit, "sigma_hit"), as_positive(r_max, "r_max")
    z_hit, z_rand = as_positive(z_hit, "z_hit", allow_zero=True), as_positive(z_rand, "z_rand", allow_zero=True)
    used = np.isfinite(r) & (r < r_max)
    ends = p[:2] + r[used, None] * np.column_stack([np.cos(p[2] + a[used]), np.sin(p[2] + a[used])])
    d = field.lookup(ends) if used.any() else np.zeros(0)
    hit = z_hit * np.exp(-0.5 * (d / sigma_hit) ** 2) / (np.sqrt(2 * np.pi) * sigma_hit)
    rand = z_rand / r_max
    log_q = float(likelihood_field_log_weights([p], r, a, field, sigma_hit=sigma_hit, z_hit=z_hit, z_rand=z_rand,
                                               r_max=r_max, combine="product")[0])
    return {"distance": d, "hit": hit, "rand": float(rand), "log_q": log_q}


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


def mcl_track(run: dict) -> np.ndarray:
    """Monte-Carlo localization over a pre-simulated corridor run: the estimate after each update.

    The loop exercise's reference, :func:`~robocourse.lessons.corridor_localization.mcl_runs.track`
    (motion with the given noise draws, Table 6.3's likelihood field, the weighted mean, Table 4.4's
    resampling with the given uniforms).

    Examples
    --------
    >>> from robocourse.lessons.corridor_localization.mcl_runs import simulate_run
    >>> run, truth = simulate_run(np.random.default_rng(1))
    >>> bool(np.hypot(*(mcl_track(run)[-1, :2] - truth[-1, :2])) < 0.25)
    True
    """
    return track(run)


def _terms(terms: dict, rtol: float, atol: float):
    """A comparison of a dict answer term by term that names each wrong term and what it stands for;
    a term whose values (two or more) are all off by one factor says so (a normalising constant)."""
    one = close(rtol=rtol, atol=atol)

    def compare(expected: Any, got: Any) -> str | None:
        if not isinstance(got, dict):
            return f"expected a dict with the terms {list(terms)}, got {summarize(got)}"
        missing = [k for k in terms if k not in got]
        if missing:
            return f"expected a dict with the terms {list(terms)}; missing {missing}"
        wrong = []
        for key, meaning in terms.items():
            msg = one(expected[key], got[key])
            if msg is None:
                continue
            note = ""
            try:
                e, g = np.atleast_1d(np.asarray(expected[key], float)), np.atleast_1d(np.asarray(got[key], float))
                big = np.abs(e) > 1e-12
                if e.shape == g.shape and big.sum() >= 2 and np.all(np.isfinite(g)):
                    ratio = g[big] / e[big]
                    if np.ptp(ratio) <= 1e-6 * np.abs(ratio).max() and abs(ratio[0] - 1) > 1e-6:
                        note = f"; every value is off by the same factor, {ratio[0]:.6g}: check the normalisation"
            except (TypeError, ValueError):
                pass
            wrong.append(f"'{key}' ({meaning}) is wrong: {msg}{note}")
        if not wrong:
            return None
        return f"{len(wrong)} of {len(terms)} terms wrong. " + " | ".join(wrong)

    return compare


def _converges(expected: Any, got: Any) -> str | None:
    """Accept a track of estimates whose last :data:`SETTLED` are each within :data:`TOLERANCE` of
    the truth (``expected``); the feedback shows the error at a few updates."""
    truth = np.asarray(expected, dtype=float)
    try:
        est = np.asarray(got, dtype=float)
    except (TypeError, ValueError):
        return f"expected a ({len(truth)}, 3) array of estimates [x, y, theta], got {summarize(got)}"
    if est.shape != truth.shape:
        return f"expected a ({len(truth)}, 3) array of estimates [x, y, theta], one per update, got shape {est.shape}"
    if not np.all(np.isfinite(est)):
        return f"your estimates hold NaN or inf (first at update {int(np.argmax(~np.isfinite(est).all(axis=1))) + 1})"
    err = track_errors(est, truth)
    T = len(err)
    show = sorted({0, T // 4, T // 2, 3 * T // 4, T - SETTLED, T - 1})
    shown = ", ".join(f"{k + 1}: {err[k, 0]:.2f} m {np.rad2deg(err[k, 1]):.1f} deg" for k in show)
    ok = (err <= TOLERANCE).all(axis=1)
    if ok[-SETTLED:].all():
        return None
    inside = np.flatnonzero(ok)
    if not inside.size:
        story = "it was never within the tolerance"
    else:
        story = (f"it was within the tolerance at update {inside[0] + 1} and left it again at update "
                 f"{inside[0] + 1 + int(np.argmin(ok[inside[0]:]))}")
    return (f"did not converge: the last {SETTLED} estimates must each be within {TOLERANCE[0]} m and "
            f"{np.rad2deg(TOLERANCE[1]):.1f} deg of the truth; {story}. Error at update {shown}")


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



def _truncated(run: dict, updates: int) -> dict:
    """The first ``updates`` updates of a run (a small input for the bad-input cases)."""
    out = dict(run)
    for key in ("odometry", "noise", "scans", "uniforms"):
        out[key] = run[key][:updates]
    return out


def _track_cases(rng: np.random.Generator) -> list[Case]:
    """Three fair drives in the lesson's corridor (:func:`~.mcl_runs.simulate_run`), judged on the truth."""
    cases = []
    for _ in range(3):
        run, truth = simulate_run(rng)
        start = np.mean(np.asarray(run["particles"])[:, 0])
        cases.append(Case((run,), expected=truth.round(4).tolist(),
                          label=f"a drive {'east' if np.cos(truth[0, 2]) > 0 else 'west'} from x = {truth[0, 0]:.1f} m, "
                                f"the start cloud centred {start - truth[0, 0]:+.2f} m along the corridor from the "
                                f"robot"))
    small = _truncated(cases[0].args[0], 4)
    bad_r = dict(small, uniforms=[0.5] + small["uniforms"][1:])
    short = dict(small, scans=small["scans"][:3])
    return cases + [
        Case((bad_r,), raises="ValueError", label="a resampling number outside [0, 1/M)"),
        Case((short,), raises="ValueError", label="one scan fewer than odometry increments"),
    ]


def _held_start(run: dict) -> list:
    """A shortcut: the start cloud's mean, every update."""
    mean = np.mean(np.asarray(run["particles"], dtype=float), axis=0)
    return [mean.tolist()] * len(run["odometry"])


def _laser_blind(run: dict) -> np.ndarray:
    """A shortcut: the filter without its measurement update (equal weights), so dead reckoning with noise."""
    P = np.asarray(run["particles"], dtype=float)
    std, out = np.asarray(run["motion_std"], dtype=float), []
    for u, n in zip(np.asarray(run["odometry"], dtype=float), np.asarray(run["noise"], dtype=float)):
        P = se2_compose(P, u + n * std)
        out.append(weighted_pose_mean(P))
    return np.array(out)


#: Ways to produce a track without the loop: they pass no fair run (:mod:`.mcl_runs`).
TRACK_SHORTCUTS = {"dead reckoning from the start cloud's mean": dead_reckoning,
                   "the start cloud's mean, held": _held_start,
                   "the filter without its measurement update": _laser_blind,
                   "the particle the first scan likes best, dead-reckoned": one_shot}


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
        signature="bow_similarity(words_a: list of int, words_b: list of int, idf: (m,)) -> dict "
                  "{'a': (m,), 'b': (m,), 'score': float}",
        points=1, cases=_bow_cases, answer=bow_similarity, compare=_terms(BOW_TERMS, 1e-9, 1e-12),
        kind="derivation",
        description="Eqs. (16)-(17) from their description: each image's TF-IDF vector scaled to sum to 1, and "
                    "the affine map of their L1 distance that gives 1 for the same image and 0 for no shared word "
                    "(derived, not given); feedback names the wrong term; ValueError for a word outside the "
                    "vocabulary."),
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
                  "sigma_hit=0.2, z_hit=0.95, z_rand=0.05, r_max=8.0, max_distance=2.0) -> dict "
                  "{'distance': (K,), 'hit': (K,), 'rand': float, 'log_q': float}",
        points=2, cases=_field_cases, answer=likelihood_field_weight, compare=_terms(FIELD_TERMS, 1e-7, 1e-9),
        kind="derivation",
        description="Thrun et al. Table 6.3 derived from the model's description: each used beam's end-point "
                    "distance, the hit term (the normal density, its normalisation derived), the random-return "
                    "term (the uniform density) and log q; feedback names the wrong term; ValueError for NaN "
                    "ranges."),
    Exercise(
        id="03.ellipse_start_weights", function="ellipse_start_weights",
        signature="ellipse_start_weights(points: (N, 2), centre: (2,), sigma_x, sigma_y) -> numpy.ndarray (N,)",
        points=1, cases=_ellipse_cases, answer=ellipse_start_weights, compare=close(rtol=1e-9, atol=1e-12),
        kind="warm-up",
        description="Eq. (19), unnormalised; ValueError for a non-positive sigma."),
    Exercise(
        id="03.recognise_keyframe", function="recognise_keyframe",
        signature="recognise_keyframe(query: (N, 32) uint8, keyframes: list of (M_k, 32) uint8) -> int",
        points=2, cases=_keyframe_cases, answer=recognise_keyframe, compare=exact(),
        kind="open",
        description="Open: the index of the keyframe the query was taken at, by any method; ValueError for no "
                    "keyframes."),
    Exercise(
        id="03.mcl_track", function="mcl_track",
        signature="mcl_track(run: dict) -> array-like (T, 3) of estimates [x, y, theta]",
        points=2, cases=_track_cases, answer=mcl_track, compare=_converges,
        kind="loop",
        description="Loop: Monte-Carlo localization over a pre-simulated drive in the lesson's corridor (motion "
                    "with the given noise draws, the likelihood-field weight, the weighted mean, low-variance "
                    "resampling with the given numbers); passes when the last 5 estimates are within 0.25 m and "
                    "5.7 deg of the simulator's truth; ValueError for a resampling number outside [0, 1/M) or "
                    "inputs of mismatched lengths.",
        shortcuts=TRACK_SHORTCUTS),
]
