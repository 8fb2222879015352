"""Recorded runs: contents, .npz round trip without pickle, caching by parameters."""
import numpy as np
import pytest

from robokit.sim import (Lidar, OmniCamera, PinholeCamera, Run, StereoRig, box_room, lab_lap, lab_room, record,
                         waypoint_path)


@pytest.fixture()
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBOKIT_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def small_sensors():
    cam = PinholeCamera.from_fov(width=80, height=60)
    return {"cam": cam, "stereo": StereoRig(cam, 0.1), "laser": Lidar(beams=90, noise=0.01)}


def test_record_contents_and_round_trip(cache, tmp_path):
    world = box_room()
    path = waypoint_path([[1.0, 1.0], [4.0, 1.0], [4.0, 3.0]], speed=0.5, rate=2)
    run = record(world, path, small_sensors(), rate=1.0, seed=3)
    n = len(run)
    assert n == len(run.poses) == len(run.odometry) and n >= 8
    assert run.images["cam"].shape == (n, 60, 80, 3) and run.images["cam"].dtype == np.uint8
    assert set(run.images) == {"cam", "stereo/left", "stereo/right"}
    assert run.scans["laser"].shape == (n, 90)
    np.testing.assert_allclose(run.poses[0], [1, 1, 0])
    assert not np.allclose(run.odometry[-1], run.poses[-1])  # noisy odometry drifts
    back = Run.load(run.save(tmp_path / "r.npz"))
    for a, b in [(run.t, back.t), (run.poses, back.poses), (run.images["stereo/right"], back.images["stereo/right"]),
                 (run.scans["laser"], back.scans["laser"]), (run.depths["cam"], back.depths["cam"])]:
        assert np.array_equal(a, b)
    assert back.meta["seed"] == 3 and back.meta["world"] == "box_room"


def test_frames_made_side_by_side_equal_the_frames_made_in_turn(cache, monkeypatch):
    # camera frames come from worker processes in batches, the noisy scans from here in order:
    # the recording does not depend on how many workers made it
    world = box_room()
    path = waypoint_path([[1.0, 1.0], [4.5, 1.0], [4.5, 3.0], [1.0, 3.0]], speed=0.5, rate=2)
    runs = {}
    for workers in ("1", "2"):
        monkeypatch.setenv("ROBOKIT_WORKERS", workers)
        runs[workers] = record(world, path, small_sensors(), rate=5.0, seed=4, cache=False)
    one, two = runs["1"], runs["2"]
    assert len(one) >= 64                                   # enough frames for several batches
    for group in ("images", "depths", "scans"):
        a, b = getattr(one, group), getattr(two, group)
        assert list(a) == list(b)
        for key in a:
            assert np.array_equal(a[key], b[key]), (group, key)
    assert np.array_equal(one.odometry, two.odometry)


def test_cache_is_keyed_by_parameters(cache):
    world = box_room()
    path = waypoint_path([[1.0, 1.0], [2.0, 1.0]], rate=2)
    a = record(world, path, small_sensors(), seed=1)
    files = list((cache / "runs").glob("*.npz"))
    assert len(files) == 1
    b = record(world, path, small_sensors(), seed=1)
    assert np.array_equal(a.images["cam"], b.images["cam"])
    assert len(list((cache / "runs").glob("*.npz"))) == 1  # loaded, not re-recorded
    record(world, path, small_sensors(), seed=2)
    assert len(list((cache / "runs").glob("*.npz"))) == 2
    c = record(world, path, small_sensors(), seed=1, cache=False)
    assert np.array_equal(a.odometry, c.odometry)  # deterministic


def test_a_corrupt_or_stale_cache_file_is_rebuilt_not_loaded(cache):
    world = box_room()
    path = waypoint_path([[1.0, 1.0], [2.0, 1.0]], rate=2)
    fresh = record(world, path, small_sensors(), seed=1, cache=False)
    record(world, path, small_sensors(), seed=1)
    (target,) = (cache / "runs").glob("*.npz")
    target.write_bytes(target.read_bytes()[:1000])  # a write cut short
    again = record(world, path, small_sensors(), seed=1)
    assert np.array_equal(again.images["cam"], fresh.images["cam"])
    # a run stored under this key by other code (another simulator version) is not served either
    stale = Run(fresh.t, fresh.poses, fresh.odometry + 1.0, fresh.images, fresh.depths, fresh.scans,
                {**fresh.meta, "code": {**fresh.meta["code"], "robokit": "0" * 16}})
    stale.save(target)
    assert np.array_equal(record(world, path, small_sensors(), seed=1).odometry, fresh.odometry)
    assert fresh.meta["code"]["numpy"] == np.__version__


def test_record_omni_and_lab_lap(cache):
    world = lab_room()
    lap = lab_lap(world, rate=1.0)
    omni = OmniCamera(width=64, height=48, face_size=48)
    run = record(world, (lap.t[:3], lap.poses[:3]), {"omni": omni}, rate=None)
    assert run.images["omni"].shape == (3, 48, 64, 3)
    assert np.isinf(run.depths["omni"][0, 0, 0])  # corner pixel is outside the mirror's annulus


@pytest.mark.parametrize("kwargs, match", [
    ({"sensors": {}}, "sensors"),
    ({"sensors": {"x": object()}}, "sensors"),
    ({"path": np.array([[1.0, 1.0, 0.0], [9.0, 1.0, 0.0]])}, "path"),
    ({"path": np.array([[1.0, np.nan, 0.0]])}, "path"),
    ({"rate": 0.0}, "rate"),
])
def test_bad_input_is_named(cache, kwargs, match):
    args = {"world": box_room(), "path": np.array([[1.0, 1.0, 0.0], [1.5, 1.0, 0.0]]),
            "sensors": {"laser": Lidar()}, "rate": 1.0}
    args.update(kwargs)
    with pytest.raises((ValueError, TypeError), match=match):
        record(**args)
