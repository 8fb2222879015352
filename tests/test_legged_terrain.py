"""Rough terrain for lesson 04 (robokit.legged.terrain, the terrain-aware plan, the boards in MuJoCo,
and the lesson's terrain table)."""
import dataclasses

import mujoco
import numpy as np
import pytest

from robokit.geometry import DegenerateFitError
from robokit.legged import (FOOT_RADIUS, STANDING_HEIGHT, Terrain, TooFewMarkersError, crawl_gait, edge_distance,
                            height_at, littledog_mjcf, locate_terrain, simulate_mocap, simulate_walk, step_terrain,
                            terrain_transform, trot_gait, walking_plan)
from robocourse.lessons.littledog.experiment import LESSON_CRAWL, LESSON_TROT
from robocourse.lessons.littledog.terrain import terrain_table

BOARD = Terrain([[0.3, 0.5, -0.3, 0.3, 0.02], [0.4, 0.6, -0.3, 0.3, 0.03]],
                markers=[[0.3, -0.3, 0.02], [0.3, 0.3, 0.02], [0.6, -0.3, 0.03], [0.6, 0.3, 0.03]])


def test_height_at_known_boards_the_tallest_wins():
    xy = [[0.0, 0.0], [0.35, 0.1], [0.45, -0.2], [0.55, 0.0], [0.7, 0.0], [0.45, 0.31]]
    assert height_at(BOARD, xy).tolist() == [0.0, 0.02, 0.03, 0.03, 0.0, 0.0]
    assert height_at(BOARD, np.zeros((2, 3, 2))).shape == (2, 3)          # vectorised over any leading axes
    assert height_at(Terrain(), [[0.4, 0.0]]).tolist() == [0.0]


def test_height_at_follows_the_terrains_pose():
    moved = dataclasses.replace(BOARD, pose=(1.0, 2.0, np.pi / 2))       # board x now runs along world y
    assert height_at(moved, [[1.0, 2.35], [1.0, 2.45], [1.0 + 0.35, 2.0], [1.0, 2.0]]).tolist() == [0.02, 0.03, 0.0,
                                                                                                     0.0]


def test_edge_distance_inside_outside_and_rotated():
    board = Terrain([[0.3, 0.5, -0.3, 0.3, 0.02]])
    d = edge_distance(board, [[0.0, 0.0], [0.32, 0.0], [0.4, 0.0], [0.4, 0.29], [0.2, 0.4]])
    np.testing.assert_allclose(d, [0.3, 0.02, 0.1, 0.01, np.hypot(0.1, 0.1)], atol=1e-12)
    turned = dataclasses.replace(board, pose=(0.0, 0.0, 0.3))
    p = np.array([[0.4, 0.0], [0.0, 0.0]]) @ np.array([[np.cos(0.3), np.sin(0.3)], [-np.sin(0.3), np.cos(0.3)]])
    np.testing.assert_allclose(edge_distance(turned, p), [0.1, 0.3], atol=1e-12)
    assert np.isinf(edge_distance(Terrain(), [[0.0, 0.0]])).all()


def test_a_terrain_is_hashable_and_keeps_tuples():
    again = Terrain(np.array(BOARD.blocks), markers=np.array(BOARD.markers))
    assert again == BOARD and hash(again) == hash(BOARD)
    assert isinstance(again.blocks, tuple) and isinstance(again.blocks[0][0], float)
    assert dataclasses.replace(BOARD, pose=(0.1, 0.0, 0.0)) != BOARD


@pytest.mark.parametrize("kwargs, error, name", [
    ({"blocks": [[0.5, 0.3, -0.3, 0.3, 0.02]]}, ValueError, "blocks"),          # x_min > x_max
    ({"blocks": [[0.3, 0.5, -0.3, 0.3, 0.0]]}, ValueError, "blocks"),           # no height
    ({"blocks": [[0.3, 0.5, -0.3, 0.3]]}, ValueError, "blocks"),
    ({"blocks": [[0.3, 0.5, -0.3, 0.3, np.nan]]}, ValueError, "blocks"),
    ({"blocks": [[0.3, 1e3, -0.3, 0.3, 0.02]]}, ValueError, "blocks"),
    ({"markers": [[0.0, 0.0]]}, ValueError, "markers"),
    ({"pose": (0.0, 0.0)}, ValueError, "pose"),
    ({"pose": (0.0, 0.0, 1e300)}, ValueError, "pose"),
    ({"blocks": "boards"}, TypeError, "blocks"),
])
def test_a_bad_terrain_is_refused_by_name(kwargs, error, name):
    with pytest.raises(error, match=f"^{name}: "):
        Terrain(**kwargs)


