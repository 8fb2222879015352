"""Huang & Jiang's reduction (robokit.arm.position_posture): Newton on joints 1-4 for the wrist centre,
closed-form joints 5-7; FK-verified answers, honest failures, validated inputs."""
import numpy as np
import pytest

from robokit.arm import iiwa14, ik_position_posture, panda, wrist_centre

IIWA = iiwa14()


def _targets(n, seed, spread=0.1):
    rng = np.random.default_rng(seed)
    q = IIWA.random_q(n, rng)
    start = np.clip(q + rng.normal(0, spread, q.shape), IIWA.qmin, IIWA.qmax)
    return q, IIWA.fk(q), start


def test_reaches_targets_from_nearby_starts_and_places_the_wrist_centre():
    q, T, start = _targets(30, 0)
    results = [ik_position_posture(IIWA, Ti, s) for Ti, s in zip(T, start)]
    assert np.mean([r.success for r in results]) >= 0.9
    for r, Ti in zip(results, T):
        if r.success:
            W = IIWA.link_frames(r.q)[5, :3, 3]                  # frame 5's origin is the wrist centre
            assert np.abs(W - wrist_centre(Ti, 0.126)).max() < 1e-6
            assert r.position_error < 1e-6 and r.orientation_error < 1e-6


def test_a_start_on_the_answer_takes_no_step_and_returns_it():
    q, T, _ = _targets(3, 1)
    for qi, Ti in zip(q, T):
        r = ik_position_posture(IIWA, Ti, qi)
        assert r.iterations == 0
        assert np.abs(r.q - qi).max() < 1e-9


def test_failures_are_reported_not_hidden():
    far = np.eye(4)
    far[:3, 3] = [1.4, 0.0, 0.4]                                  # the wrist centre out of reach
    for method in ("newton", "joint_parameter"):
        r = ik_position_posture(IIWA, far, method=method)
        assert not r.success and r.reason.startswith("out of reach") and r.iterations == 0
    q, T, start = _targets(60, 3, spread=2.0)                      # far starts: some land outside the limits
    reasons = [ik_position_posture(IIWA, Ti, s).reason for Ti, s in zip(T, start)]
    assert any("outside its limits" in x for x in reasons)


@pytest.mark.parametrize("kwargs, word", [
    (dict(T=np.eye(3)), "T"),
    (dict(q0=np.zeros(6)), "q0"),
    (dict(tol=0.0), "tol"),
    (dict(max_iter=0), "max_iter"),
    (dict(method="lee_bejczy"), "method"),
])
def test_bad_input_names_the_argument(kwargs, word):
    args = dict(chain=IIWA, T=IIWA.fk(np.zeros(7)))
    args.update(kwargs)
    with pytest.raises(ValueError, match=word):
        ik_position_posture(**args)


def test_only_s_r_s_arms():
    with pytest.raises(ValueError, match="S-R-S"):
        ik_position_posture(panda(), panda().fk(np.zeros(7)))
    with pytest.raises(TypeError, match="chain"):
        ik_position_posture("iiwa", np.eye(4))


def test_joint_parameter_reading_reaches_targets_without_a_pseudo_inverse_and_keeps_the_limits():
    """The second reading (q3 as the parameter, q1, q2, q4 in closed form) places the wrist centre
    exactly and, unlike Newton, searches the parameter until every joint is inside its limits."""
    q, T, start = _targets(40, 5, spread=2.0)
    newton = [ik_position_posture(IIWA, Ti, s) for Ti, s in zip(T, start)]
    param = [ik_position_posture(IIWA, Ti, s, method="joint_parameter") for Ti, s in zip(T, start)]
    assert all(r.success for r in param)
    assert not all(r.success for r in newton)                       # far starts: Newton lands outside sometimes
    for r in param:
        assert r.position_error < 1e-9 and r.orientation_error < 1e-9
    kept = [r for r, s in zip(param, start) if r.iterations == 1]    # the first try keeps the current q3
    assert kept and all(abs(r.q[2] - s[2]) < 1e-12 for r, s in zip(param, start) if r.iterations == 1)
