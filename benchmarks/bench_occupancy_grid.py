"""Speed of log-odds occupancy grid mapping over the full corridor run, against real time and the reference.

Run: ``.venv/bin/python benchmarks/bench_occupancy_grid.py`` (add ``--quick`` for fewer repeats).

The run is :func:`robokit.sim.corridor_path` through :func:`robokit.sim.long_corridor` at 10 Hz
(0.3 m/s, 115 s, 1151 scans of a 360-beam :class:`robokit.sim.Lidar`); the scans are computed
first, untimed. Prints the median time of :func:`robokit.mapping.occupancy_grid_mapping` of the
whole run at 0.05 m, its real-time factor (run duration / mapping time; issue target >= 10x), and
its speed per scan against :func:`robokit.mapping.occupancy_grid_mapping_readable` (Tables 9.1 and
9.2 in plain Python loops) on the first few scans of the same run, timed in the same process.
Then the likelihood field of the map (``distance_transform_edt``) and a lookup of 1000 particles x
360 beam endpoints, the inner step of a Monte-Carlo localizer.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from timing import median_time

from robokit.mapping import likelihood_field, occupancy_grid_mapping, occupancy_grid_mapping_readable
from robokit.sim import Lidar, corridor_path, long_corridor



def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    args = ap.parse_args()
    reps = 3 if args.quick else 7
    world = long_corridor()
    lidar = Lidar()
    path = corridor_path(world, rate=10.0)
    scans = np.array([lidar.scan(world, pose) for pose in path.poses])
    duration = float(path.t[-1] - path.t[0])
    bounds = (-0.2, -1.4, 36.3, 1.4)
    kw = dict(r_max=lidar.r_max, sensor_offset=lidar.offset)

    t_map = median_time(lambda: occupancy_grid_mapping(path.poses, scans, lidar.angles, bounds, 0.05, **kw), reps)
    n_ref = 3
    t_fast_few = median_time(lambda: occupancy_grid_mapping(path.poses[:n_ref], scans[:n_ref], lidar.angles, bounds,
                                                            0.05, **kw), reps)
    t0 = time.perf_counter()
    occupancy_grid_mapping_readable(path.poses[:n_ref], scans[:n_ref], lidar.angles, bounds, 0.05, **kw)
    t_ref = time.perf_counter() - t0
    grid = occupancy_grid_mapping(path.poses, scans, lidar.angles, bounds, 0.05, **kw)
    t_field = median_time(lambda: likelihood_field(grid), reps)
    field = likelihood_field(grid)
    pts = np.random.default_rng(0).uniform([0, -1.2], [36, 1.2], (1000, 360, 2))
    t_look = median_time(lambda: field.lookup(pts, validate=False), reps)

    print(f"run: {len(scans)} scans x {lidar.beams} beams, {duration:.1f} s; grid {grid.shape[0]} x {grid.shape[1]} "
          f"cells at 0.05 m")
    print(f"{'operation':<52}{'median':>12}{'ratio':>26}")
    print(f"{'occupancy_grid_mapping, full run':<52}{t_map:>10.3f} s{duration / t_map:>14.0f} x real time")
    print(f"{'  per scan (fast)':<52}{t_map / len(scans) * 1e3:>9.2f} ms")
    print(f"{f'  per scan, reference (first {n_ref} scans)':<52}{t_ref / n_ref * 1e3:>9.0f} ms"
          f"{t_ref / t_fast_few:>14.0f} x fast")
    print(f"{'likelihood_field (distance_transform_edt)':<52}{t_field * 1e3:>9.2f} ms")
    print(f"{'LikelihoodField.lookup, 1000 x 360 endpoints':<52}{t_look * 1e3:>9.2f} ms")


if __name__ == "__main__":
    main()
