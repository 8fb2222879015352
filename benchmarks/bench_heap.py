"""The heap pad of ``import robokit`` (:func:`robokit.config.pad_heap`) against glibc's default.

A Monte-Carlo localization update over thousands of particles makes and frees arrays of megabytes.
With glibc's adaptive thresholds such arrays are mapped afresh, or the freed top of the heap goes
back to the system, and the next update faults the memory in again, page by page; ``import robokit``
fixes the thresholds and keeps a pad of ``ROBOKIT_HEAP_PAD_MB`` (64 by default) instead. The same
update (:func:`robokit.localization.mcl_step`: motion model, likelihood field over 60 beams of a
360-beam scan, resampling; ``bench_mcl``'s inputs) runs on the same inputs with and without the
setting; the ratio "padded / default" of the median times is printed (below 1: the setting is
faster), and the results must be identical.

The peer cannot run in this process: the allocator's settings are the whole process's, and once
``mallopt`` has been called glibc no longer adapts its thresholds as it does by default. So each
side runs in a fresh process (``ROBOKIT_HEAP_PAD_MB=0`` for the default), the two alternating
``--rounds`` times on the same machine.

    python benchmarks/bench_heap.py [--repeats 40] [--rounds 3]

Linux with glibc only (elsewhere ``pad_heap`` changes nothing and this prints so).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys

import numpy as np

from bench_mcl import ALPHAS, MODEL, room_field, room_update
from robokit.config import pad_heap
from robokit.localization import mcl_step
from timing import median_time

SIZES = (500, 2000, 5000)


def update(n: int, field, seed: int):
    """One MCL update of ``n`` particles spread over the room (bench_mcl's inputs), as a function of nothing."""
    particles, weights, angles, ranges, odom = room_update(n, seed)

    def run():
        step = mcl_step(particles, weights, *odom, ranges, angles, field, alphas=ALPHAS,
                        rng=np.random.default_rng(seed), **MODEL)
        return step.particles, step.weights
    return run


def child(repeats: int) -> None:
    """This process's side: median time and a digest of the result per size, as one JSON line."""
    field = room_field()
    out = {}
    for n in SIZES:
        run = update(n, field, seed=n)
        digest = hashlib.sha256(b"".join(a.tobytes() for a in run())).hexdigest()
        out[n] = (median_time(run, repeats), digest)
    print(json.dumps(out))


def side(pad_mb: str | None, repeats: int) -> dict:
    """One fresh process: robokit's heap setting (``pad_mb`` None) or none ("0"); the user's own allocator
    variables are left out of both, so that the two sides differ in this setting only."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("MALLOC_", "GLIBC_TUNABLES", "ROBOKIT_HEAP"))}
    if pad_mb is not None:
        env["ROBOKIT_HEAP_PAD_MB"] = pad_mb
    done = subprocess.run([sys.executable, __file__, "--child", "--repeats", str(repeats)], env=env, check=True,
                          capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.repeats)
        return
    if pad_heap({}) == 0:
        print("pad_heap changes nothing here (not Linux with glibc)")
        return
    runs = {"padded": [], "default": []}
    for k in range(args.rounds):                 # alternating, each side first in every other round
        for name in (("default", "padded") if k % 2 == 0 else ("padded", "default")):
            runs[name].append(side("0" if name == "default" else None, args.repeats))
    print(f"one MCL update (60 beams), median of {args.repeats}; {args.rounds} fresh processes a side, alternating")
    for n in map(str, SIZES):
        t = {k: statistics.median(r[n][0] for r in v) for k, v in runs.items()}
        digests = {r[n][1] for v in runs.values() for r in v}
        print(f"{n:>5} particles: padded {t['padded'] * 1e3:6.2f} ms, glibc's default {t['default'] * 1e3:6.2f} ms, "
              f"ratio {t['padded'] / t['default']:.2f}x; the same result in every process: {len(digests) == 1}")
        if len(digests) != 1:
            raise SystemExit("the heap pad changed a result")


if __name__ == "__main__":
    main()
