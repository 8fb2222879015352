"""Lesson 02 benchmarks: hue histograms (coarse stage) and SIFT on omni images (fine stage).

Run from the repository root::

    .venv/bin/python -m benchmarks.bench_omni_features

Prints, each against a peer run in the same process: ranking one hue histogram against 1000 node
histograms (vectorised Eq. (5) vs a per-node Python loop), our HSI histogram vs OpenCV's HSV one,
one query image matched against one node by KD-tree, FLANN, brute force and OpenCV, ``omni_sift``
vs plain OpenCV SIFT, and the "matched accurate rate" of radial, gradient and upright SIFT on
random ``office_floor()`` view pairs 0.1-0.5 m apart with any turn.
"""
from __future__ import annotations


import numpy as np

from timing import median_time

from robokit.sim import OmniCamera, office_floor, omni_ground_truth_inliers
from robokit.vision import DescriptorIndex, detect_sift_features, omni_sift
from robokit.vision.colour import histogram_distance, histogram_intersection, hue_histogram, hue_histogram_opencv



def bench_coarse_ranking(n_nodes: int = 1000, bins: int = 32) -> None:
    rng = np.random.default_rng(0)
    nodes = rng.dirichlet(np.ones(bins), size=n_nodes)
    h = rng.dirichlet(np.ones(bins))

    def loop():
        return np.array([np.sqrt(((h - node) ** 2).sum()) for node in nodes])

    assert np.allclose(loop(), histogram_distance(h, nodes))
    t_vec = median_time(lambda: np.argsort(histogram_distance(h, nodes)), 7)
    t_int = median_time(lambda: np.argsort(-histogram_intersection(h, nodes)), 7)
    t_loop = median_time(lambda: np.argsort(loop()), 7)
    print(f"coarse stage, 1 query vs {n_nodes} node histograms ({bins} bins): Eq. (5) vectorised {t_vec * 1e3:.3f} ms, "
          f"intersection {t_int * 1e3:.3f} ms, per-node Python loop {t_loop * 1e3:.2f} ms; "
          f"loop/vectorised = {t_loop / t_vec:.0f}x")


def bench_histograms(image: np.ndarray) -> None:
    t_ours = median_time(lambda: hue_histogram(image), 7)
    t_cv = median_time(lambda: hue_histogram_opencv(image), 7)
    print(f"hue histogram of a 640x480 omni image: HSI (Eq. (4)) {t_ours * 1e3:.1f} ms, OpenCV HSV reference "
          f"{t_cv * 1e3:.1f} ms (its mask is ours, so it pays for rgb_to_hsi too); ratio ours/OpenCV = {t_ours / t_cv:.2f}")


def bench_matching(node, query) -> None:
    exact = DescriptorIndex(node.descriptors, "bruteforce").match(query.descriptors)
    rows = []
    for method in ("kdtree", "flann", "bruteforce", "opencv"):
        build = median_time(lambda: DescriptorIndex(node.descriptors, method), 7)
        index = DescriptorIndex(node.descriptors, method)
        match = median_time(lambda: index.match(query.descriptors), 7)
        m = index.match(query.descriptors)
        same = len(set(zip(m.query, m.train)) & set(zip(exact.query, exact.train)))
        rows.append((method, build, match, len(m), same))
    ref = rows[2][2]
    print(f"one query image ({len(query)} descriptors) vs one node ({len(node)}), ratio 0.8:")
    for method, build, match, n, same in rows:
        print(f"  {method:10s} build {build * 1e3:6.2f} ms, match {match * 1e3:6.1f} ms "
              f"(x{match / ref:.2f} of brute force), {n} matches, {same} as brute force's {len(exact)}")


def bench_extraction(image: np.ndarray, cam: OmniCamera) -> None:
    centre = (cam.cx, cam.cy)
    t_plain = median_time(lambda: detect_sift_features(image), 5)
    print(f"SIFT on a 640x480 omni image: plain detect_sift_features {t_plain * 1e3:.0f} ms "
          f"({len(detect_sift_features(image))} features)")
    for orientation in ("gradient", "radial", "upright"):
        t = median_time(lambda: omni_sift(image, centre, cam.radii, orientation=orientation), 5)
        n = len(omni_sift(image, centre, cam.radii, orientation=orientation))
        print(f"  omni_sift {orientation:8s} {t * 1e3:.0f} ms ({n} features in the annulus); ratio to plain = {t / t_plain:.2f}")


def _pairs(world, n: int, seed: int = 3) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        p = np.r_[rng.uniform(0.5, 15.5), rng.uniform(0.5, 11.5), 0.0]
        step, bearing = rng.uniform(0.1, 0.5), rng.uniform(0, 2 * np.pi)
        q = np.r_[p[:2] + step * np.array([np.cos(bearing), np.sin(bearing)]), rng.uniform(-np.pi, np.pi)]
        if world.is_free(np.array([p[:2], q[:2]])).all():
            out.append((p, q))
    return out


def bench_accurate_rate(world, cam: OmniCamera, n_pairs: int = 20) -> None:
    centre = (cam.cx, cam.cy)
    counts = {o: np.zeros((n_pairs, 2)) for o in ("radial", "gradient", "upright")}
    for k, (p, q) in enumerate(_pairs(world, n_pairs)):
        f1, f2 = cam.observe(world, p), cam.observe(world, q)
        T1, T2 = cam.transform_at(p), cam.transform_at(q)
        for orientation, c in counts.items():
            a = omni_sift(f1.image, centre, cam.radii, orientation=orientation)
            b = omni_sift(f2.image, centre, cam.radii, orientation=orientation)
            m = DescriptorIndex(a.descriptors).match(b.descriptors, ratio=0.8)
            ok = omni_ground_truth_inliers(cam, f1.depth, T1, T2, a.keypoints.xy[m.train], b.keypoints.xy[m.query])
            c[k] = len(m), ok.sum()
    print(f"matched accurate rate, {n_pairs} office_floor pairs 0.1-0.5 m apart, any turn (ratio 0.8, tol 3 px; "
          f"the paper: > 80 %):")
    for orientation, c in counts.items():
        rate = c[:, 1] / np.maximum(c[:, 0], 1)
        print(f"  {orientation:8s} {c[:, 0].mean():6.1f} matches per pair, pooled rate {c[:, 1].sum() / c[:, 0].sum():.3f}, "
              f"per pair mean {rate.mean():.3f}, worst {rate.min():.3f}")


def main() -> None:
    world, cam = office_floor(), OmniCamera()
    node = cam.observe(world, np.array([12.0, 3.5, 0.0])).image
    query = cam.observe(world, np.array([12.3, 3.6, 1.0])).image
    bench_coarse_ranking()
    bench_histograms(node)
    centre = (cam.cx, cam.cy)
    bench_matching(omni_sift(node, centre, cam.radii), omni_sift(query, centre, cam.radii))
    bench_extraction(node, cam)
    bench_accurate_rate(world, cam)


if __name__ == "__main__":
    main()
