"""Speed of lesson 04's sensing against peers run in the same process.

Run: ``.venv/bin/python benchmarks/bench_sensing.py`` (add ``--quick`` for fewer repeats).

Prints median times, for a 30 s trial at 100 Hz (3001 frames, LittleDog's four markers, 15 %
occlusions), of: ``mocap_body_poses`` (one batched SVD fit) against a loop of ``fit_marker_pose``
and against a loop of scipy's ``Rotation.align_vectors`` (the same fit); ``fuse_body_state``
against ``integrate_gyro`` over the same samples (the fusion's loop against the bare gyro loop);
``detect_contacts`` on four legs against a plain Python loop of the same state machine; and
``fit_se2`` on a RANSAC-sized batch (128 two-point problems) against ``np.linalg.svd`` of as many
2x2 matrices (the kernel's floor).
"""
from __future__ import annotations

import argparse

import numpy as np
from scipy.spatial.transform import Rotation

from timing import median_time

from robokit.geometry import fit_se2, rot_z, se3_from_rt
from robokit.legged import (MARKERS, detect_contacts, fit_marker_pose, fuse_body_state, integrate_gyro,
                            mocap_body_poses, simulate_mocap)



def loop_detector(force, on, off, debounce):
    out = np.zeros(force.shape, bool)
    for j in range(force.shape[1]):
        h, state, last, run = False, False, None, 0
        for k, f in enumerate(force[:, j]):
            h = True if f > on else False if f < off else h
            run = run + 1 if h == last else 1
            last = h
            if k == 0 or (h != state and run >= debounce):
                state = h
            out[k, j] = state
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    reps = 3 if ap.parse_args().quick else 11
    n = 3001
    k = np.arange(n)
    T = se3_from_rt(rot_z(0.001 * k), np.column_stack([0.001 * k, np.zeros(n), np.full(n, 0.13)]))
    frames = simulate_mocap(T, MARKERS, 0.001, 0.15, 0)
    vis = frames.visible

    def loop_fit():
        for i in range(n):
            if vis[i].sum() >= 3:
                fit_marker_pose(MARKERS, frames.positions[i], vis[i])

    def loop_scipy():
        for i in range(n):
            v = vis[i]
            if v.sum() >= 3:
                s, t = MARKERS[v], frames.positions[i][v]
                Rotation.align_vectors(t - t.mean(0), s - s.mean(0))

    batch = median_time(lambda: mocap_body_poses(MARKERS, frames.positions, vis), reps)
    print(f"mocap_body_poses, {n} frames: {batch * 1e3:.1f} ms; "
          f"loop of fit_marker_pose x{median_time(loop_fit, reps) / batch:.1f}, "
          f"loop of scipy align_vectors x{median_time(loop_scipy, reps) / batch:.1f}")
    poses = mocap_body_poses(MARKERS, frames.positions, vis)
    gyro, acc = np.tile([0.0, 0.0, 0.1], (n, 1)), np.tile([0.0, 0.0, 9.81], (n, 1))
    fuse = median_time(lambda: fuse_body_state(gyro, acc, 0.01, poses.T_world_body, poses.ok), reps)
    bare = median_time(lambda: integrate_gyro(np.eye(3), gyro, 0.01), reps)
    print(f"fuse_body_state, {n} samples: {fuse * 1e3:.1f} ms; integrate_gyro x{bare / fuse:.2f} of it")
    force = np.random.default_rng(0).normal(3.0, 3.0, (n, 4))
    det = median_time(lambda: detect_contacts(force, 3.0, 1.0, 3), reps)
    print(f"detect_contacts, {n} x 4: {det * 1e3:.2f} ms; plain loop x{median_time(lambda: loop_detector(force, 3.0, 1.0, 3), reps) / det:.0f}")
    rng = np.random.default_rng(1)
    s2 = rng.normal(size=(128, 2, 2))
    se2 = median_time(lambda: fit_se2(s2, s2 + 1.0, validate=False), reps * 20)
    svd = median_time(lambda: np.linalg.svd(s2), reps * 20)
    print(f"fit_se2, 128 two-point problems: {se2 * 1e6:.0f} us; its SVD alone x{svd / se2:.2f}")


if __name__ == "__main__":
    main()
