"""The topological map (robokit.mapping.topological, topological_build, omni_views).

Independent references: hand-worked criterion values, synthetic frame sequences with a known
blocker, brute-force sorting and matching, ground-truth poses of a recorded run in office_floor().
"""
import numpy as np
import pytest

from robokit.geometry import se2_between, wrap_angle
from robokit.mapping import (LOOP_EDGE, EmptyMapError, PoseGraph, TopologicalMap, build_topological_map, optimize_pose_graph, relax)
from robokit.mapping.pose_graph import edge_variances
from robokit.mapping.topological import ODOMETRY_EDGE
from robokit.mapping.topological_build import Comparison, appearance_changed, local_map_full, select_key_frames
from robokit.sim import odometry_covariance
from robokit.vision import ImageSizeError, histogram_distance, ratio_match
from tests.office_runs import camera, office, room_of, short_map, short_map_and_log, short_run


# --- the criteria, one by one --------------------------------------------------------------------

def test_appearance_needs_both_a_far_histogram_and_few_matches():
    d = np.array([0.01, 0.2, 0.2, 0.01])
    m = np.array([10, 10, 200, 200])
    assert appearance_changed(d, m, similarity=0.1, min_matches=50).tolist() == [False, True, False, False]
    assert appearance_changed(0.1, 10, similarity=0.1, min_matches=50) is False          # strictly above
    assert appearance_changed(0.1001, 49, similarity=0.1, min_matches=50) is True


def test_local_map_limits_act_on_either_count_or_variance():
    out = local_map_full([10, 999, 1000, 10], [0.0, 0.0, 0.0, 0.2], max_features=1000, max_variance=0.2)
    assert out.tolist() == [False, False, True, True]


def sequence(far_frames, n=20, variance_step=0.0, features=300):
    """compare(key, k) for frames whose place is 'far' (another place) in ``far_frames``."""
    far = set(far_frames)

    def compare(key, k):
        changed = (k in far) != (key in far)
        return Comparison(0.5 if changed else 0.01, 5 if changed else 120, features, variance_step * (k - key))
    return compare


@pytest.mark.parametrize("blocked", [[5], [5, 6], [3, 4, 9, 10, 14]])
def test_a_transient_blocker_starts_no_node(blocked):
    keys, reasons = select_key_frames(20, sequence(blocked), occlusion_frames=3)
    assert keys == [0] and reasons == ["start"]


def test_a_lasting_change_starts_a_node_once_confirmed():
    keys, reasons = select_key_frames(20, sequence(range(8, 20)), occlusion_frames=3)
    assert keys == [0, 10] and reasons == ["start", "appearance"]             # 8, 9, 10: confirmed at 10
    # without the guard the blocker itself starts nodes (and the place after it another)
    keys, _ = select_key_frames(20, sequence([5]), occlusion_frames=1)
    assert keys == [0, 5, 6]


def test_limits_start_nodes_at_once_and_say_why():
    keys, reasons = select_key_frames(10, sequence([], variance_step=0.03), max_variance=0.1)
    assert keys == [0, 4, 8] and set(reasons[1:]) == {"variance"}
    keys, reasons = select_key_frames(5, sequence([], features=2000), max_features=1000)
    assert keys == [0, 1, 2, 3, 4] and set(reasons[1:]) == {"features"}


def test_select_key_frames_refuses_a_compare_that_returns_something_else():
    with pytest.raises(TypeError, match="compare"):
        select_key_frames(3, lambda key, k: (0.1, 5))
    with pytest.raises(ValueError, match="occlusion_frames"):
        select_key_frames(3, sequence([]), occlusion_frames=0)


# --- the map as data ------------------------------------------------------------------------------

