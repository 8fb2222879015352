"""Hierarchical localization (robokit.localization.hierarchical) and the relative pose of two views.

References: ground-truth poses of rendered views of office_floor(); brute-force ranking.
"""
import numpy as np
import pytest

from robokit.geometry import se2_between, se2_compose, wrap_angle
from robokit.localization import HierarchicalLocalizer
from robokit.mapping import EmptyMapError, TopologicalMap, omni_view, relative_pose
from robokit.vision import DescriptorIndex, ImageSizeError
from tests.office_runs import camera, office, short_map, short_run, true_node_map

#: Metric error bound for a query 0.2 m from a node. Measured: 1-4 cm on the eleven office test
#: poses (0.2-1 m from their node) and about 1 cm here; floor points 1-2.7 m away carry 2-5 cm of
#: range error per pixel of feature position, and the translation averages a handful of them.
METRIC_BOUND = 0.1
HEADING_BOUND = 0.02          # rad; the essential matrix's heading is good to about 0.005 rad


def query_near(node: int, offset=(0.2, 0.0), turn=0.3, seed=0):
    truth = true_node_map().poses[node]
    pose = se2_compose(truth, [offset[0], offset[1], turn])
    return pose, camera().observe(office(), pose, rng=seed).image


@pytest.mark.parametrize("node", [0, 2, 5])
def test_a_query_near_a_node_is_recognised_with_a_metric_pose(node):
    tmap = true_node_map()
    pose, image = query_near(node)
    result = HierarchicalLocalizer(tmap, camera()).localize(image)
    assert result.recognised and result.verified and result.metric
    nearest = int(np.argmin(np.linalg.norm(tmap.poses[:, :2] - pose[:2], axis=1)))
    assert result.node == nearest == node or np.linalg.norm(tmap.poses[result.node, :2] - pose[:2]) < 1.0
    err = result.pose - pose
    assert np.hypot(err[0], err[1]) < METRIC_BOUND and abs(wrap_angle(err[2])) < HEADING_BOUND, err
    # reporting the node's pose alone errs by the node spacing (here 0.2 m and 0.3 rad)
    node_only = result.node_pose - pose
    assert np.hypot(node_only[0], node_only[1]) > 0.15


def test_far_from_every_node_the_directions_from_two_nodes_cross_at_the_robot():
    # 1.36 m from the nearest node: too far for floor matches, but two nodes see the way to it
    tmap = true_node_map()
    pose = np.array([11.6, 2.0, 2.5])
    result = HierarchicalLocalizer(tmap, camera()).localize(camera().observe(office(), pose).image)
    assert result.method == "bearings" and result.verified and result.metric
    assert np.hypot(*(result.pose - pose)[:2]) < 0.3          # measured 0.11 m (0.05-0.34 m on the tour)
    assert abs(wrap_angle(result.pose[2] - pose[2])) < HEADING_BOUND
    assert np.linalg.norm(tmap.poses[:, :2] - pose[:2], axis=1).min() > 1.3


def test_relative_pose_of_rendered_views_matches_the_known_transform():
    cam = camera()
    node_pose = np.array([13.5, 3.6, np.pi])
    node = omni_view(cam.observe(office(), node_pose).image, cam)
    for offset in ([0.2, 0.0, 0.3], [-0.3, 0.25, -0.5], [0.5, -0.2, 1.0]):
        pose = se2_compose(node_pose, offset)
        query = omni_view(cam.observe(office(), pose).image, cam)
        matches = DescriptorIndex(node.features.descriptors).match(query.features.descriptors, ratio=0.7)
        rel = relative_pose(query, node, matches, cam)
        truth = se2_between(node_pose, pose)
        assert rel.verified and rel.metric, (offset, rel)
        assert np.hypot(*(rel.pose[:2] - truth[:2])) < METRIC_BOUND
        assert abs(wrap_angle(rel.pose[2] - truth[2])) < HEADING_BOUND
        assert abs(wrap_angle(rel.heading_epipolar - truth[2])) < HEADING_BOUND
        assert rel.n_floor >= 3 and rel.n_epipolar >= 12


