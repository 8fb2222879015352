"""Analytic (arm-angle) IK of the S-R-S iiwa: branches, self-motion, limits, honesty of success."""
import numpy as np
import pytest

from robokit.arm import arm_angle, iiwa14, ik_srs, ik_srs_batch, ik_srs_branches, panda
from robokit.geometry import pose_error

IIWA = iiwa14()


def _errors(chain, T, q):
    e = pose_error(T, chain.fk(q))
    return np.linalg.norm(e[..., :3], axis=-1), np.linalg.norm(e[..., 3:], axis=-1)


@pytest.mark.parametrize("seed", [0, 1])
def test_all_eight_branches_reach_the_pose_and_include_the_original(seed):
    q = IIWA.random_q(20, rng=seed)
    T = IIWA.fk(q)
    psi = arm_angle(IIWA, q)
    for qi, Ti, pi in zip(q, T, psi):
        br = ik_srs_branches(IIWA, Ti, pi, within_limits=False)
        assert br.shape == (8, 7)
        pos, rot = _errors(IIWA, np.broadcast_to(Ti, (8, 4, 4)), br)
        assert pos.max() < 1e-12 and rot.max() < 1e-12
        assert np.abs(br - qi).max(axis=1).min() < 1e-9
        # distinct branches
        assert len({tuple(np.round(b, 6)) for b in br}) == 8
        valid = ik_srs_branches(IIWA, Ti, pi)
        assert len(valid) >= 1 and IIWA.within_limits(valid).all()


def test_self_motion_keeps_the_hand_fixed_and_moves_the_elbow_on_a_circle():
    q = IIWA.random_q(rng=3)
    T = IIWA.fk(q)
    elbows = []
    for psi in np.linspace(-np.pi, np.pi, 13)[:-1]:
        qs = ik_srs_branches(IIWA, T, psi, within_limits=False)[0]
        assert np.allclose(IIWA.fk(qs), T, atol=1e-12)
        assert abs(arm_angle(IIWA, qs) - psi) < 1e-9 or abs(abs(psi) - np.pi) < 1e-9
        elbows.append(IIWA.link_frames(qs)[3, :3, 3])
    elbows = np.array(elbows)
    # every elbow is 0.42 m from the shoulder, and the elbows are spread around the S-W axis
    assert np.allclose(np.linalg.norm(elbows - [0, 0, 0.36], axis=1), 0.42)
    assert np.ptp(elbows, axis=0).max() > 0.1


@pytest.mark.parametrize("seed", [10, 11])
def test_batch_success_rate_and_accuracy(seed):
    rng = np.random.default_rng(seed)
    q = IIWA.random_q(2000, rng)
    T = IIWA.fk(q)
    res = ik_srs_batch(IIWA, T, IIWA.random_q(2000, rng))
    assert res.success_rate >= 0.999
    # success is honest: recompute errors and limits independently of the solver
    pos, rot = _errors(IIWA, T, res.q)
    ok = (pos < 1e-6) & (rot < 1e-6) & IIWA.within_limits(res.q)
    assert np.array_equal(ok, res.success)
    assert all(r == "converged" for r, s in zip(res.reason, res.success) if s)


def test_q0_equal_to_a_solution_is_returned():
    q = IIWA.random_q(50, rng=12)
    res = ik_srs_batch(IIWA, IIWA.fk(q), q)
    assert res.success.all()
    assert np.abs(res.q - q).max() < 1e-9


def test_solution_is_near_q0_for_nearby_targets():
    q = IIWA.random_q(200, rng=13)
    q_near = np.clip(q + np.random.default_rng(14).normal(0, 0.02, q.shape), IIWA.qmin, IIWA.qmax)
    res = ik_srs_batch(IIWA, IIWA.fk(q_near), q)
    assert res.success.all()
    assert np.median(np.abs(res.q - q_near).max(axis=1)) < 0.05


def test_single_solve_result_object():
    q = IIWA.random_q(rng=15)
    r = ik_srs(IIWA, IIWA.fk(q), np.zeros(7))
    assert r.success and r.reason == "converged" and r.q.shape == (7,)
    assert r.position_error < 1e-6 and r.orientation_error < 1e-6 and r.residual < 1e-6


def test_unreachable_target_fails_with_a_reason():
    T = np.eye(4)
    T[:3, 3] = [1.5, 0.0, 0.5]
    r = ik_srs(IIWA, T)
    assert not r.success and "out of reach" in r.reason
    T[:3, 3] = [0.0, 0.0, 0.36 + 0.126]  # wrist centre on the shoulder: closer than |0.42 - 0.40|
    r = ik_srs(IIWA, T)
    assert not r.success and "out of reach" in r.reason


