"""Serial chains of revolute joints described by DH or modified-DH parameters.

A :class:`Chain` knows its link parameters, joint offsets and limits, a fixed tool (flange)
transform and a base transform. It computes the transform of every link frame in one vectorised pass,
for one configuration or a batch of them.

References
----------
.. [1] J. Denavit and R. S. Hartenberg, "A kinematic notation for lower-pair mechanisms based on
   matrices", *Journal of Applied Mechanics* 22(2), 215-221, 1955.
.. [2] M. W. Spong, S. Hutchinson and M. Vidyasagar, *Robot Modeling and Control*, Wiley, 2006.
.. [3] J. J. Craig, *Introduction to Robotics: Mechanics and Control*, 3rd ed., Pearson, 2005.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..geometry import as_se3
from ..validation import array_ndim, as_array, as_rng, as_choice, as_int
from .dh import dh_transform, mdh_transform

__all__ = ["Chain", "dh_fk", "chain_from_table", "LIMIT_TOL"]

#: Slack [rad] of every joint-limit test in robokit.arm. An angle computed in closed form for a
#: target whose joint sits exactly on its limit (a pose from a clamped trajectory) lands a rounding
#: error (a few 1e-16 rad) on either side of it; without slack such targets were refused. Solvers
#: clip what they return to the exact limits.
LIMIT_TOL = 1e-12


class Chain:
    """A serial chain of revolute joints.

    Parameters
    ----------
    name : str
        Human-readable name, e.g. ``"KUKA LBR iiwa 14 R820"``.
    d, a, alpha : array_like, shape (n,)
        DH parameters of each link [m, m, rad]. For ``convention="modified"`` they are Craig's
        ``d_i, a_{i-1}, alpha_{i-1}``.
    qmin, qmax : array_like, shape (n,), optional
        Joint limits [rad]; ``qmin <= qmax`` elementwise; ``-pi`` and ``pi`` by default.
    convention : {"standard", "modified"}, default "standard"
        Standard DH (joint ``i`` turns about ``z_{i-1}``) or modified DH (about ``z_i``).
    offset : array_like, shape (n,), optional
        Constant added to each joint variable (``theta_i = q_i + offset_i``); zeros by default.
    tool : array_like, shape (4, 4), optional
        Transform of the flange (end-effector) in the last link frame; identity by default.
    base : array_like, shape (4, 4), optional
        Transform of frame 0 in the world; identity by default.

    Raises
    ------
    ValueError
        If the parameter vectors differ in length, contain NaN, if ``qmin > qmax`` for a joint, or if
        ``tool``/``base`` are not SE(3) matrices.

    Notes
    -----
    Link transforms follow Denavit & Hartenberg (1955) as in Spong et al. (2006), Eq. (3.10), or
    Craig (2005), Eq. (3.6); forward kinematics is their ordered product (Spong et al., Eq. (3.5)).
    """

    def __init__(self, name: str, d: Any, a: Any, alpha: Any, qmin: Any = None, qmax: Any = None, *,
                 convention: str = "standard", offset: Any = None, tool: Any = None, base: Any = None):
        if not isinstance(name, str):
            raise TypeError(f"name: expected a string, got {type(name).__name__}")
        self.name = name
        self.d = as_array(d, "d", ndim=1, min_size=1)
        n = self.d.shape[0]
        self.a = as_array(a, "a", shape=(n,))
        self.alpha = as_array(alpha, "alpha", shape=(n,))
        self.offset = np.zeros(n) if offset is None else as_array(offset, "offset", shape=(n,))
        self.qmin = np.full(n, -np.pi) if qmin is None else as_array(qmin, "qmin", shape=(n,))
        self.qmax = np.full(n, np.pi) if qmax is None else as_array(qmax, "qmax", shape=(n,))
        bad = np.flatnonzero(self.qmin > self.qmax)
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"qmin, qmax: expected qmin <= qmax for every joint, got joint {i + 1} with "
                             f"qmin = {self.qmin[i]:.4g} > qmax = {self.qmax[i]:.4g} rad")
        self.convention = as_choice(convention, "convention", ("standard", "modified"))
        self.tool = np.eye(4) if tool is None else as_se3(tool, "tool")
        self.base = np.eye(4) if base is None else as_se3(base, "base")
        self._has_tool = not np.array_equal(self.tool, np.eye(4))
        self._has_offset = bool(np.any(self.offset != 0))
        # Each link transform is affine in (cos theta, sin theta): A = K + cos U + sin V. Sampling the
        # DH formula at theta = 0, pi, +-pi/2 gives K, U, V, so FK needs no trig of the twists.
        link = mdh_transform if self.modified else dh_transform
        A = {t: link(np.full(n, t), self.d, self.a, self.alpha) for t in (0.0, np.pi, np.pi / 2, -np.pi / 2)}
        self._K = 0.5 * (A[0.0] + A[np.pi])
        self._U = 0.5 * (A[0.0] - A[np.pi])
        self._V = 0.5 * (A[np.pi / 2] - A[-np.pi / 2])
        for arr in (self.d, self.a, self.alpha, self.offset, self.qmin, self.qmax, self.tool, self.base,
                    self._K, self._U, self._V):
            arr.setflags(write=False)

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.d.shape[0]

    @property
    def modified(self) -> bool:
        """True for the modified (Craig) DH convention."""
        return self.convention == "modified"

    @property
    def link_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(K, U, V)``, each (n, 4, 4) and read-only: link ``i`` is ``K_i + cos(theta_i) U_i + sin(theta_i) V_i``
        (what :meth:`frames` and the compiled kernels multiply)."""
        return self._K, self._U, self._V

    def __repr__(self) -> str:
        return f"Chain({self.name!r}, n={self.n}, convention={self.convention!r})"

    # --- validation ------------------------------------------------------------------------------
    def as_q(self, q: Any, name: str = "q", *, batch: bool = False) -> np.ndarray:
        """Return ``q`` as a finite float array of shape ``(n,)`` (or ``(N, n)`` with ``batch``).

        Raises
        ------
        ValueError
            If the joint vector has the wrong length or contains NaN/infinity.
        """
        q = as_array(q, name)
        if batch and q.ndim == 1:
            q = q[None]
        if q.ndim != (2 if batch else 1) or q.shape[-1] != self.n:
            want = f"(N, {self.n})" if batch else f"({self.n},)"
            raise ValueError(f"{name}: expected {self.n} joint angles for {self.name}, shape {want}, "
                             f"got shape {q.shape}")
        return q

    def within_limits(self, q: Any, tol: float = LIMIT_TOL) -> np.ndarray | bool:
        """Return whether each configuration lies inside ``[qmin - tol, qmax + tol]``.

        Parameters
        ----------
        q : array_like, shape (n,) or (N, n)
            Joint angles [rad].
        tol : float, default :data:`LIMIT_TOL`
            Slack [rad] (for rounding).

        Returns
        -------
        bool or numpy.ndarray of bool, shape (N,)
        """
        q = self.as_q(q, batch=array_ndim(q, "q") == 2)
        ok = np.all((q >= self.qmin - tol) & (q <= self.qmax + tol), axis=-1)
        return bool(ok) if ok.ndim == 0 else ok

    def random_q(self, size: int | None = None, rng: Any = None) -> np.ndarray:
        """Draw configurations uniformly inside the joint limits.

        Parameters
        ----------
        size : int, optional
            Number of configurations; ``None`` returns a single ``(n,)`` vector.
        rng : numpy.random.Generator or int, optional
            Source of randomness (seed 0 by default).

        Returns
        -------
        numpy.ndarray, shape (n,) or (size, n)
        """
        gen = as_rng(rng)
        if size is None:
            return gen.uniform(self.qmin, self.qmax)
        size = as_int(size, "size", minimum=1)
        return gen.uniform(self.qmin, self.qmax, size=(size, self.n))

    def reach(self) -> float:
        """Upper bound [m] on the distance from the base origin to the flange.

        The sum of every link's offset ``sqrt(a^2 + d^2)`` plus the tool offset (triangle
        inequality); targets farther away are certainly unreachable.
        """
        return float(np.sum(np.hypot(self.a, self.d)) + np.linalg.norm(self.tool[:3, 3]))

    # --- kinematics ------------------------------------------------------------------------------
    def frames(self, q: Any, *, validate: bool = True) -> np.ndarray:
        """Transforms of frames 0..n (base, then every link) in the world, in one vectorised pass.

        Parameters
        ----------
        q : array_like, shape (..., n)
            Joint angles [rad]; with ``validate=True`` one ``(n,)`` vector or a batch ``(N, n)``.
        validate : bool, default True
            Validate ``q``; ``False`` skips it (solvers' inner loops, float arrays).

        Returns
        -------
        numpy.ndarray, shape (..., n + 1, 4, 4)

        Raises
        ------
        ValueError
            On a wrong-length or non-finite joint vector.

        Notes
        -----
        Product of link transforms, Spong et al. (2006), Eq. (3.5). Each link transform is affine
        in ``(cos theta, sin theta)``: ``A = K + cos(theta) U + sin(theta) V``, precomputed per chain.

        Examples
        --------
        >>> from robokit.arm import iiwa14
        >>> iiwa14().frames([0.0] * 7)[-1, :3, 3].tolist()
        [0.0, 0.0, 1.306]
        """
        if validate:
            q = self.as_q(q, batch=array_ndim(q, "q") == 2)
        th = q + self.offset if self._has_offset else q
        links = self._K + np.cos(th)[..., None, None] * self._U + np.sin(th)[..., None, None] * self._V
        out = np.empty(q.shape[:-1] + (self.n + 1, 4, 4))
        out[..., 0, :, :] = self.base
        for i in range(self.n):
            np.matmul(out[..., i, :, :], links[..., i, :, :], out=out[..., i + 1, :, :])
        return out

    def as_frames(self, frames: Any) -> np.ndarray:
        """Return ``frames`` (of :meth:`frames`) as a finite float array of shape ``(..., n + 1, 4, 4)``.

        Raises
        ------
        ValueError
            If the shape is not (..., n + 1, 4, 4) or a value is not finite.
        """
        frames = as_array(frames, "frames")
        if frames.shape[-3:] != (self.n + 1, 4, 4):
            raise ValueError(f"frames: expected shape (..., {self.n + 1}, 4, 4) from Chain.frames, "
                             f"got shape {frames.shape}")
        return frames

    def flange_transform(self, frames: Any, *, validate: bool = True) -> np.ndarray:
        """The flange's transform (last link frame times the tool) from the frames of :meth:`frames`.

        Parameters
        ----------
        frames : array_like, shape (..., n + 1, 4, 4)
        validate : bool, default True
            Check the shape and values of ``frames``; ``False`` skips it.

        Returns
        -------
        numpy.ndarray, shape (..., 4, 4)

        Raises
        ------
        ValueError
            If ``frames`` does not have shape (..., n + 1, 4, 4) or is not finite.

        Notes
        -----
        Spong et al. (2006), Eq. (3.5), followed by the fixed tool transform.

        Examples
        --------
        The Panda's flange sits 0.107 m beyond its last link frame (the tool transform):

        >>> from robokit.arm import panda
        >>> arm = panda()
        >>> frames = arm.frames(arm.random_q(rng=0))
        >>> T = arm.flange_transform(frames)
        >>> print(round(float(np.linalg.norm(T[:3, 3] - frames[-1, :3, 3])), 3))
        0.107
        """
        if validate:
            frames = self.as_frames(frames)
        return frames[..., -1, :, :] @ self.tool if self._has_tool else frames[..., -1, :, :]

    def joint_frames(self, frames: Any, *, validate: bool = True) -> np.ndarray:
        """Select, from frames 0..n of :meth:`frames`, the frame whose z axis is each joint's axis.

        Parameters
        ----------
        frames : array_like, shape (..., n + 1, 4, 4)
        validate : bool, default True
            Check the shape and values of ``frames``; ``False`` skips it (the Jacobian's kernel).

        Returns
        -------
        numpy.ndarray, shape (..., n, 4, 4)

        Raises
        ------
        ValueError
            If ``frames`` does not have shape (..., n + 1, 4, 4) or is not finite.

        Notes
        -----
        Standard DH: joint ``i`` turns about ``z_{i-1}``; modified DH: about ``z_i`` (Craig 2005,
        Sec. 3.4).

        Examples
        --------
        >>> from robokit.arm import iiwa14
        >>> arm = iiwa14()
        >>> axes = arm.joint_frames(arm.frames(np.zeros(7)))[:, :3, 2]     # joint axes, stretched arm
        >>> print(np.round(axes, 3) + 0.0)
        [[ 0.  0.  1.]
         [ 0.  1.  0.]
         [ 0.  0.  1.]
         [ 0. -1.  0.]
         [ 0.  0.  1.]
         [ 0.  1.  0.]
         [ 0.  0.  1.]]
        """
        if validate:
            frames = self.as_frames(frames)
        return frames[..., 1:, :, :] if self.modified else frames[..., :-1, :, :]

    def link_frames(self, q: Any) -> np.ndarray:
        """Transforms of every link frame 0..n and of the flange in the world frame.

        Parameters
        ----------
        q : array_like, shape (n,) or (N, n)
            Joint angles [rad].

        Returns
        -------
        numpy.ndarray, shape (n + 2, 4, 4) or (N, n + 2, 4, 4)
            Frame 0 (the base), the n link frames, then the flange.

        Raises
        ------
        ValueError
            On a wrong-length or non-finite joint vector.

        Notes
        -----
        Product of link transforms, Spong et al. (2006), Eq. (3.5).
        """
        frames = self.frames(q)
        return np.concatenate([frames, self.flange_transform(frames, validate=False)[..., None, :, :]], axis=-3)

    def fk(self, q: Any) -> np.ndarray:
        """Transform of the flange for joint angles ``q`` (one ``(n,)`` vector or a batch ``(N, n)``).

        Returns
        -------
        numpy.ndarray, shape (4, 4) or (N, 4, 4)

        Raises
        ------
        ValueError
            On a wrong-length or non-finite joint vector.

        Notes
        -----
        Spong et al. (2006), Eq. (3.5), followed by the fixed tool transform.
        """
        return self.flange_transform(self.frames(q), validate=False)


