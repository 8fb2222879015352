"""A 2D scanning LiDAR (defaults like an RPLIDAR A2) over a world's footprint.

A scan casts every beam over the layout of the world's walls at the scan height
(:meth:`robokit.sim.World.layout`, cached per world and height) with the course's one ray caster,
:meth:`robokit.sim.Layout.raycast`, so the LiDAR, lesson 05's sonars and the field share one
geometry and one tie rule.

References
----------
.. [1] S. Thrun, W. Burgard and D. Fox, *Probabilistic Robotics*, MIT Press, 2005.
.. [2] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering*, 2023,
   doi:10.1631/FITEE.2200208.
.. [3] R. Smith, M. Self and P. Cheeseman, "Estimating uncertain spatial relationships in
   robotics", in *Autonomous Robot Vehicles*, Springer, 1990, pp. 167-193.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..geometry import se2_compose
from ..validation import as_array, as_rng, as_int, as_positive
from .layout import Layout
from .world import World

__all__ = ["Lidar", "scan_points"]

#: How far past ``r_max`` a beam is cast (a factor): far enough that "nothing within range" is told
#: apart from a return at ``r_max``, near enough that the ray caster culls everything beyond reach.
_BEYOND = 1.001


@dataclasses.dataclass
class Lidar:
    """A 360-degree 2D laser scanner.

    Parameters
    ----------
    beams : int, default 360
        Number of beams over a full turn (angular resolution ``2 pi / beams``).
    r_min, r_max : float, default 0.15, 8.0
        Valid range interval (metres); returns outside it are reported as ``inf``. Defaults after
        the RPLIDAR A2 used by Ge et al. (2023, Sec. 4.1: "effective measurement radius of 8-10 m").
    noise : float, default 0.0
        Standard deviation of additive Gaussian range noise (metres).
    height : float, default 0.25
        Height of the scan plane above the floor (metres).
    offset : array_like, shape (3,), default (0, 0, 0)
        Planar mount ``[x, y, theta]`` of the sensor in the robot frame.

    Notes
    -----
    Beam ``i`` points at ``2 pi i / beams`` counter-clockwise from the sensor's forward axis.
    Range model: Thrun et al. (2005), Sec. 6.3.1 (the Gaussian ``p_hit`` part of the beam model;
    max-range readings reported as ``inf``).

    Examples
    --------
    >>> from robokit.sim import long_corridor
    >>> corridor = long_corridor()
    >>> door = corridor.info["doors"][0]                    # ('north', x0, x1)
    >>> ranges = Lidar().scan(corridor, [(door[1] + door[2]) / 2, 0.0, 0.0])
    >>> round(float(ranges[90]), 3), round(float(ranges[270]), 3)   # half width 1.085 m + 0.07 m recess
    (1.155, 1.155)
    """

    beams: int = 360
    r_min: float = 0.15
    r_max: float = 8.0
    noise: float = 0.0
    height: float = 0.25
    offset: Any = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        self.beams = as_int(self.beams, "beams", minimum=1)
        self.r_min = as_positive(self.r_min, "r_min", allow_zero=True)
        self.r_max = as_positive(self.r_max, "r_max")
        if self.r_max <= self.r_min:
            raise ValueError(f"r_max: expected a value above r_min = {self.r_min}, got {self.r_max}")
        self.noise = as_positive(self.noise, "noise", allow_zero=True)
        self.height = as_positive(self.height, "height")
        self.offset = as_array(self.offset, "offset", shape=(3,))

    @property
    def angles(self) -> np.ndarray:
        """Beam angles in the sensor frame (radians), shape ``(beams,)``."""
        return 2 * np.pi * np.arange(self.beams) / self.beams

    def sensor_pose(self, robot_pose: Any) -> np.ndarray:
        """Planar pose of the sensor for a robot at ``[x, y, theta]``.

        Notes
        -----
        ``robot_pose ⊕ offset`` (Smith, Self & Cheeseman 1990, Eq. (3)).
        """
        return se2_compose(as_array(robot_pose, "robot_pose", shape=(3,)), self.offset)

    def scan(self, world: World, robot_pose: Any, rng: Any = None) -> np.ndarray:
        """Simulate one scan from a robot at planar pose ``[x, y, theta]``.

        Parameters
        ----------
        world : World
        robot_pose : array_like, shape (3,)
        rng : Generator or int, optional
            Noise source (only used when ``noise > 0``).

        Returns
        -------
        numpy.ndarray, shape (beams,)
            Ranges in metres; ``inf`` where the true range is outside ``[r_min, r_max]``.

        Raises
        ------
        TypeError
            If ``world`` is not a World.
        ValueError
            For a NaN pose or a sensor inside a wall / outside the world.

        Notes
        -----
        :meth:`robokit.sim.Layout.raycast` over ``world.layout(height)``; noise is the Gaussian
        ``p_hit`` part of the beam model (Thrun et al. 2005, Sec. 6.3.1).

        Examples
        --------
        >>> from robokit.sim import box_room
        >>> r = Lidar(beams=4, r_max=20.0).scan(box_room(), [2.0, 1.0, 0.0])   # 6 m x 4 m room
        >>> np.round(r, 3).tolist()
        [4.0, 3.0, 2.0, 1.0]
        """
        if not isinstance(world, World):
            raise TypeError(f"world: expected a robokit.sim World, got {type(world).__name__}")
        sp = self.sensor_pose(robot_pose)
        world.as_viewpoint([sp[0], sp[1], self.height], "robot_pose", clearance=0.0)
        return self._cast(world.layout(self.height), sp, rng)

    def scan_layout(self, layout: Layout, robot_pose: Any, rng: Any = None) -> np.ndarray:
        """Simulate one scan over a planar layout, e.g. a map's outline (:meth:`Layout.from_cells`).

        Parameters
        ----------
        layout : Layout
            What the beams hit (the scan plane's walls).
        robot_pose : array_like, shape (3,)
            ``[x, y, theta]``; the caller keeps the sensor in free space (a layout of segments has no
            inside to check against).
        rng : Generator or int, optional
            Noise source (only used when ``noise > 0``).

        Returns
        -------
        numpy.ndarray, shape (beams,)
            As :meth:`scan`.

        Raises
        ------
        TypeError
            If ``layout`` is not a Layout.
        ValueError
            For a NaN or badly shaped pose.

        Notes
        -----
        The same ray casting and noise as :meth:`scan` (Thrun et al. 2005, Sec. 6.3.1), without a
        world: lesson 03 scans a real building's map this way.

        Examples
        --------
        >>> walls = Layout.from_cells([[False, False, False, True]], 1.0)   # one occupied cell at x in [3, 4]
        >>> Lidar(beams=2, r_max=5.0).scan_layout(walls, [0.5, 0.5, 0.0]).tolist()   # ahead 2.5 m; behind: nothing
        [2.5, inf]
        """
        if not isinstance(layout, Layout):
            raise TypeError(f"layout: expected a robokit.sim Layout, got {type(layout).__name__}")
        return self._cast(layout, self.sensor_pose(robot_pose), rng)

    def _cast(self, layout: Layout, sp: np.ndarray, rng: Any) -> np.ndarray:
        """Ranges from sensor pose ``sp`` over ``layout``, with noise and the valid interval applied."""
        # only obstacles within reach are cast against (max_range culls the rest); a beam that hits
        # nothing within it reads just over r_max, which the mask below turns into inf
        true = layout.raycast(sp[:2], self.angles + sp[2], _BEYOND * self.r_max, validate=False)
        out = true.copy()
        if self.noise > 0:
            out = out + as_rng(rng).normal(0.0, self.noise, self.beams)
        out[(true < self.r_min) | (true > self.r_max)] = np.inf
        return out

    def observe(self, world: World, robot_pose: Any, rng: Any = None) -> np.ndarray:
        """Alias of :meth:`scan` (the common sensor interface used by :func:`robokit.sim.record`).

        Parameters
        ----------
        world : World
        robot_pose : array_like, shape (3,)
        rng : Generator or int, optional

        Returns
        -------
        numpy.ndarray, shape (beams,)

        Notes
        -----
        See :meth:`scan`.
        """
        return self.scan(world, robot_pose, rng)


def scan_points(ranges: Any, pose: Any, angles: Any) -> np.ndarray:
    """World (x, y) points of the finite returns of a scan taken at sensor pose ``[x, y, theta]``.

    Parameters
    ----------
    ranges : array_like, shape (B,)
        Metres; ``inf`` marks a beam without a return (skipped). NaN and negative ranges are refused.
    pose : array_like, shape (3,)
        Sensor pose (see :meth:`Lidar.sensor_pose`).
    angles : array_like, shape (B,)
        Beam angles in the sensor frame.

    Returns
    -------
    numpy.ndarray, shape (K, 2)

    Notes
    -----
    Polar to Cartesian conversion (Thrun et al. 2005, Eq. (6.32) endpoint model).
    """
    r = as_array(ranges, "ranges", ndim=1, finite=False)
    if np.any(np.isnan(r) | (r < 0)):
        raise ValueError(f"ranges: expected non-negative ranges or inf (no return), got {r[np.isnan(r) | (r < 0)][0]}")
    a = as_array(angles, "angles", ndim=1)
    p = as_array(pose, "pose", shape=(3,))
    if len(r) != len(a):
        raise ValueError(f"angles: expected {len(r)} angles to match ranges, got {len(a)}")
    ok = np.isfinite(r)
    return p[:2] + r[ok, None] * np.column_stack([np.cos(a[ok] + p[2]), np.sin(a[ok] + p[2])])
