"""Measure screenshots of 3D scenes: decode PNGs, and how much of a shot shows something.

Used by :mod:`robocourse.site.browser` (its :class:`~robocourse.site.browser.SceneShot`) and by the
course site's browser test: a scene is drawn when its shot differs enough from an empty scene's.
"""
from __future__ import annotations

import io
import math
import numbers

import numpy as np

__all__ = ["decode_png", "changed_fraction", "changed_span", "content_fraction"]


def decode_png(png: bytes) -> np.ndarray:
    """Decode PNG bytes into an ``(H, W, 3)`` ``uint8`` RGB array (alpha dropped).

    Examples
    --------
    >>> import io, matplotlib.pyplot as plt
    >>> buf = io.BytesIO(); plt.imsave(buf, np.zeros((2, 3, 3)), format="png")
    >>> decode_png(buf.getvalue()).shape
    (2, 3, 3)
    """
    import matplotlib.image as mimage

    if not isinstance(png, (bytes, bytearray)):
        raise TypeError(f"png: expected bytes, got {type(png).__name__}")
    if not png.startswith(b"\x89PNG\r\n\x1a\n"):
        raise ValueError(f"png: expected PNG data (starting with the PNG signature), got {bytes(png[:8])!r}")
    img = mimage.imread(io.BytesIO(png), format="png")
    if img.ndim == 2:
        img = np.repeat(img[..., None], 3, axis=2)
    img = img[..., :3]
    return (img * 255 + 0.5).astype(np.uint8) if img.dtype.kind == "f" else img.astype(np.uint8)


def _as_image(value: object, name: str) -> np.ndarray:
    """``value`` as a float ``(H, W, 3)`` image in [0, 255] (alpha dropped); errors name ``name``."""
    try:
        img = np.asarray(value)
    except ValueError:                                   # ragged nested lists
        img = np.empty(0, dtype=object)
    if img.dtype.kind not in "uif":
        raise TypeError(f"{name}: expected an image of numbers (uint8 or float), got dtype {img.dtype}")
    if img.ndim != 3 or img.shape[2] not in (3, 4) or img.shape[0] == 0 or img.shape[1] == 0:
        raise ValueError(f"{name}: expected an (H, W, 3) or (H, W, 4) image, got shape {img.shape}")
    img = img[..., :3].astype(float)
    if not np.all(np.isfinite(img)) or img.min() < 0 or img.max() > 255:
        raise ValueError(f"{name}: expected values in [0, 255], got values in [{img.min():g}, {img.max():g}]")
    return img


def _tolerance(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"tolerance: expected a number, got {value!r:.60}")
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"tolerance: expected a finite number >= 0, got {value!r}")
    return float(value)


def _image_pair(image: object, reference: object, tolerance: object) -> tuple[np.ndarray, np.ndarray, float]:
    img, ref = _as_image(image, "image"), _as_image(reference, "reference")
    if img.shape != ref.shape:
        raise ValueError(f"reference: expected the image's shape {img.shape[:2] + (3,)}, got {ref.shape}")
    return img, ref, _tolerance(tolerance)


def changed_fraction(image: np.ndarray, reference: np.ndarray, *, tolerance: float = 30.0) -> float:
    """Fraction of pixels of ``image`` that differ from ``reference`` (e.g. an empty scene's shot).

    A pixel differs when the sum of its absolute red, green and blue differences exceeds
    ``tolerance`` (0-255 scale), which ignores anti-aliasing noise.

    Parameters
    ----------
    image, reference : array_like
        ``(H, W, 3)`` or ``(H, W, 4)`` images of the same height and width, values in [0, 255].
    tolerance : float
        Summed difference below which two pixels count as equal.

    Returns
    -------
    float
        In [0, 1].

    Examples
    --------
    >>> empty = np.full((4, 4, 3), 200, dtype=np.uint8)
    >>> shot = empty.copy(); shot[:2, :2] = (255, 0, 255)       # a magenta box over a quarter
    >>> changed_fraction(shot, empty)
    0.25
    """
    img, ref, tolerance = _image_pair(image, reference, tolerance)
    return float((np.abs(img - ref).sum(axis=2) > tolerance).mean())


