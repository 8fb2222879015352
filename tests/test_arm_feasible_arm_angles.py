"""Exact feasible arm-angle intervals (Shimizu et al. 2008, Sec. IV) and the compiled S-R-S solve:
the intervals against dense sampling, the compiled kernels against their readable counterparts, the
optimum against the reference search and a brute-force one, and the import/caching rules of numba."""
import os
import subprocess
import sys

import numpy as np
import pytest

from robokit.arm import LIMIT_TOL, arm_angle, feasible_arm_angles, iiwa14, ik_srs, ik_srs_batch, ik_srs_readable
from robokit.arm.arm_angle_intervals import split_points
from robokit.arm.ik_analytic import SRSArm
from robokit.arm.srs_geometry import ARRAY, coefficient_terms

IIWA = iiwa14()
ARM = SRSArm(IIWA)


def _targets(n, seed):
    rng = np.random.default_rng(seed)
    return IIWA.fk(IIWA.random_q(n, rng)), IIWA.random_q(n, rng)


def _inside(intervals, psi):
    return np.any((intervals[:, :1] <= psi) & (psi <= intervals[:, 1:]), axis=0) if len(intervals) else np.zeros(
        psi.shape, bool)


def test_intervals_agree_with_dense_sampling_and_their_ends_are_on_limits():
    T, _ = _targets(8, 0)
    psi = np.linspace(-np.pi, np.pi, 4001)
    for Ti in T:
        intervals = feasible_arm_angles(IIWA, Ti)
        q = ARM.joints(ARM.coefficients(ARM.to_link7(Ti)), psi[None])[0]          # (psi, 8, 7)
        ok = IIWA.within_limits(q.reshape(-1, 7)).reshape(q.shape[:2])
        ends = split_points(IIWA, Ti)
        far = np.abs(psi[:, None] - np.append(ends, np.pi)[None]).min(1) > 1e-6   # away from any split point
        for b in range(8):
            assert np.array_equal(_inside(intervals[b], psi)[far], ok[far, b])
            for end in intervals[b].ravel():
                if abs(abs(end) - np.pi) < 1e-12:
                    continue
                qe = ARM.joints(ARM.coefficients(ARM.to_link7(Ti)), np.array([[end]]))[0, 0, b]
                assert np.min(np.minimum(np.abs(qe - IIWA.qmin), np.abs(qe - IIWA.qmax))) < 1e-9   # a joint on a limit


def test_own_arm_angle_is_feasible_and_unreachable_targets_have_none():
    q = IIWA.random_q(20, rng=1)
    for qi in q:
        b = 4 * (qi[3] < 0) + 2 * (qi[1] < 0) + (qi[5] < 0)
        assert _inside(feasible_arm_angles(IIWA, IIWA.fk(qi))[b], np.array([arm_angle(IIWA, qi)]))[0]
    T = np.eye(4)
    T[:3, 3] = [1.5, 0.0, 0.5]
    assert all(len(i) == 0 for i in feasible_arm_angles(IIWA, T)) and split_points(IIWA, T).size == 0


