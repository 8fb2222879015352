"""The nearest-neighbour distance-ratio test and the matches it keeps (Lin et al. Sec. 3; Lowe 2004).

A descriptor ``D_A`` is matched to its nearest neighbour ``D_B`` when
``||D_A - D_B|| / ||D_A - D_C|| < t`` with ``D_C`` the second nearest: an ambiguous match, whose
second neighbour is almost as close, is rejected. Lin et al. use ``t = 0.65``, Lowe 0.8. Every
matcher of robokit (:mod:`robokit.vision.matching` for float descriptors,
:mod:`robokit.vision.hamming` for binary ones) finds the two nearest neighbours its own way and
keeps the rows this test keeps.

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [2] D. G. Lowe, "Distinctive image features from scale-invariant keypoints", International Journal
   of Computer Vision 60(2), 91-110, 2004.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..validation import as_array, as_positive

__all__ = ["Matches", "LIN_RATIO", "LOWE_RATIO", "distance_ratio", "as_ratio", "as_distance_bound", "ratio_test"]

#: Lin et al.'s nearest-neighbour ratio threshold ``t`` (PLOT paper, Sec. 3: "t is set equal to 0.65").
LIN_RATIO = 0.65
#: Lowe's (2004, Sec. 7.1) ratio threshold, 0.8 (lesson 02's paper gives none).
LOWE_RATIO = 0.8

@dataclass(frozen=True)
class Matches:
    """Index pairs of matched descriptors.

    Attributes
    ----------
    query, train : numpy.ndarray of int, shape (M,)
        Row in the first and the second descriptor set.
    distance : numpy.ndarray, shape (M,)
        Euclidean descriptor distance to the nearest neighbour.
    ratio : numpy.ndarray, shape (M,)
        Nearest / second-nearest distance.
    """

    query: np.ndarray
    train: np.ndarray
    distance: np.ndarray
    ratio: np.ndarray

    def __len__(self) -> int:
        return int(self.query.size)

    @classmethod
    def empty(cls) -> "Matches":
        """Return zero matches."""
        z = np.zeros(0, int)
        return cls(z, z.copy(), np.zeros(0), np.zeros(0))


def distance_ratio(best, second) -> np.ndarray:
    """Nearest over second-nearest descriptor distance, the quantity the ratio test thresholds.

    Parameters
    ----------
    best, second : array_like, shape (N,)
        Distances to the nearest and the second-nearest candidate (``second`` may be ``inf`` when
        there is only one candidate).

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``best / second``; 1 where ``second`` is 0 (two exact duplicates are ambiguous, so a test
        ``ratio < t`` with ``t <= 1`` rejects them) and 0 where ``second`` is infinite.

    Raises
    ------
    ValueError
        For different shapes, NaN, a negative ``best``, an infinite ``best`` or ``second < best``.

    Notes
    -----
    Lin et al. Sec. 3, ``||D_A - D_B|| / ||D_A - D_C|| < t``; Lowe (2004), Sec. 7.1.
    """
    b = as_array(best, "best")
    c = as_array(second, "second", finite=False)
    if b.shape != c.shape:
        raise ValueError(f"second: expected the shape of best {b.shape}, got {c.shape}")
    if np.any(b < 0) or np.any(np.isnan(c)) or np.any(c < b):
        raise ValueError("best, second: expected distances 0 <= best <= second (second may be inf)")
    return np.divide(b, c, out=np.ones(b.shape), where=c > 0)


def as_distance_bound(max_distance) -> float:
    """``max_distance`` as a bound on a match's descriptor distance: ``inf`` for none, else positive.

    Parameters
    ----------
    max_distance : float or None
        ``None`` or ``inf``: no bound; otherwise a positive number.

    Returns
    -------
    float

    Raises
    ------
    ValueError, TypeError
        For zero, a negative number, NaN or a non-number.

    Notes
    -----
    The optional absolute gate beside Lowe's (2004, Sec. 7.1) ratio test.
    """
    if max_distance is None:
        return np.inf
    bound = as_array(max_distance, "max_distance", shape=(), finite=False).item()
    if not bound > 0:        # also catches NaN
        raise ValueError(f"max_distance: expected a positive number or inf, got {bound}")
    return bound


def as_ratio(ratio) -> float:
    """A distance-ratio bound in (0, 1], or a ValueError/TypeError naming ``ratio``."""
    ratio = as_positive(ratio, "ratio")
    if ratio > 1:
        raise ValueError(f"ratio: expected a value in (0, 1], got {ratio}")
    return ratio


def ratio_test(dist, index, *, ratio: float = LIN_RATIO, max_distance: float | None = None) -> Matches:
    """Keep the query rows whose nearest neighbour passes the distance-ratio test.

    Parameters
    ----------
    dist : array_like, shape (N, 2)
        Distances to the nearest and second-nearest neighbour (second may be ``inf``).
    index : array_like of int, shape (N, 2)
        Their indices (only the first column is used).
    ratio : float, default 0.65
        Keep a row when ``dist[:, 0] / dist[:, 1] < ratio``, in (0, 1].
    max_distance : float, optional
        Also reject rows whose nearest distance exceeds this.

    Returns
    -------
    Matches

    Raises
    ------
    ValueError
        For mismatched shapes, distances that are not ``0 <= best <= second`` or a ratio
        outside (0, 1].

    Notes
    -----
    Lin et al. Sec. 3; Lowe 2004, Sec. 7.1. The one place the ratio test is applied: used by
    :func:`~robokit.vision.matching.ratio_match` and
    :meth:`~robokit.vision.matching.DescriptorIndex.match`.

    Examples
    --------
    >>> m = ratio_test([[0.1, 1.0], [0.9, 1.0]], [[4, 2], [0, 1]], ratio=0.8)
    >>> m.query.tolist(), m.train.tolist(), m.ratio.tolist()
    ([0], [4], [0.1])
    """
    ratio = as_ratio(ratio)
    d = as_array(dist, "dist", shape=(None, 2), finite=False)
    idx = as_array(index, "index", shape=(d.shape[0], 2), dtype=int)
    if not (np.all(np.isfinite(d[:, 0])) and np.all(d[:, 0] >= 0) and np.all(d[:, 1] >= d[:, 0])):
        raise ValueError("dist: expected rows 0 <= nearest <= second (finite nearest; second may be inf)")
    if idx.size and idx.min() < 0:
        raise ValueError(f"index: expected non-negative indices, got {idx.min()}")
    r = distance_ratio(d[:, 0], d[:, 1])
    keep = (r < ratio) & (d[:, 0] <= as_distance_bound(max_distance))
    rows = np.nonzero(keep)[0]
    return Matches(rows, idx[rows, 0], d[rows, 0], r[rows])
