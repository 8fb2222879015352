"""Exercises of assignment 06 (redundant 7-DOF arm IK): from one DH transform to a null-space step.

Inputs are generated from the KUKA LBR iiwa 14 R820 and the Franka Panda of :mod:`robokit.arm`
(random configurations inside the joint limits), plus small hand-checkable chains.
"""
from __future__ import annotations

import numpy as np

from ..arm import (dh_fk, dh_jacobian, dh_transform, elbow_angle, geometric_jacobian, iiwa14,
                   limit_distance_gradient, null_space_step, panda, shoulder_angles, wrist_centre)
from .compare import close
from .spec import Case, Exercise

ASSIGNMENT = "06_redundant_ik"
#: Written (manually graded) questions: id -> points.
WRITTEN = {"06.extra_dof": 2}

_IIWA = iiwa14()
_IIWA_DH = np.stack([_IIWA.d, _IIWA.a, _IIWA.alpha], 1).tolist()
_PLANAR = [[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]]            # two-link planar arm, lengths 1 m and 0.5 m
_SHOULDER = [0.0, 0.0, 0.36]
_D_SE, _D_EW, _D_WF = 0.42, 0.40, 0.126


def _iiwa_q(rng: np.random.Generator, n: int) -> np.ndarray:
    q = _IIWA.random_q(n, rng)
    # keep clear of the shoulder/wrist singularities (sin q2 = 0), where q1 and q3 are not unique
    q[:, 1] = np.sign(q[:, 1]) * np.clip(np.abs(q[:, 1]), 0.2, None)
    return q


def _dh_cases(rng: np.random.Generator) -> list[Case]:
    p = rng.uniform([-np.pi, -0.5, -0.5, -np.pi], [np.pi, 0.5, 0.5, np.pi], size=(3, 4))
    return [
        Case((0.0, 0.0, 0.0, 0.0), label="all zero: identity"),
        Case((np.pi / 2, 0.36, 0.0, -np.pi / 2), label="iiwa joint 1 at 90 deg"),
        *[Case(tuple(float(v) for v in row), label="random parameters") for row in p],
        Case((float("nan"), 0.1, 0.0, 0.0), raises="ValueError", label="NaN theta"),
    ]


def _fk_cases(rng: np.random.Generator) -> list[Case]:
    q = _iiwa_q(rng, 2)
    return [
        Case((_PLANAR, [0.0, 0.0]), label="planar arm stretched out"),
        Case((_PLANAR, [np.pi / 2, -np.pi / 2]), label="planar arm, elbow bent"),
        Case((_IIWA_DH, [0.0] * 7), label="iiwa at zero: 1.306 m straight up"),
        *[Case((_IIWA_DH, qi.tolist()), label="iiwa, random configuration") for qi in q],
        Case((_IIWA_DH, [0.0] * 6), raises="ValueError", label="6 angles for 7 joints"),
    ]


def _jacobian_cases(rng: np.random.Generator) -> list[Case]:
    q = _iiwa_q(rng, 2)
    return [
        Case((_PLANAR, [0.3, 0.4]), label="planar arm"),
        *[Case((_IIWA_DH, qi.tolist()), label="iiwa, random configuration") for qi in q],
        Case((_IIWA_DH, [0.1] * 8), raises="ValueError", label="8 angles for 7 joints"),
    ]


def _wrist_cases(rng: np.random.Generator) -> list[Case]:
    T = _IIWA.fk(_iiwa_q(rng, 3))
    bad = T[0].copy()
    bad[:3, :3] *= 1.5
    return [
        *[Case((Ti.tolist(), _D_WF), label="iiwa target pose") for Ti in T],
        Case((np.eye(4).tolist(), 0.2), label="identity pose"),
        Case((bad.tolist(), _D_WF), raises="ValueError", label="rotation block scaled: not SE(3)"),
    ]


def _elbow_cases(rng: np.random.Generator) -> list[Case]:
    frames = _IIWA.link_frames(_iiwa_q(rng, 3))
    W = frames[:, 5, :3, 3]
    return [
        *[Case((_SHOULDER, w.tolist(), _D_SE, _D_EW), label="iiwa wrist centre") for w in W],
        Case((_SHOULDER, [0.0, 0.0, 0.36 + 0.82], _D_SE, _D_EW), label="arm stretched: q4 = 0"),
        Case((_SHOULDER, [0.0, 0.0, 1.5], _D_SE, _D_EW), raises="ValueError", label="wrist out of reach"),
    ]


def _shoulder_cases(rng: np.random.Generator) -> list[Case]:
    q = _iiwa_q(rng, 4)
    W = _IIWA.link_frames(q)[:, 5, :3, 3]
    psi = rng.uniform(-np.pi, np.pi, size=4)
    return [
        *[Case((_SHOULDER, w.tolist(), float(qi[3]), float(p), _D_SE, _D_EW), label="iiwa, random arm angle")
          for w, qi, p in zip(W, q, psi)],
        Case((_SHOULDER, W[0].tolist(), float(q[0, 3]), float("nan"), _D_SE, _D_EW), raises="ValueError",
             label="NaN arm angle"),
    ]


