"""Lesson 03's real-map experiment: routes through a map, the runs' records, the shipped map."""
import dataclasses
import hashlib
from importlib import resources

import numpy as np
import pytest

from robocourse.lessons.corridor_localization import real_map
from robocourse.lessons.corridor_localization.real_map import GlobalRuns, building_routes
from robocourse.lessons.corridor_localization.trials import middle_line_drive
from robokit.mapping import OccupancyGrid
from robokit.sim import Layout, waypoint_path


def _room(free_rows: slice, free_cols: slice, shape=(40, 60)) -> OccupancyGrid:
    P = np.ones(shape)
    P[free_rows, free_cols] = 0.0
    return OccupancyGrid.from_probability(P, 0.1)


def test_the_shipped_map_is_the_upstream_file():
    folder = resources.files("robocourse") / "data" / "maps"
    digest = hashlib.sha256((folder / "willow-full.pgm").read_bytes()).hexdigest()
    assert digest in (folder / "README.md").read_text()
    assert "BSD" in (folder / "README.md").read_text() and (folder / "LICENSE.willow").is_file()
    assert real_map.willow_map().shape == (526, 584)


def test_routes_keep_their_length_and_stay_in_free_space():
    grid = _room(slice(2, 38), slice(2, 58))                   # 3.6 m x 5.6 m free, walls around
    for route in building_routes(grid, 5, 3.0, rng=1, clearance=0.3):
        assert np.hypot(*np.diff(route, axis=0).T).sum() == pytest.approx(3.0)
        (ij, inside) = grid.cell_of(route)
        assert inside.all() and grid.free_mask()[ij[:, 0], ij[:, 1]].all()


def test_the_grid_edge_counts_as_a_wall():
    grid = _room(slice(0, 40), slice(0, 60))                    # all free: only the edge bounds it
    for route in building_routes(grid, 5, 2.0, rng=0, clearance=0.5):
        assert np.all((route >= 0.5 - 1e-9) & (route <= np.array([6.0, 4.0]) - 0.5 + 1e-9))


def test_routes_refuse_a_map_too_narrow_or_too_short():
    with pytest.raises(ValueError, match="clearance"):
        building_routes(_room(slice(18, 22), slice(2, 58)), 1, 2.0, clearance=0.3)   # a 0.4 m corridor
    with pytest.raises(ValueError, match="length"):
        building_routes(_room(slice(2, 38), slice(2, 58)), 1, 50.0, clearance=0.3)


def test_global_runs_of_unequal_length_are_judged_at_their_own_ends():
    truth = np.zeros((2, 4, 3))
    estimates = np.array([[[3.0, 0, 0], [0.1, 0, 0], [2.0, 0, 0], [0.2, 0, 0]],     # leaves and comes back
                          [[1.0, 0, 0], [0.1, 0, 0], [np.nan] * 3, [np.nan] * 3]])  # two updates only
    travelled = np.array([[0.0, 1.0, 2.0, 3.0], [0.0, 1.0, np.nan, np.nan]])
    runs = GlobalRuns(estimates, np.where(np.isnan(estimates), np.nan, truth), travelled, np.ones((2, 4)))
    assert runs.last().tolist() == [3, 1]
    assert runs.right_place().tolist() == [True, True]
    assert runs.localized_after().tolist() == [3.0, 1.0]
    with pytest.raises(ValueError, match="tolerance"):
        runs.right_place((-0.5, 0.1))


def test_a_batch_is_its_groups_run_one_by_one():
    """One pool for several maps and settings: each group's runs equal its own call, with or without
    workers beside them; a bad group is refused by its index."""
    section = real_map.willow_section()
    walls = Layout.from_cells(section.occupied_mask(), section.resolution, section.origin)
    drives = [waypoint_path(r, 0.3).poses for r in building_routes(section, 2, 1.5, rng=4)]
    groups = [dict(grid=section, walls=walls, drives=drives, particles=300),
              dict(grid=section, walls=walls, drives=drives[:1], particles=600, settings="turtlebot2", seed=2)]
    alone = [real_map.global_localization_runs(**g, workers=1) for g in groups]
    for workers in (1, 2):
        batch = real_map.global_localization_batch(groups, workers=workers)
        for one, other in zip(alone, batch):
            for a, b in zip(dataclasses.astuple(one), dataclasses.astuple(other)):
                assert np.array_equal(a, b, equal_nan=True)
    assert not np.array_equal(alone[0].errors[:1], alone[1].errors, equal_nan=True)   # the groups differ
    with pytest.raises(ValueError, match=r"groups\[1\]: particles"):
        real_map.global_localization_batch([groups[0], dict(groups[1], particles=10)])
    with pytest.raises(ValueError, match=r"groups\[0\].*unknown \['speed'\]"):
        real_map.global_localization_batch([dict(groups[0], speed=1.0)])
    with pytest.raises(ValueError, match=r"groups\[0\].*no \['walls'\]"):
        real_map.global_localization_batch([{k: v for k, v in groups[0].items() if k != "walls"}])
    with pytest.raises(ValueError, match=r"groups\[0\].*unknown \['speed', 1\]; no \['drives', 'grid', 'walls'\]"):
        real_map.global_localization_batch([{1: 0, "speed": 1.0}])
    with pytest.raises(TypeError, match=r"groups\[1\]: expected a dict"):
        real_map.global_localization_batch([groups[0], [section, walls, drives]])
    with pytest.raises(TypeError, match="groups: expected a list"):
        real_map.global_localization_batch(groups[0])
    with pytest.raises(ValueError, match=r"groups\[1\]: drives"):      # too short for one filter update
        real_map.global_localization_batch([groups[0], dict(groups[1], drives=[drives[0][:2] * 0.0])], workers=1)


def test_the_middle_line_drive_turns_before_the_ends():
    poses = middle_line_drive([30.0, 0.0, 0.0], 36.1, 20.0)
    assert poses[:, 0].max() == pytest.approx(35.3) and poses[:, 0].min() >= 0.8 - 1e-9
    travelled = np.hypot(*np.diff(poses[:, :2], axis=0).T).sum()
    assert travelled == pytest.approx(20.0, abs=0.03)
    for bad, match in (([35.8, 0.0, 0.0], "start"), ([0.5, 0.0, np.pi], "start")):
        with pytest.raises(ValueError, match=match):
            middle_line_drive(bad, 36.1, 5.0)
    with pytest.raises(ValueError, match="distance"):
        middle_line_drive([10.0, 0.0, 0.0], 36.1, 5000.0)


def test_table_2_judges_the_scan_matched_estimate_on_request():
    from robocourse.lessons.corridor_localization.trials import TrialSet
    error = np.array([[0.03, 0.02], [0.03, 0.001]])
    refined = np.array([[0.03, 0.001], [0.2, 0.001]])
    runs = TrialSet("ours", np.zeros(2, int), np.array([True, True]), np.array([1, 1]), np.ones(2), error,
                    error, refined, np.full(2, np.nan))
    assert runs.success().tolist() == [False, True]
    assert runs.success(refined=True).tolist() == [True, False]
    with pytest.raises(ValueError, match="settled, refined"):
        runs.success(settled=True, refined=True)
