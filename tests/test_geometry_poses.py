"""SE(2)/SE(3) poses: composition, inverse, points, the planar embedding, the SE(3) validator and pose error."""
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


def test_se2_functions_take_stacks_and_broadcast_one_pose():
    rng = np.random.default_rng(5)
    a, b = _random_se2(rng, 7), _random_se2(rng, 7)
    np.testing.assert_array_equal(g.se2_compose(a, b), [g.se2_compose(x, y) for x, y in zip(a, b)])
    np.testing.assert_array_equal(g.se2_inverse(a), [g.se2_inverse(x) for x in a])
    np.testing.assert_array_equal(g.se2_between(a, b), [g.se2_between(x, y) for x, y in zip(a, b)])
    np.testing.assert_array_equal(g.se2_compose(a[0], b), [g.se2_compose(a[0], y) for y in b])
    np.testing.assert_array_equal(g.se2_compose(a, b[:1]), [g.se2_compose(x, b[0]) for x in a])
    np.testing.assert_array_equal(g.se2_compose(a, b, validate=False), g.se2_compose(a, b))
    assert g.se2_compose(a[0], b[0]).shape == g.se2_inverse(a[0]).shape == (3,)
    out = g.se2_compose([[0.0, 0.0, 3.0]] * 2, [[0.0, 0.0, 0.5], [0.0, 0.0, -0.5]])
    np.testing.assert_allclose(out[:, 2], [3.5 - 2 * np.pi, 2.5])          # headings wrapped
    with pytest.raises(ValueError, match="a, b: expected one pose or stacks of equal length"):
        g.se2_compose(a, b[:3])
    with pytest.raises(ValueError, match="b"):
        g.se2_between(a, np.zeros((2, 2, 3)))


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
    R = g.so3_exp(rng.normal(size=3))
    T = g.se3_from_rt(R, rng.normal(size=3))
    assert np.array_equal(g.se3_from_rt(R, T[:3, 3], validate=False), T)
    np.testing.assert_allclose(g.se3_compose(T, g.se3_inverse(T)), np.eye(4), atol=1e-12)
    pts = rng.normal(size=(10, 3))
    back = g.transform_points(g.se3_inverse(T), g.transform_points(T, pts))
    np.testing.assert_allclose(back, pts, atol=1e-12)
    np.testing.assert_allclose(g.transform_points(T, pts), pts @ R.T + T[:3, 3], atol=1e-12)


def test_se2_se3_lift_agrees_with_planar_compose():
    rng = np.random.default_rng(4)
    a, b = _random_se2(rng, 2)
    T = g.se2_to_se3(a) @ g.se2_to_se3(b)
    ref = g.se2_compose(a, b)
    got = g.se3_to_se2(T)
    np.testing.assert_allclose(got[:2], ref[:2], atol=1e-12)
    assert g.wrap_angle(got[2] - ref[2]) == pytest.approx(0, abs=1e-12)


