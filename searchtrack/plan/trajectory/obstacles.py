"""Obstacles the trajectory controllers must keep clear of: spheres and vertical cylinders.

A vertical cylinder is infinitely tall (a building or mast); its ``z`` centre is ignored. For a
planar vehicle (2-D positions) every obstacle acts as a vertical cylinder of its radius.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


@dataclass(frozen=True)
class Obstacles:
    """``k`` obstacles (read-only arrays).

    Parameters
    ----------
    centers_m
        ``(k, 3)`` centres (m); ``(k, 2)`` is accepted and padded with ``z = 0``.
    radii_m
        ``(k,)`` radii (m), > 0.
    cylinder
        ``(k,)`` flags: vertical cylinder (True) or sphere (False); default all cylinders.
    """

    centers_m: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    radii_m: FloatArray = field(default_factory=lambda: np.zeros(0))
    cylinder: NDArray[np.bool_] | None = None

    def __post_init__(self) -> None:
        raw = np.asarray(self.centers_m, dtype=float)
        if raw.ndim == 2 and raw.shape[1] == 2:
            raw = np.column_stack([raw, np.zeros(raw.shape[0])])
        if raw.size == 0:
            raw = raw.reshape(0, 3)
        centers = checks.finite_array("centers_m", raw, (None, 3))
        k = centers.shape[0]
        radii = checks.finite_array("radii_m", np.atleast_1d(np.asarray(self.radii_m, float))
                                     if k else np.zeros(0), (k,))
        if np.any(radii <= 0):
            raise InvalidInputError("radii_m", radii.tolist(), "radii must be > 0 (m)")
        flags = np.ones(k, dtype=bool) if self.cylinder is None else np.array(self.cylinder)
        if flags.shape != (k,) or flags.dtype != np.bool_:
            raise InvalidInputError("cylinder", self.cylinder, f"must be {k} booleans")
        flags.setflags(write=False)
        object.__setattr__(self, "centers_m", centers)
        object.__setattr__(self, "radii_m", radii)
        object.__setattr__(self, "cylinder", flags)

    @property
    def k(self) -> int:
        """Number of obstacles."""
        return int(self.radii_m.shape[0])

    @property
    def is_cylinder(self) -> NDArray[np.bool_]:
        """``(k,)`` cylinder flags."""
        assert self.cylinder is not None  # set in __post_init__
        return self.cylinder

    def distance_m(self, points_m: ArrayLike) -> FloatArray:
        """``(n, k)`` signed distances from ``(n, 2)`` or ``(n, 3)`` points to each obstacle's
        surface (negative inside)."""
        pts = np.atleast_2d(np.asarray(points_m, dtype=float))
        if pts.ndim != 2 or pts.shape[1] not in (2, 3):
            raise InvalidInputError("points_m", points_m, "must be (n, 2) or (n, 3) positions")
        diff = pts[:, None, :2] - self.centers_m[None, :, :2]
        sq = np.sum(diff**2, axis=2)
        if pts.shape[1] == 3:
            dz = pts[:, None, 2] - self.centers_m[None, :, 2]
            sq = sq + np.where(self.is_cylinder[None, :], 0.0, dz**2)
        return np.asarray(np.sqrt(sq) - self.radii_m[None, :], dtype=np.float64)

    def clearance_m(self, points_m: ArrayLike) -> FloatArray:
        """``(n,)`` distance from each point to the nearest obstacle surface (``inf`` if none)."""
        d = self.distance_m(points_m)
        if self.k == 0:
            return np.full(d.shape[0], np.inf)
        return np.asarray(d.min(axis=1), dtype=np.float64)

    def check_outside(self, field: str, point_m: ArrayLike) -> None:
        """:class:`InvalidInputError` if ``point_m`` lies inside (or on) an obstacle."""
        if self.k == 0:
            return
        d = self.distance_m(point_m)[0]
        if np.any(d <= 0.0):
            j = int(np.argmin(d))
            raise InvalidInputError(field, np.asarray(point_m).tolist(),
                                    f"starts inside obstacle {j} (centre "
                                    f"{self.centers_m[j].tolist()}, radius {self.radii_m[j]:g} m)")

    def parameters(self, dim: int, margin_m: float) -> FloatArray:
        """``(k, 5)`` rows ``(c_x, c_y, c_z, r + margin, sphere flag)`` for the solvers; a planar
        vehicle (``dim = 2``) sees every obstacle as a cylinder."""
        sphere = np.where(self.is_cylinder | (dim == 2), 0.0, 1.0)
        return np.column_stack([self.centers_m, self.radii_m + margin_m, sphere])
