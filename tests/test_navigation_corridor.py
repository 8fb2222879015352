"""Lesson 03's experiments on the fast corridor map: the hybrid map, a run of each method, a kidnapping."""
from __future__ import annotations

import numpy as np
import pytest

from robocourse.lessons.corridor_localization import experiment, kidnapping as corridor_kidnapping, trials


@pytest.fixture(scope="module")
def setup():
    return experiment.corridor_map(fast=True)


def test_the_hybrid_map_geo_tags_every_keyframe_where_it_was_taken(setup):
    assert setup.n_keyframes == len(setup.database) > 20
    # the grid's pose log is the truth, so the Eq. (18) tags equal where the frames were rendered
    assert np.abs(setup.keyframe_poses - setup.keyframe_truth).max() < 1e-9
    assert np.all(np.diff(setup.keyframe_poses[:, 0]) > 0)
    walls = setup.grid.occupied_mask()
    _, inside = setup.grid.cell_of([[10.0, 0.0]])
    assert inside.all() and walls.any() and setup.grid.free_mask().sum() > walls.sum()


def test_the_hybrid_maps_grid_is_the_clutter_maps(setup):
    """One mapping run per corridor: AMCL's runs (clutter_map) localize in the hybrid map's own grid."""
    world, grid = experiment.clutter_map(0.0)
    assert world is setup.world
    assert np.array_equal(grid.log_odds, setup.grid.log_odds) and np.array_equal(grid.origin, setup.grid.origin)


def test_retrieval_finds_the_place_facing_the_way_the_map_was_recorded(setup):
    found = [trials.retrieve_pose(setup, [x, 0.0, 0.0], rng=2)[0] for x in (4.0, 9.0, 14.0, 19.0)]
    assert all(p is not None and abs(p[0] - x) < 0.5 for p, x in zip(found, (4.0, 9.0, 14.0, 19.0)))


def test_ours_starts_near_the_truth_and_converges_at_once(setup):
    run = trials.localization_trial(setup, trials.START_POSES[2], "ours", rng=3)
    assert run.converged and run.iterations <= 3
    assert run.retrieval_error < 0.5 and run.error[0] < 0.5 and run.error[1] < np.deg2rad(5)
    assert run.distance < 2.0               # the moving strategy and a few updates


def test_amcl_spreads_over_the_whole_map_and_moves_much_further(setup):
    run = trials.localization_trial(setup, trials.START_POSES[2], "amcl", rng=3, keep_particles=True)
    start = run.particles[0]
    assert len(start) == trials.PARTICLES["amcl"] and np.ptp(start[:, 0]) > 30.0
    assert not run.converged or run.distance > 2.0


def test_trial_sets_judge_on_the_paper_criterion(setup):
    runs = trials.localization_trials(setup, "ours", trials=1, positions=[0, 1], cache=False)
    assert runs.positions.tolist() == [0, 1] and runs.error.shape == (2, 2)
    loose = runs.success((10.0, np.pi))
    assert loose.tolist() == runs.converged.tolist()
    assert (runs.success() <= loose).all()


@pytest.mark.parametrize("confirm", [1, 2])
def test_kidnapping_ours_recovers_amcl_does_not(setup, confirm):
    kid = corridor_kidnapping.kidnapping(setup, origin=0, destination=2, after=14.0, confirm=confirm)
    assert kid.jump == pytest.approx(trials.START_POSES[2][0] - trials.START_POSES[0][0])
    recovered = min(t for t in kid.reinitialised if t >= 0)
    assert recovered < 5.0 * confirm                           # one retrieval period per confirmation
    late = kid.times > recovered + 1.0
    assert np.abs(kid.errors["amcl"][late]).min() > kid.jump - 1.0
    assert np.abs(kid.errors["ours"][late]).max() < 0.5
    assert abs(kid.final_error("ours")) < 0.5 < kid.jump - 1.0 < abs(kid.final_error("amcl"))


def test_one_wrong_retrieval_does_not_overrule_the_filter():
    vote = corridor_kidnapping.Confirmation(confirm=2, distance=1.0)
    # tracking at x = 5, 6.5, 8: one retrieval says x = 20 (a look-alike), the next agrees with the filter
    assert not vote.disagrees([20.0, 0, 0], [5.0, 0, 0], [0.0, 0, 0])
    assert not vote.disagrees([6.4, 0, 0], [6.5, 0, 0], [1.5, 0, 0])
    assert not vote.disagrees([21.0, 0, 0], [8.0, 0, 0], [3.0, 0, 0])      # a run of one again
    # two far retrievals that disagree with each other (20 then 30, 1.5 m of odometry apart): no
    assert not vote.disagrees([30.0, 0, 0], [9.5, 0, 0], [4.5, 0, 0])
    # ... but one that follows the last by the odometry confirms it
    assert vote.disagrees([31.4, 0.1, 0], [11.0, 0, 0], [6.0, 0, 0])
    printed = corridor_kidnapping.Confirmation(confirm=1, distance=1.0)
    assert printed.disagrees([20.0, 0, 0], [5.0, 0, 0], [0.0, 0, 0])        # the algorithm as printed


