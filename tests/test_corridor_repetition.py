"""A less repetitive corridor (long_corridor's clutter), amcl's two settings and the comparison of lesson 03."""
import numpy as np
import pytest

from robocourse.lessons.corridor_localization import experiment, repetition
from robocourse.lessons.corridor_localization.experiment import MAPPING_ALPHAS, corridor_lidar, mapping_grid
from robocourse.lessons.corridor_localization.trials import AMCL_SETTINGS, START_POSES, amcl_localizer, middle_line_drive
from robokit.mapping import OccupancyGrid
from robokit.sim import box_room, corridor_path, long_corridor


def _same_surfaces(a, b):
    return [s.name for s in a] == [s.name for s in b] and all(
        np.array_equal(s.texture, t.texture) and np.array_equal(np.r_[s.corner, s.u, s.v], np.r_[t.corner, t.u, t.v])
        for s, t in zip(a, b))


def test_clutter_adds_cabinets_and_changes_nothing_else():
    plain = long_corridor()
    assert plain.info["clutter"] == [] and not any(s.name.startswith("cabinet") for s in plain.surfaces)
    long_corridor.cache_clear()
    assert _same_surfaces(plain.surfaces, long_corridor(clutter=0.0).surfaces)
    full = long_corridor(clutter=1.0)
    rest = [s for s in full.surfaces if not s.name.startswith("cabinet")]
    assert _same_surfaces(plain.surfaces, rest)
    assert len(full.surfaces) - len(rest) == 5 * len(full.info["clutter"])      # four sides and a top each


def test_a_larger_share_keeps_the_cabinets_of_a_smaller_one():
    found = [set(long_corridor(clutter=s).info["clutter"]) for s in (0.0, 0.25, 0.5, 1.0)]
    assert all(small <= large for small, large in zip(found[:-1], found[1:]))
    assert len(found[1]) < len(found[3]) and len(found[3]) >= 14     # 18 stretches, a few too short


def test_cabinets_stand_against_the_walls_clear_of_the_doors_and_the_middle_line():
    world = long_corridor(clutter=1.0)
    L, W = world.info["length"], world.info["width"]
    for side, x0, x1, depth in world.info["clutter"]:
        assert 0.0 < x0 < x1 < L and 0.3 <= x1 - x0 <= 0.9 and 0.2 <= depth <= 0.45
        doors = [(d0, d1) for s, d0, d1 in world.info["doors"] if s == side]
        assert all(x1 + 0.2 <= d0 + 1e-9 or d1 + 0.2 <= x0 + 1e-9 for d0, d1 in doors)
        y_face = (W / 2 - depth) * (1 if side == "north" else -1)
        centre = [(x0 + x1) / 2, (W / 2 - depth / 2) * (1 if side == "north" else -1)]
        assert not world.is_free(np.array([centre])).all()                  # the cabinet is solid
        assert world.is_free(np.array([[(x0 + x1) / 2, y_face * 0.8]])).all()   # the corridor in front is not
    xs = np.linspace(1.0, L - 1.0, 200)
    assert world.is_free(np.column_stack([xs, np.zeros_like(xs)])).all()
    # the laser sees one: abreast of a cabinet mid-corridor, the nearest return comes from its face
    side, x0, x1, depth = next(c for c in world.info["clutter"] if 5.0 < c[1] < L - 5.0)
    pose = [(x0 + x1) / 2, 0.0, 0.0]
    nearest = [float(np.min(corridor_lidar().scan(w, pose, rng=0))) for w in (world, long_corridor())]
    assert nearest[0] == pytest.approx(W / 2 - depth, abs=0.05) and nearest[1] > W / 2 - 0.05


@pytest.mark.parametrize("bad", [-0.1, 1.5, np.nan, np.inf, "half", [0.5]])
def test_a_bad_clutter_share_is_named(bad):
    with pytest.raises((ValueError, TypeError), match="clutter"):
        long_corridor(clutter=bad)


def _box_grid():
    P = np.ones((40, 60))
    P[2:38, 2:58] = 0.0
    return OccupancyGrid.from_probability(P, 0.1)


