"""Where the viewer's camera stands: :func:`look_from` a given point, or :func:`fit_view` to what a scene draws.

meshcat's viewer has one perspective camera (three.js ``PerspectiveCamera(75, 1, 0.01, 100)`` in the
viewer bundled with the ``meshcat`` package: a 75 degree vertical field of view, and nothing nearer
than 1 cm or farther than 100 m is drawn), orbiting a target point. A lesson's scene shows what its
text talks about when the camera looks at that and stands just far enough away for it to fill the
view: :func:`fit_view` works that distance out from the box around the objects (:meth:`Scene.bounding_box`)
and moves the clipping planes past the box, so a 100 m field is not cut off at 100 m.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..validation import as_array, require_finite_result, as_int, as_positive
from .scene import Scene, as_scene

__all__ = ["look_from", "fit_view", "FOV", "NEAR", "FAR", "VIEW_WIDTH"]

FOV = 75.0
"""Vertical field of view (degrees) of meshcat's default camera."""
NEAR, FAR = 0.01, 100.0
"""meshcat's default clipping distances (metres): :func:`fit_view` only ever widens them."""
_CAMERA = ("Cameras", "default", "rotated", "<object>")
_SMALLEST = 0.1          # a box smaller than this (metres) is framed as one this size


#: Width (px) the framing assumes by default: the course site's content column, where a scene's
#: iframe is about 674 px wide; JupyterLab's notebook is wider, so there it shows a little more.
VIEW_WIDTH = 680


def _camera_property(scene: Scene, name: str, value: Any) -> None:
    from meshcat.commands import SetProperty
    from meshcat.path import Path as MeshcatPath

    scene.send(SetProperty(name, value, MeshcatPath(_CAMERA)))


def look_from(scene: Scene, position: Any, target: Any = None) -> Scene:
    """Place the viewer's camera at world ``position`` (metres, z up), looking at ``target``.

    Parameters
    ----------
    scene : Scene
    position : array_like, shape (3,)
    target : array_like, shape (3,), optional
        The point looked at and orbited about (:meth:`Scene.set_camera_target`); the origin if
        omitted. Frame what the text talks about: a 0.3 m robot seen from 0.7 m, not the origin of
        a 20 m grid (:func:`fit_view` works the position out from the objects).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        If ``position`` is the target (no direction to look in).

    Notes
    -----
    meshcat's default camera lives under ``/Cameras/default/rotated``, a node that turns
    three.js's y-up convention into robokit's z-up one, so the position is given to it as
    ``(x, z, -y)``; the orbit controls then look at the target.

    Examples
    --------
    >>> from robokit.viz import Scene, look_from
    >>> look_from(Scene(), [5.0, -5.0, 8.0])          # above and south-east of the origin
    Scene(title='robokit scene', commands=1)
    >>> look_from(Scene(), [0.6, -0.7, 0.45], target=[0.1, 0.0, 0.1])   # a small robot, close up
    Scene(title='robokit scene', commands=2)
    """
    as_scene(scene)
    p = as_array(position, "position", shape=(3,))
    t = np.zeros(3) if target is None else as_array(target, "target", shape=(3,))
    if np.linalg.norm(p - t) == 0:
        where = "origin" if target is None else "target"
        raise ValueError(f"position: expected a point away from the {where}, got {p.tolist()}")
    _camera_property(scene, "position", [float(p[0]), float(p[2]), float(-p[1])])
    if target is not None:
        scene.set_camera_target(t)
    return scene


