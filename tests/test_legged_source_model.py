"""robokit's LittleDog against its source, the MIT model's URDF (tests/data/littledog/).

The URDF is read here with the standard library: each joint's origin and axis, each leg's
``*_foot_center`` frame, each joint's limits. Forward kinematics of the file (a chain of fixed
offsets and rotations about the stated axes) must put every foot where robokit's
``foot_position`` does, once the knee angle is moved by ``KNEE_SHIFT`` (robokit draws the bent
shank straight), and robokit's joint limits must be the file's moved the same way.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robokit.legged import leg_kinematics as lk
from robokit.legged.littledog import (HIP_OFFSETS, JOINT_LIMITS, JOINT_NAMES, KNEE_SHIFT, LEGS, SOURCE_JOINT_LIMITS,
                                      littledog_model)

URDF = Path(__file__).parent / "data" / "littledog" / "LittleDog.urdf"
SOURCE_LEG = {"FL": "front_left", "FR": "front_right", "HL": "back_left", "HR": "back_right"}
JOINTS = ("hip_roll", "hip_pitch", "knee")


def _floats(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.split()])


def _source():
    """Per leg: [(origin, axis)] of its three joints, its foot centre, and its joint limits (3 x 2)."""
    root = ET.parse(URDF).getroot()
    for element in root.iter():                                  # the file declares Drake's XML namespace
        element.tag = element.tag.split("}")[-1]
    joints = {j.get("name"): j for j in root.iter("joint") if j.get("type")}
    frames = {f.get("name"): f for f in root.iter("frame")}
    out = {}
    for leg, name in SOURCE_LEG.items():
        chain, limits = [], []
        for joint in JOINTS:
            j = joints[f"{name}_{joint}"]
            chain.append((_floats(j.find("origin").get("xyz")), _floats(j.find("axis").get("xyz"))))
            lim = j.find("limit")
            limits.append([float(lim.get("lower")), float(lim.get("upper"))])
        foot = _floats(frames[f"{name}_foot_center"].get("xyz"))
        out[leg] = (chain, foot, np.array(limits))
    return out


def _shift(leg: str) -> float:
    """Knee angle that turns a straight-down shank onto the file's foot centre (about +y)."""
    foot = SOURCE[leg][1]
    return float(np.arctan2(-foot[0], -foot[2]))


SOURCE = _source()


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    k = axis / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def source_foot(q_source: np.ndarray, leg: str) -> np.ndarray:
    """The file's foot centre in the body frame for the file's joint angles."""
    chain, foot, _ = SOURCE[leg]
    R, p = np.eye(3), np.zeros(3)
    for (origin, axis), angle in zip(chain, q_source):
        p = p + R @ origin
        R = R @ _rotation(axis, angle)
    return p + R @ foot


def test_the_file_is_the_one_the_readme_names():
    import hashlib

    assert hashlib.sha256(URDF.read_bytes()).hexdigest() == \
        "3a72a96ffe60491bae0e2da9b0c190801af98e06bfa873b5aa931a1cbad16e94"
    assert SOURCE["HR"][0][1][0][1] == pytest.approx(-0.0207) and SOURCE["HL"][0][1][0][1] == pytest.approx(0.0236)


@pytest.mark.parametrize("leg", LEGS)
def test_every_foot_stands_where_the_source_puts_it(leg):
    i = LEGS.index(leg)
    rng = np.random.default_rng(i)
    lo, hi = SOURCE[leg][2].T
    q_source = rng.uniform(lo, hi, size=(2000, 3))               # the file's whole range
    ours = lk.foot_position(q_source + [0.0, 0.0, _shift(leg)], leg)
    theirs = np.array([source_foot(q, leg) for q in q_source])
    # equal to rounding: the issue asks < 0.01 mm, but a lower leg of 0.1020 m instead of the shank's
    # 0.102002 m would move the feet only 2.5 um, so the check is kept at 10 nm
    assert np.abs(ours - theirs).max() < 1e-8


def test_the_joint_limits_are_the_sources_in_our_knee_convention():
    for i, leg in enumerate(LEGS):
        assert KNEE_SHIFT[i] == pytest.approx(_shift(leg), abs=1e-12)       # +0.2628 front, -0.2628 hind
        np.testing.assert_allclose(SOURCE_JOINT_LIMITS[3 * i:3 * i + 3], SOURCE[leg][2], atol=0)
        moved = SOURCE[leg][2] + [[0.0], [0.0], [_shift(leg)]]
        np.testing.assert_allclose(JOINT_LIMITS[3 * i:3 * i + 3], moved, atol=1e-12)   # 0.001 rad asked
    assert HIP_OFFSETS.tolist() == [abs(SOURCE[leg][0][1][0][1]) for leg in LEGS]


def test_a_pose_inside_our_limits_is_inside_the_sources_and_back():
    rng = np.random.default_rng(7)
    for i, leg in enumerate(LEGS):
        q = rng.uniform(JOINT_LIMITS[3 * i:3 * i + 3, 0] - 0.2, JOINT_LIMITS[3 * i:3 * i + 3, 1] + 0.2, (5000, 3))
        q_source = q - [0.0, 0.0, _shift(leg)]
        lo, hi = SOURCE[leg][2].T
        inside_source = np.all((q_source >= lo) & (q_source <= hi), axis=1)
        assert np.array_equal(lk.within_limits(q, leg), inside_source)
        assert 0.2 < inside_source.mean() < 0.9                  # both kinds of pose drawn


def test_the_mujoco_model_carries_the_same_limits_and_feet():
    model = littledog_model()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(3)
    for k, name in enumerate(JOINT_NAMES):
        np.testing.assert_allclose(model.jnt_range[model.joint(name).id], JOINT_LIMITS[k], atol=1e-5)
    q = np.concatenate([rng.uniform(JOINT_LIMITS[3 * i:3 * i + 3, 0], JOINT_LIMITS[3 * i:3 * i + 3, 1])
                        for i in range(4)])
    for k, name in enumerate(JOINT_NAMES):
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = q[k]
    mujoco.mj_kinematics(model, data)
    trunk = data.body("trunk")
    R, p = trunk.xmat.reshape(3, 3), trunk.xpos
    for i, leg in enumerate(LEGS):
        foot_body = R.T @ (data.site(f"{leg}_foot").xpos - p)
        q_source = q[3 * i:3 * i + 3] - [0.0, 0.0, _shift(leg)]
        np.testing.assert_allclose(foot_body, source_foot(q_source, leg), atol=1e-9)
