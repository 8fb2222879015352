"""Benchmark robokit.mapping's pose-graph solvers against gtsam on the same graphs.

On a generated Manhattan-world graph (3500 poses, like Olson's M3500, with ground truth), on
graphs gtsam ships with its Python package (``--gtsam-example w10000``: Olson's 10,000-pose W10000,
64,311 edges) and on any g2o files given on the command line (Intel, MIT, CSAIL, M3500 ... as
distributed in the g2o format), this runs:

* robokit's hand-written sparse Gauss-Newton (``optimize_pose_graph(method="gauss-newton")``),
* robokit's scipy ``least_squares`` path (``method="scipy"``),
* gtsam 4's Levenberg-Marquardt on ``BetweenFactorPose2`` factors with the same information
  matrices and the fixed node held by a ``NonlinearEqualityPose2`` (the peer; skipped if gtsam is
  not installed),
* the paper's relaxation (``relax``), to convergence or ``--relax-iterations`` sweeps.

It prints time, iterations, the final chi2 (g2o's error, robokit's cost), the ratio of that chi2 to
robokit's cost at gtsam's optimum (gtsam minimises the SE(2)-log error, which differs from g2o's
at second order, so both are shown: "chi2/peer" in g2o's error and "gtsam err/peer" in gtsam's),
the position RMSE to the truth where there is one, and the time ratio to gtsam's optimize() call
(the Python loop that builds gtsam's factor graph is timed apart). Nothing is asserted.

Usage::

    python benchmarks/bench_pose_graph.py                     # 3500-pose Manhattan graph
    python benchmarks/bench_pose_graph.py data/input_INTEL_g2o.g2o --n 0   # a file only
    python benchmarks/bench_pose_graph.py big.g2o --n 0 --no-scipy --relax-iterations 2000
    python benchmarks/bench_pose_graph.py --n 0 --gtsam-example w10000 --no-scipy --relax-iterations 0
    python benchmarks/bench_pose_graph.py --n 10000 --no-scipy --relax-iterations 0
    ROBOKIT_FAST=1 python benchmarks/bench_pose_graph.py      # 500 poses

Numbers depend on the machine and its load; compare the ratios to the peer run in the same process.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from robokit.config import fast_mode
from robokit.mapping import PoseGraph, manhattan_world_graph, optimize_pose_graph, pose_graph_cost, read_g2o, relax


def gtsam_solve(graph):
    """gtsam's LM on the same graph: (poses, seconds of optimize(), iterations, seconds to build, error fn)."""
    try:
        import gtsam
    except ImportError:
        return None
    t0 = time.perf_counter()
    factors, values = gtsam.NonlinearFactorGraph(), gtsam.Values()
    for k, p in enumerate(graph.poses):
        values.insert(k, gtsam.Pose2(*p))
    for (i, j), z, info in zip(graph.edges, graph.measurements, graph.information):
        factors.add(gtsam.BetweenFactorPose2(int(i), int(j), gtsam.Pose2(*z), gtsam.noiseModel.Gaussian.Information(info)))
    between = factors.clone()
    factors.add(gtsam.NonlinearEqualityPose2(graph.fixed, gtsam.Pose2(*graph.poses[graph.fixed])))
    params = gtsam.LevenbergMarquardtParams()
    params.setRelativeErrorTol(1e-9)
    params.setAbsoluteErrorTol(1e-9)
    params.setMaxIterations(100)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    optimizer = gtsam.LevenbergMarquardtOptimizer(factors, values, params)
    out = optimizer.optimize()
    seconds = time.perf_counter() - t0
    poses = np.array([[out.atPose2(k).x(), out.atPose2(k).y(), out.atPose2(k).theta()] for k in range(graph.n_poses)])

    def gtsam_chi2(p):
        v = gtsam.Values()
        for k, pk in enumerate(p):
            v.insert(k, gtsam.Pose2(*pk))
        return 2.0 * between.error(v)

    return poses, seconds, optimizer.iterations(), build, gtsam_chi2


