"""Keyframe selection from ORB features: Ge et al. (2023)'s four conditions and an ORB-SLAM-like rule.

Ge et al. (2023), Sec. 3.2: the first image is a keyframe; a later one is a keyframe when

1. its ORB feature count exceeds ``F_min`` (Eq. (15), from a calibration run: :func:`feature_threshold`;
   we test "at least", see :class:`KeyframeSelector`);
2. more than 10 frames have passed since the last keyframe;
3. it shares fewer than 90 % but more than 70 % matched points with the last keyframe;
4. the robot has moved (about) 0.02 m since the last keyframe.

Condition (3)'s "shared matched points" is :func:`shared_fraction`: the fraction of the last
keyframe's features that find a match in the current frame (mutual nearest neighbours by Hamming
distance within ORB-SLAM's 50 bits, :func:`.hamming.hamming_match`). The denominator is the
keyframe's feature count, as in ORB-SLAM's "tracks less than 90 % points than K_ref": it asks how
much of the stored keyframe is still seen, and does not change while the current frame's own count
varies. The paper does not say how it matches. A second reading follows ORB-SLAM, the system the
paper compares its rule with (Table 1): :func:`tracked_matches` finds a keyframe's features the way
ORB-SLAM tracks points from frame to frame (a search window around each feature, the nearest
neighbour there within 100 bits, an orientation check), and the share is taken over the keyframe's
*matched points* (:func:`matched_points`), its features that another view also saw: tracked into it
from the frame before it. ORB-SLAM likewise counts only a reference keyframe's points that other
keyframes (at least three) observe. Matching mode ``"tracked"`` of :class:`KeyframeSelector` shares
those: :func:`tracked_fraction` with ``points``.

Taken literally, condition (3) also means that a frame sharing 70 % or less is never a
keyframe: if the robot jumps too far between frames, selection stops until it sees the last
keyframe's scene again (``below_band="skip"``); ``below_band="take"`` takes such a frame when the
other conditions hold (:class:`KeyframeSelector` records each frame's conditions).

The ORB-SLAM rule beside it (Mur-Artal, Montiel & Tardos 2015, Sec. V-E, conditions 2-4; the
relocalisation and local-mapping-idle parts do not apply here): more than 20 frames since the last
keyframe insertion, the current frame tracks at least 50 points, and it tracks fewer than 90 % of
the reference keyframe's points. "Tracked points" are approximated by matches with the reference
keyframe, mutual or tracked as above (ORB-SLAM tracks map points; we have no map).

Positions are planar robot positions ``(N, 2)`` or poses ``[x, y, theta]`` ``(N, 3)`` in metres;
condition (4) uses the Euclidean distance between positions (the heading is ignored).

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang (Ge et al.), "Visual-feature-assisted
   mobile robot localization in a long corridor environment", Frontiers of Information Technology
   & Electronic Engineering 24(6), 2023, doi:10.1631/FITEE.2200208.
.. [2] R. Mur-Artal, J. M. M. Montiel and J. D. Tardos, "ORB-SLAM: a versatile and accurate monocular
   SLAM system", IEEE Transactions on Robotics 31(5), 1147-1163, 2015.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..validation import as_array, as_choice, as_finite_scalar, as_int, describe
from .features import Features
from .hamming import ORB_MATCH_DISTANCE, as_binary_descriptors, hamming_distance, hamming_match, same_width
from .orb import ORB_SCALE_FACTOR

__all__ = ["KeyframeConditions", "KeyframeSelector", "feature_threshold", "shared_fraction", "tracked_matches",
           "matched_points", "tracked_fraction",
           "select_keyframes", "select_keyframes_orbslam", "TRACK_WINDOW", "TRACK_DISTANCE"]

#: ORB-SLAM's search window when it tracks a monocular frame with its motion model: 15 pixels each way
#: at pyramid level 0, times the level's scale (``Tracking::TrackWithMotionModel``, ``th = 15``).
TRACK_WINDOW = 15.0
#: ORB-SLAM's ``TH_HIGH``: the largest Hamming distance of a match found in a search window.
TRACK_DISTANCE = 100
#: ORB-SLAM's rotation-consistency histogram (``HISTO_LENGTH``): 30 bins over 360 degrees.
ROTATION_BINS = 30


def feature_threshold(counts) -> float:
    """``F_min`` of Ge et al. (2023), Eq. (15): ``max(0.5 * mean count, smallest count)``.

    Parameters
    ----------
    counts : array_like, shape (N,)
        ORB feature count of every image of a calibration run (the paper records 10 m of
        corridor), non-negative, N >= 1.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        For an empty, negative or non-finite ``counts``.

    Examples
    --------
    >>> feature_threshold([400, 420, 380, 100])       # half the mean, 162.5, beats the smallest
    162.5
    >>> feature_threshold([300, 310])
    300.0
    """
    c = as_array(counts, "counts", ndim=1, min_size=1)
    if np.any(c < 0):
        raise ValueError(f"counts: expected non-negative feature counts, got {c.min()}")
    return float(max(0.5 * c.mean(), c.min()))                  # Eq. (15)


def _bits(max_distance) -> float:
    """The checked Hamming bound ``max_distance`` (a positive number of bits)."""
    bits = as_finite_scalar(max_distance, "max_distance")
    if bits <= 0:
        raise ValueError(f"max_distance: expected a positive number of bits, got {bits}")
    return bits


def _match_count(current: np.ndarray, keyframe: np.ndarray, max_distance: float) -> int:
    m = hamming_match(current, keyframe, ratio=1.0, max_distance=max_distance, cross_check=True)
    return len(m)


def shared_fraction(desc_current, desc_keyframe, *, max_distance: float = ORB_MATCH_DISTANCE) -> float:
    """Fraction of a keyframe's features matched in the current frame (Ge et al. (2023), Sec. 3.2, condition (3)).

    Parameters
    ----------
    desc_current, desc_keyframe : array_like of uint8, shape (N, 32) and (M, 32)
        ORB descriptors of the current frame and of the last keyframe.
    max_distance : float, default 50
        Largest Hamming distance of a match (ORB-SLAM's ``TH_LOW``).

    Returns
    -------
    float
        ``(mutual nearest neighbours within max_distance) / M``, in [0, 1]; 0 when either frame
        has no features.

    Examples
    --------
    >>> kf = np.array([[0] * 32, [255] * 32, [15] * 32, [240] * 32], np.uint8)
    >>> shared_fraction(kf[:3], kf)                      # 3 of the keyframe's 4 features seen
    0.75
    """
    cur = as_binary_descriptors(desc_current, "desc_current")
    key = as_binary_descriptors(desc_keyframe, "desc_keyframe")
    max_distance = _bits(max_distance)
    same_width(cur, key, "desc_current", "desc_keyframe")
    if len(key) == 0 or len(cur) == 0:
        return 0.0
    return _match_count(cur, key, max_distance) / len(key)    # denominator: the keyframe's features


def _orb_features(value, name: str = "features") -> Features:
    """Check that ``value`` is a :class:`.features.Features` with binary (ORB) descriptors; return it."""
    if not isinstance(value, Features):
        raise TypeError(f"{name}: expected Features (detect_orb_features), got {describe(value)}")
    if value.descriptors.dtype != np.uint8:
        raise ValueError(f"{name}: expected binary (uint8) ORB descriptors, got {value.descriptors.dtype}")
    return value


def _octaves(scale: np.ndarray, scale_factor: float) -> np.ndarray:
    return np.rint(np.log(scale) / np.log(scale_factor)).astype(np.int64)


def _window_pairs(centres: np.ndarray, points: np.ndarray, half_width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All ``(i, j)`` with ``points[j]`` less than ``half_width[i]`` from ``centres[i]`` in x and in y, by row."""
    by_x = np.argsort(points[:, 0], kind="stable")
    xs = points[by_x, 0]
    lo = np.searchsorted(xs, centres[:, 0] - half_width, "right")
    count = np.maximum(np.searchsorted(xs, centres[:, 0] + half_width, "left") - lo, 0)
    rows = np.repeat(np.arange(len(centres)), count)
    cols = by_x[np.repeat(lo - np.cumsum(count) + count, count) + np.arange(count.sum())]
    keep = np.abs(points[cols, 1] - centres[rows, 1]) < half_width[rows]
    return rows[keep], cols[keep]


def _rows(points, n: int) -> np.ndarray:
    """Distinct row indices into n rows (``points`` of :func:`tracked_fraction`)."""
    rows = as_array(points, "points", ndim=1, dtype=np.int64)
    if len(rows) and (rows.min() < 0 or rows.max() >= n):
        expected = f"rows 0 .. {n - 1} of keyframe" if n else "no rows (keyframe has no features)"
        raise ValueError(f"points: expected {expected}, got values from {rows.min()} to {rows.max()}")
    if len(np.unique(rows)) < len(rows):
        raise ValueError("points: expected distinct rows, got a row more than once")
    return rows


def _tracked_rows(cur: Features, key: Features, window: float = TRACK_WINDOW, max_distance: float = TRACK_DISTANCE,
                  scale_factor: float = ORB_SCALE_FACTOR, check_orientation: bool = True) -> np.ndarray:
    """The rows of ``key`` :func:`tracked_matches` finds in ``cur`` (trusted inputs)."""
    if len(key) == 0 or len(cur) == 0:
        return np.zeros(0, np.int64)
    return _tracked_pairs(cur, key, window, max_distance, scale_factor, check_orientation)[0]


def _tracked_share(cur: Features, key: Features, rows: np.ndarray, *args) -> float:
    """Share of ``key``'s rows ``rows`` found in ``cur``; 0 for no rows (trusted inputs)."""
    return float(np.isin(rows, _tracked_rows(cur, key, *args)).sum() / len(rows)) if len(rows) else 0.0


def _tracked_pairs(cur: Features, key: Features, window: float, max_distance: float, scale_factor: float,
                   check_orientation: bool) -> tuple[np.ndarray, np.ndarray]:
    """Keyframe rows and current rows of the matches :func:`tracked_fraction` counts (trusted inputs)."""
    rows, cols = _window_pairs(key.keypoints.xy, cur.keypoints.xy, window * key.keypoints.scale)
    level_cur, level_key = _octaves(cur.keypoints.scale, scale_factor), _octaves(key.keypoints.scale, scale_factor)
    level_step = np.abs(level_cur[cols] - level_key[rows])
    rows, cols = rows[level_step <= 1], cols[level_step <= 1]                      # window and pyramid levels
    dist = hamming_distance(key.descriptors[rows], cur.descriptors[cols], validate=False)
    near = dist <= max_distance
    order = np.lexsort((cols[near], dist[near], rows[near]))   # each keyframe feature's candidates, nearest first
    rows, cols = rows[near][order], cols[near][order].tolist()
    first = np.searchsorted(rows, np.arange(len(key) + 1)).tolist()
    partner = np.full(len(key), -1, np.int64)
    taken = np.zeros(len(cur), bool)
    for i in range(len(key)):                                  # in keyframe order, a current feature matches once
        for j in cols[first[i]:first[i + 1]]:
            if not taken[j]:
                partner[i], taken[j] = j, True
                break
    ki = np.flatnonzero(partner >= 0)
    ci = partner[ki]
    if check_orientation and len(ki):
        turn = np.degrees(key.keypoints.orientation[ki] - cur.keypoints.orientation[ci]) % 360.0
        bins = np.floor(turn * ROTATION_BINS / 360.0 + 0.5).astype(np.int64) % ROTATION_BINS   # C's round
        counts = np.bincount(bins, minlength=ROTATION_BINS)
        top = np.argsort(-counts, kind="stable")[:3]       # the three fullest bins, earlier bins first on ties
        keep = top[counts[top] >= 0.1 * counts[top[0]]]
        ki, ci = ki[np.isin(bins, keep)], ci[np.isin(bins, keep)]
    return ki, ci


def _tracking_args(current, keyframe, window, max_distance, scale_factor) -> tuple:
    cur = _orb_features(current, "current")
    key = _orb_features(keyframe, "keyframe")
    same_width(cur.descriptors, key.descriptors, "current", "keyframe")
    window = as_finite_scalar(window, "window")
    max_distance = _bits(max_distance)
    scale_factor = as_finite_scalar(scale_factor, "scale_factor")
    if window <= 0:
        raise ValueError(f"window: expected a positive half-width in pixels, got {window}")
    if not 1 < scale_factor <= 2:
        raise ValueError(f"scale_factor: expected a pyramid step in (1, 2], got {scale_factor}")
    return cur, key, window, max_distance, scale_factor


def tracked_matches(current, keyframe, *, window: float = TRACK_WINDOW, max_distance: float = TRACK_DISTANCE,
                    scale_factor: float = ORB_SCALE_FACTOR, check_orientation: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """A keyframe's features found again in the current frame by ORB-SLAM-style tracking.

    Each keyframe feature is searched for the way ORB-SLAM tracks a map point into a new frame
    (Mur-Artal et al. 2015, Sec. V-B; ``ORBmatcher::SearchByProjection`` of ORB-SLAM2). Without map
    points or a motion model, the window is centred on the feature's own position in the keyframe, as
    if the camera had not moved:

    1. candidates: current features less than ``window`` times the keyframe feature's scale away in x
       and in y, on the same pyramid level or the next one up or down;
    2. the keyframe's features in order, each takes its nearest candidate by Hamming distance that no
       earlier feature took (ties: the lowest index), if that distance is at most ``max_distance``;
    3. orientation check: the rotations between matched keypoints go into 30 bins over 360 degrees;
       matches outside the three fullest bins (ties: the earlier bin), or in a bin with under a tenth
       of the fullest one's count, are dropped (a camera turning in its own plane turns every keypoint
       alike).

    Parameters
    ----------
    current, keyframe : Features
        ORB features (:func:`.orb.detect_orb_features`) of the current frame and of the last keyframe.
    window : float, default 15
        Half-width of the search window at pyramid level 0, pixels (ORB-SLAM's monocular ``th``), > 0.
    max_distance : float, default 100
        Largest Hamming distance of a match (ORB-SLAM's ``TH_HIGH``), > 0.
    scale_factor : float, default 1.2
        The pyramid's scale step the features were detected with (keypoint scale = factor ** level), in (1, 2].
    check_orientation : bool, default True
        Apply step 3.

    Returns
    -------
    keyframe_index, current_index : numpy.ndarray of int64
        Matched rows of ``keyframe`` (increasing) and of ``current``; empty when either has no features.

    Raises
    ------
    TypeError, ValueError
        For something that is not ORB ``Features``, or a window, distance or scale factor out of range.

    Notes
    -----
    Ge et al. (2023), Sec. 3.2, condition (3), read as ORB-SLAM counts tracked points
    (:func:`tracked_fraction`). ORB-SLAM2's code bins the rotation as ``round(rot / 30)``,
    30-degree bins of which only 13 are used; we use the 30 bins of 12 degrees its ``HISTO_LENGTH``
    describes.

    Examples
    --------
    >>> from robokit.vision import Features, Keypoints
    >>> d = np.random.default_rng(0).integers(0, 256, (3, 32), dtype=np.uint8)
    >>> kp = Keypoints(np.array([[10.0, 10.0], [50.0, 10.0], [90.0, 10.0]]), np.ones(3), np.ones(3), np.zeros(3))
    >>> now = Features(Keypoints(kp.xy[::-1] + [2.0, 0.0], kp.scale, kp.response, kp.orientation), d[::-1])
    >>> [a.tolist() for a in tracked_matches(now, Features(kp, d))]      # the rows come reversed
    [[0, 1, 2], [2, 1, 0]]
    """
    cur, key, window, max_distance, scale_factor = _tracking_args(current, keyframe, window, max_distance,
                                                                  scale_factor)
    if len(key) == 0 or len(cur) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return _tracked_pairs(cur, key, window, max_distance, scale_factor, bool(check_orientation))


def _matched_rows(key: Features, previous: Features | None = None, following: Features | None = None) -> np.ndarray:
    """:func:`matched_points` on trusted inputs."""
    if previous is not None:
        if len(previous) == 0 or len(key) == 0:
            return np.zeros(0, np.int64)
        return np.sort(_tracked_pairs(key, previous, TRACK_WINDOW, TRACK_DISTANCE, ORB_SCALE_FACTOR, True)[1])
    if following is not None:
        return _tracked_rows(following, key)
    return np.arange(len(key))


def matched_points(keyframe, previous=None, *, following=None) -> np.ndarray:
    """A keyframe's matched points: the rows of its features that another view also saw.

    With ``previous``, the keyframe's features found when the previous frame's features are tracked
    into it (:func:`tracked_matches` ``(keyframe, previous)``); without it (the first keyframe), those
    tracked from it into ``following``, the next frame; with neither, all of its features.

    Parameters
    ----------
    keyframe : Features
        The keyframe's ORB features.
    previous, following : Features, optional
        The frame just before the keyframe and the frame just after it; ``following`` counts only
        without ``previous`` (the first keyframe).

    Returns
    -------
    numpy.ndarray of int64
        Increasing rows of ``keyframe``: ``points`` for :func:`tracked_fraction`.

    Raises
    ------
    TypeError, ValueError
        For something that is not ORB ``Features``, or descriptors of another width.

    Notes
    -----
    Ge et al. (2023), Sec. 3.2, condition (3) ("shares ... matched points with the last keyframe"),
    read after ORB-SLAM (Mur-Artal et al. 2015, Sec. V-E), which compares a frame's tracked points with
    those of its reference keyframe that at least three keyframes observe; here one neighbouring frame
    suffices. A frame offered just after a first keyframe shares all of that keyframe's matched points
    by construction (they were found in it).

    Examples
    --------
    >>> from robokit.vision import Features, Keypoints
    >>> d = np.random.default_rng(0).integers(0, 256, (3, 32), dtype=np.uint8)
    >>> kp = Keypoints(np.array([[10.0, 10.0], [50.0, 10.0], [90.0, 10.0]]), np.ones(3), np.ones(3), np.zeros(3))
    >>> key = Features(kp, d)
    >>> before = Features(Keypoints(kp.xy[1:] - [2.0, 0.0], kp.scale[1:], kp.response[1:], kp.orientation[1:]), d[1:])
    >>> matched_points(key, before).tolist()                # feature 0 was not in the frame before
    [1, 2]
    """
    key = _orb_features(keyframe, "keyframe")
    others = {}
    for name, value in (("previous", previous), ("following", following)):
        if value is not None:
            others[name] = _orb_features(value, name)
            same_width(others[name].descriptors, key.descriptors, name, "keyframe")
    return _matched_rows(key, others.get("previous"), others.get("following"))


def tracked_fraction(current, keyframe, *, points=None, window: float = TRACK_WINDOW,
                     max_distance: float = TRACK_DISTANCE, scale_factor: float = ORB_SCALE_FACTOR,
                     check_orientation: bool = True) -> float:
    """Fraction of a keyframe's features found again by ORB-SLAM-style tracking (Ge et al. (2023), condition (3)).

    A second reading of condition (3)'s "shares matched points" (Sec. 3.2): of the keyframe features
    ``points``, the share :func:`tracked_matches` finds in the current frame (search windows around
    each feature's position, neighbouring pyramid levels, the nearest within ``max_distance`` bits,
    each current feature used once, an orientation check).

    Parameters
    ----------
    current, keyframe : Features
        ORB features (:func:`.orb.detect_orb_features`) of the current frame and of the last keyframe.
    points : array_like of int, optional
        Rows of ``keyframe`` to count, each once (e.g. its :func:`matched_points`); default all of them.
    window, max_distance, scale_factor, check_orientation
        As in :func:`tracked_matches` (defaults 15 px, 100 bits, 1.2, True).

    Returns
    -------
    float
        The ``points`` found, divided by their count, in [0, 1]; 0 when there are none or the current
        frame has no features.

    Raises
    ------
    TypeError, ValueError
        For something that is not ORB ``Features``, points that are not distinct rows of ``keyframe``,
        or a window, distance or scale factor out of range.

    Notes
    -----
    Ge et al. (2023), Sec. 3.2, condition (3); Mur-Artal et al. (2015), Sec. V-B and V-E (ORB-SLAM
    counts a frame's tracked points against those of its reference keyframe that other keyframes
    also observe).

    Examples
    --------
    >>> from robokit.vision import Features, Keypoints
    >>> rng = np.random.default_rng(0)
    >>> d = rng.integers(0, 256, (4, 32), dtype=np.uint8)
    >>> kp = Keypoints(np.array([[10., 10.], [50., 10.], [90., 10.], [130., 10.]]), np.ones(4), np.ones(4), np.zeros(4))
    >>> key = Features(kp, d)
    >>> moved = Features(Keypoints(kp.xy + [3.0, 0.0], kp.scale, kp.response, kp.orientation), d)
    >>> tracked_fraction(moved, key)                               # every feature 3 px on: all found
    1.0
    >>> far = Features(Keypoints(kp.xy + [30.0, 0.0], kp.scale, kp.response, kp.orientation), d)
    >>> tracked_fraction(far, key)                                 # 30 px is outside the 15 px window
    0.0
    >>> half = Features(Keypoints(kp.xy[:2], kp.scale[:2], kp.response[:2], kp.orientation[:2]), d[:2])
    >>> tracked_fraction(half, key), tracked_fraction(half, key, points=[0, 1, 2])
    (0.5, 0.6666666666666666)
    """
    cur, key, window, max_distance, scale_factor = _tracking_args(current, keyframe, window, max_distance,
                                                                  scale_factor)
    rows = np.arange(len(key)) if points is None else _rows(points, len(key))
    return _tracked_share(cur, key, rows, window, max_distance, scale_factor, bool(check_orientation))


class KeyframeConditions(NamedTuple):
    """Ge et al. (2023)'s conditions (1)-(4) for one frame, and the measured quantities."""

    features: bool        #: (1) feature count >= F_min
    frames: bool          #: (2) more than min_frame_gap frames since the last keyframe
    shared: bool          #: (3) shared fraction inside (low, high)
    moved: bool           #: (4) moved >= min_distance since the last keyframe
    n_features: int
    frame_gap: int
    fraction: float
    distance: float

    @property
    def all(self) -> bool:
        """Whether every condition holds."""
        return self.features and self.frames and self.shared and self.moved


def _position(position, name="position") -> np.ndarray:
    p = as_array(position, name, ndim=1)
    if p.size not in (2, 3):
        raise ValueError(f"{name}: expected [x, y] or a pose [x, y, theta], got shape {p.shape}")
    return p[:2]


class KeyframeSelector:
    """Online keyframe selection with Ge et al. (2023)'s conditions (1)-(4) (Sec. 3.2).

    Parameters
    ----------
    f_min : float
        Condition (1): a keyframe has at least ``f_min`` features (:func:`feature_threshold`). The
        paper says the count must "exceed" the threshold; when every calibration frame reaches ORB's
        feature cap, Eq. (15) gives the cap itself and a strict ``>`` would refuse every frame.
    min_frame_gap : int, default 10
        Condition (2): more than this many frames since the last keyframe.
    shared_range : (float, float), default (0.70, 0.90)
        Condition (3): ``low < share < high``, the share as ``matching`` reads it.
    min_distance : float, default 0.02
        Condition (4): metres moved since the last keyframe, at least.
    max_distance : float, default 50
        Hamming bound of a match in :func:`shared_fraction` (``matching="mutual"`` only).
    matching : {"mutual", "tracked"}, default "mutual"
        What "shares matched points" means. ``"mutual"``: :func:`shared_fraction` over all of the
        keyframe's features; frames are descriptor arrays. ``"tracked"``: :func:`tracked_fraction` with
        its defaults (ORB's scale step 1.2) over the keyframe's :func:`matched_points`, found from the
        frame offered just before it (for the first keyframe, from the next frame, which therefore
        shares them all); frames are ORB ``Features``. A keyframe after a frame without features has
        no matched points and shares 0 with every frame.
    below_band : {"skip", "take"}, default "skip"
        A frame sharing ``low`` or less: ``"skip"`` it, as condition (3) is printed (once no frame
        shares more than ``low``, selection stalls for good), or ``"take"`` it when (1), (2) and (4)
        hold (ours: the band's floor is where the frame rate should catch the overlap; a camera too
        slow for that still gets keyframes, like ORB-SLAM inserting one when tracking weakens).

    Attributes
    ----------
    indices : list of int
        Frame numbers (0-based, in offer order) of the keyframes so far.
    conditions : KeyframeConditions or None
        The last offered frame's conditions (None for the first frame, always a keyframe). Its share
        is measured only when condition (2) holds (otherwise ``fraction`` is NaN and ``shared``
        False); :meth:`evaluate` always measures it.

    Examples
    --------
    >>> kf = np.random.default_rng(0).integers(0, 256, (10, 32), dtype=np.uint8)
    >>> sel = KeyframeSelector(5, min_frame_gap=1)
    >>> sel.offer(kf, [0.0, 0.0]), sel.offer(kf, [0.1, 0.0]), sel.offer(kf[:8], [0.2, 0.0])
    (True, False, True)
    >>> sel.conditions.fraction, sel.indices
    (0.8, [0, 2])
    >>> for rule in ("skip", "take"):                  # a frame sharing 60 %, below the band
    ...     sel = KeyframeSelector(5, min_frame_gap=0, below_band=rule)
    ...     print(rule, sel.offer(kf, [0.0, 0.0]), sel.offer(kf[:6], [0.1, 0.0]))
    skip True False
    take True True
    """

    def __init__(self, f_min: float, *, min_frame_gap: int = 10, shared_range=(0.70, 0.90), min_distance: float = 0.02,
                 max_distance: float = ORB_MATCH_DISTANCE, matching: str = "mutual", below_band: str = "skip") -> None:
        self.f_min = as_finite_scalar(f_min, "f_min")
        self.min_frame_gap = as_int(min_frame_gap, "min_frame_gap", minimum=0)
        rng = as_array(shared_range, "shared_range", shape=(2,))
        if not 0 <= rng[0] < rng[1] <= 1:
            raise ValueError(f"shared_range: expected 0 <= low < high <= 1, got {rng.tolist()}")
        self.shared_range = (float(rng[0]), float(rng[1]))
        self.min_distance = as_finite_scalar(min_distance, "min_distance")
        if self.min_distance < 0:
            raise ValueError(f"min_distance: expected a non-negative distance, got {self.min_distance}")
        self.max_distance = _bits(max_distance)
        self.matching = as_choice(matching, "matching", ("mutual", "tracked"))
        self.below_band = as_choice(below_band, "below_band", ("skip", "take"))
        self.reset()

    def reset(self) -> None:
        """Forget every frame: the next one offered is a keyframe again."""
        self.indices: list[int] = []
        self.conditions: KeyframeConditions | None = None
        self._n = 0
        self._key = None
        self._key_pos = None
        self._points = None        # "tracked": the last keyframe's matched points (rows)
        self._previous = None      # "tracked": the frame offered last

    def _frame(self, frame):
        if self.matching == "tracked":
            return _orb_features(frame, "frame")
        return as_binary_descriptors(frame, "frame")

    def evaluate(self, frame, position) -> KeyframeConditions:
        """Evaluate conditions (1)-(4) for a frame against the last keyframe, without recording it."""
        if self._key is None:
            raise ValueError("evaluate: no keyframe yet (offer the first frame, which is always one)")
        return self._evaluate(self._frame(frame), _position(position))

    def _evaluate(self, d, p, measure: bool = True) -> KeyframeConditions:
        gap = self._n - self.indices[-1]
        if not measure:
            fraction = np.nan
        elif self.matching == "tracked":
            same_width(d.descriptors, self._key.descriptors, "frame", "keyframe")
            points = _matched_rows(self._key, following=d) if self._points is None else self._points
            fraction = _tracked_share(d, self._key, points)
        else:
            same_width(d, self._key, "frame", "keyframe")
            empty = len(d) == 0 or len(self._key) == 0
            fraction = 0.0 if empty else _match_count(d, self._key, self.max_distance) / len(self._key)
        moved = float(np.hypot(*(p - self._key_pos)))
        low, high = self.shared_range
        low = -1.0 if self.below_band == "take" else low
        return KeyframeConditions(len(d) >= self.f_min, gap > self.min_frame_gap,      # (1), (2)
                                  low < fraction < high, moved >= self.min_distance,   # (3), (4)
                                  len(d), gap, fraction, moved)

    def offer(self, frame, position) -> bool:
        """Offer the next frame; returns whether it becomes a keyframe (the first always does).

        Parameters
        ----------
        frame : array_like of uint8, shape (N, 32), or Features
            The frame's ORB descriptors (N may be 0), or with ``matching="tracked"`` its ORB features.
        position : array_like, shape (2,) or (3,)
            The robot's position ``[x, y]`` or pose ``[x, y, theta]`` in metres.
        """
        d, p = self._frame(frame), _position(position)
        if self._key is None:
            self._accept(d, p)
            return True
        if self.matching == "tracked" and self._points is None:     # the first keyframe's matched points
            same_width(d.descriptors, self._key.descriptors, "frame", "keyframe")
            self._points = _matched_rows(self._key, following=d)
        # a frame inside condition (2)'s gap cannot be a keyframe: its share is not measured (NaN)
        self.conditions = self._evaluate(d, p, measure=self._n - self.indices[-1] > self.min_frame_gap)
        if self.conditions.all:
            self._accept(d, p)
            return True
        self._previous = d
        self._n += 1
        return False

    def _accept(self, d, p) -> None:
        self.indices.append(self._n)
        if self.matching == "tracked":
            self._points = None if self._previous is None else _matched_rows(d, previous=self._previous)
            self._previous = d
        self._key, self._key_pos = d, p
        self._n += 1


def _stream(descriptor_list, positions, matching="mutual"):
    if not isinstance(descriptor_list, (list, tuple)):
        raise TypeError(f"descriptor_list: expected a list of per-frame descriptor arrays (or Features), "
                        f"got {describe(descriptor_list)}")
    check = _orb_features if matching == "tracked" else as_binary_descriptors
    frames = [check(d, f"descriptor_list[{i}]") for i, d in enumerate(descriptor_list)]
    if positions is None:
        return frames, None
    p = as_array(positions, "positions", ndim=2)
    if p.shape != (len(frames), p.shape[1]) or p.shape[1] not in (2, 3):
        raise ValueError(f"positions: expected shape ({len(frames)}, 2) or ({len(frames)}, 3), got {p.shape}")
    return frames, p


def select_keyframes(descriptor_list, positions, f_min: float, **kw) -> np.ndarray:
    """Indices of the keyframes Ge et al. (2023)'s conditions (1)-(4) pick from a run (Sec. 3.2).

    Parameters
    ----------
    descriptor_list : list of array_like of uint8, shape (N_i, 32) each, or of Features
        Every frame's ORB descriptors, in time order (ORB ``Features`` with ``matching="tracked"``).
    positions : array_like, shape (n_frames, 2) or (n_frames, 3)
        The robot's position (or pose) at each frame, metres.
    f_min : float
        Condition (1)'s threshold (:func:`feature_threshold`).
    **kw
        ``min_frame_gap``, ``shared_range``, ``min_distance``, ``max_distance``, ``matching``,
        ``below_band`` of :class:`KeyframeSelector`.

    Returns
    -------
    numpy.ndarray of int
        Frame indices, starting with 0 (the first frame is always a keyframe); empty for no frames.

    Examples
    --------
    >>> kf = np.random.default_rng(0).integers(0, 256, (10, 32), dtype=np.uint8)
    >>> frames = [kf, kf, kf[:8], kf[:8], kf[:7]]
    >>> select_keyframes(frames, np.c_[np.arange(5) * 0.1, np.zeros(5)], 5, min_frame_gap=1).tolist()
    [0, 2, 4]
    """
    selector = KeyframeSelector(f_min, **kw)
    frames, p = _stream(descriptor_list, positions, selector.matching)
    if p is None:
        raise TypeError("positions: expected an array of shape (n_frames, 2) or (n_frames, 3), got None")
    for d, x in zip(frames, p):
        selector.offer(d, x)
    return np.array(selector.indices, dtype=np.int64)


def select_keyframes_orbslam(descriptor_list, positions=None, *, min_frame_gap: int = 20, min_tracked: int = 50,
                             max_tracked_fraction: float = 0.90, max_distance: float = ORB_MATCH_DISTANCE,
                             matching: str = "mutual") -> np.ndarray:
    """Indices of the keyframes an ORB-SLAM-like rule picks (Mur-Artal et al. 2015, Sec. V-E).

    Parameters
    ----------
    descriptor_list : list of array_like of uint8, shape (N_i, 32) each, or of Features
        Every frame's ORB descriptors, in time order (ORB ``Features`` with ``matching="tracked"``).
    positions : array_like, shape (n_frames, 2|3), optional
        Accepted (and checked) so both rules take the same arguments; ORB-SLAM's rule does not
        use the distance moved.
    min_frame_gap : int, default 20
        More than this many frames since the last keyframe insertion.
    min_tracked : int, default 50
        The frame tracks at least this many points (matches with the reference keyframe, as
        ``matching`` reads them).
    max_tracked_fraction : float, default 0.90
        ... and fewer than this fraction of the reference keyframe's features.
    max_distance : float, default 50
        Hamming bound of a match (``matching="mutual"``).
    matching : {"mutual", "tracked"}, default "mutual"
        How a point counts as tracked: a mutual nearest neighbour of any of the reference keyframe's
        features within ``max_distance``; or, of the reference keyframe's matched points (its features
        tracked from the frame before it; frame 0's, into frame 1), one :func:`tracked_matches` finds
        (ORB-SLAM counts only points other views also observed).

    Returns
    -------
    numpy.ndarray of int
        Frame indices; frame 0 is the first keyframe (ORB-SLAM's map initialisation, which makes
        its first keyframes from two views, is not modelled).

    Examples
    --------
    >>> kf = np.random.default_rng(0).integers(0, 256, (100, 32), dtype=np.uint8)
    >>> frames = [kf] * 3 + [kf[:80]] * 3
    >>> select_keyframes_orbslam(frames, min_frame_gap=2).tolist()
    [0, 3]
    """
    matching = as_choice(matching, "matching", ("mutual", "tracked"))
    frames, _ = _stream(descriptor_list, positions, matching)
    min_frame_gap = as_int(min_frame_gap, "min_frame_gap", minimum=0)
    min_tracked = as_int(min_tracked, "min_tracked", minimum=0)
    top = as_finite_scalar(max_tracked_fraction, "max_tracked_fraction")
    if not 0 < top <= 1:
        raise ValueError(f"max_tracked_fraction: expected a value in (0, 1], got {top}")
    max_distance = _bits(max_distance)
    keys: list[int] = []
    points = None                                # "tracked": the reference keyframe's matched points
    for i, d in enumerate(frames):
        if not keys:
            keys.append(i)
            continue
        ref = frames[keys[-1]]
        if i - keys[-1] <= min_frame_gap:
            continue
        if matching == "tracked":
            if points is None:                   # frame k + 1 exists: frame i comes after it
                k = keys[-1]
                points = _matched_rows(ref, frames[k - 1] if k else None, frames[k + 1])
            tracked, reference = int(np.isin(points, _tracked_rows(d, ref)).sum()), len(points)
        else:
            tracked, reference = (_match_count(d, ref, max_distance) if len(d) and len(ref) else 0), len(ref)
        if tracked >= min_tracked and tracked < top * reference:
            keys.append(i)
            points = None
    return np.array(keys, dtype=np.int64)
