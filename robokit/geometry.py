"""Planar and spatial geometry: angle wrapping and rigid-body poses.

Conventions: SI units; planar poses are ``[x, y, theta]`` with ``theta`` the heading measured
counter-clockwise from the x axis. (The seeds' ``[p, q, theta]`` convention is handled where the
lessons need it.)
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .validation import as_array

__all__ = ["wrap_angle", "se2_compose"]


def wrap_angle(angle: Any) -> Any:
    """Wrap angles to the interval [-pi, pi).

    Parameters
    ----------
    angle : float or array_like
        Angles in radians (finite).

    Returns
    -------
    float or numpy.ndarray
        Same shape as the input; a float for scalar input.

    Raises
    ------
    ValueError
        If any angle is NaN or infinite.

    Notes
    -----
    Standard identity ``(a + pi) mod 2 pi - pi`` (e.g. Thrun, Burgard & Fox, *Probabilistic
    Robotics*, 2005, Sec. 5.4); used by every heading computation in the course.
    """
    a = as_array(angle, "angle")
    out = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return float(out) if out.ndim == 0 else out


def se2_compose(a: Any, b: Any) -> np.ndarray:
    """Compose planar poses: the pose ``b`` expressed in frame ``a``, mapped to the world.

    Parameters
    ----------
    a, b : array_like, shape (3,)
        Poses ``[x, y, theta]``.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``a ⊕ b = [x_a + cos(t_a) x_b - sin(t_a) y_b, y_a + sin(t_a) x_b + cos(t_a) y_b,
        wrap(t_a + t_b)]``.

    Raises
    ------
    ValueError
        If a pose does not have shape (3,) or is not finite.

    Notes
    -----
    The compounding operator of Smith, Self & Cheeseman, "Estimating uncertain spatial
    relationships in robotics" (1990), Eq. (3); it is also Eq. (1)'s composition in Duckett's
    relaxation used by lesson 02.
    """
    pa = as_array(a, "a", shape=(3,))
    pb = as_array(b, "b", shape=(3,))
    c, s = np.cos(pa[2]), np.sin(pa[2])
    return np.array([pa[0] + c * pb[0] - s * pb[1], pa[1] + s * pb[0] + c * pb[1],
                     wrap_angle(pa[2] + pb[2])])
