"""The results of lesson 03's global-localization runs: one run, and the runs of one method (Table 2).

Ge et al. (2023), Sec. 4.1 and Table 2 count a run as a success when the filter converges to within
0.05 m and 0.5 degrees of the truth (:data:`PAPER_TOLERANCE`); :class:`TrialResult` holds one run of
:func:`robocourse.lessons.corridor_localization.trials.localization_trial` and :class:`TrialSet` the runs of
:func:`robocourse.lessons.corridor_localization.trials.localization_trials`, with the test of that criterion.

References
----------
.. [1] G. Ge, Y. Zhang, W. Wang, L. Hu, Y. Wang and Q. Jiang, "Visual-feature-assisted mobile robot
   localization in a long corridor environment", *Frontiers of Information Technology & Electronic
   Engineering* 24(6), 2023, doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from robokit.validation import as_array

__all__ = ["PAPER_TOLERANCE", "TrialResult", "TrialSet"]

#: The paper's success criterion (Sec. 4.1): 0.05 m and 0.5 degrees.
PAPER_TOLERANCE = (0.05, float(np.deg2rad(0.5)))


@dataclasses.dataclass
class TrialResult:
    """One global-localization run.

    Attributes
    ----------
    method : str
    start : numpy.ndarray (3,)
    converged : bool
    iterations : int
        Filter updates until convergence (or until the run gave up).
    distance : float
        Metres driven from the start (the moving strategy included).
    error : numpy.ndarray (2,)
        Position (m) and heading (rad) error of the estimate against the truth at convergence (NaN
        when the filter never converged).
    settled : numpy.ndarray (2,)
        The same, ``settle`` updates later (or when the run ended).
    retrieval_error : float
        Ours: distance from the retrieved keyframe's geo-tag to the true position (NaN for AMCL).
    truth, estimates : numpy.ndarray (K, 3)
        True poses and the filter's estimates at each update.
    particles : list of numpy.ndarray or None
        The cloud at the start and after each update (only when asked for).
    """

    method: str
    start: np.ndarray
    converged: bool
    iterations: int
    distance: float
    error: np.ndarray
    settled: np.ndarray
    retrieval_error: float
    truth: np.ndarray
    estimates: np.ndarray
    particles: list | None = None


@dataclasses.dataclass
class TrialSet:
    """The runs of one method from every start (Table 2).

    Attributes
    ----------
    method : str
    positions : numpy.ndarray of int, shape (n,)
        The start's index in :data:`~robocourse.lessons.corridor_localization.trials.START_POSES` (0-based) for each run.
    converged : numpy.ndarray of bool, shape (n,)
    iterations : numpy.ndarray of int, shape (n,)
    distance : numpy.ndarray, shape (n,)
        Metres driven.
    error : numpy.ndarray, shape (n, 2)
        Position (m) and heading (rad) error at convergence (NaN when not converged).
    settled : numpy.ndarray, shape (n, 2)
        The same, :data:`~robocourse.lessons.corridor_localization.trials.SETTLE` updates after convergence.
    retrieval_error : numpy.ndarray, shape (n,)
        Ours: the retrieved keyframe's distance from the truth (NaN for AMCL).
    """

    method: str
    positions: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray
    distance: np.ndarray
    error: np.ndarray
    settled: np.ndarray
    retrieval_error: np.ndarray

    def success(self, tolerance: Any = PAPER_TOLERANCE, *, settled: bool = False) -> np.ndarray:
        """Runs that converged within ``tolerance`` = (metres, radians) of the truth (default the paper's).

        ``settled=True`` judges the estimate :data:`~robocourse.lessons.corridor_localization.trials.SETTLE` updates after convergence instead.

        Examples
        --------
        >>> errors = np.array([[0.03, 0.001], [np.nan, np.nan]])
        >>> runs = TrialSet("ours", np.zeros(2, int), np.array([True, False]), np.array([3, 40]),
        ...                 np.array([0.5, 40.0]), errors, errors / 2, np.full(2, np.nan))
        >>> runs.success().tolist(), runs.success((0.01, 0.1)).tolist(), runs.success((0.02, 0.1), settled=True).tolist()
        ([True, False], [False, False], [True, False])
        """
        tol = as_array(tolerance, "tolerance", shape=(2,))
        if np.any(tol <= 0):
            raise ValueError(f"tolerance: expected positive (metres, radians), got {tol.tolist()}")
        err = np.nan_to_num(self.settled if settled else self.error, nan=np.inf)
        return self.converged & (err[:, 0] <= tol[0]) & (err[:, 1] <= tol[1])
