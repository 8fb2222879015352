"""An omnidirectional catadioptric camera (a camera looking up at a mirror), 640x480 colour.

Projection model: the unified central catadioptric model (Geyer & Daniilidis 2000; Mei & Rives
2007, Sec. II). A point ``X`` in the omni frame is first put
on the unit sphere, ``Xs = X / |X|``, then projected from a centre ``xi`` above the sphere's centre:

    m = (xs / (zs + xi), ys / (zs + xi)),      (u, v) = (f m_x + cx, f m_y + cy).

Its inverse lifts a pixel back to the sphere (Mei & Rives 2007, Eq. (6)):

    r2 = m_x^2 + m_y^2,   eta = (xi + sqrt(1 + (1 - xi^2) r2)) / (r2 + 1),   Xs = (eta m_x, eta m_y, eta - xi).

``xi = 1`` is a parabolic mirror with an orthographic camera. The robot of lesson 02's paper (Sec.
"Implementation for omnidirectional vision") uses a spherical mirror, which has no single
viewpoint; the unified model is the standard central approximation of such systems.

Omni frame: z points down (the image centre sees the floor below the robot), x forward. Only
elevations within ``elevation_range`` are imaged (an annulus): the robot body hides the centre
and the mirror's rim limits the outside. Outside the annulus the image is black and the depth
``inf``. Depth images of this camera hold the *range* ``|X|`` (distance from the viewpoint), not Z.

Rendering: the world is rendered into the faces of a cube around the viewpoint with the pinhole
renderer, then resampled into the omni image with one ``cv2.remap`` (a cube map, Greene 1986).

References
----------
.. [1] C. Geyer and K. Daniilidis, "A unifying theory for central panoramic systems and practical
   implications", *Proc. European Conference on Computer Vision (ECCV)*, 445-461, 2000.
.. [2] C. Mei and P. Rives, "Single view point omnidirectional camera calibration from planar
   grids", *Proc. IEEE International Conference on Robotics and Automation (ICRA)*, 3945-3950,
   2007.
.. [3] N. Greene, "Environment mapping and other applications of world projections", *IEEE
   Computer Graphics and Applications* 6(11), 21-29, 1986.
.. [4] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
"""
from __future__ import annotations

import dataclasses
import functools
from typing import Any

import cv2
import numpy as np

from ..geometry import as_se3, se3_from_rt
from ..validation import as_array, as_points, as_int, as_positive, describe
from .camera import Frame, MountedSensor, finish_image
from .render import render_pinhole
from .world import World

__all__ = ["OmniCamera", "omni_mount", "as_omni_camera"]

# cube faces: rotation omni <- face optical frame (columns: face x, y, z in omni axes)
_FACES = {
    "down": np.eye(3),
    "front": np.column_stack([[0, 1, 0], [0, 0, 1], [1, 0, 0]]).astype(float),
    "back": np.column_stack([[0, -1, 0], [0, 0, 1], [-1, 0, 0]]).astype(float),
    "right": np.column_stack([[-1, 0, 0], [0, 0, 1], [0, 1, 0]]).astype(float),
    "left": np.column_stack([[1, 0, 0], [0, 0, 1], [0, -1, 0]]).astype(float),
    "up": np.column_stack([[0, 1, 0], [1, 0, 0], [0, 0, -1]]).astype(float),
}


def omni_mount(height: float = 1.0) -> np.ndarray:
    """``T_body_omni`` for an omni camera at ``height`` metres: z down, x forward (body: x fwd, z up).

    Parameters
    ----------
    height : float, default 1.0
        Height of the single viewpoint above the floor (metres, > 0).

    Returns
    -------
    numpy.ndarray, shape (4, 4)

    Notes
    -----
    Lesson 02's paper mounts the camera on top of the robot looking up at the mirror; the omni frame's z axis
    is the mirror axis pointing down, as in Mei & Rives (2007), Sec. II.
    """
    return se3_from_rt(np.diag([1.0, -1.0, -1.0]), [0.0, 0.0, as_positive(height, "height")])


