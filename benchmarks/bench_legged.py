"""LittleDog's two speed targets: the walking simulation against real time, batched leg IK.

Run: ``.venv/bin/python benchmarks/bench_legged.py`` (add ``--quick`` for fewer repeats).

1. :func:`robokit.legged.simulate_walk` - MuJoCo physics every 1 ms, the joint servo at 500 Hz
   driving twelve DC motors, the host at 100 Hz sending IK set-points over the link, every host
   cycle logged - on the lesson's 1 m trot and crawl: simulated seconds per wall second (target:
   at least 20x real time on one core), and against MuJoCo stepping the same model for the same
   time with constant torques and nothing else (the peer: what the loops cost on top of physics).
2. :func:`robokit.legged.leg_kinematics.leg_ik_batch` on 10,000 reachable targets (target: under
   5 ms), against a Python loop of the single-target :func:`~robokit.legged.leg_kinematics.leg_ik`
   on the same targets, after checking they agree.
"""
from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np
from timing import median_time

from robokit.controllers import LITTLEDOG_MOTOR
from robokit.legged import STANCE_FEET, littledog_model, simulate_walk
from robokit.legged import leg_kinematics as lk
from robocourse.lessons.littledog.experiment import lesson_plans


def bare_physics(seconds: float) -> float:
    """Wall time of MuJoCo alone stepping the model for ``seconds`` of simulated time."""
    model = littledog_model(motor=LITTLEDOG_MOTOR)
    data = mujoco.MjData(model)
    data.qpos[7:] = lk.body_ik(STANCE_FEET).q[0]
    steps = int(round(seconds / model.opt.timestep))
    t = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    reps = 1 if ap.parse_args().quick else 3
    for name, plan in lesson_plans(1.0).items():
        sim_time = float(plan.t[-1])
        wall = median_time(lambda: simulate_walk(plan), reps)
        bare = median_time(lambda: bare_physics(sim_time), reps)
        print(f"simulate_walk({name}, 1 m): {sim_time:.1f} s simulated in {wall:.2f} s = {sim_time / wall:.1f}x "
              f"real time; MuJoCo alone {sim_time / bare:.0f}x real time (the loops cost {wall / bare:.1f}x physics)")
    targets = lk.reachable_workspace("FL", 40000, rng=0)[:10000]
    assert len(targets) == 10000
    fast = median_time(lambda: lk.leg_ik_batch(targets, "FL"), 5 * reps)
    q = lk.leg_ik_batch(targets, "FL").q
    loop_q = np.array([lk.leg_ik(p, "FL") for p in targets[:500]])
    np.testing.assert_allclose(loop_q, q[:500], atol=1e-12)
    slow = median_time(lambda: [lk.leg_ik(p, "FL") for p in targets[:1000]], reps) * 10
    print(f"leg_ik_batch on 10,000 targets: {fast * 1e3:.2f} ms (target < 5 ms); a loop of leg_ik: "
          f"{slow * 1e3:.0f} ms (from 1,000 targets): {slow / fast:.0f}x")


if __name__ == "__main__":
    main()
