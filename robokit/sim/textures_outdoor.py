"""Seeded procedural textures for the outdoor field (:func:`robokit.sim.open_field`).

Grass, hedge, tree bark, straw (hay bales), shed planks, painted posts and sky. Like the indoor
textures in :mod:`robokit.sim.textures` they are ``(H, W, 3)`` uint8 RGB images built from a
``numpy.random.Generator`` and carry structure at several scales (leaf blobs, blades, knots,
twine) so that SIFT and ORB find keypoints on them. All are vectorised value noise (Perlin 1985,
Sec. 4: sums of smoothly interpolated noise octaves) plus a few OpenCV drawing calls; no pictures
are downloaded.

References
----------
.. [1] K. Perlin, "An image synthesizer", *SIGGRAPH Computer Graphics* 19(3), 1985, pp. 287-296.
.. [2] N. Greene, "Environment mapping and other applications of world projections", *IEEE
   Computer Graphics and Applications* 6(11), 1986, pp. 21-29.
.. [3] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
"""
from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from ..validation import as_rng, as_int
from .textures import noise_texture

__all__ = ["grass", "hedge", "bark", "straw", "planks", "painted_post", "sky", "STAINS", "PAINTS"]

#: Wood stains of shed planks and paints of posts (RGB); a builder picks one per object so all
#: faces of one shed or post match.
STAINS = ((120, 84, 56), (92, 104, 84), (140, 62, 48))
PAINTS = ((200, 200, 196), (196, 72, 40), (230, 150, 30), (40, 90, 60))


def _octave(w: int, h: int, rng: np.random.Generator, scale: float) -> np.ndarray:
    """One octave of value noise (unit standard deviation) with features ``scale`` pixels wide."""
    small = rng.standard_normal((max(2, int(h / scale) + 2), max(2, int(w / scale) + 2))).astype(np.float32)
    out = cv2.resize(small, (w, h), interpolation=cv2.INTER_CUBIC)
    return out / max(float(out.std()), 1e-6)