def small_map(**change):
    rng = np.random.default_rng(0)
    arrays = dict(poses=[[0, 0, 0], [1, 0, 0], [2, 0, 0.5]], variances=[0.0, 0.01, 0.02],
                  histograms=rng.dirichlet(np.ones(8), 3), frames=[0, 4, 9], keypoints=rng.uniform(0, 100, (9, 4)),
                  bearings=rng.normal(size=(9, 3)), descriptors=rng.normal(size=(9, 128)).astype(np.float32),
                  offsets=[0, 3, 6, 9], edges=[[0, 1], [1, 2], [0, 2]],
                  measurements=[[1, 0, 0], [1, 0, 0.5], [2, 0, 0.5]], covariances=np.tile(np.eye(3) * 0.01, (3, 1, 1)),
                  kinds=[ODOMETRY_EDGE, ODOMETRY_EDGE, LOOP_EDGE])
    arrays.update(change)
    return TopologicalMap(**arrays)


def test_save_and_load_give_back_the_same_arrays(tmp_path):
    m = small_map()
    back = TopologicalMap.load(m.save(tmp_path / "map.npz"))
    for name, value in m.to_arrays().items():
        assert np.array_equal(value, getattr(back, name)), name
    assert back.descriptors.dtype == np.float32
    assert back.index == "opencv" and TopologicalMap.load(small_map(index="kdtree").save(tmp_path / "k.npz")).index == "kdtree"
    np.savez(tmp_path / "other.npz", poses=np.zeros((1, 3)))
    with pytest.raises(ValueError, match="path"):
        TopologicalMap.load(tmp_path / "other.npz")


def test_graph_and_with_poses():
    m = small_map()
    g = m.graph()
    assert isinstance(g, PoseGraph) and g.fixed == 0
    assert np.allclose(g.information, np.linalg.inv(m.covariances))
    assert np.allclose(edge_variances(g), 0.01)
    moved = m.with_poses(m.poses + [0.1, 0.0, 0.0])
    assert np.allclose(moved.poses[:, 0], [0.1, 1.1, 2.1]) and np.allclose(m.poses[:, 0], [0, 1, 2])
    assert moved.descriptors is m.descriptors
    with pytest.raises(ValueError, match="poses"):
        m.with_poses([[np.nan, 0, 0]] * 3)
    extra = m.with_edges(m.edges[:2], m.measurements[:2], m.covariances[:2], m.kinds[:2])
    assert extra.n_edges == 2 and m.n_edges == 3


def test_rank_by_histogram_is_a_sort_of_eq5_distances():
    m = small_map()
    h = np.random.default_rng(1).dirichlet(np.ones(8))
    order, d = m.rank_by_histogram(h)
    brute = sorted(range(3), key=lambda i: np.sqrt(((m.histograms[i] - h) ** 2).sum()))
    assert order.tolist() == brute and np.allclose(d, histogram_distance(h, m.histograms)[brute])
    order, _ = m.rank_by_histogram(h, exclude=[brute[0]])
    assert order.tolist() == brute[1:]


def test_match_counts_equal_ratio_matching_against_each_node():
    m = small_map()
    q = m.descriptors[[0, 4, 7, 8]] + 0.01
    counts, matches = m.match_counts(q, [0, 1, 2], ratio=0.7)
    for node, (c, mt) in enumerate(zip(counts, matches)):
        ref = ratio_match(q, m.descriptors[m.offsets[node]:m.offsets[node + 1]], ratio=0.7)
        assert c == len(ref) and mt.train.tolist() == ref.train.tolist()
    assert counts.tolist() == [1, 1, 2]


@pytest.mark.parametrize("change, error, match", [
    (dict(poses=np.zeros((0, 3))), EmptyMapError, "poses"),
    (dict(poses=[[0, 0, 0], [np.nan, 0, 0], [2, 0, 0]]), ValueError, "poses"),
    (dict(variances=[0.0, -1.0, 0.0]), ValueError, "variances"),
    (dict(offsets=[0, 3, 2, 9]), ValueError, "offsets"),
    (dict(edges=[[0, 1], [1, 1], [0, 2]]), ValueError, "edges"),
    (dict(edges=[[0, 1], [1, 3], [0, 2]]), ValueError, "edges"),
    (dict(covariances=np.tile(-np.eye(3), (3, 1, 1))), ValueError, "covariances"),
    (dict(kinds=[0, 1, 7]), ValueError, "kinds"),
    (dict(histograms=np.ones((2, 8))), ValueError, "histograms"),
    (dict(index="octree"), ValueError, "index"),
])
def test_bad_maps_are_refused_by_name(change, error, match):
    with pytest.raises(error, match=match):
        small_map(**change)


