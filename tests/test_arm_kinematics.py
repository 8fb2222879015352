"""robokit.arm kinematics: DH transforms, FK against independent models, Jacobian, manipulability."""
import numpy as np
import pytest
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

from robokit.arm import (Chain, dh_transform, geometric_jacobian, iiwa14, manipulability, mdh_transform,
                         panda)


def _tz(d):
    T = np.eye(4)
    T[2, 3] = d
    return T


def _tx(a):
    T = np.eye(4)
    T[0, 3] = a
    return T


def _rot(axis, angle):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.asarray(axis, float) * angle).as_matrix()
    return T


@pytest.mark.parametrize("seed", [0, 1])
def test_dh_transforms_equal_products_of_elementary_motions(seed):
    rng = np.random.default_rng(seed)
    th, d, a, al = rng.uniform(-3, 3, 4)
    std = _rot([0, 0, 1], th) @ _tz(d) @ _tx(a) @ _rot([1, 0, 0], al)
    mod = _rot([1, 0, 0], al) @ _tx(a) @ _rot([0, 0, 1], th) @ _tz(d)
    assert np.allclose(dh_transform(th, d, a, al), std, atol=1e-14)
    assert np.allclose(mdh_transform(th, d, a, al), mod, atol=1e-14)
    # vectorised over joint angles
    thetas = rng.uniform(-3, 3, 5)
    assert dh_transform(thetas, d, a, al).shape == (5, 4, 4)
    assert np.allclose(dh_transform(thetas, d, a, al)[2], dh_transform(thetas[2], d, a, al))


