"""A generator of planar pose graphs with ground truth: a robot walking a Manhattan grid.

Like Olson et al.'s (2006) synthetic "Manhattan world" M3500 (3500 poses, about 5450 edges): the
robot moves one metre per step along the lines of a square grid, sometimes turning by 90 degrees;
odometry edges join consecutive poses and a loop-closure edge joins a pose to an earlier pose at
the same grid point. Every measurement is the true relative pose perturbed by Gaussian noise, and
the initial estimate is dead reckoning (the noisy odometry composed), which drifts.

References
----------
.. [1] E. Olson, J. Leonard and S. Teller, "Fast iterative alignment of pose graphs with poor
   initial estimates", Proc. IEEE Int. Conf. on Robotics and Automation (ICRA), 2262-2269, 2006.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..geometry import se2_between, se2_compose, wrap_angle
from ..validation import as_array, as_rng, broadcast_to, as_finite_scalar, as_int
from .pose_graph import PoseGraph

__all__ = ["manhattan_world_graph"]

_TURNS = np.array([0.0, np.pi / 2, -np.pi / 2, np.pi])


def _walk(n: int, extent: int, turn_probability: float, rng: np.random.Generator) -> np.ndarray:
    """Grid points and headings (multiples of pi/2) of a random walk kept inside the square."""
    cells = np.zeros((n, 2), np.int64)
    heading = np.zeros(n, np.int64)                                   # in quarter turns
    steps = np.array([[1, 0], [0, 1], [-1, 0], [0, -1]])
    for k in range(1, n):
        turn = 0 if rng.random() >= turn_probability else rng.choice([1, 3])
        for extra in (0, 2, 1, 3):                                    # straight/turn, else try the others
            h = (heading[k - 1] + turn + extra) % 4
            nxt = cells[k - 1] + steps[h]
            if np.all(np.abs(nxt) <= extent):
                break
        cells[k], heading[k] = nxt, h
    return np.column_stack([cells.astype(float), wrap_angle(heading * np.pi / 2)])


def manhattan_world_graph(n_poses: int = 3500, *, seed: int = 0, noise: Any = (0.05, 0.05, 0.01), extent: int = 10,
                          closure_probability: float = 0.6, min_gap: int = 10) -> tuple[PoseGraph, np.ndarray]:
    """A Manhattan-world pose graph with its ground truth.

    Parameters
    ----------
    n_poses : int, default 3500
        Number of poses (>= 1); 3500 gives about as many edges as Olson's M3500.
    seed : int, default 0
        Seeds the walk, the loop closures and the noise.
    noise : float or array_like, shape (3,), default (0.05, 0.05, 0.01)
        Standard deviations ``[x, y, theta]`` [m, m, rad] of the noise added to every measurement;
        the graph's information is ``diag(1 / noise^2)`` (the model is right).
    extent : int, default 10
        The walk stays within ``|x|, |y| <= extent`` metres (a grid of ``(2 extent + 1)^2`` points).
    closure_probability : float, default 0.6
        Probability that a pose at a grid point visited at least ``min_gap`` steps before gets a
        loop-closure edge (to one such earlier pose, drawn at random).
    min_gap : int, default 10
        Fewest steps between the two poses of a loop closure.

    Returns
    -------
    graph : PoseGraph
        Odometry edges ``(k, k + 1)`` first, then loop closures ``(earlier, later)``; initial poses
        by dead reckoning from the true first pose ``[0, 0, 0]``, which is the fixed node.
    truth : numpy.ndarray, shape (N, 3)
        The true poses (on the grid, headings multiples of pi/2).

    Raises
    ------
    ValueError
        For non-positive noise or sizes, or a probability outside [0, 1].

    Notes
    -----
    After Olson et al. (2006), Sec. V (their synthetic Manhattan data set); our walk, turn rule and
    noise are our own. Each measurement is ``z = se2_compose(z_true, n)`` with
    ``n ~ N(0, diag(noise^2))``, so g2o's error at the truth is ``-n`` rotated by ``n_theta``.

    Examples
    --------
    >>> g, truth = manhattan_world_graph(200, seed=1)
    >>> g.n_poses, g.n_edges, truth.shape
    (200, 229, (200, 3))
    >>> print(np.round(truth[:3], 3) + 0.0)
    [[0. 0. 0.]
     [1. 0. 0.]
     [2. 0. 0.]]
    """
    n = as_int(n_poses, "n_poses", minimum=1, maximum=10 ** 6)
    seed = as_int(seed, "seed", minimum=0)
    sig = broadcast_to(as_array(noise, "noise"), (3,), "noise", "[x, y, theta] standard deviations")
    with np.errstate(over="ignore", under="ignore", divide="ignore"):
        info = 1.0 / sig ** 2
    if not np.all((sig > 0) & (info > 0) & np.isfinite(info)):
        raise ValueError(f"noise: expected positive standard deviations between 1e-150 and 1e150, got {sig.tolist()}")
    extent = as_int(extent, "extent", minimum=1, maximum=10 ** 6)
    p = as_finite_scalar(closure_probability, "closure_probability")
    if not 0.0 <= p <= 1.0:
        raise ValueError(f"closure_probability: expected a probability in [0, 1], got {p}")
    min_gap = as_int(min_gap, "min_gap", minimum=1)
    rng = as_rng(seed, "seed")
    truth = _walk(n, extent, 0.3, rng)
    visits: dict[tuple[int, int], list[int]] = {}
    closures = []
    for k, (x, y) in enumerate(truth[:, :2].astype(np.int64)):
        earlier = [e for e in visits.get((x, y), []) if k - e >= min_gap]
        if earlier and rng.random() < p:
            closures.append((earlier[rng.integers(len(earlier))], k))
        visits.setdefault((x, y), []).append(k)
    chain = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    edges = np.concatenate([chain, np.array(closures, np.int64).reshape(-1, 2)])
    true_z = se2_between(truth[edges[:, 0]], truth[edges[:, 1]]) if len(edges) else np.zeros((0, 3))
    z = se2_compose(true_z, rng.normal(size=true_z.shape) * sig)
    start = truth[0]
    initial = [start]
    for dz in z[:n - 1]:                                              # dead reckoning
        initial.append(se2_compose(initial[-1], dz))
    information = np.tile(np.diag(info), (len(edges), 1, 1))
    return PoseGraph(np.array(initial), edges, z, information), truth
