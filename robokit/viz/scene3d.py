"""3D helpers on top of :class:`robokit.viz.Scene`: textured worlds, camera frustums, trajectories,
particle clouds, landmarks with covariance ellipsoids, and pose animations.

Each helper takes the scene as its first argument, records meshcat commands and returns the scene,
so calls chain and the result is the same offline HTML page (no server, no ports).
"""
from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from ..geometry import as_se3, se2_to_se3
from ..sim.camera import PinholeCamera
from ..sim.world import World
from ..validation import as_array, as_points, as_finite_scalar, as_int, as_positive
from .maps import as_graph
from .scene import Scene, as_color, as_scene

__all__ = ["add_world", "add_camera", "add_trajectory", "add_graph", "add_image", "add_particles", "add_landmarks"]


def _textured_mesh(vertices: np.ndarray, faces: np.ndarray, uvs: np.ndarray):
    """A meshcat BufferGeometry with texture coordinates (three.js ``uv`` attribute)."""
    from meshcat.geometry import TriangularMeshGeometry, pack_numpy_array

    class TexturedMesh(TriangularMeshGeometry):
        def lower(self, object_data):
            data = super().lower(object_data)
            data["data"]["attributes"]["uv"] = pack_numpy_array(np.asarray(uvs, np.float32).T)
            return data

    return TexturedMesh(vertices, faces)


def _atlas(world: World, cell: int) -> tuple[np.ndarray, int]:
    """Pack every surface texture, shrunk to ``cell`` x ``cell`` pixels, into one square image."""
    n = len(world.surfaces)
    cols = int(np.ceil(np.sqrt(n)))
    atlas = np.zeros((cols * cell, cols * cell, 3), np.uint8)
    for k, s in enumerate(world.surfaces):
        r, c = divmod(k, cols)
        atlas[r * cell:(r + 1) * cell, c * cell:(c + 1) * cell] = cv2.resize(s.texture, (cell, cell),
                                                                             interpolation=cv2.INTER_AREA)
    return atlas, cols


def add_world(scene: Scene, world: World, path: str = "world", cell: int = 48, ceiling: bool = False) -> Scene:
    """Add a world's textured surfaces as one mesh (one texture atlas), plus its footprint in red.

    Parameters
    ----------
    scene : Scene
    world : World
    path : str, default "world"
    cell : int, default 48
        Pixels per surface in the texture atlas (small keeps the HTML page light).
    ceiling : bool, default False
        Draw the ceiling and an outdoor world's far backdrop (surfaces named ``backdrop/...``: sky
        band and far ground of :func:`robokit.sim.open_field`); hidden by default so the scene can
        be seen from above.

    Returns
    -------
    Scene

    Notes
    -----
    One ``BufferGeometry`` with ``uv`` coordinates into an atlas image (three.js texture
    mapping); the world's own surfaces, so the 3D view matches what the cameras render.

    Examples
    --------
    >>> from robokit import sim
    >>> from robokit.viz import Scene, add_world
    >>> scene = add_world(Scene(), sim.box_room())
    >>> scene.html().count("meshcat") > 0
    True
    """
    as_scene(scene, path)
    from meshcat.geometry import ImageTexture, Mesh, MeshBasicMaterial, PngImage

    if not isinstance(world, World):
        raise TypeError(f"world: expected a robokit.sim World, got {type(world).__name__}")
    cell = as_int(cell, "cell", minimum=4)
    atlas, cols = _atlas(world, cell)
    verts, faces, uvs = [], [], []
    size = cols * cell
    for k, s in enumerate(world.surfaces):
        if not ceiling and ((s.normal[2] < -0.5 and s.corner[2] >= world.height - 1e-6)
                            or s.name.startswith("backdrop/")):
            continue
        r, c = divmod(k, cols)
        u0, u1 = (c * cell + 0.5) / size, ((c + 1) * cell - 0.5) / size
        v0, v1 = 1 - (r * cell + 0.5) / size, 1 - ((r + 1) * cell - 0.5) / size  # three.js flips images
        base = len(verts)
        verts.extend(s.corners)  # corner, +u, +u+v, +v
        uvs.extend([[u0, v0], [u1, v0], [u1, v1], [u0, v1]])
        faces.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]])
    ok, png = cv2.imencode(".png", cv2.cvtColor(atlas, cv2.COLOR_RGB2BGR))
    texture = ImageTexture(PngImage(png.tobytes()))
    scene.set_object(f"{path}/surfaces", Mesh(_textured_mesh(np.array(verts), np.array(faces), np.array(uvs)),
                                              MeshBasicMaterial(map=texture, side=2)))
    seg = world.segments
    pts = np.concatenate([np.column_stack([seg[:, 0], np.full(len(seg), 0.01)]),
                          np.column_stack([seg[:, 1], np.full(len(seg), 0.01)])], axis=1).reshape(-1, 3)
    return _segments(scene, f"{path}/footprint", pts, 0xCC2222)


