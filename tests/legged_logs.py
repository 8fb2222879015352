"""A small synthetic LittleDog trial log, random but valid and self-consistent (feet and MoCap
markers placed by the kinematics from the logged joints and trunk pose), shared by the trial-log and
the legged-viz tests."""
from __future__ import annotations

import numpy as np


def synthetic_log(n: int = 40, seed: int = 0, **meta):
    """A crawl-like trial of ``n`` rows: the trunk walks forward and turns a little, one leg at a time
    swings (its foot lifted, its contact False), the others stand."""
    from robokit.geometry import quat_to_matrix, se3_from_rt, transform_points
    from robokit.legged.leg_kinematics import body_fk, body_ik
    from robokit.legged.littledog import MARKERS, STANCE_FEET, STANDING_HEIGHT
    from robokit.legged.trial_log import TrialLog, empty_streams, trial_meta

    rng = np.random.default_rng(seed)
    s = empty_streams(n)
    k = np.arange(n)
    q0 = body_ik(STANCE_FEET).q[0]
    s["q"][:] = q0 + 0.15 * np.sin(2 * np.pi * k[:, None] / 25 + np.arange(12)) * (rng.random(12) > 0.3)
    s["qd"][:] = np.gradient(s["q"], s["t"], axis=0)
    s["q_cmd"][:] = s["q"] + rng.normal(0, 0.01, (n, 12))
    s["q_ref"][1:] = s["q_cmd"][:-1]                      # one cycle of link latency
    s["q_ref"][0] = s["q_cmd"][0]
    s["tau"][:] = rng.normal(0, 0.3, (n, 12))
    s["voltage"][:] = rng.normal(0, 4.0, (n, 12))
    s["current"][:] = rng.normal(0, 0.5, (n, 12))
    yaw = 0.2 * k / n
    s["body_quat"][:] = np.column_stack([np.cos(yaw / 2), np.zeros(n), np.zeros(n), np.sin(yaw / 2)])
    s["body_pos"][:] = np.column_stack([0.003 * k, 0.001 * k, np.full(n, STANDING_HEIGHT)])
    s["body_vel"][:] = rng.normal(0, 0.05, (n, 6))
    T = se3_from_rt(quat_to_matrix(s["body_quat"]), s["body_pos"])
    s["com"][:] = s["body_pos"] + [0.005, 0.0, -0.01]
    s["feet"][:] = np.stack([transform_points(T[i], body_fk(s["q"][i])) for i in range(n)])
    swing = (k // 5) % 5                                   # 0-3: that leg swings; 4: all four stand
    s["contact"][:] = swing[:, None] != np.arange(4)
    s["foot_force"][:] = s["contact"] * (29.4 / s["contact"].sum(1, keepdims=True)) + rng.normal(0, 0.2, (n, 4))
    s["imu_gyro"][:] = rng.normal(0, 0.02, (n, 3))
    s["imu_acc"][:] = [0.0, 0.0, 9.81] + rng.normal(0, 0.05, (n, 3))
    s["mocap_visible"][:] = rng.random((n, 4)) > 0.1
    s["mocap"][:] = np.stack([transform_points(T[i], MARKERS) for i in range(n)]) * s["mocap_visible"][..., None]
    return TrialLog(s, trial_meta(**{"gait": "crawl", "link_latency": 0.01, "link_jitter": 0.002,
                                     "link_loss": 0.01, "seed": seed, "notes": "synthetic", **meta}))
