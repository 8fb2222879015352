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
    np.testing.assert_allclose(g.paper_frames.R_BODY_OPTICAL @ [0, 0, 1], [1, 0, 0])
    np.testing.assert_allclose(g.paper_frames.R_BODY_OPTICAL.T @ [0, 1, 0], [-1, 0, 0])
    np.testing.assert_allclose(g.paper_frames.optical_to_y_up([[1, 2, 3]]), [[1, -2, 3]])


def test_pqt_robot_to_world_by_hand():
    """Worked by hand: the robot at p = 2 m, q = 1 m has turned left by 30 degrees (theta = pi/6).

    Its forward axis Z points, in the world, to (X, Z) = (-sin 30, cos 30) = (-0.5, 0.866); its
    right axis X to (cos 30, sin 30) = (0.866, 0.5). A point 2 m ahead, 1 m to the right and
    0.4 m up is at (2 + 0.866 - 1.0, 0.4, 1 + 0.5 + 1.732) = (1.866, 0.4, 3.232).
    """
    pqt = [2.0, 1.0, np.pi / 6]
    world = g.pqt_robot_to_world([[1.0, 0.4, 2.0]], pqt)
    np.testing.assert_allclose(world, [[2 + np.sqrt(3) / 2 - 1.0, 0.4, 1 + 0.5 + np.sqrt(3)]], atol=1e-12)
    np.testing.assert_allclose(g.pqt_world_to_robot(world, pqt), [[1.0, 0.4, 2.0]], atol=1e-12)
    # theta = +90 degrees: the robot looks along -X (it has turned left)
    np.testing.assert_allclose(g.pqt_robot_to_world([[0, 0, 1.0]], [0, 0, np.pi / 2]), [[-1, 0, 0]], atol=1e-15)
    # the transform is the right-handed rotation about Y by minus the heading (the frame is left-handed)
    T = g.pqt_to_se3(pqt)
    np.testing.assert_array_equal(T[:3, :3], g.rot_y(-np.pi / 6))
    np.testing.assert_array_equal(T[:3, 3], [2.0, 0.0, 1.0])


def test_pqt_acts_like_se2_on_the_ground_plane():
    rng = np.random.default_rng(0)
    pqt = np.array([0.4, -1.2, 0.7])
    pts = rng.normal(size=(10, 3))
    world = g.pqt_robot_to_world(pts, pqt)
    for r, w in zip(pts, world):
        assert np.allclose(g.se2_compose(pqt, [r[0], r[2], 0.0])[:2], w[[0, 2]])
    assert np.allclose(world[:, 1], pts[:, 1])
    assert np.allclose(g.pqt_world_to_robot(world, pqt), pts)


def test_pqt_convention_agrees_with_the_simulator_frame():
    """One convention in the course: a point seen by the robot lands at the same spot whether the
    pose is robokit's [x, y, theta] (z up) or the papers' [p, q, theta] (Y up)."""
    rng = np.random.default_rng(11)
    for pose in _random_se2(rng, 10):
        X, Y, Z = rng.uniform(-3, 3, size=3)        # papers' robot frame: right, up, forward
        body = np.array([Z, -X])                     # robokit body frame: forward, left
        c, s_ = np.cos(pose[2]), np.sin(pose[2])
        world_xy = pose[:2] + np.array([[c, -s_], [s_, c]]) @ body
        paper_world = g.pqt_robot_to_world([[X, Y, Z]], g.se2_to_pqt(pose))[0]
        np.testing.assert_allclose([paper_world[0], paper_world[2]], world_xy, atol=1e-12)
        assert paper_world[1] == pytest.approx(Y)


def test_ground_plane_action_is_batched_over_poses_and_points():
    """RANSAC's hypotheses x matches and the Hough vote's headings x matches in one call each, equal to
    one pose at a time through the 3-D function (and to SE(2) composition on (X, Z))."""
    rng = np.random.default_rng(7)
    poses = np.column_stack([rng.uniform(-5, 5, (6, 2)), rng.uniform(-4, 4, 6)])
    xz = rng.normal(size=(9, 2))
    moved = g.paper_frames.pqt_transform_xz(poses[:, None, :], xz)
    assert moved.shape == (6, 9, 2)
    for pqt, m in zip(poses, moved):
        pts = np.column_stack([xz[:, 0], rng.normal(size=9), xz[:, 1]])
        np.testing.assert_array_equal(g.pqt_robot_to_world(pts, pqt)[:, ::2], m)
        for r, w in zip(xz, m):
            np.testing.assert_allclose(g.se2_compose(pqt, [r[0], r[1], 0.0])[:2], w, atol=1e-12)
        np.testing.assert_allclose(g.paper_frames.pqt_transform_xz(pqt, m, inverse=True), xz, atol=1e-12)
    np.testing.assert_array_equal(g.paper_frames.pqt_transform_xz(poses[:, None, :], xz, validate=False), moved)
    # the rotation alone is the action of [0, 0, theta]
    np.testing.assert_array_equal(g.paper_frames.pqt_rotate_xz(poses[:, 2:], xz),
                                  g.paper_frames.pqt_transform_xz(np.column_stack([0 * poses[:, :2], poses[:, 2]])[:, None], xz))
    # many poses, one point each (the 3-D functions broadcast the same way)
    pts = rng.normal(size=(6, 3))
    np.testing.assert_allclose(g.pqt_world_to_robot(g.pqt_robot_to_world(pts, poses), poses), pts, atol=1e-12)


