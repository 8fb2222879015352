"""Motion capture of the LittleDog: the markers a Vicon system reports, and the body pose back from them.

The LittleDog's body pose comes from a Vicon system: cameras see retroreflective markers on the
robot (LittleDog User Guide, Sec. 1) and the host reads the result at 100 Hz with the rest of the
robot's state (Sec. 2). :func:`simulate_mocap` makes the marker positions a trial would report,
from the simulator's true body poses: each marker gets Gaussian noise, each can be hidden (an
occlusion) and whole frames can be lost in bursts (the robot's own legs, a dropped packet).
:func:`fit_marker_pose` recovers one frame's ``T_world_body`` from the visible markers by
:func:`robokit.geometry.fit_se3` (Arun et al. 1987; Umeyama 1991), :func:`mocap_body_poses` does a
whole trial at once and holds the last good pose where a frame has fewer than three markers.

Missing markers are a boolean mask ``visible``, never NaN: where ``visible`` is False the
position is set to 0 and means nothing.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Secs. 1-2).
.. [2] K. S. Arun, T. S. Huang and S. D. Blostein, "Least-squares fitting of two 3-D point sets",
   IEEE Trans. Pattern Analysis and Machine Intelligence 9(5), 698-700, 1987.
.. [3] S. Umeyama, "Least-squares estimation of transformation parameters between two point
   patterns", IEEE Trans. Pattern Analysis and Machine Intelligence 13(4), 376-380, 1991.
.. [4] K. M. Lynch and F. C. Park, *Modern Robotics: Mechanics, Planning, and Control*, Cambridge
   University Press, 2017 (Definition 3.13, SE(3)).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..geometry import DegenerateFitError, as_se3, fit_rigid, fit_se3
from ..validation import as_array, as_points, as_rng, as_int, as_positive, require_sample_count

__all__ = ["TooFewMarkersError", "MocapPoses", "fit_marker_pose", "mocap_body_poses", "MocapFrames",
           "simulate_mocap"]


class MocapFrames(NamedTuple):
    """What the MoCap reported over a trial."""

    #: (N, M, 3) marker positions in the world frame (m); 0 where not visible (meaningless there).
    positions: np.ndarray
    #: (N, M) True where the marker was seen.
    visible: np.ndarray


def _fraction(value: Any, name: str) -> float:
    p = as_positive(value, name, allow_zero=True)
    if p > 1.0:
        raise ValueError(f"{name}: expected a probability in [0, 1], got {p}")
    return p


def _poses(value: Any) -> np.ndarray:
    """Rigid transforms (N, 4, 4), N >= 1; a single (4, 4) promoted."""
    T = as_se3(value, "T_world_body", batch=True)
    T = T[None] if T.ndim == 2 else T
    if len(T) == 0:
        raise ValueError("T_world_body: expected at least one pose, got none")
    return T


def simulate_mocap(T_world_body: Any, markers_body: Any, noise: float, dropout: float, rng: Any = None, *,
                   bursts: float = 0.0, burst_length: int = 20) -> MocapFrames:
    """Marker positions a MoCap system reports for a trajectory of body poses.

    Parameters
    ----------
    T_world_body : array_like, shape (N, 4, 4) or (4, 4)
        True body poses, one per MoCap frame (100 Hz on the LittleDog).
    markers_body : array_like, shape (M, 3)
        Marker positions in the body frame (m), e.g. :data:`robokit.legged.MARKERS`.
    noise : float
        Standard deviation of the Gaussian noise on each coordinate of each marker (m, >= 0).
    dropout : float
        Probability that a marker is hidden in a frame, independently of the others (in [0, 1]).
    rng : numpy.random.Generator or int, optional
    bursts : float, default 0
        Probability per frame that a burst of lost frames starts there (in [0, 1]).
    burst_length : int, default 20
        Frames a burst hides every marker for (>= 1).

    Returns
    -------
    MocapFrames
        ``positions`` (N, M, 3) in the world frame and ``visible`` (N, M). Where ``visible`` is
        False the position is 0 and means nothing.

    Raises
    ------
    ValueError
        For poses that are not rigid transforms, markers not of shape (M, 3), a negative noise, or
        probabilities outside [0, 1].
    TypeError
        For an ``rng`` that is neither a Generator nor a non-negative integer seed.

    Notes
    -----
    The sensor model is ours (the guide gives none): ``p = R p_body + t + n`` with
    ``n ~ N(0, noise^2 I)``, a Bernoulli occlusion per marker and frame, and bursts that start as
    a Bernoulli process and last ``burst_length`` frames (they may overlap). The draws come in this
    order (noise, occlusions, burst starts) whatever the probabilities, so changing one of them
    keeps the others' draws.

    Examples
    --------
    >>> from robokit.geometry import se3_from_rt
    >>> T = se3_from_rt(np.eye(3), [1.0, 0.0, 0.13])[None]
    >>> frames = simulate_mocap(T, [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0]], noise=0.0, dropout=0.0, rng=0)
    >>> print(frames.positions[0], frames.visible.tolist())
    [[1.1  0.   0.13]
     [1.   0.1  0.13]] [[True, True]]
    """
    T = _poses(T_world_body)
    m = as_points(markers_body, "markers_body", 3, min_count=1)
    sigma = as_positive(noise, "noise", allow_zero=True)
    p_drop = _fraction(dropout, "dropout")
    p_burst = _fraction(bursts, "bursts")
    length = as_int(burst_length, "burst_length", minimum=1)
    require_sample_count(len(T) * len(m) * 3, "T_world_body, markers_body")
    gen = as_rng(rng)
    n = len(T)
    positions = np.einsum("nij,mj->nmi", T[:, :3, :3], m) + T[:, None, :3, 3]
    positions += gen.normal(0.0, 1.0, positions.shape) * sigma
    visible = gen.random((n, len(m))) >= p_drop
    starts = (gen.random(n) < p_burst).astype(float)
    lost = np.convolve(starts, np.ones(min(length, n)))[:n] > 0      # a burst covers its start and after
    visible[lost] = False
    positions[~visible] = 0.0
    return MocapFrames(positions, visible)


class TooFewMarkersError(DegenerateFitError):
    """Fewer than three markers are visible: a body pose cannot be fitted (a ``ValueError``)."""


class MocapPoses(NamedTuple):
    """Body poses fitted to a trial's markers."""

    #: (N, 4, 4) the fitted pose, or the last good one where ``ok`` is False.
    T_world_body: np.ndarray
    #: (N,) True where the frame had three or more visible markers (and they fixed a pose).
    ok: np.ndarray


