"""Plain data for assignment 04: the model's constants, simulated crawls with their true touchdowns, MoCap frames.

Assignment 04's data (:func:`robocourse.lessons.littledog.exercises.data`). The crawls are the
lesson's walk in MuJoCo (:func:`robokit.legged.simulate_walk`): the lower legs' force sensors, the
plan the host played and MuJoCo's true contacts (the open touchdown exercise's cases are drawn from
them); the MoCap frames come from :func:`robokit.legged.simulate_mocap`.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Secs. 2-3).
"""
from __future__ import annotations

import dataclasses
import functools
from typing import Any

import numpy as np

from robokit.geometry.rotations import rot_x, rot_y, rot_z
from robokit.geometry.spatial import se3_from_rt
from robokit.validation import as_finite_scalar, as_int, as_mapping, as_positive, as_rng
from robokit.legged.gait import walking_plan
from robokit.legged.gait_schedule import crawl_gait
from robokit.legged.littledog import (FOOT_RADIUS, GUIDE, HIP_OFFSETS, HIP_POSITIONS, JOINT_LIMITS, JOINTS, LEGS,
                                      LOWER_LEG, MARKERS, STANCE_FEET, STANDING_HEIGHT, TRUNK_SIZE, UPPER_LEG)
from robokit.legged.mocap import simulate_mocap
from robokit.legged.simulation import LoopSettings, SensorSettings, simulate_walk
from robokit.legged.touchdown import contact_events
from robocourse.lessons.littledog.experiment import LESSON_CRAWL

__all__ = ["CRAWL_LATENCY_MAX", "CRAWL_DISTANCE_MAX", "model_facts", "crawl_touchdowns", "mocap_frames"]


def model_facts() -> dict:
    """The LittleDog model's constants (:mod:`robokit.legged.littledog`) as plain data.

    Returns
    -------
    dict
        ``LEGS``, ``JOINTS``, ``HIP_POSITIONS`` (4 x 3, m, body frame), ``HIP_OFFSETS`` (4, m),
        ``UPPER_LEG``, ``LOWER_LEG``, ``FOOT_RADIUS`` (m), ``STANCE_FEET`` (4 x 3, m),
        ``STANDING_HEIGHT`` (m), ``TRUNK_SIZE`` (m), ``JOINT_LIMITS`` (12 x 2, rad), ``MARKERS``
        (4 x 3, m) and ``GUIDE`` (the guide's numbers, SI units); lists, tuples and floats, named as in
        :mod:`robokit.legged.littledog`.

    Notes
    -----
    The constants are the model's (LittleDog User Guide, Secs. 2-3, and the MIT model).

    Examples
    --------
    >>> facts = model_facts()
    >>> facts["LEGS"], facts["UPPER_LEG"], round(facts["LOWER_LEG"], 6), facts["HIP_OFFSETS"]
    (('FL', 'FR', 'HL', 'HR'), 0.0751, 0.102002, [0.0236, 0.0236, 0.0236, 0.0207])
    """
    return {"LEGS": LEGS, "JOINTS": JOINTS, "HIP_POSITIONS": HIP_POSITIONS.tolist(),
            "HIP_OFFSETS": HIP_OFFSETS.tolist(),
            "UPPER_LEG": UPPER_LEG, "LOWER_LEG": LOWER_LEG, "FOOT_RADIUS": FOOT_RADIUS,
            "STANCE_FEET": STANCE_FEET.round(6).tolist(), "STANDING_HEIGHT": STANDING_HEIGHT,
            "TRUNK_SIZE": TRUNK_SIZE, "JOINT_LIMITS": JOINT_LIMITS.tolist(), "MARKERS": MARKERS.tolist(),
            "GUIDE": dict(GUIDE)}


CRAWL_LATENCY_MAX = 0.15
"""Longest link delay (s) :func:`crawl_touchdowns` simulates: 15 host periods."""
CRAWL_DISTANCE_MAX = 1.0
"""Longest walk (m) :func:`crawl_touchdowns` simulates (the lesson's; about 1.5 s of computing)."""


@functools.lru_cache(maxsize=32)
def _simulated_crawl(gait: tuple, distance: float, latency: float, force_noise: float, seed: int) -> tuple:
    """The walk of :func:`crawl_touchdowns`, computed once per process for equal parameters (a
    notebook's ``check()`` and the grader draw the same public cases again)."""
    plan = walking_plan(crawl_gait(**dict(gait)), distance)
    sensors = dataclasses.replace(SensorSettings(), force_noise=force_noise)
    log = simulate_walk(plan, LoopSettings(latency=latency), sensors, rng=seed).log
    force, stance = log.foot_force.copy(), plan.stance[:len(log)].copy()
    truth = tuple(tuple(int(k) for k in e) for e in contact_events(log.contact))
    force.flags.writeable = stance.flags.writeable = False
    return force, stance, float(log.t[1] - log.t[0]), truth


