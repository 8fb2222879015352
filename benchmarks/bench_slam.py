"""Lesson 01 benchmark: Se, Lowe & Little's global-localization experiment in the simulated lab.

Run from the repository root::

    .venv/bin/python -m benchmarks.bench_slam [sift128|reduced16]

Builds the map of the lab with :class:`robokit.localization.VisualSLAM` over the recorded lap
(1 frame per second, only the first pose given), localises from the 8 test poses with the Hough
transform and prints the table of Se et al. Sec. 6 next to the paper's numbers (about 6 cm,
1.2 degrees, 2.5 s on a 700 MHz Pentium III). Times are also given relative to OpenCV SIFT
``detectAndCompute`` on one left image, measured in the same run, so machines can be compared.
"""
from __future__ import annotations

import sys
import time

import cv2
import numpy as np

from robocourse.lessons.visual_slam.experiment import lab_experiment, mapping_run


def _opencv_sift_seconds(image: np.ndarray, repeats: int = 5) -> float:
    sift = cv2.SIFT_create()
    gray = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    sift.detectAndCompute(gray, None)  # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        sift.detectAndCompute(gray, None)
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def main(descriptor: str = "sift128") -> None:
    run, _ = mapping_run(1.0)
    peer = _opencv_sift_seconds(run.images["stereo/left"][0])
    ex = lab_experiment(rate=1.0, descriptor=descriptor)
    est, truth = ex.slam.trajectory, ex.truth
    drift = np.hypot(*(est[:, :2] - truth[:, :2]).T)
    per_frame = ex.mapping_seconds / len(truth)
    print(f"descriptor {descriptor}: {len(truth)} frames, {len(ex.slam.map)} landmarks, tracking error max "
          f"{100 * drift.max():.1f} cm, final {100 * drift[-1]:.1f} cm")
    print(f"mapping {ex.mapping_seconds:.1f} s = {per_frame:.2f} s per stereo frame "
          f"({per_frame / peer:.1f}x OpenCV SIFT detectAndCompute on one image, {1e3 * peer:.0f} ms)")
    print(f"global localization {ex.mean_seconds:.2f} s per view ({ex.mean_seconds / peer:.1f}x OpenCV SIFT on one image)")
    print(ex.table())
    ok = ex.mean_error_m <= 0.05 and ex.mean_error_rad <= np.deg2rad(1.2) and max(r["error_m"] for r in ex.rows) < 0.10
    print(f"issue 5 acceptance (mean <= 5 cm and <= 1.2 deg, each < 10 cm): {'met' if ok else 'NOT met'}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