def _markers(markers_body: Any) -> np.ndarray:
    return as_points(markers_body, "markers_body", 3, min_count=1)


def _visible(visible: Any, shape: tuple) -> np.ndarray:
    return as_array(visible, "visible", shape=shape, dtype=bool)


def fit_marker_pose(markers_body: Any, observed: Any, visible: Any = None) -> np.ndarray:
    """The body pose of one MoCap frame: a least-squares rigid fit of the visible markers.

    Parameters
    ----------
    markers_body : array_like, shape (M, 3)
        Marker positions in the body frame (m).
    observed : array_like, shape (M, 3)
        Where the MoCap saw them in the world frame (m); ignored where not visible.
    visible : array_like of bool, shape (M,), optional
        Which markers were seen (default: all).

    Returns
    -------
    numpy.ndarray, shape (4, 4)
        ``T_world_body`` minimising ``sum |T @ marker - observed|^2`` over the visible markers.

    Raises
    ------
    TooFewMarkersError
        (A ``ValueError``) if fewer than three markers are visible.
    DegenerateFitError
        (A ``ValueError``) if the visible markers lie on one line.
    ValueError
        For shapes that do not agree or NaN/inf in a visible marker.

    Notes
    -----
    :func:`robokit.geometry.fit_se3`: Arun et al. (1987) with Umeyama's (1991) reflection guard,
    Eqs. (34)-(41) and (43) without scale.

    Examples
    --------
    >>> from robokit.geometry import rot_z, se3_from_rt, transform_points
    >>> markers = np.array([[0.10, 0.03, 0.0115], [0.10, -0.04, 0.0115], [-0.11, 0.035, 0.0115],
    ...                     [-0.05, -0.02, 0.04]])
    >>> seen = transform_points(se3_from_rt(rot_z(0.5), [1.0, 2.0, 0.13]), markers)
    >>> seen[1] = 0.0                                      # marker 1 hidden
    >>> T = fit_marker_pose(markers, seen, [True, False, True, True])
    >>> print(np.round(T[:3, 3], 6), round(float(np.arctan2(T[1, 0], T[0, 0])), 6))
    [1.   2.   0.13] 0.5
    """
    m = _markers(markers_body)
    obs = as_array(observed, "observed", shape=m.shape, finite=False)
    vis = np.ones(len(m), bool) if visible is None else _visible(visible, (len(m),))
    if vis.sum() < 3:
        raise TooFewMarkersError(f"visible: expected at least 3 visible markers for a body pose, got {int(vis.sum())}")
    if not np.all(np.isfinite(obs[vis])):
        raise ValueError("observed: expected finite positions of the visible markers, got NaN or infinity")
    try:
        return fit_se3(m[vis], obs[vis])
    except DegenerateFitError:
        raise DegenerateFitError("markers_body, observed: expected visible markers that are not all on one line "
                                 "(relative to their spread), got a degenerate set") from None


