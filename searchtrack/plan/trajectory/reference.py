"""References to track: a waypoint sequence flown at constant speed, or a sampled path ``r(t)``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


class Reference(Protocol):
    """A time-parameterised reference position ``r(t)``."""

    @property
    def dim(self) -> int:
        """2 or 3 position axes."""
        ...

    @property
    def duration_s(self) -> float:
        """Time at which the reference reaches its end (it holds the end afterwards)."""
        ...

    def positions(self, times_s: ArrayLike) -> FloatArray:
        """``(n, dim)`` reference positions at ``times_s``."""
        ...


@dataclass(frozen=True)
class SampledPath:
    """A reference given at increasing times, linearly interpolated and held at both ends."""

    times_s: FloatArray
    positions_m: FloatArray

    def __post_init__(self) -> None:
        t = checks.finite_array("times_s", self.times_s, (None,))
        if t.shape[0] < 1 or np.any(np.diff(t) <= 0):
            raise InvalidInputError("times_s", t.tolist(), "must be ≥ 1 increasing times")
        pos = checks.finite_array("positions_m", self.positions_m, (t.shape[0], None))
        if pos.shape[1] not in (2, 3):
            raise InvalidInputError("positions_m", pos.shape, "must be (n, 2) or (n, 3)")
        object.__setattr__(self, "times_s", t)
        object.__setattr__(self, "positions_m", pos)

    @property
    def dim(self) -> int:
        """Number of position axes."""
        return int(self.positions_m.shape[1])

    @property
    def duration_s(self) -> float:
        """Last sample time."""
        return float(self.times_s[-1])

    def positions(self, times_s: ArrayLike) -> FloatArray:
        """``(n, dim)`` interpolated positions."""
        t = np.atleast_1d(np.asarray(times_s, dtype=float))
        cols = [np.interp(t, self.times_s, self.positions_m[:, i]) for i in range(self.dim)]
        return np.column_stack(cols)


def waypoint_path(waypoints_m: ArrayLike, speed_mps: float, *, start_time_s: float = 0.0
                  ) -> SampledPath:
    """The polyline through ``waypoints_m`` ``(k, 2|3)`` flown at ``speed_mps`` from
    ``start_time_s`` (repeated waypoints are dropped)."""
    pts = np.asarray(waypoints_m, dtype=float)
    if pts.ndim != 2 or pts.shape[0] < 1:
        raise InvalidInputError("waypoints_m", waypoints_m, "must be a (k, 2) or (k, 3) array")
    pts = checks.finite_array("waypoints_m", pts, (None, pts.shape[1]))
    speed = checks.positive("speed_mps", speed_mps)
    start = checks.real("start_time_s", start_time_s)
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    keep = np.concatenate([[True], seg > 1e-9])
    pts = pts[keep]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    return SampledPath(times_s=start + arc / speed, positions_m=pts)
