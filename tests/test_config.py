import numpy as np
import pytest

import robokit
from robokit.config import cache_dir, cache_key, fast_mode


@pytest.mark.parametrize("raw, expected", [("1", True), ("true", True), ("ON", True), ("0", False),
                                           ("", False), ("no", False)])
def test_fast_mode_reads_the_variable(raw, expected):
    assert fast_mode({"ROBOKIT_FAST": raw}) is expected


def test_fast_mode_unset_is_false():
    assert fast_mode({}) is False


def test_fast_mode_rejects_typos():
    with pytest.raises(ValueError, match="ROBOKIT_FAST"):
        fast_mode({"ROBOKIT_FAST": "fats"})


def test_package_exposes_fast_flag():
    assert isinstance(robokit.FAST, bool)


def test_cache_dir_honours_override(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBOKIT_CACHE", str(tmp_path / "c"))
    d = cache_dir("runs")
    assert d == (tmp_path / "c" / "runs").resolve() and d.is_dir()


def test_cache_dir_uses_xdg(tmp_path, monkeypatch):
    monkeypatch.delenv("ROBOKIT_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache_dir(create=False) == (tmp_path / "robokit").resolve()


@pytest.mark.parametrize("bad", ["", "..", "a/b"])
def test_cache_dir_rejects_path_tricks(bad):
    with pytest.raises(ValueError, match="parts"):
        cache_dir(bad, create=False)


def test_cache_key_is_stable_and_order_free():
    assert cache_key(a=1, b=[1, 2]) == cache_key(b=[1, 2], a=1)
    assert cache_key(a=1) != cache_key(a=2)
    assert len(cache_key(a=1)) == 16


def test_cache_key_rejects_unserialisable():
    with pytest.raises(TypeError, match="params"):
        cache_key(a=np.zeros(2))
