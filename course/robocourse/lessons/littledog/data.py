"""Plain data for assignment 04: the model's constants, synthetic foot-force traces, MoCap frames.

Assignment 04's data (:func:`robocourse.lessons.littledog.exercises.data`). The force
traces come from a generator of our own whose true touchdowns are known (the open exercise's cases
are drawn from it too); the MoCap frames come from :func:`robokit.legged.simulate_mocap`.

The force trace is a model of ours, shaped by the LittleDog User Guide (Sec. 3: "a single axis force
sensor in the lower leg, capable of detecting touchdown events and measuring approximate lower leg
axial forces"; Sec. 2: the host reads the robot's state every 10 ms) and the robot's 3 kg (a foot
in stance carries a third to a half of its 29 N weight).

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Secs. 2-3).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from robokit.geometry.rotations import rot_x, rot_y, rot_z
from robokit.geometry.spatial import se3_from_rt
from robokit.validation import as_rng, as_int, as_positive
from robokit.legged.littledog import (FOOT_RADIUS, GUIDE, HIP_OFFSETS, HIP_POSITIONS, JOINT_LIMITS, JOINTS, LEGS,
                                      LOWER_LEG,
                        MARKERS, STANCE_FEET, STANDING_HEIGHT, TRUNK_SIZE, UPPER_LEG)
from robokit.legged.mocap import simulate_mocap

__all__ = ["TRACE_DT", "MAX_TRACE_NOISE", "MAX_TRACE_DRIFT", "model_facts", "touchdown_trace", "touchdown_traces",
           "mocap_frames"]

TRACE_DT = 0.01
"""Sample period of the force traces (s): the host reads the robot every 10 ms (guide, Sec. 2)."""
MAX_TRACE_NOISE = 0.4
"""Largest noise (N, standard deviation) :func:`touchdown_trace` makes."""
MAX_TRACE_DRIFT = 1.0
"""Largest offset drift (N, amplitude) :func:`touchdown_trace` makes."""


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


def _bounded(value: Any, name: str, high: float) -> float:
    v = as_positive(value, name, allow_zero=True)
    if v > high:
        raise ValueError(f"{name}: expected a value in [0, {high:g}], got {v}")
    return v


def touchdown_trace(rng: Any = None, *, duration: float = 8.0, noise: float = 0.2, bounce: float = 0.5,
                    drift: float = 0.5) -> dict:
    """A lower-leg axial force trace of one walking foot, sampled every 10 ms, with its true touchdowns.

    Parameters
    ----------
    rng : numpy.random.Generator or int, optional
    duration : float, default 8
        Length (s), from 1 to 600.
    noise : float, default 0.2
        Standard deviation (N) of the sensor noise, in [0, :data:`MAX_TRACE_NOISE`]; the noise is
        Gaussian clipped at three standard deviations.
    bounce : float, default 0.5
        Probability, in [0, 1], that a touchdown bounces: the force drops to 0-1 N for one or two
        samples (10-20 ms) right after the impact sample.
    drift : float, default 0.5
        Amplitude (N) of the sensor's slow offset drift, a sine of period 4-10 s, in
        [0, :data:`MAX_TRACE_DRIFT`].

    Returns
    -------
    dict
        ``t`` (N,) times (s) and ``force`` (N,) newtons, as lists; ``touchdowns``, the true
        touchdowns' sample indices (list of int); ``dt`` = :data:`TRACE_DT`.

    Raises
    ------
    ValueError
        For parameters outside their ranges.
    TypeError
        For an ``rng`` that is neither a Generator nor a non-negative integer seed.

    Notes
    -----
    A model of ours (the guide gives none). The trace starts with 0.2-0.4 s in the air, then
    repeats stance (0.4-0.8 s) and swing (0.15-0.35 s), ending in the air. A stance carries a load
    of 10-15 N (a third to a half of the 3 kg robot's weight): its first sample - the touchdown - is
    the impact, 0.8-1.2 times the load; then the load varies by 10 % as the weight shifts, and the
    last 60-120 ms unload linearly. Swing is 0 N. Drift and noise are added everywhere. So every
    touchdown sample reads above 5.8 N and every swing sample below 2.2 N, and a bounce ends by the
    second sample after the touchdown: a detector with hysteresis and a 30 ms debounce finds every
    touchdown within 50 ms, and a plain threshold counts most bounces as touchdowns. The random
    draws come in the same order whatever the parameters.

    Examples
    --------
    >>> trace = touchdown_trace(0, duration=3.0, noise=0.0, bounce=0.0, drift=0.0)
    >>> trace["touchdowns"], [round(trace["force"][k], 2) for k in (32, 33, 34)]   # the air, the impact, stance
    ([33, 100, 172], [0.0, 16.39, 13.06])
    """
    g = as_rng(rng)
    seconds = as_positive(duration, "duration")
    if not 1.0 <= seconds <= 600.0:
        raise ValueError(f"duration: expected 1 to 600 s (a step to ten minutes), got {seconds}")
    sigma = _bounded(noise, "noise", MAX_TRACE_NOISE)
    p_bounce = _bounded(bounce, "bounce", 1.0)
    amplitude = _bounded(drift, "drift", MAX_TRACE_DRIFT)
    n = int(round(seconds / TRACE_DT))
    t = np.arange(n) * TRACE_DT
    force = np.zeros(n)
    touchdowns = []
    k = int(round(g.uniform(0.2, 0.4) / TRACE_DT))
    while True:
        stance, swing, ramp = (int(round(g.uniform(lo, hi) / TRACE_DT))
                               for lo, hi in ((0.4, 0.8), (0.15, 0.35), (0.06, 0.12)))
        load, impact, phase = g.uniform(10.0, 15.0), g.uniform(0.8, 1.2), g.uniform(0, 2 * np.pi)
        bounces, two, dips = g.random() < p_bounce, g.random() < 0.5, g.uniform(0.0, 1.0, 2)
        if k + stance + swing > n:
            break
        j = np.arange(stance)
        shape = load * (1.0 + 0.1 * np.sin(2 * np.pi * j / stance + phase))   # weight shifting
        shape[0] = load * impact                                               # the impact: the touchdown
        shape[-ramp:] *= (ramp - np.arange(ramp)) / (ramp + 1)                 # unloading before lift-off
        if bounces:
            first = 1 if two else 1 + int(dips[1] < 0.5)                       # samples 1-2, 1 or 2
            shape[first:first + 1 + two] = dips[:1 + two]
        force[k:k + stance] = shape
        touchdowns.append(k)
        k += stance + swing
    period, offset = g.uniform(4.0, 10.0), g.uniform(0, 2 * np.pi)
    force += amplitude * np.sin(2 * np.pi * t / period + offset)
    force += np.clip(g.normal(0.0, 1.0, n), -3.0, 3.0) * sigma
    return {"t": t.round(6).tolist(), "force": force.tolist(), "touchdowns": touchdowns, "dt": TRACE_DT}


def touchdown_traces(seed: int = 0) -> dict:
    """Three force traces for the assignment's question on touchdown detection: clean, bouncy, noisy.

    Parameters
    ----------
    seed : int, default 0

    Returns
    -------
    dict
        ``{"clean": ..., "bouncy": ..., "noisy": ...}``, each a :func:`touchdown_trace` of 20 s:
        clean (0.05 N noise, no bounce, no drift), bouncy (0.1 N noise, 90 % of touchdowns bounce,
        0.2 N drift) and noisy (0.4 N noise, 30 % bounce, 1 N drift).

    Notes
    -----
    :func:`touchdown_trace`'s model (ours).

    Examples
    --------
    >>> traces = touchdown_traces()
    >>> sorted(traces), len(traces["clean"]["force"]), len(traces["noisy"]["touchdowns"])
    (['bouncy', 'clean', 'noisy'], 2000, 22)
    """
    seed = as_int(seed, "seed", minimum=0)
    settings = {"clean": (0.05, 0.0, 0.0), "bouncy": (0.1, 0.9, 0.2), "noisy": (0.4, 0.3, 1.0)}
    return {name: touchdown_trace(np.random.default_rng([seed, i]), duration=20.0, noise=noise, bounce=bounce,
                                  drift=drift)
            for i, (name, (noise, bounce, drift)) in enumerate(settings.items())}


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
