"""Local equirectangular projection: round trip, WGS84 scales, centring, wrapping, bad centres."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import LocalProjection
from tests.models.osm_data import EW_M, NS_M


def test_projection_round_trip_and_scale() -> None:
    """Forward then inverse is the identity, and degree lengths at 45°N match geodesy tables."""
    proj = LocalProjection(math.radians(45.0), math.radians(7.0))
    lat = np.radians([45.0, 45.0, 45.0009])
    lon = np.radians([7.0, 7.001, 7.0])
    xy = proj.forward(lat, lon)
    assert xy[1, 0] == pytest.approx(EW_M, rel=1e-4) and xy[2, 1] == pytest.approx(NS_M, rel=1e-4)
    back_lat, back_lon = proj.inverse(xy)
    np.testing.assert_allclose(back_lat, lat, rtol=0, atol=1e-15)
    np.testing.assert_allclose(back_lon, lon, rtol=0, atol=1e-15)
    # 1 km north of the centre the east-west scale is off by about tan(45°)·(1 km / 6371 km)
    assert proj.max_scale_error([[0.0, 1000.0]]) == pytest.approx(1000.0 / 6.37e6, rel=0.01)


def test_equator_scales_are_the_wgs84_radii() -> None:
    """At φ0 = 0 a radian east is a = 6 378 137 m and a radian north is a(1 − e²) = 6 335 439 m."""
    proj = LocalProjection(0.0, 0.0)
    xy = proj.forward([0.0, 1e-3], [1e-3, 0.0])
    np.testing.assert_allclose(xy, [[6378.137, 0.0], [0.0, 6335.439327]], rtol=1e-9, atol=1e-9)


def test_about_centres_on_the_bounding_box() -> None:
    """about() centres on the middle of the points' latitude and longitude ranges."""
    proj = LocalProjection.about([0.1, 0.3, 0.2], [-0.5, 0.1, 0.0])
    assert (proj.lat0_rad, proj.lon0_rad) == pytest.approx((0.2, -0.2))
    np.testing.assert_allclose(proj.forward(0.2, -0.2), [[0.0, 0.0]], atol=1e-9)


def test_forward_wraps_longitude_across_the_antimeridian() -> None:
    """A point 0.002 rad east of a centre at π − 0.001 lies at +0.002 a, not 2π a to the west."""
    proj = LocalProjection(0.0, math.pi - 0.001)
    xy = proj.forward(0.0, -math.pi + 0.001)
    assert xy[0, 0] == pytest.approx(0.002 * 6378137.0, rel=1e-9)


def test_max_scale_error_vanishes_at_the_centre() -> None:
    """The scale error is 0 at the centre and for no points at all."""
    proj = LocalProjection(math.radians(38.0), 0.1)
    assert proj.max_scale_error([[0.0, 0.0]]) == pytest.approx(0.0, abs=1e-15)
    assert proj.max_scale_error(np.empty((0, 2))) == 0.0


@pytest.mark.parametrize(("lat0", "lon0", "field"), [
    (math.radians(86.0), 0.0, "lat0_rad"),
    (math.nan, 0.0, "lat0_rad"),
    (0.0, 3.2, "lon0_rad"),
    (0.0, "0.1", "lon0_rad"),
])
def test_bad_centres_are_named(lat0: object, lon0: object, field: str) -> None:
    """Centres beyond ±85° or ±π, not finite or not numbers are refused by name."""
    with pytest.raises(InvalidInputError) as err:
        LocalProjection(lat0, lon0)  # type: ignore[arg-type]
    assert err.value.field == field


def test_about_needs_matching_points() -> None:
    """about() refuses no points and latitudes and longitudes of different shapes."""
    for lat, lon in (([], []), ([0.1, 0.2], [0.1])):
        with pytest.raises(InvalidInputError, match="lat_rad"):
            LocalProjection.about(lat, lon)
