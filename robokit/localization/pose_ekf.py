"""An extended Kalman filter over ``(x, y, theta, v, omega)`` that fuses odometry with visual pose fixes.

Source: "Robust omnidirectional vision based mobile robot hierarchical localization and autonomous
navigation", Sec. 'Visual-servoing for navigation': noise in the self-localization "directly
implies noise in control outputs", so the fixes are integrated over time by an EKF "whose inputs
and outputs are then poses (x, y, theta) and the dynamics are that of a wheeled mobile robot,
Eq. 8 with state vector augmented with velocities". Eq. (8) there is a slip: Eq. (8) is the
control law, Eq. (6) the motion model. This filter uses Eq. (6) with the velocities as states that
stay constant over a step (a constant-velocity model), driven by white accelerations:

* predict (:func:`ekf_predict`): the pose moves along the exact arc of Eq. (6)
  (:func:`robokit.sim.unicycle_step`), ``v`` and ``omega`` are kept; the Jacobian
  (:func:`unicycle_jacobian`) is analytic; the process noise (:func:`unicycle_process_noise`)
  is a linear and an angular acceleration, each constant over the step (Bar-Shalom et al. 2001,
  Sec. 6.3.3);
* updates (:func:`ekf_update`, Joseph form): odometry measures ``(v, omega)``
  (:meth:`UnicycleEKF.update_velocity`), the hierarchical localizer a pose ``[x, y, theta]``
  (:meth:`UnicycleEKF.update_pose`, the heading innovation wrapped).

Consistency is checked as Bar-Shalom et al. (2001, Sec. 5.4) do: the normalised estimation error
squared (:func:`nees`) averaged over Monte-Carlo runs must lie in the chi-square interval of
:func:`nees_bounds`. Poses are robokit's ``[x, y, theta]`` (the paper writes ``(x, z, theta)``
for its map nodes and ``(x, y, theta)`` in this section).

References
----------
.. [1] Y. Bar-Shalom, X. R. Li and T. Kirubarajan, *Estimation with Applications to Tracking and
   Navigation*, Wiley, 2001.
.. [2] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..geometry import wrap_angle
from ..sim import unicycle_step
from ..geometry.planar import as_planar
from ..validation import (as_array, as_covariance, as_finite_scalar, as_int, as_positive, describe,
                          require_angles, require_finite_result)

__all__ = ["unicycle_jacobian", "unicycle_process_noise", "ekf_predict", "ekf_update", "nees", "nees_bounds",
           "UnicycleEKF"]

#: Measurement matrices of the two sensors: odometry sees (v, omega), the localizer the pose.
H_VELOCITY = np.array([[0.0, 0, 0, 1, 0], [0, 0, 0, 0, 1]])
H_POSE = np.eye(3, 5)


def _state_and_step(x: Any, dt: Any) -> tuple[np.ndarray, float]:
    """The state and a time step whose heading change ``omega * dt`` stays within ``MAX_ANGLE``."""
    state, step = _state(x), as_positive(dt, "dt", allow_zero=True)
    require_angles(state[4] * step, "x, dt", "a heading change omega * dt")
    return state, step


def _state(x: Any, name: str = "x") -> np.ndarray:
    state = as_array(x, name, shape=(5,))
    require_angles(state[2], name, "heading (element 2)")
    return state


def _sinc_and_slope(u: float) -> tuple[float, float]:
    """``sin(u)/u`` and its derivative, with the series near 0 (no cancellation)."""
    if abs(u) < 1e-2:
        return 1.0 - u * u / 6.0, -u / 3.0 + u ** 3 / 30.0
    return np.sin(u) / u, (u * np.cos(u) - np.sin(u)) / (u * u)


def unicycle_jacobian(x: Any, dt: float) -> np.ndarray:
    """Jacobian ``F = df/dx`` of the constant-velocity unicycle step over ``dt`` seconds.

    Parameters
    ----------
    x : array_like, shape (5,)
        State ``[x, y, theta, v, omega]``.
    dt : float
        Step (s, >= 0).

    Returns
    -------
    numpy.ndarray, shape (5, 5)

    Notes
    -----
    Eq. (6) integrated exactly with ``v``, ``omega`` constant: the chord of the arc has length
    ``L = v dt sin(u)/u`` with ``u = omega dt / 2`` and direction ``phi = theta + u``, the same
    arc as :func:`robokit.sim.unicycle_step` (Thrun et al. 2005, Eq. (5.9)), written so that it
    is smooth through ``omega = 0``. Differentiated by hand; tests compare it with finite
    differences of ``unicycle_step``.

    Examples
    --------
    >>> F = unicycle_jacobian([0.0, 0.0, 0.0, 1.0, 0.0], 0.5)
    >>> np.round(F[:3, 2:], 4).tolist()          # d(x, y, theta) / d(theta, v, omega)
    [[0.0, 0.5, 0.0], [0.5, 0.0, 0.125], [1.0, 0.0, 0.5]]
    """
    F = _jacobian(*_state_and_step(x, dt))
    require_finite_result("x, dt", F)
    return F


def _jacobian(x: np.ndarray, dt: float) -> np.ndarray:
    """Unchecked :func:`unicycle_jacobian`."""
    th, v, w = float(x[2]), float(x[3]), float(x[4])
    u = w * dt / 2
    S, dS = _sinc_and_slope(u)
    L, phi = v * dt * S, th + u
    c, s = np.cos(phi), np.sin(phi)
    dL_dw = v * dt * dS * dt / 2
    F = np.eye(5)
    F[0, 2], F[1, 2] = -L * s, L * c                                         # d/dtheta
    F[0, 3], F[1, 3] = dt * S * c, dt * S * s                                # d/dv
    F[0, 4], F[1, 4] = dL_dw * c - L * s * dt / 2, dL_dw * s + L * c * dt / 2   # d/domega
    F[2, 4] = dt
    return F


def unicycle_process_noise(x: Any, dt: float, sigma_accel: float, sigma_alpha: float) -> np.ndarray:
    """Process noise ``Q = G diag(sigma_accel^2, sigma_alpha^2) G^T`` of one step.

    Parameters
    ----------
    x : array_like, shape (5,)
        State at which the arc is linearised.
    dt : float
        Step (s, >= 0).
    sigma_accel, sigma_alpha : float
        Standard deviations (>= 0) of the linear (m/s^2) and angular (rad/s^2) accelerations the
        filter assumes, each constant over a step.

    Returns
    -------
    numpy.ndarray, shape (5, 5)
        Positive semidefinite (rank 2).

    Notes
    -----
    Discrete white-noise acceleration (Bar-Shalom et al. 2001, Sec. 6.3.3): an acceleration
    ``a`` held over the step changes ``v`` by ``a dt`` and the mean speed over the step by
    ``a dt / 2``, so ``G = [F[:3, 3:5] dt / 2; dt I]`` with ``F`` from :func:`unicycle_jacobian`
    (``dt^2 / 2`` and ``dt`` on a straight line, the textbook's ``Gamma``). The pose rows are
    first order in the step: an angular acceleration moves the robot sideways by
    ``v alpha dt^3 / 4`` here against ``v alpha dt^3 / 6`` on the exact curve, a difference far
    below the noise of a 10 Hz step.

    Examples
    --------
    >>> Q = unicycle_process_noise([0.0, 0.0, 0.0, 1.0, 0.0], 0.1, 0.5, 1.0)
    >>> np.round(np.sqrt(np.diag(Q)), 5).tolist()     # 0.5 * 0.1^2 / 2 = 0.0025 on x
    [0.0025, 0.00025, 0.005, 0.05, 0.1]
    """
    Q = _process_noise(*_state_and_step(x, dt),
                       as_positive(sigma_accel, "sigma_accel", allow_zero=True),
                       as_positive(sigma_alpha, "sigma_alpha", allow_zero=True))
    require_finite_result("x, dt, sigma_accel, sigma_alpha", Q)
    return Q


def _process_noise(x: np.ndarray, dt: float, sigma_accel: float, sigma_alpha: float) -> np.ndarray:
    """Unchecked :func:`unicycle_process_noise`."""
    F = _jacobian(x, dt)
    G = np.zeros((5, 2))
    G[:3] = F[:3, 3:5] * (dt / 2)
    G[3, 0] = G[4, 1] = dt
    G = G * np.array([sigma_accel, sigma_alpha])
    return G @ G.T


def ekf_predict(x: Any, P: Any, dt: float, Q: Any) -> tuple[np.ndarray, np.ndarray]:
    """EKF prediction over ``dt`` seconds with the constant-velocity unicycle (Eq. (6)).

    Parameters
    ----------
    x : array_like, shape (5,)
        State ``[x, y, theta, v, omega]``.
    P : array_like, shape (5, 5)
        Its covariance (positive definite).
    dt : float
        Step (s, >= 0).
    Q : array_like, shape (5, 5)
        Process noise of the step (positive semidefinite), e.g. :func:`unicycle_process_noise`.

    Returns
    -------
    (x, P) : numpy.ndarray, numpy.ndarray
        ``x' = f(x)`` (the pose moved along the arc, heading wrapped, velocities kept) and
        ``P' = F P F^T + Q``.

    Raises
    ------
    ValueError
        For wrong shapes, NaN or infinity, a covariance that is not symmetric positive (semi)definite,
        a negative ``dt``, or a result that overflows.

    Notes
    -----
    Eq. (6) with the state augmented with ``(v, omega)`` (Sec. 'Visual-servoing for
    navigation'); the EKF prediction of Thrun et al. (2005), Table 3.3, lines 2-3.

    Examples
    --------
    >>> x, P = ekf_predict([0.0, 0.0, 0.0, 1.0, 0.0], np.eye(5) * 0.01, 1.0, np.zeros((5, 5)))
    >>> np.round(x, 3).tolist(), round(float(P[1, 1]), 4)    # heading variance spreads sideways
    ([1.0, 0.0, 0.0, 1.0, 0.0], 0.0225)
    """
    state, step = _state_and_step(x, dt)
    return _predict(state, as_covariance(P, "P", 5), step,
                    as_covariance(Q, "Q", 5, semidefinite=True))


def _predict(x: np.ndarray, P: np.ndarray, dt: float, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unchecked :func:`ekf_predict` (the result's finiteness is still checked: it can overflow)."""
    F = _jacobian(x, dt)
    x_new = np.empty(5)
    x_new[:3] = unicycle_step(x[:3], x[3], x[4], dt, validate=False)         # Eq. (6), exact arc
    x_new[3:] = x[3:]
    P_new = F @ P @ F.T + Q
    P_new = 0.5 * (P_new + P_new.T)
    require_finite_result("x, P, dt, Q", x_new, P_new)
    return x_new, P_new


def _innovation(x: np.ndarray, P: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray,
                angles: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """Innovation ``z - H x`` (the listed components wrapped) and its covariance ``H P H^T + R``."""
    y = z - H @ x
    for i in angles:
        y[i] = wrap_angle(y[i])
    return y, H @ P @ H.T + R


def ekf_update(x: Any, P: Any, z: Any, H: Any, R: Any, *, angles: Sequence[int] = ()) -> tuple[np.ndarray, np.ndarray]:
    """Kalman update with a linear measurement ``z = H x + noise``, covariance in Joseph form.

    Parameters
    ----------
    x : array_like, shape (n,)
        State.
    P : array_like, shape (n, n)
        Its covariance (positive definite).
    z : array_like, shape (m,)
        Measurement.
    H : array_like, shape (m, n)
        Measurement matrix.
    R : array_like, shape (m, m)
        Measurement noise covariance (positive definite).
    angles : sequence of int, default ()
        Components of ``z`` that are angles: their innovation is wrapped to ``[-pi, pi)``.

    Returns
    -------
    (x, P) : numpy.ndarray, numpy.ndarray
        ``x + K y`` and ``(I - K H) P (I - K H)^T + K R K^T`` with ``K = P H^T S^-1``,
        ``S = H P H^T + R``. An angle in the state is not wrapped here (the caller knows which).

    Raises
    ------
    ValueError
        For shapes that disagree, NaN or infinity, covariances that are not symmetric positive
        definite, angle indices out of range, or a result that overflows.

    Notes
    -----
    Thrun et al. (2005), Table 3.3, lines 4-6; the Joseph form keeps ``P`` symmetric positive
    definite under rounding and for any gain (Bar-Shalom et al. 2001, Sec. 5.2.3).

    Examples
    --------
    >>> x, P = ekf_update([0.0, 0.0], np.eye(2), [1.0], [[1.0, 0.0]], [[1.0]])   # equal weights
    >>> x.tolist(), P.tolist()
    ([0.5, 0.0], [[0.5, 0.0], [0.0, 1.0]])
    """
    x = as_array(x, "x", ndim=1, min_size=1)
    n = len(x)
    P = as_covariance(P, "P", n)
    z = as_array(z, "z", ndim=1, min_size=1)
    m = len(z)
    H = as_array(H, "H", shape=(m, n))
    R = as_covariance(R, "R", m)
    if not isinstance(angles, (list, tuple, range, np.ndarray)):
        raise TypeError(f"angles: expected a sequence of indices into z, got {describe(angles)}")
    angles = [as_int(i, "angles", minimum=0, maximum=m - 1) for i in np.asarray(angles, dtype=object).ravel()]
    require_angles(z[angles], "z", "angles (the rows named by angles)")
    require_angles((H @ x)[angles], "x, H", "predicted angles (H x in the rows named by angles)")
    return _update(x, P, z, H, R, angles)


def _update(x: np.ndarray, P: np.ndarray, z: np.ndarray, H: np.ndarray, R: np.ndarray,
            angles: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """Unchecked :func:`ekf_update` (the result's finiteness is still checked: it can overflow)."""
    y, S = _innovation(x, P, z, H, R, angles)
    try:
        K = np.linalg.solve(S, H @ P).T                  # K = P H^T S^-1 (S symmetric)
    except np.linalg.LinAlgError:
        raise ValueError("P, H, R: expected a finite, invertible innovation covariance H P H^T + R, got a "
                         "singular one (values too large?)") from None
    I_KH = np.eye(len(x)) - K @ H
    P_new = I_KH @ P @ I_KH.T + K @ R @ K.T              # Joseph form
    x_new = x + K @ y
    P_new = 0.5 * (P_new + P_new.T)
    require_finite_result("x, P, z, H, R", x_new, P_new)
    return x_new, P_new


def nees(error: Any, P: Any) -> Any:
    """Normalised estimation error squared ``e^T P^-1 e`` of one estimate or a stack.

    Parameters
    ----------
    error : array_like, shape (n,) or (K, n)
        True minus estimated state (angles already wrapped).
    P : array_like, shape (n, n) or (K, n, n)
        The filter's covariances.

    Returns
    -------
    float or numpy.ndarray, shape (K,)

    Raises
    ------
    ValueError
        For shapes that disagree, NaN or infinity, or a covariance that is not symmetric positive
        definite (a singular or negative-definite one would give an infinite or negative NEES).

    Notes
    -----
    Bar-Shalom et al. (2001), Sec. 5.4.2: for a consistent filter it is chi-square with ``n``
    degrees of freedom (mean ``n``).

    Examples
    --------
    >>> round(nees([0.1, -0.2], np.diag([0.01, 0.04])), 6)
    2.0
    """
    e = as_array(error, "error", min_size=1)
    if e.ndim not in (1, 2):
        raise ValueError(f"error: expected shape (n,) or (K, n), got shape {e.shape}")
    n = e.shape[-1]
    C = as_array(P, "P", shape=(n, n) if e.ndim == 1 else (len(e), n, n))
    scale = np.abs(C).max(axis=(-2, -1), initial=0.0)
    if not np.all(np.abs(C - np.swapaxes(C, -1, -2)) <= 1e-9 * scale[..., None, None]):
        raise ValueError("P: expected symmetric covariances, got P[i, j] != P[j, i]")
    low = np.linalg.eigvalsh(C)[..., 0]
    if np.any(low <= 1e-14 * scale):         # a negative-definite P would give a negative NEES
        raise ValueError(f"P: expected positive-definite covariances, got an eigenvalue {float(np.min(low)):.3g}")
    out = np.einsum("...i,...i->...", e, np.linalg.solve(C, e[..., None])[..., 0])
    require_finite_result("error, P", out)
    return float(out) if out.ndim == 0 else out


def nees_bounds(dof: int, runs: int, confidence: float = 0.95) -> tuple[float, float]:
    """Two-sided interval for the NEES averaged over ``runs`` Monte-Carlo runs.

    Parameters
    ----------
    dof : int
        State dimension ``n``.
    runs : int
        Number of independent runs ``N`` averaged.
    confidence : float, default 0.95
        Probability the interval holds the average of a consistent filter.

    Returns
    -------
    (low, high) : float
        ``chi2.ppf((1 -+ confidence) / 2, n N) / N``.

    Notes
    -----
    Bar-Shalom et al. (2001), Sec. 5.4.2: ``N`` times the average NEES is chi-square with
    ``n N`` degrees of freedom.

    Examples
    --------
    >>> lo, hi = nees_bounds(5, 50)
    >>> round(lo, 3), round(hi, 3)
    (4.162, 5.914)
    """
    n = as_int(dof, "dof", minimum=1, maximum=10 ** 6)
    r = as_int(runs, "runs", minimum=1, maximum=10 ** 9)
    c = as_positive(confidence, "confidence")
    if not c < 1:
        raise ValueError(f"confidence: expected a probability in (0, 1), got {c}")
    from scipy.stats import chi2        # here, not at the top: importing scipy.stats takes half a second

    lo, hi = chi2.ppf([(1 - c) / 2, (1 + c) / 2], n * r) / r
    return float(lo), float(hi)


class UnicycleEKF:
    """EKF over ``[x, y, theta, v, omega]``: odometry and visual pose fixes fused (Sec. 'Visual-servoing for navigation').

    Parameters
    ----------
    x0 : array_like, shape (5,)
        Initial state (heading wrapped).
    P0 : array_like, shape (5, 5)
        Initial covariance (symmetric positive definite).
    sigma_accel : float, default 0.5
        Linear acceleration (m/s^2, std-dev) the model allows per step.
    sigma_alpha : float, default 1.0
        Angular acceleration (rad/s^2, std-dev) the model allows per step.

    Attributes
    ----------
    state : numpy.ndarray, shape (5,)
    covariance : numpy.ndarray, shape (5, 5)
    pose : numpy.ndarray, shape (3,)
        ``state[:3]``.
    nis : float or None
        Normalised innovation squared of the last pose fix offered (accepted or not).

    Notes
    -----
    Eq. (6) with the velocities as states (the paper's "Eq. 8" is a slip; module docstring);
    :func:`ekf_predict`, :func:`ekf_update`. The paper does not give its noise levels; the
    defaults suit a robot at 0.3 m/s commanded at 10 Hz.

    Examples
    --------
    >>> ekf = UnicycleEKF([0, 0, 0, 0, 0], np.diag([0.01, 0.01, 0.01, 1.0, 1.0]))
    >>> ekf.update_velocity(0.3, 0.0, np.diag([1e-4, 1e-4]))
    >>> ekf.predict(1.0)
    >>> np.round(ekf.pose, 3).tolist()
    [0.3, 0.0, 0.0]
    >>> ekf.update_pose([0.4, 0.0, 0.0], np.diag([0.01, 0.01, 0.01]))
    True
    >>> round(float(ekf.pose[0]), 2)     # nearer the fix: surer than a 1 s prediction
    0.39
    """

    def __init__(self, x0: Any, P0: Any, *, sigma_accel: float = 0.5, sigma_alpha: float = 1.0) -> None:
        self._x = _state(x0, "x0").copy()
        self._x[2] = wrap_angle(self._x[2])
        self._P = as_covariance(P0, "P0", 5)
        self.sigma_accel = as_positive(sigma_accel, "sigma_accel", allow_zero=True)
        self.sigma_alpha = as_positive(sigma_alpha, "sigma_alpha", allow_zero=True)
        self.nis: float | None = None

    @property
    def state(self) -> np.ndarray:
        """``[x, y, theta, v, omega]`` (a copy)."""
        return self._x.copy()

    @property
    def covariance(self) -> np.ndarray:
        """5 x 5 covariance (a copy)."""
        return self._P.copy()

    @property
    def pose(self) -> np.ndarray:
        """``[x, y, theta]`` (a copy)."""
        return self._x[:3].copy()

    def predict(self, dt: float) -> None:
        """Move the estimate ``dt`` seconds along Eq. (6) (:func:`ekf_predict`)."""
        _, h = _state_and_step(self._x, dt)
        Q = _process_noise(self._x, h, self.sigma_accel, self.sigma_alpha)
        self._x, self._P = _predict(self._x, self._P, h, Q)

    def update_velocity(self, v: float, omega: float, R: Any) -> None:
        """Fuse odometry's ``(v, omega)`` with covariance ``R`` (2 x 2, positive definite)."""
        z = np.array([as_finite_scalar(v, "v"), as_finite_scalar(omega, "omega")])
        self._x, self._P = _update(self._x, self._P, z, H_VELOCITY, as_covariance(R, "R", 2), ())

    def update_pose(self, z: Any, R: Any, *, gate: float | None = None) -> bool:
        """Fuse a pose fix ``[x, y, theta]`` with covariance ``R`` (3 x 3); heading innovation wrapped.

        Parameters
        ----------
        z : array_like, shape (3,)
        R : array_like, shape (3, 3)
        gate : float, optional
            Reject the fix when its normalised innovation squared exceeds this (e.g.
            ``scipy.stats.chi2.ppf(0.999, 3)`` = 16.3): a false place recognition, the failure the
            paper reports, then does not pull the estimate away.

        Returns
        -------
        bool
            Whether the fix was used.
        """
        zz = as_planar(z, "z", shape=(3,))
        RR = as_covariance(R, "R", 3)
        g = None if gate is None else as_positive(gate, "gate")
        y, S = _innovation(self._x, self._P, zz, H_POSE, RR, (2,))
        self.nis = float(y @ np.linalg.solve(S, y))
        if g is not None and self.nis > g:
            return False
        self._x, self._P = _update(self._x, self._P, zz, H_POSE, RR, (2,))
        self._x[2] = wrap_angle(self._x[2])
        return True
