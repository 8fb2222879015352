"""Distances, bearings and a local east-north plane on the Earth, spherical and WGS84.

Hamid et al. (2009) steer their truck by the bearing and distance from the GPS fix
to the next waypoint. Three models, from simplest to exact:

* **sphere** - haversine distance and initial bearing on a sphere of radius ``R`` (Sinnott 1984). With the IUGG mean radius the error against the
  ellipsoid is up to about 0.56 % (north-south near the equator); with the *osculating* radius
  ``sqrt(M N)`` at the mean latitude (the default here) it is below 0.34 % in any direction.
* **tangent plane** - east/north metres around a reference point from the meridian (``M``) and
  prime-vertical (``N``) radii of curvature of WGS84 (Torge & Mueller 2012, Sec. 4.2); errors grow with the square of the distance from the reference (below 0.5 mm at
  100 m, 5 cm at 1 km, up to latitude 60 degrees) - ample for a 100 m field.
* **wgs84** - Vincenty's inverse formula on the WGS84 ellipsoid (Vincenty 1975, Eqs. 13-21), accurate to
  well below a millimetre except for nearly antipodal points, where it may not converge.

All angles are radians (latitude north positive, longitude east positive, bearings clockwise from
true north in [0, 2 pi)); distances are metres. Functions broadcast over numpy arrays.

References
----------
.. [1] M. H. A. Hamid, A. H. Adom, N. A. Rahim and M. H. F. Rahiman, "Navigation of mobile robot
   using Global Positioning System (GPS) and obstacle avoidance system with commanded loop daisy
   chaining application method", 5th International Colloquium on Signal Processing & Its
   Applications (CSPA), 2009.
.. [2] R. W. Sinnott, "Virtues of the haversine", *Sky & Telescope* 68(2), 1984, p. 159.
.. [3] W. Torge and J. Mueller, *Geodesy*, 4th ed., de Gruyter, 2012.
.. [4] T. Vincenty, "Direct and inverse solutions of geodesics on the ellipsoid with application
   of nested equations", *Survey Review* 23(176), 1975, pp. 88-93.
.. [5] J. P. Snyder, *Map Projections - A Working Manual*, USGS Professional Paper 1395, 1987.
.. [6] H. Moritz, "Geodetic Reference System 1980", *Bulletin Geodesique* 54, 1980.
.. [7] National Imagery and Mapping Agency, *Department of Defense World Geodetic System 1984*,
   TR8350.2, 3rd ed., 2000.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..geometry import wrap_angle
from ..validation import array_ndim, as_array, as_choice, as_int, as_positive

__all__ = [
    "WGS84_A", "WGS84_F", "WGS84_B", "WGS84_E2", "EARTH_MEAN_RADIUS", "GeodesyError",
    "meridian_radius", "prime_vertical_radius", "osculating_radius",
    "haversine_distance", "initial_bearing", "haversine_distance_bearing", "vincenty_inverse", "distance_bearing", "LocalTangentPlane",
]

#: WGS84 semi-major axis (m) and flattening (NIMA TR8350.2, 3rd ed., Table 3.1).
WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563
#: Semi-minor axis (m) and first eccentricity squared.
WGS84_B = WGS84_A * (1.0 - WGS84_F)
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)
#: IUGG mean Earth radius R1 = (2a + b) / 3 (Moritz, "Geodetic Reference System 1980").
EARTH_MEAN_RADIUS = (2.0 * WGS84_A + WGS84_B) / 3.0


class GeodesyError(ValueError):
    """A geodesic computation failed (e.g. Vincenty's iteration did not converge)."""


def _latlon(lat: Any, lon: Any, suffix: str = "") -> tuple[np.ndarray, np.ndarray]:
    la = as_array(lat, "lat" + suffix)
    lo = as_array(lon, "lon" + suffix)
    if np.any(np.abs(la) > np.pi / 2 + 1e-12):
        bad = la.flat[int(np.argmax(np.abs(la)))]
        raise ValueError(f"lat{suffix}: expected radians in [-pi/2, pi/2] (did you pass degrees?), got {bad:g}")
    return la, lo


def _two_points(lat1: Any, lon1: Any, lat2: Any, lon2: Any) -> list[np.ndarray]:
    p1, l1 = _latlon(lat1, lon1, "1")
    p2, l2 = _latlon(lat2, lon2, "2")
    try:
        return np.broadcast_arrays(p1, l1, p2, l2)
    except ValueError:
        raise ValueError(f"lat1, lon1, lat2, lon2: expected shapes that broadcast together, got "
                         f"{', '.join(str(x.shape) for x in (p1, l1, p2, l2))}") from None


def _out(x: np.ndarray) -> Any:
    return float(x) if np.ndim(x) == 0 else x


def meridian_radius(lat: Any) -> Any:
    """Radius of curvature of the WGS84 meridian, ``M = a (1 - e^2) / (1 - e^2 sin^2 lat)^(3/2)``.

    Parameters
    ----------
    lat : float or array_like
        Geodetic latitude in radians.

    Returns
    -------
    float or numpy.ndarray
        Metres.

    Notes
    -----
    Torge & Mueller, *Geodesy* (2012), Sec. 4.2, Eq. (4.26).
    """
    la = _latlon(lat, 0.0)[0]
    return _out(WGS84_A * (1 - WGS84_E2) / (1 - WGS84_E2 * np.sin(la) ** 2) ** 1.5)


def prime_vertical_radius(lat: Any) -> Any:
    """Radius of curvature in the prime vertical, ``N = a / sqrt(1 - e^2 sin^2 lat)`` (metres).

    Notes
    -----
    Torge & Mueller, *Geodesy* (2012), Sec. 4.2, Eq. (4.27). ``lat`` in radians.
    """
    la = _latlon(lat, 0.0)[0]
    return _out(WGS84_A / np.sqrt(1 - WGS84_E2 * np.sin(la) ** 2))


def osculating_radius(lat: Any) -> Any:
    """Gaussian mean radius of curvature ``sqrt(M N)`` at a latitude (metres).

    A sphere of this radius touches the ellipsoid to second order at that latitude, so short
    haversine distances on it are within ``(N - M) / (2 sqrt(M N))`` (<= 0.34 %) of the ellipsoid
    in any direction. Torge & Mueller (2012), Sec. 4.2, Eq. (4.32).
    """
    return _out(np.sqrt(np.asarray(meridian_radius(lat)) * np.asarray(prime_vertical_radius(lat))))


def haversine_distance(lat1: Any, lon1: Any, lat2: Any, lon2: Any, radius: float = EARTH_MEAN_RADIUS) -> Any:
    """Great-circle distance on a sphere by the haversine formula.

    Parameters
    ----------
    lat1, lon1, lat2, lon2 : float or array_like
        Radians; broadcast together.
    radius : float, default EARTH_MEAN_RADIUS
        Sphere radius in metres.

    Returns
    -------
    float or numpy.ndarray
        ``d = 2 R asin(sqrt(sin^2(dlat/2) + cos lat1 cos lat2 sin^2(dlon/2)))`` in metres.

    Raises
    ------
    ValueError
        Non-finite input, latitude outside [-pi/2, pi/2] or a non-positive radius.

    Notes
    -----
    Sinnott (1984); well conditioned for short distances, unlike the spherical law of cosines.
    """
    p1, l1, p2, l2 = _two_points(lat1, lon1, lat2, lon2)
    r = as_positive(radius, "radius")
    h = np.sin((p2 - p1) / 2) ** 2 + np.cos(p1) * np.cos(p2) * np.sin((l2 - l1) / 2) ** 2
    return _out(2 * r * np.arcsin(np.sqrt(np.clip(h, 0.0, 1.0))))


def initial_bearing(lat1: Any, lon1: Any, lat2: Any, lon2: Any) -> Any:
    """Initial great-circle bearing from point 1 to point 2, clockwise from north in [0, 2 pi).

    Returns
    -------
    float or numpy.ndarray
        ``atan2(sin dlon cos lat2, cos lat1 sin lat2 - sin lat1 cos lat2 cos dlon)`` in radians
        (0 for coincident points).

    Raises
    ------
    ValueError
        Non-finite input or latitude outside [-pi/2, pi/2].

    Notes
    -----
    Spherical trigonometry (e.g. Snyder 1987, Eq. 5-4b); the "bearing" field of $GPRMB in Hamid
    et al. (2009).
    """
    p1, l1, p2, l2 = _two_points(lat1, lon1, lat2, lon2)
    dl = l2 - l1
    y = np.sin(dl) * np.cos(p2)
    x = np.cos(p1) * np.sin(p2) - np.sin(p1) * np.cos(p2) * np.cos(dl)
    return _out(np.mod(np.arctan2(y, x), 2 * np.pi))


def haversine_distance_bearing(lat1: float, lon1: float, lat2: float, lon2: float,
                               radius: float = EARTH_MEAN_RADIUS) -> np.ndarray:
    """``[distance_m, bearing_rad]`` from point 1 to point 2 on a sphere (scalar points).

    Parameters
    ----------
    lat1, lon1, lat2, lon2 : float
        Radians.
    radius : float, default EARTH_MEAN_RADIUS

    Returns
    -------
    numpy.ndarray, shape (2,)
        :func:`haversine_distance` and :func:`initial_bearing` together (what $GPRMB reports as
        range and bearing to the destination, Hamid et al. 2009).

    Raises
    ------
    ValueError
        Non-scalar, non-finite or out-of-range input.

    Notes
    -----
    Haversine formula (Sinnott 1984) and the initial great-circle bearing (Snyder 1987, Eq. 5-4b).

    Examples
    --------
    >>> lat1, lon1, lat2, lon2 = np.radians([6.4590, 100.3505, 6.4594, 100.3509])
    >>> np.round(haversine_distance_bearing(lat1, lon1, lat2, lon2), 4).tolist()   # 62.7 m to the north-east
    [62.7021, 0.7822]
    """
    for name, value in (("lat1", lat1), ("lon1", lon1), ("lat2", lat2), ("lon2", lon2)):
        if array_ndim(value, name) != 0:
            raise ValueError(f"{name}: expected a scalar in radians, got shape {np.shape(value)}")
    return np.array([haversine_distance(lat1, lon1, lat2, lon2, radius), initial_bearing(lat1, lon1, lat2, lon2)])


def vincenty_inverse(lat1: Any, lon1: Any, lat2: Any, lon2: Any, *, tol: float = 1e-12,
                     max_iter: int = 200) -> tuple[Any, Any, Any]:
    """Geodesic distance and azimuths between two points on the WGS84 ellipsoid (Vincenty 1975).

    Parameters
    ----------
    lat1, lon1, lat2, lon2 : float or array_like
        Geodetic coordinates in radians; broadcast together.
    tol : float, default 1e-12
        Convergence threshold on the auxiliary longitude ``lambda`` (radians; 1e-12 is ~6 um).
    max_iter : int, default 200
        Iteration limit.

    Returns
    -------
    distance : float or numpy.ndarray
        Metres along the geodesic.
    azimuth1, azimuth2 : float or numpy.ndarray
        Forward azimuths at the start and the end, clockwise from north in [0, 2 pi).

    Raises
    ------
    ValueError
        Bad input (see :func:`haversine_distance`).
    GeodesyError
        If the iteration does not converge (nearly antipodal points).

    Notes
    -----
    Vincenty (1975), Eqs. (13)-(21) with the auxiliary sphere of reduced latitudes
    ``tan U = (1 - f) tan lat``; written for this course from the paper's equations.

    Examples
    --------
    >>> s12, az1, az2 = vincenty_inverse(*np.radians([6.4590, 100.3505, 6.4594, 100.3509]))
    >>> round(float(s12), 4), round(float(az1), 4)
    (62.5665, 0.7855)
    """
    p1, l1, p2, l2 = _two_points(lat1, lon1, lat2, lon2)
    as_positive(tol, "tol")
    n_iter = as_int(max_iter, "max_iter", minimum=1)
    a, b, f = WGS84_A, WGS84_B, WGS84_F
    L = np.asarray(wrap_angle(l2 - l1), dtype=float)
    U1, U2 = np.arctan((1 - f) * np.tan(p1)), np.arctan((1 - f) * np.tan(p2))
    sU1, cU1, sU2, cU2 = np.sin(U1), np.cos(U1), np.sin(U2), np.cos(U2)
    lam = L.copy()
    done = np.zeros(L.shape, dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        for _ in range(n_iter):
            sl, cl = np.sin(lam), np.cos(lam)
            s_sig = np.hypot(cU2 * sl, cU1 * sU2 - sU1 * cU2 * cl)
            c_sig = sU1 * sU2 + cU1 * cU2 * cl
            sig = np.arctan2(s_sig, c_sig)
            s_alpha = np.where(s_sig > 0, cU1 * cU2 * sl / s_sig, 0.0)
            c2_alpha = 1 - s_alpha ** 2
            c2sm = np.where(c2_alpha > 0, c_sig - 2 * sU1 * sU2 / c2_alpha, 0.0)  # equatorial line: 0
            C = f / 16 * c2_alpha * (4 + f * (4 - 3 * c2_alpha))
            new = L + (1 - C) * f * s_alpha * (sig + C * s_sig * (c2sm + C * c_sig * (-1 + 2 * c2sm ** 2)))
            done = np.abs(new - lam) <= tol
            lam = new
            if np.all(done):
                break
    if not np.all(done) or not np.all(np.isfinite(lam)):
        where = "" if L.ndim == 0 else " at index " + ", ".join(str(tuple(i)) for i in np.argwhere(~done)[:3].tolist())
        raise GeodesyError(f"lat1, lon1, lat2, lon2: expected points that are not nearly antipodal, got no convergence "
                           f"of Vincenty's iteration within {n_iter} iterations{where}")
    u2 = c2_alpha * (a * a - b * b) / (b * b)
    A = 1 + u2 / 16384 * (4096 + u2 * (-768 + u2 * (320 - 175 * u2)))
    B = u2 / 1024 * (256 + u2 * (-128 + u2 * (74 - 47 * u2)))
    d_sig = B * s_sig * (c2sm + B / 4 * (c_sig * (-1 + 2 * c2sm ** 2)
                                         - B / 6 * c2sm * (-3 + 4 * s_sig ** 2) * (-3 + 4 * c2sm ** 2)))
    s = b * A * (sig - d_sig)
    sl, cl = np.sin(lam), np.cos(lam)
    az1 = np.mod(np.arctan2(cU2 * sl, cU1 * sU2 - sU1 * cU2 * cl), 2 * np.pi)
    az2 = np.mod(np.arctan2(cU1 * sl, -sU1 * cU2 + cU1 * sU2 * cl), 2 * np.pi)
    return _out(s), _out(az1), _out(az2)


def distance_bearing(lat1: Any, lon1: Any, lat2: Any, lon2: Any, model: str = "sphere") -> tuple[Any, Any]:
    """Distance (m) and initial bearing (rad) from point 1 to point 2 under a chosen Earth model.

    Parameters
    ----------
    lat1, lon1, lat2, lon2 : float or array_like
        Radians.
    model : {"sphere", "mean_sphere", "wgs84"}, default "sphere"
        ``"sphere"``: haversine on the osculating sphere at the mean latitude (error < 0.34 %);
        ``"mean_sphere"``: haversine with the IUGG mean radius (error < 0.57 %);
        ``"wgs84"``: Vincenty's ellipsoidal inverse (error << 1 mm).

    Returns
    -------
    distance, bearing : float or numpy.ndarray

    Raises
    ------
    ValueError
        Unknown model or bad coordinates.

    Notes
    -----
    What a GPS receiver reports in $GPRMB (range, bearing to destination), Hamid et al.
    (2009); formulas as in :func:`haversine_distance`, :func:`vincenty_inverse`.

    Examples
    --------
    >>> lat1, lon1, lat2, lon2 = np.radians([6.4590, 100.3505, 6.4594, 100.3509])
    >>> for model in ("sphere", "wgs84"):
    ...     d, b = distance_bearing(lat1, lon1, lat2, lon2, model=model)
    ...     print(model, round(float(d), 3), round(float(b), 4))
    sphere 62.567 0.7822
    wgs84 62.567 0.7855
    """
    as_choice(model, "model", ("sphere", "mean_sphere", "wgs84"))
    if model == "wgs84":
        s, az1, _ = vincenty_inverse(lat1, lon1, lat2, lon2)
        return s, az1
    if model == "sphere":
        p1, _, p2, _ = _two_points(lat1, lon1, lat2, lon2)
        radius = np.asarray(osculating_radius((p1 + p2) / 2))
        d = np.asarray(haversine_distance(lat1, lon1, lat2, lon2, radius=1.0)) * radius
        return _out(d), initial_bearing(lat1, lon1, lat2, lon2)
    return haversine_distance(lat1, lon1, lat2, lon2), initial_bearing(lat1, lon1, lat2, lon2)


class LocalTangentPlane:
    """East-north metres around a reference point, from WGS84 radii of curvature.

    ``east = (lon - lon0) N(lat0) cos(lat0)`` and ``north = (lat - lat0) M(lat0)`` - the local
    flat-Earth approximation used to drive a robot on a field of a few hundred metres.

    Parameters
    ----------
    lat0, lon0 : float
        Reference (origin) in radians.

    Raises
    ------
    ValueError
        Latitude outside (-pi/2, pi/2) (the east axis is undefined at the poles) or non-finite.

    Notes
    -----
    Radii from Torge & Mueller (2012), Sec. 4.2. For ``|lat0| <= 60`` degrees, distances from the
    reference in this plane agree with the WGS84 geodesic to better than 0.5 mm at 100 m, 5 cm at
    1 km and 4.5 m at 10 km (the error grows with the square of the distance; measured against
    geographiclib in tests/test_outdoor_geodesy.py); the inverse is exact by construction.

    Examples
    --------
    >>> plane = LocalTangentPlane(*np.radians([6.4590, 100.3505]))
    >>> np.round(plane.to_local(*np.radians([6.4594, 100.3509])), 3).tolist()   # east, north (m)
    [44.247, 44.235]
    >>> np.round(np.degrees(plane.to_geodetic([44.247, 44.235])), 6).tolist()
    [6.4594, 100.3509]
    """

    def __init__(self, lat0: float, lon0: float) -> None:
        la, lo = _latlon(lat0, lon0, "0")
        if la.ndim or lo.ndim:
            raise ValueError(f"lat0, lon0: expected scalars, got shapes {la.shape} and {lo.shape}")
        if abs(float(la)) >= np.pi / 2 - 1e-9:
            raise ValueError(f"lat0: expected a latitude strictly inside (-pi/2, pi/2), got {float(la):g}")
        self.lat0, self.lon0 = float(la), float(lo)
        self._kn = float(meridian_radius(self.lat0))
        self._ke = float(prime_vertical_radius(self.lat0)) * np.cos(self.lat0)

    def to_local(self, lat: Any, lon: Any) -> np.ndarray:
        """Return ``[..., 2]`` east-north metres for geodetic ``lat``, ``lon`` (radians).

        Notes
        -----
        ``east = dlon N(lat0) cos(lat0)``, ``north = dlat M(lat0)`` (Torge & Mueller 2012, Sec. 4.2).
        """
        la, lo = _latlon(lat, lon)
        dlon = wrap_angle(lo - self.lon0)
        return np.stack(np.broadcast_arrays((dlon * self._ke), (la - self.lat0) * self._kn), axis=-1)

    def to_geodetic(self, east_north: Any) -> tuple[Any, Any]:
        """Return ``(lat, lon)`` in radians for east-north metres of shape ``(2,)`` or ``(N, 2)``.

        Notes
        -----
        Exact inverse of :meth:`to_local` (Torge & Mueller 2012, Sec. 4.2 radii).
        """
        en = as_array(east_north, "east_north")
        if en.shape[-1:] != (2,):
            raise ValueError(f"east_north: expected shape (2,) or (N, 2), got shape {en.shape}")
        lat = self.lat0 + en[..., 1] / self._kn
        lon = wrap_angle(self.lon0 + en[..., 0] / self._ke)
        return _out(lat), _out(lon)

    def __repr__(self) -> str:
        return f"LocalTangentPlane(lat0={self.lat0:.9f}, lon0={self.lon0:.9f})"
