"""Pinhole cameras and a rectified stereo rig (optionally trinocular, like the Triclops).

Frames: a camera's placement is ``T_world_cam`` (4x4), its frame the OpenCV optical frame (x right,
y down, z forward). A camera carries a ``mount`` ``T_body_cam`` so that :meth:`PinholeCamera.observe`
can render from a planar robot pose ``[x, y, theta]``.

References
----------
.. [1] R. Hartley and A. Zisserman, *Multiple View Geometry in Computer Vision*, 2nd ed., Cambridge
   University Press, 2004.
.. [2] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features", Proc.
   IEEE/RSJ Int. Conf. on Intelligent Robots and Systems (IROS), 2002.
.. [3] G. E. Healey and R. Kondepudy, "Radiometric CCD camera calibration and noise estimation",
   *IEEE Transactions on Pattern Analysis and Machine Intelligence* 16(3), 267-276, 1994.
.. [4] K. M. Lynch and F. C. Park, *Modern Robotics: Mechanics, Planning, and Control*, Cambridge
   University Press, 2017.
"""
from __future__ import annotations

import dataclasses
from typing import Any, NamedTuple

import numpy as np

from ..geometry import as_se3, euler_matrix, se2_to_se3, se3_from_rt, se3_inverse, transform_points
from ..geometry.paper_frames import R_BODY_OPTICAL
from ..validation import as_array, as_points, as_rng, as_int, as_positive
from .render import render_pinhole
from .textures import illuminate
from .world import World

__all__ = ["Frame", "camera_mount", "PinholeCamera", "StereoRig", "finish_image"]


class Frame(NamedTuple):
    """A rendered view: ``image`` (H, W, 3) uint8 RGB and ``depth`` (H, W) float32 metres (inf: nothing)."""

    image: np.ndarray
    depth: np.ndarray


def camera_mount(height: float, forward: float = 0.0, pitch: float = 0.0) -> np.ndarray:
    """Return ``T_body_cam`` of a forward-looking camera on a robot (body: x forward, y left, z up).

    Parameters
    ----------
    height : float
        Height of the optical centre above the floor (metres, > 0).
    forward : float, default 0
        Offset of the optical centre ahead of the robot's origin (metres).
    pitch : float, default 0
        Tilt in radians; positive looks down.

    Returns
    -------
    numpy.ndarray, shape (4, 4)

    Raises
    ------
    ValueError
        For a non-positive height or non-finite values.

    Notes
    -----
    Optical-frame convention of OpenCV / Hartley & Zisserman (2004), Sec. 6.1; body frame of
    ROS REP 103.
    """
    h = as_positive(height, "height")
    R = euler_matrix([0.0, pitch, 0.0]) @ R_BODY_OPTICAL  # pitch about the body's y axis (left)
    return se3_from_rt(R, [as_array(forward, "forward", shape=()).item(), 0.0, h])


def finish_image(image: np.ndarray, noise: float, rng: Any, lighting: dict | None) -> np.ndarray:
    """Apply lighting (see :func:`robokit.sim.textures.illuminate`) and Gaussian pixel noise.

    Parameters
    ----------
    image : numpy.ndarray, uint8
    noise : float
        Standard deviation of additive Gaussian noise in grey levels (>= 0).
    rng : Generator or int, optional
    lighting : dict, optional
        Keyword arguments of :func:`~robokit.sim.textures.illuminate`.

    Returns
    -------
    numpy.ndarray, uint8 (clipped to 0-255 like a real sensor)

    Notes
    -----
    Additive Gaussian read noise (Healey & Kondepudy 1994, Sec. 2) after a gain/offset lighting
    change.
    """
    if lighting:
        image = illuminate(image, **lighting)
    sigma = as_positive(noise, "noise", allow_zero=True)
    if sigma > 0:
        noisy = as_rng(rng).standard_normal(image.shape)   # the draws of normal(0, sigma), made in place
        noisy *= sigma
        noisy += image
        image = np.clip(noisy, 0, 255, out=noisy).astype(np.uint8)
    return image