def test_the_default_settings_are_table_2s_amcl_and_turtlebot2s_are_its_package():
    grid, lidar = _box_grid(), corridor_lidar()
    a = amcl_localizer(grid, None, lidar)
    assert (a.n_particles, a.kld.min_particles, a.kld.max_particles, a.kld.epsilon) == (500, 100, 500, 0.01)
    assert np.array_equal(a.alphas, MAPPING_ALPHAS) and a.model["max_beams"] == 30 and a.model["z_hit"] == 0.95
    assert (a.update_min_d, a.update_min_a, a.resample_interval) == (0.2, pytest.approx(np.pi / 6), 2)
    t = amcl_localizer(grid, None, lidar, "turtlebot2", 2000, rng=1)
    assert (t.n_particles, t.kld.min_particles, t.kld.max_particles, t.kld.epsilon) == (2000, 500, 2000, 0.05)
    assert (t.model["z_hit"], t.model["z_rand"], t.model["max_beams"]) == (0.5, 0.5, 60)
    assert (t.update_min_d, t.update_min_a, t.resample_interval) == (0.25, 0.2, 1)
    # turtlebot_navigation's amcl.launch.xml: odom_alpha1..4 = 0.2 in ROS's diff model, standard deviations
    # per squared motion; robokit's are variances per squared motion, matched at one update's 0.25 m and
    # 0.2 rad. The translation noise of one update, sqrt(alpha3) x 0.25 m, is then ROS's 0.2 x 0.25^2 m.
    ros, step, turn = 0.2, t.update_min_d, t.update_min_a
    assert np.allclose(t.alphas, [(ros * turn) ** 2, (ros * step) ** 2, (ros * step) ** 2, (ros * turn) ** 2])
    assert np.sqrt(t.alphas[2]) * step == pytest.approx(ros * step ** 2)
    # amcl's diff-corrected model reads the same 0.2 as variances, as robokit does: sqrt(0.2) x 0.25 m a step
    assert amcl_localizer(grid, None, lidar, "turtlebot2").n_particles == 2000       # the settings' max_particles
    c = amcl_localizer(grid, None, lidar, "turtlebot2-corrected", 2000)
    assert np.allclose(c.alphas, ros) and (c.n_particles, c.kld.min_particles, c.model["max_beams"]) == (2000, 500, 60)
    assert np.sqrt(c.alphas[2]) * step > 8 * np.sqrt(t.alphas[2]) * step
    assert set(AMCL_SETTINGS) == {"defaults", "turtlebot2", "turtlebot2-corrected"}


@pytest.mark.parametrize("kwargs, match", [({"settings": "ros"}, "settings"),
                                           ({"settings": "turtlebot2", "particles": 400}, "particles"),
                                           ({"particles": 50}, "particles")])
def test_amcl_localizer_names_a_bad_argument(kwargs, match):
    with pytest.raises(ValueError, match=match):
        amcl_localizer(_box_grid(), None, corridor_lidar(), **kwargs)
    with pytest.raises(TypeError, match="lidar"):
        amcl_localizer(_box_grid(), None, "rplidar")


def test_the_mapping_grid_names_a_bad_argument():
    world, lidar = long_corridor(), corridor_lidar()
    with pytest.raises(TypeError, match="world"):
        mapping_grid(box_room(), lidar, [[1.0, 1.0, 0.0]])
    with pytest.raises(ValueError, match="poses"):
        mapping_grid(world, lidar, [[1.0, 0.0]])
    with pytest.raises(ValueError, match="resolution"):
        mapping_grid(world, lidar, [[5.0, 0.0, 0.0]], resolution=5.0)


def test_the_clutter_map_holds_the_cabinets():
    world, grid = experiment.clutter_map(1.0)
    assert world is long_corridor(clutter=1.0)
    occupied = grid.occupied_mask()
    mapped = []
    for side, x0, x1, depth in world.info["clutter"]:
        face = (world.info["width"] / 2 - depth - 0.005) * (1 if side == "north" else -1)
        (ij, inside) = grid.cell_of(np.array([[(x0 + x1) / 2, face]]))       # the cells the laser hit at its face
        mapped.append(inside.all() and occupied[ij[0, 0] - 1:ij[0, 0] + 2, ij[0, 1]].any())
    # a face just short of a cell's far edge can stay free: the beams that cross the cell on their way
    # to the face further along outvote the few that end in it (15 of the 17 are mapped)
    assert len(mapped) == 17 and np.mean(mapped) >= 0.8
    plain = experiment.clutter_map(0.0)[1]
    assert occupied.sum() > plain.occupied_mask().sum()


