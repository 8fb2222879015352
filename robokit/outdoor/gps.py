"""A 1 Hz GPS receiver and a magnetic compass that speak NMEA 0183, as on the paper's truck.

Hamid et al. (2009) read position from a Garmin eTrex Vista ($GPRMC, $GPGGA) and
heading from its compass ($HCHDG), and note that the position may be wrong by up to about 9 m.
Consumer GPS errors are not independent from second to second: they wander slowly (satellite
geometry, atmosphere, multipath). We model each horizontal axis as a first-order Gauss-Markov
process (standard deviation ``noise``, correlation time ``tau``) plus a little white noise (Grewal
et al. 2013, Sec. 10.2 on time-correlated GNSS errors); with ``noise`` = 2.5 m the error is a few
metres and exceeds 9 m well under 1 % of the time.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] M. S. Grewal, A. P. Andrews and C. G. Bartone, *Global Navigation Satellite Systems,
   Inertial Navigation, and Integration*, 3rd ed., Wiley, 2013.
.. [3] National Marine Electronics Association, *NMEA 0183 Standard for Interfacing Marine
   Electronic Devices*, version 4.11, 2018.
"""
from __future__ import annotations

import datetime as _dt
import math
from typing import Any

import numpy as np

from ..geometry import wrap_angle
from ..validation import as_array, as_rng, as_finite_scalar, as_positive
from .geodesy import LocalTangentPlane, haversine_distance_bearing
from .nmea_write import gga_sentence, hdg_sentence, rmb_sentence, rmc_sentence

__all__ = ["GPSReceiver", "Compass", "heading_to_compass", "compass_to_heading", "MISSION_START"]

#: UTC time the simulated missions start (any fixed time keeps runs reproducible).
MISSION_START = _dt.datetime(2012, 6, 4, 2, 30, 0)


def heading_to_compass(theta: float) -> float:
    """Field heading (rad, counter-clockwise from east) to compass heading (degrees clockwise from north).

    Notes
    -----
    ``psi = 90 deg - theta`` modulo 360 (navigation convention, NMEA 0183 Sec. 6.3 HDG/RMC course).
    """
    return (90.0 - math.degrees(as_finite_scalar(theta, "theta"))) % 360.0


def compass_to_heading(psi_deg: float) -> float:
    """Compass heading (degrees clockwise from north) to field heading (rad CCW from east) in [-pi, pi).

    Notes
    -----
    Inverse of :func:`heading_to_compass` (NMEA 0183 Sec. 6.3 heading convention).

    Examples
    --------
    >>> round(compass_to_heading(90.0), 6), round(compass_to_heading(0.0), 6)     # east, north
    (0.0, 1.570796)
    """
    return wrap_angle(math.radians(90.0 - as_finite_scalar(psi_deg, "psi_deg")))