def _grain(width: int, height: int, rng: np.random.Generator, base: Any, shrink: tuple[int, int],
           amplitude: float, scales: tuple, tint: float, wobble: float = 0.0, blob: float = 2.0) -> np.ndarray:
    """Noise stretched along one axis (drawn ``shrink`` times smaller, then resized: fibres, ridges,
    grain) with an optional brightness wobble of relative size ``wobble`` and blobs ``blob`` px wide."""
    w, h = as_int(width, "width", minimum=8), as_int(height, "height", minimum=8)
    small = noise_texture(max(8, w // shrink[0]), max(8, h // shrink[1]), rng, base=base, amplitude=amplitude,
                          scales=scales, tint=tint)
    img = cv2.resize(small, (w, h), interpolation=cv2.INTER_CUBIC)
    if wobble:
        img = np.clip(img * (1 + wobble * np.clip(_octave(w, h, rng, blob), -2, 2))[..., None], 0, 255)
    return img.astype(np.uint8)


def grass(width: int, height: int, rng: Any = None) -> np.ndarray:
    """Mown grass with fine speckle (blades), darker tufts and the odd bare-earth patch.

    Parameters
    ----------
    width, height : int
        Size in pixels (at least 8).
    rng : numpy.random.Generator or int, optional

    Returns
    -------
    numpy.ndarray, uint8 (height, width, 3)

    Notes
    -----
    The ground of Hamid et al.'s test site (2009, description of the truck: "semi-rugged terrain
    such a football field", as printed); procedural, no paper equation.
    """
    rng = as_rng(rng)
    img = noise_texture(width, height, rng, base=(78, 124, 52), amplitude=26.0, scales=(1, 3, 10), tint=0.01)
    h, w = img.shape[:2]
    tufts = _octave(w, h, rng, 6.0)
    img = img.astype(np.float32) * (1 + 0.12 * np.clip(tufts, -2, 2))[..., None]
    dirt = np.clip(_octave(w, h, rng, max(w, h) / 3) - 1.3, 0, None)  # a few large patches
    dirt = np.clip(dirt * 2.5, 0, 1)[..., None]
    soil = np.array([128, 100, 66], np.float32) * (1 + 0.15 * _octave(w, h, rng, 2.0))[..., None]
    return np.clip(img * (1 - dirt) + soil * dirt, 0, 255).astype(np.uint8)


def hedge(width: int, height: int, rng: Any = None) -> np.ndarray:
    """A dense hedge or tree line: leaf-sized light and dark blobs over dark green.

    Notes
    -----
    Procedural (course design, no paper); it closes the field all round so a camera always sees
    something. Parameters and returns as :func:`grass`.
    """
    rng = as_rng(rng)
    img = noise_texture(width, height, rng, base=(46, 82, 36), amplitude=22.0, scales=(2, 8, 32), tint=0.06)
    h, w = img.shape[:2]
    img = img.astype(np.float32)
    lit = np.clip(_octave(w, h, rng, 3.0) - 0.8, 0, 1.2)[..., None]    # sunlit leaves
    shade = np.clip(-_octave(w, h, rng, 5.0) - 0.9, 0, 1.2)[..., None]  # holes into the foliage
    img = img + lit * np.array([55, 70, 25], np.float32) - shade * img * 0.6
    return np.clip(img, 0, 255).astype(np.uint8)


def bark(width: int, height: int, rng: Any = None) -> np.ndarray:
    """Tree bark: vertical ridges and dark furrows in grey-brown.

    Notes
    -----
    Procedural (course design, no paper). Parameters and returns as :func:`grass`.
    """
    return _grain(width, height, as_rng(rng), (104, 88, 72), (2, 10), 32.0, (1, 3), 0.05, wobble=0.18, blob=4.0)


def straw(width: int, height: int, rng: Any = None) -> np.ndarray:
    """A square hay bale: yellow straw streaks and two dark twine bands.

    Notes
    -----
    Procedural (course design, no paper). Parameters and returns as :func:`grass`.
    """
    rng = as_rng(rng)
    img = _grain(width, height, rng, (206, 176, 96), (1, 6), 30.0, (1, 4), 0.04, wobble=0.15, blob=2.0)
    h, w = img.shape[:2]
    for x in (w // 3, 2 * w // 3):
        x += int(rng.integers(-max(1, w // 20), max(2, w // 20)))
        cv2.line(img, (x, 0), (x, h - 1), (70, 52, 30), max(1, w // 60))
    return img


def planks(width: int, height: int, rng: Any = None, stain: Any = None) -> np.ndarray:
    """Vertical shed planks with dark joints and knots.

    Notes
    -----
    Procedural (course design, no paper). Parameters and returns as :func:`grass`; ``stain`` is
    an RGB colour (default: one of :data:`STAINS` at random).
    """
    rng = as_rng(rng)
    base = STAINS[int(rng.integers(len(STAINS)))] if stain is None else stain
    img = _grain(width, height, rng, base, (1, 8), 18.0, (1, 3), 0.03)
    h, w = img.shape[:2]
    step = max(4, int(round(w / max(1, round(w / 18)))))
    for x in range(step // 2, w, step):
        cv2.line(img, (x, 0), (x, h - 1), (38, 28, 20), max(1, step // 10))
    for _ in range(int(rng.integers(2, 6))):
        centre = (int(rng.integers(0, w)), int(rng.integers(0, h)))
        cv2.ellipse(img, centre, (max(2, step // 5), max(3, step // 3)), 0, 0, 360, (55, 38, 25), -1)
    return img


def painted_post(width: int, height: int, rng: Any = None, paint: Any = None) -> np.ndarray:
    """A painted post or bin: a plain colour with reflective bands and scuffs.

    Notes
    -----
    Procedural (course design, no paper). Parameters and returns as :func:`grass`; ``paint`` is
    an RGB colour (default: one of :data:`PAINTS` at random).
    """
    rng = as_rng(rng)
    base = PAINTS[int(rng.integers(len(PAINTS)))] if paint is None else paint
    img = noise_texture(width, height, rng, base=base, amplitude=12.0, scales=(1, 6), tint=0.02)
    h, w = img.shape[:2]
    for k in range(1, 4):
        y = int(h * k / 5)
        cv2.rectangle(img, (0, y), (w - 1, y + max(2, h // 24)), (235, 235, 225) if k % 2 else (30, 30, 30), -1)
    return img


def sky(width: int, height: int, rng: Any = None, top: float = 1.0, bottom: float = 0.0) -> np.ndarray:
    """Sky: pale at the horizon, deeper blue higher up, with soft low-contrast clouds.

    Parameters
    ----------
    width, height : int
    rng : Generator or int, optional
    top, bottom : float
        Elevation of the texture's first and last row as a fraction of the sky's height
        (0 horizon, 1 zenith), so tiles stacked around a skybox share one gradient.

    Returns
    -------
    numpy.ndarray, uint8 (height, width, 3)

    Notes
    -----
    A skybox (Greene 1986): the sky is painted on far surfaces rather than left empty, so every pixel has a
    colour and a finite depth.
    """
    rng = as_rng(rng)
    w, h = as_int(width, "width", minimum=8), as_int(height, "height", minimum=8)
    t = np.linspace(top, bottom, h, dtype=np.float32)[:, None, None]
    horizon, zenith = np.array([206, 222, 236], np.float32), np.array([84, 134, 204], np.float32)
    img = horizon * (1 - t) + zenith * t + np.zeros((h, w, 1), np.float32)
    cloud = np.clip(0.5 * (_octave(w, h, rng, 24.0) + 0.4 * _octave(w, h, rng, 6.0) - 0.7), 0, 1)[..., None]
    img = img * (1 - 0.6 * cloud) + 245 * 0.6 * cloud
    return np.clip(img, 0, 255).astype(np.uint8)
