"""LittleDog's model and leg kinematics, checked against MuJoCo (which reads only the MJCF) and
against finite differences."""
import mujoco
import numpy as np
import pytest

from robokit.legged import leg_kinematics as lk
from robokit.legged import leg_kinematics as ls
from robokit.legged.littledog import (GUIDE, HIP_OFFSETS, HIP_POSITIONS, JOINT_NAMES, LEGS, LOWER_LEG, MARKERS,
                                      STANCE_FEET, STANDING_HEIGHT, TRUNK_SIZE, UPPER_LEG, littledog_mjcf,
                                      littledog_model)


def _below_hip_configs(rng, n, leg, branch):
    """Joint angles whose foot is below the hip in the rolled frame (the IK's chosen roll root)."""
    q = np.column_stack([rng.uniform(-0.6, 0.6, n), rng.uniform(-1.2, 1.2, n), branch * rng.uniform(0.05, 2.8, n)])
    sagittal_z = -UPPER_LEG * np.cos(q[:, 1]) - LOWER_LEG * np.cos(q[:, 1] + q[:, 2])
    return q[sagittal_z < -0.02]


def test_model_totals_and_the_guides_facts():
    m = littledog_model()
    assert m.nu == 12 and m.nq == 19 and m.nv == 18
    assert sum(m.body_mass) == pytest.approx(GUIDE["total_mass"], abs=1e-9)
    assert [m.joint(j + 1).name for j in range(12)] == list(JOINT_NAMES)
    # the guide's height and clearance are the trunk's top and bottom when standing
    assert STANDING_HEIGHT - TRUNK_SIZE[2] / 2 == pytest.approx(GUIDE["ground_clearance"])
    assert STANDING_HEIGHT + TRUNK_SIZE[2] / 2 == pytest.approx(GUIDE["body_size"][2])
    assert UPPER_LEG + LOWER_LEG == pytest.approx(GUIDE["leg_length"], abs=0.005)


@pytest.mark.parametrize("leg", range(4))
def test_fk_matches_mujoco_sites(leg):
    """Our FK and MuJoCo's (built only from the MJCF text) agree for random joint angles."""
    m = littledog_model()
    d = mujoco.MjData(m)
    rng = np.random.default_rng(leg)
    for _ in range(20):
        d.qpos[:7] = [0, 0, 0, 1, 0, 0, 0]
        d.qpos[7:] = rng.uniform(-1.5, 1.5, 12)
        mujoco.mj_kinematics(m, d)
        q = d.qpos[7 + 3 * leg:10 + 3 * leg]
        np.testing.assert_allclose(lk.foot_position(q, leg), d.site(f"{LEGS[leg]}_foot").xpos, atol=1e-12)
        knee = lk.leg_points(q, leg)[2]
        np.testing.assert_allclose(knee, d.body(f"{LEGS[leg]}_lower").xpos, atol=1e-12)
    np.testing.assert_allclose(lk.body_fk(d.qpos[7:]), [d.site(f"{n}_foot").xpos for n in LEGS], atol=1e-12)


def test_markers_are_where_the_model_puts_them():
    m = littledog_model()
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    np.testing.assert_allclose([d.site(f"marker{k}").xpos for k in range(4)], MARKERS + [0, 0, STANDING_HEIGHT])


@pytest.mark.parametrize("leg", range(4))
@pytest.mark.parametrize("branch", [-1, 1])
def test_ik_round_trip_on_both_branches(leg, branch):
    rng = np.random.default_rng(10 * leg + branch + 1)
    q = _below_hip_configs(rng, 3000, leg, branch)
    assert len(q) > 1000
    res = lk.leg_ik_batch(lk.foot_position(q, leg), leg, branch)
    assert res.ok.all()
    np.testing.assert_allclose(res.q, q, atol=1e-9)
    # the other branch reaches the same foot with the knee mirrored
    other = lk.leg_ik_batch(lk.foot_position(q, leg), leg, -branch)
    np.testing.assert_allclose(other.q[:, 2], -q[:, 2], atol=1e-9)
    np.testing.assert_allclose(lk.foot_position(other.q, leg), lk.foot_position(q, leg), atol=1e-12)