def _segments(scene: Scene, path: str, pts: np.ndarray, color: Any) -> Scene:
    from meshcat.geometry import LineBasicMaterial, LineSegments, PointsGeometry

    return scene.set_object(path, LineSegments(PointsGeometry(np.asarray(pts, np.float32).T),
                                               LineBasicMaterial(color=as_color(color))))


def add_camera(scene: Scene, path: str, camera: PinholeCamera, T_world_cam: Any, depth: float = 0.4,
               color: Any = 0x2255CC) -> Scene:
    """Draw a pinhole camera as a frustum (apex at the optical centre) plus its axes.

    Parameters
    ----------
    scene : Scene
    path : str
    camera : PinholeCamera
    T_world_cam : array_like (4, 4)
        Pose of the camera's optical frame in the world (e.g. ``camera.transform_at(robot_pose)``).
    depth : float, default 0.4
        Distance of the drawn image rectangle from the apex (metres).

    Returns
    -------
    Scene

    Notes
    -----
    The image corners back-projected to depth ``depth`` (Hartley & Zisserman 2004, Sec. 6.2.2).

    Examples
    --------
    >>> from robokit import sim
    >>> from robokit.viz import Scene, add_camera
    >>> camera = sim.PinholeCamera.from_fov()
    >>> add_camera(Scene(), "camera", camera, camera.transform_at([1.0, 1.0, 0.0]))   # frustum and axes
    Scene(title='robokit scene', commands=3)
    """
    as_scene(scene, path)
    if not isinstance(camera, PinholeCamera):
        raise TypeError(f"camera: expected a PinholeCamera, got {type(camera).__name__}")
    d = as_positive(depth, "depth")
    T_world_cam = as_se3(T_world_cam, "T_world_cam")
    corners = np.array([[0, 0], [camera.width - 1, 0], [camera.width - 1, camera.height - 1], [0, camera.height - 1]], float)
    P = camera.backproject(corners, np.full(4, d), T_world_cam)
    apex = np.asarray(T_world_cam, float)[:3, 3]
    lines = []
    for k in range(4):
        lines += [apex, P[k], P[k], P[(k + 1) % 4]]
    _segments(scene, f"{path}/frustum", np.array(lines), color)
    return scene.add_triad(f"{path}/axes", T_world_cam, scale=d / 2)


def add_trajectory(scene: Scene, path: str, poses: Any, z: float = 0.02, color: Any = 0x22AA22,
                   every: int = 0) -> Scene:
    """Draw a planar trajectory ``(N, 3)`` as a polyline at height ``z``; optionally a triad every ``every`` poses.

    Parameters
    ----------
    scene : Scene
    path : str
    poses : array_like (N, 3)
        ``[x, y, theta]`` rows (at least two).
    z : float, default 0.02
        Drawing height (metres).
    color : int or RGB
    every : int, default 0
        Draw a coordinate triad every ``every`` poses (0: none).

    Returns
    -------
    Scene

    Notes
    -----
    Planar poses lifted with :func:`robokit.geometry.se2_to_se3`.

    Examples
    --------
    >>> from robokit.viz import Scene, add_trajectory
    >>> add_trajectory(Scene(), "path", [[0, 0, 0], [1, 0, 0.5], [2, 1, 1.0]], every=2)   # line + 2 triads
    Scene(title='robokit scene', commands=5)
    """
    as_scene(scene, path)
    P = as_points(poses, "poses", 3, min_count=2)
    z = as_finite_scalar(z, "z")
    step = as_int(every, "every", minimum=0)
    scene.add_line(f"{path}/line", np.column_stack([P[:, :2], np.full(len(P), z)]), color=color)
    if step:
        for k in range(0, len(P), step):
            scene.add_triad(f"{path}/pose{k}", se2_to_se3(P[k], z), scale=0.2)
    return scene


