"""GeoJSON features in longitude/latitude order that the geojson library finds valid."""

from __future__ import annotations

import json

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.export import geojson as gj


def test_collection_is_valid_geojson_with_lon_lat_order() -> None:
    geojson = pytest.importorskip("geojson", reason="the geojson library (the test extra)")
    fc = gj.collection([
        gj.point([[21.88, -102.29]], {"kind": "depot"}),
        gj.line([[21.88, -102.29], [21.89, -102.28]], {"kind": "route", "route": 0}),
        gj.lines([[[21.0, -102.0], [21.1, -102.1]], [[21.2, -102.2], [21.3, -102.3]]],
                 {"kind": "road"}),
    ])
    parsed = geojson.loads(json.dumps(fc))
    assert parsed.is_valid, parsed.errors()
    assert fc["features"][0]["geometry"]["coordinates"] == [-102.29, 21.88]
    assert fc["features"][1]["properties"] == {"kind": "route", "route": 0}


@pytest.mark.parametrize(("build", "field"), [
    (lambda: gj.line([[1.0, 2.0]], {}), "latlon"),
    (lambda: gj.lines([[[1.0, 2.0]]], {}), "segments"),
    (lambda: gj.point([[float("nan"), 2.0]], {}), "latlon"),
])
def test_degenerate_geometry_is_refused(build: object, field: str) -> None:
    with pytest.raises(InvalidInputError, match=field):
        build()  # type: ignore[operator]
