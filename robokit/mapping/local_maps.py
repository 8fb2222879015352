"""Cutting a recorded sequence into local maps: when a new node (key image) starts.

Lesson 02's paper, Sec. "Partitioning for the local map": the local map ``M_i`` is closed and
``M_{i+1}`` started when the current image is no longer "similar enough" to it (we measure the
hue-histogram distance of Eq. (5) to the node's key image and, when that has changed, the SIFT
match count, :func:`appearance_changed`), unless the change is someone "blocking the camera view"
(the change must persist for a few frames, :func:`select_key_frames`), or when the local map's
features reach a maximum or its uncertainty a limit (:func:`local_map_full`).
:func:`robokit.mapping.build_topological_map` uses these criteria on omni views; here they only
see numbers, so they can be studied and tested on their own.

References
----------
.. [1] "Robust omnidirectional vision based mobile robot hierarchical localization and autonomous
   navigation" (the source paper of lesson 02; our copy gives no authors, venue or year).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..validation import as_array, as_callable, as_int, as_positive, describe

__all__ = ["Comparison", "appearance_changed", "local_map_full", "select_key_frames"]


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
