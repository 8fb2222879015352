"""Geo-tags of the hybrid map (Ge et al. 2023, Sec. 3.4, Eq. (18)): poses at keyframe times."""
from __future__ import annotations

import math

import numpy as np
import pytest

from robokit.mapping import geo_index, geo_tag
from robokit.mapping.hybrid_map import GeoIndex

T = [0.0, 1.0, 3.0]
P = [[0.0, 0.0, 0.0], [2.0, 1.0, math.pi - 0.1], [2.0, 5.0, -math.pi + 0.3]]


def test_interpolation_by_hand():
    got = geo_tag([0.25, 1.0, 2.5], T, P)
    # t = 0.25: a quarter of the way from pose 0 to 1; theta 0 -> pi - 0.1 the short way (+)
    # t = 2.5: three quarters from pose 1 to 2; theta pi - 0.1 -> -pi + 0.3 crosses +-pi (+0.4 rad)
    want = [[0.5, 0.25, 0.25 * (math.pi - 0.1)],
            [2.0, 1.0, math.pi - 0.1],
            [2.0, 4.0, math.pi - 0.1 + 0.75 * 0.4 - 2 * math.pi]]
    assert got == pytest.approx(np.array(want), abs=1e-12)


def test_log_times_give_the_logged_poses_and_the_ends_are_inside():
    got = geo_tag(T, T, P)
    assert got == pytest.approx(np.array(P), abs=1e-12)


def test_one_pose_log():
    assert geo_tag([2.0], [2.0], [[1.0, 2.0, 3.0]]).tolist() == [[1.0, 2.0, 3.0]]


def test_a_straight_run_at_constant_speed_is_exact():
    t = np.linspace(0.0, 10.0, 11)
    poses = np.column_stack([0.3 * t, 0 * t, 0 * t])
    tk = np.array([0.05, 3.3, 9.99])
    assert geo_tag(tk, t, poses)[:, 0] == pytest.approx(0.3 * tk)


@pytest.mark.parametrize("kf, pt, poses, match", [
    ([-0.1], T, P, "within the pose log"),
    ([3.5], T, P, "within the pose log"),
    ([1.0, 1.0], T, P, "keyframe_times: expected strictly increasing"),
    ([0.5], [0.0, 2.0, 1.0], P, "pose_times: expected strictly increasing"),
    ([np.nan], T, P, "keyframe_times"),
    ([0.5], T, [[0, 0, 0], [1, 1, np.nan], [0, 0, 0]], "poses"),
    ([0.5], T, P[:2], "poses: expected shape"),
    ([], T, P, "keyframe_times"),
])
def test_bad_input_is_named(kf, pt, poses, match):
    with pytest.raises(ValueError, match=match):
        geo_tag(kf, pt, poses)


def test_geo_index_records():
    tags = geo_index([4, 7], [0.5, 2.0], T, P)
    assert [g.keyframe_id for g in tags] == [4, 7] and isinstance(tags[0], GeoIndex)
    assert tags[0].pose == pytest.approx([1.0, 0.5, 0.5 * (math.pi - 0.1)])
    with pytest.raises(ValueError, match="distinct"):
        geo_index([4, 4], [0.5, 2.0], T, P)
    with pytest.raises(ValueError, match="keyframe_ids: expected 2"):
        geo_index([4], [0.5, 2.0], T, P)