@dataclasses.dataclass
class OmniCamera(MountedSensor):
    """Unified-model omnidirectional camera (see the module docstring for the model).

    Parameters
    ----------
    width, height : int, default 640, 480
        Image size (lesson 02's paper: "full resolution 640x480 pixels", colour).
    xi : float, default 1.0
        Mirror parameter in (0, 1] (1: parabolic).
    elevation_range : (float, float), default (-60 deg, +30 deg)
        Imaged elevations above the horizon (radians); the upper one sets the image rim.
    f : float, optional
        Generalised focal length in pixels; default puts the upper elevation at the image's
        half-height minus 4 pixels.
    mount : array_like (4, 4), optional
        ``T_body_omni``; default :func:`omni_mount` at 1.0 m.
    face_size : int, default 400
        Cube-face resolution used for rendering.

    Examples
    --------
    A point on the horizon straight ahead (omni frame: x forward, z down) lands on the circle of
    elevation 0, and lifts back to the same point:

    >>> cam = OmniCamera()
    >>> uv, r = cam.project([[2.0, 0.0, 0.0]])
    >>> print(np.round(uv, 2), np.round(r, 3))
    [[455.75 239.5 ]] [2.]
    >>> print(np.round(cam.backproject(uv, r), 6))
    [[2. 0. 0.]]
    """

    width: int = 640
    height: int = 480
    xi: float = 1.0
    elevation_range: tuple = (np.deg2rad(-60.0), np.deg2rad(30.0))
    f: float | None = None
    mount: Any = None
    face_size: int = 400

    def __post_init__(self) -> None:
        self.width = as_int(self.width, "width", minimum=16)
        self.height = as_int(self.height, "height", minimum=16)
        self.xi = as_positive(self.xi, "xi")
        if self.xi > 1:
            raise ValueError(f"xi: expected a mirror parameter in (0, 1], got {self.xi}")
        lo, hi = as_array(self.elevation_range, "elevation_range", shape=(2,))
        if not -np.pi / 2 < lo < hi < np.arcsin(self.xi):
            raise ValueError(f"elevation_range: expected -pi/2 < low < high < asin(xi) = {np.arcsin(self.xi):.3f}, "
                             f"got ({lo:.3f}, {hi:.3f})")
        self.elevation_range = (float(lo), float(hi))
        self.cx, self.cy = (self.width - 1) / 2, (self.height - 1) / 2
        if self.f is None:
            self.f = (min(self.width, self.height) / 2 - 4) / self._radius(hi)
        self.f = as_positive(self.f, "f")
        self.face_size = as_int(self.face_size, "face_size", minimum=16)
        self.mount = omni_mount() if self.mount is None else as_se3(self.mount, "mount")

    def _radius(self, elevation: float) -> float:
        """Normalised image radius of rays at ``elevation`` (z points down, so zs = -sin e)."""
        return np.cos(elevation) / (self.xi - np.sin(elevation))

    @property
    def radii(self) -> tuple[float, float]:
        """Inner and outer radius (pixels) of the imaged annulus."""
        lo, hi = self.elevation_range
        return self.f * self._radius(lo), self.f * self._radius(hi)

    def project(self, points: Any, T_world_omni: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """Project points to omni pixels.

        Parameters
        ----------
        points : array_like, shape (N, 3)
            World points if ``T_world_omni`` is given, else omni-frame points.
        T_world_omni : array_like (4, 4), optional

        Returns
        -------
        pixels : numpy.ndarray, shape (N, 2)
            NaN where the point is outside the imaged elevation band.
        ranges : numpy.ndarray, shape (N,)
            Distance ``|X|`` from the viewpoint (the omni depth).

        Notes
        -----
        Unified model, Mei & Rives (2007), Eqs. (1)-(3) without distortion.
        """
        P = as_points(points, "points", 3)
        if T_world_omni is not None:
            T = as_se3(T_world_omni, "T_world_omni")
            P = (P - T[:3, 3]) @ T[:3, :3]
        rng_ = np.linalg.norm(P, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            S = P / rng_[:, None]
            m = S[:, :2] / (S[:, 2:3] + self.xi)
            elev = np.arcsin(np.clip(-S[:, 2], -1, 1))
        uv = self.f * m + [self.cx, self.cy]
        lo, hi = self.elevation_range
        uv[~((elev >= lo) & (elev <= hi) & (rng_ > 0))] = np.nan
        return uv, rng_

    def rays(self, pixels: Any) -> np.ndarray:
        """Unit viewing directions (omni frame) of pixels: the inverse projection (lifting).

        Parameters
        ----------
        pixels : array_like, shape (N, 2)

        Returns
        -------
        numpy.ndarray, shape (N, 3)

        Notes
        -----
        Mei & Rives (2007), Eq. (6); valid for any pixel when ``xi <= 1``.
        """
        uv = as_points(pixels, "pixels", 2)
        m = (uv - [self.cx, self.cy]) / self.f
        r2 = (m ** 2).sum(axis=1)
        eta = (self.xi + np.sqrt(1 + (1 - self.xi ** 2) * r2)) / (r2 + 1)
        return np.column_stack([eta * m[:, 0], eta * m[:, 1], eta - self.xi])

    def backproject(self, pixels: Any, ranges: Any, T_world_omni: Any = None) -> np.ndarray:
        """3D points at distance ``ranges`` along the rays of ``pixels`` (inverse of :meth:`project`).

        Parameters
        ----------
        pixels : array_like, shape (N, 2)
        ranges : array_like, shape (N,)
            Positive distances from the viewpoint (the omni depth image).
        T_world_omni : array_like (4, 4), optional
            ``T_world_omni``; when given the points are returned in the world frame.

        Returns
        -------
        numpy.ndarray, shape (N, 3)

        Raises
        ------
        ValueError
            For mismatched lengths or non-positive ranges.

        Notes
        -----
        Lifting of Mei & Rives (2007), Eq. (6), scaled by the range.
        """
        r = as_array(ranges, "ranges", ndim=1)
        d = self.rays(pixels)
        if len(r) != len(d) or np.any(r <= 0):
            raise ValueError(f"ranges: expected {len(d)} positive values, got {len(r)} (min {r.min() if len(r) else None})")
        P = d * r[:, None]
        if T_world_omni is None:
            return P
        T = as_se3(T_world_omni, "T_world_omni")
        return P @ T[:3, :3].T + T[:3, 3]

    @functools.cached_property
    def _lookup(self):
        """Per-pixel face index, atlas sampling maps and z-to-range factors (computed once)."""
        v, u = np.mgrid[0:self.height, 0:self.width]
        pix = np.column_stack([u.ravel(), v.ravel()]).astype(float)
        d = self.rays(pix)
        elev = np.arcsin(np.clip(-d[:, 2], -1, 1))
        lo, hi = self.elevation_range
        inside = (elev >= lo) & (elev <= hi)
        names = list(_FACES)
        dots = np.stack([d @ _FACES[n][:, 2] for n in names], axis=1)
        face = np.argmax(dots, axis=1)
        used = [names[k] for k in np.unique(face[inside])]
        S, pad = self.face_size, 2
        fpx = S / 2
        mapx = np.full(len(d), -10.0, np.float32)
        mapy = np.full(len(d), -10.0, np.float32)
        factor = np.full(len(d), np.inf, np.float32)
        for slot, name in enumerate(used):
            sel = inside & (face == names.index(name))
            q = d[sel] @ _FACES[name]  # ray in the face's optical frame
            mapx[sel] = fpx * q[:, 0] / q[:, 2] + (S - 1) / 2 + pad
            mapy[sel] = fpx * q[:, 1] / q[:, 2] + (S - 1) / 2 + pad + slot * (S + 2 * pad)
            factor[sel] = 1.0 / q[:, 2]  # range = Z_face / cos(angle to the face axis)
        K = np.array([[fpx, 0, (S - 1) / 2 + pad], [0, fpx, (S - 1) / 2 + pad], [0, 0, 1.0]])
        shape = (self.height, self.width)
        return used, K, S + 2 * pad, mapx.reshape(shape), mapy.reshape(shape), factor.reshape(shape), inside.reshape(shape)

    def render(self, world: World, T_world_omni: Any, *, noise: float = 0.0, rng: Any = None,
               lighting: dict | None = None) -> Frame:
        """Render colour and range images from ``T_world_omni`` (see :meth:`PinholeCamera.render`).

        Returns
        -------
        Frame
            ``image`` uint8 (H, W, 3), black outside the annulus; ``depth`` float32 range in metres,
            ``inf`` outside the annulus.

        Raises
        ------
        TypeError, ValueError
            For a non-World, a bad transform or a viewpoint inside a wall / outside the world.
        """
        if not isinstance(world, World):
            raise TypeError(f"world: expected a robokit.sim World, got {type(world).__name__}")
        T = as_se3(T_world_omni, "T_world_omni")
        world.as_viewpoint(T[:3, 3], "T_world_omni")
        used, K, size, mapx, mapy, factor, inside = self._lookup
        images, depths = [], []
        for name in used:
            Tf = T.copy()
            Tf[:3, :3] = T[:3, :3] @ _FACES[name]
            img, dep = render_pinhole(world, K, size, size, Tf)
            images.append(img)
            depths.append(dep)
        atlas_img, atlas_dep = np.vstack(images), np.vstack(depths)
        image = cv2.remap(atlas_img, mapx, mapy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
        depth = cv2.remap(atlas_dep, mapx, mapy, cv2.INTER_NEAREST, borderMode=cv2.BORDER_CONSTANT,
                          borderValue=np.inf) * factor
        depth[~inside] = np.inf
        image[~inside] = 0
        return Frame(finish_image(image, noise, rng, lighting), depth.astype(np.float32))


def as_omni_camera(camera: Any) -> OmniCamera:
    """``camera`` if it is an :class:`~robokit.sim.OmniCamera`, else a TypeError naming it.

    Notes
    -----
    Validation only (DESIGN.md, "Errors").

    Examples
    --------
    >>> as_omni_camera("omni")
    Traceback (most recent call last):
    ...
    TypeError: camera: expected a robokit.sim.OmniCamera, got 'omni'
    """
    if not isinstance(camera, OmniCamera):
        raise TypeError(f"camera: expected a robokit.sim.OmniCamera, got {describe(camera)}")
    return camera
