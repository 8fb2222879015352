import numpy as np
import pytest

from robokit.validation import (as_array, as_points, as_rng, check_choice, check_finite_scalar,
                                check_int, check_positive)


def test_as_array_checks_shape_and_names_argument():
    assert as_array([[1, 2, 3]], "x", shape=(None, 3)).shape == (1, 3)
    with pytest.raises(ValueError, match=r"pose: expected shape \(4, 4\), got shape \(3, 3\)"):
        as_array(np.eye(3), "pose", shape=(4, 4))


def test_as_array_rejects_nan_and_objects():
    with pytest.raises(ValueError, match="x: expected finite"):
        as_array([1.0, np.nan], "x")
    with pytest.raises(TypeError, match="x:"):
        as_array(["a", None], "x")


def test_as_points_promotes_single_point():
    assert as_points([1, 2, 3], "p", 3).shape == (1, 3)
    with pytest.raises(ValueError, match="at least 2 points"):
        as_points([[1, 2]], "p", 2, min_count=2)


def test_scalars():
    assert check_finite_scalar(np.float32(2), "a") == 2.0
    with pytest.raises(TypeError, match="a: expected a real number"):
        check_finite_scalar(True, "a")
    with pytest.raises(ValueError, match="f: expected a positive number, got -1.0"):
        check_positive(-1, "f")
    assert check_positive(0, "f", allow_zero=True) == 0
    with pytest.raises(ValueError):
        check_positive(float("inf"), "f")


def test_ints_and_choices():
    assert check_int(np.int64(3), "n", minimum=1) == 3
    with pytest.raises(TypeError):
        check_int(3.0, "n")
    with pytest.raises(ValueError, match="n: expected an integer >= 1, got 0"):
        check_int(0, "n", minimum=1)
    with pytest.raises(ValueError, match="mode"):
        check_choice("x", "mode", ["a", "b"])


def test_rng_is_reproducible():
    assert as_rng(5).random() == as_rng(5).random()
    g = np.random.default_rng(1)
    assert as_rng(g) is g
    with pytest.raises(TypeError, match="rng"):
        as_rng(np.random.RandomState(0))
