"""A meshcat scene that needs no server.

:class:`Scene` records meshcat drawing commands. It renders them as one self-contained HTML page
(meshcat's viewer JavaScript, shipped inside the ``meshcat`` package, plus the commands encoded
with MessagePack as meshcat's own server would send them), so a scene shows in JupyterLab, in an
executed notebook, in the course site and in a saved file without starting any process or opening
any port. Notebooks executed in parallel therefore never clash. With ``live=True`` the same
commands are also sent to a running meshcat server for interactive work.
"""
from __future__ import annotations

import base64
import functools
import html as _html
import json
from importlib import resources
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..validation import as_array, as_points, as_int, as_positive, as_text, describe

__all__ = ["Scene", "viewer_javascript", "as_color", "as_scene"]


@functools.lru_cache(maxsize=1)
def viewer_javascript() -> str:
    """Return meshcat's bundled viewer JavaScript (read once from the installed package)."""
    return resources.files("meshcat").joinpath("viewer/dist/main.min.js").read_text(encoding="utf-8")


def as_color(value: Any, name: str = "color") -> int:
    """Return a colour as meshcat's integer ``0xRRGGBB``.

    Parameters
    ----------
    value : int or array_like, shape (3,)
        ``0xRRGGBB``, or an ``(r, g, b)`` triple of floats in [0, 1] (matplotlib's convention).
    name : str, default "color"
        Argument name for error messages.

    Returns
    -------
    int

    Raises
    ------
    ValueError, TypeError
        For anything else.

    Examples
    --------
    >>> hex(as_color((1.0, 0.5, 0.0)))
    '0xff8000'
    """
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool) and 0 <= int(value) <= 0xFFFFFF:
        return int(value)
    rgb = as_array(value, name, shape=(3,))
    if np.any((rgb < 0) | (rgb > 1)):
        raise ValueError(f"{name}: expected 0xRRGGBB or RGB floats in [0, 1], got {value!r}")
    r, g, b = (np.round(rgb * 255)).astype(int)
    return int(r) << 16 | int(g) << 8 | int(b)


def _transform(value: Any, name: str = "transform") -> np.ndarray:
    if value is None:
        return np.eye(4)
    T = as_array(value, name, shape=(4, 4))
    if not np.allclose(T[3], [0, 0, 0, 1]):
        raise ValueError(f"{name}: expected a homogeneous 4x4 transform with last row [0, 0, 0, 1], got {T[3]}")
    return T


def _object_corners(obj: Any) -> np.ndarray | None:
    """The 8 corners of the box around a meshcat object's geometry, in its node's frame (None: not known)."""
    from meshcat import geometry as g

    geometry = getattr(obj, "geometry", None)
    if isinstance(geometry, g.Box):
        half = np.abs(np.asarray(geometry.lengths, float)) / 2
        lo, hi = -half, half
    elif isinstance(geometry, g.Sphere):                  # an Ellipsoid too: a unit sphere, scaled below
        r = float(geometry.radius)
        lo, hi = np.full(3, -r), np.full(3, r)
    elif isinstance(geometry, g.Cylinder):                # three.js: the axis along y
        r, h = max(float(geometry.radiusTop), float(geometry.radiusBottom)), float(geometry.height) / 2
        lo, hi = np.array([-r, -h, -r]), np.array([r, h, r])
    elif isinstance(geometry, (g.TriangularMeshGeometry, g.PointsGeometry)):
        v = geometry.vertices if isinstance(geometry, g.TriangularMeshGeometry) else np.asarray(geometry.position).T
        v = np.asarray(v, float).reshape(-1, 3)
        if not len(v):
            return None
        lo, hi = v.min(axis=0), v.max(axis=0)
    else:
        return None
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    M = np.asarray(geometry.intrinsic_transform(), float)
    return corners @ M[:3, :3].T + M[:3, 3]