def test_ground_plane_jacobian_matches_finite_differences():
    rng = np.random.default_rng(8)
    pqt, xz = np.array([0.5, -1.0, 2.5]), rng.normal(size=(5, 2))
    moved, J = g.paper_frames.pqt_transform_xz(pqt, xz, jacobian=True)
    np.testing.assert_array_equal(moved, g.paper_frames.pqt_transform_xz(pqt, xz))
    h = 1e-6
    for k in range(3):
        d = np.zeros(3)
        d[k] = h
        fd = (g.paper_frames.pqt_transform_xz(pqt + d, xz) - g.paper_frames.pqt_transform_xz(pqt - d, xz)) / (2 * h)
        np.testing.assert_allclose(J[..., k], fd, atol=1e-8)
    assert g.paper_frames.pqt_transform_xz(np.zeros((4, 1, 3)), xz, jacobian=True)[1].shape == (4, 5, 2, 3)


def test_paper_world_to_robokit_is_the_course_identification():
    """A point seen by a robot lands at the same place in robokit's world whether it goes through
    robokit's frames (body x forward, y left, z up; camera at height h) or through the papers'
    (se2_to_pqt, pqt_robot_to_world, then paper_world_to_robokit)."""
    rng = np.random.default_rng(12)
    h = 0.8
    for pose in _random_se2(rng, 10):
        X, Y, Z = rng.uniform(-3, 3, size=3)            # papers' camera frame: right, up, forward
        c, s_ = np.cos(pose[2]), np.sin(pose[2])
        body = np.array([Z, -X])                         # forward, left
        expected = np.array([*(pose[:2] + np.array([[c, -s_], [s_, c]]) @ body), h + Y])
        paper = g.pqt_robot_to_world([[X, Y, Z]], g.se2_to_pqt(pose))
        m = rng.normal(size=(3, 3))
        cov = (m @ m.T)[None]                            # in (X, Y, Z)
        pts, covs = g.paper_world_to_robokit(paper, cov, camera_height=h)
        np.testing.assert_allclose(pts[0], expected, atol=1e-12)
        perm = np.array([[1.0, 0, 0], [0, 0, 1], [0, 1, 0]])   # x = X, y = Z, z = Y
        np.testing.assert_allclose(covs[0], perm @ cov[0] @ perm.T, atol=1e-12)
    assert g.paper_world_to_robokit([[0.0, 0.0, 0.0]])[1] is None


@pytest.mark.parametrize("call, match", [
    (lambda: g.paper_frames.pqt_transform_xz([0, 0, 0], [[1, 2, 3]]), "xz"),
    (lambda: g.paper_frames.pqt_transform_xz(np.zeros((4, 3)), np.zeros((5, 2))), "pqt, xz"),
    (lambda: g.paper_frames.pqt_rotate_xz(np.zeros(4), np.zeros((5, 2))), "theta, xz"),
    (lambda: g.paper_frames.pqt_transform_xz([0, 0, np.inf], [1, 2], jacobian=True), "pqt"),
    (lambda: g.paper_frames.pqt_transform_xz([0, 0, 0], [1, 2], jacobian=True, inverse=True), "inverse, jacobian"),
    (lambda: g.pqt_robot_to_world(np.zeros((5, 3)), np.zeros((4, 3))), "pqt, points"),
    (lambda: g.paper_world_to_robokit([[1, 2, 3]], camera_height=0.0), "camera_height"),
    (lambda: g.paper_world_to_robokit([[1, 2, 3]], np.eye(3)), "covariances"),

    (lambda: g.se2_to_pqt([[1, 2]]), "pose"),
    (lambda: g.pqt_to_se2(np.zeros((2, 2, 3))), "pqt"),
    (lambda: g.paper_frames.as_pqt([0, 0, np.nan]), "pqt"),
    (lambda: g.pqt_robot_to_world([[0, 0]], [0, 0, 0]), "points"),
    (lambda: g.pqt_world_to_robot([[0, 0, 1]], [0, 0]), "pqt"),
    (lambda: g.paper_frames.optical_to_y_up([1, 2]), "points"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises(ValueError, match=match):
        call()