def add_graph(scene: Scene, path: str, poses: Any, edges: Any, z: float = 0.05, node_color: Any = 0x2255CC,
              edge_color: Any = 0x2255CC, size: float = 0.12) -> Scene:
    """Draw a pose graph at height ``z``: nodes as points, edges as line segments.

    Parameters
    ----------
    scene : Scene
    path : str
    poses : array_like (N, 3)
        Node poses ``[x, y, theta]``.
    edges : array_like of int (M, 2)
        Node index pairs.
    z : float, default 0.05
        Drawing height (metres).
    node_color, edge_color : int or RGB
    size : float, default 0.12
        Node point size (metres).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError, TypeError
        For malformed poses or edges to missing nodes.

    Notes
    -----
    The topological map of lesson 02's paper (Sec. "Environment map", Fig. 1 and 8).

    Examples
    --------
    >>> from robokit.viz import Scene, add_graph
    >>> add_graph(Scene(), "map", [[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 1], [1, 2], [2, 0]])
    Scene(title='robokit scene', commands=2)
    """
    as_scene(scene, path)
    P, E = as_graph(poses, edges)
    z = as_finite_scalar(z, "z")
    lifted = np.column_stack([P[:, :2], np.full(len(P), z)])
    scene.add_points(f"{path}/nodes", lifted, size=as_positive(size, "size"), color=node_color)
    if len(E):
        _segments(scene, f"{path}/edges", lifted[E.reshape(-1)], edge_color)
    return scene


def add_image(scene: Scene, path: str, image: Any, centre: Any, width: float = 1.5) -> Scene:
    """Lay an RGB image flat (facing up) at ``centre``, e.g. a robot's omni view above its node.

    Parameters
    ----------
    scene : Scene
    path : str
    image : array_like (H, W, 3) uint8
        RGB image; drawn with its top row towards +y.
    centre : array_like, shape (3,)
        World position of the image's centre (metres).
    width : float, default 1.5
        Width in metres (the height follows the aspect ratio).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError, TypeError
        For an image that is not (H, W, 3) uint8, a bad centre or a non-positive width.

    Notes
    -----
    A textured quad (meshcat mesh with an image texture), as :func:`add_world` draws surfaces.

    Examples
    --------
    >>> from robokit.viz import Scene, add_image
    >>> add_image(Scene(), "view", np.zeros((4, 6, 3), np.uint8), [1.0, 2.0, 3.0])
    Scene(title='robokit scene', commands=1)
    """
    as_scene(scene, path)
    from meshcat.geometry import ImageTexture, Mesh, MeshBasicMaterial, PngImage

    img = np.asarray(image)
    if img.ndim != 3 or img.shape[2] != 3 or img.dtype != np.uint8 or min(img.shape[:2]) < 1:
        raise ValueError(f"image: expected an (H, W, 3) uint8 RGB image, got {img.dtype} of shape {img.shape}")
    c = as_array(centre, "centre", shape=(3,))
    w = as_positive(width, "width")
    h = w * img.shape[0] / img.shape[1]
    verts = c + np.array([[-w / 2, -h / 2, 0], [w / 2, -h / 2, 0], [w / 2, h / 2, 0], [-w / 2, h / 2, 0]])
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    ok, png = cv2.imencode(".png", cv2.cvtColor(img, cv2.COLOR_RGB2BGR))
    return scene.set_object(path, Mesh(_textured_mesh(verts, np.array([[0, 1, 2], [0, 2, 3]]), uvs),
                                       MeshBasicMaterial(map=ImageTexture(PngImage(png.tobytes())), side=2)))


