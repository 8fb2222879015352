"""Lesson 03's ORB checks on the rendered corridor (course/robocourse/lessons/corridor_localization/orb_realism.py).

The renderer-realism test compares our views with six real photographs (scikit-image's bundled ones
and matplotlib's grace_hopper, the set of benchmarks/bench_vision.py) under the same small motions:
it fails if a change to the corridor's textures or to the renderer makes ORB less (or more) repeatable
on our views than on real images.
"""
from __future__ import annotations

import numpy as np
import pytest

from benchmarks.bench_vision import photos
from robocourse.lessons.corridor_localization.experiment import N_FEATURES, corridor_camera
from robocourse.lessons.corridor_localization.orb_realism import MOTIONS, feature_counts, motion_shares, move_image
from robokit.sim import long_corridor
from robokit.vision import detect_orb_features, feature_threshold


def test_our_views_keep_as_many_orb_matches_as_real_photographs():
    real = motion_shares(photos())
    world, camera = long_corridor(), corridor_camera()
    views = {x: camera.observe(world, [x, 0.0, 0.0], rng=0).image for x in (3.0, 8.0, 14.0, 20.0, 26.0, 31.0)}
    ours = motion_shares(views)
    for motion in MOTIONS:
        r = [row[motion] for row in real.values()]
        mean = np.mean([row[motion] for row in ours.values()])
        assert min(r) <= mean <= max(r), (motion, mean, min(r), max(r))
    # the measure can tell images apart: a texture of fine independent noise keeps far fewer matches
    noise = (np.random.default_rng(0).random((480, 640)) * 255).astype(np.uint8)
    shaky = motion_shares({"noise": noise})["noise"]
    assert all(shaky[m] < min(row[m] for row in real.values()) - 0.1 for m in MOTIONS if m != "1 px")


def test_tracked_reading_our_views_are_no_less_repeatable_than_real_photographs():
    """Under ORB-SLAM-style tracking (the lesson's second reading) every view of ours keeps at least what
    the least repeatable photograph keeps, and none keeps 90 %: the band's ceiling is gone at once."""
    real = motion_shares(photos(), matching="tracked")
    world, camera = long_corridor(), corridor_camera()
    views = {x: camera.observe(world, [x, 0.0, 0.0], rng=0).image for x in (3.0, 14.0, 26.0)}
    ours = motion_shares(views, matching="tracked")
    for motion in MOTIONS:
        lowest = min(row[motion] for row in real.values())
        assert all(lowest <= row[motion] < 0.9 for row in ours.values()), motion
        assert max(row[motion] for row in real.values()) < 0.9, motion
    noise = (np.random.default_rng(0).random((480, 640)) * 255).astype(np.uint8)
    shaky = motion_shares({"noise": noise}, matching="tracked")["noise"]
    assert shaky["zoom 5 %"] < min(row["zoom 5 %"] for row in real.values()) - 0.1


def test_move_image_shifts_and_zooms_about_the_centre():
    rng = np.random.default_rng(1)
    img = (rng.random((40, 60)) * 255).astype(np.uint8)
    assert np.array_equal(move_image(img, 3.0, 2.0)[5:-5, 5:-5], np.roll(img, (2, 3), axis=(0, 1))[5:-5, 5:-5])
    spot = np.zeros((41, 61), np.uint8)
    spot[20, 30] = 255                                   # the centre stays put under a zoom
    assert move_image(spot, zoom=1.5)[20, 30] == 255
    spot[20, 40] = 255                                   # 10 px right of the centre moves to 15 px
    assert move_image(spot, zoom=1.5)[20, 45] == 255
    assert np.array_equal(move_image(img), img)
    assert np.array_equal(move_image(np.dstack([img] * 3)), img)


@pytest.mark.parametrize("kw, name", [({"shift_x": 51.0}, "shift_x"), ({"shift_y": -51.0}, "shift_y"),
                                      ({"shift_y": np.nan}, "shift_y"), ({"zoom": 0.4}, "zoom"),
                                      ({"zoom": "1.0"}, "zoom")])
def test_move_image_names_a_bad_motion(kw, name):
    with pytest.raises((ValueError, TypeError), match=f"^{name}:"):
        move_image(np.zeros((8, 8), np.uint8), **kw)


def test_motion_shares_are_one_for_no_motion_and_refuse_bad_input():
    img = corridor_camera().observe(long_corridor(), [10.0, 0.0, 0.0], rng=0).image
    assert motion_shares({"v": img}, {"none": (0.0, 0.0, 1.0)}) == {"v": {"none": 1.0}}
    with pytest.raises(TypeError, match="images"):
        motion_shares({})
    with pytest.raises(TypeError, match="motions"):
        motion_shares({"v": img}, [(0.0, 0.0, 1.0)])
    with pytest.raises(ValueError, match="motions\\['far'\\]"):
        motion_shares({"v": img}, {"far": (80.0, 0.0, 1.0)})
    with pytest.raises(ValueError, match="n_features"):
        motion_shares({"v": img}, n_features=0)
    with pytest.raises(ValueError, match="images\\['blank'\\].*none"):       # no features: no share to read
        motion_shares({"v": img, "blank": np.zeros((60, 80), np.uint8)})
    with pytest.raises((ValueError, TypeError), match="images\\['b'\\]"):
        motion_shares({"v": img, "b": None})
    with pytest.raises(ValueError, match="images"):
        motion_shares({1: img, "1": img})


def test_feature_counts_before_and_after_the_cap():
    counts = feature_counts(2.5, section=(10.0, 20.0))
    x = counts["x"]
    assert x[0] == 0.5 and x[-1] <= long_corridor().info["length"] - 0.5 and np.allclose(np.diff(x), 2.5)
    assert np.all(counts["capped"] <= N_FEATURES) and np.all(counts["capped"] <= counts["uncapped"])
    inside = (x >= 10.0) & (x <= 20.0)
    assert counts["f_min"] == feature_threshold(counts["uncapped"][inside])
    # the cap binds mid-corridor (thousands of corners), not at the end wall
    assert counts["uncapped"][inside].min() > 4 * N_FEATURES
    world, camera = long_corridor(), corridor_camera()
    k = int(np.argmin(np.abs(x - 15.5)))
    assert counts["uncapped"][k] == len(detect_orb_features(camera.observe(world, [15.5, 0.0, 0.0], rng=0).image,
                                                            1 << 20))
    for kw, name in (({"spacing": 0.05}, "spacing"), ({"spacing": np.inf}, "spacing"),
                     ({"spacing": 2.0, "section": (40.0, 50.0)}, "section"),
                     ({"spacing": 2.0, "section": (1.0,)}, "section")):
        with pytest.raises((ValueError, TypeError), match=name):
            feature_counts(**kw)