def chain_from_table(dh: Any, *, modified: bool = False) -> Chain:
    """A :class:`Chain` from a plain DH table with rows ``[d, a, alpha]`` (no limits, no tool).

    Raises
    ------
    ValueError
        If ``dh`` is not an (n, 3) table of finite numbers with n >= 1.
    """
    table = as_array(dh, "dh")
    if table.ndim != 2 or table.shape[1] != 3 or table.shape[0] < 1:
        raise ValueError(f"dh: expected a table with rows [d, a, alpha], shape (n, 3), got shape {table.shape}")
    return Chain("DH table", d=table[:, 0], a=table[:, 1], alpha=table[:, 2],
                 convention="modified" if modified else "standard")


def dh_fk(dh: Any, q: Any, *, modified: bool = False) -> np.ndarray:
    """Flange transform of a chain given as a plain DH table.

    Parameters
    ----------
    dh : array_like, shape (n, 3)
        Rows ``[d, a, alpha]`` [m, m, rad], standard DH (or modified with ``modified=True``).
    q : array_like, shape (n,)
        Joint angles [rad].

    Returns
    -------
    numpy.ndarray, shape (4, 4)
        ``A_1(q_1) A_2(q_2) ... A_n(q_n)``.

    Raises
    ------
    ValueError
        On a malformed table or a joint vector of the wrong length.

    Notes
    -----
    Spong et al. (2006), Eq. (3.5).
    """
    chain = chain_from_table(dh, modified=modified)
    return chain.fk(chain.as_q(q))
