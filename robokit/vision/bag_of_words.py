"""A bag of binary words: a vocabulary tree over ORB descriptors, TF-IDF vectors and their L1 score.

Ge et al. (2023), Sec. 3.3 and Fig. 7: the ORB descriptor space is discretised by a tree of ``k``
branches and ``L`` levels (Nister & Stewenius 2006), built by clustering the training descriptors
into ``k`` groups, then each group again, ``L`` times; its leaves are the visual words. For binary
descriptors the clustering is k-majority (Galvez-Lopez & Tardos 2012, as in DBoW2): k-means++
seeding and assignment by Hamming distance, and each centre is the per-bit majority of its
members. :class:`.bow_database.BowDatabase` adds the inverted index.

The tree is stored as arrays (node ``0`` is the root): ``children[node]`` (-1 where a node has
fewer than ``k``), ``centres[node]`` and ``word_of_node[node]`` (-1 for inner nodes), so
:meth:`Vocabulary.words` walks every descriptor down one level at a time together, with one
Hamming-distance array per level (:func:`.hamming.hamming_distance`).

An image whose descriptors fall on the words ``w_i`` becomes the vector of its words weighted by
``tf_i * idf_i`` (:func:`tf_idf`, Eq. (16)); two vectors score
``s = 1 - 0.5 * | v_a / |v_a| - v_b / |v_b| |_1`` (:func:`l1_score`, Eq. (17)), 1 for proportional
vectors and 0 for vectors that share no word (Galvez-Lopez & Tardos 2012, as in DBoW2).

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang (Ge et al.), "Visual-feature-assisted
   mobile robot localization in a long corridor environment", Frontiers of Information Technology
   & Electronic Engineering 24(6), 2023, doi:10.1631/FITEE.2200208.
.. [2] D. Galvez-Lopez and J. D. Tardos, "Bags of binary words for fast place recognition in image
   sequences", IEEE Transactions on Robotics 28(5), 1188-1197, 2012 (DBoW2).
.. [3] D. Nister and H. Stewenius, "Scalable recognition with a vocabulary tree", Proc. IEEE Conf.
   on Computer Vision and Pattern Recognition (CVPR), 2161-2168, 2006.
.. [4] D. Arthur and S. Vassilvitskii, "k-means++: the advantages of careful seeding", Proc.
   ACM-SIAM Symposium on Discrete Algorithms (SODA), 1027-1035, 2007.
"""
from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..files import as_file_path, read_npz, save_npz, write_atomically
from ..validation import as_array, as_int, as_rng, describe
from .hamming import as_binary_descriptors, hamming_distance

__all__ = ["Vocabulary", "TooFewDescriptorsError", "VocabularyFileError", "BowVector", "as_bow_vector", "tf_idf",
           "l1_score", "MAX_FILE_BYTES", "MAX_FILE_VALUES", "MAX_BRANCHING"]


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


_FORMAT = "robokit-vocabulary-1"


#: The largest vocabulary or database file robokit reads (bytes), and values per array.
MAX_FILE_BYTES, MAX_FILE_VALUES = 512 * 1024**2, 1 << 27
#: The largest branching factor a vocabulary may have (``train`` and a loaded file alike).
MAX_BRANCHING = 256


class TooFewDescriptorsError(ValueError):
    """A vocabulary was asked to learn from fewer descriptors (or images) than it needs."""


class VocabularyFileError(ValueError):
    """A file is not a vocabulary saved by :meth:`Vocabulary.save` (corrupt, foreign or truncated)."""


#: The bits of every byte value, most significant first (``np.unpackbits``' order): row ``v`` is ``v``'s bits.
_BYTE_BITS = np.unpackbits(np.arange(256, dtype=np.uint8)[:, None], axis=1).astype(np.float64)


