"""Geodesy against geographiclib (Karney's geodesics, the reference implementation)."""
from __future__ import annotations

import numpy as np
import pytest

geographiclib = pytest.importorskip("geographiclib.geodesic")
GEOD = geographiclib.Geodesic.WGS84

from robokit.outdoor.geodesy import (EARTH_MEAN_RADIUS, GeodesyError, LocalTangentPlane, distance_bearing,
                                     haversine_distance, initial_bearing, meridian_radius, osculating_radius,
                                     prime_vertical_radius, vincenty_inverse)


def _pairs(rng, n, max_distance, max_lat=89.0):
    """Random point pairs at known geodesic distance (geographiclib's direct problem)."""
    out = []
    for _ in range(n):
        lat1, lon1 = rng.uniform(-max_lat, max_lat), rng.uniform(-180, 180)
        azi, dist = rng.uniform(0, 360), max_distance * rng.uniform(0.001, 1.0)
        r = GEOD.Direct(lat1, lon1, azi, dist)
        inv = GEOD.Inverse(lat1, lon1, r["lat2"], r["lon2"])
        out.append((lat1, lon1, r["lat2"], r["lon2"], inv["s12"], inv["azi1"] % 360, inv["azi2"] % 360))
    return np.array(out)


def _angle_diff_deg(a, b):
    return np.abs((a - b + 180) % 360 - 180)


@pytest.fixture(scope="module")
def short_pairs():
    return _pairs(np.random.default_rng(11), 400, 10_000.0)


def test_sphere_within_half_percent_up_to_10km(short_pairs):
    lat1, lon1, lat2, lon2, s = np.radians(short_pairs[:, :4]).T.tolist() + [short_pairs[:, 4]]
    d, _ = distance_bearing(lat1, lon1, lat2, lon2)
    rel = np.abs(d / s - 1)
    assert rel.max() < 0.005
    # the osculating sphere's documented bound: (N - M) / (2 sqrt(M N)) <= 0.34 %
    assert rel.max() < 0.0034


def test_mean_radius_sphere_error_is_as_documented(short_pairs):
    lat1, lon1, lat2, lon2 = np.radians(short_pairs[:, :4]).T
    d, _ = distance_bearing(lat1, lon1, lat2, lon2, model="mean_sphere")
    rel = np.abs(d / short_pairs[:, 4] - 1)
    assert 0.003 < rel.max() < 0.0057  # worst near the equator going north-south


def test_sphere_bearing_close_to_ellipsoid(short_pairs):
    lat1, lon1, lat2, lon2 = np.radians(short_pairs[:, :4]).T
    brg = np.degrees(initial_bearing(lat1, lon1, lat2, lon2))
    assert _angle_diff_deg(brg, short_pairs[:, 5]).max() < 0.2


def test_vincenty_within_1mm_short(short_pairs):
    lat1, lon1, lat2, lon2 = np.radians(short_pairs[:, :4]).T
    s, az1, az2 = vincenty_inverse(lat1, lon1, lat2, lon2)
    assert np.abs(s - short_pairs[:, 4]).max() < 1e-3
    assert _angle_diff_deg(np.degrees(az1), short_pairs[:, 5]).max() < 1e-5
    assert _angle_diff_deg(np.degrees(az2), short_pairs[:, 6]).max() < 1e-5


def test_vincenty_within_1mm_global():
    pairs = _pairs(np.random.default_rng(12), 300, 19_000_000.0)
    lat1, lon1, lat2, lon2 = np.radians(pairs[:, :4]).T
    s, az1, _ = vincenty_inverse(lat1, lon1, lat2, lon2)
    assert np.abs(s - pairs[:, 4]).max() < 1e-3


