"""A short, readable version of the PLOT detector, kept beside the tuned one.

:func:`detect_plot_readable` follows Lin et al. Sec. 2.i step by step on the full image grid at
every scale: smooth, build the normalised orientation tensor with the public
:func:`~robokit.vision.plot_detector.orientation_tensor`, take its junction strength ``lambda_2``,
and keep the thresholded points that are maxima of their 26 neighbours in scale space (8 at their
level, 9 on each adjacent level). :func:`~robokit.vision.plot_detector.detect_plot` computes
the same keypoints faster (coarse levels on subsampled grids, in-place float32 arithmetic); the
tests compare the two.

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter

from .features import Keypoints, as_gray_image
from .plot_detector import PlotParams, junction_strength, orientation_tensor, plot_scales

__all__ = ["detect_plot_readable"]


def detect_plot_readable(image, params: PlotParams | None = None) -> Keypoints:
    """PLOT keypoints by the plain full-resolution algorithm (slow; the tests' reference).

    Parameters
    ----------
    image : array_like, shape (H, W) or (H, W, 3)
        Image; integer images are scaled to [0, 1].
    params : PlotParams, optional
        Detector parameters (default :class:`~robokit.vision.plot_detector.PlotParams`).

    Returns
    -------
    Keypoints
        Sorted by decreasing response, at most ``params.max_keypoints``, orientation zero. Positions
        are whole pixels (no sub-pixel refinement); the scale is refined by a parabola in
        ``log sigma`` through the three levels (the fast detector fits position and scale together).

    Raises
    ------
    ValueError, TypeError
        For a malformed image or ``params`` that is not a :class:`PlotParams`.

    Notes
    -----
    Lin et al. Sec. 2.i: junction strength ``lambda_2`` of the normalised orientation tensor at the
    scales ``sigma_n = sigma_0 k^n``, thresholded, 8-neighbour maxima. The comparison with the
    adjacent scales' 3 x 3 neighbourhoods (inner levels only) is our addition, which the paper does
    not describe (docs/DECISIONS.md).

    Examples
    --------
    >>> from robokit.vision.plot_readable import detect_plot_readable
    >>> import numpy as np
    >>> square = np.zeros((64, 64), np.float32)
    >>> square[20:44, 20:44] = 1.0
    >>> kp = detect_plot_readable(square)
    >>> # strongest: the whole square, a blob at a coarse scale, on a whole pixel next to its centre 31.5
    >>> bool(np.abs(kp.xy[0] - 31.5).max() == 0.5), bool(kp.scale[0] > 5)
    (True, True)
    >>> corners = kp.xy[np.abs(kp.xy - 31.5).min(axis=1) > 6]     # the next ones sit near its 4 corners
    >>> len(corners) >= 4, bool(np.all(np.abs(np.abs(corners - 31.5) - 9.5) < 2))
    (True, True)
    """
    p = params if params is not None else PlotParams()
    if not isinstance(p, PlotParams):
        raise TypeError(f"params: expected PlotParams, got {type(p).__name__}")
    img = as_gray_image(image)
    sigmas = plot_scales(p.sigma0, p.k, p.n_scales)
    resp = np.stack([junction_strength(orientation_tensor(img, s, gamma=p.gamma, integration=p.integration))
                     for s in sigmas])                                   # (levels, H, W)
    thr = max(p.threshold * resp.max(), p.min_response)
    is_max = (resp == maximum_filter(resp, size=(3, 3, 3), mode="nearest")) & (resp > thr)
    is_max[0], is_max[-1] = False, False                                 # inner levels only
    b = min(p.border, (min(img.shape) - 1) // 2)
    is_max[:, :b], is_max[:, -b:], is_max[:, :, :b], is_max[:, :, -b:] = False, False, False, False
    lev, rows, cols = np.nonzero(is_max)
    strength = resp[lev, rows, cols]
    below, above = resp[lev - 1, rows, cols], resp[lev + 1, rows, cols]
    den = below - 2 * strength + above
    shift = np.clip(np.divide(0.5 * (below - above), den, out=np.zeros(lev.size), where=den < 0), -0.5, 0.5)
    order = np.argsort(-strength, kind="stable")[: p.max_keypoints]
    return Keypoints(np.column_stack([cols, rows])[order].astype(float), p.sigma0 * p.k ** (lev + shift)[order],
                     strength[order].astype(float), np.zeros(order.size))
