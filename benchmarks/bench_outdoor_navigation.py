"""The paper's experiment over seeded courses: waypoints, collisions, path ratio, time, GPS error.

Run from the repository root:  .venv/bin/python -m benchmarks.bench_outdoor_navigation [--courses N]

Each course is ``random_course(seed)`` for seed = 0..N-1 (100 m x 60 m field, four waypoints,
fourteen obstacles, about half on the straight legs); the truck runs with chained sonars (the
paper's commanded loop), with free-running sonars (cross-talk) and with no sonar. Prints the
distribution of each figure per firing mode, plus the wall time per simulated mission.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from robocourse.lessons.gps_sonar_truck.experiment import run_courses
from robokit.outdoor.mission import summarize_runs


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--courses", type=int, default=20)
    ap.add_argument("--modes", default="chained,free,off")
    args = ap.parse_args(argv)
    for mode in args.modes.split(","):
        t0 = time.perf_counter()
        results = run_courses(range(args.courses), firing=mode)
        wall = time.perf_counter() - t0
        s = summarize_runs(results)
        print(f"== {mode}: {s['runs']} courses, {wall / s['runs']:.1f} s wall per mission")
        print(f"   success (all waypoints, no collision): {s['success_rate']:.0%}   waypoints {s['waypoints_reached']}")
        print(f"   collisions per run: {s['collisions_per_run']}")
        print(f"   avoidance manoeuvres per run: {s['avoidances_per_run']}")
        for key in ("path_ratio", "time_s", "arrival_error_m"):
            d = s[key]
            print(f"   {key:<16} min {d['min']:8.3f}  median {d['median']:8.3f}  max {d['max']:8.3f}")
        print(f"   GPS error max over all fixes: {s['gps_error_max_m']:.1f} m;  "
              f"mean path ratio {np.mean([r.path_ratio for r in results]):.3f}")


if __name__ == "__main__":
    main()