# --- built from a recorded run ----------------------------------------------------------------------

def test_map_of_a_short_run_has_nodes_in_every_visited_room_and_closes_its_loop():
    run = short_run()
    tmap, log = short_map_and_log()
    visited = set(room_of(run.poses[:, :2]))
    assert {"R1", "R4"} <= visited
    assert set(room_of(run.poses[tmap.frames, :2])) == visited == {"R1", "corridor", "R4"}
    assert tmap.frames[0] == 0 and np.all(np.diff(tmap.frames) > 0)
    assert np.allclose(tmap.poses, run.odometry[tmap.frames])
    odo = tmap.kinds == ODOMETRY_EDGE
    assert tmap.edges[odo].tolist() == [[i, i + 1] for i in range(len(tmap) - 1)]
    assert np.allclose(tmap.measurements[odo], se2_between(tmap.poses[:-1], tmap.poses[1:]))
    # edge covariances are the propagated odometry noise; node variances accumulate Eq. (1)
    a, b = tmap.frames[0], tmap.frames[1]
    assert np.allclose(tmap.covariances[0], odometry_covariance(run.odometry[a:b + 1], (0.01, 0.001, 0.01, 0.001))[-1],
                       atol=2e-6)
    assert np.all(np.diff(tmap.variances) > 0)
    # the lap of R1 brings the robot back to the start: a loop edge, measured by vision
    loops = np.flatnonzero(tmap.kinds == LOOP_EDGE)
    assert len(loops) >= 1 and any("loop closure" in line for line in log)
    for k in loops:
        j, i = tmap.edges[k]
        truth = se2_between(run.poses[tmap.frames[j]], run.poses[tmap.frames[i]])
        err = tmap.measurements[k] - truth
        assert np.hypot(err[0], err[1]) < 0.05 and abs(wrap_angle(err[2])) < 0.01, (j, i, err)


def test_relaxing_the_short_map_pulls_the_loop_together():
    run = short_run()
    tmap = short_map()
    k = int(np.flatnonzero(tmap.kinds == LOOP_EDGE)[0])
    j, i = tmap.edges[k]
    for result in (relax(tmap.graph()), optimize_pose_graph(tmap.graph())):
        aligned = tmap.with_poses(result.poses)
        before = np.hypot(*(se2_between(tmap.poses[j], tmap.poses[i]) - tmap.measurements[k])[:2])
        after = np.hypot(*(se2_between(aligned.poses[j], aligned.poses[i]) - tmap.measurements[k])[:2])
        assert after < before
        assert np.all(np.isfinite(aligned.poses))
    # least squares brings the nodes of the loop nearer the truth than odometry had them
    last = int(tmap.edges[tmap.kinds == LOOP_EDGE].max()) + 1
    truth = run.poses[tmap.frames[:last], :2]
    odo = np.linalg.norm(tmap.poses[:last, :2] - truth, axis=1).mean()
    ls = np.linalg.norm(optimize_pose_graph(tmap.graph()).poses[:last, :2] - truth, axis=1).mean()
    assert ls < odo


def test_build_refuses_empty_runs_wrong_sizes_and_bad_odometry():
    run = short_run()
    with pytest.raises(EmptyMapError, match="images"):
        build_topological_map(np.zeros((0, 480, 640, 3), np.uint8), np.zeros((0, 3)), camera())
    with pytest.raises(ImageSizeError, match="images"):
        build_topological_map(run.images["omni"][:2, :240], run.odometry[:2], camera())
    with pytest.raises(ValueError, match="odometry"):
        build_topological_map(run.images["omni"][:2], run.odometry[:3], camera())
    with pytest.raises(ValueError, match="odometry"):
        build_topological_map(run.images["omni"][:2], [[0, 0, 0], [np.nan, 0, 0]], camera())
    with pytest.raises(TypeError, match="camera"):
        build_topological_map(run.images["omni"][:2], run.odometry[:2], "omni")