def test_modes_coarse_fine_hierarchical():
    tmap = true_node_map()
    pose, image = query_near(3, offset=(0.1, -0.1))
    results = {mode: HierarchicalLocalizer(tmap, camera(), mode=mode, top_k=2).localize(image)
               for mode in ("coarse", "fine", "hierarchical")}
    coarse, fine, hier = results["coarse"], results["fine"], results["hierarchical"]
    # coarse: every node ranked by Eq. (5), the nearest histogram's node answered with its pose
    h = omni_view(image, camera(), features=False).histogram
    brute = np.argsort(np.sqrt(((tmap.histograms - h) ** 2).sum(1)), kind="stable")
    assert coarse.candidates.tolist() == brute.tolist() and coarse.node == brute[0]
    assert np.array_equal(coarse.pose, tmap.poses[coarse.node]) and coarse.relative is None
    assert coarse.times["sift"] < 0.005 and coarse.times["matching"] == 0.0     # no SIFT extracted
    # fine: every node matched; hierarchical: only the coarse top 2
    assert len(fine.candidates) == len(tmap) and sorted(hier.candidates.tolist()) == sorted(brute[:2].tolist())
    assert fine.match_counts.max() == hier.match_counts.max()
    assert fine.node == hier.node
    for r in results.values():
        assert set(r.times) == {"histogram", "sift", "coarse", "matching", "verification", "total"}
        assert all(v >= 0 for v in r.times.values())
        assert r.times["total"] == pytest.approx(sum(v for k, v in r.times.items() if k != "total"))


def test_two_identical_nodes_are_ambiguous_and_verification_still_answers():
    tmap = true_node_map()
    twice = TopologicalMap(**{**tmap.to_arrays(),
                              "poses": np.vstack([tmap.poses, tmap.poses[2]]),
                              "variances": np.r_[tmap.variances, tmap.variances[2]],
                              "histograms": np.vstack([tmap.histograms, tmap.histograms[2]]),
                              "frames": np.r_[tmap.frames, tmap.frames[2]],
                              "keypoints": np.vstack([tmap.keypoints, tmap.keypoints[tmap.offsets[2]:tmap.offsets[3]]]),
                              "bearings": np.vstack([tmap.bearings, tmap.bearings[tmap.offsets[2]:tmap.offsets[3]]]),
                              "descriptors": np.vstack([tmap.descriptors,
                                                        tmap.descriptors[tmap.offsets[2]:tmap.offsets[3]]]),
                              "offsets": np.r_[tmap.offsets, tmap.offsets[-1] + tmap.offsets[3] - tmap.offsets[2]]})
    pose, image = query_near(2)
    result = HierarchicalLocalizer(twice, camera()).localize(image)
    assert result.ambiguous and result.verified and result.node in (2, len(tmap))
    assert np.hypot(*(result.pose - pose)[:2]) < METRIC_BOUND


def test_a_place_not_in_the_map_is_not_recognised():
    tmap = true_node_map()
    image = camera().observe(office(), [3.0, 10.0 + 0.7, 0.0]).image          # R3, never visited
    result = HierarchicalLocalizer(tmap, camera(), min_matches=40).localize(image)
    assert not result.recognised and not result.verified and result.relative is None
    assert np.array_equal(result.pose, result.node_pose)