class MountedSensor:
    """Mixin for a sensor fixed on the robot by a ``mount`` transform ``T_body_sensor``.

    Gives :meth:`transform_at` (the sensor's ``T_world_sensor`` for a planar robot pose) and
    :meth:`observe` (render from there); the class provides ``mount`` and
    ``render(world, T_world_sensor, **kwargs)``.
    """

    mount: Any

    def transform_at(self, robot_pose: Any, world: World | None = None) -> np.ndarray:
        """``T_world_sensor`` for a planar robot pose ``[x, y, theta]`` (uses :attr:`mount`).

        Parameters
        ----------
        robot_pose : array_like, shape (3,)
        world : World, optional
            When given, also check that the sensor is inside the world's free space and below its
            ceiling (errors name ``robot_pose``).

        Returns
        -------
        numpy.ndarray, shape (4, 4)
            ``T_world_body @ T_body_sensor``.

        Raises
        ------
        TypeError
            If ``world`` is given and is not a World.
        ValueError
            For a malformed pose, or one that puts the sensor inside a wall or outside the world.

        Notes
        -----
        Composition of frames (Lynch & Park 2017, Sec. 3.3.1).
        """
        T = se2_to_se3(as_array(robot_pose, "robot_pose", shape=(3,))) @ self.mount
        if world is not None:
            if not isinstance(world, World):
                raise TypeError(f"world: expected a robokit.sim World, got {type(world).__name__}")
            world.as_viewpoint(T[:3, 3], "robot_pose")
        return T

    def observe(self, world: World, robot_pose: Any, **kwargs: Any) -> Frame:
        """Render from the sensor mounted on a robot at planar pose ``[x, y, theta]``.

        Parameters
        ----------
        world : World
        robot_pose : array_like, shape (3,)
        **kwargs
            ``noise``, ``rng``, ``lighting`` as in :meth:`render`.

        Returns
        -------
        Frame

        Notes
        -----
        ``render(world, transform_at(robot_pose))``.
        """
        return self.render(world, self.transform_at(robot_pose, world), **kwargs)


