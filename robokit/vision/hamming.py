"""The Hamming distance between binary descriptors (ORB's rBRIEF) and nearest-neighbour matching by it.

A binary descriptor is a row of bytes (ORB: 256 intensity tests, Ge et al. (2023) Eqs. (13)-(14),
packed into 32 uint8); the distance between two is the number of bits in which they differ
(Rublee et al. 2011, Sec. 5). :func:`hamming_distance` is the readable kernel: it XORs 64-bit words
and counts their set bits with ``numpy.bitwise_count``; :func:`hamming_distances` is its all-pairs
form, in row blocks so memory stays bounded. :func:`hamming_match`, the nearest-neighbour matcher, finds each
row's two nearest with OpenCV's ``cv2.batchDistance`` (its fast path; the tests check it against
:func:`hamming_distances` and against ``cv2.BFMatcher(cv2.NORM_HAMMING)``).

Matching rule: the nearest neighbour is kept when its distance is at most ``max_distance``
(ORB-SLAM's ``TH_LOW = 50`` bits of 256, Mur-Artal et al. 2015, in its ``ORBmatcher``) and it
passes the distance-ratio test of :func:`robokit.vision.matching.ratio_test` (ORB-SLAM uses ratios
0.6-0.9 depending on the search; we default to 0.75, its relocalisation value); with
``cross_check=True`` it must also be the mutual best (OpenCV's ``crossCheck``).

References
----------
.. [1] E. Rublee, V. Rabaud, K. Konolige and G. Bradski, "ORB: an efficient alternative to SIFT or
   SURF", Proc. IEEE Int. Conf. on Computer Vision (ICCV), 2564-2571, 2011.
.. [2] R. Mur-Artal, J. M. M. Montiel and J. D. Tardos, "ORB-SLAM: a versatile and accurate monocular
   SLAM system", IEEE Transactions on Robotics 31(5), 1147-1163, 2015.
.. [3] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang (Ge et al.), "Visual-feature-assisted
   mobile robot localization in a long corridor environment", Frontiers of Information Technology
   & Electronic Engineering 24(6), 2023, doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import cv2
import numpy as np

from ..validation import as_array, describe
from .matching import Matches, as_ratio, ratio_test

__all__ = ["ORB_BYTES", "ORB_MATCH_DISTANCE", "ORB_RATIO", "as_binary_descriptors", "same_width", "hamming_distance",
           "hamming_distances", "hamming_match"]

#: Bytes of one ORB descriptor (256 bits).
ORB_BYTES = 32
#: ORB-SLAM's ``TH_LOW``: the largest Hamming distance (of 256 bits) accepted as a match.
ORB_MATCH_DISTANCE = 50
#: Default nearest / second-nearest ratio for ORB matches (ORB-SLAM's relocalisation value).
ORB_RATIO = 0.75
_BLOCK = 1 << 22          # distances computed per block of hamming_distances


def as_binary_descriptors(value, name: str = "descriptors", *, n_bytes: int | None = None) -> np.ndarray:
    """Return binary descriptors as a C-contiguous uint8 array of shape ``(N, B)``.

    Parameters
    ----------
    value : array_like, shape (N, B)
        Integers in [0, 255] (one byte of 8 binary tests each). An empty input (``[]``, shape
        ``(0,)`` or ``(0, B)``) gives shape ``(0, n_bytes or 32)``.
    name : str
        Argument name for error messages.
    n_bytes : int, optional
        Required row length ``B``.

    Returns
    -------
    numpy.ndarray, shape (N, B), uint8

    Raises
    ------
    TypeError
        For strings, booleans, complex numbers, ragged lists or objects.
    ValueError
        For another shape, fractions, or values outside [0, 255].

    Examples
    --------
    >>> as_binary_descriptors([[0, 255]]).tolist()
    [[0, 255]]
    >>> as_binary_descriptors([]).shape
    (0, 32)
    """
    if isinstance(value, np.ndarray) and value.dtype == np.uint8:
        arr = value
    else:
        arr = as_array(value, name, dtype=np.int64) if not (isinstance(value, np.ndarray)
                                                              and value.dtype.kind in "iu") else value
        if arr.dtype.kind not in "iu":
            raise TypeError(f"{name}: expected bytes (integers 0-255), got {describe(value)}")
        if arr.size and (arr.min() < 0 or arr.max() > 255):
            raise ValueError(f"{name}: expected bytes in [0, 255], got values in [{arr.min()}, {arr.max()}]")
        arr = arr.astype(np.uint8)
    if arr.size == 0 and arr.ndim <= 2:
        width = n_bytes if n_bytes is not None else (arr.shape[1] if arr.ndim == 2 and arr.shape[1] else ORB_BYTES)
        return np.zeros((0, width), np.uint8)
    if arr.ndim != 2 or arr.shape[1] == 0:
        raise ValueError(f"{name}: expected shape (N, B) of binary descriptors, got shape {arr.shape}")
    if n_bytes is not None and arr.shape[1] != n_bytes:
        raise ValueError(f"{name}: expected {n_bytes} bytes per descriptor, got shape {arr.shape}")
    return np.ascontiguousarray(arr)


def same_width(a: np.ndarray, b: np.ndarray, name_a: str, name_b: str) -> None:
    """Raise a ValueError naming both arguments unless their descriptors have one length (or one set is empty)."""
    if a.size and b.size and a.shape[-1] != b.shape[-1]:
        raise ValueError(f"{name_a}, {name_b}: expected descriptors of one length, got {a.shape[-1]} and "
                         f"{b.shape[-1]} bytes")


def _leading_rows(x, name: str) -> np.ndarray:
    """Byte rows with any leading axes, (..., B), as uint8."""
    arr = x if isinstance(x, np.ndarray) and x.dtype == np.uint8 else as_array(x, name, dtype=np.int64)
    if arr.ndim == 0 or arr.shape[-1] == 0:
        raise ValueError(f"{name}: expected rows of bytes, shape (..., B), got shape {arr.shape}")
    return as_binary_descriptors(arr.reshape(-1, arr.shape[-1]), name).reshape(arr.shape)


def _words64(d: np.ndarray) -> np.ndarray:
    """Rows of bytes as 64-bit words (zero-padded to a multiple of 8 bytes; zeros XOR to zero)."""
    pad = -d.shape[-1] % 8
    if pad:
        d = np.concatenate([d, np.zeros(d.shape[:-1] + (pad,), np.uint8)], axis=-1)
    return np.ascontiguousarray(d).view(np.uint64)


def hamming_distance(a, b, *, validate: bool = True) -> np.ndarray:
    """Hamming distance between descriptor rows, broadcasting over the leading axes.

    Parameters
    ----------
    a, b : array_like of uint8, shape (..., B)
        Binary descriptors; the leading axes broadcast (``a[:, None]`` against ``b[None]`` gives
        all pairs; :func:`hamming_distances` does that in bounded memory).
    validate : bool, default True
        ``False`` skips validation (the fast path for callers holding uint8 arrays).

    Returns
    -------
    numpy.ndarray of int64
        The number of differing bits, shape ``broadcast(a.shape[:-1], b.shape[:-1])``.

    Raises
    ------
    ValueError
        If the rows differ in length or the leading axes do not broadcast.

    Notes
    -----
    Rublee et al. (2011), Sec. 5: rBRIEF descriptors are compared by Hamming distance (XOR, then
    a bit count).

    Examples
    --------
    >>> hamming_distance([[0b1011, 0]], [[0b0001, 255]], validate=True).tolist()
    [10]
    """
    if validate:
        a, b = _leading_rows(a, "a"), _leading_rows(b, "b")
        same_width(a, b, "a", "b")
        try:
            np.broadcast_shapes(a.shape[:-1], b.shape[:-1])
        except ValueError:
            raise ValueError(f"a, b: expected leading shapes that broadcast, got {a.shape} and {b.shape}") from None
    a64, b64 = _words64(a), _words64(b)
    out = np.zeros(np.broadcast_shapes(a64.shape[:-1], b64.shape[:-1]), np.int64)
    for w in range(a64.shape[-1]):      # word by word: adding a few columns beats a reduction over them
        out += np.bitwise_count(np.bitwise_xor(a64[..., w], b64[..., w]))
    return out[()]                      # a numpy integer for two single rows


def hamming_distances(a, b) -> np.ndarray:
    """All-pairs Hamming distances between two sets of binary descriptors.

    Parameters
    ----------
    a : array_like of uint8, shape (Na, B)
    b : array_like of uint8, shape (Nb, B)

    Returns
    -------
    numpy.ndarray of int64, shape (Na, Nb)

    Raises
    ------
    ValueError
        If the row lengths differ.

    Notes
    -----
    Rublee et al. (2011), Sec. 5; computed with :func:`hamming_distance` in blocks of rows of
    ``a`` so that no more than about 4 million distances are held at once.

    Examples
    --------
    >>> hamming_distances([[0], [3]], [[1], [2], [255]]).tolist()
    [[1, 1, 8], [1, 1, 6]]
    """
    a, b = as_binary_descriptors(a, "a"), as_binary_descriptors(b, "b")
    same_width(a, b, "a", "b")
    out = np.empty((a.shape[0], b.shape[0]), np.int64)
    step = max(1, _BLOCK // max(1, b.shape[0]))
    for s in range(0, a.shape[0], step):
        out[s:s + step] = hamming_distance(a[s:s + step, None], b[None], validate=False)
    return out


def _two_nearest(q: np.ndarray, t: np.ndarray, k: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """Distances (floats, ``inf`` for a missing second) and indices of each query row's ``k`` nearest.

    ``k`` is 1 or 2; the neighbours are train rows.

    OpenCV's ``cv2.batchDistance`` keeps the ``K`` nearest while it scans the train rows with
    SIMD bit counts, about six times faster than the full table of :func:`hamming_distances` for
    500 x 500 ORB rows; a train row displaces a kept one only when strictly nearer, so ties go to
    the lowest index, as ``numpy.argmin`` over that table gives them (the tests compare the two).
    """
    found = min(k, len(t))
    d, i = cv2.batchDistance(np.ascontiguousarray(q), np.ascontiguousarray(t), cv2.CV_32S,
                             normType=cv2.NORM_HAMMING, K=found)
    dist, index = np.full((len(q), k), np.inf), np.empty((len(q), k), np.int64)
    dist[:, :found], index[:, :found] = d, i
    index[:, found:] = index[:, :1]
    return dist, index


def hamming_match(query, train, *, ratio: float = ORB_RATIO, max_distance: float | None = ORB_MATCH_DISTANCE,
                  cross_check: bool = False) -> Matches:
    """Match binary descriptors to their nearest neighbour by Hamming distance.

    Parameters
    ----------
    query : array_like of uint8, shape (N, B)
    train : array_like of uint8, shape (M, B)
    ratio : float, default 0.75
        Distance-ratio bound in (0, 1] (:func:`robokit.vision.matching.ratio_test`); ``1`` keeps
        every nearest neighbour except exact ties. With one train row the ratio is 0 (no second).
    max_distance : float or None, default 50
        Largest accepted distance in bits (ORB-SLAM's ``TH_LOW``); ``None`` or ``inf`` mean no bound.
    cross_check : bool, default False
        Keep only mutual nearest neighbours (the query row is also the train row's nearest).

    Returns
    -------
    Matches
        ``distance`` in bits (as floats); empty when either set is empty.

    Raises
    ------
    ValueError
        For row lengths that differ, a ratio outside (0, 1] or a non-positive ``max_distance``.

    Notes
    -----
    Rublee et al. (2011), Sec. 5 (Hamming distance); the thresholds are ORB-SLAM's (Mur-Artal et
    al. 2015). The nearest neighbour of a row is the lowest-index train row among those at the
    smallest distance, as OpenCV's ``BFMatcher(cv2.NORM_HAMMING)`` reports it.

    Examples
    --------
    >>> train = np.array([[0, 0], [255, 255], [15, 0]], np.uint8)
    >>> m = hamming_match(np.array([[1, 0], [254, 255]], np.uint8), train)
    >>> m.query.tolist(), m.train.tolist(), m.distance.tolist()
    ([0, 1], [0, 1], [1.0, 1.0])
    """
    ratio = as_ratio(ratio)
    q = as_binary_descriptors(query, "query")
    t = as_binary_descriptors(train, "train")
    same_width(q, t, "query", "train")
    if len(q) == 0 or len(t) == 0:       # validates ratio and max_distance all the same
        ratio_test(np.zeros((0, 2)), np.zeros((0, 2), int), ratio=ratio, max_distance=max_distance)
        return Matches.empty()
    dist, index = _two_nearest(q, t)
    m = ratio_test(dist, index, ratio=ratio, max_distance=max_distance)
    if cross_check and len(m):
        matched = np.unique(m.train)                  # only these train rows need their nearest query row
        nearest = np.empty(len(t), np.int64)
        nearest[matched] = _two_nearest(t[matched], q, k=1)[1][:, 0]
        mutual = nearest[m.train] == m.query
        m = Matches(m.query[mutual], m.train[mutual], m.distance[mutual], m.ratio[mutual])
    return m