def test_bad_input_is_named():
    tmap = short_map()
    loc = HierarchicalLocalizer(tmap, camera())
    with pytest.raises(ImageSizeError, match="image"):
        loc.localize(np.zeros((240, 320, 3), np.uint8))
    with pytest.raises(ValueError, match="image"):
        loc.localize(np.full((480, 640, 3), np.nan))
    with pytest.raises(TypeError, match="map"):
        HierarchicalLocalizer("map", camera())
    with pytest.raises(TypeError, match="camera"):
        HierarchicalLocalizer(tmap, "camera")
    with pytest.raises(ValueError, match="mode"):
        HierarchicalLocalizer(tmap, camera(), mode="medium")
    with pytest.raises(ValueError, match="top_k"):
        HierarchicalLocalizer(tmap, camera(), top_k=0)
    with pytest.raises(EmptyMapError, match="poses"):
        TopologicalMap(**{**tmap.to_arrays(), "poses": np.zeros((0, 3))})
    with pytest.raises(TypeError, match="view"):
        loc.localize_view(np.zeros(3))
    assert short_run().images["omni"].shape[1:] == (480, 640, 3)


def test_the_pose_is_always_the_node_pose_composed_with_the_relative_pose():
    tmap = true_node_map()
    loc = HierarchicalLocalizer(tmap, camera())
    for pose in ([11.6, 2.0, 2.5], [14.1, 1.0, 2.0]):                     # a crossing and a floor fix
        r = loc.localize(camera().observe(office(), pose).image)
        assert np.allclose(se2_compose(r.node_pose, r.relative.pose), r.pose)


def test_a_view_given_its_histogram_equals_the_view_computed_whole():
    # the map builder adds SIFT to a histogram-only view without computing the histogram again
    image = camera().observe(office(), [3.0, 2.0, 0.4]).image
    whole = omni_view(image, camera(), n_features=200)
    coarse = omni_view(image, camera(), n_features=200, features=False)
    added = omni_view(image, camera(), n_features=200, histogram=coarse.histogram)
    assert np.array_equal(added.histogram, whole.histogram) and np.array_equal(coarse.histogram, whole.histogram)
    assert np.array_equal(added.features.descriptors, whole.features.descriptors)
    assert np.array_equal(added.bearings, whole.bearings) and len(added) > 20
    given = np.full(32, 1 / 32)
    np.testing.assert_array_equal(omni_view(image, camera(), features=False, histogram=given).histogram, given)
    for bad, match in ((np.full(16, 1 / 16), "histogram"), (-given, "histogram"), (np.full(32, np.nan), "histogram")):
        with pytest.raises(ValueError, match=match):
            omni_view(image, camera(), histogram=bad)


def test_an_unverified_top_k_widens_to_the_right_node():
    # node 3's histogram is replaced by one all in the bin the query has least of, so the coarse stage
    # ranks node 3 last: the plain top-2 search cannot find it, the coarse-to-fine check goes on down
    # the ranking until it does
    tmap = true_node_map()
    pose, image = query_near(3, offset=(0.1, -0.1))
    h = omni_view(image, camera(), features=False).histogram
    hist = tmap.histograms.copy()
    hist[3] = np.eye(len(h))[int(np.argmin(h))]
    swapped = TopologicalMap(**{**tmap.to_arrays(), "histograms": hist})
    plain = HierarchicalLocalizer(swapped, camera(), top_k=2, max_rounds=1).localize(image)
    checked = HierarchicalLocalizer(swapped, camera(), top_k=2).localize(image)
    assert 3 not in plain.candidates.tolist() and plain.rounds == 1
    assert checked.node == 3 and checked.rounds > 1 and checked.metric
    assert len(checked.candidates) == 2 * checked.rounds or len(checked.candidates) == len(tmap)
    assert np.hypot(*(checked.pose - pose)[:2]) < METRIC_BOUND
    # the check stops at the first batch with a verified metric pose: a good first batch costs nothing
    fine = HierarchicalLocalizer(tmap, camera(), top_k=2).localize(image)
    assert fine.rounds == 1 and len(fine.candidates) == 2
    with pytest.raises(ValueError, match="max_rounds"):
        HierarchicalLocalizer(tmap, camera(), max_rounds=0)