def _twist(w, p):
    w = np.asarray(w, float)
    v = -np.cross(w, p)
    S = np.zeros((4, 4))
    S[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
    S[:3, 3] = v
    return S


def _poe(screws, M, q):
    """Product of exponentials (Lynch & Park 2017, Eq. 4.14), built from each arm's zero-pose geometry."""
    T = np.eye(4)
    for S, qi in zip(screws, q):
        T = T @ expm(S * qi)
    return T @ M


# Zero-configuration geometry read off each arm's drawing: joint axis directions and a point on each.
IIWA_POE = ([_twist(w, p) for w, p in [([0, 0, 1], [0, 0, 0]), ([0, 1, 0], [0, 0, 0.36]),
                                        ([0, 0, 1], [0, 0, 0.36]), ([0, -1, 0], [0, 0, 0.78]),
                                        ([0, 0, 1], [0, 0, 0.78]), ([0, 1, 0], [0, 0, 1.18]),
                                        ([0, 0, 1], [0, 0, 1.18])]], _tz(1.306))
_PANDA_M = _rot([1, 0, 0], np.pi)
_PANDA_M[:3, 3] = [0.088, 0, 0.926]
PANDA_POE = ([_twist(w, p) for w, p in [([0, 0, 1], [0, 0, 0.333]), ([0, 1, 0], [0, 0, 0.333]),
                                         ([0, 0, 1], [0, 0, 0.649]), ([0, -1, 0], [0.0825, 0, 0.649]),
                                         ([0, 0, 1], [0, 0, 1.033]), ([0, -1, 0], [0, 0, 1.033]),
                                         ([0, 0, -1], [0.088, 0, 1.033])]], _PANDA_M)


@pytest.mark.parametrize("make, model", [(iiwa14, IIWA_POE), (panda, PANDA_POE)], ids=["iiwa14", "panda"])
def test_fk_matches_product_of_exponentials(make, model):
    chain = make()
    q = chain.random_q(50, rng=3)
    T = chain.fk(q)
    for qi, Ti in zip(q, T):
        ref = _poe(*model, qi)
        assert np.abs(Ti[:3, 3] - ref[:3, 3]).max() < 1e-9
        assert np.abs(Ti[:3, :3] - ref[:3, :3]).max() < 1e-9


def test_panda_fk_matches_roboticstoolbox_urdf_model():
    rtb = pytest.importorskip("roboticstoolbox")
    robot = rtb.models.Panda()  # URDF model from franka_description: independent of our DH table
    chain = panda()
    for q in chain.random_q(50, rng=4):
        ref = robot.fkine(q, end="panda_link8").A
        assert np.abs(chain.fk(q) - ref).max() < 1e-9


def test_iiwa_fk_matches_roboticstoolbox_dh_robot():
    rtb = pytest.importorskip("roboticstoolbox")
    chain = iiwa14()
    robot = rtb.DHRobot([rtb.RevoluteDH(d=d, a=a, alpha=al) for d, a, al in zip(chain.d, chain.a, chain.alpha)])
    for q in chain.random_q(50, rng=5):
        assert np.abs(chain.fk(q) - robot.fkine(q).A).max() < 1e-9


def test_link_frames_are_consistent_with_fk():
    chain = iiwa14()
    q = chain.random_q(4, rng=6)
    frames = chain.link_frames(q)
    assert frames.shape == (4, 9, 4, 4)
    assert np.allclose(frames[:, -1], chain.fk(q))
    assert np.allclose(frames[:, 0], np.eye(4))
    # shoulder (frames 1, 2) and wrist centre (frames 5, 6) of an S-R-S arm
    assert np.allclose(frames[:, 1, :3, 3], [0, 0, 0.36])
    assert np.allclose(frames[:, 5, :3, 3], frames[:, 6, :3, 3])
    assert np.allclose(np.linalg.norm(frames[:, 5, :3, 3] - frames[:, 3, :3, 3], axis=1), 0.40)


def _fd_jacobian(chain, q, h=1e-6):
    J = np.zeros((6, chain.n))
    for i in range(chain.n):
        dq = np.zeros(chain.n)
        dq[i] = h
        Tp, Tm = chain.fk(q + dq), chain.fk(q - dq)
        J[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        J[3:, i] = Rotation.from_matrix(Tp[:3, :3] @ Tm[:3, :3].T).as_rotvec() / (2 * h)
    return J


@pytest.mark.parametrize("make", [iiwa14, panda])
def test_jacobian_matches_finite_differences(make):
    chain = make()
    qs = chain.random_q(10, rng=7)
    J = geometric_jacobian(chain, qs)
    assert J.shape == (10, 6, 7)
    for q, Ji in zip(qs, J):
        assert np.abs(Ji - _fd_jacobian(chain, q)).max() < 1e-7


def test_manipulability():
    chain = iiwa14()
    # the stretched-out arm is singular (axes 1, 3, 5, 7 coincide)
    assert manipulability(geometric_jacobian(chain, np.zeros(7))) < 1e-12
    q = chain.random_q(5, rng=8)
    J = geometric_jacobian(chain, q)
    w = manipulability(J)
    assert np.allclose(w, [np.prod(np.linalg.svd(j, compute_uv=False)) for j in J])
    with pytest.raises(ValueError, match="J"):
        manipulability(np.zeros((7, 6)))


def test_limits_and_random_configurations():
    chain = panda()
    q = chain.random_q(1000, rng=9)
    assert chain.within_limits(q).all()
    bad = q[0].copy()
    bad[3] = 0.0  # the Panda's elbow cannot straighten fully
    assert not chain.within_limits(bad)
    assert np.array_equal(chain.random_q(3, rng=1), chain.random_q(3, rng=1))


def test_bad_input_is_rejected_with_clear_messages():
    chain = iiwa14()
    with pytest.raises(ValueError, match="q: expected 7 joint angles"):
        chain.fk(np.zeros(6))
    with pytest.raises(ValueError, match="finite"):
        chain.fk([0, 0, np.nan, 0, 0, 0, 0])
    with pytest.raises(ValueError, match="qmin <= qmax"):
        Chain("bad", d=[0.1, 0.1], a=[0, 0], alpha=[0, 0], qmin=[0, 1], qmax=[1, 0])
    with pytest.raises(ValueError, match="alpha"):
        Chain("bad", d=[0.1, 0.1], a=[0, 0], alpha=[0], qmin=[0, 0], qmax=[1, 1])
    with pytest.raises(ValueError, match="tool"):
        Chain("bad", d=[0.1], a=[0], alpha=[0], qmin=[0], qmax=[1], tool=2 * np.eye(4))
    with pytest.raises(ValueError, match="convention"):
        Chain("bad", d=[0.1], a=[0], alpha=[0], qmin=[0], qmax=[1], convention="craig")
    with pytest.raises(TypeError, match="chain"):
        geometric_jacobian("iiwa", np.zeros(7))


def test_plain_table_functions_match_the_chain():
    from robokit.arm import dh_fk, dh_jacobian

    chain = iiwa14()
    table = np.stack([chain.d, chain.a, chain.alpha], 1)
    q = chain.random_q(rng=11)
    assert np.allclose(dh_fk(table, q), chain.fk(q), atol=1e-14)
    assert np.allclose(dh_jacobian(table, q), geometric_jacobian(chain, q), atol=1e-14)
    p = panda()
    ptable = np.stack([p.d, p.a, p.alpha], 1)
    assert np.allclose(dh_fk(ptable, q, modified=True) @ p.tool, p.fk(q), atol=1e-14)
    with pytest.raises(ValueError, match="dh"):
        dh_fk(table[:, :2], q)
    with pytest.raises(ValueError, match="q"):
        dh_fk(table, q[:5])


def test_public_frames_flange_and_jacobian_kernels_match_the_checked_functions():
    from robokit.arm.jacobian import jacobian_from_frames
    from robokit.geometry import pose_error as geometry_pose_error
    from robokit.geometry import pose_error

    assert pose_error is geometry_pose_error              # lesson 06 calls arm.pose_error
    chain = panda()
    q = chain.random_q(6, rng=15)
    frames = chain.frames(q)
    assert frames.shape == (6, 8, 4, 4)
    np.testing.assert_array_equal(chain.frames(q, validate=False), frames)
    np.testing.assert_array_equal(chain.flange_transform(frames), chain.fk(q))
    np.testing.assert_array_equal(jacobian_from_frames(chain, frames), geometric_jacobian(chain, q))
    np.testing.assert_array_equal(jacobian_from_frames(chain, frames, validate=False), geometric_jacobian(chain, q))
    with pytest.raises(ValueError, match=r"frames: expected shape \(\.\.\., 8, 4, 4\)"):
        chain.flange_transform(frames[:, :5])
    np.testing.assert_array_equal(chain.joint_frames(frames), chain.joint_frames(frames, validate=False))
    for bad in (np.eye(3), frames[:, :5]):                  # (3, 3) raised IndexError inside numpy
        with pytest.raises(ValueError, match=r"frames: expected shape \(\.\.\., 8, 4, 4\)"):
            chain.joint_frames(bad)
    with pytest.raises(ValueError, match="finite"):
        chain.joint_frames(np.full((8, 4, 4), np.nan))
    with pytest.raises(ValueError, match="frames"):
        jacobian_from_frames(chain, frames[:, :, :3])
    with pytest.raises(TypeError, match="chain"):
        jacobian_from_frames("panda", frames)
    with pytest.raises(ValueError, match="q"):
        chain.frames(q[:, :6])


def test_verify_needs_the_pose_and_the_limits():
    from robokit.arm.result import verify

    chain = panda()
    q = chain.random_q(3, rng=16)
    T = chain.fk(q)
    bad = q.copy()
    bad[1, 0] += 0.05                                      # pose off
    r = verify(chain, T, bad)
    assert r.success.tolist() == [True, False, True]
    assert r.reason[1].startswith("pose error above tolerance")
    assert r.position_error[1] > 1e-3 and r.position_error[0] < 1e-12
    # the flange pose reached with a joint outside its limits is no success
    outside = chain.qmax.copy()
    outside[3] = 0.5                                       # the Panda's elbow cannot reach +0.5 rad
    r = verify(chain, chain.fk(outside)[None], outside[None])
    assert not r.success[0] and "joint 4 is outside its limits" in r.reason[0]
    with pytest.raises(ValueError, match="one per target"):
        verify(chain, T, q[:2])
    with pytest.raises(ValueError, match="tol"):
        verify(chain, T, q, tol=0.0)
