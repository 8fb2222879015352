"""LV-MaxSonar-EZ ultrasonic rangers: pulse-width output, beam, timing, and chained versus free firing.

Hamid et al. (2009) mount four MaxBotix LV-MaxSonar-EZ sensors on the front of the
truck, read their pulse-width output and convert it to centimetres or inches (their Eqs. (1), (2)),
and fire them in a commanded daisy-chain loop so that they never hear each other. Sensor facts from
the MaxBotix LV-MaxSonar-EZ datasheet: 147 us of pulse width per inch, 6 to 254 inch reported
range (closer objects read 6 inch), 1 inch resolution, one reading every 49 ms (20 Hz), and the
chaining application note "Using multiple sensors in a single system" (RX/BW/TX loop).

Frames: a sensor mount is ``[x, y, yaw]`` in the truck frame (x forward, y left, metres, radians);
the field frame is x east, y north (see :mod:`robokit.outdoor.field`).

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] MaxBotix Inc., *LV-MaxSonar-EZ Series High Performance Sonar Range Finder* (datasheet,
   MB1000-MB1040).
.. [3] MaxBotix Inc., *Using Multiple Sensors in a Single System* (application note).
.. [4] R. Smith, M. Self and P. Cheeseman, "Estimating uncertain spatial relationships in
   robotics", in *Autonomous Robot Vehicles*, Springer, 1990, pp. 167-193.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any, Sequence

import numpy as np

from ..geometry import se2_compose
from ..validation import (as_array, as_rng, as_choice, as_finite_scalar, as_int, as_positive,
                          require_sample_count)
from ..sim.layout import Layout

__all__ = ["INCH", "SECONDS_PER_INCH", "SPEED_OF_SOUND", "LVMaxSonarEZ", "SonarMount", "PAPER_LAYOUT",
           "pulse_width_to_range", "range_to_pulse_width", "pulse_width_to_cm_inches",
           "firing_schedule", "sensor_poses", "true_ranges", "read_sensors"]

#: One inch in metres.
INCH = 0.0254
#: Pulse width per inch of range (LV-MaxSonar-EZ datasheet: 147 us/inch).
SECONDS_PER_INCH = 147e-6
#: Speed of sound in air at about 20 degC (m/s); 2 * INCH / 343 = 148 us, the datasheet's scale.
SPEED_OF_SOUND = 343.0


@dataclasses.dataclass(frozen=True)
class LVMaxSonarEZ:
    """Parameters of one LV-MaxSonar-EZ sensor (MaxBotix datasheet).

    Attributes
    ----------
    min_range : float
        Closest reported range, 6 inch (0.1524 m); nearer objects read as this value.
    max_range : float
        Farthest reported range, 254 inch (6.45 m); nothing in range reads as this value.
    cycle : float
        Time of one reading, 49 ms.
    half_angle : float
        Half-angle of the detection cone in radians. The datasheet draws a tear-drop beam; 0.35 rad
        (20 deg) is our approximation of the EZ1's pattern for a large target.
    resolution : float
        Range resolution, 1 inch.

    Raises
    ------
    ValueError, TypeError
        For a non-positive range, cycle or resolution, ``max_range <= min_range``, or a half-angle
        outside [0, pi/2).

    Examples
    --------
    >>> sensor = LVMaxSonarEZ()
    >>> round(sensor.max_range, 4), round(sensor.listen_time * 1000, 2)     # 254 inch; echo time in ms
    (6.4516, 37.62)
    >>> round(sensor.quantize(1.0), 4), round(sensor.quantize(0.01), 4)       # 1-inch steps, 6-inch floor
    (0.9906, 0.1524)
    """

    min_range: float = 6 * INCH
    max_range: float = 254 * INCH
    cycle: float = 0.049
    half_angle: float = 0.35
    resolution: float = INCH

    def __post_init__(self) -> None:
        for name in ("min_range", "max_range", "cycle", "resolution"):
            as_positive(getattr(self, name), name)
        if not self.max_range > self.min_range:
            raise ValueError(f"max_range: expected a value above min_range = {self.min_range}, got {self.max_range}")
        if not 0.0 <= as_finite_scalar(self.half_angle, "half_angle") < np.pi / 2:
            raise ValueError(f"half_angle: expected radians in [0, pi/2), got {self.half_angle}")

    @property
    def listen_time(self) -> float:
        """Time for an echo from ``max_range`` to return (s); later echoes are never heard."""
        return 2 * self.max_range / SPEED_OF_SOUND

    def quantize(self, distance: Any) -> Any:
        """Clip to [min_range, max_range] and round to the resolution, as the sensor reports.

        Notes
        -----
        LV-MaxSonar-EZ datasheet: 6-254 inch reported range, 1 inch resolution.
        """
        d = as_array(distance, "distance", finite=False)
        if np.any(np.isnan(d)):
            raise ValueError("distance: expected numbers or inf, got NaN")
        out = np.round(np.clip(d, self.min_range, self.max_range) / self.resolution) * self.resolution
        return float(out) if out.ndim == 0 else out


def pulse_width_to_range(pulse_width: Any) -> Any:
    """Convert LV-MaxSonar-EZ pulse widths (seconds) to range in metres.

    Parameters
    ----------
    pulse_width : float or array_like
        Pulse width of the PW pin in seconds (e.g. ``1470e-6`` for 10 inches).

    Returns
    -------
    float or numpy.ndarray
        ``pulse_width / 147e-6`` inches, in metres.

    Raises
    ------
    ValueError
        For negative or non-finite widths.

    Notes
    -----
    Hamid et al. (2009), Eqs. (1)-(2); scale factor from the LV-MaxSonar-EZ
    datasheet (147 us per inch).
    """
    pw = as_array(pulse_width, "pulse_width")
    if np.any(pw < 0):
        raise ValueError(f"pulse_width: expected non-negative seconds, got {float(pw.min()):g}")
    out = pw / SECONDS_PER_INCH * INCH                    # Eqs. (1)-(2), in metres
    return float(out) if out.ndim == 0 else out


def range_to_pulse_width(distance: Any) -> Any:
    """Inverse of :func:`pulse_width_to_range`: metres to pulse width in seconds (datasheet scale)."""
    d = as_array(distance, "distance")
    if np.any(d < 0):
        raise ValueError(f"distance: expected non-negative metres, got {float(d.min()):g}")
    out = d / INCH * SECONDS_PER_INCH
    return float(out) if out.ndim == 0 else out


def pulse_width_to_cm_inches(pulse_width_us: float) -> dict:
    """The paper's two conversions: pulse width in microseconds to ``{"inches": .., "cm": ..}``.

    Parameters
    ----------
    pulse_width_us : float
        Pulse width in microseconds, between 0 and 60000 (one 49 ms cycle plus margin).

    Returns
    -------
    dict
        ``inches = pulse_width_us / 147`` (Eq. 1) and ``cm = inches * 2.54`` (Eq. 2).

    Raises
    ------
    ValueError
        Negative, non-finite or longer than 60 ms.

    Notes
    -----
    Hamid et al. (2009), Eqs. (1)-(2); the datasheet scale is 147 us per inch.

    Examples
    --------
    >>> pulse_width_to_cm_inches(1470)
    {'inches': 10.0, 'cm': 25.4}
    """
    pw = as_positive(pulse_width_us, "pulse_width_us", allow_zero=True)
    if pw > 60000:
        raise ValueError(f"pulse_width_us: expected at most 60000 us (one reading cycle), got {pw:g}")
    inches = pw / 147.0                                   # Eq. (1)
    return {"inches": inches, "cm": inches * 2.54}        # Eq. (2)


@dataclasses.dataclass(frozen=True)
class SonarMount:
    """Where a sensor sits on the truck: ``name`` and ``[x, y, yaw]`` (m, m, rad; x forward, y left).

    Raises
    ------
    TypeError, ValueError
        For a name that is not a string or a coordinate that is not a finite number.
    """

    name: str
    x: float
    y: float
    yaw: float

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise TypeError(f"name: expected a string, got {self.name!r}")
        for field in ("x", "y", "yaw"):
            as_finite_scalar(getattr(self, field), field)


#: The paper's layout on the 50 cm truck's front bumper (x = 0.25 m from the centre): the outer pair
#: 20 cm apart turned 45 degrees outwards, the middle pair 10 cm apart facing forward
#: (Hamid et al. 2009). Order: outer left, middle left, middle right, outer right.
PAPER_LAYOUT = (
    SonarMount("outer_left", 0.25, 0.10, np.pi / 4),
    SonarMount("middle_left", 0.25, 0.05, 0.0),
    SonarMount("middle_right", 0.25, -0.05, 0.0),
    SonarMount("outer_right", 0.25, -0.10, -np.pi / 4),
)


def firing_schedule(n_sensors: int, duration: float, mode: str = "chained", *, cycle: float = 0.049,
                    rng: Any = None) -> list[np.ndarray]:
    """Ping start times of each sensor over ``duration`` seconds.

    Parameters
    ----------
    n_sensors : int
        Number of sensors (>= 1).
    duration : float
        Seconds to cover.
    mode : {"chained", "free"}
        ``"chained"``: the commanded loop - sensor k starts when sensor k-1 finishes, so one sensor
        pings at a time and each one repeats every ``n_sensors * cycle``. ``"free"``: every sensor
        free-runs every ``cycle`` from a random power-up phase, so pings overlap.
    cycle : float, default 0.049
        Reading cycle of one sensor (datasheet: 49 ms).
    rng : numpy.random.Generator or int, optional
        Phases for ``"free"``.

    Returns
    -------
    list of numpy.ndarray
        One array of start times per sensor.

    Raises
    ------
    ValueError
        For a bad count, duration, cycle or mode.

    Notes
    -----
    MaxBotix application note on chaining (RX of the first sensor triggered once, each TX output
    triggering the next RX, the last fed back to the first); Hamid et al. (2009) call it the
    commanded loop daisy chaining method.

    Examples
    --------
    >>> [np.round(t, 3).tolist() for t in firing_schedule(4, 0.4)]      # one ping at a time
    [[0.0, 0.196, 0.392], [0.049, 0.245], [0.098, 0.294], [0.147, 0.343]]
    """
    n = as_int(n_sensors, "n_sensors", minimum=1)
    T = as_positive(duration, "duration")
    c = as_positive(cycle, "cycle")
    as_choice(mode, "mode", ("chained", "free"))
    g = as_rng(rng)     # checked in either mode; only "free" draws from it
    require_sample_count((1 if mode == "chained" else n) * T / c + n, "n_sensors, duration, cycle")
    if mode == "chained":
        return [np.arange(k * c, T, n * c) for k in range(n)]
    return [np.arange(p, T, c) for p in g.uniform(0, c, n)]


def sensor_poses(pose: Any, mounts: Sequence[SonarMount] = PAPER_LAYOUT) -> np.ndarray:
    """Field-frame poses ``(n, 3)`` of the sensors for a truck pose ``[x, y, theta]`` (headings wrapped
    to [-pi, pi)).

    Parameters
    ----------
    pose : array_like, shape (3,)
        Truck pose in the field.
    mounts : sequence of SonarMount, default :data:`PAPER_LAYOUT`

    Returns
    -------
    numpy.ndarray, shape (n, 3)

    Raises
    ------
    ValueError, TypeError
        For a malformed pose, or ``mounts`` that is empty or holds something else than SonarMount.

    Notes
    -----
    Planar pose composition (Smith, Self & Cheeseman 1990) of the truck pose and each mount of
    :data:`PAPER_LAYOUT` (Hamid et al. 2009).

    Examples
    --------
    >>> np.round(sensor_poses([0.0, 0.0, 0.0]), 3).tolist()     # x forward, y left, yaw
    [[0.25, 0.1, 0.785], [0.25, 0.05, 0.0], [0.25, -0.05, 0.0], [0.25, -0.1, -0.785]]
    """
    m = np.array([[mt.x, mt.y, mt.yaw] for mt in _as_sensors(mounts)])
    return se2_compose(as_array(pose, "pose", shape=(3,)), m, validate=False)    # pose ⊕ mount


def _cone(sensor: LVMaxSonarEZ, rays: int) -> np.ndarray:
    """Ray offsets across the cone; one ray is the axis (``linspace`` would give its edge)."""
    return np.linspace(-sensor.half_angle, sensor.half_angle, rays) if rays > 1 else np.zeros(1)


def _as_sensors(mounts: Any, sensor: Any = LVMaxSonarEZ()) -> tuple:
    """``mounts`` as a non-empty tuple of :class:`SonarMount` (each checked when it was made); ``sensor`` typed."""
    if not isinstance(sensor, LVMaxSonarEZ):
        raise TypeError(f"sensor: expected an LVMaxSonarEZ, got {type(sensor).__name__}")
    if isinstance(mounts, SonarMount) or not isinstance(mounts, Sequence) or not mounts:
        raise TypeError(f"mounts: expected a non-empty sequence of SonarMount, got {mounts!r}")
    for i, m in enumerate(mounts):
        if not isinstance(m, SonarMount):
            raise TypeError(f"mounts[{i}]: expected a SonarMount, got {type(m).__name__}")
    return tuple(mounts)


def true_ranges(field: Layout, pose: Any, mounts: Sequence[SonarMount] = PAPER_LAYOUT,
                sensor: LVMaxSonarEZ = LVMaxSonarEZ(), rays: int = 9) -> tuple[np.ndarray, np.ndarray]:
    """Nearest obstacle within each sensor's cone, and where it is.

    Parameters
    ----------
    field : robokit.outdoor.field.Field
    pose : array_like, shape (3,)
        Truck pose in the field.
    mounts : sequence of SonarMount
    sensor : LVMaxSonarEZ
    rays : int, default 9
        Rays fanned across the cone (the beam is sampled, not integrated).

    Returns
    -------
    ranges : numpy.ndarray, shape (n,)
        Metres to the first echo (``inf`` when nothing is within ``max_range``).
    hits : numpy.ndarray, shape (n, 2)
        Field coordinates of the reflecting point (NaN when nothing is hit).

    Raises
    ------
    TypeError, ValueError
        For a ``field`` that is not a layout, a bad pose, an empty ``mounts`` or one that is not
        made of :class:`SonarMount`, a ``sensor`` that is not an :class:`LVMaxSonarEZ`, or ``rays < 1``.

    Notes
    -----
    A sonar reports the *first* echo anywhere in its cone, which is why wide beams see obstacles
    off to the side (datasheet beam pattern; Hamid et al. 2009, side sensors at 45 degrees).
    The rays are cast with :meth:`robokit.sim.Layout.raycast` (its tie rule applies).

    Examples
    --------
    >>> from robokit.outdoor import Field
    >>> ranges, hits = true_ranges(Field(circles=[[2.5, 0.0, 0.3]]), [0.0, 0.0, 0.0])
    >>> np.round(ranges, 3).tolist()                 # a post 2.5 m ahead: only the middle pair sees it
    [inf, 1.954, 1.954, inf]
    """
    if not isinstance(field, Layout):
        raise TypeError(f"field: expected a robokit.outdoor.Field (or any robokit.sim.Layout), got "
                        f"{type(field).__name__}")
    k = as_int(rays, "rays", minimum=1)
    mounts = _as_sensors(mounts, sensor)
    sp = sensor_poses(pose, mounts)
    offs = _cone(sensor, k)
    angles = (sp[:, 2:3] + offs[None, :]).ravel()
    origins = np.repeat(sp[:, :2], k, axis=0)
    d = field.raycast(origins, angles, sensor.max_range * 1.0001, validate=False).reshape(len(sp), k)
    j = d.argmin(axis=1)
    r = d[np.arange(len(sp)), j]
    hit = r < sensor.max_range
    ang = sp[:, 2] + offs[j]
    pts = sp[:, :2] + r[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    pts[~hit] = np.nan
    return np.where(hit, r, np.inf), pts


def read_sensors(field: Any, pose: Any, which: Sequence[int], ping_times: Sequence[float], *,
                 mounts: Sequence[SonarMount] = PAPER_LAYOUT, sensor: LVMaxSonarEZ = LVMaxSonarEZ(),
                 others: dict | None = None, rng: Any = None, noise: float = 0.01) -> np.ndarray:
    """Simulate the readings of sensors ``which`` pinging at ``ping_times``, with cross-talk.

    Each sensor listens after its own ping and reports the first echo it hears. Besides its own
    echo, it hears the echo of any other sensor's ping that is in flight (listed in ``others``) if
    that sensor's reflecting point lies inside its cone; when that arrives first the reading is
    wrong (too short, or from the wrong direction). With chained firing no other ping is in flight,
    so ``others`` is empty and there is no cross-talk.

    Parameters
    ----------
    field, pose
        As in :func:`true_ranges`.
    which : sequence of int
        Indices (into ``mounts``) of the sensors whose readings are wanted.
    ping_times : sequence of float
        Their ping start times (s).
    others : dict, optional
        ``{sensor_index: ping_time}`` of every sensor whose ping may overlap (free-running mode).
    rng : numpy.random.Generator or int, optional
        For the range noise.
    noise : float, default 0.01
        Standard deviation (m) of Gaussian range noise before quantisation.

    Returns
    -------
    numpy.ndarray
        Reported ranges in metres, quantised to 1 inch and clipped to the sensor limits.

    Raises
    ------
    TypeError, ValueError
        As :func:`true_ranges`, and for sensor indices outside ``mounts``, ping times that are not
        one finite number per sensor, ``others`` that is not ``{index: finite time}``, or a
        negative ``noise``.

    Notes
    -----
    Cross-talk is the reason for the chained, commanded-loop firing in Hamid et al.
    (2009) and in the MaxBotix multi-sensor application note.

    Examples
    --------
    >>> from robokit.outdoor import Field
    >>> post = Field(circles=[[2.5, 0.0, 0.3]])
    >>> read_sensors(post, [0.0, 0.0, 0.0], [1, 2], [0.0, 0.049], noise=0.0).round(4).tolist()   # chained
    [1.9558, 1.9558]
    """
    g = as_rng(rng)
    mounts = _as_sensors(mounts, sensor)
    idx = [as_int(int(i), f"which[{k}]", minimum=0, maximum=len(mounts) - 1)
           for k, i in enumerate(as_array(which, "which", ndim=1, dtype=int))]
    times = as_array(ping_times, "ping_times", shape=(len(idx),))
    sigma = as_positive(noise, "noise", allow_zero=True)
    if not isinstance(others, (dict, type(None))):
        raise TypeError(f"others: expected a dict {{sensor index: ping time}}, got {type(others).__name__}")
    pending = {as_int(j, "others key", minimum=0, maximum=len(mounts) - 1): as_finite_scalar(t, f"others[{j}]")
               for j, t in (others or {}).items()}
    if not pending:  # no ping in flight but our own: only the wanted sensors need a ray fan
        ranges = np.full(len(mounts), np.inf)
        ranges[idx] = true_ranges(field, pose, [mounts[i] for i in idx], sensor)[0]
        hits, sp = None, None
    else:
        ranges, hits = true_ranges(field, pose, mounts, sensor)
        sp = sensor_poses(pose, mounts)
    out = np.empty(len(idx))
    for n, (i, t_i) in enumerate(zip(idx, times)):
        arrival = t_i + 2 * ranges[i] / SPEED_OF_SOUND
        for j, t_j in pending.items():
            if j == i or not np.isfinite(ranges[j]):
                continue
            vx, vy = float(hits[j, 0] - sp[i, 0]), float(hits[j, 1] - sp[i, 1])
            dist = math.hypot(vx, vy)
            bearing = (math.atan2(vy, vx) - float(sp[i, 2]) + math.pi) % (2 * math.pi) - math.pi   # wrapped
            if abs(bearing) > sensor.half_angle or dist > sensor.max_range:
                continue
            a = t_j + (ranges[j] + dist) / SPEED_OF_SOUND
            if t_i < a < arrival:
                arrival = a
        heard = SPEED_OF_SOUND * (arrival - t_i) / 2
        if np.isfinite(heard):
            heard += g.normal(0, sigma) if sigma else 0.0
        out[n] = heard if np.isfinite(heard) else np.inf
    return np.asarray(sensor.quantize(out), dtype=float).reshape(len(idx))