def test_single_ik_default_branches_and_unreachable_targets():
    for leg in range(4):
        q = lk.leg_ik(STANCE_FEET[leg], leg)
        assert np.sign(q[2]) == lk.KNEE_BRANCH[leg]
        assert lk.within_limits(q, leg)
    with pytest.raises(lk.UnreachableFootError, match="out of reach of leg FL"):
        lk.leg_ik([0.101, 0.06, -0.19], "FL")                   # 0.19 m below the hip: too far
    with pytest.raises(lk.UnreachableFootError):
        lk.leg_ik([0.101, 0.03625, -0.01], "FL")                # inside the roll axis' offset circle
    res = lk.leg_ik_batch([[0.101, 0.06, -0.19], STANCE_FEET[0]], 0)
    assert res.ok.tolist() == [False, True] and np.all(res.q[0] == 0)


def test_ik_at_the_workspace_boundary_reaches_with_a_straight_knee():
    p = lk.foot_position([0.2, 0.3, 0.0], "HL")
    q = lk.leg_ik(p, "HL")
    assert q[2] == pytest.approx(0.0, abs=1e-6)
    np.testing.assert_allclose(lk.foot_position(q, "HL"), p, atol=1e-9)
    just_out = p + 1e-6 * (p - lk.leg_points([0.2, 0.3, 0.0], "HL")[1])
    assert not lk.leg_ik_batch(just_out, "HL").ok[0]


@pytest.mark.parametrize("leg", range(4))
def test_jacobian_matches_finite_differences(leg):
    rng = np.random.default_rng(leg)
    q = rng.uniform(-2, 2, (200, 3))
    eps = 1e-6
    fd = np.stack([(lk.foot_position(q + eps * e, leg) - lk.foot_position(q - eps * e, leg)) / (2 * eps)
                   for e in np.eye(3)], axis=-1)
    np.testing.assert_allclose(lk.foot_jacobian(q, leg), fd, atol=1e-8)


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="leg"):
        lk.foot_position([0, 0, 0], "XX")
    with pytest.raises(ValueError, match="q_leg"):
        lk.foot_position([0, 0], "FL")
    with pytest.raises(ValueError, match="p_foot"):
        lk.leg_ik([np.nan, 0, -0.1], "FL")
    with pytest.raises(ValueError, match="branch"):
        lk.leg_ik(STANCE_FEET[0], "FL", branch=0)
    with pytest.raises(ValueError, match="singular"):
        ls.foot_force_from_torques([0, 0, 0], [0, 0, 0], "FL")
    with pytest.raises(ValueError, match="timestep"):
        littledog_mjcf(timestep=0.02)


def test_statics_name_the_argument_whose_batch_does_not_fit_and_refuse_an_overflow():
    # found by the fuzz: numpy's "operands could not be broadcast" named no argument, and torques near
    # the largest float gave a silent inf/NaN force
    q2 = np.tile([0.0, 0.6, -1.2], (2, 1))
    with pytest.raises(ValueError, match=r"^force: .*broadcast"):
        ls.torques_from_foot_force(q2, np.ones((5, 3)), "FL")
    with pytest.raises(ValueError, match=r"^tau: .*broadcast"):
        ls.foot_force_from_torques(q2, np.ones((5, 3)), "FL")
    with pytest.raises(ValueError, match=r"^gravity_torque: .*broadcast"):
        ls.foot_force_from_torques(q2[0], np.ones((2, 3)), "FL", np.ones((5, 3)))
    with pytest.raises(ValueError, match="tau, gravity_torque"):
        ls.foot_force_from_torques(q2[0], np.full(3, 1e308), "FL", np.full(3, -1e308))
    # batches that do broadcast still give each row's own answer
    f = np.array([[0.0, 0.0, -7.4], [1.0, 0.5, -3.0]])
    tau = ls.torques_from_foot_force(q2[0], f, "FL")
    assert np.allclose(tau[1], lk.foot_jacobian(q2[0], "FL").T @ f[1])
    back = ls.foot_force_from_torques(q2, tau[:, None, :], "FL")      # (2, 1, 3) against q's (2,)
    assert back.shape == (2, 2, 3) and np.allclose(back[:, 0], -f)


