import os
import platform
import subprocess
import sys

import numpy as np
import pytest

import robokit
from robokit.config import HEAP_PAD_MB, fast_mode, pad_heap
from robokit.cache import cache_dir, cache_key


@pytest.mark.parametrize("raw, expected", [("1", True), ("true", True), ("ON", True), ("0", False),
                                           ("", False), ("no", False)])
def test_fast_mode_reads_the_variable(raw, expected):
    assert fast_mode({"ROBOKIT_FAST": raw}) is expected


def test_fast_mode_unset_is_false():
    assert fast_mode({}) is False


def test_fast_mode_rejects_typos():
    with pytest.raises(ValueError, match="ROBOKIT_FAST"):
        fast_mode({"ROBOKIT_FAST": "fats"})


def test_the_course_exposes_fast_mode_and_the_library_does_not():
    import robocourse

    assert isinstance(robocourse.FAST, bool) and not hasattr(robokit, "FAST")


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


# --- cache files: a corrupt, truncated or stale file is rebuilt, never loaded -------------------

def _cache_file(tmp_path, meta):
    from robokit.cache import write_arrays

    return write_arrays(tmp_path / "c.npz", {"a": np.arange(1000.0), "b": np.eye(3)}, meta)


def test_write_arrays_round_trip_needs_equal_parameters(tmp_path):
    from robokit.cache import code_version, read_arrays

    meta = {"n": 3, "x": [0.5, 1.0], "code": code_version("geometry")}
    target = _cache_file(tmp_path, meta)
    data = read_arrays(target, ["a", "b"], {"code": code_version("geometry"), "x": [0.5, 1.0], "n": 3})  # key order free
    assert data is not None and np.array_equal(data["a"], np.arange(1000.0))
    assert read_arrays(target, ["a"], {**meta, "n": 4}) is None                                 # other parameters
    assert read_arrays(target, ["a"], {**meta, "code": {**meta["code"], "robokit": "0" * 16}}) is None  # other code
    assert read_arrays(target, ["a"], {**meta, "code": {**meta["code"], "numpy": "0.0"}}) is None      # other numpy
    assert read_arrays(target, ["a", "missing"], meta) is None
    assert sorted(read_arrays(target, ["a"]).keys()) == ["a"]        # a caller without parameters reads it too


def test_a_file_without_parameters_is_not_served_to_a_caller_with_them(tmp_path):
    from robokit.cache import read_arrays, write_arrays

    target = write_arrays(tmp_path / "c.npz", {"a": np.arange(3)})
    assert read_arrays(target, ["a"]) is not None and read_arrays(target, ["a"], {"n": 3}) is None


