"""The Monte-Carlo check of hierarchical localization (robokit.localization.appearance_mcl).

References: the true poses of rendered office views; a look-alike node planted 3 m from its place.
"""
import numpy as np
import pytest

from robokit.geometry import se2_compose
from robokit.localization import HierarchicalLocalizer
from robokit.localization.appearance_mcl import monte_carlo_check, place_hypotheses
from robokit.mapping import TopologicalMap
from robokit.sim import noisy_odometry
from tests.office_runs import camera, office, true_node_map


def _with_look_alike(tmap, node, shift):
    """The map with ``node`` moved ``shift`` metres in x (a look-alike place the coarse order puts
    first) and its true place appended as a new node with the same images."""
    a, b = tmap.offsets[node], tmap.offsets[node + 1]
    poses = tmap.poses.copy()
    poses[node] += [shift, 0.0, 0.0]
    return TopologicalMap(**{**tmap.to_arrays(),
                             "poses": np.vstack([poses, tmap.poses[node]]),
                             "variances": np.r_[tmap.variances, tmap.variances[node]],
                             "histograms": np.vstack([tmap.histograms, tmap.histograms[node]]),
                             "frames": np.r_[tmap.frames, tmap.frames[node]],
                             "keypoints": np.vstack([tmap.keypoints, tmap.keypoints[a:b]]),
                             "bearings": np.vstack([tmap.bearings, tmap.bearings[a:b]]),
                             "descriptors": np.vstack([tmap.descriptors, tmap.descriptors[a:b]]),
                             "offsets": np.r_[tmap.offsets, tmap.offsets[-1] + b - a]})


def _drive(start, towards, steps=4, step=0.25):
    """``start``, then ``steps`` poses ``step`` metres apart heading for the point ``towards``."""
    d = np.asarray(towards, float) - start[:2]
    heading = np.arctan2(d[1], d[0])
    s = np.arange(1, steps + 1)[:, None] * step
    return np.vstack([start, np.column_stack([start[:2] + s * [np.cos(heading), np.sin(heading)],
                                              np.full(steps, heading)])])


@pytest.mark.parametrize("node, steps, step, towards", [(1, 4, 0.25, 1), (3, 6, 0.3, 2), (5, 4, 0.25, 1)])
def test_a_drive_overturns_a_look_alike_answer(node, steps, step, towards):
    tmap = true_node_map()
    twin = _with_look_alike(tmap, node, 3.0)
    start = se2_compose(tmap.poses[node], [0.1, 0.0, 0.0])
    truth = _drive(start, tmap.poses[node + towards, :2], steps, step)
    assert office().is_free(truth[:, :2], clearance=0.2).all(), truth     # the drive stays in free space
    images = [camera().observe(office(), p, rng=k).image for k, p in enumerate(truth)]
    loc = HierarchicalLocalizer(twin, camera())
    first = loc.localize(images[0])
    assert first.node == node and np.hypot(*(first.pose - start)[:2]) > 2.5      # fooled by the look-alike
    nodes, poses, counts, metric = place_hypotheses(loc, images[0])
    assert nodes[0] == node and len(tmap) in nodes.tolist()
    odometry = noisy_odometry(truth, (0.005, 0.0005, 0.005, 0.0005), rng=1)
    check = monte_carlo_check(loc, images[0], images[1:], odometry, rng=2)
    assert not check.confirmed and check.nodes[check.winner] == len(tmap)
    assert np.hypot(*(check.pose - start)[:2]) < 0.15
    assert check.support[check.winner] > 0.8 and check.support.sum() == pytest.approx(1.0)


def test_a_drive_confirms_a_right_answer():
    tmap = true_node_map()
    start = se2_compose(tmap.poses[3], [0.1, 0.0, 0.0])
    truth = _drive(start, tmap.poses[4, :2], 4, 0.25)
    images = [camera().observe(office(), p, rng=k).image for k, p in enumerate(truth)]
    loc = HierarchicalLocalizer(tmap, camera())
    odometry = noisy_odometry(truth, (0.005, 0.0005, 0.005, 0.0005), rng=1)
    check = monte_carlo_check(loc, images[0], images[1:], odometry, rng=2)
    assert check.confirmed and check.winner == 0 and check.support[0] > 0.8
    assert np.hypot(*(check.pose - start)[:2]) < 0.15


def test_without_evidence_the_answer_stands():
    # drive images that show nothing (black): no metric fix, so the particles' start split decides nothing
    tmap = true_node_map()
    twin = _with_look_alike(tmap, 3, 3.0)
    start = se2_compose(tmap.poses[3], [0.1, 0.0, 0.0])
    truth = _drive(start, tmap.poses[5, :2], 3, 0.3)
    first = camera().observe(office(), truth[0]).image
    blank = [np.zeros_like(first) for _ in truth[1:]]
    odometry = noisy_odometry(truth, (0.005, 0.0005, 0.005, 0.0005), rng=1)
    loc = HierarchicalLocalizer(twin, camera())
    check = monte_carlo_check(loc, first, np.stack(blank), odometry, rng=2)     # a stack of images is accepted
    assert check.confirmed and check.winner == 0
    assert np.array_equal(check.pose, loc.localize(first).pose)


def test_bad_input_is_named():
    tmap = true_node_map()
    loc = HierarchicalLocalizer(tmap, camera())
    image = camera().observe(office(), tmap.poses[1]).image
    with pytest.raises(TypeError, match="localizer"):
        monte_carlo_check("loc", image, [image], np.zeros((2, 3)))
    with pytest.raises(ValueError, match="drive_images"):
        monte_carlo_check(loc, image, [], np.zeros((1, 3)))
    with pytest.raises(ValueError, match="drive_odometry"):
        monte_carlo_check(loc, image, [image], np.zeros((3, 3)))
    with pytest.raises(ValueError, match="drive_images"):
        monte_carlo_check(loc, image, [image[:10]], np.zeros((2, 3)))
    with pytest.raises(ValueError, match="sigma"):
        monte_carlo_check(loc, image, [image], np.zeros((2, 3)), sigma=0.0)
    with pytest.raises(ValueError, match="drive_odometry"):
        monte_carlo_check(loc, image, [image], np.full((2, 3), np.nan))
    with pytest.raises(ValueError, match="max_hypotheses"):
        place_hypotheses(loc, image, max_hypotheses=0)