def test_pose_reachable_only_outside_the_limits_fails():
    q = np.zeros(7)
    q[3] = 2.5  # elbow beyond +-120 deg: every arm angle needs |q4| = 2.5
    r = ik_srs(IIWA, IIWA.fk(q))
    assert not r.success and "limits" in r.reason
    assert len(ik_srs_branches(IIWA, IIWA.fk(q), 0.3)) == 0


def test_bad_input():
    T = IIWA.fk(np.zeros(7))
    with pytest.raises(ValueError, match=r"T\[:3, :3\]: expected a rotation matrix"):
        ik_srs(IIWA, T @ np.diag([2, 1, 1, 1]))
    with pytest.raises(ValueError, match="T"):
        ik_srs(IIWA, np.full((4, 4), np.nan))
    with pytest.raises(ValueError, match="q0"):
        ik_srs(IIWA, T, np.zeros(6))
    with pytest.raises(ValueError, match="q0: expected one joint vector or 3"):
        ik_srs_batch(IIWA, np.stack([T] * 3), np.zeros((2, 7)))
    with pytest.raises(ValueError, match="chain"):
        ik_srs(panda(), T)
    with pytest.raises(ValueError, match="psi"):
        ik_srs_branches(IIWA, T, float("nan"))
    with pytest.raises(TypeError, match="chain"):
        ik_srs([1, 2], T)


def test_step_functions_reproduce_the_solver():
    from robokit.arm import elbow_angle, shoulder_angles, wrist_centre

    q = IIWA.random_q(20, rng=30)
    for qi in q:
        T = IIWA.fk(qi)
        frames = IIWA.link_frames(qi)
        W = wrist_centre(T, 0.126)
        assert np.allclose(W, frames[5, :3, 3], atol=1e-12)
        S = np.array([0, 0, 0.36])
        q4 = elbow_angle(S, W, 0.42, 0.40)
        assert abs(q4 - abs(qi[3])) < 1e-9
        psi = arm_angle(IIWA, qi)
        sh = shoulder_angles(S, W, qi[3], psi, 0.42, 0.40)
        mirror = np.array([sh[0] + np.pi, -sh[1], sh[2] + np.pi])
        mirror[[0, 2]] = (mirror[[0, 2]] + np.pi) % (2 * np.pi) - np.pi
        assert min(np.abs(sh - qi[:3]).max(), np.abs(mirror - qi[:3]).max()) < 1e-9
    with pytest.raises(ValueError, match="out of reach"):
        elbow_angle([0, 0, 0.36], [0, 0, 2.0], 0.42, 0.40)
    with pytest.raises(ValueError, match="T"):
        wrist_centre(np.eye(3), 0.126)


def test_single_solve_on_floats_matches_the_vectorised_batch():
    # ik_srs computes the per-target geometry on Python floats, ik_srs_batch on arrays; for at
    # most 16 targets both run the same dense arm-angle grid, so the answers must agree
    rng = np.random.default_rng(40)
    q = IIWA.random_q(12, rng)
    T, seeds = IIWA.fk(q), IIWA.random_q(12, rng)
    batch = ik_srs_batch(IIWA, T, seeds)
    single = np.array([ik_srs(IIWA, Ti, si).q for Ti, si in zip(T, seeds)])
    assert batch.success.all()
    assert np.abs(single - batch.q).max() < 1e-9
    assert np.allclose([arm_angle(IIWA, qi) for qi in q], arm_angle(IIWA, q), atol=1e-12)


@pytest.mark.parametrize("joint", [3, 1, 5])
def test_a_target_with_a_joint_exactly_on_its_limit_solves(joint):
    # poses from clamped trajectories put a joint exactly on its limit; the closed-form angle then
    # lands a rounding error either side of it, and a strict limit test refused every branch
    # (67 % of q4-on-limit targets solved before the tolerance)
    from robokit.arm import LIMIT_TOL

    arm = iiwa14()
    q = arm.random_q(400, rng=np.random.default_rng(joint))
    q[:200, joint], q[200:, joint] = arm.qmax[joint], arm.qmin[joint]
    res = ik_srs_batch(arm, arm.fk(q), q0=q)
    assert res.success.all(), res.reason[int(np.argmin(res.success))]
    assert np.all(res.q >= arm.qmin) and np.all(res.q <= arm.qmax)  # clipped onto the limit, not past it
    single = [ik_srs(arm, T) for T in arm.fk(q[::40])]
    assert all(r.success for r in single)
    branches = ik_srs_branches(arm, arm.fk(q[0]), arm_angle(arm, q[0]))
    assert len(branches) and np.abs(branches - q[0]).max(axis=1).min() < 1e-9
    past = q[0].copy()
    past[joint] = arm.qmax[joint] + LIMIT_TOL / 2
    assert arm.within_limits(past)
    past[joint] = arm.qmax[joint] + 1e-9
    assert not arm.within_limits(past)