@pytest.mark.parametrize("damage", ["truncated", "zeroed middle", "flipped byte", "empty", "text", "directory"])
def test_a_damaged_cache_file_reads_as_none(tmp_path, damage):
    from robokit.cache import read_arrays

    meta = {"n": 3}
    target = _cache_file(tmp_path, meta)
    raw = bytearray(target.read_bytes())
    if damage == "truncated":
        target.write_bytes(raw[: len(raw) // 2])
    elif damage == "zeroed middle":
        raw[200:-200] = bytes(len(raw) - 400)
        target.write_bytes(raw)
    elif damage == "flipped byte":          # inside the compressed data of an array: the CRC check finds it
        raw[len(raw) // 3] ^= 0xFF
        target.write_bytes(raw)
    elif damage == "empty":
        target.write_bytes(b"")
    elif damage == "text":
        target.write_text("not a cache file")
    else:
        target.unlink()
        target.mkdir()
    assert read_arrays(target, ["a", "b"], meta) is None


def test_write_arrays_refuses_bad_input(tmp_path):
    from robokit.cache import write_arrays

    with pytest.raises(TypeError, match="meta"):
        write_arrays(tmp_path / "c.npz", {"a": np.zeros(2)}, {"a": np.zeros(2)})
    with pytest.raises(ValueError, match="arrays"):
        write_arrays(tmp_path / "c.npz", {"cache_meta": np.zeros(2)}, {"n": 1})
    with pytest.raises(TypeError, match="arrays"):
        write_arrays(tmp_path / "c.npz", [np.zeros(2)])
    assert not list(tmp_path.iterdir())               # nothing half written is left behind


def test_code_version_names_the_code_and_the_numerics():
    from robokit.cache import code_version, source_digest

    v = code_version("sim", "geometry")
    assert v["robokit"] == source_digest("sim", "geometry") and v["numpy"] == np.__version__
    assert code_version("sim") != v
    with pytest.raises(ValueError, match="packages"):
        code_version("no_such_package")


# --- progress bars ----------------------------------------------------------------------------

def test_progress_bar_headless_prints_one_final_line(capsys):
    from robokit.progress import progress_bar

    seen = []
    with progress_bar(50, "mapping", unit="frame", callback=lambda d, t: seen.append((d, t)),
                      environ={"ROBOKIT_HEADLESS": "1"}) as bar:
        for k in range(50):
            bar(k + 1, 50)
    out = capsys.readouterr()
    assert out.out.count("\n") == 1 and "\r" not in out.out and out.err == ""
    assert out.out.startswith("mapping: 100%") and "50/50" in out.out
    assert seen[-1] == (50, 50) and len(seen) == 50          # the caller's own callback still runs


def test_progress_bar_is_quiet_in_fast_mode_and_live_otherwise(capsys):
    from robokit.progress import progress_bar

    with progress_bar(3, "quiet", environ={"ROBOKIT_FAST": "1", "ROBOKIT_HEADLESS": "1"}) as bar:
        bar.update(3)
    assert capsys.readouterr() == ("", "")
    with progress_bar(3, "live", unit="trial", environ={}) as bar:   # a terminal: tqdm's own bar
        bar.update()
        bar.update(2)
    out = capsys.readouterr()
    assert out.out == "" and "live: 100%" in out.err and "3/3" in out.err
    assert bar.done == 3


@pytest.mark.parametrize("kwargs, error, match", [({"total": -1}, ValueError, "total"), ({"total": 2.5}, TypeError, "total"),
                                                  ({"total": True}, TypeError, "total"),
                                                  ({"desc": ""}, ValueError, "desc"), ({"unit": " "}, ValueError, "unit")])
def test_progress_bar_refuses_bad_input(kwargs, error, match):
    from robokit.progress import progress_bar

    args = {"total": 3, "desc": "x", **kwargs}
    with pytest.raises(error, match=match):
        progress_bar(args.pop("total"), args.pop("desc"), **args)
    with pytest.raises(TypeError, match="callback"):
        progress_bar(3, "x", callback=3)
    assert progress_bar(np.int64(3), "x", environ={"ROBOKIT_FAST": "1"}).total == 3     # a numpy count is a count


def test_lazy_module_runs_the_module_on_first_use_only():
    import subprocess
    import sys

    code = ("import sys\nfrom robokit.config import lazy_module\n"
            "m = lazy_module('fractions')\nassert lazy_module('fractions') is m and 'fractions' in sys.modules\n"
            "before = 'decimal' in sys.modules       # fractions imports decimal when it runs\n"
            "half = m.Fraction(1, 2)\n"
            "print(before, 'decimal' in sys.modules, half)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "True", "1/2"]
    from robokit.config import lazy_module
    assert lazy_module("os") is __import__("os")
    with pytest.raises(ModuleNotFoundError, match="no_such_module_here"):
        lazy_module("no_such_module_here")
    with pytest.raises(TypeError, match="name"):
        lazy_module(42)


def test_importing_robokit_leaves_python_control_and_scipy_stats_for_later():
    import subprocess
    import sys

    code = ("import sys\nfrom robokit import controllers, localization, mapping, sim, vision\n"
            "print(type(sys.modules['control']).__name__, 'scipy.stats' in sys.modules)\n"
            "controllers.path_following_poles(1.0, 0.3)\nprint(type(sys.modules['control']).__name__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["_LazyModule", "False", "module"], out


def test_the_kld_quantile_is_scipys():
    from scipy.stats import norm

    from robokit.localization.particle_filter import KLD_Z_99

    assert KLD_Z_99 == float(norm.ppf(0.99))


GLIBC = sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc"

#: Page faults per round of four 1.9 MB arrays made and freed (a filter update's pattern), after warming up.
FAULTS = """
import resource, sys, numpy as np, robokit
from robokit.config import pad_heap
def update():
    arrays = [np.ones((2000, 60, 2)) for _ in range(4)]
    return float(np.exp(arrays[0]).sum())
for _ in range(3):
    update()
start = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(20):
    update()
print((resource.getrusage(resource.RUSAGE_SELF).ru_minflt - start) / 20)
"""


def _python(code: str, **env: str) -> subprocess.CompletedProcess:
    environ = {k: v for k, v in os.environ.items() if not k.startswith(("MALLOC_", "GLIBC_TUNABLES", "ROBOKIT_HEAP"))}
    return subprocess.run([sys.executable, "-c", code], env={**environ, **env}, capture_output=True, text=True)


@pytest.mark.skipif(not GLIBC, reason="glibc's mallopt only")
def test_the_heap_pad_keeps_a_filter_updates_arrays_mapped():
    runs = {pad: _python(FAULTS, ROBOKIT_HEAP_PAD_MB=pad) for pad in ("64", "0")}
    assert all(r.returncode == 0 for r in runs.values()), [r.stderr[-400:] for r in runs.values()]
    padded, default = (float(r.stdout) for r in runs.values())
    if default < 400:            # the four arrays are 1900 pages of 4 KiB; huge pages or earlier frees hide it
        pytest.skip(f"glibc's default faulted only {default} pages a round here: nothing to keep")
    assert padded < 10


@pytest.mark.skipif(not GLIBC, reason="glibc's mallopt only")
def test_the_heap_pad_reads_its_variable_and_leaves_a_users_own_setting():
    code = ("from robokit.config import pad_heap\n"
            "print([pad_heap(e) for e in ({}, {'ROBOKIT_HEAP_PAD_MB': '16'}, {'ROBOKIT_HEAP_PAD_MB': '0'},"
            " {'MALLOC_TOP_PAD_': '4096'}, {'GLIBC_TUNABLES': 'glibc.malloc.trim_threshold=1'})])")
    assert _python(code).stdout.strip() == str([HEAP_PAD_MB << 20, 16 << 20, 0, 0, 0])


@pytest.mark.parametrize("bad", ["lots", "-1", "1025", "1.5"])
def test_the_heap_pad_refuses_a_bad_variable(bad):
    with pytest.raises(ValueError, match="ROBOKIT_HEAP_PAD_MB"):
        pad_heap({"ROBOKIT_HEAP_PAD_MB": bad})
    with pytest.raises(TypeError, match="environ"):
        pad_heap(["ROBOKIT_HEAP_PAD_MB"])


def test_import_robokit_warns_of_a_bad_heap_pad_and_goes_on():
    done = _python("import warnings; warnings.simplefilter('error'); import robokit", ROBOKIT_HEAP_PAD_MB="plenty")
    assert done.returncode != 0 and "ROBOKIT_HEAP_PAD_MB" in done.stderr       # it is a warning, named
    assert _python("import robokit.geometry", ROBOKIT_HEAP_PAD_MB="plenty").returncode == 0
