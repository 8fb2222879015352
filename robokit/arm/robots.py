"""Two real 7-DOF arms with their published kinematic parameters.

* KUKA LBR iiwa 14 R820: an S-R-S arm (spherical shoulder, revolute elbow, spherical wrist).
* Franka Emika Panda: not S-R-S (its elbow and wrist have link offsets), so only numerical IK
  applies to it.

References
----------
.. [1] KUKA Roboter GmbH, *LBR iiwa 7 R800, LBR iiwa 14 R820 Specification*, Spez LBR iiwa V7,
   2016.
.. [2] M. Shimizu, H. Kakuya, W.-K. Yoon, K. Kitagaki and K. Kosuge, "Analytical inverse kinematic
   computation for 7-DOF redundant manipulators with joint limits and its application to redundancy
   resolution", *IEEE Transactions on Robotics* 24(5), 1131-1142, 2008.
.. [3] C. Faria, F. Ferreira, W. Erlhagen, S. Monteiro and E. Bicho, "Position-based kinematics for
   7-DoF serial manipulators with global configuration control, joint limit and singularity
   avoidance", *Mechanism and Machine Theory* 121, 317-334, 2018.
.. [4] Franka Emika, *Franka Control Interface (FCI) documentation*, "Robot and interface
   specifications", https://frankaemika.github.io/docs/control_parameters.html.
"""
from __future__ import annotations

import numpy as np

from .chain import Chain

__all__ = ["iiwa14", "panda"]


def iiwa14() -> Chain:
    """The KUKA LBR iiwa 14 R820 in standard DH form.

    Link offsets ``d = (0.36, 0, 0.42, 0, 0.40, 0, 0.126)`` m, all ``a = 0``, twists
    ``alpha = (-pi/2, pi/2, pi/2, -pi/2, -pi/2, pi/2, 0)``; limits
    ``+-(170, 120, 170, 120, 170, 120, 175)`` degrees. At ``q = 0`` the arm stands straight up and
    the flange is at ``z = 1.306`` m. Frames 1 and 2 meet at the shoulder, frames 5 and 6 at the
    wrist centre; the flange is frame 7.

    Returns
    -------
    Chain

    Notes
    -----
    Dimensions and axis ranges: KUKA (2016), Sec. 4 (principal dimensions, axis data). The DH
    assignment is the S-R-S form used by Shimizu et al. (2008), Table I (with the iiwa's link
    lengths), and by Faria et al. (2018), Table 1.

    Examples
    --------
    >>> arm = iiwa14()
    >>> arm.n, arm.convention, arm.fk(np.zeros(7))[:3, 3].tolist()
    (7, 'standard', [0.0, 0.0, 1.306])
    """
    deg = np.pi / 180.0
    lim = np.array([170, 120, 170, 120, 170, 120, 175]) * deg
    return Chain(
        "KUKA LBR iiwa 14 R820",
        d=[0.36, 0.0, 0.42, 0.0, 0.40, 0.0, 0.126],
        a=np.zeros(7),
        alpha=np.array([-1, 1, 1, -1, -1, 1, 0]) * np.pi / 2,
        qmin=-lim, qmax=lim, convention="standard",
    )


def panda() -> Chain:
    """The Franka Emika Panda in modified (Craig) DH form, with its flange.

    ``a_{i-1} = (0, 0, 0, 0.0825, -0.0825, 0, 0.088)`` m, ``d_i = (0.333, 0, 0.316, 0, 0.384, 0, 0)``
    m, ``alpha_{i-1} = (0, -pi/2, pi/2, pi/2, -pi/2, pi/2, pi/2)``, zero joint offsets, and the
    flange ``d = 0.107`` m along ``z_7``. Joint limits [rad]: ``qmin = (-2.8973, -1.7628, -2.8973,
    -3.0718, -2.8973, -0.0175, -2.8973)``, ``qmax = (2.8973, 1.7628, 2.8973, -0.0698, 2.8973,
    3.7525, 2.8973)``.

    Returns
    -------
    Chain

    Notes
    -----
    Franka Emika, FCI documentation, "Robot and interface specifications": Denavit-Hartenberg
    parameters (Craig's convention) and joint space limits.

    Examples
    --------
    >>> arm = panda()
    >>> arm.convention
    'modified'
    >>> print(np.round(arm.fk(np.zeros(7))[:3, 3], 3) + 0.0)    # the flange at q = 0 (+ 0.0: no "-0.")
    [0.088 0.    0.926]
    """
    T_flange = np.eye(4)
    T_flange[2, 3] = 0.107
    return Chain(
        "Franka Emika Panda",
        d=[0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0],
        a=[0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088],
        alpha=np.array([0, -1, 1, 1, -1, 1, 1]) * np.pi / 2,
        qmin=[-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973],
        qmax=[2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973],
        convention="modified", tool=T_flange,
    )