def content_fraction(image: np.ndarray, *, tolerance: float = 30.0) -> float:
    """Fraction of pixels of ``image`` that differ from its background, taken row by row.

    Each row's background is its most common colour (meshcat's background is a vertical
    gradient, the same across a row). Without a reference shot this is an estimate: the grid and
    axes of an empty scene count as content, and where content fills most of a row that row's
    content is not counted; :func:`changed_fraction` against an empty scene is exact.

    Parameters
    ----------
    image : array_like
        An ``(H, W, 3)`` or ``(H, W, 4)`` image, values in [0, 255].
    tolerance : float
        Summed red, green and blue difference below which a pixel counts as background.

    Returns
    -------
    float
        In [0, 1].

    Examples
    --------
    >>> shot = np.zeros((4, 4, 3)); shot[:, :, 2] = [[10], [20], [30], [40]]   # a vertical gradient
    >>> shot[1:3, 1] = (255, 255, 0)                                           # a small yellow post
    >>> content_fraction(shot)
    0.125
    """
    img = _as_image(image, "image")
    tolerance = _tolerance(tolerance)
    rgb = np.round(img).astype(np.int64)
    packed = (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
    changed = 0
    for row, colours in zip(img, packed):
        values, counts = np.unique(colours, return_counts=True)
        mode = values[np.argmax(counts)]
        background = np.array([(mode >> 16) & 255, (mode >> 8) & 255, mode & 255], dtype=float)
        changed += int((np.abs(row - background).sum(axis=1) > tolerance).sum())
    return changed / (img.shape[0] * img.shape[1])


def changed_span(image: np.ndarray, reference: np.ndarray, *, tolerance: float = 30.0,
                 trim: float = 0.01) -> float:
    """How much of the view what differs from ``reference`` spans: the larger of the height and
    width fractions of the box around the changed pixels (between the ``trim`` and ``1 - trim``
    quantiles of their rows and columns, so a few stray pixels do not count).

    A drawing made of lines (a robot arm, a path) changes few pixels however well it is framed, and
    a long corridor framed whole is a strip; a view framed on what it shows is spanned by it in
    at least one direction, a speck on the grid in neither.

    Parameters
    ----------
    image, reference : array_like
        ``(H, W, 3)`` or ``(H, W, 4)`` images of the same height and width, values in [0, 255].
    tolerance : float
        Summed difference below which two pixels count as equal (as in :func:`changed_fraction`).
    trim : float
        Share of changed pixels ignored at each end, in [0, 0.5).

    Returns
    -------
    float
        In [0, 1]; 0 if nothing changed.

    Examples
    --------
    >>> empty = np.full((10, 20, 3), 200, dtype=np.uint8)
    >>> shot = empty.copy(); shot[2, 1:17] = 0; shot[4:7, 9] = 0      # a long thin line and a tick
    >>> round(changed_fraction(shot, empty), 3), changed_span(shot, empty, trim=0.0)
    (0.095, 0.8)
    """
    img, ref, tolerance = _image_pair(image, reference, tolerance)
    if isinstance(trim, bool) or not isinstance(trim, numbers.Real) or not 0 <= trim < 0.5:
        raise ValueError(f"trim: expected a number in [0, 0.5), got {trim!r:.60}")
    rows, cols = np.nonzero(np.abs(img - ref).sum(axis=2) > tolerance)
    if rows.size == 0:
        return 0.0
    r0, r1 = np.quantile(rows, [trim, 1 - trim])
    c0, c1 = np.quantile(cols, [trim, 1 - trim])
    return float(max((r1 - r0 + 1) / img.shape[0], (c1 - c0 + 1) / img.shape[1]))