def bit_majority(desc: np.ndarray, labels: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-bit majority of each cluster's members (ties give 1, as DBoW2) and the cluster sizes.

    A bit is set in the centre when at least half the members set it. The per-cluster bit sums are
    counted one of two ways, with the same result: a small set unpacks every bit and sums them per
    cluster (the plain reading); a large one counts how often each byte value occurs in each
    cluster's byte column (one ``bincount``) and turns those counts into bit sums with the table of
    each byte value's bits, touching each byte once instead of each of its eight bits (about 15x
    faster for 50 000 descriptors; the two ways are compared in the tests).
    """
    size = np.bincount(labels, minlength=k)
    if len(desc) < 64 * k:
        sums = _bit_sums_unpacked(desc, labels, size)
    else:
        sums = _bit_sums_by_byte_value(desc, labels, k)
    return np.packbits(2 * sums >= size[:, None], axis=1), size


def _bit_sums_unpacked(desc: np.ndarray, labels: np.ndarray, size: np.ndarray) -> np.ndarray:
    """How many members of each cluster set each bit: unpack the bits and sum them per cluster."""
    bits = np.unpackbits(desc, axis=1)
    sums = np.zeros((len(size), bits.shape[1]), np.int64)
    filled = np.flatnonzero(size)             # the members of each cluster sit together once sorted by label
    sums[filled] = np.add.reduceat(bits[np.argsort(labels, kind="stable")], (np.cumsum(size) - size)[filled],
                                   axis=0, dtype=np.int64)
    return sums


def _bit_sums_by_byte_value(desc: np.ndarray, labels: np.ndarray, k: int) -> np.ndarray:
    """The same sums as :func:`_bit_sums_unpacked`, from a histogram of byte values per cluster and column."""
    n_bytes = desc.shape[1]
    cell = (labels[:, None] * n_bytes + np.arange(n_bytes)) * 256 + desc    # (cluster, column, value)
    counts = np.bincount(cell.ravel(), minlength=k * n_bytes * 256).reshape(k * n_bytes, 256)
    return np.rint(counts @ _BYTE_BITS).astype(np.int64).reshape(k, 8 * n_bytes)


def _k_majority(desc: np.ndarray, k: int, iterations: int, rng: np.random.Generator) -> list[np.ndarray]:
    """Split ``desc`` into at most ``k`` clusters; returns each non-empty cluster's member rows.

    Seeding is k-means++ (Arthur & Vassilvitskii 2007) with squared Hamming distances; each step
    assigns every descriptor to its nearest centre and replaces centres by majorities.
    """
    unique = np.unique(desc, axis=0)
    if len(unique) <= k:                            # DBoW2: one cluster per distinct descriptor
        labels = np.unique(desc, axis=0, return_inverse=True)[1].reshape(-1)
        return [np.nonzero(labels == j)[0] for j in range(len(unique))]
    centres = [desc[rng.integers(len(desc))]]
    nearest = hamming_distance(desc, centres[0][None], validate=False).astype(float)
    for _ in range(1, k):
        p = nearest ** 2
        pick = rng.choice(len(desc), p=p / p.sum()) if p.sum() > 0 else rng.integers(len(desc))
        centres.append(desc[pick])
        nearest = np.minimum(nearest, hamming_distance(desc, desc[pick][None], validate=False))
    centres = np.array(centres)
    labels = None
    for _ in range(max(1, iterations)):
        new = np.argmin(hamming_distance(desc[:, None], centres[None], validate=False), axis=1)
        if labels is not None and np.array_equal(new, labels):
            break
        labels = new
        majority, size = bit_majority(desc, labels, len(centres))
        centres = np.where((size > 0)[:, None], majority, centres)
    labels = np.argmin(hamming_distance(desc[:, None], centres[None], validate=False), axis=1)
    return [rows for rows in (np.nonzero(labels == j)[0] for j in range(len(centres))) if rows.size]


class Vocabulary:
    """A vocabulary tree of binary words with IDF weights (Ge et al. (2023), Sec. 3.3, Fig. 7).

    Build one with :meth:`train` (or :meth:`load`); it turns descriptors into words
    (:meth:`words`) and an image into a TF-IDF vector (:meth:`transform`), the API of DBoW2's
    ``TemplatedVocabulary``.

    Parameters
    ----------
    children : array_like of int, shape (n_nodes, k)
        Child node ids per node, -1 where there are fewer; node 0 is the root.
    centres : array_like of uint8, shape (n_nodes, B)
        Each node's centre (the root's is unused).
    idf : array_like, shape (n_words,)
        ``IDF_i`` (Eq. (16)) of every word; words are the leaves, numbered in node order.
    levels : int
        Depth ``L`` the tree was built to.

    Attributes
    ----------
    branching, levels, n_words : int
    idf : numpy.ndarray, shape (n_words,)

    Raises
    ------
    ValueError
        For arrays that do not describe a tree (a child id out of range, a node with two parents,
        more IDF values than leaves, ...).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> images = [rng.integers(0, 256, (50, 32), dtype=np.uint8) for _ in range(5)]
    >>> voc = Vocabulary.train(images, branching=4, levels=3, rng=0)
    >>> voc.n_words <= 4 ** 3, voc.words(images[0][:3]).shape
    (True, (3,))
    >>> from robokit.vision import l1_score
    >>> v = voc.transform(images[0])
    >>> bool(np.isclose(v.weights.sum(), 1.0)), l1_score(v, voc.transform(images[0]))
    (True, 1.0)
    """

    def __init__(self, children, centres, idf, levels: int) -> None:
        self.children = np.ascontiguousarray(as_array(children, "children", dtype=np.int64, ndim=2))
        n_nodes, self.branching = self.children.shape
        if not 2 <= self.branching <= MAX_BRANCHING:   # transform's work grows with it (a file could say 10^6)
            raise ValueError(f"children: expected 2 to {MAX_BRANCHING} columns (the branching factor), "
                             f"got {self.branching}")
        self.centres = as_binary_descriptors(centres, "centres")
        self.levels = as_int(levels, "levels", minimum=1, maximum=16)
        if self.centres.shape[0] != n_nodes or n_nodes < 2:
            raise ValueError(f"centres: expected one row per node ({n_nodes} >= 2), got {self.centres.shape[0]}")
        rows, cols = np.nonzero(self.children >= 0)
        kids = self.children[rows, cols]
        packed = np.all(np.diff((self.children >= 0).astype(np.int8), axis=1) <= 0)     # children first, then -1
        if (kids.size != n_nodes - 1 or np.unique(kids).size != kids.size or np.any(kids <= rows)
                or np.any(kids >= n_nodes) or not packed):
            raise ValueError("children: expected a tree in node order (each node but the root the child of exactly "
                             "one earlier node; child ids first in each row, then -1)")
        depth = np.zeros(n_nodes, np.int64)
        for _ in range(n_nodes):                   # children come after parents: one sweep per level
            new = depth.copy()
            new[kids] = depth[rows] + 1
            if np.array_equal(new, depth) or new.max() > self.levels:
                break
            depth = new
        if depth.max() > self.levels or not np.array_equal(depth[kids], depth[rows] + 1):
            raise ValueError(f"children: expected a tree at most levels={self.levels} deep")
        leaf = self.children[:, 0] < 0
        self.word_of_node = np.where(leaf, np.cumsum(leaf) - 1, -1)
        self.n_words = int(leaf.sum())
        self.idf = as_array(idf, "idf", shape=(self.n_words,))
        if np.any(self.idf < 0):
            raise ValueError(f"idf: expected non-negative values, got {self.idf.min()}")

    @classmethod
    def train(cls, descriptors, *, branching: int = 10, levels: int = 4, iterations: int = 10,
              rng=0) -> "Vocabulary":
        """Learn a vocabulary tree by hierarchical k-majority clustering and the words' IDF.

        Parameters
        ----------
        descriptors : list of array_like of uint8, shape (n_k, B) each
            The training images' descriptors, one array per image (``N = len(descriptors)`` in
            Eq. (16)'s IDF). One array (not a list) counts as one image.
        branching : int, default 10
            ``k``, children per node (>= 2).
        levels : int, default 4
            ``L``, depth of the tree (1 to 8): at most ``k ** L`` words.
        iterations : int, default 10
            Most k-majority steps per node (it stops earlier when assignments settle).
        rng : numpy.random.Generator or int, default 0
            Seeds the k-means++ seeding.

        Returns
        -------
        Vocabulary

        Raises
        ------
        TooFewDescriptorsError
            With fewer distinct training descriptors than ``branching`` (no first split exists).
        TypeError, ValueError
            For descriptors that are not byte rows of one length, or parameters out of range.

        Notes
        -----
        Ge et al. (2023), Sec. 3.3 (a k-branch, d-level tree of k-means clusters; IDF leaves) with
        DBoW2's k-majority for binary descriptors (Galvez-Lopez & Tardos 2012, Sec. IV); a node
        with at most ``k`` distinct descriptors gets one child per distinct descriptor, and a node
        of one distinct descriptor is a leaf. ``IDF_i = log2(N / n_i)`` (Eq. (16)) with ``n_i`` the
        number of training images that contain word ``i`` (DBoW2's reading of Eq. (16)'s "number
        of occurrences ... in the database"); a word no training image reaches gets IDF 0.

        Examples
        --------
        >>> d = np.random.default_rng(1).integers(0, 256, (60, 32), dtype=np.uint8)
        >>> Vocabulary.train([d[:30], d[30:]], branching=3, levels=2).branching
        3
        """
        branching = as_int(branching, "branching", minimum=2, maximum=MAX_BRANCHING)
        levels = as_int(levels, "levels", minimum=1, maximum=8)
        iterations = as_int(iterations, "iterations", minimum=1, maximum=1000)
        rng = as_rng(rng)
        images = [descriptors] if isinstance(descriptors, np.ndarray) else descriptors
        if not isinstance(images, (list, tuple)):
            raise TypeError(f"descriptors: expected a list of per-image descriptor arrays, got {describe(descriptors)}")
        images = [as_binary_descriptors(d, f"descriptors[{i}]") for i, d in enumerate(images)]
        width = {d.shape[1] for d in images if len(d)}
        if len(width) > 1:
            raise ValueError(f"descriptors: expected one descriptor length for every image, got {sorted(width)}")
        desc = np.concatenate(images) if images else np.zeros((0, 32), np.uint8)
        distinct = len(np.unique(desc, axis=0)) if len(desc) else 0
        if distinct < branching:          # k-means cannot split fewer distinct rows into k clusters
            raise TooFewDescriptorsError(f"descriptors: expected at least branching={branching} distinct training "
                                         f"descriptors, got {distinct} distinct of {len(desc)}")
        children, centres = [[-1] * branching], [np.zeros(desc.shape[1], np.uint8)]
        todo = [(0, np.arange(len(desc)), 0)]                 # (node, member rows, depth)
        while todo:
            node, rows, depth = todo.pop()
            if depth == levels or np.all(desc[rows] == desc[rows[0]]):     # a node of one distinct descriptor
                continue
            for j, members in enumerate(_k_majority(desc[rows], branching, iterations, rng)):
                child = len(centres)
                children.append([-1] * branching)
                centres.append(bit_majority(desc[rows[members]], np.zeros(members.size, int), 1)[0][0])
                children[node][j] = child
                todo.append((child, rows[members], depth + 1))
        voc = cls(np.array(children), np.array(centres), np.zeros(sum(c[0] < 0 for c in children)), levels)
        n_i = np.zeros(voc.n_words)
        for d in images:
            if len(d):
                n_i[np.unique(voc._words(d))] += 1
        voc.idf = np.where(n_i > 0, np.log2(len(images) / np.maximum(n_i, 1)), 0.0)   # Eq. (16): log2(N / n_i)
        return voc

    def words(self, descriptors) -> np.ndarray:
        """The word (leaf) of every descriptor, all descending the tree together.

        Parameters
        ----------
        descriptors : array_like of uint8, shape (N, B)

        Returns
        -------
        numpy.ndarray of int64, shape (N,)
            Word ids in ``[0, n_words)``; at each node the nearest child centre by Hamming distance
            (the first of equals).

        Examples
        --------
        >>> d = np.array([[0] * 4, [255] * 4, [1] * 4, [254] * 4], np.uint8)
        >>> voc = Vocabulary.train([d], branching=2, levels=1)
        >>> w = voc.words(d)
        >>> voc.n_words, bool(w[0] == w[2] != w[1] == w[3])
        (2, True)
        """
        return self._words(as_binary_descriptors(descriptors, "descriptors", n_bytes=self.centres.shape[1]))

    def _words(self, d: np.ndarray) -> np.ndarray:
        """Unchecked :meth:`words`."""
        node = np.zeros(len(d), np.int64)
        for _ in range(self.levels):                       # one Hamming array per level
            kids = self.children[node]                     # (N, k)
            inner = kids[:, 0] >= 0
            if not inner.any():
                break
            kids, rows = kids[inner], np.nonzero(inner)[0]
            dist = hamming_distance(d[rows][:, None], self.centres[np.maximum(kids, 0)], validate=False)
            dist[kids < 0] = np.iinfo(np.int64).max
            node[rows] = kids[np.arange(len(rows)), np.argmin(dist, axis=1)]
        return self.word_of_node[node]

    def transform(self, descriptors) -> BowVector:
        """One image's bag-of-words vector: TF-IDF weights (Eq. (16)), L1-normalised.

        Parameters
        ----------
        descriptors : array_like of uint8, shape (n_k, B)
            The image's descriptors; none (shape (0, B), an image without ORB features) gives the
            empty vector, whose every score is 0.

        Returns
        -------
        BowVector
            Sorted word ids and weights summing to 1 (or empty).

        Examples
        --------
        >>> d = np.array([[0] * 4, [255] * 4, [1] * 4, [254] * 4], np.uint8)
        >>> voc = Vocabulary.train([d[:2], d[2:3]], branching=2, levels=1)
        >>> sorted(voc.idf.tolist()), voc.transform(d[:1]).weights.tolist()   # log2(2/2), log2(2/1)
        ([0.0, 1.0], [])
        >>> voc.transform(d[1:2]).weights.tolist()
        [1.0]
        """
        d = as_binary_descriptors(descriptors, "descriptors", n_bytes=self.centres.shape[1])
        v = tf_idf(self._words(d), self.idf)
        total = v.weights.sum()
        return BowVector(v.words, v.weights / total) if total > 0 else BowVector.empty()

    def arrays(self) -> dict[str, np.ndarray]:
        """The arrays that define the vocabulary (what :meth:`save` writes)."""
        return {"format": np.array(_FORMAT), "children": self.children, "centres": self.centres, "idf": self.idf,
                "levels": np.array(self.levels)}

    @classmethod
    def from_arrays(cls, arrays, source: str = "arrays") -> "Vocabulary":
        """Rebuild a vocabulary from :meth:`arrays` (a dict or an open npz); a VocabularyFileError if foreign."""
        try:
            if str(arrays["format"][()]) != _FORMAT:
                raise VocabularyFileError(f"{source}: expected a {_FORMAT} file, got format {arrays['format']!r}")
            return cls(arrays["children"], arrays["centres"], arrays["idf"], int(arrays["levels"][()]))
        except VocabularyFileError:
            raise
        except (KeyError, ValueError, TypeError, IndexError) as err:
            raise VocabularyFileError(f"{source}: not a vocabulary saved by Vocabulary.save ({err})") from None

    def save(self, path) -> Path:
        """Write the vocabulary to ``path`` (numpy ``.npz``), atomically; returns the path written."""
        arrays = self.arrays()
        return write_atomically(as_file_path(path), lambda tmp: save_npz(tmp, arrays))

    @classmethod
    def load(cls, path) -> "Vocabulary":
        """Read a vocabulary written by :meth:`save`.

        The file is read by :func:`robokit.files.read_npz` within :data:`MAX_FILE_BYTES` bytes and
        :data:`MAX_FILE_VALUES` values per array, checked before its data are read.

        Raises
        ------
        VocabularyFileError
            If the file is not one (corrupt, truncated, another format, a device, beyond the bounds);
            FileNotFoundError if absent.
        """
        path = as_file_path(path)
        try:
            return cls.from_arrays(read_npz(path, max_bytes=MAX_FILE_BYTES, max_values=MAX_FILE_VALUES), str(path))
        except (VocabularyFileError, FileNotFoundError):
            raise
        except Exception as err:         # zip/pickle/format errors of a foreign file
            raise VocabularyFileError(f"path: {path} is not a vocabulary saved by Vocabulary.save ({err})") from None