def test_a_map_built_from_images_as_they_arrive_is_the_map_of_the_array():
    import dataclasses
    run = short_run()
    images, odometry = run.images["omni"][:24], run.odometry[:24]
    whole = build_topological_map(images, odometry, camera(), loop_exclude=2)
    arriving = build_topological_map(iter(list(images)), odometry, camera(), loop_exclude=2)
    assert len(whole) >= 2
    for field in dataclasses.fields(whole):
        a, b = getattr(whole, field.name), getattr(arriving, field.name)
        if isinstance(a, np.ndarray):
            assert np.array_equal(a, b), field.name


def test_images_that_arrive_must_be_one_per_pose_and_the_camera_s_size():
    run = short_run()
    images, odometry = list(run.images["omni"][:3]), run.odometry[:3]
    with pytest.raises(ValueError, match="images: expected 3 images .* ended after 2"):
        build_topological_map(iter(images[:2]), odometry, camera())
    with pytest.raises(ValueError, match="images: expected 3 images .* has more"):
        build_topological_map(iter(images + images[:1]), odometry, camera())
    with pytest.raises(ImageSizeError, match=r"images\[1\]"):
        build_topological_map(iter([images[0], images[1][:240], images[2]]), odometry, camera())
    with pytest.raises(EmptyMapError, match="odometry"):
        build_topological_map(iter([]), np.zeros((0, 3)), camera())


def test_every_argument_is_checked_before_an_image_is_taken():
    def never():
        raise AssertionError("an image was taken")
        yield
    odometry = short_run().odometry[:3]
    for change, error, match in [({"camera": "omni"}, TypeError, "camera"), ({"index": "octree"}, ValueError, "index"),
                                 ({"sigma_visual": (0.1, 0.0, 0.1)}, ValueError, "sigma_visual"),
                                 ({"loop_top_k": 0}, ValueError, "loop_top_k"), ({"bins": 0}, ValueError, "bins"),
                                 ({"similarity": -1.0}, ValueError, "similarity"),
                                 ({"odometry": [[0.0, 0.0]]}, ValueError, "odometry")]:
        args = {"images": never(), "odometry": odometry, "camera": camera(), **change}
        with pytest.raises(error, match=match):
            build_topological_map(**args)
    from robokit.sim import record_stream
    with pytest.raises(TypeError, match=r"\.frames"):
        build_topological_map(record_stream(office(), short_run().poses[:2], camera()), odometry[:2], camera())


def test_frames_similar_in_colour_skip_sift_and_the_feature_count():
    """A transient blocker's features never fill the local map (they only count while it looks alike)."""
    calls = []

    def compare(key, k):
        calls.append(k)
        return Comparison(0.01, None, None, 0.0) if k < 5 else Comparison(0.5, 5, 2000, 0.0)
    # frames 5.. look different: their features are not the local map's, so the occlusion guard decides
    keys, reasons = select_key_frames(8, compare, occlusion_frames=2, max_features=1000)
    assert keys == [0, 6] and reasons == ["start", "appearance"]

    def same_colours(key, k):   # the histogram hardly moves, but the features are new: the count binds
        return Comparison(0.01, None, None, 0.0) if k < 5 else Comparison(0.01, 5, 2000, 0.0)
    keys, reasons = select_key_frames(8, same_colours, occlusion_frames=2, max_features=1000)
    assert keys == [0, 5, 6, 7] and reasons[1:] == ["features"] * 3
    keys, reasons = select_key_frames(8, same_colours, occlusion_frames=2, max_features=10 ** 6)
    assert keys == [0] and reasons == ["start"]


def test_rank_by_histogram_refuses_nodes_that_do_not_exist_and_wrong_bin_counts():
    tmap = short_map()
    h = tmap.histograms[0]
    order, _ = tmap.rank_by_histogram(h, exclude=[0])
    assert 0 not in order and len(order) == len(tmap) - 1
    for bad in ([-1], [len(tmap)], np.ones(len(tmap) + 1, bool)):
        with pytest.raises(ValueError, match="exclude"):
            tmap.rank_by_histogram(h, exclude=bad)
    with pytest.raises(ValueError, match="histogram"):
        tmap.rank_by_histogram(h[:5])
