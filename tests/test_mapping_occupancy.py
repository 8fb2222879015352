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
    P = np.array([[0.1, 0.195, 0.197, 0.5, 0.65, 0.651, 0.3]])
    g = OccupancyGrid.from_probability(P, 1.0)
    assert g.free_mask().tolist() == [[True, True, False, False, False, False, False]]
    assert g.occupied_mask().tolist() == [[False, False, False, False, False, True, False]]
    assert g.unknown_mask().tolist() == [[False, False, True, True, True, False, True]]
    with pytest.raises(ValueError, match="free_threshold"):
        g.unknown_mask(0.7, 0.6)


def test_free_cells_and_empty_map_error():
    g = OccupancyGrid.from_probability([[0.0, 1.0], [0.5, 0.0]], 0.5, origin=(10.0, 0.0))
    np.testing.assert_allclose(g.free_cells(), [[10.25, 0.25], [10.75, 0.75]])
    with pytest.raises(EmptyMapError, match="no free cell"):
        OccupancyGrid.from_probability([[1.0, 0.5]], 0.5).free_cells()


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
    np.testing.assert_allclose(field.lookup(pts.reshape(17, 23, 2), validate=False), brute, atol=1e-9, rtol=0)
    off = np.array([[-0.31, 1.2], [5.0, 1.2], [0.0, np.nan]])
    assert field.lookup(off[:2]).tolist() == [10.0, 10.0]
    assert field.lookup(off, validate=False).tolist() == [10.0, 10.0, 10.0]
    with pytest.raises(ValueError, match="xy"):
        field.lookup(off)


def test_likelihood_field_without_obstacles_is_max_distance():
    field = likelihood_field(OccupancyGrid(np.zeros((4, 5)), 0.1), max_distance=1.5)
    assert np.all(field.distance == 1.5)
    with pytest.raises(TypeError, match="grid"):
        likelihood_field(np.zeros((4, 5)))


# ---- mapping with known poses (Thrun et al. 2005, Tables 9.1 and 9.2) ----

from robokit.mapping import (L_FREE, L_OCC, LOG_ODDS_MAX, inverse_range_sensor_model,  # noqa: E402
                             occupancy_grid_mapping, occupancy_grid_mapping_readable, update_log_odds)
from robokit.sim import Lidar, corridor_path, long_corridor  # noqa: E402


def test_one_cell_over_two_scans_by_hand():
    grid = OccupancyGrid.empty((0.0, 0.0, 3.0, 0.5), 0.5)          # one row, cell 4 centred at x = 2.25
    one = update_log_odds(grid, [0.0, 0.25, 0.0], [2.25], [0.0], r_max=4.0, thickness=0.5)
    two = update_log_odds(one, [1.0, 0.25, 0.0], [2.0], [0.0], r_max=4.0, thickness=0.5)
    # scan 1 ends in the cell: a hit; scan 2 passes through it (r = 1.25 < z = 2.0): a miss
    assert one.log_odds[0, 4] == pytest.approx(math.log(0.7 / 0.3), abs=1e-12)
    assert two.log_odds[0, 4] == pytest.approx(math.log(0.7 * 0.4 / (0.3 * 0.6)), abs=1e-12)
    assert grid.log_odds[0, 4] == 0.0                                # the input grid is left alone
    # the prior is subtracted once per update: outside the field a cell keeps its value
    prior = update_log_odds(grid, [0.0, 0.25, 0.0], [0.6], [0.0], r_max=4.0, thickness=0.5, l0=0.2,
                            l_occ=1.0, l_free=-1.0)
    assert prior.log_odds[0].tolist() == [-1.2, 0.8, 0.0, 0.0, 0.0, 0.0]


def test_clamping_lets_a_cell_change_its_mind():
    grid = OccupancyGrid.empty((0.0, 0.0, 3.0, 0.5), 0.5)
    for _ in range(10):
        grid = update_log_odds(grid, [0.0, 0.25, 0.0], [2.25], [0.0], r_max=4.0, thickness=0.5)
    assert grid.log_odds[0, 4] == LOG_ODDS_MAX
    for _ in range(13):                                              # then 13 misses make it free
        grid = update_log_odds(grid, [0.0, 0.25, 0.0], [np.inf], [0.0], r_max=4.0, thickness=0.5)
    assert grid.log_odds[0, 4] == pytest.approx(LOG_ODDS_MAX + 13 * L_FREE)
    assert grid.free_mask()[0, 4]