@pytest.mark.parametrize("call, match", [
    (lambda: g.se2_inverse([0, 0]), "a"),
    (lambda: g.se2_to_matrix([0, np.nan, 0]), "pose"),
    (lambda: g.se3_from_rt(np.ones((3, 3)), [0, 0, 0]), "rotation"),
    (lambda: g.se3_inverse(np.zeros((4, 4))), "transform"),
    (lambda: g.se3_compose(), "transforms"),
    (lambda: g.transform_points(np.eye(4), [[1, 2]]), "points"),
    (lambda: g.euler_matrix([0, 0, 0], seq="xq"), "seq"),
    (lambda: g.se2_to_pqt([[1, 2]]), "pose"),
    (lambda: g.matrix_to_se2(np.diag([1.0, -1.0, 1.0])), "matrix"),
    (lambda: g.se3_to_se2(np.ones((4, 4))), "transform"),
    (lambda: g.se2_to_se3([0, 0, 0], z=np.inf), "z"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_as_se3_accepts_rigid_transforms_and_promotes_batches():
    T = g.se3_from_rt(g.rot_z(0.4), [1.0, 2.0, 3.0])
    assert g.as_se3(T, "T").shape == (4, 4)
    assert g.as_se3(T, "T", batch=True).shape == (1, 4, 4)
    assert g.as_se3(np.stack([T, T]), "T", batch=True).shape == (2, 4, 4)
    # a rotation off by 1e-8 passes the default tolerance, not a tight one
    R = T.copy()
    R[0, 0] += 1e-8
    g.as_se3(R, "T")
    with pytest.raises(ValueError, match=r"tolerance 1e-10"):
        g.as_se3(R, "T", tol=1e-10)


@pytest.mark.parametrize("value, kwargs, match", [
    (np.eye(3), {}, r"T: expected shape \(4, 4\)"),
    (np.full((4, 4), np.nan), {}, r"T: .*finite"),
    (np.diag([1.0, 1.0, 1.0, 2.0]), {}, r"T: expected an SE\(3\) matrix with last row \[0, 0, 0, 1\], got \[0.0, 0.0, 0.0, 2.0\]"),
    (np.diag([1.0, 1.0, -1.0, 1.0]), {}, r"T\[:3, :3\]: expected a rotation matrix .* det = -1"),
    (np.diag([2.0, 1.0, 1.0, 1.0]), {}, r"max \|R\^T R - I\| = 3"),
    (np.stack([np.eye(4), np.diag([1.0, 1.0, -1.0, 1.0])]), {"batch": True}, r"at index 1"),
    (np.stack([np.eye(4)] * 2), {}, r"T: expected shape \(4, 4\)"),
])
def test_as_se3_errors_name_the_argument_and_the_defect(value, kwargs, match):
    with pytest.raises(ValueError, match=match):
        g.as_se3(value, "T", **kwargs)


def test_se3_functions_on_stacks_equal_the_single_transform_results():
    rng = np.random.default_rng(6)
    R = g.so3_exp(rng.normal(size=(5, 3)))
    t = rng.normal(size=(5, 3))
    T = g.se3_from_rt(R, t)
    assert T.shape == (5, 4, 4)
    poses = _random_se2(rng, 5)
    lifted = g.se2_to_se3(poses, z=0.3)
    for i in range(5):
        np.testing.assert_array_equal(T[i], g.se3_from_rt(R[i], t[i]))
        np.testing.assert_allclose(g.se3_inverse(T)[i], g.se3_inverse(T[i]), atol=1e-15)
        np.testing.assert_allclose(g.se3_compose(T, T[0])[i], T[i] @ T[0], atol=1e-15)
        np.testing.assert_array_equal(lifted[i], g.se2_to_se3(poses[i], z=0.3))
        np.testing.assert_allclose(g.se3_to_se2(lifted)[i], g.se3_to_se2(lifted[i]), atol=1e-15)
    np.testing.assert_allclose(g.se3_inverse(T) @ T, np.broadcast_to(np.eye(4), (5, 4, 4)), atol=1e-12)


def test_pose_error_is_validated_and_exact_for_known_motions():
    T = np.eye(4)
    T2 = g.se3_from_rt(g.rot_z(0.3), [0.1, 0.0, 0.0])
    np.testing.assert_allclose(g.pose_error(T2, T), [0.1, 0, 0, 0, 0, 0.3], atol=1e-15)
    near_pi = g.se3_from_rt(g.so3_exp(np.array([1, 1, 0]) / np.sqrt(2) * (np.pi - 1e-9)), np.zeros(3))
    assert np.isclose(np.linalg.norm(g.pose_error(near_pi, T)[3:]), np.pi - 1e-9)
    # a stack against one transform, and the unchecked fast path gives the same numbers
    stack = np.stack([T2, near_pi, T])
    np.testing.assert_array_equal(g.pose_error(stack, T), g.pose_error(stack, T, validate=False))
    assert g.pose_error(stack, T).shape == (3, 6)
    with pytest.raises(ValueError, match="T_target"):
        g.pose_error(np.ones((4, 4)), T)
    with pytest.raises(ValueError, match="equal length"):
        g.pose_error(np.stack([T, T]), np.stack([T, T, T]))


def test_intersect_lines_least_squares_point_and_cheirality():
    from robokit.geometry.planar import intersect_lines
    rng = np.random.default_rng(0)
    target = np.array([1.5, -0.5])
    origins = rng.uniform(-3, 3, (4, 2))
    dirs = (target - origins) * rng.uniform(0.5, 2.0, (4, 1))          # any length
    point, along = intersect_lines(origins, dirs)
    assert np.allclose(point, target) and np.allclose(along, np.linalg.norm(target - origins, axis=1))
    # noisy lines: the normal equations' solution is the brute-force minimum of squared distances
    noisy = dirs + rng.normal(0, 0.05, dirs.shape)
    point, _ = intersect_lines(origins, noisy)
    u = noisy / np.linalg.norm(noisy, axis=1, keepdims=True)

    def cost(p):
        r = p - origins
        return ((r ** 2).sum(1) - (r * u).sum(1) ** 2).sum()
    grid = point + np.stack(np.meshgrid(np.linspace(-0.01, 0.01, 21), np.linspace(-0.01, 0.01, 21)), -1).reshape(-1, 2)
    assert cost(point) <= min(cost(g) for g in grid) + 1e-12
    # a line pointing away has the point behind it
    _, along = intersect_lines([[0.0, 0.0], [4.0, 0.0]], [[-1.0, -1.0], [-1.0, 1.0]])
    assert along[0] < 0 < along[1]
    with pytest.raises(ValueError, match="parallel"):
        intersect_lines([[0.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [2.0, 0.0]])
    with pytest.raises(ValueError, match="origins"):
        intersect_lines([[0.0, 0.0]], [[1.0, 0.0]])


def test_cross_rays_agrees_with_intersect_lines_and_marks_parallel_pairs():
    from robokit.geometry.planar import cross_rays, intersect_lines
    g = np.random.default_rng(3)
    p, q = g.normal(size=(50, 2)), g.normal(size=(50, 2))
    a, b = g.uniform(-np.pi, np.pi, 50), g.uniform(-np.pi, np.pi, 50)
    d, e = np.column_stack([np.cos(a), np.sin(a)]), np.column_stack([np.cos(b), np.sin(b)])
    s, t, sin = cross_rays(p, d, q, e)
    assert np.allclose(p + s[:, None] * d, q + t[:, None] * e)           # the same point from both rays
    assert np.allclose(sin, np.sin(b - a))
    for k in range(5):                                                   # the least-squares crossing of two lines
        point, along = intersect_lines(np.array([p[k], q[k]]), np.array([d[k], e[k]]))
        assert np.allclose(point, p[k] + s[k] * d[k]) and np.allclose(along, [s[k], t[k]])
    s, t, sin = cross_rays([0.0, 0.0], [[1.0, 0.0]], [[0.0, 1.0]], [[1.0, 0.0]])   # parallel: no crossing
    assert sin[0] == 0.0 and not np.isfinite(s[0])
    with pytest.raises(ValueError, match="p, d, q, e"):
        cross_rays(np.zeros((3, 2)), np.ones((2, 2)), np.zeros((3, 2)), np.ones((3, 2)))
    with pytest.raises(ValueError, match="d"):
        cross_rays([0.0, 0.0], [[np.nan, 0.0]], [1.0, 1.0], [[0.0, 1.0]])
