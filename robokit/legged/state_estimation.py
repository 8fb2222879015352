"""The LittleDog's body state from its IMU and the MoCap: a complementary filter on SO(3) for the
orientation and a Kalman filter per axis for position and velocity.

Two sensors with opposite faults (LittleDog User Guide, Secs. 1-3): the IMU is fast and smooth
but drifts (a gyro bias integrates into an ever-growing angle, an accelerometer bias into a
position error growing like ``t^2``); the MoCap does not drift but is noisy and has holes (hidden
markers, lost frames, :mod:`robokit.legged.mocap`). :func:`fuse_body_state` fuses them:

* orientation: the explicit complementary filter with gyro-bias estimation of Mahony, Hamel &
  Pflimlin (2008), Eq. (32): the gyro, less the estimated bias, drives the estimate; where the
  MoCap has a pose its orientation pulls the estimate towards it (gain ``k_p``) and its
  integral estimates the bias (gain ``k_i``). The vector measurements of Eq. (32c) are the world
  axes ``e_i`` seen in the body frame, ``v_i = R_mocap^T e_i``, weights ``k_i = 1/2``: then
  ``omega_mes = vex(P_a(R_hat^T R_mocap))``, the error of the passive filter, ``~`` the rotation
  vector from the estimate to the MoCap for small errors. Linearised, each axis's error obeys
  ``s^2 + k_p s + k_i = 0``: the MoCap is trusted below about ``k_p`` rad/s, the gyro above.
* position and velocity: a linear Kalman filter per world axis (Thrun et al. 2005, Table 3.1),
  state ``[p, v]``, driven by the accelerometer rotated into the world by the estimated
  orientation with gravity removed, ``a = R_hat acc - [0, 0, g]``, taken as white noise of
  standard deviation ``sigma_acc`` held over each step (Bar-Shalom et al. 2001, Sec. 6.3.3), and
  corrected by the MoCap position (standard deviation ``sigma_mocap``) where ``ok``. The three
  axes share one covariance (same model, same measurement times), so the filter runs on a (3, 2)
  state.

The filters step once per host sample (100 Hz): predict with the IMU sample ``k - 1``, then
correct with the MoCap frame ``k`` when it is ``ok``.

References
----------
.. [1] R. Mahony, T. Hamel and J.-M. Pflimlin, "Nonlinear complementary filters on the special
   orthogonal group", IEEE Trans. Automatic Control 53(5), 1203-1218, 2008.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [3] Y. Bar-Shalom, X. R. Li and T. Kirubarajan, *Estimation with Applications to Tracking and
   Navigation*, Wiley, 2001.
.. [4] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006 (Secs. 1-3).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..geometry import as_se3, so3_exp, so3_log
from ..geometry.rotations import as_rotation
from ..validation import as_array, require_finite_result, as_positive
from .imu import GRAVITY, as_vector_series

__all__ = ["BodyState", "fuse_body_state", "orientation_errors", "position_errors"]


class BodyState(NamedTuple):
    """The fused estimate, one row per sample."""

    #: (N, 3, 3) orientations ``R_world_body``.
    R: np.ndarray
    #: (N, 3) positions of the body frame's origin in the world (m).
    p: np.ndarray
    #: (N, 3) velocities in the world frame (m/s).
    v: np.ndarray
    #: (N, 3) estimated gyro bias (rad/s).
    gyro_bias: np.ndarray


def fuse_body_state(gyro: Any, acc: Any, dt: float, T_mocap: Any, mocap_ok: Any, *, k_p: float = 2.0,
                    k_i: float = 0.5, sigma_acc: float = 0.5, sigma_mocap: float = 0.001, R0: Any = None,
                    p0: Any = None, g: float = GRAVITY) -> BodyState:
    """Fuse the IMU with the MoCap: orientation, position, velocity and gyro bias per sample.

    Parameters
    ----------
    gyro, acc : array_like, shape (N, 3)
        IMU readings: body rates (rad/s) and specific forces (m/s^2), one per host sample; sample
        ``k`` covers the period ``(t_k - dt, t_k]`` (the IMU's average, as the trial log stores it),
        so it carries the estimate from ``k - 1`` to ``k`` and sample 0 is not used.
    dt : float
        Sample period (s, > 0; 0.01 on the LittleDog's host).
    T_mocap : array_like, shape (N, 4, 4)
        MoCap body poses (e.g. :func:`robokit.legged.mocap_body_poses`); used only where
        ``mocap_ok``, but every row must be a rigid transform (held poses are).
    mocap_ok : array_like of bool, shape (N,)
        Where ``T_mocap`` is a measurement.
    k_p, k_i : float, default 2.0, 0.5
        Proportional (rad/s) and integral (rad/s^2) gains of the complementary filter (>= 0).
        The defaults suit the LittleDog's MoCap (about 0.02 rad of orientation noise per frame
        from markers 1 mm noisy and close together): the error poles at -0.29 and -1.71 rad/s.
    sigma_acc : float, default 0.5
        Standard deviation (m/s^2, > 0) the Kalman filter assumes for the world acceleration it
        gets from the accelerometer (noise, bias, tilt error and vibration together).
    sigma_mocap : float, default 0.001
        Standard deviation (m, > 0) it assumes for a MoCap position.
    R0, p0 : array_like, shape (3, 3) and (3,), optional
        Initial orientation and position; default: those of ``T_mocap[0]`` (which
        :func:`~robokit.legged.mocap_body_poses` fills with the first good pose). The velocity
        starts at 0 (variance 1 (m/s)^2), the position with variance ``sigma_mocap^2``, the bias at 0.
    g : float, default 9.81
        Gravity (m/s^2, >= 0) along world -z.

    Returns
    -------
    BodyState
        ``R`` (N, 3, 3), ``p`` (N, 3), ``v`` (N, 3), ``gyro_bias`` (N, 3).

    Raises
    ------
    ValueError
        For series of different lengths or not (N, 3), NaN/inf, a ``T_mocap`` row that is not
        rigid, negative gains, non-positive sigmas or ``dt``, an ``R0`` that is not a rotation.

    Notes
    -----
    Orientation, per step (Mahony et al. 2008, Eq. (32) discretised on the group; first order in
    ``dt``, the exponential keeps it on SO(3)):

    * predict ``R_hat <- R_hat exp([(gyro[k-1] - b_hat) dt])`` (Eq. (32a) without the correction);
    * where ``ok``: ``omega_mes = sum_i k_i v_i x v_hat_i`` with ``v_i = R_mocap^T e_i``,
      ``v_hat_i = R_hat^T e_i``, ``k_i = 1/2`` (Eq. (32c)); ``R_hat <- R_hat exp([k_p omega_mes dt])``
      (the rest of Eq. (32a)) and ``b_hat <- b_hat - k_i omega_mes dt`` (Eq. (32b)).

    Position, per step and axis (Thrun et al. 2005, Table 3.1, lines 2-6, with ``A = [[1, dt],
    [0, 1]]``, ``B = [dt^2 / 2, dt]``, ``R = sigma_acc^2 B B^T``, ``C = [1, 0]``,
    ``Q = sigma_mocap^2``): predict with ``a = R_hat[k-1] acc[k-1] - [0, 0, g]``; correct with the
    MoCap position where ``ok``.

    Examples
    --------
    A body at rest, level, 0.13 m up; the gyro has a bias of 0.02 rad/s about z and the MoCap
    sees every frame. After 20 s the bias is estimated and the yaw has not drifted:

    >>> from robokit.geometry import se3_from_rt
    >>> n = 2001
    >>> T = np.repeat(se3_from_rt(np.eye(3), [0.0, 0.0, 0.13])[None], n, 0)
    >>> est = fuse_body_state(np.tile([0.0, 0.0, 0.02], (n, 1)), np.tile([0.0, 0.0, 9.81], (n, 1)), 0.01,
    ...                       T, np.ones(n, bool))
    >>> print(np.round(est.gyro_bias[-1], 4), round(float(orientation_errors(est.R, T[:, :3, :3])[-1]), 5))
    [0.   0.   0.02] 0.0
    """
    w = as_vector_series(gyro, "gyro")
    f = as_vector_series(acc, "acc", len(w))
    n = len(w)
    step = np.float64(as_positive(dt, "dt"))
    T = as_se3(T_mocap, "T_mocap", batch=True)
    if len(T) != n:
        raise ValueError(f"T_mocap: expected {n} poses (one per IMU sample), got {len(T)}")
    ok = as_array(mocap_ok, "mocap_ok", shape=(n,), dtype=bool)
    kp = as_positive(k_p, "k_p", allow_zero=True)
    ki = as_positive(k_i, "k_i", allow_zero=True)
    var_acc = np.float64(as_positive(sigma_acc, "sigma_acc")) ** 2      # numpy: overflow gives inf, not an error
    var_mocap = np.float64(as_positive(sigma_mocap, "sigma_mocap")) ** 2
    gz = as_positive(g, "g", allow_zero=True)
    R_hat = T[0, :3, :3].copy() if R0 is None else as_rotation(R0, "R0")
    p_start = T[0, :3, 3] if p0 is None else as_array(p0, "p0", shape=(3,))
    require_finite_result("gyro, dt", w * step)
    R_out, p_out, v_out, b_out = np.empty((n, 3, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    b_hat = np.zeros(3)
    x = np.column_stack([p_start, np.zeros(3)])          # per axis [p, v]
    P = np.diag([var_mocap, 1.0])                     # shared by the three axes
    A = np.array([[1.0, step], [0.0, 1.0]])
    B = np.array([0.5 * step ** 2, step])
    Q_acc = var_acc * np.outer(B, B)                  # white acceleration held over a step
    gravity = np.array([0.0, 0.0, gz])
    R_out[0], p_out[0], v_out[0], b_out[0] = R_hat, x[:, 0], x[:, 1], b_hat
    for k in range(1, n):
        # --- orientation: predict with the gyro, correct with the MoCap (Mahony et al., Eq. (32))
        # the IMU's sample k covers (t_{k-1}, t_k]: it carries the state from k - 1 to k
        a_world = R_hat @ f[k] - gravity
        R_hat = R_hat @ so3_exp((w[k] - b_hat) * step, validate=False)           # Eq. (32a), gyro part
        if ok[k]:
            R_y = T[k, :3, :3]
            omega_mes = 0.5 * np.cross(R_y, R_hat).sum(0)                     # Eq. (32c), v_i = R_y^T e_i
            R_hat = R_hat @ so3_exp(kp * step * omega_mes, validate=False)        # Eq. (32a), correction
            b_hat = b_hat - ki * step * omega_mes                              # Eq. (32b)
        # --- position and velocity: Kalman filter per axis (Thrun et al., Table 3.1)
        x = x @ A.T + np.outer(a_world, B)                                     # line 2
        P = A @ P @ A.T + Q_acc                                                # line 3
        if ok[k]:
            K = P[:, 0] / (P[0, 0] + var_mocap)                             # line 4
            x = x + np.outer(T[k, :3, 3] - x[:, 0], K)                         # line 5
            P = P - np.outer(K, P[0])                                          # line 6
        R_out[k], p_out[k], v_out[k], b_out[k] = R_hat, x[:, 0], x[:, 1], b_hat
    require_finite_result("gyro, acc, dt, k_p, k_i, sigma_acc, sigma_mocap, p0, g", p_out, v_out, b_out, R_out)
    return BodyState(R_out, p_out, v_out, b_out)


def orientation_errors(R_est: Any, R_true: Any) -> np.ndarray:
    """Angle (rad) of the rotation between estimated and true orientations, per sample.

    Parameters
    ----------
    R_est, R_true : array_like, shape (N, 3, 3) or (3, 3)
        Rotations ``R_world_body``; stacks of equal length.

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``|log(R_true^T R_est)|`` in [0, pi]: the geodesic distance on SO(3).

    Raises
    ------
    ValueError
        For shapes that differ or matrices that are not rotations.

    Notes
    -----
    The angle of the rotation vector (:func:`robokit.geometry.so3_log`, Lynch & Park 2017,
    Sec. 3.2.3.3) of the error ``R_true^T R_est``, as in Mahony et al. (2008), who measure the
    error of an estimate by ``R_tilde = R_hat^T R``.

    Examples
    --------
    >>> from robokit.geometry import rot_x, rot_z
    >>> print(np.round(orientation_errors(rot_z([0.1, 0.2]), rot_z([0.1, 0.5])), 6))
    [0.  0.3]
    >>> print(np.round(orientation_errors(rot_x(0.2) @ rot_z(0.1), rot_z(0.1)), 6))
    [0.2]
    """
    Re = as_rotation(R_est, "R_est", batch=True)
    Rt = as_rotation(R_true, "R_true", batch=True)
    if len(Re) != len(Rt):
        raise ValueError(f"R_true: expected {len(Re)} rotations (one per estimate), got {len(Rt)}")
    return np.linalg.norm(so3_log(np.swapaxes(Rt, -1, -2) @ Re, validate=False), axis=-1)


def position_errors(p_est: Any, p_true: Any) -> np.ndarray:
    """Distance (m) between estimated and true positions, per sample.

    Parameters
    ----------
    p_est, p_true : array_like, shape (N, 3)

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``|p_est - p_true|``.

    Raises
    ------
    ValueError
        For shapes that differ, not (N, 3), or NaN/inf.

    Notes
    -----
    The Euclidean norm; not from a paper.

    Examples
    --------
    >>> print(position_errors([[0.0, 0.0, 0.13], [0.03, 0.04, 0.13]], [[0.0, 0.0, 0.13]] * 2))
    [0.   0.05]
    """
    pe = as_vector_series(p_est, "p_est")
    pt = as_vector_series(p_true, "p_true", len(pe))
    out = np.linalg.norm(pe - pt, axis=-1)
    require_finite_result("p_est, p_true", out)
    return out
