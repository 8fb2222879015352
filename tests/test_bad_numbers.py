"""The "bad numbers elsewhere" findings of issue 12, one test each (the fuzz in
tests/test_fuzz_public_api.py covers the classes; these pin the cases the issue names)."""
from __future__ import annotations

import numpy as np
import pytest

from robokit.arm import iiwa14, ik_numeric, ik_srs, ik_srs_batch
from robokit.geometry import wrap_angle
from robokit.outdoor.geodesy import GeodesyError, vincenty_inverse
from robokit.sim.vehicle import unicycle_step
from robokit.validation import as_array, as_finite_scalar
from robokit.vision.stereo import triangulate_svd

K = np.array([[100.0, 0.0, 80.0], [0.0, 100.0, 60.0], [0.0, 0.0, 1.0]])
P_LEFT = K @ np.eye(3, 4)


@pytest.mark.parametrize("value", ["1.0", np.array("1.0"), ["1.0", "2.0"], np.array([b"1"]), b"1.0"])
def test_numeric_strings_are_not_numbers(value):
    with pytest.raises(TypeError, match=r"^angle: expected real numbers, got (a string|bytes)"):
        wrap_angle(value)
    with pytest.raises(TypeError, match="x:"):
        as_finite_scalar(value, "x")


@pytest.mark.parametrize("value", [1 + 2j, np.array([1 + 0j, 2 + 0j]), [0.5, 1j], np.complex64(1)])
def test_complex_numbers_are_refused_not_reduced_to_their_real_part(value):
    with pytest.raises(TypeError, match="angle: expected real numbers, got complex numbers"):
        wrap_angle(value)


def test_booleans_are_refused_where_numbers_are_expected_and_kept_where_a_mask_is():
    with pytest.raises(TypeError, match="angle: expected real numbers, got booleans.*astype"):
        wrap_angle(np.array([True, False]))
    with pytest.raises(TypeError, match="x: expected a real number, got True"):
        as_finite_scalar(True, "x")
    assert as_array([True, False], "mask", dtype=bool).tolist() == [True, False]
    assert as_array([1, 0], "mask", dtype=bool).tolist() == [True, False]


def test_identical_cameras_give_the_documented_zero_disparity_error_not_the_origin():
    uv = np.array([[80.0, 60.0], [90.0, 50.0]])
    with pytest.raises(ValueError, match="p_left, p_right: .*zero disparity"):
        triangulate_svd(P_LEFT, P_LEFT, uv, uv)
    with pytest.raises(ValueError, match="zero disparity"):          # different pixels, same centre
        triangulate_svd(P_LEFT, P_LEFT, uv, uv + [5.0, 0.0])
    p_right = K @ np.hstack([np.eye(3), [[-0.12], [0.0], [0.0]]])
    assert triangulate_svd(P_LEFT, p_right, uv[:1], uv[:1] - [10.0, 0.0]).round(9).tolist() == [[0.0, 0.0, 1.2]]


@pytest.mark.parametrize("v, omega, bad", [(np.ones(3), 0.1, "v"), (1.0, np.ones((2, 1)), "omega"),
                                           (np.ones((2, 2)), 0.1, "v")])
def test_unicycle_step_names_the_argument_that_does_not_broadcast(v, omega, bad):
    with pytest.raises(ValueError, match=rf"^{bad}: expected a scalar or shape \(2,\) \(one per pose\)"):
        unicycle_step(np.zeros((2, 3)), v, omega, 0.1)


@pytest.mark.parametrize("solve", [ik_srs, ik_srs_batch, ik_numeric])
def test_ik_solvers_name_a_ragged_target_or_start(solve):
    arm = iiwa14()
    T = arm.fk(np.radians([35, 50, -40, -75, 60, 45, 20]))
    ragged = [T[0].tolist(), T[1, :3].tolist()]
    with pytest.raises(TypeError, match=r"^T: expected an array"):
        solve(arm, ragged)
    with pytest.raises(TypeError, match=r"^q0: expected an array"):
        solve(arm, T, [[0.0] * 7, [0.0] * 6])


def test_a_scalar_input_is_not_reported_at_index_empty():
    with pytest.raises(GeodesyError) as info:
        vincenty_inverse(0.0, 0.0, 0.0, np.pi)                       # antipodal: no convergence
    assert "index" not in str(info.value) and str(info.value).startswith("lat1, lon1, lat2, lon2:")
    with pytest.raises(GeodesyError, match=r"at index \(1,\)"):
        vincenty_inverse(np.zeros(2), np.zeros(2), np.zeros(2), np.array([1.0, np.pi]))
