"""One Monte-Carlo localization update, vectorised vs a straightforward per-particle loop (lesson 03).

An update is the odometry motion model (Thrun et al. Table 5.6), the likelihood-field weights
(Table 6.3, ROS amcl's ``1 + sum p^3``) over 60 of a 360-beam scan, and low-variance resampling
(Table 4.4): :func:`robokit.localization.mcl`. The peer, run in the same process on the same
inputs, loops over particles: one motion sample, :func:`likelihood_field_log_weight_readable`
(beam by beam) and the resampling loop of Table 4.4. Target: under 20 ms for 5000 particles x 60
beams. The vectorised update is timed ``repeats`` times: the best run (what an unloaded core
gives; timeit's advice) decides the target, the median is printed beside it.

    python benchmarks/bench_mcl.py [--repeats 20]
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from robokit.localization import likelihood_field_log_weight_readable, mcl_step, normalise_log_weights
from robokit.mapping import OccupancyGrid, likelihood_field
from robokit.sim import sample_motion_model_odometry

ALPHAS = (0.2, 0.2, 0.2, 0.2)
MODEL = dict(combine="ros", max_beams=60, r_max=8.0)


def room_field():
    """A 10 m x 8 m room at 0.05 m with a pillar and a partition (a hand-drawn map)."""
    P = np.zeros((160, 200))
    P[[0, -1], :] = 1.0
    P[:, [0, -1]] = 1.0
    P[60:80, 60:80] = 1.0
    P[100, 100:180] = 1.0
    return likelihood_field(OccupancyGrid.from_probability(P, 0.05, (0.0, 0.0)))


def loop_update(particles, weights, odom_prev, odom_now, ranges, angles, field, rng):
    n = len(particles)
    moved = np.array([sample_motion_model_odometry(odom_prev, odom_now, p, ALPHAS, rng) for p in particles])
    log_w = np.array([np.log(w) + likelihood_field_log_weight_readable(p, ranges, angles, field, **MODEL)
                      for p, w in zip(moved, weights)])
    w = normalise_log_weights(log_w).weights
    r, c, i, out = rng.uniform(0.0, 1.0 / n), w[0], 0, []          # Table 4.4
    for m in range(n):
        u = r + m / n
        while u > c and i < n - 1:
            i += 1
            c += w[i]
        out.append(moved[i])
    return np.array(out)


def room_update(n: int, seed: int = 0) -> tuple:
    """The inputs of one update: ``n`` particles spread over :func:`room_field`'s room, equal weights,
    a 360-beam scan (every 17th beam without a return) and an odometry step."""
    rng = np.random.default_rng(seed)
    particles = np.column_stack([rng.uniform(0.5, 9.5, n), rng.uniform(0.5, 7.5, n), rng.uniform(-np.pi, np.pi, n)])
    weights = np.full(n, 1.0 / n)
    angles = 2 * np.pi * np.arange(360) / 360
    ranges = rng.uniform(0.3, 7.0, 360)
    ranges[::17] = np.inf
    return particles, weights, angles, ranges, (np.zeros(3), np.array([0.2, 0.05, 0.1]))


def bench(n: int, repeats: int, field) -> tuple[float, float, float]:
    particles, weights, angles, ranges, odom = room_update(n)
    times = []
    for k in range(repeats):
        start = time.perf_counter()
        mcl_step(particles, weights, *odom, ranges, angles, field, alphas=ALPHAS, rng=k, **MODEL)
        times.append(time.perf_counter() - start)
    best, median = min(times), statistics.median(times)
    start = time.perf_counter()
    loop_update(particles, weights, *odom, ranges, angles, field, np.random.default_rng(0))
    slow = time.perf_counter() - start
    return best, median, slow


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    field = room_field()
    print("MCL update (motion + likelihood field, 60 beams + low-variance resampling)")
    for n in (500, 5000):
        best, median, slow = bench(n, args.repeats, field)
        verdict = f" (target < 20 ms: {'met' if best < 0.020 else 'NOT met'})" if n == 5000 else ""
        print(f"  {n:5d} particles: vectorised {best * 1e3:6.2f} ms (median {median * 1e3:6.2f}), per-particle loop "
              f"{slow * 1e3:8.1f} ms, ratio {slow / median:5.0f}x{verdict}")


if __name__ == "__main__":
    main()
