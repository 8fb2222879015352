"""Motion capture of the LittleDog, simulated: the markers a Vicon system would report, with noise,
hidden markers and lost frames.

The LittleDog's body pose comes from a Vicon system: cameras see retroreflective markers on the
robot (LittleDog User Guide, Sec. 1) and the host reads the result at 100 Hz with the rest of the
robot's state (Sec. 2). :func:`simulate_mocap` makes the marker positions a trial would report,
from the simulator's true body poses: each marker gets Gaussian noise, each can be hidden (an
occlusion) and whole frames can be lost in bursts (the robot's own legs, a dropped packet). The fit
back to a pose is :mod:`robokit.legged.mocap`'s.

The sensor lives apart from the fit: assignment 04 asks students for the fit, and its grading
worker simulates markers for a written question, so this module and what it imports must hold no
fit (the fits live in :mod:`robokit.geometry.procrustes`, which no other geometry module imports).

Missing markers are a boolean mask ``visible``, never NaN: where ``visible`` is False the
position is set to 0 and means nothing.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Secs. 1-2).
.. [2] K. M. Lynch and F. C. Park, *Modern Robotics: Mechanics, Planning, and Control*, Cambridge
   University Press, 2017 (Definition 3.13, SE(3)).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..geometry.spatial import as_se3
from ..validation import as_points, as_rng, check_int, check_positive, check_sample_count

__all__ = ["MocapFrames", "simulate_mocap"]


class MocapFrames(NamedTuple):
    """What the MoCap reported over a trial."""

    #: (N, M, 3) marker positions in the world frame (m); 0 where not visible (meaningless there).
    positions: np.ndarray
    #: (N, M) True where the marker was seen.
    visible: np.ndarray


def _fraction(value: Any, name: str) -> float:
    p = check_positive(value, name, allow_zero=True)
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
    sigma = check_positive(noise, "noise", allow_zero=True)
    p_drop = _fraction(dropout, "dropout")
    p_burst = _fraction(bursts, "bursts")
    length = check_int(burst_length, "burst_length", minimum=1)
    check_sample_count(len(T) * len(m) * 3, "T_world_body, markers_body")
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