def test_bad_inputs_of_the_terrain_functions_are_named():
    with pytest.raises(TypeError, match="^terrain: "):
        height_at("boards", [[0.0, 0.0]])
    with pytest.raises(ValueError, match="^xy: "):
        edge_distance(BOARD, [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="^heights: "):
        step_terrain(0, heights=(0.04, 0.01))
    with pytest.raises(ValueError, match="^terrain: "):
        locate_terrain(Terrain(BOARD.blocks, markers=BOARD.markers[:2]), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="^observed: "):
        locate_terrain(BOARD, np.zeros((3, 3)))
    with pytest.raises(TypeError, match="^terrain: "):
        walking_plan(crawl_gait(), 0.1, terrain="boards")
    with pytest.raises(ValueError, match="^clearance: "):
        walking_plan(crawl_gait(), 0.1, terrain=BOARD, clearance=-0.01)
    with pytest.raises(TypeError, match="^terrain: "):
        littledog_mjcf(terrain=[[0.3, 0.5, -0.3, 0.3, 0.02]])


def test_step_terrain_is_seeded_and_within_its_ranges():
    a, b = step_terrain(3), step_terrain(3)
    assert a == b and a != step_terrain(4)
    blocks = np.array(a.blocks)
    assert blocks[0, 0] == 0.3 and blocks[-1, 0] < 1.3
    assert np.all((blocks[:, 4] >= 0.01) & (blocks[:, 4] <= 0.04))
    assert np.all(blocks[1:, 0] - blocks[:-1, 1] >= 0.08)                # a floor gap between boards
    np.testing.assert_allclose(height_at(a, np.array(a.markers)[:, :2] + [[0.001, 0], [0.001, 0], [-0.001, 0],
                                                                          [-0.001, 0]]), np.array(a.markers)[:, 2])


def test_locate_terrain_recovers_the_pose_within_the_noise():
    truth = dataclasses.replace(BOARD, pose=(0.04, -0.03, 0.08))
    T = np.repeat(terrain_transform(truth)[None], 100, axis=0)
    frames = simulate_mocap(T, np.array(BOARD.markers), noise=0.0005, dropout=0.05, rng=1)
    located = locate_terrain(BOARD, frames.positions, frames.visible)
    assert np.hypot(*np.subtract(located.pose[:2], truth.pose[:2])) < 2e-4       # 100 frames of 0.5 mm noise
    assert abs(located.pose[2] - truth.pose[2]) < 1e-3
    assert located.blocks == BOARD.blocks
    one = locate_terrain(BOARD, frames.positions[0], np.ones(4, bool))           # a single frame works too
    assert np.hypot(*np.subtract(one.pose[:2], truth.pose[:2])) < 3e-3


def test_locate_terrain_needs_three_markers_off_a_line():
    seen = np.array(BOARD.markers)
    with pytest.raises(TooFewMarkersError):
        locate_terrain(BOARD, seen, [True, True, False, False])
    line = Terrain(BOARD.blocks, markers=[[0.3, 0.0, 0.0], [0.4, 0.0, 0.0], [0.5, 0.0, 0.0]])
    with pytest.raises(DegenerateFitError):
        locate_terrain(line, np.array(line.markers))


def test_the_mjcf_holds_the_boards_and_a_foot_rests_on_one():
    model = mujoco.MjModel.from_xml_string(littledog_mjcf(terrain=BOARD))
    assert model.geom("terrain1").size.tolist() == pytest.approx([0.1, 0.3, 0.015])
    assert model.geom("terrain1").pos.tolist() == pytest.approx([0.5, 0.0, 0.015])
    assert model.site("terrain_marker3").pos.tolist() == pytest.approx([0.6, 0.3, 0.03])
    assert "terrain" not in littledog_mjcf()
    # a 3 cm board under the whole robot: it stands on it, feet 3 cm up, and sinks through without it
    floor = Terrain([[-0.5, 0.5, -0.3, 0.3, 0.03]])
    plan = walking_plan(crawl_gait(), 0.02, terrain=floor)
    assert plan.T_world_body[0, 2, 3] == pytest.approx(STANDING_HEIGHT + 0.03)
    out = simulate_walk(plan, terrain=floor)
    down = out.log.contact
    assert not out.fell and down.mean() > 0.8
    np.testing.assert_allclose(out.log.feet[..., 2][down], 0.03 + FOOT_RADIUS, atol=0.003)
    assert out.log.meta["terrain"]["blocks"] == [list(b) for b in floor.blocks]
    sunk = simulate_walk(plan)
    assert sunk.log.feet[-1, :, 2].max() < FOOT_RADIUS + 0.003


@pytest.mark.parametrize("gait", ["crawl", "trot"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_plan_footholds_are_on_the_map_off_edges_and_swings_clear(gait, seed):
    terrain = step_terrain(seed)
    schedule = crawl_gait(**LESSON_CRAWL) if gait == "crawl" else trot_gait(**LESSON_TROT)
    plan = walking_plan(schedule, 1.0, terrain=terrain)
    flat = walking_plan(schedule, 1.0)
    feet, stance = plan.feet_world, plan.stance
    ground = height_at(terrain, feet[..., :2])
    np.testing.assert_allclose(feet[..., 2][stance], (ground + FOOT_RADIUS)[stance], atol=1e-12)
    footholds = np.unique(np.round(feet[stance][:, :2], 9), axis=0)
    flat_footholds = np.unique(np.round(flat.feet_world[flat.stance][:, :2], 9), axis=0)
    d, d_flat = edge_distance(terrain, footholds), edge_distance(terrain, flat_footholds)
    # the search (half a step inwards, 5 mm outwards) cannot always leave the 5 cm band around an
    # edge; then it takes the farthest point: at least 2 cm away for the crawl's 4.5 cm window,
    # 1.75 cm for the trot's 3.5 cm one
    assert d.min() >= {"crawl": 0.02, "trot": 0.0175}[gait] - 1e-9 and np.mean(d >= 0.025 - 1e-9) > 0.9
    assert d_flat.min() < 0.01 and np.mean(d_flat >= 0.025) < np.mean(d >= 0.025 - 1e-9)
    assert np.all(feet[..., 2] - FOOT_RADIUS >= ground - 1e-9)              # no foot below the surface, ever
    body_z = plan.T_world_body[:, 2, 3]
    # smooth: a 4 cm rise over a 0.2 s crawl swing, quintic, peaks at 1.875 x 2 mm per sample and
    # 5.77 x 0.04 / 0.2^2 m/s^2 (0.58 mm per sample^2); a jump would be the whole rise in one sample
    assert np.abs(np.diff(body_z)).max() < 0.005 and np.abs(np.diff(body_z, 2)).max() < 1e-3
    assert body_z.min() >= STANDING_HEIGHT - 1e-12


def test_the_terrain_plan_clears_a_riser_the_flat_plan_walks_into():
    riser = Terrain([[0.3, 1.0, -0.3, 0.3, 0.04]])
    schedule = crawl_gait(**LESSON_CRAWL)
    for plan, clears in ((walking_plan(schedule, 0.3, terrain=riser), True), (walking_plan(schedule, 0.3), False)):
        ground = height_at(riser, plan.feet_world[..., :2])
        assert bool(np.all(plan.feet_world[..., 2] - FOOT_RADIUS >= ground - 1e-9)) is clears


def test_without_terrain_the_lesson_plans_are_the_flat_ones_to_the_last_digit():
    # sums of the plans made before terrain existed (commit 86eb5ff): the lesson's numbers must not move
    for schedule, n, feet, body, squares, margin, stance in (
            (crawl_gait(**LESSON_CRAWL), 2931, 6258.783258349999, 1915.78896937776, 4829.489145846874,
             147.3229408333671, 10604),
            (trot_gait(**LESSON_TROT), 1001, 2108.238856471018, 640.4648333333402, 1608.8828668900314,
             8.079999999999998, 2204)):
        for plan in (walking_plan(schedule, 1.0), walking_plan(schedule, 1.0, terrain=None, clearance=0.05)):
            m = plan.margin[np.isfinite(plan.margin)]
            assert len(plan.t) == n and int(plan.stance.sum()) == stance
            assert float(plan.feet_world.sum()) == pytest.approx(feet, rel=1e-13, abs=0)
            assert float(plan.T_world_body[:, :3, 3].sum()) == pytest.approx(body, rel=1e-13, abs=0)
            assert float((plan.feet_world ** 2).sum()) == pytest.approx(squares, rel=1e-13, abs=0)
            assert float(m.sum()) == pytest.approx(margin, rel=1e-13, abs=0)


def test_terrain_table_rows_and_names(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBOKIT_CACHE", str(tmp_path))
    table = terrain_table(2, distance=0.1, gaits=("crawl",), modes=("blind", "mocap", "true"), workers=1)
    assert [r["mode"] for r in table["rows"]] == ["flat ground", "blind", "mocap", "true"]
    assert table["distance"].shape == (1, 3, 2) and table["walked"].all()
    assert all(0 <= r["success_rate"] <= 1 and r["falls"] <= r["trials"] for r in table["rows"])
    assert np.all(table["located_mm"] < 1.0)                           # Vicon-class noise, 100 frames
    again = terrain_table(2, distance=0.1, gaits=("crawl",), modes=("blind", "mocap", "true"), workers=1)
    np.testing.assert_array_equal(again["distance"], table["distance"])   # from the cache, the same
    for kwargs, error, name in (({"gaits": ("gallop",)}, ValueError, "gaits"), ({"modes": "blind"}, TypeError, "modes"),
                                ({"distance": 10.0}, ValueError, "distance"),
                                ({"heights": (0.0, 0.02)}, ValueError, "heights"), ({"trials": 0}, ValueError, "trials")):
        with pytest.raises(error, match=f"^{name}: "):
            terrain_table(**kwargs)


def test_terrain_table_reacting_modes_walk_under_a_reactive_host(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBOKIT_CACHE", str(tmp_path))
    table = terrain_table(1, distance=0.3, gaits=("crawl",), modes=("blind", "reacting"), workers=1)
    blind, reacting = table["tilt_deg"][0, :, 0]
    assert table["walked"].all() and blind != reacting            # same course and plan: only the host differs
