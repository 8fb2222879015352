"""Monte-Carlo localization (lesson 03): resampling, KLD, Eq. (19), the likelihood field, MCL convergence."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from robokit.localization import (KLDConfig, MonteCarloLocalizer, ellipse_weights, kld_resample, likelihood_field_log_weight_readable, likelihood_field_log_weights, low_variance_resample, mcl_step, normalise_log_weights, sample_ellipse_poses, weighted_pose_mean)
from robokit.localization.beam_models import subsample_beams
from robokit.localization.particle_filter import KLD_Z_99, kld_sample_count, pose_bins
from robokit.mapping import OccupancyGrid, likelihood_field
from robokit.sim import Lidar, lab_lap, lab_room, noisy_odometry


# --- a non-symmetric map: the lab of lesson 01 (desks, cabinets, a rotated table, crates) ------------
def lab_grid(world, res: float = 0.1) -> OccupancyGrid:
    """The lab's footprint at the LiDAR's height, rasterised: walls and furniture occupied, the room free."""
    lay = world.layout(Lidar().height)
    xs = np.arange(-0.2, 10.2, res) + res / 2
    X, Y = np.meshgrid(xs, xs)
    centres = np.column_stack([X.ravel(), Y.ravel()])
    occupied = (lay.clearance(centres) < 0.75 * res) | lay.contains(centres)
    free = world.is_free(centres, clearance=0.0) & ~occupied
    P = np.full(len(centres), 0.5)                                # unknown outside the room
    P[free], P[occupied] = 0.0, 1.0
    return OccupancyGrid.from_probability(P.reshape(X.shape), res, (-0.2, -0.2))


@pytest.fixture(scope="module")
def lab():
    world = lab_room()
    return world, lab_grid(world)


# --- resampling ------------------------------------------------------------------------------------
def table_4_4(weights, r):
    """Thrun et al. Table 4.4 as printed, with the random number given."""
    M = len(weights)
    out, c, i = [], weights[0], 0
    for m in range(M):
        U = r + m / M
        while U > c:
            i += 1
            c += weights[i]
        out.append(i)
    return out


def test_low_variance_matches_table_4_4_loop():
    w = np.random.default_rng(5).random(40)
    w /= w.sum()
    for seed in range(20):
        r = np.random.default_rng(seed).uniform(0.0, 1.0 / len(w))   # the sampler's one random number
        assert low_variance_resample(w, seed).tolist() == table_4_4(w, r)


def test_low_variance_unbiased_and_counts_are_floor_or_ceil():
    rng = np.random.default_rng(0)
    w = rng.random(7) ** 3
    w /= w.sum()
    N, R = len(w), 4000
    counts = np.array([np.bincount(low_variance_resample(w, rng), minlength=N) for _ in range(R)])
    # every draw gives each particle floor(N w) or ceil(N w) copies ...
    assert np.all((counts == np.floor(N * w)) | (counts == np.ceil(N * w)))
    # ... so each count lies in an interval of width 1 and, by Hoeffding, the mean over R draws is
    # within t = sqrt(ln(2 / delta) / (2 R)) of its expectation N w with probability 1 - delta
    t = math.sqrt(math.log(2 / 1e-9) / (2 * R))
    assert np.all(np.abs(counts.mean(axis=0) - N * w) < t)


def test_low_variance_has_lower_variance_than_multinomial():
    rng = np.random.default_rng(1)
    w = rng.random(50)
    w /= w.sum()
    N, R = len(w), 2000
    lv = np.array([np.bincount(low_variance_resample(w, rng), minlength=N) for _ in range(R)])
    mn = rng.multinomial(N, w, size=R)
    assert np.all(lv.var(axis=0) <= 0.25 + 1e-12)          # floor/ceil: at most a Bernoulli's variance
    assert lv.var(axis=0).sum() < 0.5 * mn.var(axis=0).sum()
    assert abs(mn.var(axis=0).sum() - (N * w * (1 - w)).sum()) < 0.1 * (N * w * (1 - w)).sum()


def test_low_variance_refuses_zero_weights():
    with pytest.raises(ValueError, match="weights"):
        low_variance_resample([0.0, 0.0])


# --- KLD-sampling ----------------------------------------------------------------------------------
def test_kld_count_hand_value_and_formula():
    # k = 2, epsilon = 0.01, z = 2.3263: (1/0.02) (1 - 2/9 + sqrt(2/9) z)^3 = 50 * 1.87443^3 = 329.28
    assert kld_sample_count(2) == 330
    assert kld_sample_count(1) == 0
    for k in (2, 3, 10, 57, 500):
        for eps, z in ((0.01, KLD_Z_99), (0.05, 0.99), (0.2, 3.0)):
            x = 1 - 2 / (9 * (k - 1)) + math.sqrt(2 / (9 * (k - 1))) * z
            assert kld_sample_count(k, epsilon=eps, z=z) == math.ceil((k - 1) / (2 * eps) * x ** 3)
    ks = np.arange(1, 60)
    assert kld_sample_count(ks).tolist() == [kld_sample_count(int(k)) for k in ks]


def test_kld_count_approximates_the_chi_square_quantile():
    for k in (10, 100, 1000):                   # Fox (2003): n = chi2_{k-1, 1-delta} / (2 epsilon)
        exact = chi2.ppf(0.99, k - 1) / (2 * 0.01)
        assert abs(kld_sample_count(k) - exact) < 0.01 * exact


def test_kld_resample_stops_where_table_8_4_stops():
    rng = np.random.default_rng(2)
    P = np.column_stack([rng.uniform(0, 2, 3000), rng.uniform(0, 2, 3000), rng.uniform(-0.5, 0.5, 3000)])
    w = rng.random(3000)
    out = kld_resample(P, w, rng=3, min_count=50, max_count=4000, epsilon=0.05, z=0.99)
    keys = pose_bins(out)
    k_at = np.array([len({tuple(b) for b in keys[:m]}) for m in range(1, len(out) + 1)])   # Table 8.4's k
    need = kld_sample_count(k_at, epsilon=0.05, z=0.99)
    m = np.arange(1, len(out) + 1)
    ok = (m >= need) & (m >= 50)
    assert ok[-1] and not ok[:-1].any()                      # the first M that satisfies the bound
    # a concentrated cloud needs far fewer particles than a spread one
    tight = kld_resample(np.tile([1.0, 1.0, 0.0], (100, 1)), np.ones(100), rng=0, min_count=20, max_count=4000)
    assert len(tight) == 20 and len(out) > 500
    # a cloud too spread for the bound stops at max_count
    assert len(kld_resample(P * [3, 3, 6], w, rng=3, min_count=50, max_count=700)) == 700


@pytest.mark.parametrize("shift", [-1.0, -1e3, -1e17])     # bins on both sides of zero; too far for one integer
def test_kld_resample_stops_where_table_8_4_stops_for_any_place(shift):
    rng = np.random.default_rng(2)
    P = np.column_stack([rng.uniform(0, 2, 3000), rng.uniform(0, 2, 3000), rng.uniform(-0.5, 0.5, 3000)])
    P[:1000, 0] += shift                                     # a third of the cloud far away along x
    out = kld_resample(P, rng.random(3000), rng=3, min_count=50, max_count=4000, epsilon=0.05, z=0.99)
    keys = pose_bins(out)
    k_at = np.array([len({tuple(b) for b in keys[:m]}) for m in range(1, len(out) + 1)])   # Table 8.4's k
    m = np.arange(1, len(out) + 1)
    ok = (m >= kld_sample_count(k_at, epsilon=0.05, z=0.99)) & (m >= 50)
    assert ok[-1] and not ok[:-1].any() and len(out) < 4000  # stopped by the bound, not by max_count


def test_pose_bins_refuse_a_pose_whose_bin_is_no_int64():
    with pytest.raises(ValueError, match="particles"):
        pose_bins([[0.0, 0.0, 0.0], [3e18, 0.0, 0.0]])                  # 6e18 bins of 0.5 m
    with pytest.raises(ValueError, match="particles"):
        kld_resample([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]], [1.0, 1.0], bin_size=[0.5, 0.5, 1e-19])
    assert pose_bins([[2.0 ** 60, 0.0, 0.0]], [1.0, 1.0, 1.0])[0, 0] == 2 ** 60


@pytest.mark.parametrize("far", [2.0 ** 40, 2.0 ** 61])  # 2**62 x 8 bins in the box: past 2**64
def test_kld_resample_counts_bins_however_far_apart(far):
    rng = np.random.default_rng(6)
    P = np.column_stack([rng.choice([-far, 0.0, far], 300), rng.choice([0.2, 3.7], 300), np.zeros(300)])
    out = kld_resample(P, np.ones(300), rng=2, min_count=2, max_count=5000, epsilon=0.2, bin_size=[1.0, 0.5, 0.17])
    keys = pose_bins(out, [1.0, 0.5, 0.17])                  # six bins: three places, two rows 8 bins apart
    k_at = np.array([len({tuple(b) for b in keys[:m]}) for m in range(1, len(out) + 1)])
    m = np.arange(1, len(out) + 1)
    ok = (m >= kld_sample_count(k_at, epsilon=0.2)) & (m >= 2)
    assert ok[-1] and not ok[:-1].any() and k_at[-1] == 6


# --- normalisation and the estimate ----------------------------------------------------------------
def test_normalise_recovers_from_all_zero_weights_without_nan():
    out = normalise_log_weights(np.full(5, -np.inf))
    assert out.degenerate and out.weights.tolist() == [0.2] * 5
    big = normalise_log_weights([-1e6, -1e6 - math.log(3.0)])           # would underflow as plain exp
    assert np.allclose(big.weights, [0.75, 0.25]) and not big.degenerate
    with pytest.raises(ValueError, match="log_w"):
        normalise_log_weights([0.0, np.nan])


def test_weighted_pose_mean_is_circular():
    P = [[0.0, 1.0, np.pi - 0.1], [2.0, 3.0, -np.pi + 0.1]]
    # sum w sin = -0.5 sin(0.1), sum w cos = -cos(0.1): just past -pi, not the arithmetic mean near -1.6
    assert np.allclose(weighted_pose_mean(P, [1, 3]), [1.5, 2.5, -np.pi + math.atan(0.5 * math.tan(0.1))])


# --- Ge et al. (2023), Eq. (19) --------------------------------------------------------------------
def test_eq19_weights_by_hand():
    P = np.array([[1.0, 0.0, 0.0], [0.0, 0.5, 0.0], [1.0, 2.0, 0.3]])
    sx, sy = 0.5, 0.25
    hand = [math.exp(-(dx ** 2 / (2 * sx ** 2) + dy ** 2 / (2 * sy ** 2))) / (2 * math.pi * sx * sy)
            for dx, dy in ((0.0, -1.0), (-1.0, -0.5), (0.0, 1.0))]
    w = ellipse_weights(P, [1.0, 1.0, 0.0], sx, sy, normalise=False)
    assert np.allclose(w, hand)
    assert np.allclose(ellipse_weights(P, [1.0, 1.0, 0.0], sx, sy), np.array(hand) / sum(hand))
    # the ellipse turns with the keyframe's heading: at theta = pi/2, x is across and y along
    assert np.allclose(ellipse_weights(P, [1.0, 1.0, np.pi / 2], sy, sx, normalise=False), hand)


def test_ellipse_samples_are_uniform_inside():
    P = sample_ellipse_poses([3.0, -1.0, np.pi / 2], 0.4, 0.1, n=4000, nsigma=2.0, sigma_theta=0.02, rng=0)
    along, across = P[:, 1] + 1.0, -(P[:, 0] - 3.0)          # heading pi/2: along is +y
    q = (along / 0.8) ** 2 + (across / 0.2) ** 2
    assert q.max() <= 1.0
    inner = np.mean(q <= 0.25)                               # half the semi-axes: a quarter of the area
    assert abs(inner - 0.25) < 4 * math.sqrt(0.25 * 0.75 / 4000)
    assert abs(np.std(P[:, 2] - np.pi / 2) - 0.02) < 0.002


# --- the likelihood field --------------------------------------------------------------------------
@pytest.mark.parametrize("combine", ["product", "ros"])
def test_likelihood_field_vectorised_equals_reference(lab, combine):
    world, grid = lab
    field = likelihood_field(grid)
    lidar = Lidar(noise=0.02)
    ranges = lidar.scan(world, [5.0, 2.0, 0.3], rng=0)
    ranges[[3, 50]] = np.inf
    ranges[7] = 20.0                                         # beyond r_max: skipped like inf
    rng = np.random.default_rng(4)
    P = np.column_stack([rng.uniform(-1, 11, 40), rng.uniform(-1, 11, 40), rng.uniform(-np.pi, np.pi, 40)])
    kw = dict(sensor_offset=(0.1, -0.05, 0.2), max_beams=45, combine=combine, sigma_hit=0.15)
    fast = likelihood_field_log_weights(P, ranges, lidar.angles, field, **kw)
    slow = [likelihood_field_log_weight_readable(p, ranges, lidar.angles, field, **kw) for p in P]
    assert np.allclose(fast, slow, rtol=1e-12, atol=1e-12)
    assert len(subsample_beams(360, 45)) == 45


def test_likelihood_field_scores_the_true_pose_best(lab):
    world, grid = lab
    field = likelihood_field(grid)
    lidar = Lidar()
    true = np.array([5.0, 2.0, 0.3])
    scan = lidar.scan(world, true)
    near = true + [[0, 0, 0], [0.3, 0, 0], [0, -0.3, 0], [0, 0, 0.2]]
    lw = likelihood_field_log_weights(near, scan, lidar.angles, field, max_beams=60)
    assert lw.argmax() == 0


def test_scan_with_nan_raises_and_all_max_range_is_uninformative(lab):
    _, grid = lab
    field = likelihood_field(grid)
    with pytest.raises(ValueError, match="ranges"):
        likelihood_field_log_weights(np.zeros((2, 3)), [1.0, np.nan], [0.0, 1.0], field)
    assert likelihood_field_log_weights(np.zeros((2, 3)), [np.inf, 9.0], [0.0, 1.0], field).tolist() == [0.0, 0.0]


def test_zero_weights_everywhere_recover_without_nan(lab):
    world, grid = lab
    lidar = Lidar()
    # no random term and a tiny sigma: every beam that misses an obstacle by a cell has likelihood 0
    mcl = MonteCarloLocalizer(grid, n_particles=100, combine="product", z_rand=0.0, sigma_hit=0.001, rng=0,
                              resample_interval=1)
    mcl.initialize_gaussian([5.0, 5.0, 0.0], np.diag([0.01, 0.01, 0.01]))
    scan = lidar.scan(world, [5.0, 2.0, 0.3])
    mcl.update([0.0, 0.0, 0.0], scan)
    assert mcl.update([0.5, 0.0, 0.0], scan)
    assert mcl.degenerate and np.all(np.isfinite(mcl.weights)) and np.isclose(mcl.weights.sum(), 1.0)
    step = mcl_step(mcl.particles, mcl.weights, [0, 0, 0], [0.3, 0, 0], scan, lidar.angles, mcl.field,
                    combine="product", z_rand=0.0, sigma_hit=0.001, rng=0)
    assert step.degenerate and np.all(np.isfinite(step.particles)) and step.log_evidence == -np.inf


# --- the filter ------------------------------------------------------------------------------------
def test_update_schedule_follows_ros(lab):
    _, grid = lab
    mcl = MonteCarloLocalizer(grid, n_particles=50, rng=0)
    scan = np.full(360, np.inf)
    assert not mcl.update([2.0, 2.0, 0.0], scan)                 # the first scan only stores odometry
    assert not mcl.update([2.15, 2.15, 0.5], scan)               # |dx|, |dy| <= 0.2 and |dtheta| <= pi/6
    assert mcl.update([2.15, 2.25, 0.5], scan) and mcl.n_updates == 1
    assert mcl.update([2.15, 2.25, 1.1], scan) and mcl.n_updates == 2   # a turn alone
    assert mcl.update([2.15, 2.25, 1.1], scan, force=True)
    with pytest.raises(ValueError, match="ranges"):
        mcl.update([3.0, 3.0, 0.0], np.full(360, np.nan))
    assert mcl.n_updates == 3


def test_resample_interval_and_kld_shrink(lab):
    world, grid = lab
    lidar = Lidar()
    true = np.array([5.0, 2.0, 0.0])
    kld = KLDConfig(min_particles=80, max_particles=3000)
    mcl = MonteCarloLocalizer(grid, n_particles=500, kld=kld, rng=0, resample_interval=2, max_beams=60,
                              alphas=[0.01] * 4)
    mcl.initialize_gaussian(true, np.diag([0.02, 0.02, 0.01]), n=2000)
    mcl.update(true, lidar.scan(world, true))
    true = true + [0.25, 0, 0]
    mcl.update(true, lidar.scan(world, true))
    assert len(mcl.particles) == 2000 and mcl.weights.std() > 0     # one update: weighted, not resampled
    true = true + [0.25, 0, 0]
    mcl.update(true, lidar.scan(world, true))
    assert 80 <= len(mcl.particles) < 1500 and np.ptp(mcl.weights) == 0   # resampled, and KLD shrank it


def test_converges_from_uniform_on_the_lab(lab):
    """Global localization on a non-symmetric map: 5 seeded runs of one lap, all within 0.2 m."""
    world, grid = lab
    lidar = Lidar(noise=0.02)
    lap = lab_lap(world)
    final = []
    for seed in range(5):
        odo = noisy_odometry(lap.poses, [0.01, 0.001, 0.01, 0.001], rng=seed)
        mcl = MonteCarloLocalizer(grid, n_particles=2000, alphas=[0.05, 0.01, 0.05, 0.01], resample_interval=1,
                                  rng=seed)
        first = None
        for k in range(0, len(lap.t), 2):
            if mcl.update(odo[k], lidar.scan(world, lap.poses[k], rng=1000 * seed + k), lidar.angles):
                err = np.linalg.norm(mcl.estimate()[:2] - lap.poses[k, :2])
                first = err if first is None else first
        final.append(err)
        assert mcl.n_updates > 80 and first > 0.5              # it started lost
    assert max(final) < 0.2, final


def test_augmented_mcl_injects_after_a_kidnapping(lab):
    world, grid = lab
    lidar = Lidar()
    mcl = MonteCarloLocalizer(grid, n_particles=500, alpha_slow=0.001, alpha_fast=0.1, rng=0, resample_interval=1,
                              alphas=[0.01] * 4)
    pose = np.array([3.0, 2.0, 0.0])
    mcl.initialize_gaussian(pose, np.diag([0.01, 0.01, 0.001]))
    mcl.update(pose, lidar.scan(world, pose))
    for _ in range(6):
        pose = pose + [0.25, 0, 0]
        mcl.update(pose, lidar.scan(world, pose))
    tracking = mcl.inject_probability                         # w_fast ~ w_slow while the scans fit
    kidnapped = np.array([7.0, 7.0, 2.0])
    for _ in range(4):                                        # odometry goes on, the scans come from elsewhere
        pose = pose + [0.25, 0, 0]
        mcl.update(pose, lidar.scan(world, kidnapped))
    assert tracking < 0.1 and mcl.inject_probability > 0.2 and mcl.n_injected > 100


def test_bad_arguments(lab):
    _, grid = lab
    with pytest.raises(TypeError, match="grid"):
        MonteCarloLocalizer(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="combine"):
        MonteCarloLocalizer(grid, combine="sum")
    with pytest.raises(ValueError, match="alphas"):
        MonteCarloLocalizer(grid, alphas=[0.1, -0.1, 0.1, 0.1])
    with pytest.raises(ValueError, match="sigma_x"):
        MonteCarloLocalizer(grid).initialize_ellipse([1.0, 1.0, 0.0], -1.0, 0.1)