class GPSReceiver:
    """Simulated receiver emitting ``$GPRMC``, ``$GPGGA`` (and ``$GPRMB`` to a waypoint) once per ``period`` s.

    Parameters
    ----------
    plane : LocalTangentPlane
        Maps the field's east-north metres to latitude/longitude.
    noise : float, default 2.5
        Standard deviation (m) of the slowly varying error on each axis.
    tau : float, default 60
        Correlation time (s) of that error.
    white_noise : float, default 0.3
        Standard deviation (m) of the independent per-fix noise.
    period : float, default 1
        Seconds between fixes (1 Hz like the eTrex).
    rng : numpy.random.Generator or int, optional

    Notes
    -----
    Gauss-Markov update ``b_k+1 = phi b_k + sqrt(1 - phi^2) noise n_k``, ``phi = exp(-period/tau)``
    (Grewal et al. 2013, Sec. 10.2). Sentences built by :mod:`robokit.outdoor.nmea_write`.

    Examples
    --------
    >>> from robokit.outdoor.field import UNIMAP_ORIGIN
    >>> gps = GPSReceiver(LocalTangentPlane(*UNIMAP_ORIGIN), rng=1)
    >>> rmc, gga = gps.fix(0.0, [50.0, 30.0], speed=0.7, heading=0.0)
    >>> rmc
    '$GPRMC,023000.00,A,0627.5571,N,10021.0578,E,1.36,90.0,040612,,,A*5E'
    >>> np.round(gps.last_error, 2).tolist()      # east, north error (m) in that fix
    [1.27, 1.56]
    """

    def __init__(self, plane: LocalTangentPlane, *, noise: float = 2.5, tau: float = 60.0, white_noise: float = 0.3,
                 period: float = 1.0, rng: Any = None) -> None:
        if not isinstance(plane, LocalTangentPlane):
            raise TypeError(f"plane: expected a LocalTangentPlane, got {type(plane).__name__}")
        self.plane = plane
        self.noise = as_positive(noise, "noise", allow_zero=True)
        self.tau = as_positive(tau, "tau")
        self.white_noise = as_positive(white_noise, "white_noise", allow_zero=True)
        self.period = as_positive(period, "period")
        self.rng = as_rng(rng)
        self.bias = self.rng.normal(0.0, self.noise, 2) if self.noise else np.zeros(2)
        self.last_error = np.zeros(2)

    def fix(self, t: float, position: Any, speed: float, heading: float, destination: Any = None,
            destination_id: str = "001", *, origin: Any = None, origin_id: str = "000",
            arrival_radius: float = 2.0) -> list[str]:
        """Advance the error one period and return the NMEA sentences of a fix at time ``t``.

        Parameters
        ----------
        t : float
            Seconds since :data:`MISSION_START`.
        position : array_like, shape (2,)
            True east-north position (m).
        speed : float
            True ground speed (m/s).
        heading : float
            True heading (rad CCW from east), reported as RMC course over ground.
        destination : array_like, shape (2,), optional
            ``[latitude, longitude]`` (radians) of the active waypoint. When given, the receiver
            also sends ``$GPRMB``: its own range and bearing from this (noisy) fix to the waypoint,
            computed on the sphere (:func:`~robokit.outdoor.geodesy.haversine_distance_bearing`)
            and written, as NMEA does, in nautical miles to 0.001 and degrees to 0.1, with the closing
            velocity ``speed * cos(course - bearing)`` and the arrival status.
        destination_id : str, default "001"
            The waypoint's name in the RMB sentence.
        origin : array_like, shape (2,), optional
            ``[latitude, longitude]`` (radians) where the active leg starts (the previous waypoint
            or the start). When given, RMB carries the cross-track error: the fix's signed distance
            (m) from the straight leg origin -> destination in the local plane, with the side to
            steer back; without it the cross-track field is 0.
        origin_id : str, default "000"
            The origin's name in the RMB sentence.
        arrival_radius : float, default 2.0
            RMB's arrival status is "A" when the unrounded range from the fix is below this (m).

        Returns
        -------
        list of str
            ``[RMC, GGA]`` or ``[RMC, GGA, RMB]``; :attr:`last_error` holds the position error (m)
            that went into them.

        Notes
        -----
        Gauss-Markov error (Grewal et al. 2013, Sec. 10.2); sentences per NMEA 0183 v4.11 Sec. 6.3.
        The paper's truck reads RMB's bearing and range to the waypoint (Hamid et al. 2009).

        Examples
        --------
        >>> from robokit.outdoor.field import UNIMAP_ORIGIN
        >>> plane = LocalTangentPlane(*UNIMAP_ORIGIN)
        >>> gps = GPSReceiver(plane, noise=0.0, white_noise=0.0)
        >>> wp = np.column_stack(plane.to_geodetic([[60.0, 30.0]]))[0]
        >>> gps.fix(0.0, [0.0, 30.0], 0.7, 0.0, destination=wp)[2]      # 60 m due east, closing at 0.7 m/s
        '$GPRMB,A,0.000,L,000,001,0627.5563,N,10021.0625,E,0.032,90.0,1.4,V,A*52'
        >>> start = np.column_stack(plane.to_geodetic([[0.0, 33.0]]))[0]   # leg from 3 m further north
        >>> gps.fix(1.0, [0.0, 30.0], 0.7, 0.0, destination=wp, origin=start)[2].split(",")[2:4]
        ['0.002', 'L']
        """
        p = as_array(position, "position", shape=(2,))
        ts = as_positive(t, "t", allow_zero=True)
        goal = None if destination is None else as_array(destination, "destination", shape=(2,))
        leg_start = None if origin is None else as_array(origin, "origin", shape=(2,))
        radius = as_positive(arrival_radius, "arrival_radius", allow_zero=True)
        phi = math.exp(-self.period / self.tau)
        self.bias = phi * self.bias + math.sqrt(1 - phi * phi) * self.noise * self.rng.normal(size=2)  # Gauss-Markov
        self.last_error = self.bias + self.white_noise * self.rng.normal(size=2)
        lat, lon = self.plane.to_geodetic(p + self.last_error)
        when = MISSION_START + _dt.timedelta(seconds=round(ts, 2))
        lat_d, lon_d = math.degrees(lat), math.degrees(lon)
        v = abs(as_finite_scalar(speed, "speed"))
        hdop = 1.0 + float(np.hypot(*self.bias)) / 4
        out = [rmc_sentence(when, lat_d, lon_d, speed_mps=v, course_deg=heading_to_compass(heading)),
               gga_sentence(when.time(), lat_d, lon_d, quality=1, satellites=8, hdop=hdop, altitude_m=12.0)]
        if goal is not None:   # the receiver's own navigation to the active waypoint
            rng_m, brg = haversine_distance_bearing(float(lat), float(lon), float(goal[0]), float(goal[1]))
            closing = v * math.cos(math.radians(heading_to_compass(heading)) - float(brg))
            xte = 0.0
            if leg_start is not None:
                a, b = (self.plane.to_local(*leg_start), self.plane.to_local(*goal))
                u = (b - a) / max(float(np.hypot(*(b - a))), 1e-9)
                rel = p + self.last_error - a
                xte = -float(u[0] * rel[1] - u[1] * rel[0])     # left of the leg: steer right (negative)
            out.append(rmb_sentence(math.degrees(goal[0]), math.degrees(goal[1]), range_m=float(rng_m),
                                    bearing_deg=math.degrees(brg), cross_track_m=xte, origin_id=origin_id,
                                    destination_id=destination_id, closing_velocity_mps=closing,
                                    arrived=bool(rng_m < radius)))
        return out


