"""Local equirectangular projection of WGS84 longitude/latitude to planar metres.

``x = N(φ0) cos φ0 (λ − λ0)`` east and ``y = M(φ0) (φ − φ0)`` north, where ``M`` and ``N`` are the
WGS84 meridional and prime-vertical radii of curvature at the centre latitude ``φ0``. Scale is
exact at the centre; elsewhere the east–west scale is off by ``cos φ / cos φ0 − 1 ≈ −tan φ0 Δφ``
and the north–south scale by ``M(φ)/M(φ0) − 1 ≈ 3e² sin φ0 cos φ0 Δφ`` (``e² ≈ 0.0067``).
A map 2 km tall (``|Δφ| ≤ 1 km / 6371 km``) at latitude 38° thus has distances right to 1.3e-4
(13 cm per km); :meth:`LocalProjection.max_scale_error` gives the exact figure for given points.
That is far below the 10 m node spacing of the road graphs, so no pyproj is needed for
city-sized extracts; for maps tens of kilometres across, use a proper transverse Mercator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError

WGS84_A_M = 6378137.0
"""WGS84 semi-major axis (m)."""
WGS84_F = 1.0 / 298.257223563
"""WGS84 flattening."""
_E2 = WGS84_F * (2.0 - WGS84_F)
_MAX_LAT_RAD = math.radians(85.0)


def _radii_m(lat_rad: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Meridional ``M`` and prime-vertical ``N`` radii of curvature (m) at ``lat_rad``."""
    w2 = 1.0 - _E2 * np.sin(lat_rad) ** 2
    n = WGS84_A_M / np.sqrt(w2)
    return n * (1.0 - _E2) / w2, n


@dataclass(frozen=True)
class LocalProjection:
    """Equirectangular projection on the WGS84 ellipsoid about ``(lat0_rad, lon0_rad)``.

    Parameters
    ----------
    lat0_rad, lon0_rad
        The centre (radians); ``|lat0_rad|`` at most 85°, where the projection still makes sense.
    """

    lat0_rad: float
    lon0_rad: float

    def __post_init__(self) -> None:
        for name in ("lat0_rad", "lon0_rad"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise InvalidInputError(name, value, "must be a finite angle in radians")
            object.__setattr__(self, name, float(value))
        if abs(self.lat0_rad) > _MAX_LAT_RAD:
            raise InvalidInputError("lat0_rad", self.lat0_rad, "must be within ±85° (in radians)")
        if abs(self.lon0_rad) > math.pi:
            raise InvalidInputError("lon0_rad", self.lon0_rad, "must be within ±π")

    @classmethod
    def about(cls, lat_rad: ArrayLike, lon_rad: ArrayLike) -> LocalProjection:
        """The projection centred on the middle of the bounding box of the given points.

        Longitudes are not unwrapped: a map straddling the antimeridian is not supported.
        """
        lat = np.asarray(lat_rad, dtype=np.float64)
        lon = np.asarray(lon_rad, dtype=np.float64)
        if lat.size == 0 or lat.shape != lon.shape:
            raise InvalidInputError("lat_rad", lat_rad, "needs ≥ 1 point, same shape as lon_rad")
        return cls(
            float(0.5 * (lat.min() + lat.max())), float(0.5 * (lon.min() + lon.max()))
        )

    @property
    def _scales(self) -> tuple[float, float]:
        m0, n0 = _radii_m(np.array(self.lat0_rad))
        return float(n0) * math.cos(self.lat0_rad), float(m0)

    def forward(self, lat_rad: ArrayLike, lon_rad: ArrayLike) -> NDArray[np.float64]:
        """Planar ``(n, 2)`` coordinates (m, x east and y north) of the given points."""
        lat = np.asarray(lat_rad, dtype=np.float64).reshape(-1)
        lon = np.asarray(lon_rad, dtype=np.float64).reshape(-1)
        kx, ky = self._scales
        dlon = wrap_angle(lon - self.lon0_rad)
        return np.column_stack([kx * dlon, ky * (lat - self.lat0_rad)])

    def inverse(self, xy_m: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Latitudes and longitudes (radians) of planar ``(n, 2)`` points (m)."""
        xy = np.asarray(xy_m, dtype=np.float64).reshape(-1, 2)
        kx, ky = self._scales
        return self.lat0_rad + xy[:, 1] / ky, self.lon0_rad + xy[:, 0] / kx

    def max_scale_error(self, xy_m: ArrayLike) -> float:
        """Largest relative error of projected distances near the given planar points.

        The true local scale at latitude ``φ`` is ``N(φ) cos φ`` east–west and ``M(φ)``
        north–south; the projection uses the centre's values. A short segment's projected length
        is off by at most the larger of the two relative differences.
        """
        lat, _ = self.inverse(xy_m)
        if lat.size == 0:
            return 0.0
        m, n = _radii_m(lat)
        kx, ky = self._scales
        ew = np.abs(kx / (n * np.cos(lat)) - 1.0)
        ns = np.abs(ky / m - 1.0)
        return float(max(ew.max(), ns.max()))