def _null_space_cases(rng: np.random.Generator) -> list[Case]:
    arm = panda()
    q = arm.random_q(3, rng)
    J = geometric_jacobian(arm, q)
    g = limit_distance_gradient(arm, q)
    e = rng.normal(0, 0.01, size=(3, 6))
    return [
        Case((J[0], [0.0] * 6, g[0].tolist(), 0.0, 1.0), label="zero pose error: pure self-motion"),
        Case((J[1], e[1].tolist(), [0.0] * 7, 0.05, 1.0), label="zero gradient: plain DLS"),
        Case((J[2], e[2].tolist(), g[2].tolist(), 0.01, 0.5), label="both terms"),
        Case((J[0][:5], e[0].tolist(), g[0].tolist(), 0.01, 0.5), raises="ValueError",
             label="Jacobian with 5 rows"),
    ]


EXERCISES = [
    Exercise(
        id="06.dh_transform",
        function="dh_transform",
        signature="dh_transform(theta: float, d: float, a: float, alpha: float) -> numpy.ndarray",
        points=1,
        cases=_dh_cases,
        reference=dh_transform,
        references=("robokit.arm.dh.dh_transform", "robokit.arm.dh.mdh_transform", "robokit.arm.dh._link_matrices",
                    "robokit.arm.dh._params"),
        compare=close(rtol=0, atol=1e-9),
        description="Standard DH link transform Rz(theta) Tz(d) Tx(a) Rx(alpha), 4x4; ValueError on NaN.",
    ),
    Exercise(
        id="06.forward_kinematics",
        function="forward_kinematics",
        signature="forward_kinematics(dh: list[list[float]], q: list[float]) -> numpy.ndarray",
        points=1,
        cases=_fk_cases,
        reference=dh_fk,
        references=("robokit.arm.chain.dh_fk", "robokit.arm.chain.chain_from_table"),
        compare=close(rtol=0, atol=1e-9),
        description=("Flange pose (4x4) of a standard-DH chain with rows [d, a, alpha]; "
                     "ValueError on a length mismatch."),
    ),
    Exercise(
        id="06.geometric_jacobian",
        function="geometric_jacobian",
        signature="geometric_jacobian(dh: list[list[float]], q: list[float]) -> numpy.ndarray",
        points=2,
        cases=_jacobian_cases,
        reference=dh_jacobian,
        references=("robokit.arm.jacobian.dh_jacobian", "robokit.arm.jacobian.geometric_jacobian",
                    "robokit.arm.jacobian.jacobian_from_frames"),
        compare=close(rtol=0, atol=1e-9),
        description="6 x n geometric Jacobian [v; omega] in the base frame; ValueError on a length mismatch.",
    ),
    Exercise(
        id="06.wrist_centre",
        function="wrist_centre",
        signature="wrist_centre(T: list[list[float]], d_wf: float) -> numpy.ndarray",
        points=1,
        cases=_wrist_cases,
        reference=wrist_centre,
        references=("robokit.arm.srs.wrist_centre",),
        compare=close(rtol=0, atol=1e-9),
        description="W = p - d_wf * z of the target pose; ValueError if T is not SE(3).",
    ),
    Exercise(
        id="06.elbow_angle",
        function="elbow_angle",
        signature="elbow_angle(shoulder: list[float], wrist: list[float], d_se: float, d_ew: float) -> float",
        points=1,
        cases=_elbow_cases,
        reference=elbow_angle,
        references=("robokit.arm.srs.elbow_angle",),
        compare=close(rtol=0, atol=1e-7),
        description="Elbow joint q4 >= 0 by the law of cosines; ValueError when the wrist is out of reach.",
    ),
    Exercise(
        id="06.shoulder_angles",
        function="shoulder_angles",
        signature=("shoulder_angles(shoulder: list[float], wrist: list[float], q4: float, psi: float, "
                   "d_se: float, d_ew: float) -> numpy.ndarray"),
        points=2,
        cases=_shoulder_cases,
        reference=shoulder_angles,
        references=("robokit.arm.srs.shoulder_angles", "robokit.arm.srs._reference_rotation",
                    "robokit.arm.ik_analytic.ik_srs_branches"),
        compare=close(rtol=0, atol=1e-7),
        description="(q1, q2 >= 0, q3) of the iiwa for arm angle psi; ValueError on NaN.",
    ),
    Exercise(
        id="06.null_space_step",
        function="null_space_step",
        signature=("null_space_step(J: numpy.ndarray, e: list[float], gradient: list[float], damping: float, "
                   "gain: float) -> numpy.ndarray"),
        points=2,
        cases=_null_space_cases,
        reference=null_space_step,
        references=("robokit.arm.ik_steps.null_space_step", "robokit.arm.ik_steps.dls_step", "robokit.arm.ik_steps._gp",
                    "robokit.arm.ik_steps._jacobian_and_error", "robokit.arm.ik_steps.GradientProjection"),
        compare=close(rtol=1e-6, atol=1e-9),
        description="DLS step plus the gradient projected into the null space; ValueError on a bad Jacobian shape.",
    ),
]
