"""PLOT keypoints: Polynomial Local Orientation Tensor (Lin, Wang, Sun & Sun, Sec. 2.i).

Each pixel's neighbourhood is approximated by a second-order polynomial
``f(x) ~ x^T A x + b^T x + c`` whose coefficients are Gaussian-derivative responses of the smoothed
image ``L = G_sigma * I`` (the Maclaurin expansion of Sec. 2.i): ``c = L``, ``b = (L_x, L_y)`` and
``A = 1/2 [[L_xx, L_xy], [L_xy, L_yy]]``. The scale-normalised orientation tensor
``T = sigma^4 A A^T + gamma sigma^2 b b^T`` (Farnebaeck's polynomial-expansion tensor, normalised
so that responses at different ``sigma`` are comparable) is averaged over a Gaussian window and split
into an edge part ``lambda_1 - lambda_2`` and a junction part ``lambda_2``.

Scale selection. The paper's multi-scale strategy is the series ``sigma_n = sigma_0 k^n`` with a
small ``n`` ("n = 3 to accelerate the computation") and an 8-neighbour maximum search; it gives no
value of ``k`` and does not say how a keypoint's scale is chosen (our copy's equations are
unnumbered, so we cite the section). Within that series we use three levels per octave
(``k = 2^(1/3)``) over nine levels (``sigma`` from 1.6 to 10.2 px, about three octaves), and keep a
point when its junction strength is the maximum of its 26 neighbours in scale space (the paper's 8
at its level and 9 on each adjacent level): an extremum in scale of the scale-normalised response,
as in Lindeberg's scale selection [3] and SIFT's difference-of-Gaussian extrema [4]. Only inner
levels can hold one, so the outermost levels 1.6 and 10.2 px only bracket the search. Position and
scale are refined together by the peak of a quadratic through the 3 x 3 x 3 neighbourhood (Lowe's
Eq. 3 [4]). Comparing only the same place on the adjacent levels, with a parabola per axis,
kept twice as many keypoints and let their scales follow a zoom less closely;
``benchmarks/bench_vision.py`` measures where the selection stands (six real photographs) and
docs/DECISIONS.md what each choice contributed.

Speed. Each level is one incremental Gaussian blur of the previous one; once ``sigma`` is 4 px on
the current grid the level is subsampled by two (SIFT's octaves, though SIFT halves at 3.2 px: PLOT's
tensor, averaged over half a sigma, needs the finer sampling), and the maxima are searched on each
level's own grid (:func:`scale_space_maxima`). Derivatives are fourth-order central
differences, so that a level's response does not depend on how finely its grid samples it. The
normalisation is folded into the derivative kernels and the tensor is accumulated in place in
float32 by OpenCV. :mod:`robokit.vision.plot_readable` keeps the plain full-resolution algorithm,
and the tests compare the two.

OpenCV does the filtering; the tensor, the eigenvalues and the maximum search are the lesson and
are written here, vectorised with numpy.

The search for maxima is :func:`scale_space_maxima`, public because a detector of another response
could use it: levels may be sampled on grids of different spacing, and the adjacent levels are read
by bilinear lookup at the candidates' neighbourhoods only.

References
----------
.. [1] R. Lin, Z. Wang, R. Sun and L. Sun, "Vision-based mobile robot localization and mapping using
   the PLOT features" (Question 1 of the course's assignment; our copy gives no venue or year).
.. [2] G. Farnebäck, *Polynomial Expansion for Orientation and Motion Estimation*, PhD thesis,
   Linköping University, 2002.
.. [3] T. Lindeberg, "Feature detection with automatic scale selection", International Journal of
   Computer Vision 30(2), 79-116, 1998.
.. [4] D. G. Lowe, "Distinctive image features from scale-invariant keypoints", International Journal
   of Computer Vision 60(2), 91-110, 2004.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from ..validation import as_array, as_int, as_positive, describe, require_finite_result
from .features import Keypoints, as_gray_image

__all__ = ["PlotParams", "ScaleSpace", "plot_scales", "polynomial_expansion", "orientation_tensor",
           "tensor_eigenvalues", "junction_strength", "edge_strength", "detect_plot", "detect_plot_levels",
           "scale_space_maxima"]


@dataclass(frozen=True)
class PlotParams:
    """Parameters of the PLOT detector (Lin et al. Sec. 2.i).

    Attributes
    ----------
    sigma0 : float
        Initial scale ``sigma_0`` in pixels.
    k : float
        Scale factor between successive levels (the paper gives none; ``2^(1/3)``, three levels per
        octave as in SIFT).
    n_scales : int
        Number of levels, 3 to 16; keypoints lie on the inner ones (the paper suggests
        ``n = 0..3``; nine levels cover three octaves).
    gamma : float
        Weight of the odd (linear) part ``b b^T`` against the even part ``A A^T`` (the paper gives
        none; 2.0, chosen with ``integration`` by the matching score on the benchmark photographs,
        see docs/DECISIONS.md).
    integration : float
        Tensor averaging window as a multiple of ``sigma_n`` (0.5).
    threshold : float
        Keep maxima whose junction strength exceeds this fraction of the image's largest one
        (the paper thresholds "in advance" without a value; 0.01 gives about four fifths as many
        features as OpenCV's SIFT on the six benchmark photographs).
    min_response : float
        Absolute floor on the junction strength (image in [0, 1]), so that a textureless image
        yields no keypoints rather than amplified noise.
    max_keypoints : int
        Keep at most this many keypoints (strongest first).
    border : int
        Ignore maxima closer than this to the image border (pixels).
    """

    sigma0: float = 1.6
    k: float = 2 ** (1 / 3)
    n_scales: int = 9
    gamma: float = 2.0
    integration: float = 0.5
    threshold: float = 0.01
    min_response: float = 1e-6
    max_keypoints: int = 2000
    border: int = 5

    def __post_init__(self):
        as_positive(self.sigma0, "sigma0")
        if as_positive(self.k, "k") <= 1:
            raise ValueError(f"k: expected a scale factor > 1, got {self.k}")
        as_int(self.n_scales, "n_scales", minimum=3, maximum=16)
        as_positive(self.gamma, "gamma", allow_zero=True)
        as_positive(self.integration, "integration")
        as_positive(self.threshold, "threshold", allow_zero=True)
        as_positive(self.min_response, "min_response", allow_zero=True)
        as_int(self.max_keypoints, "max_keypoints", minimum=1)
        as_int(self.border, "border", minimum=1)


@dataclass(frozen=True)
class ScaleSpace:
    """Gaussian scale space of an image (Lin et al. Sec. 2.i, multi-scale strategy).

    Attributes
    ----------
    sigmas : numpy.ndarray, shape (n,)
        Scale of each level in pixels of the original image.
    images : list of numpy.ndarray
        Smoothed images, float32; level ``n`` is sampled every ``steps[n]`` pixels (the grid is
        halved each time the Gaussian is 4 samples wide on it, as in SIFT's octaves).
    steps : numpy.ndarray of int, shape (n,)
        Pixel spacing of each level: sample ``(i, j)`` is original pixel ``(steps[n] i, steps[n] j)``.
    """

    sigmas: np.ndarray
    images: list
    steps: np.ndarray


def plot_scales(sigma0: float = 1.6, k: float = 2 ** (1 / 3), n_scales: int = 9) -> np.ndarray:
    """Return the multi-scale series ``sigma_n = sigma_0 k^n``, ``n = 0..n_scales-1``.

    Parameters
    ----------
    sigma0 : float
        Initial scale in pixels (> 0).
    k : float
        Scale factor between levels (> 1).
    n_scales : int
        Number of levels, 3 to 16 (Lin et al. suggest 4, n = 0..3; the detector uses 9 at
        ``k = 2^(1/3)``, three octaves).

    Returns
    -------
    numpy.ndarray, shape (n_scales,)

    Raises
    ------
    ValueError
        For ``sigma0 <= 0``, ``k <= 1``, ``n_scales`` outside 3..16, or levels too large to be finite.

    Notes
    -----
    Lin et al. Sec. 2.i, the multi-scale strategy.

    Examples
    --------
    >>> levels = plot_scales()                 # the detector's default levels
    >>> len(levels), round(float(levels[0]), 2), round(float(levels[-1]), 2)
    (9, 1.6, 10.16)
    """
    p = PlotParams(sigma0=sigma0, k=k, n_scales=n_scales)
    with np.errstate(over="ignore"):
        levels = p.sigma0 * p.k ** np.arange(p.n_scales)
    require_finite_result("sigma0, k, n_scales", levels)
    return levels


def _blur(img: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur truncated at 3 sigma (OpenCV's default 4 sigma costs a third more)."""
    size = 2 * int(np.ceil(3.0 * sigma)) + 1
    return cv2.GaussianBlur(img, (size, size), sigma, borderType=cv2.BORDER_REFLECT)


# Fourth-order central differences: on a Gaussian of sigma = 2 samples (a level just moved to a
# coarser grid) the three-point ones lose about 4 % of a first derivative, against 0.2 % for these,
# so a level's response would otherwise depend on how finely its grid samples it.
_FIRST = np.float32([1.0, -8.0, 0.0, 8.0, -1.0]) / np.float32(12.0)     # d/dx
_SECOND = np.float32([-1.0, 16.0, -30.0, 16.0, -1.0]) / np.float32(12.0)  # d2/dx2
_IDENT = np.float32([0.0, 0.0, 1.0, 0.0, 0.0])


def _derivative(img: np.ndarray, dx: int, dy: int) -> np.ndarray:
    # central differences; the image is already Gaussian smoothed, so these are Gaussian derivatives
    kx = (_IDENT, _FIRST, _SECOND)[dx]
    ky = (_IDENT, _FIRST, _SECOND)[dy]
    return cv2.sepFilter2D(img, cv2.CV_32F, kx, ky, borderType=cv2.BORDER_REFLECT)


def polynomial_expansion(image, sigma: float):
    """Second-order polynomial expansion ``f(x) ~ x^T A x + b^T x + c`` at every pixel.

    Parameters
    ----------
    image : array_like, shape (H, W)
        Grey image (see :func:`~robokit.vision.features.as_gray_image`).
    sigma : float
        Gaussian scale in pixels.

    Returns
    -------
    A : numpy.ndarray, shape (H, W, 2, 2)
        Symmetric quadratic term ``1/2 [[L_xx, L_xy], [L_xy, L_yy]]``.
    b : numpy.ndarray, shape (H, W, 2)
        Linear term ``(L_x, L_y)``.
    c : numpy.ndarray, shape (H, W)
        Constant term ``L`` (local DC level).

    Raises
    ------
    ValueError, TypeError
        For an invalid image or a non-positive ``sigma``.

    Notes
    -----
    Lin et al. Sec. 2.i: A and b from the Maclaurin expansion of the Gaussian-smoothed image.
    Coordinates are ``x = (col, row)``.
    """
    img = as_gray_image(image)
    sigma = as_positive(sigma, "sigma")
    c = _blur(img, sigma)
    lx, ly, axx, axy, ayy = _coefficients(c)
    a = np.stack([np.stack([axx, axy], -1), np.stack([axy, ayy], -1)], -2)
    return a, np.stack([lx, ly], -1), c


def _coefficients(smoothed: np.ndarray):
    """Return (L_x, L_y, A_xx, A_xy, A_yy) of a smoothed image (A = half the Hessian)."""
    lx, ly = _derivative(smoothed, 1, 0), _derivative(smoothed, 0, 1)
    return lx, ly, 0.5 * _derivative(smoothed, 2, 0), 0.5 * _derivative(lx, 0, 1), 0.5 * _derivative(smoothed, 0, 2)


def _tensor_components(smoothed: np.ndarray, sigma: float, gamma: float, integration: float):
    """Return the averaged, normalised tensor components (t11, t12, t22) of one level, float32.

    The normalisation is folded into the derivative kernels: ``sigma^2 A`` and
    ``sqrt(gamma) sigma b`` come straight out of the filters, so that
    ``T = (sigma^2 A)^2 + (sqrt(gamma) sigma b)(sqrt(gamma) sigma b)^T`` needs no further scaling.
    """
    s2 = float(sigma) ** 2
    half, root = np.float32(0.5 * s2), np.float32(np.sqrt(float(gamma) * s2))

    def along(kernel):    # a 1-D kernel along x (a row vector) or y (a column vector)
        return cv2.filter2D(smoothed, cv2.CV_32F, kernel, borderType=cv2.BORDER_REFLECT)

    bx, by = along((_FIRST * root)[None, :]), along((_FIRST * root)[:, None])
    axx, ayy = along((_SECOND * half)[None, :]), along((_SECOND * half)[:, None])
    axy = cv2.sepFilter2D(smoothed, cv2.CV_32F, _FIRST * half, _FIRST, borderType=cv2.BORDER_REFLECT)
    # T = A A^T + b b^T of the scaled terms (A symmetric, so A A^T = A^2), accumulated in place
    t11 = cv2.multiply(axx, axx)
    cv2.accumulateSquare(axy, t11)
    cv2.accumulateSquare(bx, t11)
    t22 = cv2.multiply(ayy, ayy)
    cv2.accumulateSquare(axy, t22)
    cv2.accumulateSquare(by, t22)
    t12 = cv2.multiply(cv2.add(axx, ayy), axy)
    cv2.accumulateProduct(bx, by, t12)
    window = float(integration * sigma)
    return _blur(t11, window), _blur(t12, window), _blur(t22, window)


def orientation_tensor(image, sigma: float, *, gamma: float = 2.0, integration: float = 0.5) -> np.ndarray:
    """Normalised local orientation tensor field ``T`` at scale ``sigma``.

    Parameters
    ----------
    image : array_like, shape (H, W)
        Grey image.
    sigma : float
        Character scale in pixels.
    gamma : float, default 2.0
        Weight of the linear (odd) part (the detector's default, :class:`PlotParams`).
    integration : float, default 0.5
        Averaging window as a multiple of ``sigma``.

    Returns
    -------
    numpy.ndarray, shape (H, W, 2, 2)
        Symmetric positive semi-definite tensors.

    Notes
    -----
    Lin et al. Sec. 2.i, ``T = A A^T + gamma b b^T`` with scale-normalised derivatives
    (``sigma^2 A``, ``sigma b``), averaged over a Gaussian window as in Farnebaeck's orientation
    tensor estimation.
    """
    img = as_gray_image(image)
    sigma = as_positive(sigma, "sigma")
    smoothed = _blur(img, sigma)
    t11, t12, t22 = _tensor_components(smoothed, sigma, as_positive(gamma, "gamma", allow_zero=True),
                                       as_positive(integration, "integration"))
    return np.stack([np.stack([t11, t12], -1), np.stack([t12, t22], -1)], -2)


def _eig_sym(t11, t12, t22):
    half_trace = 0.5 * (t11 + t22)
    root = np.sqrt((0.5 * (t11 - t22)) ** 2 + t12 * t12)
    return half_trace + root, np.maximum(half_trace - root, 0.0)


def _junction(t11, t12, t22) -> np.ndarray:
    """``lambda_2`` of :func:`_eig_sym` for float32 component images, in a few OpenCV passes."""
    root = cv2.magnitude(cv2.addWeighted(t11, 0.5, t22, -0.5, 0.0), t12)   # sqrt(((t11 - t22)/2)^2 + t12^2)
    lam2 = cv2.addWeighted(t11, 0.5, t22, 0.5, 0.0)
    lam2 -= root
    return np.maximum(lam2, 0.0, out=lam2)


def tensor_eigenvalues(tensor) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues ``lambda_1 >= lambda_2 >= 0`` of a field of symmetric 2 x 2 tensors.

    Parameters
    ----------
    tensor : array_like, shape (..., 2, 2)
        Symmetric tensors (the orientation tensor is positive semi-definite).

    Returns
    -------
    lambda1, lambda2 : numpy.ndarray, shape (...)

    Raises
    ------
    ValueError
        If the trailing shape is not (2, 2), values are not finite, or a tensor is not symmetric.

    Notes
    -----
    Lin et al. Sec. 2.i, closed form
    ``lambda_{1,2} = (t11 + t22)/2 +- sqrt(((t11 - t22)/2)^2 + t12^2)``; tiny negative values of
    ``lambda_2`` from rounding are clipped to zero.
    """
    t = as_array(tensor, "tensor")
    if t.ndim < 2 or t.shape[-2:] != (2, 2):
        raise ValueError(f"tensor: expected shape (..., 2, 2), got shape {t.shape}")
    scale = max(1.0, float(np.abs(t).max(initial=0.0)))
    if not np.allclose(t[..., 0, 1], t[..., 1, 0], atol=1e-6 * scale):
        raise ValueError("tensor: expected symmetric 2 x 2 tensors, got t12 != t21")
    return _eig_sym(t[..., 0, 0], t[..., 0, 1], t[..., 1, 1])


def junction_strength(tensor) -> np.ndarray:
    """Junction (intrinsically 2-D) strength ``lambda_2`` of a 2 x 2 tensor field.

    Parameters
    ----------
    tensor : array_like, shape (..., 2, 2)
        Symmetric tensors.

    Returns
    -------
    numpy.ndarray, shape (...)
        ``lambda_2``, the smaller eigenvalue: large only where the signal varies in two directions.

    Notes
    -----
    Lin et al. Sec. 2.i: ``T = (lambda_1 - lambda_2) e1 e1^T + lambda_2 I``; ``lambda_2`` is the
    rotation-invariant junction strength that PLOT keypoints maximise.
    """
    return tensor_eigenvalues(tensor)[1]


def edge_strength(tensor) -> np.ndarray:
    """Edge (intrinsically 1-D) strength ``lambda_1 - lambda_2`` of a 2 x 2 tensor field.

    Parameters
    ----------
    tensor : array_like, shape (..., 2, 2)

    Returns
    -------
    numpy.ndarray, shape (...)

    Notes
    -----
    Lin et al. Sec. 2.i, the 1-D part of the tensor decomposition.
    """
    lam1, lam2 = tensor_eigenvalues(tensor)
    return lam1 - lam2


def detect_plot(image, params: PlotParams | None = None, **overrides) -> Keypoints:
    """Detect PLOT keypoints (position, scale, junction response) in a grey image.

    Parameters
    ----------
    image : array_like, shape (H, W) or (H, W, 3)
        Image; integer images are scaled to [0, 1].
    params : PlotParams, optional
        Detector parameters; keyword ``overrides`` replace single fields
        (e.g. ``detect_plot(img, threshold=0.01)``).

    Returns
    -------
    Keypoints
        Sorted by decreasing response, orientation zero (assign it with
        :func:`robokit.vision.descriptors.assign_orientations`). A textureless image gives zero
        keypoints (documented empty result, no error).

    Raises
    ------
    ValueError, TypeError
        For an empty or malformed image or invalid parameters.

    Notes
    -----
    Lin et al. Sec. 2.i. At each scale ``sigma_n = sigma_0 k^n`` the junction strength ``lambda_2``
    of the normalised orientation tensor is thresholded and kept where it is the maximum of its 8
    neighbours (the paper) and of the 9 places around it on both adjacent scales (our scale
    selection, see the module notes); position and scale (``log sigma``) are refined together by
    the peak of a quadratic through that 3 x 3 x 3 neighbourhood (Lowe 2004, Eq. 3).

    Examples
    --------
    >>> from robokit.vision import detect_plot
    >>> import numpy as np
    >>> square = np.zeros((64, 64), np.float32)
    >>> square[20:44, 20:44] = 1.0
    >>> kp = detect_plot(square)
    >>> kp.xy[0].round(1).tolist(), bool(kp.scale[0] > 5)   # strongest: the whole square, at a coarse scale
    ([31.5, 31.5], True)
    >>> len(kp), bool(np.all(np.abs(np.abs(kp.xy[1:] - 31.5) - 9.5) < 2))   # then its four corners
    (5, True)
    """
    return detect_plot_levels(image, params, **overrides)[0]


def detect_plot_levels(image, params: PlotParams | None = None, **overrides):
    """:func:`detect_plot`, also returning the Gaussian scale space it was computed on.

    Parameters
    ----------
    image, params, **overrides
        As for :func:`detect_plot`.

    Returns
    -------
    keypoints : Keypoints
    space : ScaleSpace
        The smoothed images ``L = G_sigma_n * I``, reused for orientations and descriptors
        (Lin et al. Sec. 2.ii computes them "based on the corresponding Gaussian smoothed image").

    Notes
    -----
    Lin et al. Sec. 2.i; see :func:`detect_plot`.
    """
    p = _params(params, overrides)
    img = as_gray_image(image)
    space = _scale_space(img, p)
    responses = [_junction(*_tensor_components(level, float(s / step), p.gamma, p.integration))
                 for level, s, step in zip(space.images, space.sigmas, space.steps)]
    peak = max(float(r.max()) for r in responses)
    thr = max(p.threshold * peak, p.min_response)
    if peak <= thr:
        return Keypoints.empty(), space
    xy, level, strength = _maxima(responses, space.steps, thr, p.border)
    order = np.argsort(-strength, kind="stable")[: p.max_keypoints]
    scale = p.sigma0 * p.k ** level[order]
    keypoints = Keypoints(xy[order], scale, strength[order].astype(float), np.zeros(order.size))
    return keypoints, space


def _params(params, overrides) -> PlotParams:
    p = params if params is not None else PlotParams()
    if not isinstance(p, PlotParams):
        raise TypeError(f"params: expected PlotParams, got {type(p).__name__}")
    return PlotParams(**{**p.__dict__, **overrides}) if overrides else p


#: A level moves to a grid twice as coarse only if its sigma stays at least this many samples wide
#: there (sigma = 4 px before halving). SIFT halves when sigma is 3.2 px, 1.6 samples after; PLOT's
#: tensor, averaged over only half a sigma, needs the finer sampling (docs/DECISIONS.md).
_MIN_SAMPLES = 2.0


def _scale_space(img: np.ndarray, p: PlotParams) -> ScaleSpace:
    """Smoothed levels ``L(x, sigma_n)``, each level one incremental blur of the previous one."""
    sigmas = p.sigma0 * p.k ** np.arange(p.n_scales)
    levels, steps = [], []
    smoothed, prev, step = img, 0.0, 1
    for s in sigmas:
        local = s / step                      # sigma in pixels of the current grid
        # incremental smoothing: G_s = G_sqrt(s^2 - prev^2) * G_prev
        smoothed = _blur(smoothed, float(np.sqrt(local * local - prev * prev)))
        if local / 2 >= _MIN_SAMPLES - 1e-9 and min(smoothed.shape) >= 32:
            # a Gaussian this wide leaves nothing at the pixel scale: halve the grid (as SIFT's octaves)
            smoothed, step, local = smoothed[::2, ::2], step * 2, local / 2
        prev = local
        levels.append(smoothed)
        steps.append(step)
    return ScaleSpace(sigmas, levels, np.array(steps))


def scale_space_maxima(responses: Any, steps: Any, threshold: float,
                       border: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
    responses, steps = _checked_levels(responses, steps)
    return _maxima(responses, steps, as_positive(threshold, "threshold", allow_zero=True),
                   as_int(border, "border", minimum=1))


def _maxima(responses: list, steps: Any, threshold: float, border: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unchecked :func:`scale_space_maxima` (float32 levels; the detector's own call)."""
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

    An adjacent level on the same grid is compared densely (its dilation), which leaves 31 % of the
    3 x 3 maxima above the threshold to gather neighbourhoods for (the six benchmark photographs);
    :func:`_cubes` then checks all 26 neighbours.

    Returns ``(xy, level, strength)``: positions in original pixels and fractional levels, both
    refined by the peak of a quadratic through the neighbourhood (:func:`_quadratic_peak`).
    """
    resp, step = responses[n], int(steps[n])
    b = max(1, min(-(-border // step), (min(resp.shape) - 1) // 2))   # border in this grid's pixels
    is_max = (resp >= dilated[n]) & (resp > thr)
    for m in (n - 1, n + 1):    # an adjacent level on the same grid: its 3 x 3 maxima, compared here at once
        if steps[m] == steps[n]:
            is_max &= resp >= dilated[m]
    is_max[:b], is_max[-b:], is_max[:, :b], is_max[:, -b:] = False, False, False, False
    rows, cols = np.nonzero(is_max)
    cube = _cubes(n, responses, steps, rows, cols)
    strength = cube[:, 1, 1, 1]
    keep = strength >= cube.reshape(-1, 27).max(axis=1)     # no weaker than any of its 26 neighbours
    rows, cols, cube, strength = rows[keep], cols[keep], cube[keep], strength[keep]
    offset = _quadratic_peak(cube)
    xy = np.column_stack([cols + offset[:, 2], rows + offset[:, 1]]) * step
    return xy, n + offset[:, 0], strength
