"""Se, Lowe & Little's global-localization experiment, re-run in the simulated lab.

The robot drives a lap of :func:`robokit.sim.lab_room` recording stereo frames and odometry;
:class:`robokit.localization.visual_slam.VisualSLAM` tracks it and builds the landmark map; then the
robot is put down at 8 test poses near its lap (a few decimetres off it, headings up to about 20
degrees off the lap's; Se et al. carried their robot "to various positions") and localises itself
from a single stereo view with the Hough transform (Se et al. Sec. 6, which reports mean errors of
6.08 cm and 1.21 degrees and about 2.5 s on a 700 MHz Pentium III).

The map is built by the pipeline; only the first frame's pose is given (it anchors the map in the
lab frame so that errors can be read against the simulator's ground truth).

References
----------
.. [1] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002.
.. [2] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [3] Y. Bar-Shalom, X. R. Li and T. Kirubarajan, *Estimation with Applications to Tracking and
   Navigation*, Wiley, 2001.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from robocourse import FAST
from robocourse.source import code_version_of
from robokit.cache import cache_dir, cache_key, read_arrays, write_arrays
from robokit.geometry import paper_world_to_robokit, se2_to_pqt, wrap_angle
from robokit.progress import progress_bar
from robokit.sim import PinholeCamera, StereoRig, World, lab_lap, lab_room, record
from robokit.validation import as_points, as_callable, as_choice, as_int, as_positive, describe
from robokit.vision.stereo import StereoCalibration
from robokit.localization.visual_slam import DESCRIPTORS, FEATURE_METHODS, VisualSLAM

__all__ = ["LAB_TEST_POSES", "PAPER_RESULT", "LabExperiment", "MapConsistency", "calibrated_rig", "mapping_run",
           "lab_experiment", "map_consistency"]

#: Eight test poses ``[x, y, theta]`` in the simulator's frame, in free space near the lap, with
#: headings within about 20 degrees of the direction the robot faced when it passed by.
LAB_TEST_POSES = np.array([
    [4.0, 2.3, 0.2], [6.0, 1.8, -0.15], [7.4, 3.5, 1.4], [7.5, 6.5, 1.85],
    [6.0, 8.2, 3.0], [4.2, 7.7, -2.9], [2.8, 6.5, -1.4], [2.9, 3.5, -1.75]])

#: Se, Lowe & Little (2002), Sec. 6: mean errors and run time of their global localization.
PAPER_RESULT = {"translation_m": 0.0608, "rotation_rad": np.deg2rad(1.21), "seconds": 2.5,
                "hardware": "700 MHz Pentium III"}


def calibrated_rig(render_rig: StereoRig) -> StereoCalibration:
    """The calibration model (:class:`robokit.vision.StereoCalibration`) of a simulated stereo rig.

    Parameters
    ----------
    render_rig : robokit.sim.StereoRig

    Returns
    -------
    robokit.vision.StereoCalibration
        Focal length, image centre and baseline as a calibration would give them.

    Raises
    ------
    TypeError
        For anything but a ``robokit.sim.StereoRig``.

    Notes
    -----
    Se et al. Sec. 3.1 (``f``, ``(c0, r0)`` and ``I``); the simulator's rigs are rectified by
    construction.

    Examples
    --------
    >>> from robokit import sim
    >>> from robocourse.lessons.visual_slam.experiment import calibrated_rig
    >>> cal = calibrated_rig(sim.StereoRig(sim.PinholeCamera.from_fov(), baseline=0.12))
    >>> round(cal.focal, 1), cal.c0, cal.r0, cal.baseline
    (502.3, 319.5, 239.5, 0.12)
    """
    if not isinstance(render_rig, StereoRig):
        raise TypeError(f"render_rig: expected robokit.sim.StereoRig, got {type(render_rig).__name__}")
    cam = render_rig.camera
    return StereoCalibration(focal=float(cam.fx), c0=float(cam.cx), r0=float(cam.cy), baseline=float(render_rig.baseline))


def mapping_run(rate: float = 1.0, *, baseline: float = 0.12, seed: int = 0):
    """Record the mapping lap of the lab with a stereo rig (cached).

    Parameters
    ----------
    rate : float, default 1
        Frames per second.
    baseline : float, default 0.12
        Interocular distance in metres (the Triclops' horizontal pair is about 10 cm).
    seed : int, default 0
        Odometry noise seed.

    Returns
    -------
    run : robokit.sim.Run
        Images under ``"stereo/left"`` and ``"stereo/right"``.
    rig : robokit.sim.StereoRig

    Notes
    -----
    Se et al. Sec. 3.6: the robot "traverses around" the 10 m x 10 m lab while building the map.
    The frames are rendered in worker processes (:func:`robokit.sim.record`): a plain script needs
    the ``if __name__ == "__main__":`` guard.
    """
    world = lab_room()
    rig = _lab_rig(baseline)
    run = record(world, lab_lap(world), {"stereo": rig}, rate=as_positive(rate, "rate"), seed=seed)
    return run, rig


def _lab_rig(baseline: float = 0.12) -> StereoRig:
    return StereoRig(PinholeCamera.from_fov(), baseline=as_positive(baseline, "baseline"))


#: The test-pose results in a cache file of :func:`lab_experiment`.
_ROW_ARRAYS = ("measured", "estimated", "errors", "matches", "seconds")


@dataclass
class LabExperiment:
    """Result of :func:`lab_experiment`.

    Attributes
    ----------
    slam : VisualSLAM
        The pipeline with the map it built.
    truth : numpy.ndarray, shape (K, 3)
        Ground-truth ``[p, q, theta]`` of the mapping frames.
    rows : list of dict
        One per test pose: ``measured`` and ``estimated`` ``[p, q, theta]``, ``error_m``,
        ``error_rad``, ``matches`` and ``seconds`` (features, stereo and Hough for that view).
    mapping_seconds : float
        Wall-clock time of map building (when it was built, for a map loaded from the cache).
    from_cache : bool
        Whether the map and the test-pose results were loaded from robokit's cache.
    """

    slam: VisualSLAM
    truth: np.ndarray
    rows: list
    mapping_seconds: float
    from_cache: bool = False

    @property
    def mean_error_m(self) -> float:
        """Mean translation error over the test poses (metres)."""
        return float(np.mean([r["error_m"] for r in self.rows]))

    @property
    def mean_error_rad(self) -> float:
        """Mean absolute heading error over the test poses (radians)."""
        return float(np.mean([r["error_rad"] for r in self.rows]))

    @property
    def mean_seconds(self) -> float:
        """Mean run time of one global localization (seconds)."""
        return float(np.mean([r["seconds"] for r in self.rows]))

    def table(self) -> str:
        """The measured-vs-estimated table of Se et al. Sec. 6 (centimetres and degrees)."""
        head = (f"{'measured p, q (m), theta (deg)':>32} | {'estimated p, q (m), theta (deg)':>32} | "
                f"{'err (cm)':>8} | {'err (deg)':>9} | {'matches':>7} | {'time (s)':>8}")
        lines = [head, "-" * len(head)]
        for r in self.rows:
            m, e = r["measured"], r["estimated"]
            lines.append(f"{m[0]:9.3f} {m[1]:9.3f} {np.rad2deg(m[2]):11.1f}  | "
                         f"{e[0]:9.3f} {e[1]:9.3f} {np.rad2deg(e[2]):11.1f}  | {100 * r['error_m']:8.2f} | "
                         f"{np.rad2deg(r['error_rad']):9.2f} | {r['matches']:7d} | {r['seconds']:8.2f}")
        lines.append(f"mean error {100 * self.mean_error_m:.2f} cm, {np.rad2deg(self.mean_error_rad):.2f} deg, "
                     f"{self.mean_seconds:.2f} s per localization (Se et al. Sec. 6: "
                     f"{100 * PAPER_RESULT['translation_m']:.2f} cm, "
                     f"{np.rad2deg(PAPER_RESULT['rotation_rad']):.2f} deg, {PAPER_RESULT['seconds']} s on a "
                     f"{PAPER_RESULT['hardware']})")
        return "\n".join(lines)


def lab_experiment(*, method: str = "sift", descriptor: str = "sift128", rate: float = 1.0,
                   frames: int | None = None, test_poses=None, noise: float = 2.0, seed: int = 0,
                   progress=None) -> LabExperiment:
    """Build the lab map with :class:`VisualSLAM`, then localise globally from the test poses.

    Parameters
    ----------
    method, descriptor : str
        Features, see :class:`VisualSLAM`. The default 128-element descriptor keeps the map's
        drift at about 2 cm over the lap; Se et al.'s 16-element vector lets wrong associations
        through and the lap drifts by about 25 cm (measured; see the lesson).
    rate : float, default 1
        Mapping frame rate in Hz.
    frames : int, optional
        Use only the first ``frames`` frames of the lap (default all; 6 with ``robocourse.FAST``).
    test_poses : array_like, shape (M, 3), optional
        Simulator poses ``[x, y, theta]`` to localise from (default :data:`LAB_TEST_POSES`; only the
        first with ``robocourse.FAST``).
    noise : float, default 2
        Pixel noise (grey levels) of the test views.
    seed : int, default 0
        Seeds odometry, image noise and RANSAC.
    progress : callable, optional
        ``progress(done, total)`` after every mapping frame (see :meth:`VisualSLAM.process`), besides
        the progress bar (:func:`robokit.progress.progress_bar`).

    Returns
    -------
    LabExperiment
        Cached under ``robokit.cache.cache_dir("lab")`` keyed by every parameter and the code that makes
        it (:func:`robocourse.source.code_version_of`): a second run loads the map and the test-pose
        results instead of rebuilding them; a corrupt or stale cache file is rebuilt.

    Raises
    ------
    ValueError
        For test poses outside the lab's free space or bad sizes.

    Notes
    -----
    Se, Lowe & Little (2002), Sec. 6. The run time per test pose covers feature extraction in both
    images, stereo matching and the Hough transform with refinement, as in the paper (for a cached
    result, the times measured when it was built). Deterministic, hence cacheable (DESIGN.md,
    "Caching"). Its recording is rendered in worker processes (:func:`mapping_run`): a plain script
    needs the ``if __name__ == "__main__":`` guard.

    Examples
    --------
    A map from the first two frames of the lap, then one kidnapped view (a few seconds):

    >>> from robocourse.lessons.visual_slam.experiment import LAB_TEST_POSES, lab_experiment
    >>> e = lab_experiment(frames=2, test_poses=LAB_TEST_POSES[:1])
    >>> len(e.rows), bool(e.mean_error_m < 0.05)
    (1, True)
    """
    # every argument is checked before the (long) mapping run
    method = as_choice(method, "method", FEATURE_METHODS)
    descriptor = as_choice(descriptor, "descriptor", DESCRIPTORS)
    rate = as_positive(rate, "rate")
    frames = None if frames is None else as_int(frames, "frames", minimum=2)
    if test_poses is None:
        test_poses = LAB_TEST_POSES[:1] if FAST else LAB_TEST_POSES
    poses = as_points(test_poses, "test_poses", 3, min_count=1)
    noise = as_positive(noise, "noise", allow_zero=True)
    seed = as_int(seed, "seed", minimum=0)
    progress = as_callable(progress, "progress")
    world = lab_room()
    if not np.all(world.is_free(poses[:, :2], clearance=0.05)):
        raise ValueError("test_poses: expected poses in the lab's free space, got one inside furniture or walls")
    render_rig = _lab_rig()
    slam = VisualSLAM(calibrated_rig(render_rig), method=method, descriptor=descriptor, rng=seed)
    meta = {"method": method, "descriptor": descriptor, "rate": rate, "frames": frames, "fast": bool(FAST),
            "test_poses": np.round(poses, 12).tolist(), "noise": noise, "seed": seed,
            "code": code_version_of(__name__)}
    target = cache_dir("lab") / f"experiment-{cache_key(**meta)}.npz"
    data = read_arrays(target, (*slam.to_arrays(), *_ROW_ARRAYS, "truth", "mapping_seconds"), meta)
    if data is not None:
        slam.load_arrays(data)
        rows = [{"measured": m, "estimated": e, "error_m": float(err[0]), "error_rad": float(err[1]),
                 "matches": int(n), "seconds": float(t)}
                for m, e, err, n, t in zip(data["measured"], data["estimated"], data["errors"], data["matches"],
                                           data["seconds"])]
        return LabExperiment(slam, data["truth"], rows, float(data["mapping_seconds"]), from_cache=True)
    run, _ = mapping_run(rate, seed=seed)
    k = min(frames or (6 if FAST else len(run)), len(run))
    corners = world.corner_array.reshape(-1, 3)
    lo, hi = corners[:, :2].min(0), corners[:, :2].max(0)
    bounds = (lo[0], hi[0], lo[1], hi[1])  # the robot is somewhere in the lab (p = x, q = y)
    truth = se2_to_pqt(run.poses[:k])
    t0 = time.perf_counter()
    with progress_bar(k, "mapping the lab", unit="frame", callback=progress) as bar:
        slam.process(run.images["stereo/left"][:k], run.images["stereo/right"][:k], se2_to_pqt(run.odometry[:k]),
                     start_pqt=truth[0], progress=bar)
    mapping_seconds = time.perf_counter() - t0
    rows = []
    with progress_bar(len(poses), "global localization", unit="pose") as bar:
        for i, pose in enumerate(poses):
            views = render_rig.observe(world, pose, noise=noise, rng=seed + 1000 + i)
            start = time.perf_counter()
            best, _ = slam.localize(views["left"].image, views["right"].image, bounds=bounds)
            seconds = time.perf_counter() - start
            measured = se2_to_pqt(pose)
            rows.append({"measured": measured, "estimated": best.pqt,
                         "error_m": float(np.hypot(*(best.pqt[:2] - measured[:2]))),
                         "error_rad": float(abs(wrap_angle(best.pqt[2] - measured[2]))),
                         "matches": best.n_matches, "seconds": seconds})
            bar.update()
    write_arrays(target, {**slam.to_arrays(), "truth": truth, "mapping_seconds": np.array(mapping_seconds),
                          "measured": np.array([r["measured"] for r in rows]).reshape(-1, 3),
                          "estimated": np.array([r["estimated"] for r in rows]).reshape(-1, 3),
                          "errors": np.array([[r["error_m"], r["error_rad"]] for r in rows]).reshape(-1, 2),
                          "matches": np.array([r["matches"] for r in rows], int),
                          "seconds": np.array([r["seconds"] for r in rows], float)}, meta)
    return LabExperiment(slam, truth, rows, mapping_seconds)


@dataclass
class MapConsistency:
    """Landmark errors against the simulator's surfaces, from :func:`map_consistency`.

    Attributes
    ----------
    errors : numpy.ndarray, shape (N,)
        Signed distance (metres) of each landmark from the surface it lies on, along its normal.
    sigmas : numpy.ndarray, shape (N,)
        The landmark's claimed standard deviation along that normal, ``sqrt(n^T Sigma n)``.
    observations : numpy.ndarray, shape (N,)
        How often each landmark was observed (fused).
    on_surface : numpy.ndarray, shape (N,), bool
        Whether the landmark lies over some surface (within ``margin`` of a rectangle's extent); the
        others are left out of the statistics. In a closed room nearly every landmark does.

    Notes
    -----
    Each landmark is measured against the surface nearest along the normal, so a grossly wrong
    landmark may be charged to a closer surface: the tail is, if anything, understated.
    """

    errors: np.ndarray
    sigmas: np.ndarray
    observations: np.ndarray
    on_surface: np.ndarray

    @property
    def normalised_squared(self) -> np.ndarray:
        """``(e / sigma)^2`` per landmark: chi-square with one degree of freedom if the map is consistent."""
        return (self.errors / self.sigmas) ** 2

    def table(self, groups=((1, 1), (2, 4), (5, None))) -> str:
        """Statistics per group of observation counts.

        A consistent map has median ``(e / sigma)^2`` of 0.45 (the median of chi-square with one
        degree of freedom) and 0.27 % of its landmarks beyond 3 sigma; a larger median means the
        covariances are too small (overconfident), a smaller one too large.
        """
        head = (f"{'observed':>10} | {'landmarks':>9} | {'median |e| (cm)':>15} | {'median sigma (cm)':>17} | "
                f"{'median (e/sigma)^2':>18} | {'beyond 3 sigma':>14}")
        lines = [head, "-" * len(head)]
        nsq = self.normalised_squared
        for lo, hi in groups:
            top = np.inf if hi is None else hi
            sel = self.on_surface & (self.observations >= lo) & (self.observations <= top)
            if not sel.any():
                continue
            label = f"{lo}" if hi == lo else (f"{lo}+" if hi is None else f"{lo}-{hi}")
            lines.append(f"{label:>10} | {sel.sum():9d} | {100 * np.median(np.abs(self.errors[sel])):15.2f} | "
                         f"{100 * np.median(self.sigmas[sel]):17.2f} | {np.median(nsq[sel]):18.3f} | "
                         f"{100 * np.mean(nsq[sel] > 9):13.2f}%")
        return "\n".join(lines)


def map_consistency(landmark_map, world=None, *, camera_height: float = 0.8,
                    margin: float = 0.02) -> MapConsistency:
    """Check a landmark map's covariances against the true geometry of the simulated lab.

    Every landmark lies on some surface of the world (a wall, a poster, a box), so its true error
    along that surface's normal is known exactly even though the true 3-D point behind a feature is
    not. Dividing it by the landmark's claimed standard deviation along the normal gives a
    normalised error whose square is chi-square with one degree of freedom for a consistent map.

    Parameters
    ----------
    landmark_map : robokit.mapping.LandmarkMap
        A map in the papers' world frame anchored at the lab's true start pose (as
        :func:`lab_experiment` builds it).
    world : robokit.sim.World, optional
        Default :func:`robokit.sim.lab_room`.
    camera_height : float, default 0.8
        Camera height above the floor (metres), see :func:`robokit.geometry.paper_world_to_robokit`.
    margin : float, default 0.02
        How far (metres) beyond a rectangle's edges a landmark may lie and still count as over it.

    Returns
    -------
    MapConsistency

    Raises
    ------
    TypeError
        If ``landmark_map`` has no ``positions``/``covariances``/``observations``.
    ValueError
        For a negative ``margin`` or malformed landmark arrays.

    Notes
    -----
    Se, Lowe & Little (2002), Sec. 3.1 (the stereo covariance) and Sec. 3.4 (per-landmark Kalman
    fusion); the test is the normalised estimation error squared (Bar-Shalom, Li & Kirubarajan,
    *Estimation with Applications to Tracking and Navigation*, 2001, Sec. 5.4) restricted to the
    one direction the simulator knows exactly.

    Examples
    --------
    One landmark 1 cm behind the lab's east wall with a claimed 1 cm standard deviation, one exactly
    on the west wall (any object with ``positions``, ``covariances`` and ``observations`` will do):

    >>> import types
    >>> import numpy as np
    >>> from robocourse.lessons.visual_slam.experiment import map_consistency
    >>> landmarks = types.SimpleNamespace(positions=np.array([[10.01, 0.2, 5.0], [0.0, 0.7, 5.0]]),
    ...                                   covariances=np.stack([1e-4 * np.eye(3)] * 2),
    ...                                   observations=np.array([3, 1]))
    >>> c = map_consistency(landmarks)
    >>> print(np.round(c.errors, 3), np.round(c.normalised_squared, 2))
    [-0.01  0.  ] [1. 0.]
    """
    for attr in ("positions", "covariances", "observations"):
        if not hasattr(landmark_map, attr):
            raise TypeError(f"landmark_map: expected a LandmarkMap with .{attr}, got {type(landmark_map).__name__}")
    margin = as_positive(margin, "margin", allow_zero=True)
    world = lab_room() if world is None else world
    if not isinstance(world, World):
        raise TypeError(f"world: expected a robokit.sim.World or None, got {describe(world)}")
    points, covs = paper_world_to_robokit(landmark_map.positions, landmark_map.covariances, camera_height)
    n = len(points)
    best = np.full(n, np.inf)
    errors, sigmas = np.zeros(n), np.ones(n)
    for surface in world.surfaces:
        normal = surface.normal
        rel = points - surface.corner
        a = rel @ surface.u / (surface.u @ surface.u)
        b = rel @ surface.v / (surface.v @ surface.v)
        mu, mv = margin / np.linalg.norm(surface.u), margin / np.linalg.norm(surface.v)
        e = rel @ normal
        take = (a > -mu) & (a < 1 + mu) & (b > -mv) & (b < 1 + mv) & (np.abs(e) < best)
        if take.any():
            best[take] = np.abs(e[take])
            errors[take] = e[take]
            sigmas[take] = np.sqrt(np.einsum("k,nkl,l->n", normal, covs[take], normal))
    observations = np.asarray(landmark_map.observations, int)
    return MapConsistency(errors, sigmas, observations, np.isfinite(best))
