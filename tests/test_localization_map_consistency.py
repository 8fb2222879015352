"""Landmark covariances checked against the simulator's surfaces (lab_experiment.map_consistency)."""
from types import SimpleNamespace

import numpy as np
import pytest

from robocourse.lessons.visual_slam.experiment import map_consistency
from robokit.sim import box_room

HEIGHT = 0.8


def _lab_to_paper(points):
    """Inverse of geometry.paper_world_to_robokit: (x, y, z) -> (X, Y, Z) = (x, z - h, y)."""
    p = np.asarray(points, float)
    return np.stack([p[:, 0], p[:, 2] - HEIGHT, p[:, 1]], axis=1)


def _map_on_surface(offsets, sigma_normal, sigma_other=0.5):
    """Landmarks on the middle of a bare wall of the box room, pushed ``offsets`` along its normal."""
    world = box_room()
    wall = next(s for s in world.surfaces if s.solid and abs(s.normal[2]) < 1e-9)
    rng = np.random.default_rng(3)
    ab = rng.uniform(0.3, 0.7, size=(len(offsets), 2))
    pts = wall.point(ab[:, 0], ab[:, 1]) + np.asarray(offsets)[:, None] * wall.normal
    # covariance: sigma_normal along the normal, sigma_other in the wall's plane (lab frame)
    basis = np.stack([wall.normal, wall.u / np.linalg.norm(wall.u), wall.v / np.linalg.norm(wall.v)], axis=1)
    cov_lab = basis @ np.diag([sigma_normal ** 2, sigma_other ** 2, sigma_other ** 2]) @ basis.T
    perm = np.array([[1.0, 0, 0], [0, 0, 1], [0, 1, 0]])
    cov_paper = np.repeat((perm @ cov_lab @ perm.T)[None], len(offsets), axis=0)
    lm = SimpleNamespace(positions=_lab_to_paper(pts), covariances=cov_paper,
                         observations=np.arange(1, len(offsets) + 1))
    return lm, world


def test_errors_and_sigmas_are_the_exact_normal_components():
    offsets = np.array([0.0, 0.01, -0.02, 0.005])
    lm, world = _map_on_surface(offsets, sigma_normal=0.01)
    mc = map_consistency(lm, world)
    assert mc.on_surface.all()
    np.testing.assert_allclose(mc.errors, offsets, atol=1e-12)
    np.testing.assert_allclose(mc.sigmas, 0.01, rtol=1e-12)   # the in-plane 0.5 m must not leak in
    np.testing.assert_allclose(mc.normalised_squared, (offsets / 0.01) ** 2, atol=1e-9)


def test_consistent_gaussian_map_reads_as_consistent():
    rng = np.random.default_rng(0)
    offsets = rng.normal(0.0, 0.004, size=4000)
    lm, world = _map_on_surface(offsets, sigma_normal=0.004)
    mc = map_consistency(lm, world)
    nsq = mc.normalised_squared
    assert 0.40 < np.median(nsq) < 0.50          # chi-square(1) median 0.455
    assert np.mean(nsq > 9) < 0.01               # 0.27 % expected beyond 3 sigma
    table = mc.table(groups=((1, 2000), (2001, None)))
    assert "2001+" in table and len(table.splitlines()) == 4


def test_overconfident_map_is_flagged():
    rng = np.random.default_rng(1)
    lm, world = _map_on_surface(rng.normal(0.0, 0.01, size=2000), sigma_normal=0.002)
    assert np.median(map_consistency(lm, world).normalised_squared) > 5


def test_landmark_beyond_every_surface_is_left_out():
    world = box_room()
    far = np.array([[100.0, 100.0, 50.0]])
    lm = SimpleNamespace(positions=_lab_to_paper(far), covariances=np.eye(3)[None] * 1e-4,
                         observations=np.array([1]))
    assert not map_consistency(lm, world).on_surface[0]


def test_bad_input_is_named():
    with pytest.raises(TypeError, match="landmark_map"):
        map_consistency(object())
    lm, world = _map_on_surface(np.zeros(2), 0.01)
    with pytest.raises(ValueError, match="margin"):
        map_consistency(lm, world, margin=-1.0)
