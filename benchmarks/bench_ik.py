"""Benchmark robokit.arm's IK solvers: success rate, accuracy and time per solve.

For the KUKA LBR iiwa 14 R820 (analytic arm-angle IK and the numerical solvers) and the Franka
Panda (numerical solvers) on random reachable targets: each target is the flange pose of a
configuration drawn uniformly inside the joint limits; each solve starts from another random
configuration inside the limits (``q0``). A solve succeeds when the FK of the answer is within
1e-6 m and 1e-6 rad of the target and every joint is inside its limits (checked here, not taken
from the solver).

If roboticstoolbox-python is installed, its C++ Levenberg-Marquardt solver ``ik_LM`` runs on the
same targets and start configurations (its error E = e^T e / 2 below 5e-13, i.e. |e| < 1e-6; joint limits
on; its default 100 searches), and the
ratios "time of robokit / time of ik_LM" are printed (below 1 means robokit is faster).

Usage::

    python benchmarks/bench_ik.py            # 10,000 targets per arm
    python benchmarks/bench_ik.py --n 1000   # quicker
    ROBOKIT_FAST=1 python benchmarks/bench_ik.py

Numbers depend on the machine and its load; the ratios against the peer run in the same process
are what to compare across machines.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import robokit
from robokit.arm import iiwa14, ik_numeric, ik_numeric_batch, ik_srs, ik_srs_batch, panda, pose_error


#: ik_LM's tolerance is on E = e^T e / 2; 5e-13 means |e| < 1e-6, the same bar as robokit's.
PEER_TOL = 5e-13


def _max(x):
    return float(x.max()) if x.size else float("nan")


def verified(chain, T, q):
    e = pose_error(T, chain.fk(q))
    ok = (np.linalg.norm(e[:, :3], axis=1) < 1e-6) & (np.linalg.norm(e[:, 3:], axis=1) < 1e-6)
    return ok & chain.within_limits(q), np.linalg.norm(e[:, :3], axis=1), np.linalg.norm(e[:, 3:], axis=1)


def run_single(solve, T, q0s):
    qs, t0 = [], time.perf_counter()
    for Ti, si in zip(T, q0s):
        qs.append(solve(Ti, si))
    return np.array(qs), (time.perf_counter() - t0) / len(T)


def peer_model(name, chain):
    """roboticstoolbox's ETS for the same kinematics (None if it is not installed)."""
    try:
        import roboticstoolbox as rtb
    except Exception:  # noqa: BLE001 - optional peer
        return None
    if name == "panda":
        robot = rtb.models.Panda()
        return robot.ets(end="panda_link8")
    links = [rtb.RevoluteDH(d=d, a=a, alpha=al, qlim=[lo, hi])
             for d, a, al, lo, hi in zip(chain.d, chain.a, chain.alpha, chain.qmin, chain.qmax)]
    return rtb.DHRobot(links).ets()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=200 if robokit.FAST else 10_000, help="targets per arm (batched)")
    parser.add_argument("--n-single", type=int, default=50 if robokit.FAST else 1000,
                        help="targets timed one at a time")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)

    rows = []
    for name, chain in (("iiwa14", iiwa14()), ("panda", panda())):
        rng = np.random.default_rng(args.seed)
        T = chain.fk(chain.random_q(args.n, rng))
        q0s = chain.random_q(args.n, rng)
        ns = min(args.n_single, args.n)
        solvers = []
        if name == "iiwa14":
            solvers.append(("analytic (arm angle)",
                            lambda T_, s_: ik_srs_batch(chain, T_, s_).q,
                            lambda Ti, si: ik_srs(chain, Ti, si).q))
        for method in ("wln", "gradient_projection", "dls"):
            solvers.append((f"numeric {method}",
                            lambda T_, s_, m=method: ik_numeric_batch(chain, T_, s_, method=m, rng=1).q,
                            lambda Ti, si, m=method: ik_numeric(chain, Ti, si, method=m, rng=1).q))
        peer = peer_model(name, chain)
        if peer is not None:
            def peer_single(Ti, si, peer=peer):
                return np.asarray(peer.ik_LM(Ti, q0=si, tol=PEER_TOL, joint_limits=True).q)
            solvers.append(("roboticstoolbox ik_LM (C++)", None, peer_single))

        peer_time = None
        results = []
        for label, batch, single in solvers:
            q1, t_single = run_single(single, T[:ns], q0s[:ns])
            ok1, _, _ = verified(chain, T[:ns], q1)
            if batch is not None:
                t0 = time.perf_counter()
                qb = batch(T, q0s)
                t_batch = (time.perf_counter() - t0) / args.n
                okb, pos, rot = verified(chain, T, qb)
                rate, n_eval = okb.mean(), args.n
                pos_max, rot_max = _max(pos[okb]), _max(rot[okb])
            else:
                t_batch, rate, n_eval = float("nan"), ok1.mean(), ns
                _, pos, rot = verified(chain, T[:ns], q1)
                pos_max, rot_max = _max(pos[ok1]), _max(rot[ok1])
            if label.startswith("roboticstoolbox"):
                peer_time = t_single
            results.append([name, label, n_eval, 100 * rate, 100 * ok1.mean(), t_single * 1e3, t_batch * 1e6,
                            pos_max, rot_max])
        for r in results:
            r.append(r[5] / (peer_time * 1e3) if peer_time else float("nan"))
        rows += results

    head = (f"{'arm':<7} {'solver':<28} {'N':>6} {'success %':>9} {'single %':>8} {'ms/solve':>9} "
            f"{'us/target':>10} {'max pos err':>11} {'max rot err':>11} {'single/ik_LM':>12}")
    print(head)
    print("-" * len(head))
    for arm, label, n, rate, r1, ms, us, pe, re, ratio in rows:
        print(f"{arm:<7} {label:<28} {n:>6} {rate:>9.2f} {r1:>8.2f} {ms:>9.3f} {us:>10.1f} {pe:>11.1e} "
              f"{re:>11.1e} {ratio:>12.2f}")
    print("\nsuccess % = batched run on N targets (single-target run for the peer); single % = the "
          "targets timed one at a time;\nms/solve = one target at a time; us/target = batched call; "
          "errors over successful solves [m, rad].")
    return rows


if __name__ == "__main__":
    main()
