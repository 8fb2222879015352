"""An image database queried by bag-of-words vectors through an inverted index (Ge et al. (2023), Fig. 7).

Each entry (a keyframe) is stored as its L1-normalised TF-IDF vector (:mod:`.bag_of_words`); the
inverted index lists, for every word, the entries that contain it and its weight there (Sec. 3.3:
"an inverse index list is created to store a list of the most similar images for each word").
A query touches only the entries that share a word with it. For L1-normalised vectors ``a, b``
(DBoW2, Galvez-Lopez & Tardos 2012, Sec. V):

    |a - b|_1 = |a|_1 + |b|_1 + sum over shared words (|a_i - b_i| - |a_i| - |b_i|)
              = 2 + sum over shared words (|a_i - b_i| - |a_i| - |b_i|),

so Eq. (17)'s ``s = 1 - |a - b|_1 / 2 = -1/2 * sum over shared words (|a_i - b_i| - |a_i| - |b_i|)``
(equal to ``sum min(a_i, b_i)`` for non-negative weights), and an entry without a shared word
scores 0. The index is held as CSR arrays (postings sorted by word), rebuilt after additions, so
a query joins the query words' posting lists and sums them per entry with one ``bincount``.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang (Ge et al.), "Visual-feature-assisted
   mobile robot localization in a long corridor environment", Frontiers of Information Technology
   & Electronic Engineering 24(6), 2023, doi:10.1631/FITEE.2200208.
.. [2] D. Galvez-Lopez and J. D. Tardos, "Bags of binary words for fast place recognition in image
   sequences", IEEE Transactions on Robotics 28(5), 1188-1197, 2012 (DBoW2).
"""
from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..files import as_file_path, read_npz, save_npz, write_atomically
from ..validation import as_int, describe
from .bag_of_words import MAX_FILE_BYTES, MAX_FILE_VALUES, Vocabulary, VocabularyFileError
from .bag_of_words import BowVector, as_bow_vector

__all__ = ["QueryResult", "BowDatabase", "DatabaseFileError", "MAX_ENTRIES"]

#: The most images a database file may hold (:meth:`BowDatabase.load` refuses more before adding any).
MAX_ENTRIES = 100_000


class DatabaseFileError(ValueError):
    """A file is not a database saved by :meth:`BowDatabase.save`."""


class QueryResult(NamedTuple):
    """One ranked answer of :meth:`BowDatabase.query`: the entry id and its Eq. (17) score."""

    entry: int
    score: float


