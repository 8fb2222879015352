"""Lesson 02's topological map and hierarchical localization on the office tour: build time, map
size, loop closures, localization error at the eleven test poses (coarse-only, fine-only,
hierarchical; paper Fig. 9 and Fig. 11) and the time of each stage.

Peers, run in the same process: the coarse stage against a per-node Python loop of the same
Eq. (5); a query against the recognised node's pose alone (the error of node spacing).

Run:  PYTHONPATH=. python benchmarks/bench_hierarchical_localization.py [--rate 1.0]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from robokit.geometry import wrap_angle
from robokit.localization import MODES, HierarchicalLocalizer
from robokit.mapping import TopologicalMap, build_topological_map, omni_view, optimize_pose_graph, relax
from robokit.sim import OFFICE_TEST_POSES, OmniCamera, office_floor, office_tour, record
from robokit.vision import histogram_distance


def timed(fn, *args, repeat=1, **kw):
    t = time.perf_counter()
    for _ in range(repeat):
        out = fn(*args, **kw)
    return out, (time.perf_counter() - t) / repeat


def node_errors(poses, truth):
    return np.linalg.norm(poses[:, :2] - truth[:, :2], axis=1)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--rate", type=float, default=1.0, help="recording rate (Hz) of the office tour")
    args = parser.parse_args()
    world, cam = office_floor(), OmniCamera()
    run, t_rec = timed(record, world, office_tour(world), {"omni": cam}, rate=args.rate, seed=0)
    print(f"office tour: {len(run)} frames at {args.rate} Hz ({t_rec:.1f} s to record or load)")

    log: list[str] = []
    tmap, t_build = timed(build_topological_map, run.images["omni"], run.odometry, cam, log=log.append)
    reasons = [line.split("(")[1].split(")")[0] for line in log if line.startswith("node")]
    print(f"map: {tmap}, built in {t_build:.1f} s ({1e3 * t_build / len(run):.0f} ms per frame)")
    print("  nodes started by:", {r: reasons.count(r) for r in sorted(set(reasons))})
    spacing = np.linalg.norm(np.diff(run.poses[tmap.frames, :2], axis=0), axis=1)
    print(f"  node spacing: median {np.median(spacing):.2f} m, max {spacing.max():.2f} m")
    truth = run.poses[tmap.frames]
    for line in log:
        if "loop" in line:
            print("  " + line)
    relaxed = tmap.with_poses(relax(tmap.graph()).poses)
    optimized = tmap.with_poses(optimize_pose_graph(tmap.graph()).poses)
    for name, m in (("odometry", tmap), ("relaxed (Eqs. 1-3)", relaxed), ("least squares", optimized)):
        e = node_errors(m.poses, truth)
        print(f"  node position error, {name:18s}: mean {e.mean():.3f} m, max {e.max():.3f} m")

    tests = np.array(OFFICE_TEST_POSES)
    images = [cam.observe(world, p).image for p in tests]
    for label, m in (("nodes at their true poses", tmap.with_poses(truth)), ("relaxed map", relaxed)):
        print(f"\nlocalization at the {len(tests)} test poses, {label}:")
        for mode in MODES:
            loc = HierarchicalLocalizer(m, cam, mode=mode)
            results = [loc.localize(im) for im in images]
            err = np.array([np.r_[r.pose[:2] - p[:2], wrap_angle(r.pose[2] - p[2])] for r, p in zip(results, tests)])
            times = {k: 1e3 * np.mean([r.times[k] for r in results]) for k in results[0].times}
            ok = sum(r.verified and r.metric for r in results)
            print(f"  {mode:12s} |ex| mean {np.abs(err[:, 0]).mean():.3f} m  |ey| mean {np.abs(err[:, 1]).mean():.3f} m  "
                  f"|e| max {np.hypot(err[:, 0], err[:, 1]).max():.3f} m  heading {np.degrees(np.abs(err[:, 2])).mean():.2f} deg"
                  f"  metric+verified {ok}/{len(tests)}")
            print("               per case |e| (m):", np.round(np.hypot(err[:, 0], err[:, 1]), 3).tolist())
            print("               ms per stage:", {k: round(v, 1) for k, v in times.items()})
            if mode == "hierarchical":
                node_only = np.array([r.node_pose[:2] - p[:2] for r, p in zip(results, tests)])
                print(f"  {'node pose only':12s} |ex| mean {np.abs(node_only[:, 0]).mean():.3f} m  "
                      f"|ey| mean {np.abs(node_only[:, 1]).mean():.3f} m (the peer: no metric step)")

    # coarse stage over 1000 nodes: one vectorised Eq. (5) against a per-node loop
    rng = np.random.default_rng(0)
    H = np.abs(np.repeat(tmap.histograms, 1000 // len(tmap) + 1, axis=0)[:1000] + rng.normal(0, 0.01, (1000, tmap.histograms.shape[1])))
    H /= H.sum(1, keepdims=True)
    big = TopologicalMap(**{**tmap.to_arrays(), "poses": np.zeros((1000, 3)), "variances": np.zeros(1000),
                            "histograms": H, "frames": np.arange(1000),
                            "offsets": np.r_[tmap.offsets, np.full(1000 - len(tmap), tmap.offsets[-1])],
                            "edges": np.zeros((0, 2)), "measurements": np.zeros((0, 3)),
                            "covariances": np.zeros((0, 3, 3)), "kinds": np.zeros(0)})
    h = H[17] + 0.001
    _, t_vec = timed(big.rank_by_histogram, h, repeat=200)
    _, t_loop = timed(lambda: np.argsort([histogram_distance(h, row) for row in H]), repeat=5)
    print(f"\ncoarse stage over 1000 nodes: {1e3 * t_vec:.3f} ms per query (per-node loop {1e3 * t_loop:.1f} ms, "
          f"{t_loop / t_vec:.0f}x slower)")

    # a full query against a 100-node map, without the query's own feature extraction
    frames = np.linspace(0, len(run) - 1, 100).astype(int)
    views = [omni_view(run.images["omni"][k], cam) for k in frames]
    counts = np.array([len(v) for v in views])
    m100 = TopologicalMap(run.odometry[frames], np.zeros(100), np.stack([v.histogram for v in views]), frames,
                          np.concatenate([np.column_stack([v.features.keypoints.xy, v.features.keypoints.scale,
                                                           v.features.keypoints.orientation]) for v in views]),
                          np.concatenate([v.bearings for v in views]),
                          np.concatenate([v.features.descriptors for v in views]), np.r_[0, np.cumsum(counts)],
                          np.zeros((0, 2)), np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros(0))
    qviews = [HierarchicalLocalizer(m100, cam).view(im) for im in images]
    mean_after = {}
    for method in ("kdtree", "opencv", "bruteforce", "flann"):
        mm = TopologicalMap(**{**m100.to_arrays(), "index": method})
        loc = HierarchicalLocalizer(mm, cam)
        stage = {k: [] for k in ("histogram", "sift", "coarse", "matching", "verification")}
        after = []
        for view, t in qviews:
            r, dt = timed(loc.localize_view, view, t)
            after.append(dt)
            for k in stage:
                stage[k].append(r.times[k])
        mean_after[method] = np.mean(after)
        print(f"query against a 100-node map ({method}, top_k={loc.top_k}): {1e3 * np.mean(after):.1f} ms after feature "
              f"extraction (max {1e3 * np.max(after):.1f});", {k: round(1e3 * float(np.mean(v)), 1) for k, v in stage.items()})
    fine = HierarchicalLocalizer(m100, cam, mode="fine")
    after_fine = [timed(fine.localize_view, view, t)[1] for view, t in qviews]
    print(f"  the peer, fine-only against all 100 nodes: {1e3 * np.mean(after_fine):.1f} ms "
          f"({np.mean(after_fine) / mean_after[m100.index]:.1f}x the hierarchical query, {m100.index} index)")


if __name__ == "__main__":
    main()
