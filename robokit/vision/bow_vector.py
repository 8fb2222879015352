"""Bag-of-words vectors: TF-IDF weights of an image's visual words and the L1 score of two images.

Ge et al. (2023), Sec. 3.3: an image whose descriptors fall on the words ``w_i`` of a vocabulary
(:class:`robokit.vision.bag_of_words.Vocabulary`) becomes the vector of its words weighted by
``tf_i * idf_i`` (Eq. (16)); two vectors score ``s = 1 - 0.5 * | v_a / |v_a| - v_b / |v_b| |_1``
(Eq. (17)), 1 for proportional vectors and 0 for vectors that share no word (Galvez-Lopez & Tardos
2012, as in DBoW2).

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang (Ge et al.), "Visual-feature-assisted
   mobile robot localization in a long corridor environment", Frontiers of Information Technology
   & Electronic Engineering 24(6), 2023, doi:10.1631/FITEE.2200208.
.. [2] D. Galvez-Lopez and J. D. Tardos, "Bags of binary words for fast place recognition in image
   sequences", IEEE Transactions on Robotics 28(5), 1188-1197, 2012 (DBoW2).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..validation import as_array, describe

__all__ = ["BowVector", "as_bow_vector", "tf_idf", "l1_score"]


class BowVector(NamedTuple):
    """A bag-of-words vector: sorted unique word ids and their weights (Ge et al. (2023) Eq. (16)'s v).

    A plain tuple ``(words, weights)``: unpack it, or build one from plain lists with
    :func:`as_bow_vector`. An image without features gives the empty vector (no words).
    """

    words: np.ndarray
    weights: np.ndarray

    def __len__(self) -> int:   # the number of words, not the tuple's two fields
        return int(self.words.size)

    @classmethod
    def empty(cls) -> "BowVector":
        """The vector of an image with no features."""
        return cls(np.zeros(0, np.int64), np.zeros(0))


def as_bow_vector(vector, name: str = "vector", *, n_words: int | None = None) -> BowVector:
    """Return ``(word ids, weights)`` as a :class:`BowVector` sorted by word id.

    Parameters
    ----------
    vector : BowVector or pair of array_like
        Unique non-negative integer word ids and finite non-negative weights of the same length.
    name : str
        Argument name for error messages.
    n_words : int, optional
        Vocabulary size; ids must be below it.

    Returns
    -------
    BowVector

    Raises
    ------
    TypeError, ValueError
        If it is not a pair, ids repeat, are negative or too large, or weights are negative or not
        finite.

    Examples
    --------
    >>> as_bow_vector(([3, 1], [0.5, 0.25]))
    BowVector(words=array([1, 3]), weights=array([0.25, 0.5 ]))
    """
    if not isinstance(vector, tuple) or len(tuple(vector)) != 2:
        raise TypeError(f"{name}: expected a BowVector or a pair (word ids, weights), got {describe(vector)}")
    ids = as_array(vector[0], f"{name}.words", dtype=np.int64).reshape(-1)
    w = as_array(vector[1], f"{name}.weights").reshape(-1)
    if ids.shape != w.shape:
        raise ValueError(f"{name}: expected as many weights as word ids, got {w.size} and {ids.size}")
    if ids.size and ids.min() < 0:
        raise ValueError(f"{name}.words: expected non-negative word ids, got {ids.min()}")
    if n_words is not None and ids.size and ids.max() >= n_words:
        raise ValueError(f"{name}.words: expected word ids below the vocabulary's {n_words}, got {ids.max()}")
    if np.any(w < 0):
        raise ValueError(f"{name}.weights: expected non-negative weights, got {w.min()}")
    order = np.argsort(ids, kind="stable")
    ids, w = ids[order], w[order]
    if ids.size > 1 and np.any(ids[1:] == ids[:-1]):
        raise ValueError(f"{name}.words: expected unique word ids, got {ids[1:][ids[1:] == ids[:-1]][0]} twice")
    return BowVector(ids, w)


def tf_idf(word_ids, idf) -> BowVector:
    """TF-IDF weights of one image's words (Ge et al. (2023), Eq. (16)), not normalised.

    Parameters
    ----------
    word_ids : array_like of int, shape (n_k,)
        The word of each of the image's ``n_k`` features (repeats count: ``n_ik``).
    idf : array_like, shape (n_words,)
        ``IDF_i`` of every word, finite and >= 0.

    Returns
    -------
    BowVector
        The words present, sorted, with ``eta_i = (n_ik / n_k) * IDF_i``. Words whose weight is 0
        (their IDF is 0: every training image has them) are left out: they add nothing to Eq. (17).
        No features give the empty vector.

    Raises
    ------
    ValueError
        For word ids outside ``[0, n_words)`` or negative/non-finite IDF.

    Examples
    --------
    >>> v = tf_idf([0, 0, 2, 3], np.log2([3.0, 3.0, 1.5, 1.0]))
    >>> v.words.tolist(), np.round(v.weights, 4).tolist()
    ([0, 2], [0.7925, 0.1462])
    """
    idf = as_array(idf, "idf", ndim=1)
    if np.any(idf < 0):
        raise ValueError(f"idf: expected non-negative values, got {idf.min()}")
    ids = as_array(word_ids, "word_ids", dtype=np.int64, ndim=1)
    if ids.size and (ids.min() < 0 or ids.max() >= idf.size):
        raise ValueError(f"word_ids: expected ids in [0, {idf.size}), got values in [{ids.min()}, {ids.max()}]")
    if ids.size == 0:
        return BowVector.empty()
    words, counts = np.unique(ids, return_counts=True)
    eta = counts / ids.size * idf[words]                 # Eq. (16): TF_i * IDF_i, TF_i = n_ik / n_k
    keep = eta > 0
    return BowVector(words[keep], eta[keep])


def l1_score(v_a, v_b) -> float:
    """L1 similarity of two bag-of-words vectors (Ge et al. (2023), Eq. (17)), in [0, 1].

    Parameters
    ----------
    v_a, v_b : BowVector or pair (word ids, weights)
        Non-negative weights; each vector is L1-normalised here.

    Returns
    -------
    float
        ``s = 1 - 0.5 * | v_a / |v_a| - v_b / |v_b| |_1``: 1 for proportional vectors, 0 for vectors
        without a common word, and 0 when either vector is empty (an image without features
        resembles nothing).

    Raises
    ------
    TypeError, ValueError
        As :func:`as_bow_vector`.

    Examples
    --------
    >>> l1_score(([0, 1], [1.0, 1.0]), ([1, 2], [2.0, 2.0]))
    0.5
    >>> l1_score(([0], [1.0]), ([], []))
    0.0
    """
    a, b = as_bow_vector(v_a, "v_a"), as_bow_vector(v_b, "v_b")
    na, nb = a.weights.sum(), b.weights.sum()
    if na == 0 or nb == 0:
        return 0.0
    words = np.union1d(a.words, b.words)
    dense_a, dense_b = np.zeros(words.size), np.zeros(words.size)
    dense_a[np.searchsorted(words, a.words)] = a.weights / na
    dense_b[np.searchsorted(words, b.words)] = b.weights / nb
    s = 1.0 - 0.5 * np.abs(dense_a - dense_b).sum()    # Eq. (17)
    return float(min(1.0, max(0.0, s)))