def _view_axes(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit vectors (back towards the camera, image right, image up) for a camera looking along
    ``-direction`` with world z up (three.js's ``lookAt`` with ``up`` = z)."""
    back = direction / np.linalg.norm(direction)
    right = np.cross(-back, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return back, right, np.cross(right, -back)


def _centred(offsets: np.ndarray, depths: np.ndarray) -> float:
    """The sideways move ``a`` of the camera that centres the image of points at ``offsets`` along
    one image axis and ``depths`` ahead: ``max((x - a) / z) = -min((x - a) / z)`` (by bisection:
    the difference falls as ``a`` grows, from >= 0 at ``min(x)`` to <= 0 at ``max(x)``)."""
    lo, hi = float(offsets.min()), float(offsets.max())
    for _ in range(100):
        a = (lo + hi) / 2
        image = (offsets - a) / depths
        if image.max() + image.min() > 0:
            lo = a
        else:
            hi = a
    return (lo + hi) / 2


def fit_view(scene: Scene, direction: Any = (0.5, -1.0, 0.9), *, paths: Sequence[str] | str | None = None,
          bounds: Any = None, margin: float = 0.08, width: int = VIEW_WIDTH) -> Scene:
    """Point the viewer's camera at the box around the scene's objects, from ``direction``, close
    enough for the box to fill the view.

    Parameters
    ----------
    scene : Scene
    direction : array_like, shape (3,), default (0.5, -1.0, 0.9)
        From the box towards the camera: the camera looks along ``-direction`` (any length; world
        frame, z up). The default looks from the south (-y), a little east, 39 degrees above the
        horizon; ``(0, 0, 1)`` looks straight down with +y up in the image; ``(-1, 0, 0.3)`` looks
        along +x from behind, slightly above.
    paths : str or sequence of str, optional
        Frame only the objects at or under these scene paths (:meth:`Scene.bounding_box`), e.g. the robot
        rather than the whole world.
    bounds : array_like, shape (2, 3), optional
        The box to frame, rows ``lo`` and ``hi`` (metres), instead of the objects' box.
    margin : float, default 0.08
        Free room around the box, as a fraction of the view's half-size.
    width : int, default VIEW_WIDTH (680)
        Width in pixels the view is assumed to have (with ``scene.height``, its aspect ratio); a
        narrower view cuts off the box's sides, a wider one leaves room beside them. The default
        is the course site's content column, the narrowest place a scene is shown (JupyterLab's
        notebook is usually wider).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError, TypeError
        For a scene with nothing (under ``paths``) to frame, both ``paths`` and ``bounds``, a box
        whose ``lo`` exceeds ``hi``, a zero or non-finite ``direction``, or bad numbers.

    Notes
    -----
    Pinhole projection (Hartley & Zisserman 2004, Sec. 6.1). With the image's right, up and forward
    axes ``r``, ``u``, ``f`` and the camera at ``p`` (relative to the box's centre), a corner ``q``
    is in view when ``|(q - p).r| <= t_x (q - p).f`` and ``|(q - p).u| <= t_y (q - p).f``, where
    ``t_y = tan(fov / 2) / (1 + margin)`` and ``t_x = aspect t_y``. Both are linear in the three
    coordinates of ``p``, so the closest camera that sees all 8 corners, and the sideways shift that
    centres the box's image, are closed form (per image axis, two maxima over the corners) - exact,
    not a bounding-sphere guess; only, the camera stays in front of the box's nearest corner by 5 %
    of the box's half-diagonal (a flat box seen at a grazing angle would let it come closer). The
    orbit target is the point looked at level with the box's centre:
    the centre itself, moved sideways by that shift (seen obliquely, a box's near side looks larger,
    so the camera aims a little beyond the centre; from straight above there is no shift).

    The near clipping plane is set before the nearest corner (at most meshcat's 1 cm) and the far
    one at four times the farthest corner (at least meshcat's 100 m), so the box can be orbited and
    zoomed out of without being cut. Animations are not in the box (:meth:`Scene.bounding_box`).

    Examples
    --------
    >>> from robokit.viz import Scene, fit_view
    >>> scene = Scene(height=420).add_box("field", size=(100.0, 60.0, 0.02))
    >>> fit_view(scene, direction=(0.0, 0.0, 1.0))      # from above: a 100 m x 60 m field fills the view
    Scene(title='robokit scene', commands=6)
    >>> [round(c["value"], 1) for c in scene.commands if c.get("property") == "far"]   # not cut at 100 m
    [174.2]
    """
    as_scene(scene)
    d = as_array(direction, "direction", shape=(3,))
    if not np.any(d):
        raise ValueError(f"direction: expected a non-zero vector from the target towards the camera, got {d.tolist()}")
    d = d / np.max(np.abs(d))                          # no overflow in its norm
    if np.hypot(d[0], d[1]) < 1e-3 * abs(d[2]):        # straight up or down: tilt to keep +y up in the image
        d = np.array([0.0, -1e-3 * abs(d[2]), d[2]])
    margin = as_positive(margin, "margin", allow_zero=True)
    aspect = as_int(width, "width", minimum=1) / scene.height
    if bounds is None:
        found = scene.bounding_box(paths)
        if found is None:
            where = "" if paths is None else f" under {paths!r}"
            raise ValueError(f"scene: expected objects{where} to frame, got none")
        lo, hi = found
    else:
        box = as_array(bounds, "bounds", shape=(2, 3))
        if paths is not None:
            raise ValueError(f"paths, bounds: expected one of them, got both (paths {paths!r})")
        if np.any(box[0] > box[1]):
            raise ValueError(f"bounds: expected rows lo <= hi, got lo {box[0].tolist()} and hi {box[1].tolist()}")
        lo, hi = box
    centre = (lo + hi) / 2
    half = (hi - lo) / 2 if np.max(hi - lo) >= _SMALLEST else np.full(3, _SMALLEST / 2)
    q = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    back, right, up = _view_axes(d)
    t_y = np.tan(np.radians(FOV) / 2) / (1 + margin)
    t_x = t_y * aspect
    qr, qu, qf = q @ right, q @ up, -(q @ back)
    with np.errstate(over="ignore", invalid="ignore"):
        # p = shift + ahead f: ``ahead`` (negative) is the camera's place along the view axis
        h = np.max(qr - t_x * qf) + np.max(-qr - t_x * qf)
        v = np.max(qu - t_y * qf) + np.max(-qu - t_y * qf)
        ahead = min(-h / (2 * t_x), -v / (2 * t_y), qf.min() - 0.05 * np.linalg.norm(half))
        depths = qf - ahead
        shift = _centred(qr, depths) * right + _centred(qu, depths) * up
        require_finite_result(("scene" if bounds is None else "bounds") + ", margin, width", centre + shift,
                            4 * depths, ahead * back)
    camera = centre + shift - ahead * back
    # orbit about the point looked at where the view axis meets the level of the box's centre
    # (within the box's depth), not below the ground beside it
    depth = -ahead if abs(back[2]) < 1e-3 else np.clip((camera[2] - centre[2]) / back[2], depths.min(), depths.max())
    look_from(scene, camera, target=camera - depth * back)
    _camera_property(scene, "near", float(min(NEAR, 0.5 * depths.min())))
    _camera_property(scene, "far", float(max(FAR, 4 * depths.max())))
    return scene
