"""The LittleDog's MEMS IMU: gyro and accelerometer readings with bias and noise, and what
integrating the gyro alone gives.

The robot carries a MEMS IMU that reports angles, rates and linear accelerations (LittleDog User
Guide, Sec. 3). The model here (ours: the guide gives no error figures) is the usual one for MEMS
sensors (Siciliano & Khatib 2016, Ch. 29; Mahony et al. 2008 model the gyro the same way):

* the gyro reads the body-frame angular rate plus a constant bias and white noise,
  ``gyro = omega_body + b_g + n_g``;
* the accelerometer reads the *specific force* in the body frame, ``f = R^T (a - g_vec)`` with
  ``g_vec = [0, 0, -g]`` (at rest and level: ``+g`` along body z), plus a constant bias and white
  noise, ``acc = f + b_a + n_a``. :func:`specific_force` computes ``f`` from a true world
  acceleration.

:func:`integrate_gyro` turns rates into orientations by the exponential map; with a biased gyro
the orientation drifts without bound (the bias integrates to an angle growing like ``b t``), which
is why :mod:`robokit.legged.state_estimation` fuses the gyro with the MoCap.

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Sec. 3).
.. [2] B. Siciliano and O. Khatib (eds.), *Springer Handbook of Robotics*, 2nd ed., Springer, 2016
   (Ch. 29, G. Dudek and M. Jenkin, "Inertial sensing, GPS and odometry").
.. [3] R. Mahony, T. Hamel and J.-M. Pflimlin, "Nonlinear complementary filters on the special
   orthogonal group", IEEE Trans. Automatic Control 53(5), 1203-1218, 2008.
.. [4] K. M. Lynch and F. C. Park, *Modern Robotics: Mechanics, Planning, and Control*, Cambridge
   University Press, 2017.
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..geometry import so3_exp
from ..geometry.rotations import as_rotation
from ..validation import as_array, as_rng, require_finite_result, as_positive

__all__ = ["GRAVITY", "ImuReadings", "simulate_imu", "integrate_gyro", "specific_force", "as_vector_series"]

#: Standard gravity (m/s^2) that the accelerometer model and the estimators assume.
GRAVITY = 9.81


class ImuReadings(NamedTuple):
    """What the IMU reported over a trial."""

    #: (N, 3) body-frame angular rates (rad/s).
    gyro: np.ndarray
    #: (N, 3) body-frame specific forces (m/s^2).
    acc: np.ndarray


def as_vector_series(value: Any, name: str, n: int | None = None) -> np.ndarray:
    """Validate a time series of 3-vectors: shape (N, 3) (N = ``n`` if given, else >= 1), finite.

    Raises
    ------
    ValueError
        Naming ``name``, for another shape, no rows or NaN/inf.

    Notes
    -----
    Validation only; not from a paper.

    Examples
    --------
    >>> as_vector_series([[0.0, 0.0, 9.81]], "acc").shape
    (1, 3)
    """
    x = as_array(value, name, shape=(n, 3))
    if len(x) == 0:
        raise ValueError(f"{name}: expected at least one sample, shape (N, 3), got shape {x.shape}")
    return x


def _bias(value: Any, name: str) -> np.ndarray:
    return as_array(value, name, shape=(3,))


def simulate_imu(omega_body: Any, specific_force_body: Any, rng: Any = None, *, gyro_noise: float = 0.0,
                 acc_noise: float = 0.0, gyro_bias: Any = (0.0, 0.0, 0.0),
                 acc_bias: Any = (0.0, 0.0, 0.0)) -> ImuReadings:
    """Gyro and accelerometer readings from the true body rates and specific forces.

    Parameters
    ----------
    omega_body : array_like, shape (N, 3)
        True angular rate of the body in the body frame (rad/s), one row per IMU sample (MuJoCo's
        ``gyro`` sensor reads it).
    specific_force_body : array_like, shape (N, 3)
        True specific force in the body frame (m/s^2): MuJoCo's ``accelerometer`` sensor, or
        :func:`specific_force` of a world acceleration.
    rng : numpy.random.Generator or int, optional
    gyro_noise, acc_noise : float, default 0
        Standard deviation of the white noise per sample and axis (rad/s; m/s^2; >= 0).
    gyro_bias, acc_bias : array_like, shape (3,), default zeros
        Constant biases (rad/s; m/s^2).

    Returns
    -------
    ImuReadings
        ``gyro = omega_body + gyro_bias + n_g`` and ``acc = specific_force_body + acc_bias + n_a``,
        each (N, 3).

    Raises
    ------
    ValueError
        For series that are not (N, 3) of equal length, NaN/inf, a negative noise or a bias that is
        not a 3-vector.
    TypeError
        For an ``rng`` that is neither a Generator nor a non-negative integer seed.

    Notes
    -----
    The MEMS model of the module docstring: Mahony et al. (2008) write the gyro as
    ``Omega_y = Omega + b + mu``; the accelerometer has the same form (Siciliano & Khatib 2016,
    Ch. 29). The gyro noise is drawn before the accelerometer's.

    Examples
    --------
    >>> imu = simulate_imu(np.zeros((2, 3)), [[0.0, 0.0, 9.81]] * 2, rng=0, gyro_bias=[0.02, 0.0, 0.0])
    >>> print(imu.gyro[0], imu.acc[0])
    [0.02 0.   0.  ] [0.   0.   9.81]
    """
    w = as_vector_series(omega_body, "omega_body")
    f = as_vector_series(specific_force_body, "specific_force_body", len(w))
    sg = as_positive(gyro_noise, "gyro_noise", allow_zero=True)
    sa = as_positive(acc_noise, "acc_noise", allow_zero=True)
    bg, ba = _bias(gyro_bias, "gyro_bias"), _bias(acc_bias, "acc_bias")
    gen = as_rng(rng)
    gyro = w + bg + gen.normal(0.0, 1.0, w.shape) * sg
    acc = f + ba + gen.normal(0.0, 1.0, f.shape) * sa
    require_finite_result("omega_body, gyro_noise, gyro_bias", gyro)
    require_finite_result("specific_force_body, acc_noise, acc_bias", acc)
    return ImuReadings(gyro, acc)


def integrate_gyro(R0: Any, gyro: Any, dt: float) -> np.ndarray:
    """Orientations from integrating body rates alone: ``R[k] = R[k-1] exp([gyro[k] dt])``.

    Parameters
    ----------
    R0 : array_like, shape (3, 3)
        Orientation ``R_world_body`` at the first sample.
    gyro : array_like, shape (N, 3)
        Body-frame rates (rad/s); sample ``k`` is what the IMU reports at ``t_k``: its rate over
        the period that ends there, ``(t_k - dt, t_k]`` (as the trial log stores it).
    dt : float
        Sample period (s, > 0).

    Returns
    -------
    numpy.ndarray, shape (N, 3, 3)
        ``R[0] = R0``; the first rate is not used (it covers the period before ``t_0``).

    Raises
    ------
    ValueError
        If ``R0`` is not a rotation, ``gyro`` is not (N, 3) and finite, or ``dt`` is not positive.

    Notes
    -----
    The body-frame kinematics ``dR/dt = R [omega_b]`` (Lynch & Park 2017, Sec. 3.2.2) integrated
    with the rate held constant over each step, whose exact solution over the step is the
    exponential map (Eq. (3.51), :func:`robokit.geometry.so3_exp`). The scheme is first order in
    ``dt`` for a rate that varies within a step (the rate's axis turning is missed), but it never
    leaves SO(3). A gyro bias ``b`` makes the result drift by about ``|b| t`` rad.

    Examples
    --------
    >>> R = integrate_gyro(np.eye(3), [[0.0, 0.0, 0.5]] * 101, 0.01)   # 0.5 rad/s about z for 1 s
    >>> print(round(float(np.arctan2(R[-1, 1, 0], R[-1, 0, 0])), 6))
    0.5
    """
    R = as_rotation(R0, "R0")
    w = as_vector_series(gyro, "gyro")
    step = as_positive(dt, "dt")
    incr = so3_exp(w[1:] * step, validate=False)
    require_finite_result("gyro, dt", incr)
    out = np.empty((len(w), 3, 3))
    out[0] = R
    for k in range(1, len(w)):
        out[k] = out[k - 1] @ incr[k - 1]                # the rate reported at t_k covers (t_k - dt, t_k]
    return out


def specific_force(acc_world: Any, R_world_body: Any, g: float = GRAVITY) -> np.ndarray:
    """What an ideal accelerometer reads: the specific force ``R^T (a - g_vec)`` in the body frame.

    Parameters
    ----------
    acc_world : array_like, shape (N, 3)
        True acceleration of the IMU in the world frame (m/s^2).
    R_world_body : array_like, shape (N, 3, 3)
        True orientations.
    g : float, default 9.81
        Gravity (m/s^2, >= 0) along world -z: ``g_vec = [0, 0, -g]``.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``R^T (acc_world + [0, 0, g])``: ``+g`` along body z for a body at rest and level.

    Raises
    ------
    ValueError
        For shapes that do not agree, NaN/inf, matrices that are not rotations or a negative ``g``.

    Notes
    -----
    An accelerometer measures the non-gravitational force per unit mass (Siciliano & Khatib 2016,
    Sec. 29.3), i.e. ``a - g_vec`` expressed in the sensor's axes.

    Examples
    --------
    >>> print(specific_force([[0.0, 0.0, 0.0]], np.eye(3)[None]))
    [[0.   0.   9.81]]
    """
    a = as_vector_series(acc_world, "acc_world")
    R = as_rotation(R_world_body, "R_world_body", batch=True)
    if len(R) != len(a):
        raise ValueError(f"R_world_body: expected {len(a)} rotations (one per acceleration), got {len(R)}")
    gz = as_positive(g, "g", allow_zero=True)
    out = np.einsum("nji,nj->ni", R, a + [0.0, 0.0, gz])
    require_finite_result("acc_world, g", out)
    return out
