"""Support polygon and static stability margin: hand-worked polygons, brute force, the vectorised twin."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import Delaunay

from robokit.legged.support import SupportPolygonError, stability_margin, stability_margins, support_polygon

SQUARE = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
RIGHT_TRIANGLE = [[0.0, 0.0], [4.0, 0.0], [0.0, 3.0]]     # 3-4-5: inradius (3 + 4 - 5) / 2 = 1 at (1, 1)


def signed_area(polygon):
    x, y = np.asarray(polygon).T
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def brute_force_margin(polygon, point, samples=20001):
    """Distance to the boundary by sampling every edge densely; inside from a Delaunay triangulation."""
    polygon = np.asarray(polygon)
    s = np.linspace(0.0, 1.0, samples)[:, None]
    boundary = np.concatenate([a + s * (b - a) for a, b in zip(polygon, np.roll(polygon, -1, axis=0))])
    distance = np.linalg.norm(boundary - point, axis=1).min()
    return distance if Delaunay(polygon).find_simplex(point) >= 0 else -distance


# --- the support polygon ------------------------------------------------------------------

def test_support_polygon_is_the_counter_clockwise_hull():
    feet = [[1.0, 1.0], [0.0, 0.0], [0.5, 0.5], [0.0, 1.0], [1.0, 0.0], [0.5, 0.0]]   # centre and an edge point
    hull = support_polygon(feet)
    assert sorted(map(tuple, hull.tolist())) == sorted(map(tuple, SQUARE))
    assert signed_area(hull) == pytest.approx(1.0)          # > 0: counter-clockwise
    shuffled = support_polygon(np.random.default_rng(1).permutation(feet))
    np.testing.assert_array_equal(shuffled, hull)


@pytest.mark.parametrize("feet, why", [
    ([[0.0, 0.0], [1.0, 0.0]], "at least three"),
    ([[0.0, 0.0]], "at least three"),
    ([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], "collinear"),
    ([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 1e-9]], "collinear"),
    ([[0.3, 0.3]] * 4, "collinear"),
])
def test_fewer_than_three_feet_or_a_line_is_no_support_polygon(feet, why):
    with pytest.raises(SupportPolygonError, match=f"feet_xy: .*{why}"):
        support_polygon(feet)
    with pytest.raises(ValueError, match="feet_xy"):             # a SupportPolygonError is a ValueError
        stability_margin(feet, [0.0, 0.0])


def test_bad_coordinates_are_named():
    with pytest.raises(ValueError, match="feet_xy: expected finite"):
        support_polygon([[0.0, 0.0], [1.0, 0.0], [np.nan, 1.0]])
    with pytest.raises(ValueError, match="com_xy: expected shape"):
        stability_margin(SQUARE, [0.5, 0.5, 0.0])
    with pytest.raises(ValueError, match="feet_xy: expected coordinates within"):
        stability_margin([[0.0, 0.0], [1e300, 0.0], [0.0, 1e300]], [0.0, 0.0])


# --- the margin on hand-made polygons --------------------------------------------------------

@pytest.mark.parametrize("com, expected", [
    ([0.5, 0.5], 0.5),                  # centre of the unit square
    ([0.25, 0.5], 0.25),                # nearer the left edge
    ([0.5, 0.0], 0.0),                  # on an edge
    ([1.0, 1.0], 0.0),                  # on a vertex
    ([2.0, 0.5], -1.0),                 # outside, beside an edge
    ([2.0, 2.0], -math.sqrt(2.0)),      # outside, nearest a vertex
    ([0.5, -0.1], -0.1),
])
def test_unit_square(com, expected):
    assert stability_margin(SQUARE, com) == pytest.approx(expected, abs=1e-15)


@pytest.mark.parametrize("com, expected", [
    ([1.0, 1.0], 1.0),                  # the incentre: the inradius
    ([1.0, 0.5], 0.5),                  # the bottom edge is nearest
    ([2.0, 1.0], 0.4),                  # hypotenuse 3x + 4y = 12: |6 + 4 - 12| / 5
    ([5.0, 0.0], -1.0),                 # beyond the vertex (4, 0)
    ([3.0, 3.0], -1.8),                 # beyond the hypotenuse: (9 + 12 - 12) / 5, foot (1.92, 1.56) on it
    ([-1.0, -1.0], -math.sqrt(2.0)),    # beyond the right-angle vertex
])
def test_right_triangle_worked_by_hand(com, expected):
    assert stability_margin(RIGHT_TRIANGLE, com) == pytest.approx(expected, abs=1e-12)


def test_equilateral_triangle_centre_is_its_inradius():
    side = 0.3
    tri = [[0.0, 0.0], [side, 0.0], [side / 2, side * math.sqrt(3) / 2]]
    assert stability_margin(tri, [side / 2, side * math.sqrt(3) / 6]) == pytest.approx(side / (2 * math.sqrt(3)))


def test_random_convex_polygons_against_brute_force():
    rng = np.random.default_rng(7)
    for _ in range(5):
        feet = rng.normal(size=(12, 2)) * [0.3, 0.2]
        polygon = support_polygon(feet)
        for com in rng.uniform(-0.6, 0.6, size=(20, 2)):
            expected = brute_force_margin(polygon, com)
            assert stability_margin(feet, com) == pytest.approx(expected, abs=1e-4)


def test_margin_does_not_depend_on_the_frame():
    rng = np.random.default_rng(3)
    feet, com = rng.normal(size=(5, 2)), rng.normal(size=2) * 0.3
    c, s = math.cos(0.7), math.sin(0.7)
    R, shift = np.array([[c, -s], [s, c]]), np.array([2.0, -1.0])
    assert stability_margin(feet @ R.T + shift, R @ com + shift) == pytest.approx(stability_margin(feet, com))


# --- the vectorised margins ------------------------------------------------------------------

def test_margins_over_time_match_one_polygon_at_a_time():
    rng = np.random.default_rng(11)
    n = 3000
    feet = rng.normal(size=(n, 4, 2)) * [0.16, 0.08] + np.array([[0.16, 0.08], [0.16, -0.08], [-0.16, 0.08],
                                                                 [-0.16, -0.08]])
    stance = rng.random((n, 4)) < 0.8
    com = rng.normal(size=(n, 2)) * 0.08
    margins = stability_margins(feet, stance, com)
    assert margins.shape == (n,)
    for k in range(n):
        if stance[k].sum() < 3:
            assert margins[k] == -np.inf
        else:
            assert margins[k] == pytest.approx(stability_margin(feet[k, stance[k]], com[k]), abs=1e-12)
    assert np.isinf(margins).sum() > 100 and (margins > 0).sum() > 100 and (margins[np.isfinite(margins)] < 0).sum() > 100


def test_margins_with_feet_on_an_edge_or_coinciding():
    square = np.array(SQUARE)
    on_edge = np.array([square[0], [0.5, 0.0], square[1], square[2], square[3]])     # a foot mid-edge
    twin = np.array([square[0], square[0], square[1], square[2], square[3]])         # two feet on one spot
    feet = np.stack([on_edge, twin, on_edge])
    stance = np.ones((3, 5), bool)
    com = np.array([[0.5, 0.3], [0.2, 0.5], [0.5, -0.2]])
    np.testing.assert_allclose(stability_margins(feet, stance, com), [0.3, 0.2, -0.2], atol=1e-15)


def test_margins_are_minus_inf_without_a_support_polygon():
    feet = np.array([[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0]]] * 3)
    stance = np.array([[1, 1, 1, 0], [1, 1, 0, 0], [1, 1, 1, 1]], bool)     # a line; two feet; a triangle
    out = stability_margins(feet, stance, [[0.5, 0.0]] * 3)
    assert out[0] == -np.inf and out[1] == -np.inf and out[2] == pytest.approx(0.0)


def test_margins_bad_shapes_are_named():
    feet = np.zeros((5, 4, 2))
    with pytest.raises(ValueError, match="stance: expected shape \\(5, 4\\)"):
        stability_margins(feet, np.ones((5, 3), bool), np.zeros((5, 2)))
    with pytest.raises(ValueError, match="com_xy: expected shape \\(5, 2\\)"):
        stability_margins(feet, np.ones((5, 4), bool), np.zeros((4, 2)))
    with pytest.raises(TypeError, match="stance"):
        stability_margins(feet, np.full((5, 4), 0.5), np.zeros((5, 2)))


def test_a_closed_or_clockwise_polygon_gives_the_same_margin():
    # a closed ring had given NaN, a clockwise polygon a negative distance for a point inside
    from robokit.legged.support import SupportPolygonError, nearest_boundary_point

    square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    want = nearest_boundary_point(square, [0.5, 0.2])
    for polygon in (square + [square[0]], square[::-1], (square + [square[0]])[::-1]):
        near, d = nearest_boundary_point(polygon, [0.5, 0.2])
        assert near.tolist() == want[0].tolist() and d == want[1] == 0.2
    with pytest.raises(SupportPolygonError, match="collinear"):
        nearest_boundary_point([[0, 0], [1, 1], [2, 2]], [0.5, 0.2])