def test_compiled_steps_match_the_readable_ones():
    from robokit.arm import chain_kernels, panda, srs_kernels

    T, q0 = _targets(10, 2)
    for Ti in T:
        G, q4 = np.empty((2, 2, 3, 9)), np.empty(2)
        c4 = srs_kernels.coefficients(Ti, ARM.d_bs, ARM.d_se, ARM.d_ew, ARM.d_wf, G, q4)
        W = ARM.wrist_centre(Ti[None])
        terms, q4_ref, c4_ref = coefficient_terms([[Ti[None, i, j] for j in range(3)] for i in range(3)],
                                                  (W[:, 0], W[:, 1], W[:, 2] - ARM.d_bs), ARM.d_se, ARM.d_ew, ARRAY)
        ref = np.stack(terms, -1).reshape(3, 2, 2, 9).transpose(1, 2, 0, 3)
        assert np.allclose(G, ref, atol=1e-14) and abs(c4 - c4_ref[0]) < 1e-14
        ivl, counts = np.empty((8, srs_kernels.MAX_SPLITS, 2)), np.zeros(8, np.int64)
        srs_kernels.feasible_intervals(G, q4, IIWA.qmin, IIWA.qmax, LIMIT_TOL, ivl, counts)
        for b, intervals in enumerate(feasible_arm_angles(IIWA, Ti)):
            assert np.allclose(ivl[b, :counts[b]], intervals, atol=1e-12)
    for chain in (IIWA, panda()):
        q = chain.random_q(rng=3)
        K, U, V, offset, base, tool, first = chain_kernels.chain_arrays(chain)
        F = np.empty((8, 4, 4))
        flange = chain_kernels.frames(q, K, U, V, offset, base, tool, F)
        assert np.allclose(F, chain.frames(q), atol=1e-14) and np.allclose(flange, chain.fk(q), atol=1e-14)
        J = np.empty((6, 7))
        chain_kernels.jacobian(F, flange, first, J)
        from robokit.arm import geometric_jacobian
        from robokit.geometry import pose_error
        assert np.allclose(J, geometric_jacobian(chain, q), atol=1e-14)
        for target in (chain.fk(chain.random_q(rng=4)), chain.fk(q) @ np.diag([-1.0, -1.0, 1.0, 1.0])):  # near pi too
            e = np.empty(6)
            chain_kernels.pose_error(target, flange, e)
            assert np.allclose(e, pose_error(target, flange), atol=1e-12)


def test_fast_solve_equals_the_reference_search():
    T, q0 = _targets(25, 3)
    for Ti, si in zip(T, q0):
        fast = ik_srs(IIWA, Ti, si)
        q_ref, psi_ref, cost_ref = ik_srs_readable(IIWA, Ti, si)
        assert fast.success
        assert np.abs(fast.q - q_ref).max() < 1e-6
        assert ((fast.q - si) ** 2).sum() <= cost_ref + 1e-12


def test_optimum_is_no_worse_than_brute_force_over_the_feasible_set():
    T, q0 = _targets(25, 4)
    res = ik_srs_batch(IIWA, T, q0)
    psi = np.linspace(-np.pi, np.pi, 20001)
    for i, (Ti, si) in enumerate(zip(T, q0)):
        q = ARM.joints(ARM.coefficients(ARM.to_link7(Ti)), psi[None])[0].reshape(-1, 7)
        q = q[IIWA.within_limits(q)]
        brute = ((np.clip(q, IIWA.qmin, IIWA.qmax) - si) ** 2).sum(1).min()
        assert ((res.q[i] - si) ** 2).sum() <= brute + 1e-9


def test_elbow_on_its_limit_solves_from_any_start():
    rng = np.random.default_rng(5)
    q = IIWA.random_q(300, rng)
    q[:150, 3], q[150:, 3] = IIWA.qmax[3], IIWA.qmin[3]
    starts = IIWA.random_q(300, rng)
    res = ik_srs_batch(IIWA, IIWA.fk(q), starts)
    assert res.success.all() and IIWA.within_limits(res.q, tol=0.0).all()
    # one target at a time (the path a slider or a real-time loop takes) gives the same answers
    single = [ik_srs(IIWA, T, s) for T, s in zip(IIWA.fk(q[::5]), starts[::5])]
    assert all(r.success for r in single)
    assert np.abs(np.array([r.q for r in single]) - res.q[::5]).max() < 1e-9


