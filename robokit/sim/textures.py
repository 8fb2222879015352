"""Textures for simulated worlds: seeded procedural patterns and photographs shipped with matplotlib.

Every texture is an ``(H, W, 3)`` ``uint8`` RGB image. Procedural textures are built from a
``numpy.random.Generator`` so a world looks the same on every run; they carry structure at several
scales (blobs, edges, printed text) so that corner and blob detectors such as SIFT and ORB find
stable keypoints on them, as they do on real posters and notice boards. Photographs come from
matplotlib's bundled sample data, so nothing is downloaded.

:func:`illuminate` changes brightness (gain, offset and a linear gradient) for lighting-change
experiments.

References
----------
.. [1] K. Perlin, "An image synthesizer", *SIGGRAPH Computer Graphics* 19(3), 1985, pp. 287-296.
.. [2] D. G. Lowe, "Distinctive image features from scale-invariant keypoints", *International
   Journal of Computer Vision* 60(2), 2004, pp. 91-110.
.. [3] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features",
   IEEE/RSJ International Conference on Intelligent Robots and Systems (IROS), 2002.
.. [4] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering*, 2023,
   doi:10.1631/FITEE.2200208.
"""
from __future__ import annotations

import functools
from typing import Any

import cv2
import numpy as np

from ..validation import as_array, as_rng, as_choice, as_finite_scalar, as_int, as_positive

__all__ = ["PHOTOS", "photo", "noise_texture", "plaster", "floor_tiles", "ceiling_panels", "wood",
           "poster", "notice_board", "door", "room_plate", "illuminate"]

#: Photographs available from matplotlib's sample data (name -> file name).
PHOTOS = {
    "grace_hopper": "grace_hopper.jpg",
    "present": "Minduka_Present_Blue_Pack.png",
    "logo": "logo2.png",
    "dem": "jacksboro_fault_dem.npz",
    "topobathy": "topobathy.npz",
}


def _size(width: Any, height: Any) -> tuple[int, int]:
    return as_int(width, "width", minimum=8), as_int(height, "height", minimum=8)


@functools.lru_cache(maxsize=None)
def _load_photo(name: str) -> np.ndarray:
    import matplotlib.cbook as cbook
    import matplotlib.image as mimage
    from matplotlib import colormaps

    path = cbook.get_sample_data(PHOTOS[name], asfileobj=False)
    if str(path).endswith(".npz"):
        with np.load(path) as data:  # elevation grids, shown as colour-mapped "maps on a wall"
            z = data["elevation"] if "elevation" in data.files else data["topo"]
        z = (z - z.min()) / max(np.ptp(z), 1e-9)
        rgb = colormaps["gist_earth" if name == "dem" else "terrain"](z)[..., :3]
        img = (rgb * 255).astype(np.uint8)
        return cv2.resize(img, (img.shape[1] * 2, img.shape[0] * 2), interpolation=cv2.INTER_CUBIC)
    img = mimage.imread(path)
    if img.dtype != np.uint8:
        img = (np.clip(img, 0, 1) * 255).astype(np.uint8)
    if img.shape[2] == 4:  # composite transparency on white paper
        alpha = img[..., 3:4].astype(np.float32) / 255
        img = (img[..., :3] * alpha + 255 * (1 - alpha)).astype(np.uint8)
    return np.ascontiguousarray(img[..., :3])


def photo(name: str) -> np.ndarray:
    """Return a photograph (or colour-mapped elevation map) shipped with matplotlib.

    Parameters
    ----------
    name : str
        One of :data:`PHOTOS`.

    Returns
    -------
    numpy.ndarray, shape (H, W, 3), uint8
        A copy, safe to modify.

    Raises
    ------
    ValueError
        If ``name`` is unknown.

    Notes
    -----
    Real images give detectors natural texture statistics (Se, Lowe & Little 2002, Sec. 2 use
    SIFT on real lab scenes); matplotlib's sample data are installed with matplotlib.

    Examples
    --------
    >>> img = photo("grace_hopper")
    >>> img.shape, img.dtype
    ((600, 512, 3), dtype('uint8'))
    """
    as_choice(name, "name", list(PHOTOS))
    return _load_photo(name).copy()


