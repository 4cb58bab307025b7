"""The geographic frame of a plan: planar metres (x east, y north) to WGS84 latitude and
longitude, and the altitude the vehicles fly at.

Maps read from OpenStreetMap keep their projection
(:class:`~searchtrack.models.projection.LocalProjection`); a problem in a local frame (a
synthetic grid, an OPTW instance, the radio scenario) is placed with an origin, the
latitude and longitude of its ``(0, 0)`` (on the command line ``--origin LAT,LON``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.projection import LocalProjection


@dataclass(frozen=True)
class GeoFrame:
    """Planar metres to degrees, and the flight altitude.

    Parameters
    ----------
    projection
        The planar frame's projection (its centre is the point ``(0, 0)``).
    altitude_m
        Flight altitude above the home position (m), > 0.
    unit_m
        Metres per unit of the planar coordinates (1 for maps; OPTW instances' coordinates have
        no unit and may be scaled).
    """

    projection: LocalProjection
    altitude_m: float
    unit_m: float = 1.0

    def __post_init__(self) -> None:
        if not isinstance(self.projection, LocalProjection):
            raise InvalidInputError("projection", self.projection, "must be a LocalProjection")
        for name in ("altitude_m", "unit_m"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                    not (math.isfinite(value) and value > 0):
                raise InvalidInputError(name, value, "must be a finite number > 0")
            object.__setattr__(self, name, float(value))

    @classmethod
    def at(cls, lat_deg: float, lon_deg: float, altitude_m: float,
           unit_m: float = 1.0) -> GeoFrame:
        """The frame whose ``(0, 0)`` lies at ``(lat_deg, lon_deg)``."""
        for name, value, most in (("lat_deg", lat_deg, 85.0), ("lon_deg", lon_deg, 180.0)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                    not (math.isfinite(value) and abs(value) <= most):
                raise InvalidInputError(name, value, f"must be a finite angle within ±{most:g}°")
        return cls(LocalProjection(math.radians(lat_deg), math.radians(lon_deg)), altitude_m,
                   unit_m)

    def degrees(self, xy: ArrayLike) -> NDArray[np.float64]:
        """``(n, 2)`` latitude and longitude (degrees) of planar ``(n, 2)`` points."""
        points = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        if not np.all(np.isfinite(points)):
            raise InvalidInputError("xy", xy, "must be finite planar coordinates")
        lat, lon = self.projection.inverse(points * self.unit_m)
        lon = (lon + math.pi) % (2.0 * math.pi) - math.pi
        return np.column_stack([np.degrees(lat), np.degrees(lon)])