def test_single_and_batch_agree_and_bad_targets_raise_named_errors():
    T, q0 = _targets(10, 6)
    batch = ik_srs_batch(IIWA, T, q0)
    single = [ik_srs(IIWA, Ti, si) for Ti, si in zip(T, q0)]
    assert np.array_equal(np.array([r.q for r in single]), batch.q)
    assert [r.iterations for r in single] == batch.iterations.tolist()
    with pytest.raises(ValueError, match=r"T\[:3, :3\]: expected a rotation matrix"):
        ik_srs(IIWA, T[0] @ np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(ValueError, match="T: expected an SE.3. matrix with last row"):
        bad = T[0].copy()
        bad[3, 0] = 0.5
        ik_srs(IIWA, bad)
    with pytest.raises(ValueError, match="q0"):
        ik_srs(IIWA, T[0], np.full(7, np.nan))
    with pytest.raises(ValueError, match="n_psi"):
        ik_srs(IIWA, T[0], n_psi=2)


def _run(code, **env):
    full = {**os.environ, **env, "PYTHONPATH": os.getcwd()}
    return subprocess.run([sys.executable, "-c", code], env=full, capture_output=True, text=True, timeout=300)


def test_import_compiles_nothing_and_an_unwritable_cache_only_disables_caching(tmp_path):
    r = _run("import sys, robokit, robokit.arm; print('numba' in sys.modules)")
    assert r.returncode == 0 and r.stdout.strip() == "False", r.stderr
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    code = ("from robokit.arm import jit\n"
            "def add(a, b):\n    return a + b\n"
            "print(jit.CACHING, jit.njit(add)(1.0, 2.0))")
    r = _run(code, ROBOKIT_CACHE=str(blocker / "cache"), NUMBA_CACHE_DIR="")
    assert r.returncode == 0 and r.stdout.split() == ["False", "3.0"], r.stderr
    r = _run(code, ROBOKIT_CACHE=str(tmp_path / "cache"), NUMBA_CACHE_DIR="")
    assert r.returncode == 0 and r.stdout.split() == ["True", "3.0"], r.stderr


def test_compiled_code_is_cached_in_robokits_cache_not_in_the_package():
    from pathlib import Path

    from numba.core import config as numba_config

    import robokit
    from robokit.arm import jit
    from robokit.cache import cache_dir

    ik_srs(IIWA, IIWA.fk(np.zeros(7)))                       # compiled or loaded by now
    if not os.environ.get("NUMBA_CACHE_DIR") and jit.CACHING:
        assert numba_config.CACHE_DIR == str(cache_dir("numba", jit.SOURCE_DIGEST))
        assert any(cache_dir("numba").rglob("*.nbi"))
    assert not list(Path(robokit.__file__).parent.rglob("*.nbi"))   # nothing written next to the source


def test_the_first_compiling_call_says_so_once_and_a_cache_hit_stays_quiet(tmp_path, monkeypatch, capsys):
    from numba.core import config as numba_config

    from robokit.arm import jit

    monkeypatch.setattr(numba_config, "CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(jit, "CACHING", True)
    record = jit.compile_notice("srs_solve", "the analytic IK solver")
    said = capsys.readouterr()
    assert record is not None and record.parent == tmp_path and said.err == ""     # information, not an error
    assert said.out.count("\n") == 1 and said.out.startswith("robokit note: compiling the analytic IK solver")
    assert "once" in said.out
    jit.compiled(record)
    assert jit.compile_notice("srs_solve", "the analytic IK solver") is None      # recorded: quiet
    assert capsys.readouterr().out == ""
    monkeypatch.setattr(jit, "CACHING", False)                  # no cache: every process compiles, and says so
    assert jit.compile_notice("srs_solve", "the analytic IK solver") is None
    assert "every new process" in capsys.readouterr().out


def test_the_compiled_cache_folder_changes_with_any_kernel_source(monkeypatch):
    # numba checks only the file of the function it compiled; our kernels inline functions of the
    # other kernel modules, so the cache folder must be named by all of their sources together
    from pathlib import Path

    import robokit.arm
    from robokit.arm import jit

    arm = Path(robokit.arm.__file__).parent
    with_kernels = {p.name for p in arm.glob("*.py") if "@njit" in p.read_text()} | {"jit.py"}
    assert with_kernels <= set(jit.SOURCES)
    assert jit.source_digest() == jit.SOURCE_DIGEST
    read = Path.read_bytes
    for name in jit.SOURCES:
        monkeypatch.setattr(Path, "read_bytes", lambda self, n=name: read(self) + (b"#" if self.name == n else b""))
        assert jit.source_digest() != jit.SOURCE_DIGEST, name
    monkeypatch.setattr(Path, "read_bytes", read)