class Scene:
    """A 3D scene built from meshcat commands, shown without a server.

    Parameters
    ----------
    title : str, default "robokit scene"
        Page title of the saved HTML.
    height : int, default 420
        Height in pixels of the scene when shown in a notebook.
    live : bool, default False
        Also send every command to a meshcat server started on first use (interactive work only;
        headless runs keep the default so no process is left behind).

    Examples
    --------
    >>> scene = Scene()
    >>> scene.add_box("robot/body", size=(0.5, 0.25, 0.15), color=0x3366cc).add_triad("world")
    Scene(title='robokit scene', commands=4)
    >>> page = scene.html()  # a complete, offline HTML page
    >>> page.startswith("<!DOCTYPE html>")
    True
    """

    def __init__(self, title: str = "robokit scene", height: int = 420, live: bool = False) -> None:
        self.title = as_text(title, "title")
        self.height = as_int(height, "height", minimum=1)
        self._commands: list[Any] = []
        self._extents: dict[tuple, np.ndarray] = {}      # object node -> (8, 3) corners in its node's frame
        self._poses: dict[tuple, np.ndarray] = {}        # node -> 4x4 transform relative to its parent
        self._live = None
        if live:
            import meshcat

            self._live = meshcat.Visualizer()

    # --- recording -------------------------------------------------------------------------------
    @staticmethod
    def meshcat_path(path: str):
        """The meshcat path object of a scene path like ``"robot/body"`` (under ``/meshcat``).

        Raises
        ------
        ValueError
            For an empty path or one that is not a string.
        """
        from meshcat.path import Path as MeshcatPath

        if not isinstance(path, str) or not path.strip("/"):
            raise ValueError(f"path: expected a non-empty scene path like 'robot/body', got {path!r}")
        return MeshcatPath(("meshcat",)).append(path.strip("/"))

    def send(self, command: Any) -> "Scene":
        """Record one meshcat command (``meshcat.commands.*``), the building block of every helper.

        Use it for what the helpers do not cover (animations, camera properties); the command is
        kept for the offline page and, with ``live=True``, sent to the meshcat server too.
        """
        self._commands.append(command)
        self._track(command)
        if self._live is not None:
            self._live.window.send(command)
        return self

    def _track(self, command: Any) -> None:
        from meshcat.commands import SetObject, SetTransform

        if isinstance(command, SetObject):
            key = tuple(command.path.entries)
            corners = _object_corners(command.object)
            if corners is None:
                self._extents.pop(key, None)
            else:
                self._extents[key] = corners
        elif isinstance(command, SetTransform):
            self._poses[tuple(command.path.entries)] = np.asarray(command.matrix, float)

    def bounding_box(self, paths: Sequence[str] | str | None = None) -> tuple[np.ndarray, np.ndarray] | None:
        """The axis-aligned box (world frame, metres) around what the scene draws, as it stands.

        Parameters
        ----------
        paths : str or sequence of str, optional
            Only objects at or under these scene paths (``"robot"`` takes ``"robot/body"``, not
            ``"robot2"``); every object if omitted.

        Returns
        -------
        (lo, hi) : tuple of ndarray, shape (3,), or None
            The least and greatest corner; None when no object matches.

        Raises
        ------
        ValueError, TypeError
            For a path that is not a non-empty string.

        Notes
        -----
        Every object recorded through :meth:`set_object` (so every ``add_*`` helper, and
        :meth:`send` with a ``SetObject``) counts with the box of its geometry (box, sphere,
        ellipsoid, cylinder, triangle mesh, points, lines), moved by the transforms last set
        (:meth:`set_transform`) on its path and on every group above it: a later
        ``set_transform`` moves the box, with its children. Not tracked: animations (the box is
        the one before an animation plays; a robot driving across a field counts where it starts),
        ``set_property`` commands, and meshes loaded from files (meshcat's ``MeshGeometry``); nor
        meshcat's own grid and axes.

        Examples
        --------
        >>> scene = Scene().add_box("robot/body", size=(2.0, 1.0, 0.5))
        >>> scene.set_transform("robot", [[1, 0, 0, 5.0], [0, 1, 0, 0], [0, 0, 1, 0.25], [0, 0, 0, 1]])
        Scene(title='robokit scene', commands=3)
        >>> lo, hi = scene.bounding_box()
        >>> lo.tolist(), hi.tolist()
        ([4.0, -0.5, 0.0], [6.0, 0.5, 0.5])
        >>> scene.bounding_box("elsewhere") is None
        True
        """
        if paths is None:
            prefixes = None
        else:
            names = [paths] if isinstance(paths, str) else paths
            if not isinstance(names, (list, tuple)) or not names:
                raise TypeError(f"paths: expected a scene path or a non-empty list of them, got {describe(paths)}")
            prefixes = []
            for name in names:
                if not as_text(name, "paths").strip("/"):
                    raise ValueError(f"paths: expected scene paths like 'robot', got {name!r}")
                prefixes.append(tuple(self.meshcat_path(name).entries))
        corners = []
        for key, local in self._extents.items():
            if prefixes is not None and not any(key[:len(p)] == p for p in prefixes):
                continue
            T = np.eye(4)
            for depth in range(1, len(key) + 1):
                T = T @ self._poses.get(key[:depth], np.eye(4))
            corners.append(local @ T[:3, :3].T + T[:3, 3])
        if not corners:
            return None
        allc = np.concatenate(corners)
        return allc.min(axis=0), allc.max(axis=0)

    @property
    def commands(self) -> list[dict]:
        """The recorded commands in meshcat's wire form (plain dicts), oldest first."""
        return [c.lower() for c in self._commands]

    def set_object(self, path: str, geometry: Any, material: Any = None) -> "Scene":
        """Place a meshcat geometry (or object) at ``path``; the building block of the helpers."""
        from meshcat.commands import SetObject

        self.send(SetObject(geometry, material, self.meshcat_path(path)))
        return self

    def set_transform(self, path: str, transform: Any) -> "Scene":
        """Set the 4x4 homogeneous pose of ``path`` relative to its parent."""
        from meshcat.commands import SetTransform

        self.send(SetTransform(_transform(transform), self.meshcat_path(path)))
        return self

    # --- helpers ---------------------------------------------------------------------------------
    def _material(self, color: Any, opacity: float):
        from meshcat.geometry import MeshLambertMaterial

        opacity = as_positive(opacity, "opacity")
        if opacity > 1:
            raise ValueError(f"opacity: expected a value in (0, 1], got {opacity}")
        return MeshLambertMaterial(color=as_color(color), opacity=opacity, transparent=opacity < 1)

    def add_box(self, path: str, size: Sequence[float], transform: Any = None, color: Any = 0x8899AA,
                opacity: float = 1.0) -> "Scene":
        """Add a box of ``size`` (x, y, z extents in metres) centred at ``transform``."""
        from meshcat.geometry import Box

        dims = as_array(size, "size", shape=(3,))
        if np.any(dims <= 0):
            raise ValueError(f"size: expected three positive extents, got {dims.tolist()}")
        self.set_object(path, Box(dims.tolist()), self._material(color, opacity))
        return self.set_transform(path, transform)

    def add_sphere(self, path: str, radius: float, transform: Any = None, color: Any = 0xCC5533,
                   opacity: float = 1.0) -> "Scene":
        """Add a sphere of ``radius`` metres centred at ``transform``."""
        from meshcat.geometry import Sphere

        self.set_object(path, Sphere(as_positive(radius, "radius")), self._material(color, opacity))
        return self.set_transform(path, transform)

    def add_cylinder(self, path: str, length: float, radius: float, transform: Any = None, color: Any = 0x8899AA,
                     opacity: float = 1.0, radius_top: float | None = None) -> "Scene":
        """Add a cylinder of ``length`` and ``radius`` metres centred at ``transform``, its axis along
        the local **y** axis (three.js's convention); ``radius_top`` (at +y) other than ``radius``
        makes a cone or a frustum (0: a cone with its tip at +y)."""
        from meshcat.geometry import Cylinder

        length, radius = as_positive(length, "length"), as_positive(radius, "radius")
        top = radius if radius_top is None else as_positive(radius_top, "radius_top", allow_zero=True)
        geometry = Cylinder(length, radiusTop=top, radiusBottom=radius)
        self.set_object(path, geometry, self._material(color, opacity))
        return self.set_transform(path, transform)

    def add_mesh(self, path: str, vertices: Any, faces: Any, transform: Any = None, color: Any = 0x8899AA,
                 opacity: float = 1.0) -> "Scene":
        """Add a triangle mesh (seen from both sides): ``vertices`` (N, 3) metres and ``faces`` (M, 3)
        vertex indices."""
        from meshcat.geometry import TriangularMeshGeometry

        v = as_points(vertices, "vertices", 3, min_count=3)
        f = as_array(faces, "faces", dtype=None)
        if f.ndim != 2 or f.shape[1] != 3 or len(f) < 1 or f.dtype.kind not in "iu":
            raise ValueError(f"faces: expected (M, 3) integer vertex indices, M >= 1, got {describe(faces)}")
        if f.min() < 0 or f.max() >= len(v):
            raise ValueError(f"faces: expected indices in [0, {len(v) - 1}] (rows of vertices), got {f.min()}..{f.max()}")
        self.set_object(path, TriangularMeshGeometry(v, f), self._material(color, opacity))
        return self.set_transform(path, transform)

    def set_camera_target(self, target: Any) -> "Scene":
        """Make the viewer's camera look at, and orbit about, world point ``target`` (metres, z up).

        meshcat's ``set_target`` command (meshcat-python's ``SetCamTarget``; its position in three.js's
        y-up frame, ``(x, z, -y)``). The viewer bundled with meshcat 0.3.2 does not know the command,
        so :meth:`html` also sets the orbit controls' target itself; a live server of that version
        ignores it (its camera keeps orbiting the origin).
        """
        p = as_array(target, "target", shape=(3,))

        class _SetTarget:
            def lower(self):
                return {"type": "set_target", "path": "", "value": [float(p[0]), float(p[2]), float(-p[1])]}

        return self.send(_SetTarget())

    def set_camera_follow(self, path: str) -> "Scene":
        """Make the viewer's camera follow the object at ``path``: as it moves (an animation), the
        camera and the point it looks at move with it, keeping the view the user chose.

        A ``robokit_follow`` command that :meth:`html` implements in the offline page (a meshcat
        server ignores it: there the camera stays put).
        """
        path = self.meshcat_path(path).lower()

        class _Follow:
            def lower(self):
                return {"type": "robokit_follow", "path": path}

        return self.send(_Follow())

    def add_triad(self, path: str, transform: Any = None, scale: float = 0.3) -> "Scene":
        """Add a coordinate frame: x red, y green, z blue, each ``scale`` metres long."""
        from meshcat.geometry import LineBasicMaterial, LineSegments, PointsGeometry

        s = as_positive(scale, "scale")
        position = np.array([[0, 0, 0], [s, 0, 0], [0, 0, 0], [0, s, 0], [0, 0, 0], [0, 0, s]], np.float32).T
        color = np.array([[1, 0, 0], [1, 0.6, 0], [0, 1, 0], [0.6, 1, 0], [0, 0, 1], [0, 0.6, 1]], np.float32).T
        self.set_object(path, LineSegments(PointsGeometry(position, color),
                                           LineBasicMaterial(vertexColors=True, linewidth=2)))
        return self.set_transform(path, transform)

    def add_points(self, path: str, points: Any, colors: Any = None, size: float = 0.03,
                   color: Any = 0x222222) -> "Scene":
        """Add a point cloud; ``points`` is (N, 3), ``colors`` optional (N, 3) RGB in [0, 1]."""
        from meshcat.geometry import PointsGeometry, PointsMaterial

        pts = as_points(points, "points", 3).astype(np.float32)
        if colors is None:  # meshcat's PointsMaterial always reads per-vertex colours
            c = as_color(color)
            cols = np.tile(np.array([c >> 16, (c >> 8) & 255, c & 255], np.float32) / 255, (len(pts), 1))
        else:
            cols = as_points(colors, "colors", 3).astype(np.float32)
            if cols.shape != pts.shape:
                raise ValueError(f"colors: expected shape {pts.shape} to match points, got {cols.shape}")
            if np.any((cols < 0) | (cols > 1)):
                raise ValueError("colors: expected RGB values in [0, 1]")
        material = PointsMaterial(size=as_positive(size, "size"))
        return self.set_object(path, PointsGeometry(pts.T, cols.T), material)

    def add_line(self, path: str, points: Any, color: Any = 0x222222) -> "Scene":
        """Add a polyline through ``points`` (N, 3), e.g. a trajectory."""
        from meshcat.geometry import Line, LineBasicMaterial, PointsGeometry

        pts = as_points(points, "points", 3, min_count=2).astype(np.float32)
        return self.set_object(path, Line(PointsGeometry(pts.T), LineBasicMaterial(color=as_color(color))))

    # --- output ----------------------------------------------------------------------------------
    def html(self) -> str:
        """Return the scene as one self-contained HTML page (works offline, no server)."""
        import umsgpack

        commands = self.commands
        payload = ",\n".join(
            '"' + base64.b64encode(umsgpack.packb(c)).decode("ascii") + '"' for c in commands
        )
        targets = [c["value"] for c in commands if c.get("type") == "set_target"]
        target = ("viewer.controls.target.set(%r, %r, %r); viewer.controls.update();\n" % tuple(targets[-1])
                  if targets else "")
        follows = [c["path"] for c in commands if c.get("type") == "robokit_follow"]
        if follows:     # after each frame, shift camera and target by what the followed node moved
            target += (
                "(function () { const node = viewer.scene_tree.find(%s).object;"
                " const last = node.position.clone(); node.getWorldPosition(last);"
                " function follow() { requestAnimationFrame(follow); const now = last.clone();"
                " node.getWorldPosition(now); const d = now.clone().sub(last);"
                " if (d.lengthSq() > 0) { viewer.controls.target.add(d); viewer.camera.position.add(d);"
                " last.copy(now); viewer.set_dirty(); } }"
                " follow(); })();\n" % json.dumps([p for p in follows[-1].split("/") if p]))
        return (
            "<!DOCTYPE html><html><head><meta charset='utf-8'>"
            f"<title>{_html.escape(self.title)}</title><style>body{{margin:0}}"
            "#meshcat-pane{width:100vw;height:100vh;overflow:hidden}</style></head><body>"
            "<div id='meshcat-pane'></div>"
            f"<script>{viewer_javascript()}</script>"
            "<script>var viewer = new MeshCat.Viewer(document.getElementById('meshcat-pane'));\n"
            f"var robokitCommands = [{payload}];\n"
            "for (const c of robokitCommands) {"
            " viewer.handle_command_bytearray(Uint8Array.from(atob(c), ch => ch.charCodeAt(0))); }\n"
            f"{target}</script></body></html>"
        )

    def save_html(self, path: str | Path) -> Path:
        """Write :meth:`html` to ``path`` and return it."""
        path = Path(path)
        path.write_text(self.html(), encoding="utf-8")
        return path

    def _repr_html_(self) -> str:
        return (f"<iframe srcdoc=\"{_html.escape(self.html(), quote=True)}\" "
                f"style=\"width:100%;height:{self.height}px;border:1px solid #ccc;box-sizing:border-box\" "
                "title=\"robokit meshcat scene\"></iframe>")

    def show(self) -> None:
        """Display the scene in a notebook as an embedded, offline viewer.

        The page is sent as a raw ``text/html`` bundle (an ``<iframe srcdoc>``), which avoids
        IPython's advice to use ``IFrame`` (that would need a URL, i.e. a server or a file).
        """
        from IPython.display import display

        display({"text/html": self._repr_html_()}, raw=True)

    def __repr__(self) -> str:
        return f"Scene(title={self.title!r}, commands={len(self._commands)})"


def as_scene(scene: Any, *paths: Any) -> Scene:
    """Return ``scene`` if it is a :class:`Scene`, and check each of ``paths`` as a scene path.

    For the drawing helpers, whose first two arguments these are: a wrong one would otherwise fail
    deep inside (or, for a number as the path, silently become a path).

    Raises
    ------
    TypeError
        If ``scene`` is not a Scene or a path not a string.
    ValueError
        If a path is empty.

    Examples
    --------
    >>> as_scene(Scene(), "robot/body")
    Scene(title='robokit scene', commands=0)
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a robokit.viz.Scene, got {describe(scene)}")
    for path in paths:
        as_text(path, "path")
        Scene.meshcat_path(path)
    return scene
