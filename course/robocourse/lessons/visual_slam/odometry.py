"""Stereo visual odometry runs in the lesson's lab, cheap enough to make grading cases from.

The assignment's loop exercise (``01.stereo_odometry``) needs what the lesson's front end sees every
frame, without rendering: the robot drives a stretch of (a variation of) :func:`robokit.sim.lab_lap` in
:func:`robokit.sim.lab_room` at 1 frame per second (the lesson's mapping rate), and at each frame
the stereo rig of the lesson (65 degree field of view, 640 x 480 pixels, 12 cm baseline, camera
0.8 m above the floor) sees points on the lab's walls and furniture. Each visible point is measured
as Se et al. measure a stereo feature (column, row and disparity with pixel noise, then
``X = (c - c0) I / d``, ``Y = (r0 - r) I / d``, ``Z = f I / d``; Se et al. Sec. 3.1), and the
features of consecutive frames are matched, a share of the matches wrongly (a look-alike feature
elsewhere in the previous view, as a descriptor match that passes the ratio test can be).

References
----------
.. [1] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002 (Sec. 3.1).
.. [2] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Sec. 5-7: ego-motion from matched stereo features with RANSAC).
"""
from __future__ import annotations

import functools

import numpy as np

from robokit.geometry import pqt_world_to_robot, se2_to_pqt, wrap_angle
from robokit.sim import PinholeCamera, lab_lap, lab_room
from robokit.validation import as_int, as_rng
from robokit.vision.stereo import StereoCalibration, disparity_to_point

__all__ = ["ODOMETRY_RUN", "odometry_run", "lab_points"]

#: The runs of the loop exercise: frames per run, frame rate (Hz), pixel noise (px, on each of the
#: left column, right column and row), the share of wrong matches (a range), features kept per
#: frame at most, how likely a visible point is detected, the depth range (m) of the stereo
#: features kept, the rig (baseline and camera height, m) and how much (rad) every run turns at
#: least (each run takes a corner of the lap) and how many right matches every step has at least (a
#: draw with fewer is drawn again: Lin et al. keep odometry below 15 supporting matches, Sec. 7);
#: ``stride`` scales the lap's speed (0.3 m/s) per run and ``weave`` is the range of the amplitude
#: (m) and the period (s) of a sideways weave about the lap (see :func:`odometry_run`).
ODOMETRY_RUN = {"frames": 14, "rate": 1.0, "pixel_noise": 0.08, "contamination": (0.2, 0.45),
                "max_features": 250, "detection": 0.8, "depth": (0.5, 6.0), "baseline": 0.12,
                "camera_height": 0.8, "min_turn": 0.8, "min_true_matches": 20,
                "stride": (0.7, 1.0), "weave": ((0.03, 0.12), (6.0, 12.0))}


@functools.lru_cache(maxsize=1)
def _lab():
    world = lab_room()
    lap = lab_lap(world, rate=10.0)
    return world, lap, world.layout(ODOMETRY_RUN["camera_height"])


@functools.lru_cache(maxsize=1)
def _upright():
    """Corners, edge vectors and areas of the lab's vertical surfaces."""
    upright = [s for s in _lab()[0].surfaces if abs(s.normal[2]) < 1e-6]
    area = np.array([np.linalg.norm(s.u) * np.linalg.norm(s.v) for s in upright])
    return (np.array([s.corner for s in upright]), np.array([s.u for s in upright]),
            np.array([s.v for s in upright]), area / area.sum())


@functools.lru_cache(maxsize=1)
def _camera() -> tuple[StereoCalibration, int, int]:
    """The lesson's rig as a rectified stereo calibration, and its image width and height."""
    cam = PinholeCamera.from_fov()
    rig = StereoCalibration(float(cam.fx), float(cam.cx), float(cam.cy), ODOMETRY_RUN["baseline"])
    return rig, int(cam.width), int(cam.height)


