"""Occupancy grids: log odds, the cell convention, the likelihood field against brute force."""
from __future__ import annotations

import math

import numpy as np
import pytest

from robokit.mapping import EmptyMapError, OccupancyGrid, likelihood_field, log_odds, probability


def test_log_odds_and_probability_are_inverse_and_hand_worked():
    assert log_odds(0.7) == pytest.approx(math.log(0.7 / 0.3), abs=1e-15)
    p = np.array([1e-9, 0.2, 0.5, 0.999])
    np.testing.assert_allclose(probability(log_odds(p)), p, rtol=1e-12)
    assert probability(-800.0) == 0.0 and probability(800.0) == 1.0       # no overflow
    for bad in (0.0, 1.0, -0.1, np.nan):
        with pytest.raises(ValueError, match="p:"):
            log_odds(bad)
    with pytest.raises(ValueError, match="l:"):
        probability(np.inf)


def test_cell_convention_row_zero_is_lowest_y():
    grid = OccupancyGrid(np.zeros((3, 4)), 0.25, origin=(-1.0, 2.0))
    assert grid.bounds == (-1.0, 2.0, 0.0, 2.75)
    ij, inside = grid.cell_of([[-0.99, 2.01], [-0.01, 2.74], [-1.01, 2.1], [0.0, 2.1], [-0.5, 1.99]])
    assert ij[:2].tolist() == [[0, 0], [2, 3]]
    assert inside.tolist() == [True, True, False, False, False]
    centres = grid.cell_centres(ij[:2])
    np.testing.assert_allclose(centres, [[-0.875, 2.125], [-0.125, 2.625]])
    back, ok = grid.cell_of(centres)
    assert back.tolist() == ij[:2].tolist() and ok.all()


def test_empty_covers_bounds_exactly():
    g = OccupancyGrid.empty((0.0, -1.2, 36.1, 1.2), 0.05)
    assert g.shape == (48, 722)
    np.testing.assert_allclose(g.bounds, (0.0, -1.2, 36.1, 1.2))
    assert g.unknown_mask().all()
    with pytest.raises(ValueError, match="bounds"):
        OccupancyGrid.empty((0.0, 0.0, -1.0, 1.0), 0.1)
    with pytest.raises(ValueError, match="bounds, resolution"):
        OccupancyGrid.empty((0.0, 0.0, 1e6, 1e6), 0.01)


def test_masks_use_map_server_thresholds():
    P = np.array([[0.1, 0.195, 0.197, 0.5, 0.65, 0.651, np.nan]])
    g = OccupancyGrid.from_probability(P, 1.0)
    assert g.free_mask().tolist() == [[True, True, False, False, False, False, False]]
    assert g.occupied_mask().tolist() == [[False, False, False, False, False, True, False]]
    assert g.unknown_mask().tolist() == [[False, False, True, True, True, False, True]]
    with pytest.raises(ValueError, match="free_threshold"):
        g.unknown_mask(0.7, 0.6)


def test_free_cells_and_empty_map_error():
    g = OccupancyGrid.from_probability([[0.0, 1.0], [np.nan, 0.0]], 0.5, origin=(10.0, 0.0))
    np.testing.assert_allclose(g.free_cells(), [[10.25, 0.25], [10.75, 0.75]])
    with pytest.raises(EmptyMapError, match="no free cell"):
        OccupancyGrid.from_probability([[1.0, np.nan]], 0.5).free_cells()


def test_likelihood_field_matches_brute_force():
    rng = np.random.default_rng(3)
    P = np.where(rng.random((17, 23)) < 0.08, 1.0, 0.0)
    res = 0.07
    grid = OccupancyGrid.from_probability(P, res, origin=(-0.3, 1.1))
    field = likelihood_field(grid, max_distance=10.0)
    occ = grid.cell_centres(np.argwhere(P > 0.5))
    every = grid.cell_centres(np.argwhere(np.ones_like(P, bool)))
    brute = np.array([np.min(np.hypot(*(occ - c).T)) for c in every]).reshape(P.shape)
    np.testing.assert_allclose(field.distance, brute, atol=1e-9, rtol=0)
    # clipped at max_distance, and lookups read the cell that holds each point
    clipped = likelihood_field(grid, max_distance=0.1)
    np.testing.assert_allclose(clipped.distance, np.minimum(brute, 0.1), atol=1e-9, rtol=0)
    pts = every + rng.uniform(-0.49, 0.49, every.shape) * res
    np.testing.assert_allclose(field.lookup(pts), brute.ravel(), atol=1e-9, rtol=0)
    np.testing.assert_allclose(field.lookup(pts.reshape(17, 23, 2), check=False), brute, atol=1e-9, rtol=0)
    off = np.array([[-0.31, 1.2], [5.0, 1.2], [0.0, np.nan]])
    assert field.lookup(off[:2]).tolist() == [10.0, 10.0]
    assert field.lookup(off, check=False).tolist() == [10.0, 10.0, 10.0]
    with pytest.raises(ValueError, match="xy"):
        field.lookup(off)


def test_likelihood_field_without_obstacles_is_max_distance():
    field = likelihood_field(OccupancyGrid(np.zeros((4, 5)), 0.1), max_distance=1.5)
    assert np.all(field.distance == 1.5)
    with pytest.raises(TypeError, match="grid"):
        likelihood_field(np.zeros((4, 5)))
