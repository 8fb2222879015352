"""Grading throughput: 50 copies of a solution notebook with 2 jobs (issue "Autograding").

Prints seconds per submission (wall time of the batch / copies, and per-worker wall time) and the
worker overhead beyond the student's own compute (worker wall time minus the time spent in the
notebook's cells and exercise calls). Target: under 2 s overhead per submission.

    python benchmarks/bench_grader.py [--assignment 00_getting_started] [--copies 50] [--jobs 2]
"""
from __future__ import annotations

import argparse
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from robocourse.grading.grader import grade_batch, isolation_note

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--assignment", default="00_getting_started")
    parser.add_argument("--copies", type=int, default=50)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    src = ROOT / "solutions" / f"{args.assignment}.ipynb"
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for i in range(args.copies):
            p = Path(tmp) / f"student{i:03d}.ipynb"
            shutil.copy(src, p)
            paths.append(p)
        start = time.perf_counter()
        results = grade_batch(paths, args.assignment, "bench-seed", jobs=args.jobs, log=lambda *_: None)
        wall = time.perf_counter() - start
    assert all(r.total == r.max_total for r in results), "a solution copy did not score full marks"
    per_worker = [r.seconds for r in results]
    overhead = [r.seconds - r.compute_seconds for r in results]
    print(f"grader benchmark: {args.copies} x {args.assignment} with {args.jobs} jobs; {isolation_note()}")
    print(f"  batch wall time             {wall:8.2f} s  ({wall / args.copies:.3f} s per submission)")
    print(f"  worker wall time (median)   {statistics.median(per_worker):8.3f} s per submission")
    print(f"  student compute (median)    {statistics.median(r.compute_seconds for r in results):8.3f} s")
    print(f"  overhead (median / max)     {statistics.median(overhead):8.3f} s / {max(overhead):.3f} s "
          f"(target < 2 s): {'met' if max(overhead) < 2 else 'NOT met'}")


if __name__ == "__main__":
    main()
