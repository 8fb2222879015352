"""Keypoints as maxima of a response in scale space, refined by a quadratic (PLOT's scale selection).

A detector that computes a response (PLOT's junction strength ``lambda_2``, Lin et al. Sec. 2.i) at
a series of scales keeps a point where the response is the largest of its 26 neighbours: the 8
around it on its level (the paper's 8-neighbour search) and the 9 at the same place on each adjacent
level (an extremum in scale, as in Lindeberg's scale selection and SIFT's difference-of-Gaussian
extrema). Levels may be sampled on grids of different spacing (SIFT-like octaves); the adjacent
levels are read by bilinear lookup at the candidates' neighbourhoods only. Position and scale are
then refined together by the peak of the quadratic through the 3 x 3 x 3 neighbourhood (Lowe 2004,
Sec. 4, Eq. 3). :func:`robokit.vision.detect_plot` uses it.

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [2] T. Lindeberg, "Feature detection with automatic scale selection", International Journal of
   Computer Vision 30(2), 79-116, 1998.
.. [3] D. G. Lowe, "Distinctive image features from scale-invariant keypoints", International Journal
   of Computer Vision 60(2), 91-110, 2004.
"""
from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from ..validation import as_array, as_int, as_positive, describe

__all__ = ["scale_space_maxima"]


