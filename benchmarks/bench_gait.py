"""Speed of the static stability margin over a whole walk, against one polygon at a time.

Run: ``.venv/bin/python benchmarks/bench_gait.py`` (add ``--quick`` for fewer repeats).

A plan holds one margin per host-loop sample (100 Hz: 5761 samples for LittleDog's 1 m crawl at the
defaults). Prints the median time of :func:`robokit.legged.stability_margins` over the crawl's
samples and its speed-up over a Python loop of :func:`robokit.legged.stability_margin` (a Qhull
hull per sample) on the same samples, timed in the same process, after checking that they agree;
then the time of :func:`robokit.legged.walking_plan` for the 1 m crawl and trot.
"""
from __future__ import annotations

import argparse

import numpy as np

from timing import median_time

from robokit.legged import crawl_gait, stability_margin, stability_margins, trot_gait, walking_plan



def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    reps = 3 if ap.parse_args().quick else 7
    plan = walking_plan(crawl_gait(), 1.0)
    feet, stance, com = plan.feet_world[..., :2], plan.stance, plan.T_world_body[:, :2, 3]

    def loop():
        return np.array([stability_margin(f[s], c) for f, s, c in zip(feet, stance, com)])

    np.testing.assert_allclose(stability_margins(feet, stance, com), loop(), atol=1e-12)
    fast = median_time(lambda: stability_margins(feet, stance, com), reps)
    slow = median_time(loop, max(1, reps // 3))
    print(f"stability margins of {len(plan.t)} samples: vectorised {fast * 1e3:.2f} ms, "
          f"loop of stability_margin {slow * 1e3:.1f} ms: {slow / fast:.0f}x")
    for gait in (crawl_gait(), trot_gait()):
        t = median_time(lambda: walking_plan(gait, 1.0), reps)
        print(f"walking_plan({gait.name}, 1 m): {t * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