def noise_texture(width: int, height: int, rng: Any = None, *, base: Any = (180, 180, 180),
                  amplitude: float = 40.0, scales: tuple = (4, 16, 64), tint: float = 0.06) -> np.ndarray:
    """Coloured multi-scale value noise around a base colour.

    Parameters
    ----------
    width, height : int
        Size in pixels (at least 8).
    rng : numpy.random.Generator or int, optional
        Randomness source (seeded; ``None`` means seed 0).
    base : array_like, shape (3,)
        Mean RGB colour, 0-255.
    amplitude : float, default 40
        Standard deviation of the brightness variation (grey levels).
    scales : tuple of int
        Feature sizes in pixels; one octave of smoothly interpolated noise per scale.
    tint : float, default 0.06
        Standard deviation of a random relative colour shift of the whole texture.

    Returns
    -------
    numpy.ndarray, shape (height, width, 3), uint8

    Raises
    ------
    ValueError, TypeError
        For bad sizes, colours or amplitudes.

    Notes
    -----
    Value noise summed over octaves (Perlin 1985, Sec. 4 uses the same sum-of-octaves idea with
    gradient noise).
    """
    w, h = _size(width, height)
    rng = as_rng(rng)
    base = as_array(base, "base", shape=(3,))
    amp = as_positive(amplitude, "amplitude", allow_zero=True)
    acc = np.zeros((h, w), np.float32)
    for s in scales:
        s = as_int(s, "scales", minimum=1)
        small = rng.standard_normal((max(2, h // s + 2), max(2, w // s + 2))).astype(np.float32)
        acc += cv2.resize(small, (w, h), interpolation=cv2.INTER_CUBIC)
    acc *= amp / max(float(acc.std()), 1e-6)
    shift = rng.normal(0, as_positive(tint, 'tint', allow_zero=True), 3)
    img = base[None, None, :] * (1 + shift) + acc[..., None]
    return np.clip(img, 0, 255).astype(np.uint8)


def plaster(width: int, height: int, rng: Any = None, tone: Any = (214, 208, 196)) -> np.ndarray:
    """Painted wall: faint large-scale blotches and fine grain (few keypoints, like real walls).

    Parameters
    ----------
    width, height : int
    rng : Generator or int, optional
    tone : array_like, shape (3,)
        Paint colour.

    Returns
    -------
    numpy.ndarray, uint8 (height, width, 3)

    Notes
    -----
    Value noise as in :func:`noise_texture`; the low contrast mimics painted plaster, on which Ge
    et al. (2023, Sec. 3.2) note that features come mostly from boards and plates instead.
    """
    return noise_texture(width, height, rng, base=tone, amplitude=10.0, scales=(3, 40), tint=0.01)


def floor_tiles(width: int, height: int, rng: Any = None, tile: int = 64) -> np.ndarray:
    """Floor of square tiles with grout lines and speckled, per-tile varying colour.

    Parameters
    ----------
    width, height : int
    rng : Generator or int, optional
    tile : int, default 64
        Tile size in pixels.

    Returns
    -------
    numpy.ndarray, uint8 (height, width, 3)

    Notes
    -----
    Procedural pattern (course design, no paper): speckle gives texture to feature detectors.
    """
    rng = as_rng(rng)
    tile = as_int(tile, "tile", minimum=4)
    img = noise_texture(width, height, rng, base=(150, 140, 125), amplitude=22.0, scales=(2, 8), tint=0.01)
    h, w = img.shape[:2]
    shade = rng.normal(0, 12, (h // tile + 1, w // tile + 1))
    img = np.clip(img + np.kron(shade, np.ones((tile, tile)))[:h, :w, None], 0, 255).astype(np.uint8)
    img[::tile, :] = (90, 85, 80)
    img[:, ::tile] = (90, 85, 80)
    return img


def ceiling_panels(width: int, height: int, rng: Any = None) -> np.ndarray:
    """Suspended-ceiling panels with a metal grid and the odd light fitting.

    Notes
    -----
    Procedural pattern (course design, no paper). Parameters as :func:`floor_tiles`.
    """
    rng = as_rng(rng)
    img = noise_texture(width, height, rng, base=(228, 228, 224), amplitude=8.0, scales=(2, 6), tint=0.005)
    h, w = img.shape[:2]
    step = max(8, min(h, w) // 2)
    for y in range(0, h, step):
        for x in range(0, w, step):
            if rng.random() < 0.2:
                cv2.rectangle(img, (x + step // 5, y + step // 5), (x + 4 * step // 5, y + 4 * step // 5),
                              (250, 250, 240), -1)
    img[::step, :] = (120, 120, 125)
    img[:, ::step] = (120, 120, 125)
    return img


def wood(width: int, height: int, rng: Any = None) -> np.ndarray:
    """Wood grain (furniture): stretched noise with knots.

    Notes
    -----
    Procedural pattern (course design, no paper). Parameters as :func:`floor_tiles`.
    """
    rng = as_rng(rng)
    w, h = _size(width, height)
    grain = noise_texture(max(8, w // 8), h, rng, base=(150, 105, 60), amplitude=30.0, scales=(1, 4))
    img = cv2.resize(grain, (w, h), interpolation=cv2.INTER_LINEAR)
    for _ in range(int(rng.integers(1, 4))):
        centre = (int(rng.integers(0, w)), int(rng.integers(0, h)))
        cv2.ellipse(img, centre, (max(2, w // 30), max(2, h // 12)), 0, 0, 360, (90, 55, 30), 2)
    return img


_WORDS = ["ROBOTICS", "SEMINAR", "VISION", "LAB", "EXIT", "MEETING", "KALMAN", "SIFT", "MAP", "LIDAR",
          "NOTICE", "POSTER", "SAFETY", "TALK", "COFFEE", "PHD", "DEFENCE", "OPEN DAY", "ROOM", "WELCOME"]


def poster(width: int, height: int, rng: Any = None, photo_name: str | None = None) -> np.ndarray:
    """A poster: coloured background, random shapes, a title in large letters and a photo or chart.

    Parameters
    ----------
    width, height : int
    rng : Generator or int, optional
    photo_name : str, optional
        Name from :data:`PHOTOS` to paste in the middle; by default one is drawn at random.

    Returns
    -------
    numpy.ndarray, uint8 (height, width, 3)

    Notes
    -----
    Procedural pattern (course design, no paper). Distinct posters make repetitive corridors
    distinguishable by appearance, as the bulletin boards in Ge et al. (2023, Sec. 3.2, Fig. 5).
    """
    rng = as_rng(rng)
    w, h = _size(width, height)
    bg = rng.integers(40, 230, 3)
    img = noise_texture(w, h, rng, base=bg, amplitude=15.0, scales=(4, 32))
    for _ in range(int(rng.integers(6, 14))):
        colour = tuple(int(c) for c in rng.integers(0, 256, 3))
        x, y = int(rng.integers(0, w)), int(rng.integers(0, h))
        r = int(rng.integers(max(2, min(w, h) // 30), max(3, min(w, h) // 6)))
        if rng.random() < 0.5:
            cv2.circle(img, (x, y), r, colour, -1)
        else:
            cv2.rectangle(img, (x - r, y - r // 2), (x + r, y + r // 2), colour, -1)
    name = photo_name if photo_name is not None else list(PHOTOS)[int(rng.integers(len(PHOTOS)))]
    pic = photo(name)
    pw, ph = int(w * 0.7), int(h * 0.45)
    pic = cv2.resize(pic, (pw, ph), interpolation=cv2.INTER_AREA)
    y0, x0 = int(h * 0.3), (w - pw) // 2
    img[y0:y0 + ph, x0:x0 + pw] = pic
    words = " ".join(rng.choice(_WORDS, 2))
    scale = max(0.3, w / 260)
    ink = (255, 255, 255) if bg.mean() < 128 else (0, 0, 0)
    cv2.putText(img, words, (max(2, w // 20), max(12, int(h * 0.2))), cv2.FONT_HERSHEY_DUPLEX, scale, ink,
                max(1, int(scale * 2)), cv2.LINE_AA)
    for k in range(3):
        line = " ".join(rng.choice(_WORDS, 3)).lower()
        cv2.putText(img, line, (max(2, w // 20), int(h * (0.82 + 0.055 * k))), cv2.FONT_HERSHEY_SIMPLEX,
                    scale * 0.5, ink, 1, cv2.LINE_AA)
    return img


def notice_board(width: int, height: int, rng: Any = None) -> np.ndarray:
    """A cork board with pinned sheets of paper and printed lines.

    Notes
    -----
    Procedural pattern (course design, no paper). Parameters as :func:`floor_tiles`.
    """
    rng = as_rng(rng)
    img = noise_texture(width, height, rng, base=(170, 120, 75), amplitude=25.0, scales=(1, 3))
    h, w = img.shape[:2]
    for _ in range(int(rng.integers(5, 10))):
        sw, sh = int(rng.integers(w // 8, w // 3)), int(rng.integers(h // 6, h // 2))
        x, y = int(rng.integers(0, max(1, w - sw))), int(rng.integers(0, max(1, h - sh)))
        paper = tuple(int(c) for c in rng.integers(200, 256, 3))
        cv2.rectangle(img, (x, y), (x + sw, y + sh), paper, -1)
        for k in range(int(rng.integers(2, 7))):
            yy = y + 8 + k * max(6, sh // 8)
            if yy < y + sh - 3:
                length = int(rng.integers(sw // 3, sw))
                cv2.line(img, (x + 4, yy), (x + max(5, length - 4), yy), (40, 40, 40), 1)
        cv2.circle(img, (x + sw // 2, y + 4), 3, tuple(int(c) for c in rng.integers(0, 256, 3)), -1)
    return img


def door(width: int, height: int, rng: Any = None) -> np.ndarray:
    """A door leaf with a frame, a handle and a small window.

    Notes
    -----
    Procedural pattern (course design, no paper). Parameters as :func:`floor_tiles`.
    """
    rng = as_rng(rng)
    base = rng.choice([(120, 80, 50), (90, 110, 140), (170, 160, 140), (80, 120, 90)])
    img = noise_texture(width, height, rng, base=base, amplitude=12.0, scales=(2, 16))
    h, w = img.shape[:2]
    cv2.rectangle(img, (2, 2), (w - 3, h - 3), (50, 40, 30), max(2, w // 40))
    cv2.rectangle(img, (w // 4, h // 8), (3 * w // 4, h // 3), (200, 220, 230), -1)
    cv2.circle(img, (int(w * 0.85), h // 2), max(3, w // 30), (200, 200, 210), -1)
    return img


def room_plate(number: str, width: int = 160, height: int = 64, rng: Any = None) -> np.ndarray:
    """A room-number plate: the number in large digits on a coloured sign.

    Parameters
    ----------
    number : str
        Text to print, e.g. ``"B214"``.
    width, height : int
    rng : Generator or int, optional

    Returns
    -------
    numpy.ndarray, uint8 (height, width, 3)

    Notes
    -----
    Ge et al. (2023, Sec. 3.2) observe that room numbers carry much of a corridor's distinctive
    texture; procedural, no paper equation.
    """
    if not isinstance(number, str) or not number:
        raise TypeError(f"number: expected a non-empty string, got {number!r}")
    rng = as_rng(rng)
    w, h = _size(width, height)
    img = np.empty((h, w, 3), np.uint8)
    img[:] = rng.integers(20, 120, 3)
    cv2.rectangle(img, (2, 2), (w - 3, h - 3), (230, 230, 230), 2)
    scale = h / 40
    cv2.putText(img, number, (w // 10, int(h * 0.75)), cv2.FONT_HERSHEY_DUPLEX, scale, (250, 250, 250),
                max(1, int(scale * 2)), cv2.LINE_AA)
    return img


def illuminate(image: Any, gain: float = 1.0, offset: float = 0.0, gradient: Any = (0.0, 0.0)) -> np.ndarray:
    """Change the lighting of a uint8 image: ``I' = clip(gain * g(x, y) * I + offset)``.

    Parameters
    ----------
    image : array_like, uint8, shape (H, W) or (H, W, 3)
    gain : float, default 1
        Global contrast factor (> 0).
    offset : float, default 0
        Added brightness in grey levels.
    gradient : array_like, shape (2,), default (0, 0)
        Relative change of gain per image width and per image height: ``g = 1 + gx (x/W - 1/2) +
        gy (y/H - 1/2)``, e.g. ``(0.6, 0)`` darkens the left side and brightens the right.

    Returns
    -------
    numpy.ndarray, uint8, same shape

    Raises
    ------
    ValueError, TypeError
        For a non-uint8 image or bad parameters.

    Notes
    -----
    Affine photometric model (gain and bias), the change SIFT descriptors are normalised against
    (Lowe 2004, Sec. 6.1); the gradient imitates uneven lighting.

    Examples
    --------
    >>> grey = np.full((4, 4, 3), 100, np.uint8)
    >>> illuminate(grey, gain=0.5, offset=10)[0, 0].tolist()          # 0.5 * 100 + 10
    [60, 60, 60]
    >>> illuminate(grey, gradient=(0.5, 0.0))[0, :, 0].tolist()       # darker left, brighter right
    [75, 87, 100, 112]
    """
    img = as_array(image, "image", dtype=None)
    if img.dtype != np.uint8 or img.ndim not in (2, 3) or img.ndim == 3 and img.shape[2] != 3:
        raise TypeError(f"image: expected a uint8 image of shape (H, W) or (H, W, 3), got {img.dtype} {img.shape}")
    g = as_positive(gain, "gain")
    b = as_finite_scalar(offset, "offset")
    gx, gy = as_array(gradient, "gradient", shape=(2,))
    h, w = img.shape[:2]
    field = 1 + gx * (np.arange(w, dtype=np.float32) / w - 0.5)[None, :] \
        + gy * (np.arange(h, dtype=np.float32) / h - 0.5)[:, None]
    if img.ndim == 3:
        field = field[..., None]
    return np.clip(img.astype(np.float32) * (g * field) + b, 0, 255).astype(np.uint8)
