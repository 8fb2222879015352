"""Landmark database with per-landmark Kalman filters (Se, Lowe & Little, Sec. 3).

Every landmark keeps its 3-D position in the initial (world) frame, a 3 x 3 covariance, a
descriptor (with the keypoint's scale and orientation for the matching constraints) and a count of
consecutive frames in which it was not matched. A new observation is transformed backwards into
the world frame with the pose covariance propagated (:func:`transform_covariance`) and fused with
the landmark by the information-form Kalman update of Sec. 3.5. Poses are the papers'
``[p, q, theta]`` (:mod:`robokit.geometry.paper_frames`).

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [2] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..geometry import pqt_robot_to_world, pqt_to_se3, pqt_world_to_robot
from ..geometry.paper_frames import as_pqt, pqt_transform_xz
from ..vision.matching import pair_distances
from ..validation import array_ndim, as_array, as_int, as_positive

__all__ = ["transform_covariance", "kalman_fuse", "LandmarkMap"]


def transform_covariance(points, covariances, pqt, pqt_covariance) -> tuple[np.ndarray, np.ndarray]:
    """Backward transformation of observations into the world frame with first-order covariance.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Observed positions in the robot frame.
    covariances : array_like, shape (N, 3, 3)
        Their covariances (e.g. from :func:`robokit.vision.stereo.disparity_to_point`).
    pqt : array_like, shape (3,)
        Robot pose ``[p, q, theta]``.
    pqt_covariance : array_like, shape (3, 3)
        Covariance of the pose estimate.

    Returns
    -------
    points_world : numpy.ndarray, shape (N, 3)
    covariances_world : numpy.ndarray, shape (N, 3, 3)
        ``R Sigma_obs R^T + J Sigma_pose J^T`` with ``J = d r_new / d(p, q, theta)``.

    Raises
    ------
    ValueError
        For shapes that do not agree or values that are not finite.

    Notes
    -----
    Se et al. Sec. 3.3-3.4: the pose uncertainty is propagated to the landmark by first-order
    analysis; with a 3-DoF pose the 12 x 12 form of the paper reduces to these two terms.

    Examples
    --------
    A point 2 m ahead, known exactly, seen from a pose whose heading is uncertain by 0.01 rad,
    is uncertain by 2 cm sideways in the world:

    >>> pts, cov = transform_covariance([[0.0, 0.0, 2.0]], np.zeros((1, 3, 3)), [0.0, 0.0, 0.0],
    ...                                 np.diag([0.0, 0.0, 0.01**2]))
    >>> print(np.round(np.sqrt(np.diag(cov[0])), 4))
    [0.02 0.   0.  ]
    """
    pts = as_array(points, "points", shape=(None, 3))
    cov = as_array(covariances, "covariances", shape=(pts.shape[0], 3, 3))
    p = as_pqt(pqt)
    pcov = as_array(pqt_covariance, "pqt_covariance", shape=(3, 3))
    rot = pqt_to_se3(p)[:3, :3]
    world = pqt_robot_to_world(pts, p, validate=False)              # r_new = P(r_obs) + V, Sec. 3.3
    jac = np.zeros((pts.shape[0], 3, 3))                       # d r_new / d(p, q, theta); Y is fixed
    jac[:, ::2] = pqt_transform_xz(p, pts[:, ::2], jacobian=True, validate=False)[1]
    out = rot @ cov @ rot.T + jac @ pcov @ np.swapaxes(jac, 1, 2)   # first-order propagation, Sec. 3.4
    return world, out


def _covariances(value, name, n):
    cov = as_array(value, name, shape=(n, 3, 3))
    if not np.allclose(cov, np.swapaxes(cov, 1, 2), atol=1e-12 + 1e-9 * np.abs(cov).max(initial=0)):
        raise ValueError(f"{name}: expected symmetric 3 x 3 covariances, got a non-symmetric one")
    if n and np.any(np.linalg.eigvalsh(cov)[:, 0] <= 0):
        raise ValueError(f"{name}: expected positive-definite covariances, got a singular or indefinite one")
    return cov


def kalman_fuse(s, sigma, r_new, sigma_new) -> tuple[np.ndarray, np.ndarray]:
    """Fuse landmark estimates with new observations (information-form Kalman update).

    Parameters
    ----------
    s : array_like, shape (3,) or (N, 3)
        Landmark positions ``s_KF`` in the database.
    sigma : array_like, shape (3, 3) or (N, 3, 3)
        Their covariances ``Sigma_KF`` (positive definite).
    r_new : array_like, shape like ``s``
        New observations transformed into the same frame.
    sigma_new : array_like, shape like ``sigma``
        Their covariances.

    Returns
    -------
    s_fused : numpy.ndarray
        ``Sigma' (Sigma_KF^-1 s_KF + Sigma_new^-1 r_new)``.
    sigma_fused : numpy.ndarray
        ``Sigma' = (Sigma_KF^-1 + Sigma_new^-1)^-1``.

    Raises
    ------
    ValueError
        For mismatched shapes or covariances that are not symmetric positive definite.

    Notes
    -----
    Se, Lowe & Little, Sec. 3.5 ("Filter update"). The fused covariance is never larger than
    either input, so a landmark's uncertainty ellipse shrinks as it is re-observed (Sec. 3.6).
    """
    single = array_ndim(s, "s") == 1
    pts = as_array(s, "s", shape=(3,) if single else (None, 3))
    n = 1 if single else pts.shape[0]
    cshape = (3, 3) if single else (n, 3, 3)
    new = as_array(r_new, "r_new", shape=pts.shape).reshape(n, 3)
    cov = _covariances(as_array(sigma, "sigma", shape=cshape).reshape(n, 3, 3), "sigma", n)
    cov_new = _covariances(as_array(sigma_new, "sigma_new", shape=cshape).reshape(n, 3, 3), "sigma_new", n)
    mean, fused = _fuse(pts.reshape(n, 3), cov, new, cov_new)
    return (mean[0], fused[0]) if single else (mean, fused)


def _fuse(pts: np.ndarray, cov: np.ndarray, new: np.ndarray, cov_new: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unchecked :func:`kalman_fuse` on stacks: (N, 3) positions, (N, 3, 3) covariances."""
    info, info_new = np.linalg.inv(cov), np.linalg.inv(cov_new)
    fused = np.linalg.inv(info + info_new)
    fused = 0.5 * (fused + np.swapaxes(fused, 1, 2))
    mean = np.einsum("nij,nj->ni", fused, np.einsum("nij,nj->ni", info, pts) + np.einsum("nij,nj->ni", info_new, new))
    return mean, fused


