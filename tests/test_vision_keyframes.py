"""Keyframe selection (Ge et al. 2023, Sec. 3.2): Eq. (15), the shared fraction, conditions (1)-(4)
each in isolation on synthetic descriptor streams whose matches we control, and the ORB-SLAM rule."""
from __future__ import annotations

import numpy as np
import pytest

import robokit.sim as sim
from robokit.vision import (KeyframeSelector, detect_orb_features, feature_threshold, select_keyframes,
                            select_keyframes_orbslam, shared_fraction)

# 400 random 256-bit descriptors: any two differ in about 128 bits, far beyond the 50-bit match bound,
# so a frame's matches with the keyframe are exactly the rows they have in common.
POOL = np.random.default_rng(0).integers(0, 256, (400, 32), dtype=np.uint8)


def frame(n_shared, n_new=0, keyframe=POOL[:100], start=200):
    """A frame sharing ``n_shared`` of ``keyframe``'s rows plus ``n_new`` unrelated ones."""
    return np.concatenate([keyframe[:n_shared], POOL[start:start + n_new]])


def test_feature_threshold_eq15_by_hand():
    assert feature_threshold([400, 420, 380, 100]) == 162.5        # 0.5 * 325 > 100
    assert feature_threshold([300, 310]) == 300.0                  # the minimum wins
    with pytest.raises(ValueError, match="counts"):
        feature_threshold([])
    with pytest.raises(ValueError, match="counts"):
        feature_threshold([3, -1])


def test_shared_fraction_counts_the_keyframes_features():
    assert shared_fraction(frame(80, 50), POOL[:100]) == 0.8        # denominator: the keyframe's 100
    assert shared_fraction(frame(80), POOL[:100]) == 0.8
    assert shared_fraction(np.repeat(POOL[:10], 3, axis=0), POOL[:100]) == 0.1   # repeats count once
    assert shared_fraction(np.zeros((0, 32), np.uint8), POOL[:100]) == 0.0
    assert shared_fraction(POOL[:5], np.zeros((0, 32), np.uint8)) == 0.0


def run(selector, frames, positions):
    return [selector.offer(f, p) for f, p in zip(frames, positions)]


def test_first_frame_is_always_a_keyframe_even_without_features():
    sel = KeyframeSelector(50)
    assert sel.offer(np.zeros((0, 32), np.uint8), [0, 0]) and sel.indices == [0]
    sel.reset()
    assert sel.indices == [] and sel.offer(POOL[:100], [1, 0, 0])


def test_each_condition_in_isolation():
    base = dict(min_frame_gap=2, shared_range=(0.70, 0.90), min_distance=0.02)
    far = [[0.0, 0.0], [0.1, 0], [0.2, 0], [0.3, 0]]
    good = frame(80, 20)                                 # 100 features, 80 % shared
    # all four hold at frame 3 (gap 3 > 2): a keyframe
    assert run(KeyframeSelector(50, **base), [POOL[:100], good, good, good], far) == [True, False, False, True]
    # (1) too few features: the same frames against f_min = 101 (a frame has 100); 100 is enough
    assert run(KeyframeSelector(100, **base), [POOL[:100], good, good, good], far)[-1]
    sel = KeyframeSelector(101, **base)
    assert run(sel, [POOL[:100], good, good, good], far) == [True, False, False, False]
    assert sel.conditions == sel.conditions._replace(features=False, frames=True, shared=True, moved=True)
    # (2) not enough frames since the last keyframe
    sel = KeyframeSelector(50, **{**base, "min_frame_gap": 3})
    assert run(sel, [POOL[:100], good, good, good], far) == [True, False, False, False]
    assert (sel.conditions.frames, sel.conditions.frame_gap) == (False, 3)
    # (3) too similar (95 %) and too different (60 %): neither is a keyframe
    for shared in (95, 60):
        sel = KeyframeSelector(50, **base)
        f = frame(shared, 100 - shared)
        assert run(sel, [POOL[:100], f, f, f], far) == [True, False, False, False]
        assert not sel.conditions.shared and sel.conditions.fraction == shared / 100
    # (4) not moved 0.02 m
    sel = KeyframeSelector(50, **base)
    near = [[0.0, 0.0], [0.005, 0], [0.01, 0], [0.015, 0.0]]
    assert run(sel, [POOL[:100], good, good, good], near) == [True, False, False, False]
    assert not sel.conditions.moved and sel.conditions.distance == pytest.approx(0.015)


