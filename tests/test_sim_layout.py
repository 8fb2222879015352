"""The one 2D obstacle layout: its ray caster's tie rule at the edge cases, against an independent
per-ray reference, and its point, clearance and collision queries."""
import math

import numpy as np
import pytest

from robokit.sim import Layout
from robokit.sim.layout import box_corners, obstacle_array

RIGHT, UP, LEFT, DOWN = 0.0, np.pi / 2, np.pi, -np.pi / 2


def reference_range(o, angle, segments=(), circles=(), boxes=()):
    """One ray, one obstacle at a time, written independently of the kernel: a 2x2 solve for
    segments, the quadratic for circles and the slab method in the box frame (Kay & Kajiya 1986)."""
    o, d = np.asarray(o, float), np.array([math.cos(angle), math.sin(angle)])
    best = math.inf
    for a, b in segments:
        a, e = np.asarray(a, float), np.asarray(b, float) - a
        if abs(d[0] * e[1] - d[1] * e[0]) <= 1e-12 * math.hypot(*e):
            continue                                            # parallel: never hit
        t, s = np.linalg.solve(np.column_stack([d, -e]), a - o)
        if t >= 0 and 0 <= s <= 1:
            best = min(best, t)
    for cx, cy, r in circles:
        oc = o - (cx, cy)
        if oc @ oc <= r * r:
            return 0.0
        b, c = d @ oc, oc @ oc - r * r
        if b * b - c >= 0 and -b - math.sqrt(b * b - c) >= 0:
            best = min(best, -b - math.sqrt(b * b - c))
    for cx, cy, length, width, yaw in boxes:
        R = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
        p, q = R.T @ (o - (cx, cy)), R.T @ d
        half = np.array([length, width]) / 2
        if np.all(np.abs(p) <= half):
            return 0.0
        lo, hi = -math.inf, math.inf
        for k in range(2):
            if q[k] == 0:
                if abs(p[k]) > half[k]:
                    lo = math.inf
                continue
            t1, t2 = sorted(((-half[k] - p[k]) / q[k], (half[k] - p[k]) / q[k]))
            lo, hi = max(lo, t1), min(hi, t2)
        if lo <= hi and lo >= 0:
            best = min(best, lo)
    return best