def greedy_one_to_one(fi: np.ndarray, li: np.ndarray, out: np.ndarray) -> np.ndarray:
    """Greedy one-to-one assignment of pairs listed best first; ``out[f] = l`` for the chosen pairs.

    Vectorised in rounds: a pair that comes first for both its feature and its landmark among the
    pairs left is exactly one the sequential greedy scan would take, so each round takes all of
    them and drops the pairs they conflict with (same result as the scan, far fewer Python steps).
    """
    while fi.size:
        _, first_f = np.unique(fi, return_index=True)
        _, first_l = np.unique(li, return_index=True)
        pick = np.intersect1d(first_f, first_l)
        out[fi[pick]] = li[pick]
        keep = ~np.isin(fi, fi[pick]) & ~np.isin(li, li[pick])
        fi, li = fi[keep], li[keep]
    return out


class LandmarkMap:
    """The database map of 3-D landmarks with uncertainty (Se et al. Sec. 3; Lin et al. Sec. V).

    Parameters
    ----------
    descriptor_size : int
        Length of the stored descriptors (128 or 16).
    max_missed : int, default 20
        A landmark is dropped once it has gone unmatched for more than this many consecutive
        frames (Se et al. Sec. 3.2: kept through temporary occlusion, dropped otherwise).

    Attributes
    ----------
    positions : numpy.ndarray, shape (N, 3)
        World-frame positions (metres).
    covariances : numpy.ndarray, shape (N, 3, 3)
    descriptors : numpy.ndarray, shape (N, D), float32
    scales, orientations : numpy.ndarray, shape (N,)
        Keypoint scale (pixels) and orientation (radians) at the first observation.
    missed : numpy.ndarray of int, shape (N,)
        Consecutive unmatched frames.
    observations : numpy.ndarray of int, shape (N,)
        Number of times each landmark was observed.
    ids : numpy.ndarray of int, shape (N,)
        Stable identifiers (never reused).
    """

    def __init__(self, descriptor_size: int, *, max_missed: int = 20):
        self.descriptor_size = as_int(descriptor_size, "descriptor_size", minimum=1)
        self.max_missed = as_int(max_missed, "max_missed", minimum=0)
        self.positions = np.zeros((0, 3))
        self.covariances = np.zeros((0, 3, 3))
        self.descriptors = np.zeros((0, self.descriptor_size), np.float32)
        self.scales = np.zeros(0)
        self.orientations = np.zeros(0)
        self.missed = np.zeros(0, int)
        self.observations = np.zeros(0, int)
        self.ids = np.zeros(0, int)
        self._next_id = 0

    def __len__(self) -> int:
        return self.positions.shape[0]

    #: The arrays of :meth:`to_arrays`, in order.
    ARRAYS = ("positions", "covariances", "descriptors", "scales", "orientations", "missed", "observations", "ids")

    def to_arrays(self, prefix: str = "") -> dict:
        """The map as plain arrays (for a cache file), named ``prefix + name``.

        Parameters
        ----------
        prefix : str, default ""

        Returns
        -------
        dict of str to numpy.ndarray
            :attr:`ARRAYS`, plus ``max_missed`` and ``next_id`` (the next identifier to hand out).

        Examples
        --------
        >>> import numpy as np
        >>> m = LandmarkMap(2)
        >>> _ = m.add(np.ones((1, 3)), np.eye(3)[None], np.zeros((1, 2)))
        >>> again = LandmarkMap.from_arrays(m.to_arrays("map:"), "map:")
        >>> len(again), again.descriptor_size, int(again.add(np.ones((1, 3)), np.eye(3)[None], np.zeros((1, 2)))[0])
        (1, 2, 1)
        """
        out = {prefix + name: getattr(self, name) for name in self.ARRAYS}
        out[prefix + "max_missed"] = np.array(self.max_missed)
        out[prefix + "next_id"] = np.array(self._next_id)
        return out

    @classmethod
    def from_arrays(cls, arrays: dict, prefix: str = "") -> "LandmarkMap":
        """The map that :meth:`to_arrays` wrote.

        Parameters
        ----------
        arrays : mapping of str to array_like
        prefix : str, default ""

        Returns
        -------
        LandmarkMap

        Raises
        ------
        ValueError
            For missing arrays, descriptors that are not a 2-D table, or arrays of unequal lengths.

        Examples
        --------
        >>> LandmarkMap.from_arrays({}) # doctest: +IGNORE_EXCEPTION_DETAIL
        Traceback (most recent call last):
        ValueError: arrays: expected the arrays of LandmarkMap.to_arrays ...
        """
        names = (*cls.ARRAYS, "max_missed", "next_id")
        missing = [prefix + n for n in names if prefix + n not in arrays]
        if missing:
            raise ValueError(f"arrays: expected the arrays of LandmarkMap.to_arrays, missing {missing}")
        descriptors = np.asarray(arrays[prefix + "descriptors"], np.float32)
        if descriptors.ndim != 2:
            raise ValueError(f"arrays: expected {prefix}descriptors of shape (N, D), got shape {descriptors.shape}")
        out = cls(descriptors.shape[1], max_missed=int(arrays[prefix + "max_missed"]))
        for name in cls.ARRAYS:
            setattr(out, name, np.asarray(arrays[prefix + name], getattr(out, name).dtype))
        if len({len(getattr(out, name)) for name in cls.ARRAYS}) != 1:
            raise ValueError(f"arrays: expected equal lengths of {list(cls.ARRAYS)}, got "
                             f"{[len(getattr(out, name)) for name in cls.ARRAYS]}")
        out._next_id = int(arrays[prefix + "next_id"])
        return out

    def add(self, positions, covariances, descriptors, scales=None, orientations=None) -> np.ndarray:
        """Append new landmarks (world frame); return their ids.

        Raises
        ------
        ValueError
            For shapes that do not agree or invalid covariances.

        Notes
        -----
        Se et al. Sec. 3.6: "A Kalman Filter is initiated for each landmark"; the descriptor is kept
        for later matching (Se et al. Sec. 4, Lin et al. Sec. 3).
        """
        pts = as_array(positions, "positions", shape=(None, 3))
        n = pts.shape[0]
        cov = _covariances(covariances, "covariances", n)
        desc = as_array(descriptors, "descriptors", shape=(n, self.descriptor_size), dtype=np.float32)
        sc = np.ones(n) if scales is None else as_array(scales, "scales", shape=(n,))
        ori = np.zeros(n) if orientations is None else as_array(orientations, "orientations", shape=(n,))
        ids = np.arange(self._next_id, self._next_id + n)
        self._next_id += n
        self.positions = np.vstack([self.positions, pts])
        self.covariances = np.concatenate([self.covariances, cov])
        self.descriptors = np.vstack([self.descriptors, desc])
        self.scales = np.concatenate([self.scales, sc])
        self.orientations = np.concatenate([self.orientations, ori])
        self.missed = np.concatenate([self.missed, np.zeros(n, int)])
        self.observations = np.concatenate([self.observations, np.ones(n, int)])
        self.ids = np.concatenate([self.ids, ids])
        return ids

    def _index(self, index) -> np.ndarray:
        idx = as_array(index, "index", ndim=1, dtype=int)
        if idx.size and (idx.min() < 0 or idx.max() >= len(self)):
            raise ValueError(f"index: expected rows in [0, {len(self)}), got {idx.min()}..{idx.max()}")
        if np.unique(idx).size != idx.size:
            raise ValueError("index: expected each landmark at most once per update, got duplicates")
        return idx

    def fuse(self, index, positions, covariances) -> None:
        """Kalman-update the landmarks in rows ``index`` with world-frame observations.

        Notes
        -----
        Se et al. Sec. 3.5, :func:`kalman_fuse` (the map's own landmarks are not checked again, only
        the observations); resets the landmarks' missed counters.
        """
        idx = self._index(index)
        if idx.size == 0:
            return
        new = as_array(positions, "positions", shape=(idx.size, 3))
        cov_new = _covariances(covariances, "covariances", idx.size)
        s, cov = _fuse(self.positions[idx], self.covariances[idx], new, cov_new)
        self.positions[idx], self.covariances[idx] = s, cov
        self.missed[idx] = 0
        self.observations[idx] += 1

    def end_frame(self, matched, expected=None) -> np.ndarray:
        """Count a frame: unmatched landmarks age, those unmatched too long are dropped.

        Parameters
        ----------
        matched : array_like of int
            Rows matched in this frame.
        expected : array_like of bool, shape (N,), optional
            Landmarks predicted to be in view in this frame. When given, only expected but
            unmatched landmarks age; the others (behind the robot, out of the field of view) keep
            their count, so the map of places visited long ago survives. Default: all age.

        Returns
        -------
        numpy.ndarray of int
            Ids of the dropped landmarks.

        Notes
        -----
        Se et al. Sec. 3.2: a landmark is discarded from the database once it has gone unmatched
        for more than a set number of consecutive frames (here: frames in which it was expected).
        """
        idx = self._index(matched)
        ages = np.ones(len(self), bool) if expected is None else as_array(expected, "expected", shape=(len(self),),
                                                                           dtype=bool)
        seen = np.zeros(len(self), bool)
        seen[idx] = True
        self.missed[~seen & ages] += 1
        self.missed[seen] = 0
        drop = self.missed > self.max_missed
        dropped = self.ids[drop]
        if drop.any():
            keep = ~drop
            for name in ("positions", "covariances", "descriptors", "scales", "orientations", "missed",
                         "observations", "ids"):
                setattr(self, name, getattr(self, name)[keep])
        return dropped

    def associate(self, points, covariances, descriptors, pqt, *, window: float = 1.0, gate: float = 14.16,
                  max_distance: float = 0.8) -> np.ndarray:
        """Data association at a known pose: the landmark each observation re-observes, or -1.

        Parameters
        ----------
        points, covariances : array_like, shapes (N, 3), (N, 3, 3)
            Observations in the robot frame and their covariances.
        descriptors : array_like, shape (N, D)
        pqt : array_like, shape (3,)
            Robot pose ``[p, q, theta]`` (e.g. the RANSAC estimate).
        window : float, default 1.0
            Landmarks predicted farther than this (metres) are not considered.
        gate : float, default 14.16
            Squared Mahalanobis distance gate with covariance
            ``Sigma_obs + R^T Sigma_landmark R`` (14.16 is the 99.73 % chi-square quantile with 3 dof,
            the 3-D "3 sigma").
        max_distance : float, default 0.8
            Maximum descriptor distance.

        Returns
        -------
        numpy.ndarray of int, shape (N,)
            Landmark row per observation; among the gated candidates the nearest descriptor wins,
            and a landmark claimed by several observations goes to the nearest descriptor.

        Notes
        -----
        Se et al. Sec. 3.2 (predict the database landmarks in the new frame, look for matches in
        the vicinity, verify them) with the uncertainty of Sec. 3.1 deciding "the vicinity".
        """
        pts = as_array(points, "points", shape=(None, 3))
        n = pts.shape[0]
        cov = as_array(covariances, "covariances", shape=(n, 3, 3))
        desc = as_array(descriptors, "descriptors", shape=(n, self.descriptor_size), dtype=np.float32)
        window = as_positive(window, "window")
        gate = as_positive(gate, "gate")
        max_distance = as_positive(max_distance, "max_distance")
        out = -np.ones(n, int)
        if n == 0 or len(self) == 0:
            return out
        rot = pqt_to_se3(pqt)[:3, :3]
        predicted = pqt_world_to_robot(self.positions, pqt)
        lists = cKDTree(predicted).query_ball_point(pts, window)
        counts = np.array([len(x) for x in lists])
        if counts.sum() == 0:
            return out
        fi = np.repeat(np.arange(n), counts)
        li = np.concatenate([np.asarray(x, int) for x in lists if x])
        dd = pair_distances(desc, self.descriptors, fi, li, precision="float32", validate=False)
        alike = dd <= max_distance                 # the cheap test first: only these need the gate
        fi, li, dd = fi[alike], li[alike], dd[alike]
        err = pts[fi] - predicted[li]
        joint = cov[fi] + rot.T @ self.covariances[li] @ rot
        m2 = np.einsum("ni,ni->n", err, np.linalg.solve(joint, err[:, :, None])[:, :, 0])
        ok = m2 <= gate
        fi, li, dd = fi[ok], li[ok], dd[ok]
        order = np.argsort(dd, kind="stable")
        return greedy_one_to_one(fi[order], li[order], out)

    def integrate(self, points, covariances, descriptors, pqt, pqt_covariance, landmark,
                  scales=None, orientations=None, expected=None) -> np.ndarray:
        """One frame of map building: backward transformation, fusion, insertion and ageing.

        Parameters
        ----------
        points, covariances : array_like, shapes (N, 3), (N, 3, 3)
            Stereo observations in the robot frame and their covariances.
        descriptors : array_like, shape (N, D)
        pqt, pqt_covariance : array_like, shapes (3,), (3, 3)
            Robot pose ``[p, q, theta]`` and its covariance.
        landmark : array_like of int, shape (N,)
            Row of the matched landmark per observation, or -1 for a new landmark.
        scales, orientations : array_like, shape (N,), optional
        expected : array_like of bool, shape (len(self),), optional
            Landmarks (before this update) predicted in view; see :meth:`end_frame`.

        Returns
        -------
        numpy.ndarray of int, shape (N,)
            The landmark id of every observation (new ids for new landmarks).

        Notes
        -----
        Se et al. Sec. 3.3-3.5 and Lin et al. Sec. V (the database is updated incrementally).
        """
        pts = as_array(points, "points", shape=(None, 3))
        n = pts.shape[0]
        lm = as_array(landmark, "landmark", shape=(n,), dtype=int)
        if np.any(lm >= len(self)) or np.any(lm < -1):
            raise ValueError(f"landmark: expected -1 or rows in [0, {len(self)}), got {lm.min()}..{lm.max()}")
        before = len(self)
        if expected is not None:
            expected = as_array(expected, "expected", shape=(before,), dtype=bool)
        world, cov = transform_covariance(pts, covariances, pqt, pqt_covariance)
        old = lm >= 0
        self.fuse(lm[old], world[old], cov[old])
        out = np.empty(n, int)
        out[old] = self.ids[lm[old]]
        desc = as_array(descriptors, "descriptors", shape=(n, self.descriptor_size), dtype=np.float32)
        new = ~old
        sc = None if scales is None else as_array(scales, "scales", shape=(n,))[new]
        ori = None if orientations is None else as_array(orientations, "orientations", shape=(n,))[new]
        out[new] = self.add(world[new], cov[new], desc[new], sc, ori)
        matched_rows = np.nonzero(np.isin(self.ids, out))[0]
        if expected is not None:  # new landmarks were seen now
            expected = np.concatenate([expected, np.ones(len(self) - before, bool)])
        self.end_frame(matched_rows, expected)
        return out
