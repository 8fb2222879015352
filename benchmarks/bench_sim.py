"""Speed of the simulator against peer operations run in the same process, plus SIFT statistics.

Run: ``.venv/bin/python benchmarks/bench_sim.py`` (add ``--quick`` for fewer repeats).

Prints median times of: a 640x480 pinhole frame of ``long_corridor()`` (issue 4 target < 100 ms) and
of ``open_field()`` (same target; hundreds of ground, hedge and skybox surfaces), a 640x480 omni
frame (< 400 ms), a 360-beam LiDAR scan (< 2 ms), each with its ratio to a peer
operation timed in the same run (``cv2.warpPerspective`` of a full 640x480 RGB frame; a numpy
``hypot`` over the same number of beam-segment pairs). Then, per world, SIFT keypoints on a rendered
640x480 view and the fraction of ratio-test matches between two views 0.3 m apart that agree with
the ground-truth geometry (back-projection with the rendered depth, 3 px).
"""
from __future__ import annotations

import argparse

import cv2
import numpy as np

from timing import median_time

from robokit.sim import (Lidar, OmniCamera, PinholeCamera, box_room, lab_room, long_corridor, office_floor, open_field,
                         sift_view_pair)



def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    args = ap.parse_args()
    reps = 5 if args.quick else 21
    corridor = long_corridor()
    cam = PinholeCamera.from_fov(width=640, height=480)
    omni = OmniCamera()
    lidar = Lidar(beams=360)
    poses = [[1.0, 0.0, 0.0], [10.0, 0.3, 0.2], [20.0, -0.4, np.pi], [30.0, 0.0, 2.5]]
    state = {"k": 0}

    def pinhole():
        state["k"] += 1
        cam.observe(corridor, poses[state["k"] % len(poses)])

    field = open_field()
    field_poses = [[50.0, 30.0, 0.3], [20.0, 10.0, 2.0], [80.0, 45.0, -1.2], [60.0, 30.0, np.pi]]

    def pinhole_field():
        state["k"] += 1
        cam.observe(field, field_poses[state["k"] % len(field_poses)])

    def omni_frame():
        state["k"] += 1
        omni.observe(corridor, poses[state["k"] % len(poses)])

    def scan():
        state["k"] += 1
        lidar.scan(corridor, poses[state["k"] % len(poses)])

    frame = cam.observe(corridor, poses[0]).image
    H = np.array([[1.01, 0.02, 3.0], [-0.01, 0.99, 2.0], [1e-5, 2e-5, 1.0]])
    warp = lambda: cv2.warpPerspective(frame, H, (640, 480))
    pairs = np.random.default_rng(0).random((360, len(corridor.segments)))
    hyp = lambda: np.hypot(pairs, pairs)

    t_pin, t_omni, t_scan = median_time(pinhole, reps), median_time(omni_frame, reps), median_time(scan, 5 * reps)
    t_field = median_time(pinhole_field, reps)
    t_warp, t_hyp = median_time(warp, 5 * reps), median_time(hyp, 5 * reps)
    print(f"cores available: {len(__import__('os').sched_getaffinity(0))}; cv2 threads: {cv2.getNumThreads()}")
    print(f"{'operation':<44}{'median':>12}{'target':>10}{'ratio to peer':>16}")
    print(f"{'pinhole 640x480 frame, long_corridor':<44}{t_pin * 1e3:>9.1f} ms{'100 ms':>10}"
          f"{t_pin / t_warp:>12.1f} x warp")
    print(f"{'pinhole 640x480 frame, open_field':<44}{t_field * 1e3:>9.1f} ms{'100 ms':>10}"
          f"{t_field / t_warp:>12.1f} x warp")
    print(f"{'omni 640x480 frame, long_corridor':<44}{t_omni * 1e3:>9.1f} ms{'400 ms':>10}"
          f"{t_omni / t_warp:>12.1f} x warp")
    print(f"{'LiDAR scan, 360 beams x %d segments' % len(corridor.segments):<44}{t_scan * 1e3:>9.3f} ms{'2 ms':>10}"
          f"{t_scan / t_hyp:>11.1f} x hypot")
    print(f"{'peer: cv2.warpPerspective 640x480 RGB':<44}{t_warp * 1e3:>9.2f} ms")
    print(f"{'peer: np.hypot over the same beam x segment':<44}{t_hyp * 1e3:>9.3f} ms")
    print()
    print(f"{'world':<16}{'keypoints':>10}{'matches':>9}{'inlier ratio':>14}   (SIFT, views 0.3 m apart)")
    for name, world, pose in [("lab_room", lab_room(), [5.0, 2.0, np.pi / 2]),
                              ("long_corridor", corridor, [3.0, 0.0, 0.0]),
                              ("office_floor", office_floor(), [10.0, 4.3, -np.pi / 2]),
                              ("box_room", box_room(), [1.0, 1.0, 0.4]),
                              ("open_field", field, [50.0, 30.0, 0.3])]:
        pair = sift_view_pair(world, cam, pose)
        print(f"{name:<16}{pair.keypoints:>10}{pair.matches:>9}{pair.inlier_ratio:>14.3f}")


if __name__ == "__main__":
    main()