@dataclasses.dataclass
class PinholeCamera(MountedSensor):
    """A distortion-free pinhole camera ``u = fx X/Z + cx``, ``v = fy Y/Z + cy``.

    Parameters
    ----------
    fx, fy : float
        Focal lengths in pixels (> 0).
    cx, cy : float
        Principal point in pixels.
    width, height : int
        Image size.
    mount : array_like (4, 4), optional
        ``T_body_cam``; default :func:`camera_mount` at 0.8 m height, level.

    Notes
    -----
    Hartley & Zisserman (2004), Eq. (6.4)-(6.5).

    Examples
    --------
    >>> cam = PinholeCamera.from_fov(np.deg2rad(90.0), width=640, height=480)
    >>> uv, z = cam.project([[1.0, 0.0, 2.0]])          # camera frame: 1 m right, 2 m ahead
    >>> print(np.round(uv, 2), z)
    [[479.5 239.5]] [2.]
    >>> print(np.round(cam.backproject(uv, z), 6))
    [[1. 0. 2.]]
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int = 640
    height: int = 480
    mount: Any = None

    def __post_init__(self) -> None:
        self.fx = as_positive(self.fx, "fx")
        self.fy = as_positive(self.fy, "fy")
        self.width = as_int(self.width, "width", minimum=8)
        self.height = as_int(self.height, "height", minimum=8)
        self.cx = float(as_array(self.cx, "cx", shape=()))
        self.cy = float(as_array(self.cy, "cy", shape=()))
        self.mount = camera_mount(0.8) if self.mount is None else as_se3(self.mount, "mount")

    @classmethod
    def from_fov(cls, hfov: float = np.deg2rad(65.0), width: int = 640, height: int = 480,
                 mount: Any = None) -> "PinholeCamera":
        """Square-pixel camera with horizontal field of view ``hfov`` (radians) and centred principal point.

        Notes
        -----
        ``fx = (width / 2) / tan(hfov / 2)`` (Hartley & Zisserman 2004, Sec. 6.1).
        """
        fov = as_positive(hfov, "hfov")
        if fov >= np.pi:
            raise ValueError(f"hfov: expected a field of view below pi rad, got {fov}")
        w = as_int(width, "width", minimum=8)
        f = (w / 2) / np.tan(fov / 2)
        h = as_int(height, "height", minimum=8)
        return cls(f, f, (w - 1) / 2, (h - 1) / 2, w, h, mount)

    @property
    def K(self) -> np.ndarray:
        """Intrinsic matrix (3, 3)."""
        return np.array([[self.fx, 0, self.cx], [0, self.fy, self.cy], [0, 0, 1.0]])

    def project(self, points: Any, T_world_cam: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """Project 3D points to pixels.

        Parameters
        ----------
        points : array_like, shape (N, 3)
            World points if ``T_world_cam`` is given, else camera-frame points.
        T_world_cam : array_like (4, 4), optional
            The camera's placement in the world.

        Returns
        -------
        pixels : numpy.ndarray, shape (N, 2)
            ``(u, v)``; NaN for points with ``Z <= 0`` (behind the camera).
        depth : numpy.ndarray, shape (N,)
            ``Z`` in the camera frame.

        Notes
        -----
        Hartley & Zisserman (2004), Eq. (6.5). Consistent with :meth:`render`: a surface point is
        painted at its projected pixel with this depth.
        """
        P = as_points(points, "points", 3)
        if T_world_cam is not None:
            P = transform_points(se3_inverse(as_se3(T_world_cam, "T_world_cam")), P)
        z = P[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            uv = np.column_stack([self.fx * P[:, 0] / z + self.cx, self.fy * P[:, 1] / z + self.cy])
        uv[z <= 0] = np.nan
        return uv, z

    def backproject(self, pixels: Any, depth: Any, T_world_cam: Any = None) -> np.ndarray:
        """Lift pixels with known depth ``Z`` to 3D points (inverse of :meth:`project`).

        Parameters
        ----------
        pixels : array_like, shape (N, 2)
        depth : array_like, shape (N,)
            Positive ``Z`` values (e.g. read from the rendered depth image).
        T_world_cam : array_like (4, 4), optional
            The camera's placement; when given the points are returned in the world frame.

        Returns
        -------
        numpy.ndarray, shape (N, 3)

        Raises
        ------
        ValueError
            For mismatched lengths or non-positive / non-finite depths.

        Notes
        -----
        ``X = Z K^-1 [u, v, 1]^T`` (Hartley & Zisserman 2004, Sec. 6.2.2).
        """
        uv = as_points(pixels, "pixels", 2)
        z = as_array(depth, "depth", ndim=1) if np.ndim(depth) else as_array([depth], "depth", ndim=1)
        if len(z) != len(uv):
            raise ValueError(f"depth: expected {len(uv)} values to match pixels, got {len(z)}")
        if np.any(z <= 0):
            raise ValueError("depth: expected positive depths, got a value <= 0")
        P = np.column_stack([(uv[:, 0] - self.cx) / self.fx * z, (uv[:, 1] - self.cy) / self.fy * z, z])
        return P if T_world_cam is None else transform_points(as_se3(T_world_cam, "T_world_cam"), P)

    def render(self, world: World, T_world_cam: Any, *, noise: float = 0.0, rng: Any = None,
               lighting: dict | None = None) -> Frame:
        """Render colour and depth of ``world`` seen by the camera placed at ``T_world_cam``.

        Parameters
        ----------
        world : World
        T_world_cam : array_like (4, 4)
            Must be inside the world's free space, below the ceiling.
        noise : float, default 0
            Standard deviation of additive Gaussian pixel noise (grey levels).
        rng : Generator or int, optional
            Noise source.
        lighting : dict, optional
            Keyword arguments of :func:`robokit.sim.textures.illuminate` (gain, offset, gradient).

        Returns
        -------
        Frame
            ``image`` uint8 (H, W, 3) and ``depth`` float32 (H, W), Z in metres.

        Raises
        ------
        TypeError
            If ``world`` is not a World.
        ValueError
            For a NaN or non-rigid transform, or a camera inside a wall or outside the world.

        Notes
        -----
        Renderer: :func:`robokit.sim.render.render_pinhole` (plane homographies + z-buffer).
        """
        if not isinstance(world, World):
            raise TypeError(f"world: expected a robokit.sim World, got {type(world).__name__}")
        T = as_se3(T_world_cam, "T_world_cam")
        world.as_viewpoint(T[:3, 3], "T_world_cam")
        image, depth = render_pinhole(world, self.K, self.width, self.height, T)
        return Frame(finish_image(image, noise, rng, lighting), depth)

@dataclasses.dataclass
class StereoRig:
    """Rectified stereo: identical cameras, the right one ``baseline`` metres along the left's +x.

    Parameters
    ----------
    camera : PinholeCamera
        Intrinsics (and mount) of the left, reference camera.
    baseline : float, default 0.12
        Distance between optical centres (metres, > 0); Se, Lowe & Little's interocular distance I.
    trinocular : bool, default False
        Add a third camera ``baseline`` metres above the left one, like the Triclops
        (Se, Lowe & Little 2002, Sec. 1), giving vertical disparities.

    Notes
    -----
    In a rectified pair a point at depth Z has disparity ``d = u_left - u_right = f B / Z`` and
    lies on the same row (Hartley & Zisserman 2004, Sec. 9.3; Se, Lowe & Little 2002, Sec. 3.1:
    ``Z = f I / d``).

    Examples
    --------
    >>> rig = StereoRig(PinholeCamera.from_fov(np.deg2rad(90.0), width=640), baseline=0.12)
    >>> print(np.round(rig.disparity([2.0, 4.0]), 2), np.round(rig.depth(19.2), 3))
    [19.2  9.6] 2.0
    >>> sorted(rig.offsets)
    ['left', 'right']
    """

    camera: PinholeCamera
    baseline: float = 0.12
    trinocular: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.camera, PinholeCamera):
            raise TypeError(f"camera: expected a PinholeCamera, got {type(self.camera).__name__}")
        self.baseline = as_positive(self.baseline, "baseline")

    @property
    def offsets(self) -> dict[str, np.ndarray]:
        """``T_left_cam`` of every camera of the rig, keyed ``left``, ``right`` (and ``top``)."""
        out = {"left": np.eye(4), "right": se3_from_rt(np.eye(3), [self.baseline, 0, 0])}
        if self.trinocular:
            out["top"] = se3_from_rt(np.eye(3), [0, -self.baseline, 0])  # optical y points down
        return out

    def disparity(self, depth: Any) -> np.ndarray:
        """Horizontal disparity ``f_x B / Z`` (pixels) of points at depth ``Z`` (metres).

        Parameters
        ----------
        depth : float or array_like
            Positive depths.

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ValueError
            For non-positive or non-finite depths.

        Notes
        -----
        Se, Lowe & Little (2002), Sec. 3.1 (``Z = f I / d``, solved for ``d``).
        """
        z = as_array(depth, "depth")
        if np.any(z <= 0):
            raise ValueError("depth: expected positive depths, got a value <= 0")
        return self.camera.fx * self.baseline / z

    def depth(self, disparity: Any) -> np.ndarray:
        """Depth ``Z = f_x B / d`` (metres) from disparities (pixels, > 0).

        Parameters
        ----------
        disparity : float or array_like

        Returns
        -------
        numpy.ndarray

        Raises
        ------
        ValueError
            For non-positive or non-finite disparities.

        Notes
        -----
        Se, Lowe & Little (2002), Sec. 3.1; Hartley & Zisserman (2004), Sec. 9.3.
        """
        d = as_array(disparity, "disparity")
        if np.any(d <= 0):
            raise ValueError("disparity: expected positive disparities, got a value <= 0")
        return self.camera.fx * self.baseline / d

    def render(self, world: World, T_world_cam: Any, **kwargs: Any) -> dict[str, Frame]:
        """Render every camera of the rig; ``T_world_cam`` places the left camera.

        Returns
        -------
        dict of str to Frame
            ``"left"``, ``"right"`` (and ``"top"``); noise uses independent draws per camera.
        """
        T = as_se3(T_world_cam, "T_world_cam")
        rng = as_rng(kwargs.pop("rng", None))
        return {name: self.camera.render(world, T @ off, rng=rng, **kwargs) for name, off in self.offsets.items()}

    def observe(self, world: World, robot_pose: Any, **kwargs: Any) -> dict[str, Frame]:
        """Render the rig mounted on a robot at planar pose ``[x, y, theta]``.

        Parameters
        ----------
        world : World
        robot_pose : array_like, shape (3,)
        **kwargs
            ``noise``, ``rng``, ``lighting`` as in :meth:`PinholeCamera.render`.

        Returns
        -------
        dict of str to Frame

        Notes
        -----
        The left camera sits at the camera's ``mount``; the others at :attr:`offsets` from it.
        """
        return self.render(world, self.camera.transform_at(robot_pose, world), **kwargs)
