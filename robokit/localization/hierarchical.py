"""Hierarchical localization in a topological map: colour histograms first, SIFT matches second.

Lesson 02's paper, Sec. "Hierarchical localization" (Fig. 5): a *coarse* stage compares the query
image's hue histogram with every node's (Eq. (5)) and keeps the nearest few as candidates; a
*fine* stage matches the query's SIFT features against each candidate's (KD-tree, distance ratio)
and "the correct position is the one getting the largest number of matches"; "if the localization
result is still ambiguous, epipolar geometry constraints ... are employed to verify the result".
The recognised node's pose is then refined to a metric pose of the robot with the relative pose
of :func:`robokit.mapping.relative_pose` (floor points below the horizon, checked against the
essential matrix). Each stage is timed (the paper's Fig. 11 compares coarse-only, fine-only and
hierarchical localization by error and by time): :class:`HierarchicalLocalizer` runs all three.

When no candidate gives a verified metric pose, the fine stage goes on with the next ``top_k``
candidates of the coarse ranking (``max_rounds``; our reading of the paper's verification step).
The paper also names Monte-Carlo localization for the ambiguous case: that needs more than one
image, and is :func:`robokit.localization.appearance_mcl.monte_carlo_check`.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] D. G. Lowe, "Distinctive image features from scale-invariant keypoints", International Journal
   of Computer Vision 60(2), 91-110, 2004.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..geometry import se2_between, se2_compose, wrap_angle
from ..geometry.planar import intersect_lines
from ..mapping.omni_views import OmniView, RelativePose, omni_view, relative_pose
from ..mapping.topological import EmptyMapError, OMNI_RATIO, TopologicalMap
from ..sim.omni import OmniCamera, as_omni_camera
from ..validation import as_choice, as_int, as_positive, describe

__all__ = ["MODES", "TOP_K", "Localization", "HierarchicalLocalizer"]

#: Candidates the coarse stage passes on to the fine stage, in the lesson and in its assignment alike.
TOP_K = 5

#: The three ways of localizing that the paper's Fig. 11 compares.
MODES = ("coarse", "fine", "hierarchical")


@dataclass(frozen=True)
class Localization:
    """The answer of :meth:`HierarchicalLocalizer.localize`.

    Attributes
    ----------
    node : int
        The recognised node (the best candidate even when not ``recognised``).
    pose : numpy.ndarray, shape (3,)
        Estimated robot pose ``[x, y, theta]`` in the map's frame, see ``method``.
    node_pose : numpy.ndarray, shape (3,)
        The recognised node's pose.
    relative : RelativePose or None
        Query relative to the node (``None`` in coarse mode or when not recognised); always
        ``pose = se2_compose(node_pose, relative.pose)``. With ``method="bearings"`` its pose is
        the crossing seen from the node (``metric`` and ``verified`` set; ``n_floor`` as the floor
        left it).
    candidates : numpy.ndarray of int
        Nodes the fine stage looked at (coarse mode: every node), nearest histogram first.
    distances : numpy.ndarray
        Their hue-histogram distances (Eq. (5)).
    match_counts : numpy.ndarray of int
        SIFT matches per candidate (zeros in coarse mode).
    recognised : bool
        Coarse mode: always; otherwise the best candidate has at least ``min_matches`` matches.
    ambiguous : bool
        The runner-up has at least ``ambiguity`` times the best count, so epipolar verification
        decided between them.
    verified : bool
        The relative pose passed the epipolar check (:attr:`RelativePose.verified`), or the
        directions of travel from two or more nodes crossed ahead of each (``method="bearings"``).
    metric : bool
        ``method`` is ``"floor"`` or ``"bearings"``.
    mode : str
    times : dict of str to float
        Seconds per stage: ``"histogram"`` and ``"sift"`` (the query's own features),
        ``"coarse"`` (ranking every node, Eq. (5)), ``"matching"`` (SIFT against the candidates),
        ``"verification"`` (epipolar, floor, crossing) and ``"total"``.
    method : str
        How ``pose`` was found: ``"floor"`` (the node's pose composed with the floor-scaled
        relative pose), ``"bearings"`` (where the essential matrices' directions from two or more
        nodes cross, heading from the recognised node's), or ``"node"`` (the node's own pose,
        its heading corrected when the essential matrix gave one).
    rounds : int
        Batches of ``top_k`` coarse candidates the fine stage matched (hierarchical mode: more
        than 1 when the first batch gave no verified metric pose; 1 in the other modes).
    """

    node: int
    pose: np.ndarray
    node_pose: np.ndarray
    relative: RelativePose | None
    candidates: np.ndarray
    distances: np.ndarray
    match_counts: np.ndarray
    recognised: bool
    ambiguous: bool
    verified: bool
    metric: bool
    mode: str
    times: dict = field(default_factory=dict)
    method: str = "node"
    rounds: int = 1


class HierarchicalLocalizer:
    """Localize an omni image in a :class:`~robokit.mapping.TopologicalMap`, coarse to fine.

    Parameters
    ----------
    map : TopologicalMap
        With at least one node.
    camera : OmniCamera
        The camera of the map's images and of the queries (same size).
    top_k : int, default 5
        Candidates the coarse stage passes on.
    max_rounds : int or None, default None
        Hierarchical mode's coarse-to-fine check: when the best of the ``top_k`` candidates gives no
        verified metric pose (a wrong place rarely does), the fine stage goes on with the next
        ``top_k`` of the coarse ranking, and so on, for at most ``max_rounds`` batches (``None``:
        until the whole map has been matched). ``1`` is the plain top-k search.
    ratio : float, default 0.7
        SIFT distance-ratio bound of the fine stage (as the map's builder).
    min_matches : int, default 25
        Fewest matches for a recognition (unrelated office views share about 9 at ratio 0.7).
    ambiguity : float, default 0.8
        Runner-up / best match count from which the answer is ambiguous and the top candidates
        are verified epipolarly (the best verified one wins).
    n_features : int, default 500
        SIFT features per query (use the map's own setting).
    mode : {"hierarchical", "coarse", "fine"}, default "hierarchical"
        Coarse: histogram only, answer the nearest node's pose. Fine: SIFT against every node.
        Hierarchical: SIFT against the coarse stage's ``top_k``.
    min_crossing : float, default 0.26
        Radians (15 deg): the narrowest spread of directions of travel from two nodes whose
        crossing is trusted as a position, when the floor gives none.
    max_range : float, default 4.0
        Metres: farthest a crossing may lie from a node (farther, the views share too little).

    Raises
    ------
    EmptyMapError
        For a map without nodes.
    TypeError, ValueError
        For other bad arguments.

    Notes
    -----
    Sec. "Hierarchical localization" and Fig. 5 of lesson 02's paper; Fig. 11 (the three modes).

    Examples
    --------
    A two-node map of rendered views; a query 0.2 m from node 1 is recognised as node 1:

    >>> from robokit.sim import OmniCamera, office_floor
    >>> from robokit.mapping import build_topological_map
    >>> cam = OmniCamera(width=320, height=240)
    >>> nodes = np.array([[14.0, 4.0, np.pi], [13.0, 1.0, 0.0]])
    >>> tmap = build_topological_map(np.stack([cam.observe(office_floor(), p).image for p in nodes]), nodes, cam,
    ...                              similarity=0.01, min_matches=10**6, occlusion_frames=1, n_features=300)
    >>> loc = HierarchicalLocalizer(tmap, cam, top_k=2, n_features=300)
    >>> result = loc.localize(cam.observe(office_floor(), [13.2, 1.0, 0.3]).image)
    >>> result.node, result.recognised, sorted(result.times)
    (1, True, ['coarse', 'histogram', 'matching', 'sift', 'total', 'verification'])
    """

    def __init__(self, map: TopologicalMap, camera: OmniCamera, *, top_k: int = TOP_K, max_rounds: int | None = None,
                 ratio: float = OMNI_RATIO,
                 min_matches: int = 25, ambiguity: float = 0.8, n_features: int = 500,
                 mode: str = "hierarchical", min_crossing: float = 0.26, max_range: float = 4.0) -> None:
        if not isinstance(map, TopologicalMap):
            raise TypeError(f"map: expected a robokit.mapping.TopologicalMap, got {describe(map)}")
        if len(map) == 0:
            raise EmptyMapError("map: expected a map with at least one node, got none")
        self.map, self.camera = map, as_omni_camera(camera)
        self.top_k = as_int(top_k, "top_k", minimum=1)
        self.max_rounds = None if max_rounds is None else as_int(max_rounds, "max_rounds", minimum=1)
        self.ratio = as_positive(ratio, "ratio")
        if self.ratio > 1:
            raise ValueError(f"ratio: expected a value in (0, 1], got {self.ratio}")
        self.min_matches = as_int(min_matches, "min_matches", minimum=1)
        self.ambiguity = as_positive(ambiguity, "ambiguity")
        self.n_features = as_int(n_features, "n_features", minimum=0)
        self.mode = as_choice(mode, "mode", MODES)
        self.min_crossing = as_positive(min_crossing, "min_crossing")
        if self.min_crossing > np.pi / 2:
            raise ValueError(f"min_crossing: expected an angle in (0, pi/2], got {self.min_crossing}")
        self.max_range = as_positive(max_range, "max_range")
        self.bins = map.histograms.shape[1]

    def __repr__(self) -> str:
        return f"HierarchicalLocalizer({self.map!r}, mode={self.mode!r}, top_k={self.top_k})"

    def view(self, image: Any) -> tuple[OmniView, dict]:
        """The query's :class:`~robokit.mapping.OmniView` and the seconds its two parts took.

        Raises
        ------
        ImageSizeError
            For an image of another size than the camera's.
        """
        times: dict = {}
        view = omni_view(image, self.camera, bins=self.bins, n_features=self.n_features,
                         features=self.mode != "coarse", times=times)
        return view, times

    def coarse(self, histogram: Any) -> tuple[np.ndarray, np.ndarray]:
        """Every node ranked by the distance of its hue histogram to the query's (Eq. (5)).

        Returns
        -------
        order, distances : numpy.ndarray
            Node indices nearest first, and their distances.

        Notes
        -----
        Sec. "Hierarchical localization", the coarse stage (Sec. "Global image features", Eq. (5)).
        """
        return self.map.rank_by_histogram(histogram)

    def fine(self, features: Any, candidates: Any) -> tuple[np.ndarray, list]:
        """SIFT match counts of the query's features against each candidate node.

        Returns
        -------
        counts : numpy.ndarray of int
        matches : list of robokit.vision.Matches

        Notes
        -----
        Sec. "Hierarchical localization", the fine stage: "the correct position is the one getting
        the largest number of matches".
        """
        return self.map.match_counts(features.descriptors, candidates, ratio=self.ratio)

    def localize(self, image: Any) -> Localization:
        """Localize one omni image (see the class docstring for the stages).

        Raises
        ------
        ImageSizeError
            For an image of another size than the camera's.
        """
        view, times = self.view(image)
        return self.localize_view(view, times)

    def localize_view(self, view: OmniView, times: dict | None = None) -> Localization:
        """Localize a query already described (histogram and features): every stage after SIFT.

        Parameters
        ----------
        view : OmniView
            E.g. from :meth:`view` or :func:`robokit.mapping.omni_view` with this camera.
        times : dict, optional
            Stage times so far (``"histogram"``, ``"sift"``), added to the result's.
        """
        if not isinstance(view, OmniView):
            raise TypeError(f"view: expected an OmniView, got {describe(view)}")
        times = {"histogram": 0.0, "sift": 0.0, **(times or {})}
        t0 = time.perf_counter()
        if self.mode == "fine":
            order, distances = np.arange(len(self.map)), np.zeros(len(self.map))
        else:
            order, distances = self.coarse(view.histogram)
        t1 = time.perf_counter()
        times["coarse"] = t1 - t0
        if self.mode == "coarse":
            node = int(order[0])
            times.update(matching=0.0, verification=0.0)
            times["total"] = sum(times.values())
            pose = self.map.poses[node].copy()
            return Localization(node, pose, pose.copy(), None, order, distances, np.zeros(len(order), int), True,
                                False, False, False, self.mode, times, "node")
        k = len(order) if self.mode == "fine" else min(self.top_k, len(order))
        limit = len(order) if self.max_rounds is None else min(len(order), k * self.max_rounds)
        counts, matches = self.fine(view.features, order[:k])
        times["matching"], times["verification"], n, rounds = time.perf_counter() - t1, 0.0, k, 1
        poses: dict = {}                     # relative poses by node, kept across rounds (RANSAC is seeded)
        while True:
            t2 = time.perf_counter()
            best, recognised, ambiguous, relative, method, pose = self._decide(view, order[:n], counts, matches, poses)
            times["verification"] += time.perf_counter() - t2
            if method != "node" or n >= limit:
                break
            # the coarse-to-fine check: no verified metric pose among these candidates, so the next
            # top_k of the coarse ranking are matched too
            t3 = time.perf_counter()
            more, more_matches = self.fine(view.features, order[n:n + k])
            counts, matches = np.concatenate([counts, more]), list(matches) + list(more_matches)
            n, rounds = min(n + k, len(order)), rounds + 1
            times["matching"] += time.perf_counter() - t3
        order, distances = order[:n], distances[:n]
        times["total"] = sum(v for key, v in times.items() if key != "total")
        node = int(order[best])
        node_pose = self.map.poses[node].copy()
        if pose is None:
            pose = se2_compose(node_pose, relative.pose) if relative is not None else node_pose.copy()
        else:                         # the crossing, as a relative pose: pose = node_pose (+) relative.pose holds
            relative = dataclasses.replace(relative, pose=se2_between(node_pose, pose), metric=True, verified=True)
        return Localization(node, pose, node_pose, relative, order, distances, counts, recognised, ambiguous,
                            bool(relative is not None and relative.verified), method != "node", self.mode, times,
                            method, rounds)

    def _relative(self, view: OmniView, node: int, matches: Any, poses: dict) -> RelativePose:
        """The query's relative pose to ``node`` (:func:`robokit.mapping.relative_pose`), computed once."""
        if node not in poses:
            poses[node] = relative_pose(view, self.map.node_view(node), matches, self.camera)
        return poses[node]

    def _decide(self, view: OmniView, order: np.ndarray, counts: np.ndarray, matches: list, poses: dict) -> tuple:
        """The fine stage's answer among the candidates ``order`` with their match ``counts``.

        Returns ``(best, recognised, ambiguous, relative, method, pose)``: the winning candidate's
        index, whether it has ``min_matches``, whether the runner-up comes close, its relative pose
        (None when not recognised), how the pose is found and the pose when it is a crossing.
        """
        ranked = np.argsort(-counts, kind="stable")
        best = int(ranked[0])
        recognised = bool(counts[best] >= self.min_matches)
        ambiguous = bool(recognised and len(ranked) > 1 and counts[ranked[1]] >= self.ambiguity * counts[best])
        relative, method, pose = None, "node", None
        if recognised:
            relative, best, tried = self._verify(view, order, counts, matches, ranked, ambiguous, poses)
            if relative.metric:
                method = "floor"
            elif relative.epipolar:
                crossing = self._crossing(view, order, counts, matches, ranked, tried, poses)
                if crossing is not None:
                    heading = self.map.poses[int(order[best]), 2] + relative.heading_epipolar
                    pose, method = np.array([crossing[0], crossing[1], wrap_angle(heading)]), "bearings"
        return best, recognised, ambiguous, relative, method, pose

    def _verify(self, view: OmniView, order: np.ndarray, counts: np.ndarray, matches: list, ranked: np.ndarray,
                ambiguous: bool, poses: dict) -> tuple[RelativePose, int, list]:
        """Relative pose to the best candidate, or to a runner-up when that one verifies and the best does not.

        The contenders are the best candidate and, when the answer is ambiguous or the best one
        gives no verified metric pose, the next ones (up to three in all) with at least
        ``min_matches``; a verified metric pose beats a verified one beats none, then more matches.
        Returns the winner, its candidate index and every ``(relative pose, candidate)`` tried.
        """
        tried = []
        for rank, c in enumerate(ranked[:3]):
            c = int(c)
            if rank and not (counts[c] >= self.min_matches and (ambiguous or not (tried[0][0].verified
                                                                                    and tried[0][0].metric))):
                break
            rel = self._relative(view, int(order[c]), matches[c], poses)
            tried.append((rel, c))
        rel, c = max(tried, key=lambda rc: (rc[0].verified and rc[0].metric, rc[0].verified, counts[rc[1]]))
        return rel, c, tried

    def _crossing(self, view: OmniView, order: np.ndarray, counts: np.ndarray, matches: list, ranked: np.ndarray,
                  tried: list, poses: dict) -> np.ndarray | None:
        """Where the directions of travel from two or more candidate nodes cross (world x, y), or None.

        Each candidate whose essential matrix holds puts the query on a ray from the node's pose;
        the rays of up to three candidates (with ``min_matches``) are intersected
        (:func:`robokit.geometry.planar.intersect_lines`). The crossing counts when the rays spread by at
        least ``min_crossing`` and it lies ahead on each, within ``max_range``.
        """
        done = {c for _, c in tried}
        rays = [(rel, c) for rel, c in tried if rel.epipolar]
        for c in ranked[:3]:
            c = int(c)
            if c not in done and counts[c] >= self.min_matches:
                rel = self._relative(view, int(order[c]), matches[c], poses)
                if rel.epipolar:
                    rays.append((rel, c))
        if len(rays) < 2:
            return None
        poses = self.map.poses[[int(order[c]) for _, c in rays]]
        cos, sin = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        d = np.array([rel.direction for rel, _ in rays])
        world = np.column_stack([cos * d[:, 0] - sin * d[:, 1], sin * d[:, 0] + cos * d[:, 1]])
        cross = world[:, None, 0] * world[None, :, 1] - world[:, None, 1] * world[None, :, 0]
        spread = np.abs(cross).max()                                                    # sin of the widest angle
        if spread < np.sin(self.min_crossing):
            return None
        point, along = intersect_lines(poses[:, :2], world)
        if np.any(along <= 0) or np.any(along > self.max_range):
            return None
        return point
