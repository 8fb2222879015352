"""Rasterise a world of textured rectangles through a pinhole camera (colour and depth).

Each surface is a plane, so the map from its texture to the image is a homography
``H = K [r1, r2, t]`` (Hartley & Zisserman 2004, Sec. 8.1.1 and Eq. (13.2)); OpenCV's ``warpPerspective`` applies it to the texture, and a z-buffer keeps the
nearest surface per pixel. On a plane ``n . X = d`` (camera frame), inverse depth is an affine
function of the pixel, ``1/Z = n . K^-1 [u, v, 1]^T / d``, so the depth image costs one multiply-add
per pixel. Surfaces outside the view frustum are culled before any pixel work, polygons are clipped
against a near plane (so no point behind the camera is ever projected) and far, small-looking
textures are read from a coarser mip-map level (Williams 1983) to avoid aliasing. What needs no
pixels (projection, bounding box, plane, mip level, homography) is computed for every surface of
a frame at once; the rest (clipping a polygon that reaches behind the near plane, rasterisation,
z-test, texture warp) goes surface by surface, in the world's order.

Pixel convention (OpenCV): the centre of pixel ``(col, row)`` is at image coordinates
``(u, v) = (col, row)``.

References
----------
.. [1] R. Hartley and A. Zisserman, *Multiple View Geometry in Computer Vision*, 2nd ed., Cambridge
   University Press, 2004.
.. [2] L. Williams, "Pyramidal parametrics", *Computer Graphics (Proc. SIGGRAPH)* 17(3), 1-11, 1983.
.. [3] E. Catmull, *A subdivision algorithm for computer display of curved surfaces*, PhD thesis,
   University of Utah, 1974.
"""
from __future__ import annotations

import cv2
import numpy as np

from .world import World

__all__ = ["render_pinhole"]


def _clip(poly: np.ndarray, normal: np.ndarray, offset: float) -> np.ndarray:
    """Sutherland-Hodgman clipping of a 3D polygon (camera frame) against ``normal . X >= offset``."""
    out = []
    n = len(poly)
    s = poly @ normal - offset
    for i in range(n):
        j = (i + 1) % n
        if s[i] >= 0:
            out.append(poly[i])
        if (s[i] >= 0) != (s[j] >= 0):
            out.append(poly[i] + s[i] / (s[i] - s[j]) * (poly[j] - poly[i]))
    return np.array(out).reshape(-1, 3)


#: Pixels beyond which a projected polygon is also clipped to the view frustum's sides: edges
#: millions of pixels long (an outdoor ground reaching behind the camera) make cv2.fillPoly take
#: ~25 ms each, and fixed point with shift 4 overflows int32 at 1.3e8. Indoor polygons stay below
#: ~7e4 px, so their rasterisation is left exactly as it was.
_FAR_PIXELS = 1e5