def test_vincenty_special_cases():
    assert vincenty_inverse(0.3, 0.2, 0.3, 0.2)[0] == 0.0
    s, az1, _ = vincenty_inverse(0.0, 0.0, 0.0, np.radians(1.0))  # along the equator
    assert s == pytest.approx(GEOD.Inverse(0, 0, 0, 1)["s12"], abs=1e-3) and az1 == pytest.approx(np.pi / 2)
    s, az1, _ = vincenty_inverse(0.0, 0.0, np.pi / 2, 0.0)  # to the pole
    assert s == pytest.approx(GEOD.Inverse(0, 0, 90, 0)["s12"], abs=1e-3) and az1 == pytest.approx(0.0)
    with pytest.raises(GeodesyError, match="converge"):
        vincenty_inverse(0.0, 0.0, np.radians(0.5), np.radians(179.7))


def test_tangent_plane_against_geodesic():
    rng = np.random.default_rng(13)
    for max_d, tol in [(100.0, 5e-4), (1000.0, 0.05)]:
        pairs = _pairs(rng, 200, max_d, max_lat=60.0)
        for lat1, lon1, lat2, lon2, s, azi, _ in pairs:
            plane = LocalTangentPlane(*np.radians([lat1, lon1]))
            e, n = plane.to_local(*np.radians([lat2, lon2]))
            assert np.hypot(e, n) == pytest.approx(s, abs=tol)
            assert _angle_diff_deg(np.degrees(np.arctan2(e, n)), azi) < 0.05


def test_tangent_plane_round_trip_and_shapes():
    plane = LocalTangentPlane(np.radians(2.86), np.radians(101.5))
    en = np.random.default_rng(0).uniform(-100, 100, (50, 2))
    lat, lon = plane.to_geodetic(en)
    assert lat.shape == (50,)
    np.testing.assert_allclose(plane.to_local(lat, lon), en, atol=1e-9)
    assert plane.to_local(plane.lat0, plane.lon0).tolist() == [0.0, 0.0]
    # across the antimeridian
    p2 = LocalTangentPlane(0.0, np.pi - 1e-7)
    e, n = p2.to_local(0.0, -np.pi + 1e-7)
    assert e == pytest.approx(2e-7 * WGS84_A_, rel=1e-6)


WGS84_A_ = 6378137.0


def test_radii():
    assert meridian_radius(0.0) == pytest.approx(6335439.327, abs=1e-3)
    assert prime_vertical_radius(0.0) == pytest.approx(6378137.0)
    assert meridian_radius(np.pi / 2) == pytest.approx(prime_vertical_radius(np.pi / 2))
    assert osculating_radius(0.0) == pytest.approx(np.sqrt(6335439.327 * 6378137.0), abs=1e-3)
    assert EARTH_MEAN_RADIUS == pytest.approx(6371008.771, abs=1e-3)


def test_broadcasting_and_scalars():
    assert isinstance(haversine_distance(0.1, 0.2, 0.1, 0.3), float)
    d = haversine_distance(0.1, 0.2, np.array([0.1, 0.2]), 0.3)
    assert d.shape == (2,)
    assert initial_bearing(0.0, 0.0, 0.0, -0.1) == pytest.approx(1.5 * np.pi)


@pytest.mark.parametrize("call, words", [
    (lambda: haversine_distance(48.1, 11.5, 48.2, 11.6), "degrees"),
    (lambda: haversine_distance(0.1, 0.2, 0.1, float("nan")), "lon2"),
    (lambda: haversine_distance(0.1, 0.2, 0.1, 0.3, radius=-1), "radius"),
    (lambda: initial_bearing("north", 0, 0, 0), "lat1"),
    (lambda: distance_bearing(0, 0, 0, 0.1, model="flat"), "model"),
    (lambda: LocalTangentPlane(np.pi / 2, 0.0), "lat0"),
    (lambda: LocalTangentPlane(0.1, 0.2).to_geodetic([1.0, 2.0, 3.0]), "east_north"),
    (lambda: vincenty_inverse(0, 0, 0, 0.1, max_iter=0), "max_iter"),
])
def test_bad_input(call, words):
    with pytest.raises((ValueError, TypeError), match=words):
        call()