class Compass:
    """Simulated magnetic compass emitting ``$HCHDG`` (heading, deviation, variation).

    Parameters
    ----------
    noise : float, default ``radians(0.5)``
        Standard deviation of the heading noise from reading to reading (rad).
    accuracy : float, default ``radians(2.0)``
        Bound of the total error after calibration (rad): Hamid et al. give +-2 degrees for the
        eTrex's compass and +-5 degrees at extreme northern and southern latitudes. Each compass gets
        one constant bias drawn uniformly within ``accuracy - resolution / 2``; bias plus noise is
        kept within that bound too, so that after rounding to the resolution every reading is within
        ``accuracy`` of the truth (within ``resolution / 2`` when ``accuracy`` is smaller).
    resolution : float, default ``radians(1.0)``
        The compass reports whole multiples of this (rad); the paper's compass: 1 degree.
    variation : float, default ``radians(-0.3)``
        Local magnetic variation (rad, east positive) sent in the sentence; the reported heading is
        the magnetic one, so true = heading + variation (NMEA 0183 Sec. 6.3, HDG). The sentence
        carries both in degrees, as NMEA does.
    rng : numpy.random.Generator or int, optional

    Attributes
    ----------
    bias : float
        This compass's constant error (rad, clockwise positive like the compass heading).
    bound : float
        Bound of bias plus noise before rounding (rad), ``max(0, accuracy - resolution / 2)``.

    Raises
    ------
    ValueError, TypeError
        For a negative or non-finite ``noise`` or ``accuracy``, a non-positive ``resolution`` or a
        non-finite ``variation``.

    Notes
    -----
    The paper's $HCHDG and its stated compass accuracy and resolution (Hamid et al. 2009, in their
    description of the GPS module). The sentence writes 0.1 degree; the value in it is a whole
    number of ``resolution`` steps.

    Examples
    --------
    >>> Compass(noise=0.0, accuracy=0.0).reading(np.pi / 2)   # facing north; magnetic 0.3 rounds to 0
    '$HCHDG,0.0,0.0,E,0.3,W*53'
    >>> c = Compass(noise=0.0, rng=4)                          # a +-2 degree compass: bias within +-1.5
    >>> round(float(np.degrees(c.bias)), 2), c.reading(np.pi / 2)
    (1.33, '$HCHDG,2.0,0.0,E,0.3,W*51')
    """

    def __init__(self, *, noise: float = math.radians(0.5), accuracy: float = math.radians(2.0),
                 resolution: float = math.radians(1.0), variation: float = math.radians(-0.3),
                 rng: Any = None) -> None:
        self.noise = as_positive(noise, "noise", allow_zero=True)
        self.accuracy = as_positive(accuracy, "accuracy", allow_zero=True)
        self.resolution = as_positive(resolution, "resolution")
        self.variation = as_finite_scalar(variation, "variation")
        self.rng = as_rng(rng)
        self.bound = max(0.0, self.accuracy - self.resolution / 2)     # bias + noise, before rounding
        self.bias = float(self.rng.uniform(-self.bound, self.bound)) if self.bound else 0.0

    def reading(self, heading: float) -> str:
        """Return the ``$HCHDG`` sentence for a true field heading (rad CCW from east).

        Notes
        -----
        HDG layout, NMEA 0183 v4.11 Sec. 6.3; the compass sentence of Hamid et al. (2009): magnetic
        heading + bias + noise (together within ``accuracy - resolution / 2``), rounded to the resolution.
        """
        noise_deg, variation_deg = math.degrees(self.noise), math.degrees(self.variation)   # NMEA's unit
        error = math.degrees(self.bias) + (self.rng.normal(0.0, noise_deg) if noise_deg else 0.0)
        bound = math.degrees(self.bound)
        true_deg = heading_to_compass(heading) + min(max(error, -bound), bound)
        step = math.degrees(self.resolution)
        magnetic = (round((true_deg - variation_deg) / step) * step) % 360.0
        return hdg_sentence(magnetic, deviation_deg=0.0, variation_deg=variation_deg)
