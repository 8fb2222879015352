"""Every ``.npz`` reader of robokit against hostile files, and every writer against an interrupted save.

The readers share :func:`robokit.files.read_npz`, which checks the file's kind and size and each
array's declared size before it reads data; each reader refuses a hostile file with its own named
error (issue "Bad input and hostile files in the lesson 02-04 APIs").
"""
import io
import zipfile
from pathlib import Path

import numpy as np
import pytest

from robokit.cache import read_arrays
from robokit.files import NpzFileError, read_npz, save_npz
from robokit.legged.trial_log import TrialLogError, load_trial, save_trial
from robokit.mapping.topological import TopologicalMap
from robokit.sim.runs import Run
from robokit.vision.bag_of_words import Vocabulary, VocabularyFileError
from robokit.vision.bow_database import BowDatabase, DatabaseFileError
from tests.legged_logs import synthetic_log
from tests.test_mapping_topological import small_map


def _vocabulary() -> Vocabulary:
    rng = np.random.default_rng(0)
    return Vocabulary.train([rng.integers(0, 256, (60, 32), dtype=np.uint8) for _ in range(3)], branching=3,
                            levels=2, rng=0)


def _database() -> BowDatabase:
    db = BowDatabase(_vocabulary())
    db.add(np.random.default_rng(1).integers(0, 256, (40, 32), dtype=np.uint8))
    return db


def _run() -> Run:
    t = np.arange(4.0)
    poses = np.zeros((4, 3))
    return Run(t, poses, poses.copy(), {}, {}, {"lidar": np.ones((4, 8))}, {"world": "test"})


# name: (load, the error it names, save a valid file at a path)
READERS = {
    "TopologicalMap.load": (TopologicalMap.load, ValueError, lambda p: small_map().save(p)),
    "Vocabulary.load": (Vocabulary.load, VocabularyFileError, lambda p: _vocabulary().save(p)),
    "BowDatabase.load": (BowDatabase.load, DatabaseFileError, lambda p: _database().save(p)),
    "load_trial": (load_trial, TrialLogError, lambda p: save_trial(p, synthetic_log(12))),
    "Run.load": (Run.load, ValueError, lambda p: _run().save(p)),
}


def _npy_header(shape, descr="<f8") -> bytes:
    """An ``.npy`` header declaring ``shape`` and ``descr``, with no data after it."""
    text = f"{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape!r}, }}".encode()
    text += b" " * (63 - (10 + len(text)) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text


def _zip(members: dict) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return buffer.getvalue()


def _hostile(valid: bytes) -> dict:
    return {
        "empty": b"",
        "text": b"this is not an archive\n",
        "truncated": valid[: len(valid) // 2],
        "zeroed middle": valid[: len(valid) // 3] + bytes(len(valid) // 3) + valid[2 * len(valid) // 3:],
        "a 10^12-row header": _zip({"poses.npy": _npy_header((10**12, 3)), "format.npy": _npy_header(())}),
        "Python objects": _zip({"poses.npy": _npy_header((3,), "|O")}),
        "a foreign member": _zip({"poses.txt": b"1 2 3"}),
        "a damaged header": _zip({"poses.npy": b"\x93NUMPY\x01\x00\x20\x00{'descr': (((((((((((((((\n"}),
    }


@pytest.mark.parametrize("reader", sorted(READERS))
def test_a_hostile_file_gets_the_readers_named_error(reader, tmp_path):
    load, error, save = READERS[reader]
    valid = tmp_path / "valid.npz"
    save(valid)
    load(valid)                                                   # the writer's file reads back
    for label, data in _hostile(valid.read_bytes()).items():
        path = tmp_path / f"{label}.npz"
        path.write_bytes(data)
        with pytest.raises(error):
            load(path)
    for path in (Path("/dev/zero"), tmp_path):                    # a device never ends; a directory
        with pytest.raises(error):
            load(path)
    with pytest.raises(FileNotFoundError):
        load(tmp_path / "missing.npz")


@pytest.mark.parametrize("reader", sorted(READERS))
def test_an_interrupted_save_leaves_the_old_file(reader, tmp_path, monkeypatch):
    load, _, save = READERS[reader]
    target = tmp_path / "file.npz"
    save(target)
    before = target.read_bytes()

    def half_then_fail(out, arrays):
        if hasattr(out, "write"):
            out.write(b"PK\x03\x04 half a file")
        else:
            Path(out).write_bytes(b"PK\x03\x04 half a file")
        raise KeyboardInterrupt("interrupted")

    import importlib
    module = importlib.import_module(load.__module__)
    monkeypatch.setattr(module, "save_npz", half_then_fail)
    with pytest.raises(KeyboardInterrupt):
        save(target)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file.npz"]


def test_read_npz_bounds_size_count_and_values_before_reading(tmp_path):
    target = save_npz(tmp_path / "a.npz", {"a": np.arange(10), "b": np.zeros(3)})
    assert read_npz(target)["a"].tolist() == list(range(10))
    for bounds, what in [({"max_bytes": 10}, "bytes"), ({"max_arrays": 1}, "members"), ({"max_values": 5}, "values")]:
        with pytest.raises(NpzFileError, match=what):
            read_npz(target, **bounds)
    big = tmp_path / "big.npz"
    big.write_bytes(_zip({"a.npy": _npy_header((10**12,))}))
    with pytest.raises(NpzFileError, match="declares 1000000000000 values"):
        read_npz(big)
    assert read_arrays(big, ["a"]) is None                        # a cache file is rebuilt instead
    fortran = save_npz(tmp_path / "f.npz", {"m": np.asfortranarray(np.arange(6.0).reshape(2, 3))})
    np.testing.assert_array_equal(read_npz(fortran)["m"], np.arange(6.0).reshape(2, 3))


def test_a_trial_log_whose_metadata_nests_deeply_is_refused(tmp_path):
    target = tmp_path / "deep.npz"
    arrays = {name: value for name, value in read_npz(save_trial(tmp_path / "ok.npz", synthetic_log(12))).items()}
    arrays["__meta__"] = np.array("[" * 100_000 + "]" * 100_000)
    save_npz(target, arrays)
    with pytest.raises(TrialLogError, match="not JSON"):
        load_trial(target)


def test_a_database_file_with_too_many_entries_is_refused_before_adding_them(tmp_path, monkeypatch):
    import robokit.vision.bow_database as bow_database

    target = _database().save(tmp_path / "db.npz")
    monkeypatch.setattr(bow_database, "MAX_ENTRIES", 0)
    with pytest.raises(DatabaseFileError, match="entries"):
        BowDatabase.load(target)
