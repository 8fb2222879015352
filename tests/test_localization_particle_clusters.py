"""Clusters of a particle cloud (ROS amcl's pf_cluster_stats), against a brute-force labelling."""
from __future__ import annotations

import numpy as np
import pytest

from robokit.localization import largest_cluster_mean, largest_cluster_share, particle_clusters, pose_clusters
from robokit.localization.particle_filter import ROS_KLD_BIN_SIZE


def brute_force_clusters(particles, size):
    """Particles are joined when their cells differ by at most one in x, y and (cyclically) heading."""
    cells = np.floor(np.asarray(particles) / size).astype(int)
    n_heading = int(np.ceil(2 * np.pi / size[2]))
    cells[:, 2] %= n_heading
    parent = list(range(len(cells)))

    def find(i):
        while parent[i] != i:
            i = parent[i]
        return i

    for i in range(len(cells)):
        for j in range(i):
            dh = abs(cells[i, 2] - cells[j, 2])
            if abs(cells[i, 0] - cells[j, 0]) <= 1 and abs(cells[i, 1] - cells[j, 1]) <= 1 and \
                    min(dh, n_heading - dh) <= 1:
                parent[find(i)] = find(j)
    roots = [find(i) for i in range(len(cells))]
    first = {}
    return np.array([first.setdefault(r, len(first)) for r in roots])


@pytest.mark.parametrize("seed", range(6))
def test_labels_equal_a_brute_force_union_of_touching_cells(seed):
    rng = np.random.default_rng(seed)
    centres = rng.uniform([0, -1, -np.pi], [20, 1, np.pi], (4, 3))
    cloud = np.vstack([c + rng.normal(0, [0.4, 0.2, 0.15], (40, 3)) for c in centres])
    cloud[:, 2] = np.angle(np.exp(1j * cloud[:, 2]))
    got = pose_clusters(cloud)
    assert got.tolist() == brute_force_clusters(cloud, np.array(ROS_KLD_BIN_SIZE)).tolist()


def test_share_counts_particles_or_weights_and_one_cluster_is_one():
    line = np.column_stack([np.arange(0, 3, 0.3), np.zeros(10), np.zeros(10)])     # touching cells
    assert largest_cluster_share(line) == 1.0
    cloud = np.vstack([line, [[10.0, 0.0, 0.0]]])
    assert largest_cluster_share(cloud) == pytest.approx(10 / 11)
    weights = np.r_[np.full(10, 0.01), 0.9]
    assert largest_cluster_share(cloud, weights) == pytest.approx(0.9)


def test_a_gap_of_one_empty_cell_splits_and_heading_wraps():
    assert pose_clusters([[0.1, 0.1, 0.0], [1.1, 0.1, 0.0]]).tolist() == [0, 1]          # cells 0 and 2
    assert pose_clusters([[0.1, 0.1, np.pi - 0.01], [0.1, 0.1, -np.pi + 0.01]]).tolist() == [0, 0]


@pytest.mark.parametrize("bad", [np.zeros((0, 3)), [[0.0, np.nan, 0.0]], [[0.0, 0.0]]])
def test_bad_particles_raise(bad):
    with pytest.raises(ValueError, match="particles"):
        pose_clusters(bad)


def test_bad_weights_raise():
    with pytest.raises(ValueError, match="weights"):
        largest_cluster_share([[0.0, 0.0, 0.0]], [0.0])
    with pytest.raises(ValueError, match="weights"):
        largest_cluster_share([[0.0, 0.0, 0.0], [1.0, 0, 0]], [1.0])


def test_largest_cluster_mean_ignores_strays_and_follows_the_weight():
    rng = np.random.default_rng(5)
    main = np.column_stack([rng.normal(10.0, 0.1, 95), rng.normal(0.0, 0.05, 95), rng.normal(0.0, 0.02, 95)])
    strays = np.column_stack([rng.uniform(25, 30, 5), np.zeros(5), np.zeros(5)])
    cloud = np.vstack([main, strays])
    mean = largest_cluster_mean(cloud)
    assert np.allclose(mean[:2], main[:, :2].mean(axis=0), atol=1e-12)
    assert abs(cloud[:, 0].mean() - 10.0) > 0.5                 # the plain mean is pulled away
    heavy = np.r_[np.full(95, 1e-3), np.full(5, 1.0)]           # the strays carry the weight: pick them
    assert largest_cluster_mean(cloud, heavy)[0] > 20.0


@pytest.mark.parametrize("dense_cells", [0, None])      # only the occupied cells; a dense box (the default)
def test_pose_clusters_equal_the_all_pairs_reference(dense_cells, monkeypatch):
    if dense_cells is not None:
        monkeypatch.setattr(particle_clusters, "_DENSE_CELLS", dense_cells)
    rng = np.random.default_rng(11)
    for _ in range(80):
        n, m = int(rng.integers(1, 120)), int(rng.integers(1, 5))
        size = np.array([rng.choice([0.25, 0.5]), rng.choice([0.25, 0.5]),
                         rng.choice([np.deg2rad(10), 0.5, 1.0, 2.5, 4.0, 7.0])])     # 36 to 1 heading cells
        centres = np.c_[rng.uniform(-5, 5, m), rng.uniform(-2, 2, m), rng.uniform(-np.pi, np.pi, m)]
        P = centres[rng.integers(0, m, n)] + rng.normal(0.0, [0.4, 0.3, 0.6], (n, 3))
        edge = rng.random(n) < 0.3                       # some exactly on cell edges
        P[edge, :2] = np.round(P[edge, :2] / size[:2]) * size[:2]
        P[:, 2] = np.mod(P[:, 2] + np.pi, 2 * np.pi) - np.pi
        P[rng.random(n) < 0.1, 2] = -np.pi               # on the wrap
        assert np.array_equal(pose_clusters(P, size), brute_force_clusters(P, size))


def test_pose_clusters_refuse_clouds_too_far_for_their_cells():
    with pytest.raises(ValueError, match="particles"):
        pose_clusters([[0.0, 0.0, 0.0], [1e300, 0.0, 0.0]])
    with pytest.raises(ValueError, match="particles"):
        pose_clusters([[0.0, 0.0, 0.0], [2e11, 2e11, 0.0]])


def test_a_dense_box_only_where_the_cloud_fills_it(monkeypatch):
    rng = np.random.default_rng(3)
    spread = np.c_[rng.uniform(0, 36, 2000), rng.uniform(-1, 1, 2000), rng.uniform(-np.pi, np.pi, 2000)]
    converged = np.c_[rng.normal(10, 0.2, 200), rng.normal(0, 0.05, 200), rng.normal(0, 0.05, 200)]
    stray = np.vstack([converged, [[60.0, 50.0, 0.0]]])         # a nearly empty box of 121 x 100 x 36 cells
    expected = {name: pose_clusters(cloud) for name, cloud in (("spread", spread), ("stray", stray))}
    monkeypatch.setattr(particle_clusters, "_components_sparse", lambda *a: pytest.fail("searched sparsely"))
    assert np.array_equal(pose_clusters(spread), expected["spread"])
    monkeypatch.undo()
    monkeypatch.setattr(particle_clusters.ndimage, "label", lambda *a, **k: pytest.fail("labelled a dense box"))
    assert np.array_equal(pose_clusters(stray), expected["stray"]) and expected["stray"].max() == 1