def _stand(armature=0.01, seconds=2.0):
    """Hold the nominal stance with a stiff joint PD in MuJoCo until it settles."""
    m = littledog_model(armature=armature)
    d = mujoco.MjData(m)
    q0 = lk.body_ik(STANCE_FEET).q[0]
    d.qpos[:7] = [0, 0, STANDING_HEIGHT, 1, 0, 0, 0]
    d.qpos[7:] = q0
    for _ in range(int(seconds / m.opt.timestep)):
        d.ctrl[:] = 20 * (q0 - d.qpos[7:]) - 0.5 * d.qvel[6:]
        mujoco.mj_step(m, d)
    return m, d


def test_jt_force_mapping_matches_mujoco_contact_forces():
    m, d = _stand()
    R = d.xmat[m.body("trunk").id].reshape(3, 3)
    contacts = {}
    for c in range(d.ncon):
        f = np.zeros(6)
        mujoco.mj_contactForce(m, d, c, f)
        con = d.contact[c]
        names = {m.geom(con.geom1).name, m.geom(con.geom2).name}
        leg = next(n for n in LEGS if f"{n}_foot" in names)
        contacts[leg] = con.frame.reshape(3, 3).T @ f[:3]         # contact frame -> world
    assert sorted(contacts) == sorted(LEGS)
    total = sum(contacts.values())
    assert total[2] == pytest.approx(3.0 * 9.81, rel=1e-3)        # the feet carry the 3 kg robot
    for i, leg in enumerate(LEGS):
        s = slice(6 + 3 * i, 9 + 3 * i)
        est = R @ ls.foot_force_from_torques(d.qpos[7 + 3 * i:10 + 3 * i], d.qfrc_actuator[s], i,
                                             gravity_torque=d.qfrc_bias[s])
        np.testing.assert_allclose(est, contacts[leg], atol=0.01)  # 10 mN of 7.4 N
        massless = R @ ls.foot_force_from_torques(d.qpos[7 + 3 * i:10 + 3 * i], d.qfrc_actuator[s], i)
        assert np.linalg.norm(massless - contacts[leg]) > 0.1      # the legs' own weight matters


def test_force_sensor_reads_the_axial_part_of_the_foot_force():
    """The guide's single-axis lower-leg sensor: minus the z (shank) component of MuJoCo's knee force."""
    m, d = _stand()
    for i, leg in enumerate(LEGS):
        sensor = d.sensor(f"{leg}_force").data
        shank = d.site(f"{leg}_force").xmat.reshape(3, 3)[:, 2]   # the shank's z axis in the world
        q = d.qpos[7 + 3 * i:10 + 3 * i]
        R = d.xmat[m.body("trunk").id].reshape(3, 3)
        ground = R @ ls.foot_force_from_torques(q, d.qfrc_actuator[6 + 3 * i:9 + 3 * i], i,
                                                gravity_torque=d.qfrc_bias[6 + 3 * i:9 + 3 * i])
        # compression: the ground's push along the shank, less the lower leg's own weight along it
        lower = m.body_subtreemass[m.body(f"{leg}_lower").id]
        expected = ground @ shank + lower * 9.81 * (np.array([0, 0, -1.0]) @ shank)
        assert -sensor[2] == pytest.approx(expected, abs=0.02)


def test_body_ik_in_the_world_frame_and_batch():
    from robokit.geometry import se3_from_rt, rot_z
    T = se3_from_rt(rot_z(0.3), [0.5, -0.2, STANDING_HEIGHT])
    feet_world = (T[:3, :3] @ STANCE_FEET.T).T + T[:3, 3]
    q, ok = lk.body_ik(np.stack([feet_world] * 3), np.stack([T] * 3))
    assert ok.all()
    np.testing.assert_allclose(lk.body_fk(q), np.stack([STANCE_FEET] * 3), atol=1e-12)
    with pytest.raises(ValueError, match="T_world_body"):
        lk.body_ik(np.stack([feet_world] * 3), np.stack([T] * 2))


def test_workspace_respects_limits_and_reach():
    pts = lk.reachable_workspace("HR", 5000, rng=1)
    pitch = HIP_POSITIONS[3] + [0, -HIP_OFFSETS[3], 0]
    assert len(pts) > 1000
    assert np.all(np.linalg.norm(pts - HIP_POSITIONS[3], axis=1) <= UPPER_LEG + LOWER_LEG + HIP_OFFSETS[3] + 1e-12)
    assert np.linalg.norm(pts - pitch, axis=1).min() < 0.06     # folded knees come close to the hip