def lab_points(rng, count: int = 4000) -> np.ndarray:
    """Points on the lab's vertical surfaces (walls, furniture, posters) in the papers' world frame.

    Parameters
    ----------
    rng : numpy.random.Generator or int
    count : int, default 4000
        How many; spread over the surfaces in proportion to their area, between 0.1 m and 2.4 m
        above the floor.

    Returns
    -------
    numpy.ndarray, shape (count, 3)
        ``(X, Y, Z)``: X east, Y up from the camera (0.8 m above the floor), Z north
        (:func:`robokit.geometry.paper_world_to_robokit`'s identification).

    Examples
    --------
    >>> pts = lab_points(0, 100)
    >>> pts.shape, bool(np.all((pts[:, 1] > -0.8) & (pts[:, 1] < 1.7)))
    ((100, 3), True)
    """
    gen = as_rng(rng)
    count = as_int(count, "count", minimum=1)
    corner, u, v, share = _upright()
    xyz = np.zeros((0, 3))
    while len(xyz) < count:                    # draw, keep the points in the height band, repeat
        pick = gen.choice(len(share), 2 * count, p=share)
        ab = gen.uniform(0.0, 1.0, (2 * count, 2))
        more = corner[pick] + ab[:, :1] * u[pick] + ab[:, 1:] * v[pick]
        xyz = np.vstack([xyz, more[(more[:, 2] > 0.1) & (more[:, 2] < 2.4)]])
    xyz = xyz[:count]
    return np.column_stack([xyz[:, 0], xyz[:, 2] - ODOMETRY_RUN["camera_height"], xyz[:, 1]])


def _visible(points_robot: np.ndarray, pose: np.ndarray, world_points: np.ndarray) -> np.ndarray:
    """Which points the left and right cameras both see: in front, in both images, not behind a wall."""
    rig, width, height = _camera()
    lo, hi = ODOMETRY_RUN["depth"]
    ok = (points_robot[:, 2] > lo) & (points_robot[:, 2] < hi)
    left, right = rig.project(points_robot[ok])
    (c, r), c_right = left.T, right[:, 0]
    ok[np.flatnonzero(ok)] = (c >= 0) & (c <= width - 1) & (r >= 0) & (r <= height - 1) & (c_right >= 0)
    if ok.any():
        layout = _lab()[2]
        dx, dz = world_points[ok, 0] - pose[0], world_points[ok, 2] - pose[1]
        reach = layout.raycast(np.tile(pose[:2], (int(ok.sum()), 1)), np.arctan2(dz, dx))
        ok[np.flatnonzero(ok)] = reach > np.hypot(dx, dz) - 0.05
    return ok


