"""GeoJSON (RFC 7946) that QGIS and web maps open: a ``FeatureCollection`` of points, line
strings and multi-line strings in WGS84 longitude and latitude, each feature with its
properties (``kind`` says what it is: road, route, uav, target, estimate, ...)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.export.autopilot import DEGREE_DECIMALS


def _positions(latlon: ArrayLike) -> list[list[float]]:
    """``[[lon, lat], ...]`` of ``(n, 2)`` latitude/longitude degrees, rounded."""
    points = np.asarray(latlon, dtype=np.float64).reshape(-1, 2)
    if not np.all(np.isfinite(points)):
        raise InvalidInputError("latlon", latlon, "must be finite degrees")
    return np.round(points[:, ::-1], DEGREE_DECIMALS).tolist()  # type: ignore[no-any-return]


def point(latlon: ArrayLike, properties: Mapping[str, Any]) -> dict[str, Any]:
    """A ``Point`` feature at one latitude/longitude."""
    return _feature({"type": "Point", "coordinates": _positions(latlon)[0]}, properties)


def line(latlon: ArrayLike, properties: Mapping[str, Any]) -> dict[str, Any]:
    """A ``LineString`` feature through ``(n ≥ 2, 2)`` latitudes/longitudes."""
    positions = _positions(latlon)
    if len(positions) < 2:
        raise InvalidInputError("latlon", latlon, "a line needs two or more points")
    return _feature({"type": "LineString", "coordinates": positions}, properties)


def path(latlon: ArrayLike, properties: Mapping[str, Any]) -> dict[str, Any]:
    """A ``LineString`` through two or more latitudes/longitudes, a ``Point`` for one (a path
    that has not moved yet)."""
    positions = _positions(latlon)
    if len(positions) == 1:
        return _feature({"type": "Point", "coordinates": positions[0]}, properties)
    return line(latlon, properties)


def lines(segments: Sequence[ArrayLike], properties: Mapping[str, Any]) -> dict[str, Any]:
    """A ``MultiLineString`` feature of several ``(n ≥ 2, 2)`` latitude/longitude lines."""
    parts = [_positions(s) for s in segments]
    if any(len(p) < 2 for p in parts):
        raise InvalidInputError("segments", segments, "each line needs two or more points")
    return _feature({"type": "MultiLineString", "coordinates": parts}, properties)


def _feature(geometry: dict[str, Any], properties: Mapping[str, Any]) -> dict[str, Any]:
    return {"type": "Feature", "geometry": geometry, "properties": dict(properties)}


def collection(features: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The ``FeatureCollection`` of ``features``."""
    return {"type": "FeatureCollection", "features": [dict(f) for f in features]}