def render_pinhole(world: World, K: np.ndarray, width: int, height: int, T_world_cam: np.ndarray,
                   near: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    """Render colour and depth of ``world`` seen by a pinhole camera (no input checking).

    Parameters
    ----------
    world : World
    K : numpy.ndarray, shape (3, 3)
        Intrinsic matrix.
    width, height : int
        Image size in pixels.
    T_world_cam : numpy.ndarray, shape (4, 4)
        Camera pose (OpenCV optical frame: x right, y down, z forward).
    near : float, default 0.02
        Near clipping distance (metres).

    Returns
    -------
    image : numpy.ndarray, uint8, shape (height, width, 3)
        RGB image; pixels that see no surface are black.
    depth : numpy.ndarray, float32, shape (height, width)
        Z coordinate (metres, along the optical axis) of the surface seen at each pixel; ``inf``
        where no surface is seen.

    Notes
    -----
    Public callers use :meth:`robokit.sim.PinholeCamera.render`, which validates its inputs.
    Planar homography: Hartley & Zisserman (2004), Sec. 8.1.1; z-buffer: Catmull (1974).
    """
    R_cw = T_world_cam[:3, :3].T
    P = (world.corner_array - T_world_cam[:3, 3]) @ R_cw.T  # (N, 4, 3) corners in the camera frame
    idx = _in_view(P, K, width, height, near)
    Pk = P[idx]
    polygons, box, zmin, zmax, seen = _image_polygons(Pk, K, width, height, near)
    plane, edge_on, level, M = _texture_maps(world.surface_arrays, idx, Pk, R_cw, K, box, zmin, zmax)
    seen &= ~edge_on                    # a plane seen edge-on covers no pixel area
    image = np.zeros((height, width, 3), np.uint8)
    zinv_buf = np.zeros((height, width), np.float32)
    # each surface in turn (in the world's order, which settles ties): rasterise, z-test, texture
    drawn = np.flatnonzero(seen)
    outlines = _fixed_point(polygons, box, drawn)
    box = box.astype(int).tolist()
    # 1/Z = (w0 u + w1 v) + w2 in float64, as one expression over the box would give it, with the
    # products made once per column and per row (of every drawn surface at once), not once per pixel
    col_terms = plane[drawn, :1] * np.arange(width, dtype=np.float32)
    row_terms = plane[drawn, 1:2] * np.arange(height, dtype=np.float32)
    for k, i in enumerate(drawn.tolist()):
        x0, y0, x1, y1 = box[i]
        zi = np.add.outer(row_terms[k, y0:y1 + 1], col_terms[k, x0:x1 + 1])
        zi += plane[i, 2]
        zi = zi.astype(np.float32)
        mask = np.zeros((y1 - y0 + 1, x1 - x0 + 1), np.uint8)
        cv2.fillPoly(mask, [outlines[k]], 1, lineType=cv2.LINE_8, shift=4)
        sub_z = zinv_buf[y0:y1 + 1, x0:x1 + 1]
        update = zi > sub_z                 # the z-buffer keeps the largest inverse depth (Catmull 1974)
        update &= mask.view(bool)           # fillPoly wrote 0 or 1
        if not update.any():
            continue
        tex = world.surfaces[idx[i]].pyramid[level[i]]
        warped = cv2.warpPerspective(tex, M[i], (x1 - x0 + 1, y1 - y0 + 1), flags=cv2.INTER_LINEAR,
                                     borderMode=cv2.BORDER_REPLICATE)
        # OpenCV's masked copy writes into the views (the image and the z-buffer) in place
        cv2.copyTo(warped, update.view(np.uint8), image[y0:y1 + 1, x0:x1 + 1])
        cv2.copyTo(zi, update.view(np.uint8), sub_z)
    # inverse depth is 0 (1/Z = inf) where no surface was drawn and positive elsewhere
    with np.errstate(divide="ignore"):
        depth = np.float32(1.0) / zinv_buf
    return image, depth


def _in_view(P: np.ndarray, K: np.ndarray, width: int, height: int, near: float) -> np.ndarray:
    """Indices of the surfaces (corners ``P``, camera frame) not culled: a surface is culled when all
    its corners lie outside one side of the view frustum."""
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    x, y, z = P[..., 0], P[..., 1], P[..., 2]
    outside = [z < near, fx * x + (cx + 0.5) * z < 0, fx * x - (width - 0.5 - cx) * z > 0,
               fy * y + (cy + 0.5) * z < 0, fy * y - (height - 0.5 - cy) * z > 0]
    return np.flatnonzero(~np.any([o.all(axis=1) for o in outside], axis=0))


def _image_polygons(Pk: np.ndarray, K: np.ndarray, width: int, height: int, near: float) -> tuple:
    """Every surface in view at once: its polygon in the image (clipped where needed), its bounding
    box ``(x0, y0, x1, y1)`` in the image, its depth range and whether it covers any pixel."""
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = _project(Pk, fx, fy, cx, cy)                                    # (n, 4, 2)
        simple = (Pk[..., 2] >= near).all(axis=1) & (np.abs(uv).max(axis=(1, 2), initial=0.0) <= _FAR_PIXELS)
    lo, hi = np.floor(uv.min(axis=1, initial=np.inf)), np.ceil(uv.max(axis=1, initial=-np.inf))
    zmin, zmax = Pk[..., 2].min(axis=1, initial=np.inf), Pk[..., 2].max(axis=1, initial=-np.inf)
    polygons, seen = list(uv), simple.copy()
    for i in np.flatnonzero(~simple):   # a corner behind the near plane, or very far off the image: clip
        clipped = _clip_to_view(Pk[i], fx, fy, cx, cy, width, height, near)
        if clipped is not None:
            poly, polygons[i] = clipped
            lo[i], hi[i] = np.floor(polygons[i].min(axis=0)), np.ceil(polygons[i].max(axis=0))
            zmin[i], zmax[i] = poly[:, 2].min(), poly[:, 2].max()
            seen[i] = True
    box = np.column_stack([np.maximum(lo, 0), np.minimum(hi, [width - 1, height - 1])])  # x0, y0, x1, y1
    seen &= (box[:, 2] >= box[:, 0]) & (box[:, 3] >= box[:, 1])
    box[~seen] = 0                      # never drawn; keeps inf and NaN out of the integer box
    return polygons, box, zmin, zmax, seen


def _fixed_point(polygons: list, box: np.ndarray, drawn: np.ndarray) -> list:
    """The outlines of the ``drawn`` surfaces for ``cv2.fillPoly`` with ``shift=4``: int32 vertices in
    sixteenths of a pixel from each one's box corner; the unclipped quadrilaterals all at once."""
    quads = [i for i in drawn.tolist() if len(polygons[i]) == 4]
    corners = box[:, None, :2]
    fixed = dict(zip(quads, np.round((np.array([polygons[i] for i in quads]).reshape(-1, 4, 2) - corners[quads]) * 16)
                          .astype(np.int32)))
    return [fixed[i] if i in fixed else np.round((polygons[i] - corners[i]) * 16).astype(np.int32)
            for i in drawn.tolist()]


def _texture_maps(arrays: dict, idx: np.ndarray, Pk: np.ndarray, R_cw: np.ndarray, K: np.ndarray, box: np.ndarray,
                  zmin: np.ndarray, zmax: np.ndarray) -> tuple:
    """Per surface: its inverse-depth plane over the pixels, whether it is seen edge-on (no plane), the
    mip level of its texture and the homography from that level to its bounding box (H&Z Sec. 8.1.1)."""
    fx = K[0, 0]
    # inverse depth is affine in the pixel: plane n.X = d in the camera frame, 1/Z = (K^-T n / d) . [u, v, 1]
    n_c = arrays["normal"][idx] @ R_cw.T
    d = np.einsum("ij,ij->i", n_c, Pk[:, 0])
    edge_on = ~(np.abs(d) >= 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        plane = np.linalg.solve(K.T, n_c.T).T / d[:, None]
        # mip level: texels per pixel at a representative depth of the visible part
        zref = np.minimum(np.sqrt(zmin * zmax), 3 * zmin)
        texels_per_pixel = zref / fx * arrays["mip_sizes"][idx, 0, 0] / arrays["u_length"][idx]
        level = np.floor(np.log2(np.maximum(np.nan_to_num(texels_per_pixel, nan=1.0), 1.0)))
    level = np.clip(level, 0, arrays["mip_levels"][idx] - 1).astype(int)
    # homography from the chosen level's texture (pixel centres) to the bounding box
    size = arrays["mip_sizes"][idx, level]
    a_col = (arrays["u"][idx] @ R_cw.T) / size[:, :1]
    b_col = (arrays["v"][idx] @ R_cw.T) / size[:, 1:]
    M = K @ np.stack([a_col, b_col, Pk[:, 0] + 0.5 * (a_col + b_col)], axis=-1)
    M[:, 0] -= box[:, :1] * M[:, 2]
    M[:, 1] -= box[:, 1:2] * M[:, 2]
    return plane, edge_on, level, M


def _project(points: np.ndarray, fx: float, fy: float, cx: float, cy: float) -> np.ndarray:
    """Pixel coordinates ``(..., 2)`` of camera-frame points ``(..., 3)`` (Hartley & Zisserman, Eq. (6.1))."""
    return np.stack([fx * points[..., 0] / points[..., 2] + cx, fy * points[..., 1] / points[..., 2] + cy], axis=-1)


def _clip_to_view(corners: np.ndarray, fx: float, fy: float, cx: float, cy: float, width: int, height: int,
                  near: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The part of a surface (camera frame) in front of the near plane, also clipped to the view's
    sides when its image would reach beyond :data:`_FAR_PIXELS`, and its image (:func:`_project`);
    ``None`` if nothing is left."""
    poly = _clip(corners, np.array([0.0, 0.0, 1.0]), near)
    if len(poly) < 3:
        return None
    uv = _project(poly, fx, fy, cx, cy)
    if np.abs(uv).max() > _FAR_PIXELS:
        # clip to planes through the optical centre 2 px outside the image: what falls inside the
        # image is unchanged, and projected coordinates stay small
        for normal in ([fx, 0.0, cx + 2], [-fx, 0.0, width + 1 - cx], [0.0, fy, cy + 2], [0.0, -fy, height + 1 - cy]):
            poly = _clip(poly, np.array(normal), 0.0)
        if len(poly) < 3:
            return None
        uv = _project(poly, fx, fy, cx, cy)
    return poly, uv