def test_the_clutter_map_is_its_mapping_run_and_comes_back_from_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBOKIT_CACHE", str(tmp_path))
    world, grid = experiment.clutter_map(0.5, resolution=0.2)
    run = mapping_grid(world, corridor_lidar(), corridor_path(world, speed=0.3, rate=10.0).poses, 0.2)
    assert np.array_equal(grid.log_odds, run.log_odds) and np.array_equal(grid.origin, run.origin)
    assert len(list(tmp_path.rglob("grid-*.npz"))) == 1

    def no_second_run(*args, **kwargs):
        raise AssertionError("the mapping run was made again")

    monkeypatch.setattr(experiment, "mapping_grid", no_second_run)
    again = experiment.clutter_map(0.5, resolution=0.2)[1]
    assert np.array_equal(again.log_odds, grid.log_odds) and again.resolution == 0.2
    with pytest.raises(AssertionError, match="again"):                # another corridor is another run
        experiment.clutter_map(0.0, resolution=0.2)
    with pytest.raises(AssertionError, match="again"):                # and so is another cell size
        experiment.clutter_map(0.5, resolution=0.25)
    # the same cabinets (none) in a corridor with other doors: another run, not the cached grid
    monkeypatch.setattr(experiment, "mapping_grid", mapping_grid)
    experiment.clutter_map(0.0, resolution=0.2)
    monkeypatch.setattr(experiment, "mapping_grid", no_second_run)
    monkeypatch.setattr(experiment, "long_corridor", lambda clutter: long_corridor(layout="facing", clutter=clutter))
    with pytest.raises(AssertionError, match="again"):
        experiment.clutter_map(0.0, resolution=0.2)


def test_the_comparison_runs_the_same_drives_everywhere_and_comes_back_from_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBOKIT_CACHE", str(tmp_path))
    kw = dict(shares=[1.0], settings=["defaults", "turtlebot2"], runs=1, positions=range(10), length=1.5, seed=3,
              progress=None)
    out = repetition.clutter_comparison(**kw)
    assert list(out) == ["defaults", "turtlebot2"] and list(out["defaults"]) == [1.0]
    d, t = out["defaults"][1.0], out["turtlebot2"][1.0]
    assert d.errors.shape[0] == t.errors.shape[0] == 10                       # Table 2's ten start poses
    L = long_corridor().info["length"]
    for i, start in enumerate(START_POSES):                                   # both settings drive the same drives
        drive = middle_line_drive(start, L, 1.5)
        for runs in (d, t):
            seen = runs.truth[i][np.isfinite(runs.truth[i, :, 0])]
            assert len(seen) and np.abs(seen[:, None, :] - drive[None]).max(axis=2).min(axis=1).max() < 1e-9
    assert np.nanmax(t.particles) <= 2000 and np.nanmin(t.particles) >= 500
    assert np.nanmax(d.particles) <= 500
    again = repetition.clutter_comparison(**kw)
    assert all(np.array_equal(getattr(again[n][1.0], f), getattr(out[n][1.0], f), equal_nan=True)
               for n in out for f in ("estimates", "truth", "travelled", "particles"))
    assert len(list(tmp_path.rglob("clutter-*.npz"))) == 1


@pytest.mark.parametrize("kwargs, match", [({"shares": [1.5]}, "shares"), ({"shares": []}, "shares"),
                                           ({"settings": "defaults"}, "settings"), ({"settings": ["ros"]}, "settings"),
                                           ({"settings": []}, "settings"), ({"length": 200.0}, "length"),
                                           ({"runs": 0}, "runs"), ({"shares": [0.5, 0.5]}, "shares"),
                                           ({"positions": [10]}, "positions"), ({"positions": []}, "positions"),
                                           ({"positions": 3}, "positions")])
def test_the_comparison_names_a_bad_argument(kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        repetition.clutter_comparison(cache=False, **kwargs)
