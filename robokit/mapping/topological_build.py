"""Building the topological map offline from a recorded omnidirectional run, and where its nodes start.

Lesson 02's paper, Sec. "Environment map": the robot is led through the environment recording
images and odometry "at a constant rate"; the sequence is then cut into local maps. A local map
``M_i`` is closed and ``M_{i+1}`` started when

1. the current image is no longer "similar enough" to the local map's images (we measure it by
   the hue-histogram distance of Eq. (5) to the node's key image,
   :func:`appearance_changed`),
2. and the change is not just "someone ... blocking the camera view": we also ask the SIFT match
   count with the key image to fall, and the change to persist for ``occlusion_frames``
   consecutive frames (the *occlusion guard*,
   :func:`select_key_frames`); a transient change that reverts sooner
   starts no node. SIFT runs only on frames whose histogram has changed: the cheap global feature
   first, the costly local ones when it asks for them, as in the localizer;
3. or the local map's number of features reaches a maximum, or its uncertainty a limit
   (:func:`local_map_full`; the uncertainty is the odometry
   covariance accumulated since the key image, :func:`robokit.sim.odometry_covariance`).

The new node's base is "the current robot position", joined to the previous node by an odometry
edge. Loop closure (Sec. "Loop closure alignment": "when a node is added or recognized in the
map, a new edge is created") asks each key image the hierarchical question against the older,
non-neighbouring nodes (hue histograms, then SIFT match counts), verifies the best candidate
epipolarly and metrically (:func:`robokit.mapping.relative_pose`) and gates it with odometry
(the visual relative pose must lie within the odometry's accumulated uncertainty of the
odometric one); a recognition that passes adds a loop edge measured by the visual relative pose.

The criteria (Sec. "Partitioning for the local map") are functions of their own,
:func:`appearance_changed`, :func:`select_key_frames` and :func:`local_map_full`: they see only
numbers, so they can be studied and tested apart from the omni views.

References
----------
.. [1] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Iterator

import numpy as np

from ..sim.motion import odometry_covariance
from ..sim.omni import OmniCamera, as_omni_camera
from ..sim.runs import FrameStream
from ..vision.colour import histogram_distance
from ..vision.matching import DescriptorIndex, METHODS
from ..geometry import se2_between, wrap_angle
from ..progress import progress_bar
from ..geometry.planar import as_planar
from ..validation import as_array, as_callable, as_choice, as_int, as_positive, describe
from .omni_views import as_omni_image, omni_view, relative_pose
from .pose_graph import position_variance
from .topological import EmptyMapError, LOOP_EDGE, ODOMETRY_EDGE, OMNI_RATIO, TopologicalMap

__all__ = ["build_topological_map", "Comparison", "appearance_changed", "local_map_full", "select_key_frames"]


@dataclass(frozen=True)
class Comparison:
    """How frame ``k`` compares with the current key image (what the criteria look at).

    Attributes
    ----------
    distance : float
        Hue-histogram distance, Eq. (5).
    matches : int or None
        SIFT matches with the key image (``None``: not computed, the histogram being similar).
    n_features : int or None
        Features the local map would hold: the key image's plus the frame's unmatched ones
        (``None`` with ``matches``).
    variance : float
        Mean position variance (m^2) of the odometry since the key image.
    """

    distance: float
    matches: int | None
    n_features: int | None
    variance: float


def appearance_changed(distance: Any, matches: Any, *, similarity: float = 0.1, min_matches: int = 80) -> Any:
    """Whether a frame no longer looks like the key image: histogram far AND few SIFT matches.

    Parameters
    ----------
    distance : float or array_like
        Hue-histogram distance to the key image (Eq. (5)).
    matches : int or array_like
        SIFT matches with the key image.
    similarity : float, default 0.1
        Distance above which the images are not "similar enough". On the office tour images less
        than 0.5 m apart are at median 0.03 (95 % below 0.12), images 1-2 m apart at 0.24 (5 %
        below 0.09).
    min_matches : int, default 80
        Match count below which the place has changed (ratio 0.7, 500 features: office views less
        than 1 m apart share about 120, 1-2 m apart 46, unrelated ones 9): nodes about 1-2 m
        apart, close enough for the floor to give a metric pose between them.

    Returns
    -------
    bool or numpy.ndarray of bool

    Notes
    -----
    Sec. "Partitioning for the local map": the first condition (similar enough) and the second,
    "necessary, as the first condition can be satisfied even when someone is blocking the camera
    view" (our reading: a person in view changes the colours, but most of the place's features
    still match).

    Examples
    --------
    >>> appearance_changed([0.05, 0.3, 0.3], [20, 80, 20]).tolist()
    [False, False, True]
    """
    d, m = _paired(distance, "distance", matches, "matches")
    s = as_positive(similarity, "similarity")
    mm = as_int(min_matches, "min_matches", minimum=0)
    out = (d > s) & (m < mm)
    return bool(out) if out.ndim == 0 else out


def _paired(a: Any, a_name: str, b: Any, b_name: str) -> tuple[np.ndarray, np.ndarray]:
    """Two non-negative scalars or 1-D arrays of one length (a scalar pairs with any length)."""
    x, y = as_array(a, a_name), as_array(b, b_name)
    for arr, name in ((x, a_name), (y, b_name)):
        if arr.ndim > 1:
            raise ValueError(f"{name}: expected a number or a 1-D array, got shape {arr.shape}")
        if np.any(arr < 0):
            raise ValueError(f"{name}: expected non-negative values, got {arr.min()}")
    if x.ndim and y.ndim and x.shape != y.shape:
        raise ValueError(f"{b_name}: expected the shape of {a_name} {x.shape}, got {y.shape}")
    return x, y


def local_map_full(n_features: Any, variance: Any, *, max_features: int = 930, max_variance: float = 0.1) -> Any:
    """Whether the local map has reached its feature count or its uncertainty limit.

    Parameters
    ----------
    n_features : int or array_like
        Features the local map holds.
    variance : float or array_like
        Its accumulated odometry position variance (m^2).
    max_features : int, default 930
        With 500 features per image (about 470 found) this binds only when the current image
        shares few matches with the key image while its colours have hardly changed: a backstop
        the appearance test (which needs both to change) would miss. The builder counts only frames
        whose SIFT features it computed (frames with an unchanged histogram skip SIFT).
    max_variance : float, default 0.1
        m^2 (about 0.3 m standard deviation along each axis).

    Returns
    -------
    bool or numpy.ndarray of bool

    Notes
    -----
    Sec. "Partitioning for the local map": "the number of features in the current local map
    reaches a maximum, or the uncertainty of the current map reaches a limit".

    Examples
    --------
    >>> local_map_full([100, 2500, 100], [0.001, 0.001, 0.5]).tolist()
    [False, True, True]
    """
    n, v = _paired(n_features, "n_features", variance, "variance")
    mf = as_int(max_features, "max_features", minimum=1)
    mv = as_positive(max_variance, "max_variance")
    out = (n >= mf) | (v >= mv)
    return bool(out) if out.ndim == 0 else out


def select_key_frames(n_frames: int, compare: Callable[[int, int], Comparison], *, similarity: float = 0.1,
                      min_matches: int = 80, occlusion_frames: int = 3, max_features: int = 930,
                      max_variance: float = 0.1) -> tuple[list[int], list[str]]:
    """Cut a sequence of frames into local maps: the key frames and why each was started.

    Parameters
    ----------
    n_frames : int
        Frames in the sequence (>= 1).
    compare : callable ``(key, k) -> Comparison``
        Compares frame ``k`` with the current key frame ``key``.
    similarity, min_matches : see :func:`appearance_changed`.
    occlusion_frames : int, default 3
        A change of appearance must hold for this many consecutive frames to start a node (1: at
        once); a shorter one (someone walking past the camera) is ignored.
    max_features, max_variance : see :func:`local_map_full` (they act at once; a frame whose
        appearance has changed adds no features, so a transient blocker cannot fill the local map).

    Returns
    -------
    keys : list of int
        Key frames, starting with 0.
    reasons : list of str
        ``"start"``, ``"appearance"``, ``"features"`` or ``"variance"`` per key.

    Notes
    -----
    Sec. "Partitioning for the local map". A node starts at the frame that confirms the change
    (``occlusion_frames - 1`` frames after it began).

    Examples
    --------
    A person blocks the camera for two frames (4, 5); the place changes for good at frame 8:

    >>> far = {4, 5} | set(range(8, 12))
    >>> compare = lambda key, k: Comparison(0.5 if (k in far) != (key in far) else 0.0,
    ...                                     10 if (k in far) != (key in far) else 90, 300, 0.0)
    >>> select_key_frames(12, compare, occlusion_frames=3)
    ([0, 10], ['start', 'appearance'])
    """
    n = as_int(n_frames, "n_frames", minimum=1)
    compare = as_callable(compare, "compare", optional=False)
    occlusion_frames = as_int(occlusion_frames, "occlusion_frames", minimum=1)
    appearance_changed(0.0, 0, similarity=similarity, min_matches=min_matches)      # validate once
    local_map_full(0, 0.0, max_features=max_features, max_variance=max_variance)
    keys, reasons, key, run = [0], ["start"], 0, 0
    for k in range(1, n):
        c = compare(key, k)
        if not isinstance(c, Comparison):
            raise TypeError(f"compare: expected a callable returning a Comparison, got {describe(c)}")
        changed = c.matches is not None and appearance_changed(c.distance, c.matches, similarity=similarity,
                                                               min_matches=min_matches)
        run = run + 1 if changed else 0
        # a frame that no longer looks like the local map (perhaps someone blocking the camera) adds
        # none of its features to it: the occlusion guard, not the feature count, decides on it
        reason, n_local = None, 0 if c.n_features is None or changed else c.n_features
        if local_map_full(n_local, c.variance, max_features=max_features, max_variance=max_variance):
            reason = "features" if n_local >= max_features else "variance"
        elif run >= occlusion_frames:
            reason = "appearance"
        if reason is not None:
            keys.append(k)
            reasons.append(reason)
            key, run = k, 0
    return keys, reasons


#: chi-square bound of 3 degrees of freedom at 99.9 %: the odometry gate of a loop closure.
GATE_3DOF = 16.27
_COVARIANCE_FLOOR = np.diag([1e-6, 1e-6, 1e-8])   # a robot that stood still still has a proper edge


def build_topological_map(images: Any, odometry: Any, camera: OmniCamera, *, similarity: float = 0.1,
                          min_matches: int = 80, occlusion_frames: int = 3, max_features: int = 930,
                          max_variance: float = 0.1, odometry_alphas: Any = (0.01, 0.001, 0.01, 0.001),
                          bins: int = 32, n_features: int = 500, ratio: float = OMNI_RATIO, loop_closure: bool = True,
                          loop_top_k: int = 5, loop_min_matches: int = 25, loop_exclude: int = 5,
                          sigma_visual: Any = (0.05, 0.05, 0.02), index: str = "opencv",
                          progress: Callable | None = None, log: Callable | None = None) -> TopologicalMap:
    """Build a topological map from recorded omni images and odometry (key images, edges, loops).

    Parameters
    ----------
    images : array_like, shape (N, H, W, 3), or iterator of N images
        The run's omni images: ``run.images["omni"]`` of :func:`robokit.sim.record`, or
        ``stream.frames`` of :func:`robokit.sim.record_stream`, whose images are used as they are
        rendered (the map is built while the workers render the next ones) and let go once their
        frame is compared. Every other argument is checked before the first image is taken.
    odometry : array_like, shape (N, 3)
        Odometry poses ``[x, y, theta]`` of the same frames (they become the nodes' poses).
    camera : OmniCamera
        The camera that took the images.
    similarity, min_matches, occlusion_frames, max_features, max_variance
        Key-image criteria, see :func:`select_key_frames`.
    odometry_alphas : array_like, shape (4,)
        Odometry noise the builder assumes (Thrun et al. 2005, Table 5.6), for the edges'
        covariances and the loop-closure gate.
    bins, n_features : int
        Hue-histogram bins and SIFT features per image (see :func:`robokit.mapping.omni_view`).
    ratio : float, default 0.7
        SIFT distance-ratio bound (0.7 rather than Lowe's 0.8: unrelated omni views of the office
        share about 9 matches at 0.7 and 27 at 0.8, views 1-2 m apart 46 and 62).
    loop_closure : bool, default True
        Look for places recognised again.
    loop_top_k : int, default 5
        Candidates the histogram stage passes to the SIFT stage.
    loop_min_matches : int, default 25
        Least SIFT matches for a recognition (then verified epipolarly and gated by odometry).
    loop_exclude : int, default 5
        The last this many nodes before a key image are its neighbours, not loop candidates.
    sigma_visual : array_like, shape (3,)
        Standard deviations assumed for a visual relative pose (m, m, rad).
    index : {"opencv", "kdtree", "bruteforce", "flann"}, default "opencv"
        The nodes' descriptor search (see :class:`~robokit.mapping.TopologicalMap`).
    progress : callable ``(done, total)``, optional
    log : callable ``(line)``, optional
        Told about every node and loop closure.

    Returns
    -------
    TopologicalMap
        Nodes at the key frames' odometry poses (the odometry's frame: the first pose of the run),
        odometry edges between consecutive nodes, loop edges for places recognised again.

    Raises
    ------
    EmptyMapError
        For a run without frames.
    ImageSizeError
        For images of another size than the camera's.
    ValueError, TypeError
        For other bad arguments (lengths that differ, NaN poses, ...).

    Notes
    -----
    Sec. "Environment map" (see the module docstring). Node variances follow Eq. (1)'s
    ``omega_i = omega_{i-1} + omega_{i-1,i}`` from ``omega_0 = 0``; relax the map with
    :func:`robokit.mapping.relax` (Eqs. (1)-(3)) on :meth:`TopologicalMap.graph` and take the poses
    back with :meth:`TopologicalMap.with_poses`.

    Examples
    --------
    >>> from robokit.sim import OmniCamera, office_floor
    >>> cam = OmniCamera(width=160, height=120)
    >>> poses = np.array([[14.0, 4.0, np.pi], [13.8, 4.0, np.pi], [13.6, 4.0, np.pi]])
    >>> images = np.stack([cam.observe(office_floor(), p).image for p in poses])
    >>> tmap = build_topological_map(images, poses, cam, n_features=100)
    >>> len(tmap), tmap.n_edges, tmap.frames.tolist()
    (1, 0, [0])
    """
    raw, odo = _images_and_odometry(images, odometry, camera)
    n = len(odo)
    sigma = as_array(sigma_visual, "sigma_visual", shape=(3,))
    if np.any(sigma <= 0):
        raise ValueError(f"sigma_visual: expected three positive standard deviations, got {sigma.tolist()}")
    alphas = as_array(odometry_alphas, "odometry_alphas", shape=(4,))
    index = as_choice(index, "index", METHODS)
    progress = as_callable(progress, "progress")
    log = as_callable(log, "log")
    ratio = as_positive(ratio, "ratio")
    bins = as_int(bins, "bins", minimum=1)
    n_features = as_int(n_features, "n_features", minimum=0)
    loop = {"top_k": as_int(loop_top_k, "loop_top_k", minimum=1),
            "min_matches": as_int(loop_min_matches, "loop_min_matches", minimum=8),
            "exclude": as_int(loop_exclude, "loop_exclude", minimum=1)}
    if raw is None:       # every argument checked (the key-image criteria by select_key_frames): start taking images
        raw = _Arrivals(images, n, camera)
    views = _Views(raw, camera, bins=bins, n_features=n_features)
    with progress_bar(n, "building the map", unit="frame", callback=progress) as bar:
        compare = _Comparisons(views, odo, alphas, similarity=similarity, ratio=ratio, bar=bar)
        keys, reasons = select_key_frames(n, compare, similarity=similarity, min_matches=min_matches,
                                          occlusion_frames=occlusion_frames, max_features=max_features,
                                          max_variance=max_variance)
    key_views = [views(k) for k in keys]
    if isinstance(raw, _Arrivals):
        raw.require_ended()
    tmap = _odometry_map(keys, key_views, odo, alphas, index)
    if log is not None:
        for i, (k, r) in enumerate(zip(keys, reasons)):
            log(f"node {i}: frame {k} ({r}), {len(key_views[i])} features")
    extra = _loop_closures(tmap, key_views, odo, alphas, camera, sigma, ratio=ratio, log=log, **loop) if loop_closure else []
    if not extra:
        return tmap
    e, meas, cov = (np.array(x) for x in zip(*extra))
    return tmap.with_edges(np.vstack([tmap.edges, e]), np.vstack([tmap.measurements, meas]),
                           np.concatenate([tmap.covariances, cov]),
                           np.concatenate([tmap.kinds, np.full(len(e), LOOP_EDGE)]))


def _images_and_odometry(images: Any, odometry: Any, camera: OmniCamera) -> tuple[np.ndarray | None, np.ndarray]:
    """The images as an array (``None`` for an iterator, whose images are checked as they come) and the
    odometry, checked against each other and the camera."""
    if isinstance(images, FrameStream):
        raise TypeError("images: expected an array of images or an iterator of them (a FrameStream's .frames), "
                        "got the FrameStream itself")
    if isinstance(images, Iterator):      # taken as they arrive (e.g. rendered by workers)
        as_omni_camera(camera)
        odo = as_planar(odometry, "odometry", shape=(None, 3))
        if len(odo) == 0:
            raise EmptyMapError("odometry: expected at least one pose to build a map from, got none")
        return None, odo
    raw = as_array(images, "images", dtype=None)
    if raw.ndim != 4 or len(raw) == 0:
        if raw.ndim == 4 or raw.size == 0:
            raise EmptyMapError(f"images: expected at least one image to build a map from, got shape {raw.shape}")
        raise ValueError(f"images: expected shape (N, H, W, 3), got shape {raw.shape}")
    as_omni_image(raw[0], camera, "images[0]")
    return raw, as_planar(odometry, "odometry", shape=(len(raw), 3))


class _Views:
    """The frames' omni views, each computed once and kept while the builder may need it again.

    ``views(k)`` is frame ``k``'s view with SIFT; ``views(k, features=False)`` its hue histogram
    alone (the first stage of every comparison), completed with SIFT, histogram kept, if a later
    comparison needs it. Only the key frames and the frame being compared are kept.
    """

    def __init__(self, images: Any, camera: OmniCamera, *, bins: int, n_features: int):
        self.images, self.camera = images, camera       # an array, or _Arrivals
        self.bins, self.n_features = bins, n_features
        self._cache: dict[int, Any] = {}      # frame -> OmniView
        self._has_sift: dict[int, bool] = {}
        self.keys: set[int] = set()

    def __call__(self, k: int, features: bool = True):
        if k not in self._cache or (features and not self._has_sift[k]):
            known = self._cache[k].histogram if k in self._cache else None      # adding SIFT keeps the histogram
            self._cache[k] = omni_view(self.images[k], self.camera, bins=self.bins, n_features=self.n_features,
                                       features=features, histogram=known)
            self._has_sift[k] = features
        return self._cache[k]

    def keep_only(self, k: int) -> None:
        """Let go of every view but the key frames' and frame ``k``'s (and of the images before ``k``)."""
        for f in [f for f in self._cache if f not in self.keys and f != k]:
            del self._cache[f], self._has_sift[f]
        if isinstance(self.images, _Arrivals):      # the key's features are known: no image before k is asked for again
            self.images.release(before=k)


class _Comparisons:
    """``compare(key, k)`` for :func:`select_key_frames`: the hue histograms' distance (Eq. (5)) first,
    SIFT matches against the key frame only when that is not similar enough, and the odometry's
    position variance since the key frame."""

    def __init__(self, views: _Views, odo: np.ndarray, alphas: np.ndarray, *, similarity: float, ratio: float,
                 bar: Callable):
        self.views, self.odo, self.alphas, self.bar = views, odo, alphas, bar
        self.similarity, self.ratio = similarity, ratio
        self.key: int | None = None
        self.index: DescriptorIndex | None = None        # the key frame's descriptors

    def __call__(self, key: int, k: int) -> Comparison:
        views = self.views
        if self.key != key:
            views.keys.add(key)
            features = views(key).features
            self.key = key
            self.index = DescriptorIndex(features.descriptors) if len(features) >= 2 else None
        views.keep_only(k)
        self.bar(k + 1, len(self.odo))
        var = float(position_variance(odometry_covariance(self.odo[key:k + 1], self.alphas)[-1]))
        d = float(histogram_distance(views(k, features=False).histogram, views(key).histogram))   # Eq. (5)
        if d <= self.similarity:      # similar enough: the global feature answers, SIFT is not needed
            return Comparison(d, None, None, var)
        v = views(k)
        m = len(self.index.match(v.features.descriptors, ratio=self.ratio)) if self.index and len(v) else 0
        return Comparison(d, m, len(views(key)) + len(v) - m, var)


def _odometry_map(keys: list, views: list, odo: np.ndarray, alphas: np.ndarray, index: str) -> TopologicalMap:
    """The map of the key frames joined by odometry edges (Eq. (1)'s variances accumulated along them)."""
    edge_cov = [odometry_covariance(odo[a:b + 1], alphas)[-1] + _COVARIANCE_FLOOR for a, b in zip(keys[:-1], keys[1:])]
    variances = np.concatenate([[0.0], np.cumsum(position_variance(np.reshape(edge_cov, (-1, 3, 3))))])
    counts = np.array([len(v) for v in views])
    return TopologicalMap(
        poses=odo[keys], variances=variances, histograms=np.stack([v.histogram for v in views]),
        frames=np.array(keys), keypoints=_stack([np.column_stack([v.features.keypoints.xy, v.features.keypoints.scale,
                                                                  v.features.keypoints.orientation])
                                                 for v in views], 4),
        bearings=_stack([v.bearings for v in views], 3),
        descriptors=_stack([v.features.descriptors for v in views], 128),
        offsets=np.concatenate([[0], np.cumsum(counts)]),
        edges=np.array([[i, i + 1] for i in range(len(keys) - 1)]).reshape(-1, 2),
        measurements=se2_between(odo[keys[:-1]], odo[keys[1:]]).reshape(-1, 3),
        covariances=np.array(edge_cov).reshape(-1, 3, 3), kinds=np.full(len(keys) - 1, ODOMETRY_EDGE), index=index)


_END = object()     # what an exhausted iterator gives


class _Arrivals:
    """The images of an iterator as a sequence: each taken (and checked) when first asked for, and
    kept until :meth:`release` lets it go (the builder needs only the current frame and the next)."""

    def __init__(self, images: Iterator, n: int, camera: OmniCamera):
        self._images, self._n, self._camera = images, n, camera
        self._kept: dict[int, np.ndarray] = {}
        self._taken = 0

    def __getitem__(self, k: int) -> np.ndarray:
        while self._taken <= k:
            image = next(self._images, _END)
            if image is _END:
                raise ValueError(f"images: expected {self._n} images (one per odometry pose), the iterator "
                                 f"ended after {self._taken}")
            self._kept[self._taken] = as_omni_image(image, self._camera, f"images[{self._taken}]")
            self._taken += 1
        if k not in self._kept:
            raise RuntimeError(f"images[{k}] was asked for after it was released (a bug of the builder)")
        return self._kept[k]

    def release(self, *, before: int) -> None:
        for k in [k for k in self._kept if k < before]:
            del self._kept[k]

    def require_ended(self) -> None:
        """Every image was taken: the iterator must have no more."""
        if next(self._images, _END) is not _END:
            raise ValueError(f"images: expected {self._n} images (one per odometry pose), the iterator has more")


def _stack(arrays: list, width: int) -> np.ndarray:
    return np.concatenate([np.asarray(a, float).reshape(-1, width) for a in arrays]) if arrays else np.zeros((0, width))


def _loop_closures(tmap, views, odo, alphas, camera, sigma, *, ratio, top_k, min_matches, exclude, log):
    """Loop edges ``(j, i, measurement, covariance)`` for key images ``i`` recognised as older nodes ``j``."""
    out = []
    visual = np.diag(sigma ** 2)
    for i in range(exclude + 1, len(tmap)):
        order, _ = tmap.rank_by_histogram(tmap.histograms[i], exclude=np.arange(i - exclude, len(tmap)))
        candidates = order[:top_k]                                                # coarse stage
        counts, matches = tmap.match_counts(views[i].features.descriptors, candidates, ratio=ratio)   # fine stage
        best = int(np.argmax(counts))
        if counts[best] < min_matches:
            continue
        j = int(candidates[best])
        rel = relative_pose(views[i], tmap.node_view(j), matches[best], camera)
        if not rel.verified:
            continue
        fi, fj = int(tmap.frames[i]), int(tmap.frames[j])
        predicted = se2_between(odo[fj], odo[fi])
        innovation = rel.pose - predicted
        innovation[2] = wrap_angle(innovation[2])
        gate_cov = odometry_covariance(odo[fj:fi + 1], alphas)[-1] + visual
        d2 = float(innovation @ np.linalg.solve(gate_cov, innovation))
        if d2 > GATE_3DOF:
            if log is not None:
                log(f"loop {j} -> {i} rejected by the odometry gate (d2 = {d2:.1f})")
            continue
        out.append(([j, i], rel.pose, visual))
        if log is not None:
            log(f"loop closure: node {i} (frame {fi}) is node {j} (frame {fj}) again: {counts[best]} matches, "
                f"{rel.n_floor} floor points, d2 = {d2:.1f}")
    return out
