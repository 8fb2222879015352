"""SO(3): skew matrices, exponential and logarithm, elementary rotations, the rotation validator."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robokit import geometry as g


def _rotvecs(rng, n, max_angle=np.pi):
    axis = rng.normal(size=(n, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    return axis * rng.uniform(0, max_angle, size=(n, 1))


def test_skew_is_the_cross_product():
    rng = np.random.default_rng(0)
    v, x = rng.normal(size=(10, 3)), rng.normal(size=(10, 3))
    K = g.skew(v)
    np.testing.assert_allclose(K @ x[..., None], np.cross(v, x)[..., None], atol=1e-15)
    np.testing.assert_array_equal(K, -np.swapaxes(K, -1, -2))
    np.testing.assert_array_equal(g.skew(v[3]), K[3])


def test_exp_and_log_agree_with_scipy():
    rng = np.random.default_rng(1)
    v = _rotvecs(rng, 200, max_angle=np.pi - 1e-3)
    R = g.so3_exp(v)
    np.testing.assert_allclose(R, Rotation.from_rotvec(v).as_matrix(), atol=1e-14)
    np.testing.assert_allclose(g.so3_log(R), Rotation.from_matrix(R).as_rotvec(), atol=1e-12)
    np.testing.assert_allclose(g.so3_log(R), v, atol=1e-12)


@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-9, 1e-7, 1e-6, 2e-6, 1e-4])
def test_exp_and_log_are_accurate_near_zero(angle):
    axis = np.array([2.0, -1.0, 0.5]) / np.linalg.norm([2.0, -1.0, 0.5])
    v = axis * angle
    R = g.so3_exp(v)
    ref = Rotation.from_rotvec(v).as_matrix()
    np.testing.assert_allclose(R, ref, rtol=0, atol=3e-16)       # 1 ulp of 1.0 is 2.2e-16
    np.testing.assert_allclose(g.so3_log(R), v, rtol=1e-9, atol=1e-20)


@pytest.mark.parametrize("gap", [0.0, 1e-12, 1e-9, 1e-6, 1e-3, 0.05])
def test_log_is_accurate_near_pi(gap):
    rng = np.random.default_rng(2)
    for axis in rng.normal(size=(20, 3)):
        axis /= np.linalg.norm(axis)
        v = axis * (np.pi - gap)
        w = g.so3_log(g.so3_exp(v))
        assert np.linalg.norm(w) == pytest.approx(np.pi - gap, abs=1e-12)
        if gap > 1e-9:   # below that, +axis and -axis are the same rotation to rounding
            np.testing.assert_allclose(w, v, atol=1e-9)
        np.testing.assert_allclose(g.so3_exp(w), g.so3_exp(v), atol=1e-12)


def test_batch_equals_single():
    rng = np.random.default_rng(3)
    v = _rotvecs(rng, 7).reshape(7, 1, 3)
    R = g.so3_exp(v)
    assert R.shape == (7, 1, 3, 3)
    assert g.so3_log(R).shape == (7, 1, 3)
    for i in range(7):
        np.testing.assert_array_equal(R[i, 0], g.so3_exp(v[i, 0]))
        np.testing.assert_array_equal(g.so3_log(R)[i, 0], g.so3_log(R[i, 0]))
    np.testing.assert_array_equal(g.so3_log(R, validate=False), g.so3_log(R))
    np.testing.assert_array_equal(g.so3_exp(v, validate=False), R)


@pytest.mark.parametrize("rot, axis", [(g.rot_x, 0), (g.rot_y, 1), (g.rot_z, 2)])
def test_elementary_rotations_are_right_handed_and_batched(rot, axis):
    e = np.eye(3)
    # a quarter turn about axis k takes the next axis to the one after it (x -> y -> z -> x)
    np.testing.assert_allclose(rot(np.pi / 2) @ e[(axis + 1) % 3], e[(axis + 2) % 3], atol=1e-15)
    angles = np.linspace(-4, 4, 12).reshape(3, 4)
    R = rot(angles)
    assert R.shape == (3, 4, 3, 3)
    np.testing.assert_allclose(R, g.so3_exp(angles[..., None] * e[axis]), atol=1e-15)
    np.testing.assert_allclose(R @ rot(-angles), np.broadcast_to(np.eye(3), R.shape), atol=1e-15)
    np.testing.assert_allclose(rot(0.3), Rotation.from_euler("xyz"[axis], 0.3).as_matrix(), atol=1e-15)


def test_euler_matrix_composes_fixed_axes():
    a = [0.1, -0.4, 0.7]
    np.testing.assert_allclose(g.euler_matrix(a), g.rot_z(a[2]) @ g.rot_y(a[1]) @ g.rot_x(a[0]), atol=1e-15)
    np.testing.assert_allclose(g.euler_matrix([0, 0, np.pi / 2]) @ [1, 0, 0], [0, 1, 0], atol=1e-12)


def test_as_rotation_accepts_rotations_and_names_the_defect():
    rng = np.random.default_rng(4)
    R = g.so3_exp(_rotvecs(rng, 3))
    assert g.rotations.as_rotation(R, "R", batch=True).shape == (3, 3, 3)
    assert g.rotations.as_rotation(R[0], "R", batch=True).shape == (1, 3, 3)
    assert g.rotations.as_rotation([[0.0, -1.0], [1.0, 0.0]], "R", dim=2).shape == (2, 2)
    with pytest.raises(ValueError, match=r"R: expected a rotation matrix .* det = -1"):
        g.rotations.as_rotation(np.diag([1.0, 1.0, -1.0]), "R")
    with pytest.raises(ValueError, match=r"at index 2"):
        g.rotations.as_rotation(np.stack([R[0], R[1], 1.01 * R[2]]), "R", batch=True)
    with pytest.raises(ValueError, match=r"R: expected shape \(3, 3\)"):
        g.rotations.as_rotation(np.eye(2), "R")


def test_zyz_angles_agree_with_scipy_and_are_batched():
    rng = np.random.default_rng(9)
    R = Rotation.random(200, random_state=3).as_matrix()
    got = g.zyz_angles(R)
    assert got.shape == (200, 3) and np.all((got[:, 1] >= 0) & (got[:, 1] <= np.pi))
    np.testing.assert_allclose(got, Rotation.from_matrix(R).as_euler("ZYZ"), atol=1e-9)
    np.testing.assert_array_equal(g.zyz_angles(R[:5].reshape(5, 1, 3, 3))[:, 0], got[:5])
    np.testing.assert_array_equal(g.zyz_angles(R, validate=False), got)
    a, b, c = got.T
    np.testing.assert_allclose(g.rot_z(a) @ g.rot_y(b) @ g.rot_z(c), R, atol=1e-12)
    # gimbal lock: b = 0 or pi, only a + c (or c - a) is defined; a = 0 and c carries it
    for b in (0.0, np.pi, 1e-14):
        a0, c0 = rng.uniform(-np.pi, np.pi, 2)
        M = g.rot_z(a0) @ g.rot_y(b) @ g.rot_z(c0)
        za, zb, zc = g.zyz_angles(M)
        assert za == 0.0 and zb == pytest.approx(b, abs=1e-12)
        np.testing.assert_allclose(g.rot_z(za) @ g.rot_y(zb) @ g.rot_z(zc), M, atol=1e-12)


@pytest.mark.parametrize("call, match", [
    (lambda: g.zyz_angles(np.eye(2)), r"R: expected rotation matrices"),
    (lambda: g.zyz_angles(np.diag([1.0, 1.0, -1.0])), r"R: expected a rotation matrix"),
    (lambda: g.zyz_angles(np.stack([np.eye(3), 2 * np.eye(3)])), "at index 1"),
    (lambda: g.skew([1.0, 2.0]), r"v: expected 3-vectors"),
    (lambda: g.so3_exp([np.nan, 0.0, 0.0]), "rotvec"),
    (lambda: g.so3_exp(1.0), r"rotvec: expected 3-vectors"),
    (lambda: g.so3_log(np.eye(4)), r"R: expected rotation matrices"),
    (lambda: g.so3_log(2 * np.eye(3)), r"R: expected a rotation matrix"),
    (lambda: g.rot_x(np.inf), "angle"),
    (lambda: g.rot_z([0.0, np.nan]), "angle"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_quat_to_matrix_agrees_with_scipy_and_with_the_axis_angle():
    rng = np.random.default_rng(7)
    q = rng.normal(size=(300, 4))                          # any non-zero quaternion, normalised inside
    R = g.quat_to_matrix(q)
    np.testing.assert_allclose(R, Rotation.from_quat(q, scalar_first=True).as_matrix(), atol=1e-14)
    np.testing.assert_allclose(g.quat_to_matrix(-q), R, atol=1e-15)             # q and -q: one rotation
    np.testing.assert_allclose(g.quat_to_matrix(q.reshape(3, 100, 4)), R.reshape(3, 100, 3, 3), atol=0)
    one_by_one = np.array([g.quat_to_matrix(x) for x in q])          # one quaternion: its own path, same bits
    assert np.array_equal(one_by_one, R) and np.array_equal(np.signbit(one_by_one), np.signbit(R))
    assert np.array_equal(g.quat_to_matrix(q[0], validate=False), R[0])
    v = _rotvecs(rng, 50)                                    # [cos(t/2), sin(t/2) u] is so3_exp(t u)
    t = np.linalg.norm(v, axis=1, keepdims=True)
    np.testing.assert_allclose(g.quat_to_matrix(np.hstack([np.cos(t / 2), np.sin(t / 2) * v / t])), g.so3_exp(v),
                               atol=1e-14)
    for s in (1e-200, 1e300):                               # scaled far from 1: still the same rotation
        np.testing.assert_allclose(g.quat_to_matrix(q[:5] * s), R[:5], atol=1e-14)


@pytest.mark.parametrize("bad, word", [([1.0, 0.0, 0.0], "shape"), ([0.0, 0.0, 0.0, 0.0], "non-zero"),
                                       ([1.0, np.nan, 0.0, 0.0], "finite")])
def test_quat_to_matrix_refuses_what_is_no_rotation(bad, word):
    with pytest.raises(ValueError, match=f"quat: .*{word}"):
        g.quat_to_matrix(bad)