def test_tie_rule_a_ray_starting_on_a_wall_reads_zero():
    wall = Layout(segments=[[[0.0, -1.0], [0.0, 1.0]]])
    np.testing.assert_array_equal(wall.raycast([0.0, 0.0], [RIGHT, LEFT, 0.3]), [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(wall.raycast([0.0, 1.0], [RIGHT]), [0.0])      # on its end point
    np.testing.assert_array_equal(wall.raycast([-0.5, 0.0], [RIGHT, LEFT]), [0.5, np.inf])


def test_tie_rule_grazing_a_circle_is_a_hit():
    lay = Layout(circles=[[5.0, 1.0, 1.0]])
    assert lay.raycast([0.0, 0.0], [RIGHT])[0] == 5.0                              # tangent at (5, 0)
    assert lay.raycast([0.0, -1e-9], [RIGHT])[0] == np.inf                         # just below: a miss
    assert lay.raycast([5.0, 0.0], [DOWN])[0] == 0.0                               # on the circle: contact


def test_tie_rule_a_segment_end_point_and_a_box_corner_are_hits():
    end = Layout(segments=[[[1.0, 0.0], [1.0, 1.0]]])
    assert end.raycast([0.0, 1.0], [RIGHT])[0] == 1.0                              # exactly its end point
    # the ray y = x touches the box [1, 3] x [-1, 1] only at its corner (1, 1)
    corner = Layout(boxes=[[2.0, 0.0, 2.0, 2.0, 0.0]])
    assert corner.raycast([0.0, 0.0], [np.pi / 4])[0] == pytest.approx(math.sqrt(2), abs=1e-12)
    assert corner.raycast([0.0, 1e-6], [np.pi / 4])[0] == np.inf


def test_tie_rule_parallel_segments_are_never_hit_but_their_neighbours_are():
    lay = Layout(segments=[[[2.0, 0.0], [4.0, 0.0]], [[2.0, 1.0], [4.0, 1.0]]])
    assert lay.raycast([0.0, 0.0], [RIGHT])[0] == np.inf                           # collinear, edge-on
    assert lay.raycast([3.0, 0.0], [RIGHT])[0] == np.inf                           # even starting on it
    # a box seen along its bottom edge: the left edge's end point is hit at the same distance
    box = Layout(boxes=[[3.0, 2.0, 2.0, 2.0, 0.0]])
    assert box.raycast([0.0, 1.0], [RIGHT])[0] == 2.0


@pytest.mark.parametrize("origin", [[10.0, 0.0], [10.5, 0.3], [11.0, 0.0], [20.0, 0.0], [21.0, 0.5], [21.0, 1.0],
                                    [30.0, 0.2]])
def test_tie_rule_inside_or_on_a_solid_reads_zero(origin):
    """Centres, interiors, a point on the circle, on a box edge, on a box corner, in a rotated box."""
    lay = Layout(circles=[[10.0, 0.0, 1.0]], boxes=[[20.0, 0.0, 2.0, 2.0, 0.0], [30.0, 0.0, 2.0, 1.0, 0.3]])
    assert lay.contains(origin)[0]
    np.testing.assert_array_equal(lay.raycast(origin, [RIGHT, UP, LEFT, DOWN]), 0.0)


def test_kernel_matches_the_per_ray_reference_on_random_layouts():
    rng = np.random.default_rng(11)
    for _ in range(30):
        segs = rng.uniform(-10, 10, (rng.integers(0, 6), 2, 2))
        nc, nb = rng.integers(0, 5, 2)
        circles = np.column_stack([rng.uniform(-10, 10, (nc, 2)), rng.uniform(0.2, 2.0, nc)])
        boxes = np.column_stack([rng.uniform(-10, 10, (nb, 2)), rng.uniform(0.3, 3.0, (nb, 2)), rng.uniform(-3, 3, nb)])
        lay = Layout(segs, circles, boxes)
        origins = rng.uniform(-12, 12, (40, 2))
        angles = rng.uniform(-np.pi, np.pi, 40)
        got = lay.raycast(origins, angles)
        want = [reference_range(o, a, segs, circles, boxes) for o, a in zip(origins, angles)]
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
        # one scanner origin for all rays, and the max_range cap with its culling, agree too
        np.testing.assert_allclose(lay.raycast(origins[0], angles), [reference_range(origins[0], a, segs, circles, boxes)
                                                                     for a in angles], rtol=0, atol=1e-9)
        np.testing.assert_allclose(lay.raycast(origins, angles, max_range=4.0), np.minimum(got, 4.0), rtol=0, atol=0)


def test_fast_path_gives_the_checked_answer():
    lay = Layout(segments=[[[3.0, -5.0], [3.0, 5.0]]], circles=[[0.0, 4.0, 1.0]], boxes=[[-4.0, 0.0, 1.0, 2.0, 0.2]])
    angles = np.linspace(-np.pi, np.pi, 37)
    np.testing.assert_array_equal(lay.raycast(np.zeros(2), angles, validate=False), lay.raycast([0.0, 0.0], angles))


def test_contains_clearance_and_collision_queries():
    lay = Layout(segments=[[[0.0, 5.0], [10.0, 5.0]]], circles=[[10.0, 0.0, 1.0]],
                 boxes=[[20.0, 0.0, 2.0, 2.0, 0.0]])
    np.testing.assert_array_equal(lay.contains([[10.0, 1.0], [21.0, 1.0], [5.0, 5.0], [0.0, 0.0]]),
                                  [True, True, False, False])               # closed solids; walls have no inside
    np.testing.assert_allclose(lay.clearance([[0.0, 0.0], [20.0, 3.0], [5.0, 4.0], [12.0, 5.0]]),
                               [5.0, 2.0, 1.0, 2.0])
    assert lay.collides([8.8, 0.0, 0.0], 0.5, 0.25) and not lay.collides([8.7, 0.0, 0.0], 0.5, 0.25)
    assert lay.collides([18.9, 0.9, np.pi / 4], 0.5, 0.25) and not lay.collides([18.9, 1.1, np.pi / 4], 0.5, 0.25)
    assert lay.collides([5.0, 4.8, 0.0], 0.5, 0.5) and not lay.collides([5.0, 4.7, 0.0], 0.5, 0.5)   # the wall
    assert lay.collides([5.0, 4.8, np.pi / 2], 0.5, 0.25) and not lay.collides([5.0, 4.7, np.pi / 2], 0.5, 0.25)
    assert not Layout().collides([0.0, 0.0, 0.0], 1.0, 1.0) and np.isinf(Layout().clearance([0.0, 0.0])).all()


def test_box_corners_are_counter_clockwise_and_validated_arrays_are_shared():
    c = box_corners([[1.0, 2.0, 4.0, 2.0, np.pi / 2]])[0]
    np.testing.assert_allclose(c, [[0.0, 4.0], [0.0, 0.0], [2.0, 0.0], [2.0, 4.0]], atol=1e-12)
    area2 = np.sum(c[:, 0] * np.roll(c[:, 1], -1) - np.roll(c[:, 0], -1) * c[:, 1])
    assert area2 == pytest.approx(16.0)                                    # positive: counter-clockwise
    assert obstacle_array([1.0, 2.0, 0.5], "circles").shape == (1, 3)
    lay = Layout(circles=[[1.0, 2.0, 0.5]])
    with pytest.raises(ValueError):
        lay.circles[0, 2] = 5.0                                             # read-only: the edges stay in step


@pytest.mark.parametrize("call, match", [
    (lambda: Layout(circles=[[1.0, 1.0, -1.0]]), r"circles: expected positive sizes \(radii, column 2\), got -1"),
    (lambda: Layout(boxes=[[1.0, 1.0, 1.0, 0.0, 0.0]]), r"boxes: expected positive sizes \(length and width"),
    (lambda: Layout(boxes=[[5.0, 5.0, 1.0, 1.0]]), r"boxes: expected shape \(N, 5\), got shape \(1, 4\)"),
    (lambda: Layout(segments=[[0.0, 1.0], [2.0, 3.0]]), r"segments: expected shape \(N, 2, 2\)"),
    (lambda: Layout(circles=[[np.nan, 1.0, 1.0]]), r"circles: expected finite values"),
    (lambda: obstacle_array([[1.0]], "walls"), r"kind: expected 'segments', 'circles' or 'boxes', got 'walls'"),
    (lambda: Layout().raycast([[0.0, 0.0], [1.0, 1.0]], [0.0, 1.0, 2.0]), r"origins: expected one origin or one per"),
    (lambda: Layout().raycast([0.0, 0.0], [[0.0]]), r"angles: expected a 1-D array"),
    (lambda: Layout().raycast([0.0, np.inf], [0.0]), r"origins: expected finite values"),
    (lambda: Layout().raycast([0.0, 0.0], [0.0], max_range=0.0), r"max_range: expected a positive number"),
    (lambda: Layout().clearance([[0.0, 0.0, 0.0]]), r"points: expected shape \(N, 2\)"),
    (lambda: Layout().collides([0.0, 0.0], 1.0, 1.0), r"pose: expected shape \(3\)"),
])
def test_bad_input_is_named(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


# --- a grid's outline as walls ---------------------------------------------------------------

def _march(occupied: np.ndarray, resolution: float, origin: np.ndarray, o: np.ndarray, angle: float,
           r_max: float) -> float:
    """Reference: Amanatides & Woo's (1987) exact cell walk, cell by cell along the ray, stopping at
    the entry into the first occupied cell."""
    d = np.array([np.cos(angle), np.sin(angle)])
    g = (o - origin) / resolution                       # grid units
    cell = np.floor(g).astype(int)
    step = np.where(d > 0, 1, -1)
    with np.errstate(divide="ignore"):
        t_next = np.where(d != 0, (cell + (step > 0) - g) / d, np.inf)
        t_delta = np.where(d != 0, 1 / np.abs(d), np.inf)
    t = 0.0
    while t * resolution < r_max:
        axis = int(np.argmin(t_next))
        t = t_next[axis]
        cell[axis] += step[axis]
        t_next[axis] += t_delta[axis]
        j, i = cell
        if 0 <= i < occupied.shape[0] and 0 <= j < occupied.shape[1] and occupied[i, j]:
            return min(float(t * resolution), r_max)
    return r_max


@pytest.mark.parametrize("seed", range(4))
def test_a_grid_outline_stops_rays_at_the_first_occupied_cell(seed):
    rng = np.random.default_rng(seed)
    occupied = rng.random((12, 15)) < 0.25
    res, origin = 0.2, np.array([-1.0, 0.5])
    walls = Layout.from_cells(occupied, res, origin)
    free = np.argwhere(~occupied)
    for i, j in free[rng.choice(len(free), 5, replace=False)]:
        o = origin + (np.array([j, i]) + rng.uniform(0.2, 0.8, 2)) * res
        angles = rng.uniform(-np.pi, np.pi, 20)
        got = walls.raycast(o, angles, 4.0)
        want = [_march(occupied, res, origin, o, a, 4.0) for a in angles]
        np.testing.assert_allclose(got, want, atol=1e-9)


def test_a_grid_outline_merges_runs_of_cell_edges():
    walls = Layout.from_cells(np.ones((3, 50), bool), 0.1)      # one solid block: four sides
    assert len(walls.segments) == 4
    assert sorted(np.ptp(walls.segments[:, :, 0], axis=1).round(9).tolist()) == [0.0, 0.0, 5.0, 5.0]


def test_a_grid_outline_refuses_bad_input():
    with pytest.raises(ValueError, match="occupied"):
        Layout.from_cells(np.ones(4, bool), 0.1)
    for bad in ([[0.0, 1.0]], [[np.nan]], [["a"]], None):
        with pytest.raises(TypeError, match="occupied"):
            Layout.from_cells(bad, 0.1)
    with pytest.raises(ValueError, match="resolution"):
        Layout.from_cells(np.ones((2, 2), bool), 0.0)
    with pytest.raises(ValueError, match="origin"):
        Layout.from_cells(np.ones((2, 2), bool), 0.1, origin=(np.nan, 0.0))
    assert len(Layout.from_cells(np.zeros((3, 3), bool), 0.1).segments) == 0