@pytest.mark.parametrize("bad, match", [(dict(method="both"), "method"), (dict(share=1.5), "share"),
                                        (dict(start=[50.0, 0.0, 0.0]), "start"), (dict(sigma_x=0.0), "sigma_x"),
                                        (dict(method="amcl", sigma_y=np.nan), "sigma_y"),
                                        (dict(method="amcl", amcl="turtlebot"), "amcl")])
def test_bad_trial_input_is_named(setup, bad, match, monkeypatch):
    def no_driving(*args, **kwargs):
        raise AssertionError("the robot moved before its arguments were checked")
    monkeypatch.setattr(trials, "move_to_middle_line", no_driving)
    kw = dict(start=trials.START_POSES[0], method="ours") | bad
    with pytest.raises((ValueError, TypeError), match=match):
        trials.localization_trial(setup, kw.pop("start"), kw.pop("method"), **kw)


def test_amcl_runs_with_the_named_settings_and_ours_keeps_its_own(setup):
    tb = trials.corridor_localizer(setup, "amcl", amcl="turtlebot2-corrected")
    assert (tb.n_particles, tb.kld.min_particles, tb.model["max_beams"]) == (2000, 500, 60)
    assert np.allclose(tb.alphas, 0.2)
    default = trials.corridor_localizer(setup, "amcl")
    assert (default.n_particles, default.kld.min_particles) == (trials.PARTICLES["amcl"], 100)
    ours = trials.corridor_localizer(setup, "ours", amcl="turtlebot2-corrected")
    assert ours.n_particles == trials.PARTICLES["ours"] and np.allclose(ours.alphas, experiment.MAPPING_ALPHAS)
    with pytest.raises(ValueError, match="amcl"):
        trials.corridor_localizer(setup, "amcl", amcl="ros")


def test_a_bad_amcl_setting_is_named_before_any_run(setup, monkeypatch):
    monkeypatch.setattr(trials, "map_runs", lambda *a, **k: pytest.fail("ran before the settings were checked"))
    monkeypatch.setattr(trials, "read_arrays", lambda *a, **k: pytest.fail("read the cache before the check"))
    with pytest.raises(ValueError, match="amcl"):
        trials.localization_trials(setup, "amcl", amcl="ros")


def test_each_amcl_setting_keeps_its_own_cached_runs(setup, tmp_path, monkeypatch):
    monkeypatch.setattr(trials, "cache_dir", lambda *parts: tmp_path)
    kw = dict(trials=1, positions=[0], max_distance=2.0, workers=1)
    default = trials.localization_trials(setup, "amcl", **kw)
    assert len(list(tmp_path.glob("trials-*.npz"))) == 2              # both methods, from one moving strategy
    turtlebot = trials.localization_trials(setup, "amcl", amcl="turtlebot2-corrected", **kw)
    assert len(list(tmp_path.glob("trials-*.npz"))) == 3              # ours was cached already
    assert turtlebot.iterations[0] != default.iterations[0]          # an update every 0.25 m, not 0.2 m
    monkeypatch.setattr(trials, "map_runs", lambda *a, **k: pytest.fail("ran again instead of reading the cache"))
    again = trials.localization_trials(setup, "amcl", amcl="turtlebot2-corrected", **kw)
    assert np.array_equal(again.iterations, turtlebot.iterations)
    assert np.array_equal(trials.localization_trials(setup, "amcl", **kw).iterations, default.iterations)


def test_a_bad_clutter_share_is_named_before_the_map_is_built(monkeypatch):
    monkeypatch.setattr(experiment, "calibration_run", lambda **kw: pytest.fail("built before the check"))
    with pytest.raises(ValueError, match="clutter"):
        experiment.corridor_map(fast=True, clutter=1.5)
    with pytest.raises(TypeError, match="clutter"):
        experiment.corridor_map(fast=True, clutter="some")


def test_keyframe_comparison_is_cached_and_a_stale_file_is_rebuilt(tmp_path, monkeypatch):
    run = experiment.calibration_run(fast=True)
    monkeypatch.setattr(experiment, "cache_dir", lambda *parts: tmp_path)
    first = experiment.keyframe_comparison(run, below_band="skip")
    (target,) = tmp_path.glob("keyframes-*.npz")
    again = experiment.keyframe_comparison(run, below_band="skip")
    assert all(np.array_equal(again[k], first[k]) for k in ("ours", "orbslam")) and again["images"] == first["images"]
    experiment.keyframe_comparison(run, below_band="take")
    (other,) = set(tmp_path.glob("keyframes-*.npz")) - {target}
    target.write_bytes(other.read_bytes())              # another parameter's result under this name
    assert np.array_equal(experiment.keyframe_comparison(run, below_band="skip")["ours"], first["ours"])
    target.write_bytes(b"broken")
    assert np.array_equal(experiment.keyframe_comparison(run, below_band="skip")["ours"], first["ours"])
