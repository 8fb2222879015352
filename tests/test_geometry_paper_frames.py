"""The papers' frames (Se, Lowe & Little; Lin et al.): [p, q, theta] and its action on points."""
import numpy as np
import pytest

from robokit import geometry as g


def _random_se2(rng, n):
    return np.column_stack([rng.uniform(-5, 5, (n, 2)), rng.uniform(-np.pi, np.pi, n)])


def test_pqt_convention():
    # the papers' ground plane (X, Z) is robokit's (x, y); the heading is offset by 90 degrees
    np.testing.assert_allclose(g.se2_to_pqt([2.0, 1.0, 0.3]), [2.0, 1.0, 0.3 - np.pi / 2])
    # a robot facing robokit's +y faces the papers' +Z (heading 0)
    np.testing.assert_allclose(g.se2_to_pqt([0.0, 0.0, np.pi / 2]), [0.0, 0.0, 0.0], atol=1e-12)
    poses = _random_se2(np.random.default_rng(5), 20)
    np.testing.assert_allclose(g.pqt_to_se2(g.se2_to_pqt(poses)), poses)
    # the body->optical rotation maps forward to optical z and left to optical -x
    np.testing.assert_allclose(g.R_BODY_OPTICAL @ [0, 0, 1], [1, 0, 0])
    np.testing.assert_allclose(g.R_BODY_OPTICAL.T @ [0, 1, 0], [-1, 0, 0])
    np.testing.assert_allclose(g.optical_to_y_up([[1, 2, 3]]), [[1, -2, 3]])


def test_robot_to_world_by_hand():
    """Worked by hand: the robot at p = 2 m, q = 1 m has turned left by 30 degrees (theta = pi/6).

    Its forward axis Z points, in the world, to (X, Z) = (-sin 30, cos 30) = (-0.5, 0.866); its
    right axis X to (cos 30, sin 30) = (0.866, 0.5). A point 2 m ahead, 1 m to the right and
    0.4 m up is at (2 + 0.866 - 1.0, 0.4, 1 + 0.5 + 1.732) = (1.866, 0.4, 3.232).
    """
    pqt = [2.0, 1.0, np.pi / 6]
    world = g.robot_to_world([[1.0, 0.4, 2.0]], pqt)
    np.testing.assert_allclose(world, [[2 + np.sqrt(3) / 2 - 1.0, 0.4, 1 + 0.5 + np.sqrt(3)]], atol=1e-12)
    np.testing.assert_allclose(g.world_to_robot(world, pqt), [[1.0, 0.4, 2.0]], atol=1e-12)
    # theta = +90 degrees: the robot looks along -X (it has turned left)
    np.testing.assert_allclose(g.robot_to_world([[0, 0, 1.0]], [0, 0, np.pi / 2]), [[-1, 0, 0]], atol=1e-15)
    # the transform is the right-handed rotation about Y by minus the heading (the frame is left-handed)
    T = g.pqt_to_se3(pqt)
    np.testing.assert_array_equal(T[:3, :3], g.rot_y(-np.pi / 6))
    np.testing.assert_array_equal(T[:3, 3], [2.0, 0.0, 1.0])


def test_pqt_acts_like_se2_on_the_ground_plane():
    rng = np.random.default_rng(0)
    pqt = np.array([0.4, -1.2, 0.7])
    pts = rng.normal(size=(10, 3))
    world = g.robot_to_world(pts, pqt)
    for r, w in zip(pts, world):
        assert np.allclose(g.se2_compose(pqt, [r[0], r[2], 0.0])[:2], w[[0, 2]])
    assert np.allclose(world[:, 1], pts[:, 1])
    assert np.allclose(g.world_to_robot(world, pqt), pts)


def test_pqt_convention_agrees_with_the_simulator_frame():
    """One convention in the course: a point seen by the robot lands at the same spot whether the
    pose is robokit's [x, y, theta] (z up) or the papers' [p, q, theta] (Y up)."""
    rng = np.random.default_rng(11)
    for pose in _random_se2(rng, 10):
        X, Y, Z = rng.uniform(-3, 3, size=3)        # papers' robot frame: right, up, forward
        body = np.array([Z, -X])                     # robokit body frame: forward, left
        c, s_ = np.cos(pose[2]), np.sin(pose[2])
        world_xy = pose[:2] + np.array([[c, -s_], [s_, c]]) @ body
        paper_world = g.robot_to_world([[X, Y, Z]], g.se2_to_pqt(pose))[0]
        np.testing.assert_allclose([paper_world[0], paper_world[2]], world_xy, atol=1e-12)
        assert paper_world[1] == pytest.approx(Y)


@pytest.mark.parametrize("call, match", [
    (lambda: g.se2_to_pqt([[1, 2]]), "pose"),
    (lambda: g.pqt_to_se2(np.zeros((2, 2, 3))), "pqt"),
    (lambda: g.as_pqt([0, 0, np.nan]), "pqt"),
    (lambda: g.robot_to_world([[0, 0]], [0, 0, 0]), "points"),
    (lambda: g.world_to_robot([[0, 0, 1]], [0, 0]), "pqt"),
    (lambda: g.optical_to_y_up([1, 2]), "points"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises(ValueError, match=match):
        call()