def test_select_keyframes_follows_the_last_keyframe():
    # keyframe 0 = POOL[0:100]; frames drift by 2 rows each; positions 1 cm apart
    frames = [POOL[2 * i:2 * i + 100] for i in range(40)]
    positions = np.c_[np.arange(40) * 0.01, np.zeros(40), np.zeros(40)]
    keys = select_keyframes(frames, positions, 50)
    # frame i shares 100 - 2 (i - k) rows with keyframe k; (2) needs i - k > 10 -> 11 (78 %): every 11
    assert keys.tolist() == [0, 11, 22, 33]
    orb = select_keyframes_orbslam(frames)
    # ORB-SLAM: > 20 frames and tracked < 90 (always, by then) and >= 50 points: every 21
    assert orb.tolist() == [0, 21]


def test_orbslam_rule_needs_fifty_tracked_points():
    frames = [POOL[:100]] + [frame(45, 55)] * 30
    assert select_keyframes_orbslam(frames).tolist() == [0]
    assert select_keyframes_orbslam(frames, min_tracked=40).tolist() == [0, 21]


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="positions"):
        select_keyframes([POOL[:10]] * 3, np.zeros((2, 2)), 5)
    with pytest.raises(ValueError, match="shared_range"):
        KeyframeSelector(5, shared_range=(0.9, 0.7))
    with pytest.raises(ValueError, match="position"):
        KeyframeSelector(5).offer(POOL[:10], [1.0])


def test_keyframes_on_a_rendered_corridor():
    """Real frames: 5 cm apart along the corridor; the shared fraction falls with distance."""
    world = sim.long_corridor()
    cam = sim.PinholeCamera.from_fov(np.deg2rad(65), 320, 240, mount=sim.camera_mount(0.5))
    xs = 4.0 + 0.05 * np.arange(12)
    desc = [detect_orb_features(cam.observe(world, [x, 0, 0]).image).descriptors for x in xs]
    fractions = [shared_fraction(d, desc[0]) for d in desc]
    assert fractions[0] == 1.0 and fractions[1] < 0.8 and fractions[-1] < fractions[1]
    f_min = feature_threshold([len(d) for d in desc])
    assert 150 < f_min < 500
    # with the paper's (0.70, 0.90) band no 5 cm step qualifies on our renderer (measured: about 0.57);
    # a wider band selects a keyframe after each gap of more than 2 frames
    assert select_keyframes(desc, np.c_[xs, 0 * xs], f_min, min_frame_gap=2).tolist() == [0]
    wide = select_keyframes(desc, np.c_[xs, 0 * xs], f_min, min_frame_gap=2, shared_range=(0.2, 0.9))
    assert wide.tolist() == [0, 3, 6, 9]


def test_below_band_take_never_stalls_where_skip_does():
    """A stream whose overlap with the last keyframe falls straight below the band's floor: the printed
    condition (3) takes no keyframe after the first; below_band="take" keeps taking them."""
    rng = np.random.default_rng(4)
    frames = [rng.integers(0, 256, (60, 32), dtype=np.uint8) for _ in range(12)]   # unrelated frames: 0 shared
    positions = np.c_[np.arange(12) * 0.1, np.zeros(12)]
    assert select_keyframes(frames, positions, 10, min_frame_gap=1).tolist() == [0]
    taken = select_keyframes(frames, positions, 10, min_frame_gap=1, below_band="take")
    assert taken.tolist() == [0, 2, 4, 6, 8, 10]