def add_particles(scene: Scene, path: str, particles: Any, weights: Any = None, z: float = 0.03,
                  arrow: float = 0.15, color: Any = 0xAA2288, size: float = 0.04) -> Scene:
    """Draw a particle cloud ``(N, 3)`` of planar poses: points plus short heading strokes.

    Weights (optional, ``(N,)`` non-negative) scale the stroke length, so likely particles stand out;
    ``size`` is the points' size in metres (larger for a view from far away).

    Notes
    -----
    The usual display of Monte Carlo localization (Thrun et al. 2005, Sec. 8.3, Fig. 8.11).

    Examples
    --------
    >>> from robokit.viz import Scene, add_particles
    >>> add_particles(Scene(), "cloud", [[0.0, 0.0, 0.0], [1.0, 0.5, 1.5]], weights=[0.2, 0.8])
    Scene(title='robokit scene', commands=2)
    """
    as_scene(scene, path)
    P = as_points(particles, "particles", 3, min_count=1)
    if weights is None:
        w = np.ones(len(P))
    else:
        w = as_array(weights, "weights", shape=(len(P),))
        if np.any(w < 0) or w.sum() <= 0:
            raise ValueError("weights: expected non-negative weights with a positive sum")
        w = w / w.max()
    L = as_positive(arrow, "arrow") * (0.3 + 0.7 * w)
    base = np.column_stack([P[:, :2], np.full(len(P), as_finite_scalar(z, "z"))])
    tip = base + np.column_stack([L * np.cos(P[:, 2]), L * np.sin(P[:, 2]), np.zeros(len(P))])
    scene.add_points(f"{path}/points", base, size=as_positive(size, "size"), color=color)
    return _segments(scene, f"{path}/headings", np.stack([base, tip], axis=1).reshape(-1, 3), color)


def add_landmarks(scene: Scene, path: str, points: Any, covariances: Any = None, nsigma: float = 1.0,
                  colors: Any = None, max_ellipsoids: int = 500) -> Scene:
    """Draw 3D landmarks with optional covariance ellipsoids (``nsigma``-standard-deviation surfaces).

    Parameters
    ----------
    points : array_like (N, 3)
    covariances : array_like (N, 3, 3), optional
        Symmetric positive semi-definite covariances (m^2).
    nsigma : float, default 1
        Ellipsoid scale in standard deviations (Se et al. 2002 draw 1 sigma), as in
        :func:`robokit.viz.plot_covariance`.
    colors : array_like (N, 3), optional
        RGB in [0, 1].
    max_ellipsoids : int, default 500
        Draw at most this many ellipsoids (the first ones) to keep the page light.

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        For shape mismatches or covariances that are not symmetric PSD.

    Notes
    -----
    Principal axes from the eigen-decomposition ``C = V diag(l) V^T``, radii ``nsigma sqrt(l)``
    (Se, Lowe & Little 2002, Sec. 3.6: landmark uncertainty drawn as ellipsoids).

    Examples
    --------
    >>> import numpy as np
    >>> from robokit.viz import Scene, add_landmarks
    >>> points = [[1.0, 0.0, 1.0], [2.0, 0.0, 1.0]]
    >>> add_landmarks(Scene(), "landmarks", points, np.stack([0.01 * np.eye(3)] * 2))  # points + 2 ellipsoids
    Scene(title='robokit scene', commands=5)
    """
    as_scene(scene, path)
    from meshcat.geometry import Ellipsoid, MeshLambertMaterial

    P = as_points(points, "points", 3, min_count=1)
    scene.add_points(f"{path}/points", P, colors=colors, size=0.05)
    if covariances is None:
        return scene
    C = as_array(covariances, "covariances", shape=(len(P), 3, 3))
    if not np.allclose(C, np.swapaxes(C, 1, 2), atol=1e-12):
        raise ValueError("covariances: expected symmetric matrices")
    lam, V = np.linalg.eigh(C)
    if np.any(lam < -1e-12):
        raise ValueError("covariances: expected positive semi-definite matrices, got a negative eigenvalue")
    s = as_positive(nsigma, "nsigma")
    for k in range(min(len(P), as_int(max_ellipsoids, "max_ellipsoids", minimum=0))):
        R = V[k] * np.sign(np.linalg.det(V[k]))
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, P[k]
        radii = np.maximum(s * np.sqrt(np.clip(lam[k], 0, None)), 1e-4)
        scene.set_object(f"{path}/ellipsoid{k}", Ellipsoid(radii.tolist()),
                         MeshLambertMaterial(color=0xFFAA00, opacity=0.35, transparent=True))
        scene.set_transform(f"{path}/ellipsoid{k}", T)
    return scene
