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
ratios "time of robokit / time of ik_LM" are printed (below 1 means robokit is faster). A third
set of iiwa targets has the elbow joint q4 exactly on its +-120 deg limit (poses from clamped
trajectories; every one must solve). TRAC-IK's published figures (Beeson & Ames 2015, Table I:
0.31 ms / 99.84 % on the iiwa14, 0.38 ms / 99.70 % on the Panda; measured on their machine, not
run here) are printed as reference lines.

The single-target solvers are compiled (numba) on their first call and cached on disk
(``$ROBOKIT_CACHE/numba``); the time of that first call in this process is printed, and
``--cold`` also measures import and first-call time in fresh processes with an empty cache (the
compile time a student pays once) and again with the cache filled.

Usage::

    python benchmarks/bench_ik.py            # 10,000 targets per arm, drawn afresh (the seed is printed)
    python benchmarks/bench_ik.py --n 1000   # quicker
    python benchmarks/bench_ik.py --seed 7   # the same targets as an earlier run
    ROBOKIT_FAST=1 python benchmarks/bench_ik.py
    python benchmarks/bench_ik.py --cold     # also the cold-cache compile time (about a minute)

Numbers depend on the machine and its load; the ratios against the peer run in the same process
are what to compare across machines.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from robokit.config import fast_mode
from robokit.arm import iiwa14, ik_numeric, ik_numeric_batch, ik_srs, ik_srs_batch, panda
from robokit.geometry import pose_error


#: ik_LM's tolerance is on E = e^T e / 2; 5e-13 means |e| < 1e-6, the same bar as robokit's.
PEER_TOL = 5e-13
#: TRAC-IK's published mean solve time [ms] and success rate [%] (Beeson & Ames 2015, Table I).
TRAC_IK = {"iiwa14": (0.31, 99.84), "panda": (0.38, 99.70)}

_FIRST_CALL = """
import time
t0 = time.perf_counter()
import numpy as np
from robokit.arm import iiwa14, ik_numeric, ik_srs, panda
t1 = time.perf_counter()
a, p = iiwa14(), panda()
ik_srs(a, a.fk(a.random_q(rng=1)))
t2 = time.perf_counter()
ik_numeric(p, p.fk(p.random_q(rng=1)), rng=1)
t3 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2)
"""


