"""Exercises of assignment 00 (getting started): a warm-up and a small derivation that exercise the grader.

References
----------
.. [1] R. Smith, M. Self and P. Cheeseman, "Estimating uncertain spatial relationships in robotics",
   in *Autonomous Robot Vehicles*, Springer, 1990 (the compounding operation).
"""
from __future__ import annotations

import numpy as np

from typing import Any

from robokit.geometry import se2_compose, wrap_angle
from robocourse.exercises.compare import close
from robocourse.exercises.plain import numeric_array
from robocourse.exercises.spec import Case, Exercise

ASSIGNMENT = "00_getting_started"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"00.why_seeds": 1}


def _wrap_cases(rng: np.random.Generator) -> list[Case]:
    values = rng.uniform(-20, 20, size=4)
    return [
        Case((0.5,), label="already inside"),
        Case((np.pi,), label="+pi maps to -pi"),
        Case((-np.pi,), label="-pi stays"),
        Case((float(values[0]),), label="large positive or negative"),
        Case((values[1:].tolist(),), label="a list of angles"),
        Case((float("nan"),), raises="ValueError", label="NaN is rejected"),
    ]


def _compose_cases(rng: np.random.Generator) -> list[Case]:
    poses = rng.uniform([-5, -5, -np.pi], [5, 5, np.pi], size=(4, 3))
    return [
        Case(([0.0, 0.0, 0.0], [1.0, 2.0, 0.3]), label="identity first"),
        Case(([1.0, 0.0, np.pi / 2], [1.0, 0.0, 0.0]), label="a quarter turn"),
        Case((poses[0].tolist(), poses[1].tolist()), label="random poses"),
        Case((poses[2].tolist(), poses[3].tolist()), label="random poses"),
        Case(([0.0, 0.0, 3.0], [0.0, 0.0, 1.0]), label="heading wraps"),
        Case(([0.0, 0.0], [1.0, 2.0, 0.3]), raises="ValueError", label="pose of length 2"),
    ]


_CLOSE = close(rtol=0, atol=1e-9)


def _compose_diagnosis(expected: Any, got: Any) -> str | None:
    """Accept ``a (+) b`` within 1e-9; otherwise say which part of the derivation is wrong: the
    position (how b's offset enters the world) or the heading (the sum, or its wrap)."""
    message = _CLOSE(expected, got)
    if message is None:
        return None
    e, g = np.asarray(expected, float), numeric_array(got)
    if g is None or g.shape != (3,) or g.dtype.kind not in "fiu":
        return message
    g = g.astype(float)
    if not np.all(np.isfinite(g)):
        return message + "; expected finite numbers"
    hints = []
    if not np.allclose(g[:2], e[:2], rtol=0, atol=1e-9):
        hints.append("the position is wrong: b's x and y are measured along frame a's axes, so they reach the "
                     "world only after a rotation by a's heading (check its direction: a turn of +90 deg takes "
                     "a's x axis to the world's y axis)")
    d = g[2] - e[2]
    if abs(wrap_angle(d)) < 1e-9 and abs(d) > 1e-9:
        hints.append("the heading is right up to a whole turn: wrap it to [-pi, pi)")
    elif abs(d) > 1e-9:
        hints.append("the heading is wrong: how much has the frame turned from the world's x axis in all?")
    return message + ("; " + "; ".join(hints) if hints else "")


EXERCISES = [
    Exercise(
        id="00.wrap_angle",
        function="wrap_angle",
        signature="wrap_angle(angle: float | list[float]) -> float | numpy.ndarray",
        points=1,
        cases=_wrap_cases,
        answer=wrap_angle,
        compare=close(rtol=0, atol=1e-9),
        kind="warm-up",
        description="Wrap angles in radians to [-pi, pi); raise ValueError on NaN.",
    ),
    Exercise(
        id="00.se2_compose",
        function="se2_compose",
        signature="se2_compose(a: list[float], b: list[float]) -> numpy.ndarray",
        points=2,
        cases=_compose_cases,
        answer=se2_compose,
        compare=_compose_diagnosis,
        kind="derivation",
        description="Compose planar poses [x, y, theta], derived from what a pose means (a rotation and a "
                    "translation of a frame); raise ValueError on a wrong shape.",
    ),
]