class BowDatabase:
    """Keyframes as bag-of-words vectors with an inverted index (DBoW2's ``TemplatedDatabase``).

    Parameters
    ----------
    vocabulary : Vocabulary
        Turns descriptors into vectors (:meth:`.bag_of_words.Vocabulary.transform`).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> images = [rng.integers(0, 256, (60, 32), dtype=np.uint8) for _ in range(6)]
    >>> db = BowDatabase(Vocabulary.train(images, branching=4, levels=3, rng=0))
    >>> [db.add(d) for d in images]
    [0, 1, 2, 3, 4, 5]
    >>> best = db.query(images[4], max_results=2)
    >>> best[0].entry, round(best[0].score, 6), len(best)
    (4, 1.0, 2)
    >>> db.query(np.zeros((0, 32), np.uint8))      # an image without features finds nothing
    []
    """

    def __init__(self, vocabulary: Vocabulary) -> None:
        if not isinstance(vocabulary, Vocabulary):
            raise TypeError(f"vocabulary: expected a Vocabulary, got {describe(vocabulary)}")
        self.vocabulary = vocabulary
        self._words: list[np.ndarray] = []      # per entry, L1-normalised
        self._weights: list[np.ndarray] = []
        self._index = None                       # (indptr, entries, weights), built on demand

    def __len__(self) -> int:
        return len(self._words)

    def _vector(self, item, name: str) -> BowVector:
        if isinstance(item, BowVector):
            v = as_bow_vector(item, name, n_words=self.vocabulary.n_words)
            total = v.weights.sum()
            return BowVector(v.words, v.weights / total) if total > 0 else BowVector.empty()
        return self.vocabulary.transform(item)

    def add(self, item) -> int:
        """Add one image (its descriptors, or its :class:`BowVector`); returns its entry id (0, 1, ...).

        An image without features is added (it keeps its id) but no query ever returns it.

        Raises
        ------
        TypeError, ValueError
            For descriptors :meth:`Vocabulary.transform` refuses, or a vector with unknown words.
        """
        v = self._vector(item, "item")
        self._words.append(v.words)
        self._weights.append(v.weights)
        self._index = None
        return len(self._words) - 1

    def vector(self, entry: int) -> BowVector:
        """The stored (L1-normalised) vector of an entry."""
        entry = as_int(entry, "entry", minimum=0, maximum=len(self) - 1)
        return BowVector(self._words[entry], self._weights[entry])

    def _inverted(self):
        if self._index is None:
            sizes = np.array([w.size for w in self._words], np.int64)
            words = np.concatenate(self._words) if self._words else np.zeros(0, np.int64)
            weights = np.concatenate(self._weights) if self._weights else np.zeros(0)
            entries = np.repeat(np.arange(len(self._words)), sizes)
            order = np.argsort(words, kind="stable")                 # postings by word, then entry
            indptr = np.zeros(self.vocabulary.n_words + 1, np.int64)
            np.cumsum(np.bincount(words, minlength=self.vocabulary.n_words), out=indptr[1:])
            self._index = (indptr, entries[order].astype(np.int32), weights[order])
        return self._index

    def query(self, item, max_results: int | None = 4) -> list[QueryResult]:
        """The entries most similar to an image, best first, by the L1 score (Ge et al. (2023), Eq. (17)).

        Parameters
        ----------
        item : array_like of uint8, shape (n, B), or BowVector
            The query image's descriptors, or its vector.
        max_results : int or None, default 4
            Most results returned (``None``: every entry that shares a word).

        Returns
        -------
        list of QueryResult
            ``(entry, score)`` with score in (0, 1], descending (equal scores: lower entry first);
            only entries sharing at least one word (every other entry scores 0). Empty for an
            image without features or an empty database.

        Notes
        -----
        Eq. (17) over the inverted index (Fig. 7): ``s = -1/2 * sum over shared words of
        (|a_i - b_i| - |a_i| - |b_i|)`` for L1-normalised vectors (module docstring).
        """
        if max_results is not None:
            max_results = as_int(max_results, "max_results", minimum=1)
        q = self._vector(item, "item")
        if len(q) == 0 or len(self) == 0:
            return []
        indptr, entries, weights = self._inverted()
        start, stop = indptr[q.words], indptr[q.words + 1]
        counts = stop - start
        total = int(counts.sum())
        if total == 0:
            return []
        # the query words' posting lists are contiguous slices of the CSR arrays: join them
        lists = [slice(a, b) for a, b in zip(start.tolist(), stop.tolist())]
        hit = np.concatenate([entries[s] for s in lists])
        b = np.concatenate([weights[s] for s in lists])
        # -1/2 (|a_i - b_i| - |a_i| - |b_i|) = min(a_i, b_i) for non-negative weights: one pass, not four
        shared = np.minimum(np.repeat(q.weights, counts), b)
        partial = np.bincount(hit, shared, minlength=len(self))
        ids = np.nonzero(partial > 0)[0]                    # a shared word adds min(a_i, b_i) > 0
        score = partial[ids]                                # Eq. (17) over shared words
        if max_results is not None and ids.size > max_results:
            # keep every entry scoring at least the max_results-th best (ties stay), then rank those
            kth = np.partition(score, ids.size - max_results)[ids.size - max_results]
            keep = score >= kth
            ids, score = ids[keep], score[keep]
        order = np.lexsort((ids, -score))
        if max_results is not None:
            order = order[:max_results]
        return [QueryResult(int(ids[i]), float(min(1.0, score[i]))) for i in order]

    def save(self, path) -> Path:
        """Write the database and its vocabulary to one ``.npz`` file, atomically; returns the path."""
        path = as_file_path(path)
        sizes = np.array([w.size for w in self._words], np.int64)
        arrays = {f"vocabulary_{k}": v for k, v in self.vocabulary.arrays().items()}
        arrays.update(entry_sizes=sizes,
                      entry_words=np.concatenate(self._words) if self._words else np.zeros(0, np.int64),
                      entry_weights=np.concatenate(self._weights) if self._weights else np.zeros(0))
        return write_atomically(path, lambda tmp: save_npz(tmp, arrays))

    @classmethod
    def _from_entries(cls, voc: Vocabulary, sizes: np.ndarray, words: np.ndarray, weights: np.ndarray,
                      path: Path) -> "BowDatabase":
        """A database from a file's flat entry arrays, checked and normalised as :meth:`add` would,
        for all entries at once (a Python loop over 10^5 entries took seconds)."""
        if words.size and (words.min() < 0 or words.max() >= voc.n_words):
            raise DatabaseFileError(f"path: {path} has word ids outside the vocabulary's {voc.n_words}")
        if not np.all(np.isfinite(weights)) or np.any(weights < 0):
            raise DatabaseFileError(f"path: {path} has negative or non-finite weights")
        entry = np.repeat(np.arange(sizes.size), sizes)
        order = np.lexsort((words, entry))                       # word ids sorted within each entry
        entry, words, weights = entry[order], words[order], weights[order]
        if np.any((entry[1:] == entry[:-1]) & (words[1:] == words[:-1])):
            raise DatabaseFileError(f"path: {path} repeats a word id within an entry")
        totals = np.bincount(entry, weights, minlength=sizes.size)
        keep = totals[entry] > 0                                 # an entry of zero weight is empty, as in add()
        entry, words, weights = entry[keep], words[keep], weights[keep] / totals[entry[keep]]
        db = cls(voc)
        if sizes.size:                                           # (np.split of nothing gives one empty part)
            cuts = np.cumsum(np.bincount(entry, minlength=sizes.size))[:-1]
            db._words, db._weights = np.split(words, cuts), np.split(weights, cuts)
        return db

    @classmethod
    def load(cls, path) -> "BowDatabase":
        """Read a database written by :meth:`save` (with its vocabulary).

        The file is read by :func:`robokit.files.read_npz` within the vocabulary's file bounds and
        may hold at most :data:`MAX_ENTRIES` images.

        Raises
        ------
        DatabaseFileError
            If the file is not one (corrupt, truncated, another format, a device, beyond the bounds);
            FileNotFoundError if absent.
        """
        path = as_file_path(path)
        try:
            npz = read_npz(path, max_bytes=MAX_FILE_BYTES, max_values=MAX_FILE_VALUES)
            voc = Vocabulary.from_arrays({k[len("vocabulary_"):]: v for k, v in npz.items()
                                          if k.startswith("vocabulary_")}, str(path))
            sizes, words, weights = npz["entry_sizes"], npz["entry_words"], npz["entry_weights"]
            if sizes.size > MAX_ENTRIES:
                raise DatabaseFileError(f"path: {path} holds {sizes.size} entries, more than the {MAX_ENTRIES} "
                                        "a database file may")
            if sizes.sum() != words.size or words.size != weights.size or np.any(sizes < 0):
                raise DatabaseFileError(f"path: {path} has inconsistent entry arrays")
            return cls._from_entries(voc, sizes, words.astype(np.int64), weights.astype(float), path)
        except (DatabaseFileError, FileNotFoundError):
            raise
        except (VocabularyFileError, Exception) as err:
            raise DatabaseFileError(f"path: {path} is not a database saved by BowDatabase.save ({err})") from None