def test_max_range_returns_clear_to_r_max_without_a_hit():
    cells = np.column_stack([np.arange(0.25, 5.0, 0.5), np.zeros(10)])
    for z in (np.inf, 3.0, 7.5):                                      # no return, r_max itself, beyond
        ism = inverse_range_sensor_model(cells, [0, 0, 0], [z], [0.0], r_max=3.0, thickness=0.5)
        assert ism.tolist() == [L_FREE] * 6 + [0.0] * 4
    ism = inverse_range_sensor_model(cells, [0, 0, 0], [2.75], [0.0], r_max=3.0, thickness=0.5)
    assert ism.tolist() == [L_FREE] * 5 + [L_OCC] + [0.0] * 4


def corridor_run(rate=2.0, lidar=None):
    world = long_corridor()
    lidar = lidar or Lidar()
    path = corridor_path(world, rate=rate)
    scans = np.array([lidar.scan(world, p) for p in path.poses])
    return world, lidar, path, scans


def test_corridor_map_has_walls_at_the_walls_and_free_middle():
    world, lidar, path, scans = corridor_run()
    res = 0.05
    grid = occupancy_grid_mapping(path.poses, scans, lidar.angles, (-0.2, -1.4, 36.3, 1.4), res, r_max=lidar.r_max)
    ij = np.argwhere(grid.occupied_mask())
    xy = grid.cell_centres(ij)
    side = (xy[:, 0] > 0.3) & (xy[:, 0] < 35.8)                      # leave the end walls aside
    wall_rows = [grid.cell_of([0.0, s * y])[0][0, 0] for s in (-1, 1) for y in (1.085, 1.155)]
    gap = np.min(np.abs(ij[side, 0][:, None] - np.array(wall_rows)[None, :]), axis=1)
    assert side.sum() > 1000 and gap.max() <= 1                       # every occupied cell within one cell of a wall
    for s in (-1, 1):                                                 # and the walls are mapped all along
        cols = np.unique(ij[side & (np.sign(xy[:, 1]) == s), 1])
        assert len(cols) >= 0.95 * (35.5 / res)
    xs = np.arange(0.9, 35.2, res)
    middle = np.column_stack([xs, np.full_like(xs, 0.01)])
    mid_ij, inside = grid.cell_of(middle)
    assert inside.all() and grid.free_mask()[mid_ij[:, 0], mid_ij[:, 1]].all()
    # behind the walls nothing was seen
    behind = grid.cell_of([[10.0, 1.35], [20.0, -1.35]])[0]
    assert grid.unknown_mask()[behind[:, 0], behind[:, 1]].all()


def test_fast_mapping_equals_the_reference():
    lidar = Lidar(beams=90, noise=0.01, offset=(0.1, 0.05, 0.2))
    world, _, path, _ = corridor_run(rate=1.0)
    poses = path.poses[10:13] + [[0.0, 0.1, 0.3]]                   # off the middle line, turned
    scans = np.array([lidar.scan(world, p, rng=i) for i, p in enumerate(poses)])
    kw = dict(r_max=lidar.r_max, sensor_offset=lidar.offset, thickness=0.15)
    fast = occupancy_grid_mapping(poses, scans, lidar.angles, (0.0, -1.3, 12.0, 1.3), 0.1, **kw)
    ref = occupancy_grid_mapping_readable(poses, scans, lidar.angles, (0.0, -1.3, 12.0, 1.3), 0.1, **kw)
    assert fast.shape == ref.shape == (26, 120)
    np.testing.assert_allclose(fast.log_odds, ref.log_odds, rtol=0, atol=1e-12)
    assert (fast.log_odds > 0).sum() > 50 and (fast.log_odds < 0).sum() > 500


def test_mapping_refuses_bad_scans():
    a = np.arange(4) * np.pi / 2
    kw = dict(bounds=(0, 0, 1, 1), resolution=0.1, r_max=3.0)
    with pytest.raises(ValueError, match=r"scans: .*nan at index \[1, 2\]"):
        occupancy_grid_mapping(np.zeros((2, 3)), [[1.0] * 4, [1.0, 1.0, np.nan, 1.0]], a, **kw)
    with pytest.raises(ValueError, match="scans: .*-1.0"):
        occupancy_grid_mapping(np.zeros((1, 3)), [[1.0, -1.0, 1.0, 1.0]], a, **kw)
    with pytest.raises(ValueError, match="scans: expected at least one beam"):
        occupancy_grid_mapping(np.zeros((1, 3)), np.zeros((1, 0)), [], **kw)
    with pytest.raises(ValueError, match="angles: expected at least one"):
        occupancy_grid_mapping(np.zeros((1, 3)), np.zeros((1, 4)), [], **kw)
    with pytest.raises(ValueError, match="scans: expected shape \\(2, 4\\)"):
        occupancy_grid_mapping(np.zeros((2, 3)), [[1.0] * 4], a, **kw)
    with pytest.raises(ValueError, match="poses"):
        occupancy_grid_mapping(np.zeros((0, 3)), np.zeros((0, 4)), a, **kw)
    with pytest.raises(ValueError, match="ranges: expected at least one beam"):
        update_log_odds(OccupancyGrid.empty((0, 0, 1, 1), 0.1), [0, 0, 0], [], [0.0], r_max=1.0)
    with pytest.raises(ValueError, match="clamp"):
        occupancy_grid_mapping(np.zeros((1, 3)), [[1.0] * 4], a, clamp=(1.0, -1.0), **kw)