def scale_space_maxima(responses: Any, steps: Any, threshold: float, border: int, *,
                       validate: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Keypoints where a response is the maximum of its 3 x 3 x 3 neighbourhood in scale space.

    Parameters
    ----------
    responses : sequence of array_like, each shape (H_n, W_n)
        The response at each level, finest first (at least three levels: only inner levels can
        hold a maximum). Level ``n`` is sampled every ``steps[n]`` original pixels.
    steps : array_like of int, shape (n_levels,)
        Each level's pixel spacing; adjacent levels have the same spacing or one twice the other.
    threshold : float
        Keep maxima whose response exceeds this (>= 0).
    border : int
        Ignore maxima closer than this to the image border (original pixels, >= 1).
    validate : bool, default True
        ``False`` skips the input checks (the detector's fast path; float32 responses expected).

    Returns
    -------
    xy : numpy.ndarray, shape (N, 2)
        Positions in original pixels ``(x, y) = (col, row)``.
    level : numpy.ndarray, shape (N,)
        Fractional level index (the scale is ``sigma_0 k^level``).
    strength : numpy.ndarray, shape (N,)
        The response at the maximum's sample.

    Raises
    ------
    TypeError
        If ``responses`` is not a sequence of levels (or a 3-D array).
    ValueError
        For fewer than three levels, a level that is not 2-D, not finite or smaller than 3 x 3,
        ``steps`` of another length or not positive integers, adjacent steps that are not equal or
        in ratio 2, a level whose shape does not match its neighbour's at those steps (the coarser
        is the finer sampled every second pixel), a negative threshold or a border below 1.

    Notes
    -----
    Lin et al. Sec. 2.i (8-neighbour maxima at each scale of the series); the scale neighbours as
    in Lindeberg (1998); the refinement is one Newton step of Lowe (2004), Eq. 3, clipped to half a
    sample.

    Examples
    --------
    >>> import numpy as np
    >>> r = [np.zeros((9, 9), np.float32) for _ in range(3)]
    >>> r[1][4, 5], r[0][4, 5], r[2][4, 5] = 1.0, 0.5, 0.5     # a peak at (x, y) = (5, 4) on level 1
    >>> xy, level, strength = scale_space_maxima(r, [1, 1, 1], 0.1, 1)
    >>> xy.tolist(), level.tolist(), strength.tolist()
    ([[5.0, 4.0]], [1.0], [1.0])
    """
    if validate:
        responses, steps = _checked_levels(responses, steps)
        threshold = as_positive(threshold, "threshold", allow_zero=True)
        border = as_int(border, "border", minimum=1)
    dilated = [cv2.dilate(r, np.ones((3, 3), np.uint8)) for r in responses]
    found = [_level_maxima(n, responses, dilated, np.asarray(steps), threshold, border)
             for n in range(1, len(responses) - 1)]
    xy, level, strength = (np.concatenate([f[i] for f in found]) for i in range(3))
    return xy, level, strength


def _checked_levels(responses: Any, steps: Any) -> tuple[list, np.ndarray]:
    """The levels as float32 arrays and their steps, or a named error: at least three finite 2-D levels
    of at least 3 x 3 samples, each adjacent pair on the same grid or one subsampled by two from the
    other (``level[::2, ::2]``, as the detector's octaves are)."""
    if isinstance(responses, np.ndarray):
        if responses.ndim != 3:
            raise ValueError(f"responses: expected a sequence of 2-D levels or a 3-D array, got shape "
                             f"{responses.shape}")
        responses = list(responses)
    if not isinstance(responses, (list, tuple)):
        raise TypeError(f"responses: expected a sequence of 2-D levels, got {describe(responses)}")
    if len(responses) < 3:
        raise ValueError(f"responses: expected at least 3 levels (maxima lie on inner ones), got {len(responses)}")
    levels = [as_array(r, f"responses[{n}]", ndim=2, dtype=np.float32) for n, r in enumerate(responses)]
    for n, r in enumerate(levels):
        if min(r.shape) < 3:
            raise ValueError(f"responses[{n}]: expected at least 3 x 3 samples, got shape {r.shape}")
    steps = as_array(steps, "steps", shape=(len(levels),), dtype=None)
    if steps.dtype.kind not in "iu" or np.any(steps < 1):
        raise ValueError(f"steps: expected positive integers, got {steps.tolist()}")
    for n in range(len(levels) - 1):
        (fine, coarse), ratio = (levels[n], levels[n + 1]), steps[n + 1] / steps[n]
        if ratio == 0.5:
            fine, coarse, ratio = coarse, fine, 2.0
        expected = fine.shape if ratio == 1 else tuple(-(-d // 2) for d in fine.shape) if ratio == 2 else None
        if expected is None:
            raise ValueError(f"steps: expected adjacent levels with equal spacing or one twice the other, got "
                             f"{steps.tolist()}")
        if coarse.shape != expected:
            raise ValueError(f"responses[{n}], responses[{n + 1}]: expected shapes that match steps {int(steps[n])} "
                             f"and {int(steps[n + 1])} (the coarser level is the finer one sampled every second "
                             f"pixel), got {levels[n].shape} and {levels[n + 1].shape}")
    return levels, steps


def _lookup(img: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Bilinear samples of ``img`` at grid positions ``(x, y)`` (clamped to the grid), shaped as ``x``."""
    n = x.size
    if not n:
        return np.zeros(x.shape, img.dtype)
    # OpenCV's maps must be under 32767 on each side: lay the samples out in rows of 1024
    width = min(n, 1024)
    rows = -(-n // width)
    mx, my = np.zeros((2, rows * width), np.float32)
    mx[:n], my[:n] = x.ravel(), y.ravel()
    out = cv2.remap(img, mx.reshape(rows, width), my.reshape(rows, width), cv2.INTER_LINEAR,
                    borderMode=cv2.BORDER_REPLICATE)
    return out.ravel()[:n].reshape(x.shape)


#: Row and column offsets of a 3 x 3 neighbourhood, row-major (index 4 is the centre).
_ROW_OFFSETS, _COL_OFFSETS = (g.ravel() for g in np.meshgrid([-1, 0, 1], [-1, 0, 1], indexing="ij"))


def _cubes(n: int, responses: list, steps: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """The responses around each candidate of level ``n``: shape (N, 3, 3, 3) as (level, row, col).

    The candidate's own level is read directly; the adjacent levels, whose grids may be twice as
    fine or as coarse, by bilinear lookup at the same places in original pixels. (Bilinear lookup
    flattens a peak between coarse samples, which pulls the selected scale of a structure just
    above a grid change towards the finer level, by up to 0.07 octave for a Gaussian blob; bicubic
    lookup removes that but overshoots at step edges and lost two corners of a plain square.)
    """
    cube = np.empty((rows.size, 3, 3, 3), np.float32)
    r, c = rows[:, None] + _ROW_OFFSETS, cols[:, None] + _COL_OFFSETS
    cube[:, 1] = responses[n][r, c].reshape(-1, 3, 3)
    for side, m in ((0, n - 1), (2, n + 1)):
        ratio = steps[n] / steps[m]
        cube[:, side] = _lookup(responses[m], c * ratio, r * ratio).reshape(-1, 3, 3)
    return cube


def _quadratic_peak(cube: np.ndarray) -> np.ndarray:
    """Offset (level, row, col) of the peak of the quadratic through each 3 x 3 x 3 cube.

    One Newton step ``offset = -H^-1 g`` with the gradient ``g`` and Hessian ``H`` from central
    differences (Lowe 2004, Sec. 4, Eq. 3), clipped to +-0.5 so that a keypoint never leaves its
    cell; a cube whose Hessian is not negative definite keeps offset zero.
    """
    c = cube.astype(float)
    centre = c[:, 1, 1, 1]
    g = 0.5 * np.stack([c[:, 2, 1, 1] - c[:, 0, 1, 1], c[:, 1, 2, 1] - c[:, 1, 0, 1], c[:, 1, 1, 2] - c[:, 1, 1, 0]], 1)
    h = np.empty((len(c), 3, 3))
    h[:, 0, 0] = c[:, 2, 1, 1] - 2 * centre + c[:, 0, 1, 1]
    h[:, 1, 1] = c[:, 1, 2, 1] - 2 * centre + c[:, 1, 0, 1]
    h[:, 2, 2] = c[:, 1, 1, 2] - 2 * centre + c[:, 1, 1, 0]
    h[:, 0, 1] = h[:, 1, 0] = 0.25 * (c[:, 2, 2, 1] - c[:, 2, 0, 1] - c[:, 0, 2, 1] + c[:, 0, 0, 1])
    h[:, 0, 2] = h[:, 2, 0] = 0.25 * (c[:, 2, 1, 2] - c[:, 2, 1, 0] - c[:, 0, 1, 2] + c[:, 0, 1, 0])
    h[:, 1, 2] = h[:, 2, 1] = 0.25 * (c[:, 1, 2, 2] - c[:, 1, 2, 0] - c[:, 1, 0, 2] + c[:, 1, 0, 0])
    # negative definite: leading principal minors alternate in sign (-, +, -)
    m2 = h[:, 0, 0] * h[:, 1, 1] - h[:, 0, 1] ** 2
    peak = (h[:, 0, 0] < 0) & (m2 > 0) & (np.linalg.det(h) < 0)
    offset = np.zeros((len(c), 3))
    if peak.any():
        offset[peak] = -np.linalg.solve(h[peak], g[peak][:, :, None])[:, :, 0]
    return np.clip(offset, -0.5, 0.5)


def _level_maxima(n: int, responses: list, dilated: list, steps: np.ndarray, thr: float, border: int) -> tuple:
    """Keypoints at inner level ``n``: thresholded maxima of their 3 x 3 x 3 scale-space neighbourhood.

    Returns ``(xy, level, strength)``: positions in original pixels and fractional levels, both
    refined by the peak of a quadratic through the neighbourhood (:func:`_quadratic_peak`).
    """
    resp, step = responses[n], int(steps[n])
    b = max(1, min(-(-border // step), (min(resp.shape) - 1) // 2))   # border in this grid's pixels
    is_max = (resp >= dilated[n]) & (resp > thr)
    is_max[:b], is_max[-b:], is_max[:, :b], is_max[:, -b:] = False, False, False, False
    rows, cols = np.nonzero(is_max)
    cube = _cubes(n, responses, steps, rows, cols)
    strength = cube[:, 1, 1, 1]
    keep = strength >= cube.reshape(-1, 27).max(axis=1)     # no weaker than any of its 26 neighbours
    rows, cols, cube, strength = rows[keep], cols[keep], cube[keep], strength[keep]
    offset = _quadratic_peak(cube)
    xy = np.column_stack([cols + offset[:, 2], rows + offset[:, 1]]) * step
    return xy, n + offset[:, 0], strength
