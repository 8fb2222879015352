"""The trial log: exact save/load round trip, and every way a file or a log can be wrong refused by name."""
from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robokit.legged.trial_log import describe_layout, load_trial, save_trial
from robokit.legged.trial_log import (LOG_FORMAT, LOG_LAYOUT, LOG_VERSION, META_KEYS, TrialLog, TrialLogError,
                                      empty_streams, trial_meta)
from tests.legged_logs import synthetic_log


@pytest.fixture(scope="module")
def log():
    return synthetic_log(40, seed=1)


def _rewrite(src, dst, change):
    """Copy a saved log's arrays into a new npz after ``change(arrays)`` (a hand-made bad file)."""
    with np.load(src, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    change(arrays)
    np.savez_compressed(dst, **arrays)
    return dst


def test_round_trip_is_exact(log, tmp_path):
    path = save_trial(tmp_path / "trial.npz", log)
    back = load_trial(path)
    assert list(back.streams) == list(LOG_LAYOUT) and len(back) == len(log) == 40
    for name, spec in LOG_LAYOUT.items():
        a, b = log.streams[name], back.streams[name]
        assert b.dtype == np.dtype(spec.dtype) and b.shape == (40,) + spec.shape
        np.testing.assert_array_equal(a, b)                 # bit for bit, bools too
    assert dict(back.meta) == dict(log.meta)
    assert back.meta["gait"] == "crawl" and back.meta["link_latency"] == 0.01 and back.meta["seed"] == 1
    # the file is plain numpy: metadata and layout readable without robokit
    with np.load(path, allow_pickle=False) as data:
        meta = json.loads(str(data["__meta__"]))
        layout = json.loads(str(data["__layout__"]))
    assert (meta["format"], meta["version"]) == (LOG_FORMAT, LOG_VERSION)
    assert layout["feet"] == {"shape": [4, 3], "dtype": "float64", "unit": "m", "description": LOG_LAYOUT["feet"].description}
    assert sorted(f.name for f in tmp_path.iterdir()) == ["trial.npz"]       # no temporary left behind


def test_attributes_views_and_slices(log):
    assert log.q is log.streams["q"] and log.feet.shape == (40, 4, 3)
    with pytest.raises(ValueError):
        log.q[0, 0] = 1.0                                   # read-only
    with pytest.raises(AttributeError, match="no attribute 'qq'"):
        log.qq
    part = log.slice(10, -5)
    assert len(part) == 25 and part.t[0] == log.t[10] and part.meta["gait"] == "crawl"
    np.testing.assert_array_equal(part.feet, log.feet[10:35])
    with pytest.raises(ValueError, match="start, stop"):
        log.slice(30, 30)


def test_T_world_body_matches_scipy(log):
    T = log.T_world_body()
    q = log.body_quat
    R = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()       # scipy's order is [x, y, z, w]
    np.testing.assert_allclose(T[:, :3, :3], R, atol=1e-15)
    np.testing.assert_array_equal(T[:, :3, 3], log.body_pos)
    np.testing.assert_array_equal(T[:, 3], np.tile([0, 0, 0, 1.0], (40, 1)))


@pytest.mark.parametrize("keep", [0, 10, 100, 0.3, 0.9, 0.99, -22, -1])
def test_truncated_file_is_refused(log, tmp_path, keep):
    data = save_trial(tmp_path / "full.npz", log).read_bytes()
    cut = int(len(data) * keep) if isinstance(keep, float) else keep % len(data) if keep < 0 else keep
    target = tmp_path / "cut.npz"
    target.write_bytes(data[:cut])
    with pytest.raises(TrialLogError, match="cut.npz: not a readable trial log .truncated or corrupt"):
        load_trial(target)


def test_corrupt_bytes_are_refused(log, tmp_path):
    data = bytearray(save_trial(tmp_path / "full.npz", log).read_bytes())
    data[len(data) // 3:len(data) // 3 + 64] = bytes(64)          # zeros in the middle of a member
    target = tmp_path / "bad.npz"
    target.write_bytes(bytes(data))
    with pytest.raises(TrialLogError, match="truncated or corrupt"):
        load_trial(target)


def test_another_version_says_which(log, tmp_path):
    src = save_trial(tmp_path / "v1.npz", log)

    def bump(arrays):
        meta = json.loads(str(arrays["__meta__"]))
        arrays["__meta__"] = np.array(json.dumps({**meta, "version": 2}))

    with pytest.raises(TrialLogError, match=r"v2.npz: a robokit-littledog-trial file of version 2; this code reads version 1"):
        load_trial(_rewrite(src, tmp_path / "v2.npz", bump))


@pytest.mark.parametrize("change, message", [
    (lambda a: a.pop("__meta__"), "not a robokit-littledog-trial file .it has no __meta__"),
    (lambda a: a.update(__meta__=np.array(json.dumps({"format": "robokit-vocabulary-1"}))),
     "a file of format 'robokit-vocabulary-1', not a 'robokit-littledog-trial' trial log"),
    (lambda a: a.update(__meta__=np.array("{not json")), "__meta__ record is not JSON"),
])
def test_another_format_is_refused(log, tmp_path, change, message):
    src = save_trial(tmp_path / "ok.npz", log)
    with pytest.raises(TrialLogError, match=message):
        load_trial(_rewrite(src, tmp_path / "other.npz", change))


def test_a_plain_npy_or_text_file_is_refused(tmp_path):
    np.save(tmp_path / "x.npy", np.arange(3))
    with pytest.raises(TrialLogError, match="x.npy: not a robokit-littledog-trial file .one .npy array"):
        load_trial(tmp_path / "x.npy")
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(TrialLogError, match="notes.txt: not a readable trial log"):
        load_trial(tmp_path / "notes.txt")
    with pytest.raises(FileNotFoundError):
        load_trial(tmp_path / "absent.npz")


@pytest.mark.parametrize("change, message", [
    (lambda a: a.pop("foot_force"), r"stream\(s\) \['foot_force'\] missing"),
    (lambda a: a.update(q=a["q"][:, :11]), r"streams\['q'\]: expected shape \(N, 12\).*got shape \(40, 11\)"),
    (lambda a: a.update(feet=a["feet"][:39]), r"streams\['feet'\]: expected shape \(N, 4, 3\).*got shape \(39, 4, 3\) \(40 rows in t\)"),
    (lambda a: a.update(contact=a["contact"] * 0.5), r"streams\['contact'\]"),
    (lambda a: a.update(t=a["t"][::-1].copy()), r"streams\['t'\]: expected strictly increasing"),
    (lambda a: a.update(body_quat=a["body_quat"] * 2), r"streams\['body_quat'\]: expected unit quaternions"),
    (lambda a: a.update(extra=np.zeros(40)), r"unknown \['extra'\]"),
])
def test_missing_or_misshapen_stream_in_a_file(log, tmp_path, change, message):
    src = save_trial(tmp_path / "ok.npz", log)
    with pytest.raises(TrialLogError, match="bad.npz: .*" + message):
        load_trial(_rewrite(src, tmp_path / "bad.npz", change))


def test_nan_in_a_stream_is_named(log, tmp_path):
    src = save_trial(tmp_path / "ok.npz", log)

    def poison(arrays):
        arrays["imu_acc"] = arrays["imu_acc"].copy()
        arrays["imu_acc"][3, 1] = np.nan

    with pytest.raises(TrialLogError, match=r"streams\['imu_acc'\]: expected finite values"):
        load_trial(_rewrite(src, tmp_path / "nan.npz", poison))


def test_empty_log_is_refused():
    with pytest.raises(ValueError, match="n: expected an integer >= 1"):
        empty_streams(0)
    streams = {k: v[:0] for k, v in empty_streams(3).items()}
    with pytest.raises(TrialLogError, match=r"streams\['t'\]: expected shape \(N\) with N >= 1 rows"):
        TrialLog(streams, trial_meta())


def test_one_row_is_a_log(tmp_path):
    one = TrialLog(empty_streams(1), trial_meta(notes="a single cycle"))
    assert len(load_trial(save_trial(tmp_path / "one.npz", one))) == 1


def test_bad_metadata_is_named():
    streams = empty_streams(2)
    with pytest.raises(TrialLogError, match=r"meta: expected the keys .* missing \['servo_rate'"):
        TrialLog(streams, {"host_rate": 100.0})
    with pytest.raises(TrialLogError, match=r"meta\['version'\]: expected 1"):
        TrialLog(streams, {**trial_meta(), "version": 3})
    with pytest.raises(ValueError, match=r"meta\['link_loss'\]: expected a fraction"):
        trial_meta(link_loss=1.5)
    with pytest.raises(ValueError, match=r"meta\['host_rate'\]: expected a positive"):
        trial_meta(host_rate=-100)
    with pytest.raises(TypeError, match="meta: expected JSON-able"):
        trial_meta(extra=object())
    assert trial_meta(pid_gains=np.array([1.0, 2.0]).tolist(), trials=np.int64(3))["trials"] == 3


def test_validate_catches_a_log_changed_behind_its_back():
    streams = empty_streams(3)
    log = TrialLog(streams, trial_meta())
    streams["t"][2] = 0.0                     # the caller's own array, which the log views
    with pytest.raises(TrialLogError, match="strictly increasing"):
        log.validate()
    with pytest.raises(TrialLogError, match="strictly increasing"):
        save_trial("/tmp/never-written.npz", log)


def test_wrong_types_name_the_argument(log):
    with pytest.raises(TypeError, match="path: expected a file path"):
        save_trial(42, log)
    with pytest.raises(TypeError, match="log: expected a TrialLog"):
        save_trial("/tmp/x.npz", {"q": 1})
    with pytest.raises(TypeError, match="streams: expected a dict"):
        TrialLog([1, 2], trial_meta())
    with pytest.raises(TypeError, match="meta: expected a dict"):
        TrialLog(empty_streams(2), "crawl")


def test_layout_table_lists_every_stream_with_units():
    text = describe_layout()
    lines = text.splitlines()
    for name, spec in LOG_LAYOUT.items():
        row = next(line for line in lines if line.split()[0] == name)
        assert spec.unit in row and spec.description in row
    for key in META_KEYS:
        assert any(line.split()[:1] == [key] for line in lines)
    assert "one row per host cycle" in text


def test_zip_members_are_the_streams(log, tmp_path):
    with zipfile.ZipFile(save_trial(tmp_path / "z.npz", log)) as z:
        names = sorted(n.removesuffix(".npy") for n in z.namelist())
    assert names == sorted(list(LOG_LAYOUT) + ["__meta__", "__layout__"])
