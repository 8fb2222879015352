"""Exercises of assignment 00 (getting started): two tiny warm-ups that exercise the grader."""
from __future__ import annotations

import numpy as np

from robokit.geometry import se2_compose, wrap_angle
from robocourse.exercises.compare import close
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
        compare=close(rtol=0, atol=1e-9),
        kind="transcription",
        description="Compose planar poses [x, y, theta]; raise ValueError on a wrong shape.",
    ),
]
