"""The Monte-Carlo check of hierarchical localization: appearance-based MCL over a short drive.

Lesson 02's paper (Li et al. 2011), Sec. "Hierarchical localization", Fig. 5: each candidate node is
matched with the query and "the correct position is the one getting the largest number of matches. If
the localization result is still ambiguous, epipolar geometry constraints and Monte-Carlo
localization strategy are employed to verify the result." The paper says no more. We read the
Monte-Carlo step as image-based Monte-Carlo localization with omnidirectional images (Menegatti et
al. 2004): the robot drives on a little, particles start at the pose each candidate node gives the
first image (:func:`place_hypotheses`), move with the odometry (Thrun et al. 2005, Table 5.6) and are
weighted at each new image by how well that image matches the map's key image nearest to them (SIFT
match counts, as the fine stage counts them). The hypothesis whose descendants hold most of the
particles at the end is the verified answer (:func:`monte_carlo_check`).

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] E. Menegatti, M. Zoccarato, E. Pagello and H. Ishiguro, "Image-based Monte Carlo localisation
   with omnidirectional images", *Robotics and Autonomous Systems* 48(1), 17-30, 2004.
.. [3] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..geometry import se2_compose, wrap_angle
from ..mapping.omni_views import as_omni_image, relative_pose
from ..sim import sample_motion_model_odometry
from ..validation import as_array, as_int, as_positive, as_rng, describe
from .hierarchical import HierarchicalLocalizer
from .particle_filter import low_variance_resample, normalise_log_weights

__all__ = ["MonteCarloCheck", "place_hypotheses", "monte_carlo_check"]


@dataclass(frozen=True)
class MonteCarloCheck:
    """The answer of :func:`monte_carlo_check`.

    Attributes
    ----------
    pose : numpy.ndarray, shape (3,)
        The first image's pose in the map's frame: the winning place's first hypothesis (the
        localizer's own answer when that place wins).
    winner : int
        Its index in ``nodes`` / ``hypotheses``.
    confirmed : bool
        The localizer's answer (hypothesis 0) stands: its place won, or no drive image gave a
        metric fix, or no other place holds more than half of the particles.
    nodes : numpy.ndarray of int, shape (m,)
        The candidate nodes, most matches first.
    hypotheses : numpy.ndarray, shape (m, 3)
        The first image's pose as each candidate gives it.
    match_counts : numpy.ndarray of int, shape (m,)
        The first image's SIFT matches with each candidate.
    support : numpy.ndarray, shape (m,)
        Share of the final particles descended from each place, indexed by the place's first
        hypothesis (zero for hypotheses merged into an earlier one; sums to 1).
    particles : numpy.ndarray, shape (N, 3)
        The particles after the last image (the robot's pose at the end of the drive).
    """

    pose: np.ndarray
    winner: int
    confirmed: bool
    nodes: np.ndarray
    hypotheses: np.ndarray
    match_counts: np.ndarray
    support: np.ndarray
    particles: np.ndarray


def _as_localizer(localizer: Any) -> HierarchicalLocalizer:
    if not isinstance(localizer, HierarchicalLocalizer):
        raise TypeError(f"localizer: expected a robokit.localization.HierarchicalLocalizer, got {describe(localizer)}")
    return localizer


def place_hypotheses(localizer: HierarchicalLocalizer, image: Any, *, max_hypotheses: int = 3
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The places an image may have been taken at: one pose per well-matched candidate node.

    Parameters
    ----------
    localizer : HierarchicalLocalizer
    image : array_like
        An omni image of the localizer's camera size.
    max_hypotheses : int, default 3
        The candidates kept: the fine stage's best by match count, each with at least the
        localizer's ``min_matches`` (the best one always).

    Returns
    -------
    nodes, poses, counts, metric : numpy.ndarray
        Candidate nodes, the localizer's answer first, then the others by match count; the image's
        pose as each gives it (the first: the localizer's own pose; the others: the node's pose
        composed with the relative pose of :func:`robokit.mapping.relative_pose`, which is the
        node's position with the essential matrix's heading when it is not metric; a candidate
        without an essential matrix gives no hypothesis), their match counts and whether each pose
        is metric.

    Raises
    ------
    TypeError, ValueError
        For a bad localizer, image or count.

    Notes
    -----
    Li et al. (2011), Sec. "Hierarchical localization": the candidates of the coarse stage are
    matched with the query; these are the ones the Monte-Carlo step decides between.

    Examples
    --------
    >>> from robokit.sim import OmniCamera, office_floor
    >>> from robokit.mapping import build_topological_map
    >>> cam, world = OmniCamera(width=320, height=240), office_floor()
    >>> nodes = np.array([[14.0, 4.0, np.pi], [13.0, 1.0, 0.0]])
    >>> tmap = build_topological_map(np.stack([cam.observe(world, p).image for p in nodes]), nodes, cam,
    ...                              similarity=0.01, min_matches=10**6, occlusion_frames=1, n_features=300)
    >>> found, poses, counts, metric = place_hypotheses(HierarchicalLocalizer(tmap, cam, top_k=2, n_features=300),
    ...                                         cam.observe(world, [13.2, 1.0, 0.3]).image)
    >>> int(found[0]), poses.shape
    (1, (1, 3))
    """
    loc = _as_localizer(localizer)
    m = as_int(max_hypotheses, "max_hypotheses", minimum=1, maximum=100)
    view, times = loc.view(image)                     # SIFT once, for the answer and the hypotheses
    result = loc.localize_view(view, times)
    ranked = np.argsort(-result.match_counts, kind="stable")
    best = int(np.flatnonzero(result.candidates == result.node)[0])
    others = [int(c) for c in ranked if int(c) != best and result.match_counts[c] >= loc.min_matches][:m - 1]
    nodes = result.candidates[[best] + others].astype(int)
    counts, matches = loc.fine(view.features, nodes)
    poses, metric, keep = [result.pose.copy()], [result.metric], [0]   # the localizer's own answer first
    for j, (node, found) in enumerate(zip(nodes[1:], matches[1:]), start=1):
        rel = relative_pose(view, loc.map.node_view(int(node)), found, loc.camera)
        if not rel.epipolar:
            continue                                 # no heading to place the robot at this node: no hypothesis
        poses.append(se2_compose(loc.map.poses[int(node)], rel.pose))   # [0, 0, heading] unless metric
        metric.append(rel.metric)
        keep.append(j)
    return nodes[keep], np.array(poses).reshape(-1, 3), np.asarray(counts, int)[keep], np.array(metric, bool)


def monte_carlo_check(localizer: HierarchicalLocalizer, image: Any, drive_images: Any, drive_odometry: Any, *,
                      max_hypotheses: int = 3, n_particles: int = 300, spread: Any = (0.15, 0.15, 0.1),
                      alphas: Any = (0.01, 0.001, 0.01, 0.001), sigma: float = 0.3, same_place: float = 0.5,
                      rng: Any = 0) -> MonteCarloCheck:
    """Decide between the places an image may show by driving on and localizing the images that follow.

    Parameters
    ----------
    localizer : HierarchicalLocalizer
    image : array_like
        The omni image whose place is in doubt (taken at odometry pose ``drive_odometry[0]``).
    drive_images : sequence of array_like, length K >= 1
        Omni images taken as the robot drives on.
    drive_odometry : array_like, shape (K + 1, 3)
        Odometry poses at ``image`` and at each drive image.
    max_hypotheses : int, default 3
        See :func:`place_hypotheses` (for the first image and for every drive image).
    n_particles : int, default 300
        Split evenly between the first image's hypotheses.
    spread : array_like, shape (3,), default (0.15, 0.15, 0.1)
        Standard deviations (m, m, rad) of the particles around each hypothesis.
    alphas : array_like, shape (4,)
        Odometry noise of the motion model (Thrun et al. 2005, Table 5.6).
    sigma : float, default 0.3
        Metres: the spread of a drive image's place hypotheses as measurements.
    same_place : float, default 0.5
        Metres: first-image hypotheses this close count as one place.
    rng : Generator or int, default 0

    Returns
    -------
    MonteCarloCheck

    Raises
    ------
    TypeError, ValueError
        For a bad localizer, images, odometry or parameter (the error names it).

    Notes
    -----
    Li et al. (2011), Sec. "Hierarchical localization" (the Monte-Carlo verification of an
    ambiguous answer), as image-based MCL after Menegatti et al. (2004). Motion by Table 5.6 of
    Thrun et al. (2005); the measurement of a drive image is a mixture over its place hypotheses
    ``f_j`` that are metric, with their match counts ``c_j``: ``p(z | x) = eps + sum_j (c_j /
    max_j c_j) exp(-|x - f_j|^2 / (2 sigma^2))`` (positions only, ``eps = 1e-6``; an image without a
    metric hypothesis is skipped); low-variance resampling (Table 4.4) after each image. A wrong first
    hypothesis keeps support only if the drive's images keep being recognised where odometry
    carries it.

    Examples
    --------
    See lesson 02 (``robocourse.lessons.omni_localization.checks``) for drives in the office.
    """
    loc = _as_localizer(localizer)
    if isinstance(drive_images, np.ndarray) and drive_images.ndim == 4:
        drive_images = list(drive_images)            # a stack of images
    images = list(drive_images) if isinstance(drive_images, (list, tuple)) else None
    if not images:
        raise ValueError(f"drive_images: expected a non-empty list of omni images, got {describe(drive_images)}")
    odo = as_array(drive_odometry, "drive_odometry", ndim=2)
    if odo.shape != (len(images) + 1, 3):
        raise ValueError(f"drive_odometry: expected shape ({len(images) + 1}, 3), one pose for the image and one "
                         f"per drive image, got {odo.shape}")
    n = as_int(n_particles, "n_particles", minimum=2, maximum=100_000)
    sd = as_array(spread, "spread", shape=(3,))
    if np.any(sd < 0):
        raise ValueError(f"spread: expected non-negative standard deviations, got {sd.tolist()}")
    alphas = as_array(alphas, "alphas", shape=(4,))
    if np.any(alphas < 0):
        raise ValueError(f"alphas: expected non-negative noise parameters, got {alphas.tolist()}")
    sigma = as_positive(sigma, "sigma")
    same_place = as_positive(same_place, "same_place")
    g = as_rng(rng)
    images = [as_omni_image(im, loc.camera, f"drive_images[{k}]") for k, im in enumerate(images)]  # before any work
    nodes, hyps, counts, _ = place_hypotheses(loc, image, max_hypotheses=max_hypotheses)
    # hypotheses within same_place of an earlier one are that place (the localizer's answer is place 0);
    # the particles are split evenly between places, each started at its first hypothesis
    place = np.arange(len(hyps))
    for j in range(1, len(hyps)):
        near = np.flatnonzero(np.hypot(*(hyps[:j, :2] - hyps[j, :2]).T) <= same_place)
        if len(near):
            place[j] = place[near[0]]
    firsts = np.unique(place)
    labels = firsts[np.arange(n) % len(firsts)]
    particles = hyps[labels] + g.normal(0.0, 1.0, (n, 3)) * sd
    particles[:, 2] = wrap_angle(particles[:, 2])
    evidence = 0
    for k, im in enumerate(images):
        particles = sample_motion_model_odometry(odo[k], odo[k + 1], particles, alphas, g)
        _, fixes, c, metric = place_hypotheses(loc, im, max_hypotheses=max_hypotheses)
        if not metric.any():
            continue                                 # no metric fix: this image says nothing about position
        evidence += 1
        fixes, c = fixes[metric], c[metric].astype(float)
        d2 = ((particles[:, None, :2] - fixes[None, :, :2]) ** 2).sum(axis=-1)
        likelihood = 1e-6 + (c[None, :] / c.max() * np.exp(-0.5 * d2 / sigma ** 2)).sum(axis=1)
        keep = low_variance_resample(normalise_log_weights(np.log(likelihood)).weights, g)
        particles, labels = particles[keep], labels[keep]
    support = np.bincount(labels, minlength=len(hyps)) / n
    # another place wins only with evidence and a majority of the particles
    winner = int(np.argmax(support)) if evidence and support.max() > 0.5 else 0
    return MonteCarloCheck(hyps[winner].copy(), winner, winner == 0, nodes, hyps, counts, support, particles)