# ---- ROS map_server files ----

from robokit.mapping import MapFileError, load_map, save_map  # noqa: E402


def masks(grid):
    return grid.free_mask(), grid.occupied_mask(), grid.unknown_mask()


@pytest.mark.parametrize("negate", [0, 1])
@pytest.mark.parametrize("mode", ["trinary", "scale"])
def test_map_server_round_trip(tmp_path, negate, mode):
    rng = np.random.default_rng(5)
    grid = OccupancyGrid(rng.uniform(-3, 4, (9, 14)), 0.05, origin=(-0.2, -1.4))
    pgm, yaml = save_map(grid, tmp_path / "run", negate=negate, mode=mode)
    assert (pgm.name, yaml.name) == ("run.pgm", "run.yaml")
    back = load_map(yaml)
    assert back.shape == grid.shape and back.resolution == 0.05 and back.origin.tolist() == [-0.2, -1.4]
    for a, b in zip(masks(back), masks(grid)):
        np.testing.assert_array_equal(a, b)
    if mode == "scale":
        unknown = grid.unknown_mask()
        np.testing.assert_allclose(back.probability[unknown], grid.probability[unknown], atol=1 / 255)


def test_pgm_rows_are_flipped_and_trinary(tmp_path):
    P = np.array([[1.0, 0.0], [0.5, 0.0], [0.0, 0.0]])             # row 0 = lowest y
    pgm, _ = save_map(OccupancyGrid.from_probability(P, 0.1), tmp_path / "m")
    data = pgm.read_bytes()
    assert data.startswith(b"P5\n2 3\n255\n")
    assert list(data[-6:]) == [254, 254, 205, 254, 0, 254]              # the top row (highest y) first


def test_load_map_reads_a_hand_written_ros_map(tmp_path):
    (tmp_path / "maps").mkdir()
    (tmp_path / "maps" / "office.pgm").write_bytes(b"P5\n# CREATOR: map_saver.cpp\n3 2\n255\n" + bytes([0, 254, 205, 100, 230, 20]))
    (tmp_path / "maps" / "office.yaml").write_text(
        "# a ROS map\nimage: office.pgm\nresolution: 0.025000\norigin: [-12.5, -7.25, 0.000000]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    grid = load_map(str(tmp_path / "maps" / "office.yaml"))
    assert grid.resolution == 0.025 and grid.origin.tolist() == [-12.5, -7.25]
    # bottom image row [100, 230, 20]: p = 0.608 (unknown), 0.098 (free), 0.922 (occupied)
    assert grid.occupied_mask().astype(int).tolist() == [[0, 0, 1], [1, 0, 0]]
    assert grid.free_mask().astype(int).tolist() == [[0, 1, 0], [0, 1, 0]]


@pytest.mark.parametrize("yaml_text, pgm, message", [
    ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\n", None,
     r"missing key\(s\) \['free_thresh'\]"),
    ("image: m.pgm\nresolution: fast\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
     None, "resolution: expected a positive number"),
    ("image: m.pgm\nresolution: 0.05\norigin: [0, zero, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
     None, "line 3: 'zero' is not a number"),
    ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0.5]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
     None, "yaw = 0.5.*not supported"),
    ("image: m.pgm\nresolution: 0.05\nresolution: 0.1\n", None, "line 3: key 'resolution' appears twice"),
    ("image: m.pgm\n  - just a list item\n", None, "line 2: expected 'key: value'"),
    ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.1\nfree_thresh: 0.2\n",
     None, "free_thresh: expected below occupied_thresh"),
    ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 2\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
     None, "negate: expected 0 or 1"),
    ("image: m.pgm\nmode: raw\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
     None, "'raw' is not supported"),
    ("image: gone.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n",
     None, "gone.pgm: the map image named by the YAML does not exist"),
    (None, b"P5\n3 2\n255\n" + bytes(5), r"m.pgm: expected 3 x 2 = 6 pixel bytes, got 5"),
    (None, b"P5\n3 2\n255\n" + bytes(7), "got 7"),
    (None, b"P2\n3 2\n255\n0 0 0 0 0 0", "expected a binary PGM"),
    (None, b"P5\n3 2\n65535\n" + bytes(12), "maxval 65535"),
    (None, b"P5\n3", "truncated PGM header"),
    (None, b"P5\n3 x\n255\n" + bytes(6), "must be integers"),
    (None, b"P5\n0 2\n255\n", "positive width and height"),
])
def test_corrupt_map_files_raise_map_file_error(tmp_path, yaml_text, pgm, message):
    good = "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.2\n"
    (tmp_path / "m.yaml").write_text(yaml_text or good)
    (tmp_path / "m.pgm").write_bytes(pgm or b"P5\n3 2\n255\n" + bytes(6))
    with pytest.raises(MapFileError, match=message):
        load_map(tmp_path / "m.yaml")


