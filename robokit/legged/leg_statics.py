"""Statics of one LittleDog leg: the joint torques a foot force needs, and the foot force from torques.

Joint torques ``tau`` and a force ``f`` at the foot balance when ``tau = J^T f`` (Siciliano & Khatib
2016, Ch. 2, Eq. (2.98), the principle of virtual work), with ``J`` the foot's Jacobian
(:func:`robokit.legged.leg_kinematics.foot_jacobian`). The ground's push on a standing foot follows
from the torques as ``f = J^{-T} (tau_g - tau)``, where ``tau_g`` is what gravity asks of the leg's
own links (:func:`foot_force_from_torques`): the lesson compares it with MuJoCo's contact forces.

References
----------
.. [1] B. Siciliano and O. Khatib (eds.), *Springer Handbook of Robotics*, 2nd ed., Springer, 2016,
   Ch. 2 "Kinematics" (K. Waldron and J. Schmiedeler).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..validation import as_array, require_finite_result, describe
from .leg_kinematics import foot_jacobian

__all__ = ["torques_from_foot_force", "foot_force_from_torques"]


def _vectors(value: Any, name: str, batch: tuple, against: str = "q_leg's") -> np.ndarray:
    """``value`` as 3-vectors (..., 3) whose leading axes broadcast with ``batch`` (the joint angles')."""
    v = as_array(value, name)
    if v.shape[-1:] != (3,):
        raise ValueError(f"{name}: expected shape (..., 3), got {describe(value)}")
    try:
        np.broadcast_shapes(v.shape[:-1], batch)
    except ValueError:
        raise ValueError(f"{name}: expected leading axes that broadcast with {against} {batch}, "
                         f"got shape {v.shape}") from None
    return v


def torques_from_foot_force(q_leg: Any, force: Any, leg: Any) -> np.ndarray:
    """Joint torques that balance a force applied at the foot: ``tau = J^T f``.

    Parameters
    ----------
    q_leg : array_like, shape (..., 3)
    force : array_like, shape (..., 3)
        The force the leg must push with, in the body frame (N) - e.g. minus the ground's reaction.
    leg : str or int

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        N m (Siciliano & Khatib 2016, Eq. (2.98)).

    Examples
    --------
    >>> torques_from_foot_force([0, 0.6, -1.2], [0, 0, -7.4], "FL").round(3).tolist()
    [-0.175, 0.112, 0.426]
    """
    J = foot_jacobian(q_leg, leg)
    f = _vectors(force, "force", J.shape[:-2])
    with np.errstate(over="ignore", invalid="ignore"):
        tau = np.einsum("...ji,...j->...i", J, f)  # Eq. (2.98)
    require_finite_result("force", tau)
    return tau


def foot_force_from_torques(q_leg: Any, tau: Any, leg: Any, gravity_torque: Any = None) -> np.ndarray:
    """The ground's force on a standing foot, from the leg's joint torques: ``f = J^{-T} (tau_g - tau)``.

    Parameters
    ----------
    q_leg : array_like, shape (..., 3)
    tau : array_like, shape (..., 3)
        Torques the motors apply at the joints (N m).
    leg : str or int
    gravity_torque : array_like, shape (..., 3), optional
        Joint torques gravity asks of the leg's own links, ``tau_g`` (MuJoCo's ``qfrc_bias`` at
        rest). Omitted, the legs are taken as massless.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Body frame (N). A quasi-static estimate: the leg's accelerations are neglected.

    Raises
    ------
    ValueError
        If the leg is singular (fully stretched or folded: ``J`` cannot be inverted), if ``tau`` or
        ``gravity_torque`` has leading axes that do not broadcast with ``q_leg``'s, or if the force
        overflows (torques near the largest float).

    Examples
    --------
    >>> q = [0, 0.6, -1.2]
    >>> foot_force_from_torques(q, torques_from_foot_force(q, [0, 0, -7.4], "FL"), "FL").round(3).tolist()
    [0.0, -0.0, 7.4]
    """
    J = foot_jacobian(q_leg, leg)
    t = _vectors(tau, "tau", J.shape[:-2])
    if gravity_torque is not None:
        g = _vectors(gravity_torque, "gravity_torque", np.broadcast_shapes(J.shape[:-2], t.shape[:-1]),
                     "those of q_leg and tau,")
        with np.errstate(over="ignore"):
            t = t - g
    if np.any(np.abs(np.linalg.det(J)) < 1e-9):
        raise ValueError("q_leg: the leg is singular there (stretched or folded); J^T cannot be inverted")
    JT = np.swapaxes(J, -1, -2)
    with np.errstate(over="ignore", invalid="ignore"):
        f = -np.linalg.solve(JT, t[..., None])[..., 0]
    require_finite_result("tau, gravity_torque", f)
    return f