def gtsam_example(name):
    """A planar pose graph from gtsam's bundled data (``gtsam.load2D``) as a robokit PoseGraph, node 0 fixed."""
    import gtsam
    factors, values = gtsam.load2D(gtsam.findExampleDataFile(name))
    keys = sorted(values.keys())
    index = {k: n for n, k in enumerate(keys)}
    poses = np.array([[values.atPose2(k).x(), values.atPose2(k).y(), values.atPose2(k).theta()] for k in keys])
    edges, measurements, information = [], [], []
    for k in range(factors.size()):
        factor = factors.at(k)
        if not isinstance(factor, gtsam.BetweenFactorPose2):
            continue
        z, root = factor.measured(), factor.noiseModel().R()         # information = R^T R
        edges.append([index[key] for key in factor.keys()])
        measurements.append([z.x(), z.y(), z.theta()])
        information.append(root.T @ root)
    return PoseGraph(poses, edges, measurements, np.array(information), ids=keys)


def run(name, graph, truth, relax_iterations, methods):
    print(f"\n{name}: {graph.n_poses} poses, {graph.n_edges} edges; initial chi2 {pose_graph_cost(graph):.6g}"
          + (f", initial position RMSE {rmse(graph.poses, truth):.4f} m" if truth is not None else ""))
    rows = []
    peer = gtsam_solve(graph)
    for method in methods:
        res = optimize_pose_graph(graph, method=method)
        rows.append((f"robokit {method}", res.time, res.iterations, res.poses, res.converged))
    if peer is not None:
        rows.append(("gtsam LM (peer)", peer[1], peer[2], peer[0], True))
    res = relax(graph, max_iterations=relax_iterations)
    rows.append(("relaxation (Jacobi)", res.time, res.iterations, res.poses, res.converged))
    peer_cost = pose_graph_cost(graph, peer[0]) if peer else float("nan")
    peer_gtsam = peer[4](peer[0]) if peer else float("nan")
    head = (f"{'solver':<24} {'time s':>8} {'t/peer':>7} {'iter':>6} {'conv':>5} {'chi2':>14} {'chi2/peer':>12} "
            f"{'gtsam err/peer':>14} {'RMSE m':>8}")
    print(head)
    print("-" * len(head))
    for label, seconds, iterations, poses, converged in rows:
        chi2 = pose_graph_cost(graph, poses)
        gtsam_ratio = peer[4](poses) / peer_gtsam if peer else float("nan")
        print(f"{label:<24} {seconds:>8.3f} {seconds / peer[1] if peer else float('nan'):>7.2f} {iterations:>6} "
              f"{str(converged):>5} {chi2:>14.8g} {chi2 / peer_cost:>12.8f} {gtsam_ratio:>14.8f} "
              f"{rmse(poses, truth) if truth is not None else float('nan'):>8.4f}")
    if peer:
        print(f"(building gtsam's factor graph in Python: {peer[3]:.3f} s, not in its time)")


def rmse(poses, truth):
    return float(np.sqrt(np.mean(np.sum((poses[:, :2] - truth[:, :2]) ** 2, axis=1))))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*", help="g2o files (VERTEX_SE2 / EDGE_SE2) to run as well")
    parser.add_argument("--n", type=int, default=500 if fast_mode() else 3500,
                        help="poses of the generated Manhattan graph (0: none)")
    parser.add_argument("--gtsam-example", action="append", default=[], metavar="NAME",
                        help="a 2-D graph gtsam ships, e.g. w10000 (repeatable; needs gtsam)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--relax-iterations", type=int, default=20000, help="most relaxation sweeps")
    parser.add_argument("--no-scipy", action="store_true",
                        help="skip scipy's least_squares (its LSMR steps take minutes on graphs like W10000)")
    args = parser.parse_args(argv)
    methods = ("gauss-newton",) if args.no_scipy else ("gauss-newton", "scipy")
    if args.n:
        graph, truth = manhattan_world_graph(args.n, seed=args.seed)
        run(f"Manhattan world (seed {args.seed})", graph, truth, args.relax_iterations, methods)
    for name in args.gtsam_example:
        run(f"gtsam example {name}", gtsam_example(name), None, args.relax_iterations, methods)
    for path in args.files:
        run(path, read_g2o(path), None, args.relax_iterations, methods)
    print("\nchi2 = sum e^T Omega e with g2o's error; chi2/peer divides by robokit's chi2 at gtsam's optimum; "
          "gtsam err/peer is the same ratio in gtsam's own (SE(2)-log) error;\nt/peer divides by the time of "
          "gtsam's optimize(); RMSE = position error to the truth (generated graphs only).")


if __name__ == "__main__":
    main()
