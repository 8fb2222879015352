"""SE(2)/SE(3) poses, rotations and the seeds' [p, q, theta] convention."""
import numpy as np
import pytest

from robokit import geometry as g


def _random_se2(rng, n):
    return np.column_stack([rng.uniform(-5, 5, (n, 2)), rng.uniform(-np.pi, np.pi, n)])


def test_existing_functions_unchanged():
    assert g.wrap_angle(3 * np.pi) == pytest.approx(-np.pi)
    np.testing.assert_allclose(g.se2_compose([1, 2, np.pi / 2], [1, 0, 0]), [1, 3, np.pi / 2], atol=1e-12)


def test_se2_inverse_and_between_round_trip():
    rng = np.random.default_rng(1)
    for a, b in zip(_random_se2(rng, 50), _random_se2(rng, 50)):
        np.testing.assert_allclose(g.se2_compose(a, g.se2_inverse(a)), 0, atol=1e-12)
        np.testing.assert_allclose(g.se2_compose(g.se2_inverse(a), a), 0, atol=1e-12)
        rel = g.se2_between(a, b)
        back = g.se2_compose(a, rel)
        np.testing.assert_allclose(back[:2], b[:2], atol=1e-12)
        assert g.wrap_angle(back[2] - b[2]) == pytest.approx(0, abs=1e-12)


def test_se2_matrix_agrees_with_compose():
    rng = np.random.default_rng(2)
    a, b = _random_se2(rng, 2)
    M = g.se2_to_matrix(a) @ g.se2_to_matrix(b)
    c = g.matrix_to_se2(M)
    ref = g.se2_compose(a, b)
    np.testing.assert_allclose(c[:2], ref[:2], atol=1e-12)
    assert g.wrap_angle(c[2] - ref[2]) == pytest.approx(0, abs=1e-12)


def test_se3_compose_inverse_and_points():
    rng = np.random.default_rng(3)
    R = g.rotation_matrix(rng.normal(size=3))
    T = g.se3_from_rt(R, rng.normal(size=3))
    np.testing.assert_allclose(g.se3_compose(T, g.se3_inverse(T)), np.eye(4), atol=1e-12)
    pts = rng.normal(size=(10, 3))
    back = g.transform_points(g.se3_inverse(T), g.transform_points(T, pts))
    np.testing.assert_allclose(back, pts, atol=1e-12)
    np.testing.assert_allclose(g.transform_points(T, pts), pts @ R.T + T[:3, 3], atol=1e-12)


def test_rotation_vector_round_trip_and_euler():
    v = np.array([0.3, -0.2, 1.1])
    np.testing.assert_allclose(g.rotation_vector(g.rotation_matrix(v)), v, atol=1e-12)
    Rz = g.euler_matrix([0, 0, np.pi / 2])
    np.testing.assert_allclose(Rz @ [1, 0, 0], [0, 1, 0], atol=1e-12)


def test_se2_se3_lift_agrees_with_planar_compose():
    rng = np.random.default_rng(4)
    a, b = _random_se2(rng, 2)
    T = g.se2_to_se3(a) @ g.se2_to_se3(b)
    ref = g.se2_compose(a, b)
    got = g.se3_to_se2(T)
    np.testing.assert_allclose(got[:2], ref[:2], atol=1e-12)
    assert g.wrap_angle(got[2] - ref[2]) == pytest.approx(0, abs=1e-12)


def test_pqt_convention():
    # the seeds' ground plane (X, Z) is robokit's (x, y); the heading is offset by 90 degrees
    np.testing.assert_allclose(g.se2_to_pqt([2.0, 1.0, 0.3]), [2.0, 1.0, 0.3 - np.pi / 2])
    # a robot facing robokit's +y faces the seeds' +Z (heading 0)
    np.testing.assert_allclose(g.se2_to_pqt([0.0, 0.0, np.pi / 2]), [0.0, 0.0, 0.0], atol=1e-12)
    poses = _random_se2(np.random.default_rng(5), 20)
    np.testing.assert_allclose(g.pqt_to_se2(g.se2_to_pqt(poses)), poses)
    # the body->optical rotation maps forward to optical z and left to optical -x
    np.testing.assert_allclose(g.R_BODY_OPTICAL @ [0, 0, 1], [1, 0, 0])
    np.testing.assert_allclose(g.R_BODY_OPTICAL.T @ [0, 1, 0], [-1, 0, 0])
    np.testing.assert_allclose(g.optical_to_seed([[1, 2, 3]]), [[1, -2, 3]])


@pytest.mark.parametrize("call, match", [
    (lambda: g.se2_inverse([0, 0]), "a"),
    (lambda: g.se2_to_matrix([0, np.nan, 0]), "pose"),
    (lambda: g.se3_from_rt(np.ones((3, 3)), [0, 0, 0]), "rotation"),
    (lambda: g.se3_inverse(np.zeros((4, 4))), "transform"),
    (lambda: g.se3_compose(), "transforms"),
    (lambda: g.transform_points(np.eye(4), [[1, 2]]), "points"),
    (lambda: g.euler_matrix([0, 0, 0], seq="xq"), "seq"),
    (lambda: g.se2_to_pqt([[1, 2]]), "pose"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_pqt_convention_agrees_with_mapping_frames():
    """One convention in the course: geometry's conversion and mapping.frames place a point seen
    by the robot at the same spot in the world."""
    from robokit.mapping.frames import robot_to_world

    rng = np.random.default_rng(11)
    for pose in _random_se2(rng, 10):
        X, Y, Z = rng.uniform(-3, 3, size=3)        # seeds' robot frame: right, up, forward
        body = np.array([Z, -X])                     # robokit body frame: forward, left
        c, s_ = np.cos(pose[2]), np.sin(pose[2])
        world_xy = pose[:2] + np.array([[c, -s_], [s_, c]]) @ body
        seeds_world = robot_to_world([[X, Y, Z]], g.se2_to_pqt(pose))[0]
        np.testing.assert_allclose([seeds_world[0], seeds_world[2]], world_xy, atol=1e-12)
        assert seeds_world[1] == pytest.approx(Y)