def crawl_touchdowns(gait: Any = None, *, distance: float = 0.25, latency: float = 0.0, force_noise: float = 0.1,
                     seed: int = 0) -> dict:
    """LittleDog crawling in MuJoCo: its lower-leg forces, its plan's stance and its true touchdowns.

    The lesson's walk (:func:`robokit.legged.simulate_walk` of a
    :func:`~robokit.legged.walking_plan` of a :func:`~robokit.legged.crawl_gait`), with every
    set-point reaching the robot ``latency`` late over the link.

    Parameters
    ----------
    gait : dict, optional
        Keyword arguments of :func:`~robokit.legged.crawl_gait` (``period``, ``step_length``,
        ``step_height``, ``duty_factor``); default the lesson's crawl
        (:data:`~robocourse.lessons.littledog.experiment.LESSON_CRAWL`).
    distance : float, default 0.25
        How far (m) the plan walks, in (0, :data:`CRAWL_DISTANCE_MAX`].
    latency : float, default 0
        One-way link delay (s) of every set-point, in [0, :data:`CRAWL_LATENCY_MAX`].
    force_noise : float, default 0.1
        Standard deviation (N) of the force sensors' noise, in [0, 1].
    seed : int, default 0
        Seeds the sensor noise.

    Returns
    -------
    dict
        ``force`` (N x 4 lists, N: the lower legs' axial forces, legs ``FL, FR, HL, HR``),
        ``planned_stance`` (N x 4 lists of bool: the plan's feet on the ground), ``dt`` (s, the host
        period) and ``touchdowns`` (4 lists of sample indices: the rising edges of MuJoCo's true
        contacts, :func:`robokit.legged.touchdown.contact_events`).

    Raises
    ------
    ValueError, TypeError
        For parameters outside their ranges, a ``gait`` that is not a dict of those keywords, or a
        gait :func:`~robokit.legged.walking_plan` refuses.

    Notes
    -----
    Without link jitter or loss the simulation is deterministic: ``seed`` changes the sensor noise,
    not the touchdowns. The same parameters in one process are simulated once.

    Examples
    --------
    >>> run = crawl_touchdowns(distance=0.1)
    >>> np.shape(run["force"]), [len(t) for t in run["touchdowns"]]
    ((681, 4), [3, 2, 3, 3])
    """
    steps = dict(LESSON_CRAWL)
    for key, value in (as_mapping(gait, "gait") or {}).items():
        if key not in steps:
            raise ValueError(f"gait: expected keywords of crawl_gait ({', '.join(steps)}), got {key!r}")
        steps[key] = as_finite_scalar(value, f"gait[{key!r}]")
    metres = as_positive(distance, "distance")
    if metres > CRAWL_DISTANCE_MAX:
        raise ValueError(f"distance: expected at most {CRAWL_DISTANCE_MAX} m, got {metres}")
    delay = as_positive(latency, "latency", allow_zero=True)
    if delay > CRAWL_LATENCY_MAX:
        raise ValueError(f"latency: expected at most {CRAWL_LATENCY_MAX} s, got {delay}")
    noise = as_positive(force_noise, "force_noise", allow_zero=True)
    if noise > 1.0:
        raise ValueError(f"force_noise: expected at most 1 N, got {noise}")
    seed = as_int(seed, "seed", minimum=0)
    force, stance, dt, truth = _simulated_crawl(tuple(steps.items()), metres, delay, noise, seed)
    return {"force": force.tolist(), "planned_stance": stance.tolist(), "dt": dt,
            "touchdowns": [list(t) for t in truth]}


def mocap_frames(seed: int = 0, n: int = 200, noise: float = 0.001) -> dict:
    """MoCap frames of the LittleDog standing and turning, for the assignment's question on the marker fit.

    Parameters
    ----------
    seed : int, default 0
    n : int, default 200
        Frames, 1 to 10000.
    noise : float, default 0.001
        Standard deviation (m) of each marker coordinate's noise (>= 0).

    Returns
    -------
    dict
        ``markers_body`` (4 x 3, m: :data:`~robokit.legged.littledog.MARKERS`), ``T_world_body``
        (n x 4 x 4, the true poses: any heading, roll and pitch within 0.1 rad, the trunk at its
        standing height within 1 cm, anywhere in a 2 m square) and ``observed`` (n x 4 x 3, m, every
        marker seen), all lists; and ``noise``.

    Notes
    -----
    The markers by :func:`robokit.legged.simulate_mocap` (no dropouts: the question
    hides markers itself); the pose ``R = R_z(yaw) R_y(pitch) R_x(roll)``.

    Examples
    --------
    >>> data = mocap_frames(n=2, noise=0.0)
    >>> T = np.array(data["T_world_body"][0])
    >>> np.allclose(data["observed"][0], np.array(data["markers_body"]) @ T[:3, :3].T + T[:3, 3])
    True
    """
    g = as_rng(as_int(seed, "seed", minimum=0))
    count = as_int(n, "n", minimum=1, maximum=10_000)
    sigma = as_positive(noise, "noise", allow_zero=True)
    roll, pitch = g.uniform(-0.1, 0.1, (2, count))
    yaw = g.uniform(-np.pi, np.pi, count)
    T = se3_from_rt(rot_z(yaw) @ rot_y(pitch) @ rot_x(roll),
                    np.column_stack([g.uniform(-1.0, 1.0, (count, 2)), STANDING_HEIGHT + g.uniform(-0.01, 0.01, count)]))
    frames = simulate_mocap(T, MARKERS, sigma, 0.0, g)
    return {"markers_body": MARKERS.tolist(), "T_world_body": T.tolist(), "observed": frames.positions.tolist(),
            "noise": sigma}
