import numpy as np
import pytest

from robokit.validation import (MAX_SAMPLES, array_ndim, as_array, as_points, as_rng, broadcast_to, as_callable,
                                as_choice, require_finite_result, as_finite_scalar, as_int, as_mapping,
                                as_positive, require_sample_count, as_text)


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
    assert as_finite_scalar(np.float32(2), "a") == 2.0
    with pytest.raises(TypeError, match="a: expected a real number"):
        as_finite_scalar(True, "a")
    with pytest.raises(ValueError, match="f: expected a positive number, got -1.0"):
        as_positive(-1, "f")
    assert as_positive(0, "f", allow_zero=True) == 0
    with pytest.raises(ValueError):
        as_positive(float("inf"), "f")


def test_ints_and_choices():
    assert as_int(np.int64(3), "n", minimum=1) == 3
    with pytest.raises(TypeError):
        as_int(3.0, "n")
    with pytest.raises(ValueError, match="n: expected an integer >= 1, got 0"):
        as_int(0, "n", minimum=1)
    with pytest.raises(ValueError, match="mode"):
        as_choice("x", "mode", ["a", "b"])


def test_rng_is_reproducible():
    assert as_rng(5).random() == as_rng(5).random()
    g = np.random.default_rng(1)
    assert as_rng(g) is g
    with pytest.raises(TypeError, match="rng"):
        as_rng(np.random.RandomState(0))


# --- what counts as a number (issue 12) -------------------------------------------------------


@pytest.mark.parametrize("value, words", [
    ("1.0", "a string"), (["1", "2"], "a string"), (b"1", "bytes"), ([1 + 0j], "complex numbers"),
    ([True, False], "booleans"), ([1.0, None], "an element None"), ([[1.0, 2.0], [3.0]], "nested lists"),
    (object(), "an element"),
])
def test_as_array_refuses_what_is_not_a_real_number(value, words):
    with pytest.raises(TypeError, match=rf"^x: expected (real numbers|an array of real numbers).*{words}"):
        as_array(value, "x")


def test_as_array_accepts_real_numbers_of_any_python_or_numpy_type_unchanged():
    from fractions import Fraction
    assert as_array([Fraction(1, 2), 2**70], "x").tolist() == [0.5, 2.0**70]
    arr = np.arange(6.0).reshape(2, 3)
    assert as_array(arr, "x") is arr                                     # no copy of a float array
    assert as_array(np.float32([0.1]), "x")[0] == np.float64(np.float32(0.1))
    assert as_array([1, 2], "n", dtype=int).dtype.kind == "i"


def test_integer_arrays_take_whole_numbers_only():
    assert as_array([1.0, 2.0], "n", dtype=int).tolist() == [1, 2]
    for bad in ([1.5], [np.nan], [1e300]):
        with pytest.raises(ValueError, match="n: expected whole numbers"):
            as_array(bad, "n", dtype=int)
    with pytest.raises(TypeError, match="mask: expected booleans"):
        as_array([0, 2], "mask", dtype=bool)


def test_scalars_refuse_strings_complex_and_string_arrays():
    for bad in ("1.0", np.array("1.0"), 1j, np.complex128(1), np.array(True), np.True_):
        with pytest.raises(TypeError, match="a: expected a real number"):
            as_finite_scalar(bad, "a")
    assert as_finite_scalar(np.array(2), "a") == 2.0


def test_ints_fit_int64_and_choices_compare_by_type():
    with pytest.raises(ValueError, match="n: expected an integer <= 9223372036854775807"):
        as_int(2**63, "n")
    with pytest.raises(ValueError, match="n: expected an integer >= -9223372036854775808"):
        as_int(-(2**63) - 1, "n")
    assert as_int(2**70, "seed", maximum=None) == 2**70
    with pytest.raises(ValueError, match="mode: expected one of"):
        as_choice(np.array(["a", "b"]), "mode", ["a", "b"])     # no ambiguous truth value
    with pytest.raises(ValueError, match="mode"):
        as_choice(b"a", "mode", ["a", "b"])
    assert as_choice(np.str_("a"), "mode", ["a", "b"]) == "a"


def test_shape_helpers_name_the_argument():
    assert array_ndim(np.zeros((2, 3)), "q") == 2 and array_ndim([[1, 2], [3, 4]], "q") == 2
    with pytest.raises(TypeError, match="^q: expected an array of numbers"):
        array_ndim([[1, 2], [3]], "q")
    assert broadcast_to(np.array(1.0), (3,), "v").shape == (3,)
    with pytest.raises(ValueError, match=r"^v: expected a scalar or shape \(3,\) \(one per pose\), got shape \(2,\)"):
        broadcast_to(np.ones(2), (3,), "v", "one per pose")


def test_text_callables_mappings_results_and_sample_counts():
    assert as_text("GP", "talker") == "GP"
    for bad in (42, b"GP", None):
        with pytest.raises(TypeError, match="talker: expected a str"):
            as_text(bad, "talker")
    with pytest.raises(ValueError, match="name: expected a non-empty str"):
        as_text("", "name", empty=False)
    assert as_callable(None, "progress") is None
    with pytest.raises(TypeError, match="progress: expected a callable or None"):
        as_callable(42, "progress")
    with pytest.raises(TypeError, match="options: expected a dict"):
        as_mapping("a=1", "options")
    require_finite_result("J", np.ones(3), 2.0)
    with pytest.raises(ValueError, match="^J, e: expected values whose result is finite"):
        require_finite_result("J, e", np.ones(3), np.array([np.nan]))
    require_sample_count(MAX_SAMPLES, "rate")
    with pytest.raises(ValueError, match="rate: expected at most"):
        require_sample_count(MAX_SAMPLES + 1, "rate")