def mocap_body_poses(markers_body: Any, observed: Any, visible: Any) -> MocapPoses:
    """Body poses of a whole MoCap trial, holding the last good pose through lost frames.

    Parameters
    ----------
    markers_body : array_like, shape (M, 3)
        Marker positions in the body frame (m).
    observed : array_like, shape (N, M, 3)
        Marker positions per frame in the world frame (m); ignored where not visible.
    visible : array_like of bool, shape (N, M)

    Returns
    -------
    MocapPoses
        ``T_world_body`` (N, 4, 4) and ``ok`` (N,). A frame is ok when three or more markers are
        visible and they do not lie on one line. A frame that is not ok holds the pose of the last
        ok frame before it (what a host loop would still have); frames before the first ok one hold
        the first ok pose. Either way ``ok`` is False there: an estimator must not treat them as
        measurements.

    Raises
    ------
    TooFewMarkersError
        (A ``ValueError``) if no frame of the trial has a pose (naming ``visible``).
    ValueError
        For shapes that do not agree, no frames, or NaN/inf in a visible marker.

    Notes
    -----
    All frames are fitted in one batch by :func:`robokit.geometry.fit_rigid` (Umeyama 1991,
    Eqs. (34)-(41) and (43)) with weight 1 on the visible markers and 0 on the hidden ones; the
    hold is a forward fill of the index of the last ok frame.

    Examples
    --------
    >>> from robokit.geometry import se3_from_rt
    >>> from robokit.legged.mocap import simulate_mocap
    >>> markers = np.array([[0.10, 0.03, 0.0115], [0.10, -0.04, 0.0115], [-0.11, 0.035, 0.0115],
    ...                     [-0.05, -0.02, 0.04]])
    >>> truth = se3_from_rt(np.eye(3)[None].repeat(3, 0), [[0.0, 0, 0.13], [0.01, 0, 0.13], [0.02, 0, 0.13]])
    >>> frames = simulate_mocap(truth, markers, noise=0.0, dropout=0.0, rng=0)
    >>> frames.visible[1, :2] = False                     # frame 1 sees only two markers
    >>> poses = mocap_body_poses(markers, frames.positions, frames.visible)
    >>> print(poses.ok.tolist(), np.round(poses.T_world_body[:, 0, 3], 6))
    [True, False, True] [0.   0.   0.02]
    """
    m = _markers(markers_body)
    obs = as_array(observed, "observed", shape=(None, len(m), 3), finite=False)
    if len(obs) == 0:
        raise ValueError("observed: expected at least one frame, shape (N, M, 3), got none")
    vis = _visible(visible, obs.shape[:2])
    if not np.all(np.isfinite(obs[vis])):
        raise ValueError("observed: expected finite positions of the visible markers, got NaN or infinity")
    n = len(obs)
    ok = vis.sum(1) >= 3
    T = np.zeros((n, 4, 4))
    if ok.any():
        fit = fit_rigid(np.broadcast_to(m, (int(ok.sum()),) + m.shape), np.where(vis[ok][..., None], obs[ok], 0.0),
                        vis[ok].astype(float), validate=False)
        T[ok, :3, :3], T[ok, :3, 3], T[:, 3, 3] = fit.R, fit.t, 1.0
        ok[ok] = ~fit.degenerate
    if not ok.any():
        raise TooFewMarkersError(f"visible, markers_body, observed: expected a frame with at least 3 visible markers "
                                 f"not all on one line, got none in {n} frames")
    last = np.maximum.accumulate(np.where(ok, np.arange(n), -1))
    last[last < 0] = int(np.argmax(ok))
    return MocapPoses(T[last], ok)
