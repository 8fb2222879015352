"""Cost of lesson 04's per-tick loop pieces: the PD servo step, the motor torque and the set-point link.

Run: ``.venv/bin/python -m benchmarks.bench_servo_loop`` (add ``--quick`` for fewer repeats).

The simulation calls :func:`robokit.controllers.pd_servo_step` and
:meth:`robokit.controllers.SetpointChannel.receive` every 2 ms servo tick and
joint_torque's law (MuJoCo's affine actuator) every 1 ms physics step, for 12 joints. Prints the median
time per call (microseconds) of each (the servo step also on its ``validate=False`` fast path), against the
bare numpy expression of the same law timed in the same process (the peer): the ratio says what
the validation and the call cost on top of the arithmetic. One simulated second takes 500 servo
steps, 500 receives and 1000 torques.
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from robokit.controllers import LITTLEDOG_MOTOR, SetpointChannel, joint_torque, pd_servo_step


def per_call(fn, calls: int, repeats: int) -> float:
    """Median over ``repeats`` of the time per call (s) of ``calls`` calls."""
    fn()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        for _ in range(calls):
            fn()
        times.append((time.perf_counter() - t) / calls)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    args = ap.parse_args()
    calls, reps = (2000, 3) if args.quick else (20000, 7)
    rng = np.random.default_rng(0)
    q_ref, q, q_prev, qd = rng.normal(0, 0.3, (4, 12))
    kp, kd, dt, vmax = 96.1, 0.42, 0.002, 14.8
    m = LITTLEDOG_MOTOR
    K, B = m.torque_per_volt, m.damping
    bare_pd = per_call(lambda: np.clip(kp * (q_ref - q) - kd * ((q - q_prev) / dt), -vmax, vmax), calls, reps)
    bare_torque = per_call(lambda: K * np.clip(q_ref, -vmax, vmax) - B * qd, calls, reps)
    link = SetpointChannel(latency=0.004, jitter=0.002, loss=0.05, rng=0)
    state = {"t": 0.0}

    def tick():
        t = state["t"] = state["t"] + 0.002
        if link.due(t):
            link.send(t, q_ref)
        link.receive(t)

    rows = [
        ("pd_servo_step, checked", per_call(lambda: pd_servo_step(q_ref, q, q_prev, kp, kd, dt, vmax), calls, reps),
         bare_pd),
        ("pd_servo_step, validate=False",
         per_call(lambda: pd_servo_step(q_ref, q, q_prev, kp, kd, dt, vmax, validate=False), calls, reps), bare_pd),
        ("joint_torque, checked", per_call(lambda: joint_torque(q_ref, qd, m), calls, reps), bare_torque),
        ("link tick (due/send every 10 ms, receive)", per_call(tick, calls, reps), bare_pd),
    ]
    print(f"{'call (12 joints)':<44}{'us/call':>9}{'x numpy peer':>14}")
    for name, sec, peer in rows:
        print(f"{name:<44}{sec * 1e6:9.2f}{sec / peer:14.1f}")
    print(f"numpy peers: PD law {bare_pd * 1e6:.2f} us, torque law {bare_torque * 1e6:.2f} us")


if __name__ == "__main__":
    main()