def test_missing_yaml_and_bad_save_arguments(tmp_path):
    with pytest.raises(MapFileError, match="no such map file"):
        load_map(tmp_path / "nothing.yaml")
    grid = OccupancyGrid(np.zeros((2, 2)), 0.1)
    with pytest.raises(ValueError, match="negate"):
        save_map(grid, tmp_path / "m", negate=3)
    with pytest.raises(ValueError, match="mode"):
        save_map(grid, tmp_path / "m", mode="raw")
    with pytest.raises(TypeError, match="grid"):
        save_map(np.zeros((2, 2)), tmp_path / "m")


def test_from_probability_refuses_nan_and_out_of_range():
    for bad in ([[0.5, np.nan]], [[0.5, 1.5]], [[-0.1]], [[np.inf]]):
        with pytest.raises(ValueError, match="P:"):
            OccupancyGrid.from_probability(bad, 0.1)
    with pytest.raises(ValueError, match="log_odds"):
        OccupancyGrid(np.zeros((0, 3)), 0.1)


@pytest.mark.parametrize("name", ["a #b", "[lead", "colon: x", "it's", " space", 'q"uote', "{brace}", "-dash"])
def test_save_map_writes_names_that_load_map_reads_back(tmp_path, name):
    # the YAML's image value was written bare: " #" began a comment, "[" a list, and load_map refused it
    from robokit.mapping.map_server import load_map, save_map

    grid = OccupancyGrid.from_probability([[0.0, 1.0, 0.5]], 0.05, origin=(-1.0, 2.0))
    _, yaml = save_map(grid, tmp_path / name)
    np.testing.assert_array_equal(load_map(yaml).probability, load_map(save_map(grid, tmp_path / "plain")[1]).probability)


def test_save_map_refuses_a_name_it_cannot_write_and_load_map_bounds_what_it_reads(tmp_path):
    from robokit.mapping.map_server import MapFileError, load_map, save_map

    grid = OccupancyGrid.from_probability([[0.0, 1.0]], 0.05)
    for name in ("new\nline", "both'\""):
        with pytest.raises(ValueError, match="stem"):
            save_map(grid, tmp_path / name)
    assert list(tmp_path.iterdir()) == []
    device = tmp_path / "device.yaml"
    device.write_text("image: /dev/zero\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                      "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    with pytest.raises(MapFileError, match="not a regular file"):
        load_map(device)
    big = tmp_path / "big.yaml"
    big.write_text("# padding\n" * 10_000)
    with pytest.raises(MapFileError, match="more than"):
        load_map(big)


def test_a_cropped_grid_keeps_its_cells_where_they_were():
    rng = np.random.default_rng(0)
    grid = OccupancyGrid(rng.normal(size=(30, 40)), 0.1, origin=(-1.0, 2.0))
    part = grid.crop((0.0, 2.5, 1.5, 4.0))
    assert part.shape == (15, 15) and part.bounds == pytest.approx((0.0, 2.5, 1.5, 4.0))
    points = rng.uniform([0.01, 2.51], [1.49, 3.99], size=(50, 2))
    ij, _ = grid.cell_of(points)
    km, inside = part.cell_of(points)
    assert inside.all()
    np.testing.assert_array_equal(grid.log_odds[ij[:, 0], ij[:, 1]], part.log_odds[km[:, 0], km[:, 1]])


@pytest.mark.parametrize("bounds, match", [((0.0, 2.5, -1.0, 4.0), "x1 > x0"), ((-2.0, 2.5, 1.0, 4.0), "inside"),
                                           ((0.0, 2.5, 0.04, 4.0), "whole cell"), ((0.0, np.nan, 1.0, 4.0), "finite")])
def test_a_crop_outside_or_empty_is_refused(bounds, match):
    grid = OccupancyGrid(np.zeros((30, 40)), 0.1, origin=(-1.0, 2.0))
    with pytest.raises(ValueError, match=match):
        grid.crop(bounds)


def test_a_crop_rounds_its_corners_to_the_nearest_cell_edge():
    grid = OccupancyGrid(np.zeros((30, 40)), 0.1, origin=(-1.0, 2.0))
    part = grid.crop((0.02, 2.48, 1.46, 4.03))
    assert part.bounds == pytest.approx((0.0, 2.5, 1.5, 4.0))
