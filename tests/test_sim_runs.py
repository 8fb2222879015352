"""Recorded runs: contents, .npz round trip without pickle, caching by parameters."""
import numpy as np
import pytest

from robokit.sim import (Lidar, OmniCamera, PinholeCamera, Run, StereoRig, box_room, lab_lap, lab_room, record,
                         record_stream, waypoint_path)


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


class NoisyCamera(PinholeCamera):
    """A caller's camera that draws pixel noise in observe: it must stay in order, seeded."""

    def observe(self, world, robot_pose, **kwargs):
        return super().observe(world, robot_pose, noise=3.0, **kwargs)


@pytest.mark.parametrize("workers", ["1", "2"])
def test_a_recording_equals_every_sensor_observed_in_turn(cache, monkeypatch, workers):
    # robokit's cameras are rendered in worker batches, the rest here: the recording is what the
    # plain loop over poses and sensors (odometry first, one generator) gives
    from robokit.sim import noisy_odometry
    monkeypatch.setenv("ROBOKIT_WORKERS", workers)
    world = box_room()
    path = waypoint_path([[1.0, 1.0], [4.5, 1.0], [4.5, 3.0], [1.0, 3.0]], speed=0.5, rate=2)
    cam = PinholeCamera.from_fov(width=48, height=36)
    sensors = {"laser": Lidar(beams=30, noise=0.01), "cam": cam, "noisy": NoisyCamera.from_fov(width=24, height=18),
               "stereo": StereoRig(cam, 0.1), "laser2": Lidar(beams=20, noise=0.02)}
    run = record(world, path, sensors, rate=5.0, seed=4, cache=False)
    assert len(run) >= 64                                   # enough frames for several batches
    rng = np.random.default_rng(4)
    assert np.array_equal(run.odometry, noisy_odometry(run.poses, (0.01, 0.001, 0.01, 0.001), rng))
    for k, pose in enumerate(run.poses):
        for name, sensor in sensors.items():
            seen = sensor.observe(world, pose, rng=rng)
            if isinstance(seen, np.ndarray):
                assert np.array_equal(run.scans[name][k], seen), (name, k)
                continue
            for sub, frame in (seen.items() if isinstance(seen, dict) else [("", seen)]):
                key = f"{name}/{sub}" if sub else name
                assert np.array_equal(run.images[key][k], frame.image), (key, k)
                assert np.array_equal(run.depths[key][k], frame.depth), (key, k)
    assert list(run.images) == ["cam", "noisy", "stereo/left", "stereo/right"]      # in the sensors' order
    assert list(run.scans) == ["laser", "laser2"]
    other = record(world, path, sensors, rate=5.0, seed=5, cache=False)
    assert not np.array_equal(other.images["noisy"], run.images["noisy"])      # the seed reaches its noise


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


@pytest.mark.parametrize("workers", ["1", "2"])
def test_a_stream_is_the_recording_without_storing_it(cache, monkeypatch, workers):
    monkeypatch.setenv("ROBOKIT_WORKERS", workers)
    world = box_room()
    path = waypoint_path([[1.0, 1.0], [4.5, 1.0], [4.5, 3.0]], speed=0.5, rate=2)
    cam = PinholeCamera.from_fov(width=48, height=36)
    run = record(world, path, {"cam": cam}, rate=5.0, seed=6, cache=False)
    stream = record_stream(world, path, cam, rate=5.0, seed=6)
    assert len(stream) == len(run) >= 2 * 16                     # several batches of frames
    for name in ("t", "poses", "odometry"):
        assert np.array_equal(getattr(stream, name), getattr(run, name)), name
    with stream:
        images = list(stream.frames)
    assert len(images) == len(run) and np.array_equal(np.stack(images), run.images["cam"])
    assert list(stream.frames) == []                              # made once
    with record_stream(world, path, cam, rate=5.0, seed=6) as again:  # left early: the rendering stops
        assert np.array_equal(next(again.frames), images[0])
    assert list(again.frames) == []
    assert not (cache / "runs").exists() or not list((cache / "runs").glob("*.npz"))     # nothing stored


def test_a_stream_takes_one_robokit_camera():
    world, path = box_room(), [[1.0, 1.0, 0.0], [1.5, 1.0, 0.0]]
    cam = PinholeCamera.from_fov(width=48, height=36)
    for bad in (StereoRig(cam, 0.1), Lidar(beams=8), NoisyCamera.from_fov(width=24, height=18), "cam"):
        with pytest.raises(TypeError, match="camera"):
            record_stream(world, path, bad, rate=1.0)
    with pytest.raises(TypeError, match="world"):
        record_stream("box_room", path, cam, rate=1.0)
    with pytest.raises(ValueError, match="path"):
        record_stream(world, [[-5.0, 1.0, 0.0], [1.0, 1.0, 0.0]], cam, rate=1.0)
    with pytest.raises(ValueError, match="seed"):
        record_stream(world, path, cam, rate=1.0, seed=-1)


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
    ({"sensors": {0: Lidar(beams=8)}}, "sensors"),
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