def cold_start():
    """Import time and first-call times (analytic, numeric) [s] in fresh processes: empty cache, then warm."""
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "NUMBA_CACHE_DIR": tmp}
        for _ in range(2):
            r = subprocess.run([sys.executable, "-c", _FIRST_CALL], env=env, capture_output=True, text=True, check=True)
            out.append([float(x) for x in r.stdout.split()])
    return out


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
    parser.add_argument("--n", type=int, default=200 if fast_mode() else 10_000, help="targets per arm (batched)")
    parser.add_argument("--n-single", type=int, default=50 if fast_mode() else 1000,
                        help="targets timed one at a time")
    parser.add_argument("--seed", type=int, default=None,
                        help="seed of the targets and start configurations (default: fresh each run, printed)")
    parser.add_argument("--cold", action="store_true", help="also time import and first calls in fresh processes")
    args = parser.parse_args(argv)
    if args.seed is None:                  # targets the solvers have never been tuned on, drawn afresh each run
        args.seed = int(np.random.SeedSequence().entropy % 2 ** 31)
    print(f"targets and starts drawn with --seed {args.seed} (pass it to repeat this run)")

    t0 = time.perf_counter()
    ik_srs(iiwa14(), iiwa14().fk(np.zeros(7)))
    t1 = time.perf_counter()
    ik_numeric(panda(), panda().fk(np.full(7, -0.5)), rng=1)
    first = (t1 - t0, time.perf_counter() - t1)

    rows = []
    for name, chain in (("iiwa14", iiwa14()), ("panda", panda()), ("iiwa14 q4 on limit", iiwa14())):
        rng = np.random.default_rng(args.seed)
        q_target = chain.random_q(args.n, rng)
        if name.endswith("limit"):
            half = args.n // 2
            q_target[:half, 3], q_target[half:, 3] = chain.qmax[3], chain.qmin[3]
            q_target[::2] = q_target[::2][::-1]               # mix the two signs in the single-target slice
        T = chain.fk(q_target)
        q0s = chain.random_q(args.n, rng)
        ns = min(args.n_single, args.n)
        solvers = []
        if name.startswith("iiwa14"):
            solvers.append(("analytic (arm angle)",
                            lambda T_, s_: ik_srs_batch(chain, T_, s_).q,
                            lambda Ti, si: ik_srs(chain, Ti, si).q))
        for method in ("wln", "gradient_projection", "dls") if name != "iiwa14 q4 on limit" else ():
            solvers.append((f"numeric {method}",
                            lambda T_, s_, m=method: ik_numeric_batch(chain, T_, s_, method=m, rng=1).q,
                            lambda Ti, si, m=method: ik_numeric(chain, Ti, si, method=m, rng=1).q))
        peer = peer_model(name.split()[0], chain)
        if peer is not None:
            def peer_single(Ti, si, peer=peer):
                return np.asarray(peer.ik_LM(Ti, q0=si, tol=PEER_TOL, joint_limits=True).q)
            peer_single(T[0], q0s[0])                          # untimed, as our solvers' first calls above
            solvers.append(("roboticstoolbox ik_LM (C++)", None, peer_single))

        peer_time = None
        results = []
        for label, batch, single in solvers:
            q1, t_single = run_single(single, T[:ns], q0s[:ns])
            ok1, _, _ = verified(chain, T[:ns], q1)
            if batch is not None:
                batch(T[:1], q0s[:1])  # untimed: a batch kernel compiles (or loads) on its first call
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
            results.append([name.split()[0] + (" q4=lim" if "limit" in name else ""), label, n_eval, 100 * rate, 100 * ok1.mean(), t_single * 1e3, t_batch * 1e6,
                            pos_max, rot_max])
        for r in results:
            r.append(r[5] / (peer_time * 1e3) if peer_time else float("nan"))
        rows += results

    head = (f"{'arm':<14} {'solver':<28} {'N':>6} {'success %':>9} {'single %':>8} {'ms/solve':>9} "
            f"{'us/target':>10} {'max pos err':>11} {'max rot err':>11} {'single/ik_LM':>12}")
    print(head)
    print("-" * len(head))
    for arm, label, n, rate, r1, ms, us, pe, re, ratio in rows:
        print(f"{arm:<14} {label:<28} {n:>6} {rate:>9.2f} {r1:>8.2f} {ms:>9.3f} {us:>10.1f} {pe:>11.1e} "
              f"{re:>11.1e} {ratio:>12.2f}")
    for arm, (ms, rate) in TRAC_IK.items():
        print(f"{arm:<14} {'TRAC-IK (published)':<28} {'':>6} {rate:>9.2f} {'':>8} {ms:>9.3f}   "
              "Beeson & Ames 2015, Table I; their machine, not run here")
    print("\nsuccess % = batched run on N targets (single-target run for the peer); single % = the "
          "targets timed one at a time;\nms/solve = one target at a time; us/target = batched call; "
          "errors over successful solves [m, rad].")
    print(f"first call in this process (compiled kernels loaded from the cache or compiled): analytic "
          f"{first[0]:.2f} s, numeric {first[1]:.2f} s")
    if args.cold:
        (imp_c, a_c, n_c), (imp_w, a_w, n_w) = cold_start()
        print(f"fresh process, empty cache: import robokit.arm {imp_c:.2f} s, first analytic solve {a_c:.1f} s, "
              f"first numeric solve {n_c:.1f} s (compile)")
        print(f"fresh process, warm cache:  import robokit.arm {imp_w:.2f} s, first analytic solve {a_w:.2f} s, "
              f"first numeric solve {n_w:.2f} s (load)")

    def pick(arm, label):
        return next(r for r in rows if r[0] == arm and r[1].startswith(label))
    a, b, c = pick("iiwa14", "analytic"), pick("panda", "numeric wln"), pick("iiwa14 q4=lim", "analytic")
    print("\nREADME row:")
    print(f"| `bench_ik` | IK on {args.n:,} targets: iiwa analytic (exact feasible arm-angle intervals), Panda "
          f"numeric (WLN), single solves vs roboticstoolbox `ik_LM` (C++) in the same run; TRAC-IK's published "
          f"0.31 ms / 99.84 % (iiwa14), 0.38 ms / 99.70 % (Panda) for reference | iiwa < 1.0x `ik_LM`, 100 % with "
          f"q4 on its limit; Panda <= 2x `ik_LM`, >= 99.5 % | iiwa {a[5]:.3f} ms = {a[9]:.2f}x `ik_LM`, "
          f"{a[3]:.2f} %, {a[6]:.1f} us batched; q4 on limit {c[3]:.1f} %; Panda {b[5]:.3f} ms = {b[9]:.2f}x "
          f"`ik_LM`, {b[3]:.2f} % |")
    return rows


if __name__ == "__main__":
    main()