def _measure(points_robot: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Se et al.'s stereo measurement: noisy column, row and disparity, then back to 3-D."""
    rig = _camera()[0]
    n, sigma = len(points_robot), ODOMETRY_RUN["pixel_noise"]
    left, right = rig.project(points_robot)
    (c, r), c_right = left.T, right[:, 0]
    c = c + rng.normal(0.0, sigma, n)
    c_right = c_right + rng.normal(0.0, sigma, n)
    r = r + rng.normal(0.0, sigma, n)
    return disparity_to_point(c, r, np.maximum(c - c_right, 0.5), rig)[0]


def odometry_run(rng, frames: int | None = None) -> dict:
    """One simulated stretch of the lab lap: stereo features per frame and matches to the previous frame.

    Parameters
    ----------
    rng : numpy.random.Generator or int
        Where on the lap the stretch starts, the points, the pixel noise and the wrong matches.
    frames : int, optional
        Frames in the run (default ``ODOMETRY_RUN["frames"]``, at least 2).

    Returns
    -------
    dict
        ``features``: a list of ``(N_k, 3)`` arrays, the stereo features of frame ``k`` in the robot
        frame of that frame (X right, Y up, Z forward; shuffled, rounded to 0.1 mm);
        ``matches``: a list of ``frames - 1`` integer arrays ``(M_k, 2)``, rows
        ``[index in frame k, index in frame k + 1]``; ``start``: the true pose ``[p, q, theta]`` of
        frame 0; ``truth``: ``(frames, 3)`` the true poses; ``contamination``: the share of wrong
        matches of each step; ``wrong``: per step, a boolean mask of the wrong matches.

    Notes
    -----
    The stretch is not the lap itself: its speed is scaled and it weaves a few centimetres to
    either side (:data:`ODOMETRY_RUN`), so the start pose does not give away the rest.
    The wrong matches pair a feature with the previous frame's feature nearest to where its true
    partner would be moved by 1-3 m in one direction (one direction per step, each wrong match
    then off by a different amount), so they all pull a least-squares fit the same way without
    agreeing on one pose among themselves.

    Examples
    --------
    >>> run = odometry_run(0, frames=3)
    >>> len(run["features"]), len(run["matches"]), run["truth"].shape
    (3, 2, (3, 3))
    """
    gen = as_rng(rng)
    k = ODOMETRY_RUN["frames"] if frames is None else as_int(frames, "frames", minimum=2)
    for _ in range(20):
        run = _draw_run(gen, k)
        if min(int((~w).sum()) for w in run["wrong"]) >= ODOMETRY_RUN["min_true_matches"]:
            return run
    return run


def _stretch(gen: np.random.Generator, k: int) -> np.ndarray:
    """``k`` true poses ``[p, q, theta]`` along the lap: a random start, a random stride (the robot
    a little faster or slower than the lap's 0.3 m/s, :data:`ODOMETRY_RUN`'s ``stride``) and a
    gentle weave across the lap (``weave``: amplitude in m and period in s), so that no two runs
    share their poses; a draw whose stretch of the lap turns less than ``min_turn`` between its
    fourth and its fourth-last frame (a corner in the middle of the run) or comes within 0.15 m of a wall or
    a piece of furniture is drawn again."""
    world, lap, _ = _lab()
    t, poses = lap.t, lap.poses
    dt = float(t[1] - t[0])
    for _ in range(50):
        stride = round(float(gen.uniform(*ODOMETRY_RUN["stride"])) / ODOMETRY_RUN["rate"] / dt)
        first = int(gen.integers(0, len(t) - (k - 1) * stride))
        index = first + stride * np.arange(k)
        amp = gen.uniform(*ODOMETRY_RUN["weave"][0])
        period, phase = gen.uniform(*ODOMETRY_RUN["weave"][1]), gen.uniform(0.0, 2 * np.pi)
        w = 2 * np.pi / period
        side = amp * np.sin(w * t[index] + phase)
        drift = amp * w * np.cos(w * t[index] + phase)            # the weave's sideways speed (m/s)
        sim = poses[index].copy()
        sim[:, 0] -= side * np.sin(sim[:, 2])
        sim[:, 1] += side * np.cos(sim[:, 2])
        sim[:, 2] = wrap_angle(sim[:, 2] + np.arctan2(drift, 0.3))
        middle = index[min(3, k // 3):max(k - 3, k - k // 3)]           # the corner away from both ends
        turn = np.abs(wrap_angle(np.diff(poses[middle, 2]))).sum() if len(middle) > 1 else 0.0
        if turn >= ODOMETRY_RUN["min_turn"] and np.all(world.is_free(sim[:, :2], clearance=0.15)):
            break
    return se2_to_pqt(sim)


def _draw_run(gen: np.random.Generator, k: int) -> dict:
    truth = _stretch(gen, k)
    points = lab_points(gen)
    features, ids = [], []
    for pose in truth:
        robot = pqt_world_to_robot(points, pose)
        seen = np.flatnonzero(_visible(robot, pose, points) & (gen.random(len(points)) < ODOMETRY_RUN["detection"]))
        if len(seen) > ODOMETRY_RUN["max_features"]:
            seen = gen.choice(seen, ODOMETRY_RUN["max_features"], replace=False)
        seen = gen.permutation(seen)
        features.append(_measure(robot[seen], gen).round(4))
        ids.append(seen)
    matches, wrong, shares = [], [], []
    lo, hi = ODOMETRY_RUN["contamination"]
    for a in range(k - 1):
        prev, cur = ids[a], ids[a + 1]
        where_prev = {int(p): i for i, p in enumerate(prev)}
        pairs = np.array([[where_prev[int(p)], j] for j, p in enumerate(cur) if int(p) in where_prev], int).reshape(-1, 2)
        eps = float(gen.uniform(lo, hi))
        n_bad = int(round(eps * len(pairs)))
        bad = gen.choice(len(pairs), n_bad, replace=False)
        heading = gen.uniform(-np.pi, np.pi)
        shift = gen.uniform(1.0, 3.0) * np.array([np.cos(heading), 0.0, np.sin(heading)])
        prev_xyz = features[a]
        if n_bad:                             # the nearest other feature to where the partner would be moved
            dist = np.linalg.norm(prev_xyz[None] - (prev_xyz[pairs[bad, 0]] + shift)[:, None], axis=2)
            dist[np.arange(n_bad), pairs[bad, 0]] = np.inf
            pairs[bad, 0] = np.argmin(dist, axis=1)
        mask = np.zeros(len(pairs), bool)
        mask[bad] = True
        order = gen.permutation(len(pairs))
        matches.append(pairs[order])
        wrong.append(mask[order])
        shares.append(n_bad / max(len(pairs), 1))
    return {"features": features, "matches": matches, "start": truth[0].copy(), "truth": truth,
            "contamination": np.array(shares), "wrong": wrong}
