"""The orienteering problem with time windows (OPTW) and its team version, as a frozen instance.

Times are integers in *ticks* (``time_scale`` ticks per time unit) so that the benchmark convention
(Euclidean distance truncated to 1 or 2 decimals) is reproduced exactly, with no float round-off.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError

Route = tuple[int, ...]
Routes = tuple[Route, ...]
Rounding = Literal["truncate", "round", "ceil"]


def _int_ticks(name: str, values: ArrayLike, n: int | None = None) -> NDArray[np.int64]:
    arr = np.asarray(values)
    if arr.dtype.kind not in "iu":
        farr = np.asarray(arr, dtype=np.float64)
        if not np.all(np.isfinite(farr)):
            raise InvalidInputError(name, values, "must be finite")
        if not np.array_equal(farr, np.round(farr)):
            raise InvalidInputError(name, values, "must be whole numbers of ticks")
        arr = farr.astype(np.int64)
    arr = arr.astype(np.int64)
    if n is not None and arr.shape != (n,):
        raise InvalidInputError(name, values, f"must have shape ({n},), got {arr.shape}")
    return arr


@dataclass(frozen=True, eq=False)
class OPTWInstance:
    """A (team) orienteering problem with time windows.

    Each route leaves ``start`` at its opening time, visits vertices (service may start only
    inside the vertex's window ``[open, close]``; arriving early means waiting) and reaches ``end``
    no later than its closing time and within ``tmax`` of departure. Each vertex is collected at
    most once over all ``vehicles`` routes; the objective is the total profit collected.

    Parameters
    ----------
    travel
        ``(n, n)`` travel times in ticks (``travel[i, j]`` from ``i`` to ``j``; may be asymmetric).
    service, open, close
        ``(n,)`` service durations and window bounds on the start of service, in ticks.
    profit
        ``(n,)`` non-negative profits; those of ``start`` and ``end`` are not collected.
    start, end
        Indices of the first and last vertex of every route; ``end=None`` lets routes end wherever
        their last visit is (an open end).
    tmax
        Longest route duration in ticks, or ``None`` for no limit beyond the windows.
    vehicles
        Number of routes ``m ≥ 1``.
    time_scale
        Ticks per time unit (10 for Solomon, 100 for Cordeau benchmark files).
    name
        Label for reports.
    coords
        Optional ``(n, 2)`` coordinates (for plots and writing files).
    ids
        Vertex identifiers as the user knows them (file ids); defaults to ``0..n-1``.
    """

    travel: NDArray[np.int64]
    service: NDArray[np.int64]
    profit: NDArray[np.float64]
    open: NDArray[np.int64]
    close: NDArray[np.int64]
    start: int = 0
    end: int | None = 0
    tmax: int | None = None
    vehicles: int = 1
    time_scale: int = 1
    name: str = "optw"
    coords: NDArray[np.float64] | None = None
    ids: tuple[int, ...] = field(default=())

    def __post_init__(self) -> None:
        travel = np.asarray(self.travel)
        if travel.ndim != 2 or travel.shape[0] != travel.shape[1] or travel.shape[0] < 1:
            raise InvalidInputError("travel", self.travel, "must be a square (n, n) matrix, n ≥ 1")
        n = travel.shape[0]
        travel = _int_ticks("travel", travel.reshape(-1)).reshape(n, n)
        if np.any(travel < 0):
            raise InvalidInputError("travel", self.travel, "travel times must be non-negative")
        service = _int_ticks("service", self.service, n)
        opn = _int_ticks("open", self.open, n)
        close = _int_ticks("close", self.close, n)
        profit = np.asarray(self.profit, dtype=np.float64)
        if profit.shape != (n,):
            raise InvalidInputError("profit", self.profit, f"must have shape ({n},)")
        if not np.all(np.isfinite(profit)) or np.any(profit < 0):
            raise InvalidInputError("profit", self.profit, "must be finite and non-negative")
        if np.any(service < 0):
            raise InvalidInputError("service", self.service, "must be non-negative")
        if np.any(opn < 0):
            raise InvalidInputError("open", self.open, "must be non-negative")
        bad = np.flatnonzero(close < opn)
        if bad.size:
            i = int(bad[0])
            raise InvalidInputError(
                f"close[{i}]", int(close[i]), f"closes before it opens (open={int(opn[i])})"
            )
        for name, v in (("start", self.start), ("end", self.end)):
            if v is None and name == "end":
                continue
            if not isinstance(v, (int, np.integer)) or not 0 <= int(v) < n:
                raise InvalidInputError(name, v, f"must be a vertex index in [0, {n})")
        if self.tmax is not None and (
            not isinstance(self.tmax, (int, np.integer)) or self.tmax < 0
        ):
            raise InvalidInputError("tmax", self.tmax, "must be a non-negative number of ticks")
        if not isinstance(self.vehicles, (int, np.integer)) or self.vehicles < 1:
            raise InvalidInputError("vehicles", self.vehicles, "must be an integer ≥ 1")
        if not isinstance(self.time_scale, (int, np.integer)) or self.time_scale < 1:
            raise InvalidInputError("time_scale", self.time_scale, "must be an integer ≥ 1")
        ids = tuple(int(i) for i in self.ids) if self.ids else tuple(range(n))
        if len(ids) != n or len(set(ids)) != n:
            raise InvalidInputError("ids", self.ids, f"must be {n} distinct integers")
        coords = None
        if self.coords is not None:
            coords = np.asarray(self.coords, dtype=np.float64)
            if coords.shape != (n, 2) or not np.all(np.isfinite(coords)):
                raise InvalidInputError("coords", self.coords, f"must be finite, shape ({n}, 2)")
        set_ = object.__setattr__
        set_(self, "travel", checks.readonly(travel))
        set_(self, "service", checks.readonly(service))
        set_(self, "open", checks.readonly(opn))
        set_(self, "close", checks.readonly(close))
        set_(self, "profit", checks.readonly(profit))
        set_(self, "coords", None if coords is None else checks.readonly(coords))
        set_(self, "ids", ids)
        set_(self, "start", int(self.start))
        set_(self, "end", None if self.end is None else int(self.end))
        set_(self, "tmax", None if self.tmax is None else int(self.tmax))
        set_(self, "vehicles", int(self.vehicles))

    @property
    def n(self) -> int:
        """Number of vertices, start and end included."""
        return int(self.travel.shape[0])

    @property
    def customers(self) -> NDArray[np.intp]:
        """Indices of the vertices that can be collected (all but start and end)."""
        mask = np.ones(self.n, dtype=bool)
        mask[self.start] = False
        if self.end is not None:
            mask[self.end] = False
        return np.flatnonzero(mask)

    @property
    def departure(self) -> int:
        """Time (ticks) at which every route leaves ``start``."""
        return int(self.open[self.start])

    @property
    def latest_finish(self) -> int:
        """Latest time (ticks) a route may reach ``end`` (or, for an open end, finish its last
        service)."""
        limits = [np.iinfo(np.int64).max // 4]
        if self.end is not None:
            limits.append(int(self.close[self.end]))
        if self.tmax is not None:
            limits.append(self.departure + self.tmax)
        return min(limits)

    def with_vehicles(self, vehicles: int) -> OPTWInstance:
        """The same instance with ``vehicles`` routes."""
        return _replace(self, vehicles=vehicles)

    def to_time(self, ticks: float) -> float:
        """Convert ticks to time units."""
        return float(ticks) / self.time_scale

    def route_ids(self, routes: Routes) -> list[list[int]]:
        """Routes as lists of external vertex ids."""
        return [[self.ids[v] for v in r] for r in routes]

    @classmethod
    def from_coordinates(
        cls,
        coords: ArrayLike,
        profit: ArrayLike,
        service: ArrayLike,
        open: ArrayLike,
        close: ArrayLike,
        *,
        decimals: int = 2,
        rounding: Rounding = "truncate",
        speed: float = 1.0,
        start: int = 0,
        end: int | None = 0,
        tmax: float | None = None,
        vehicles: int = 1,
        name: str = "optw",
        ids: Sequence[int] = (),
    ) -> OPTWInstance:
        """Build an instance whose travel times are Euclidean distances / ``speed``.

        Times are kept with ``decimals`` decimals (``time_scale = 10**decimals``); distances are
        ``rounding``-ed to that precision. With ``speed=1`` and coordinates that are exact decimals
        (up to 6 places) the truncation is exact, as the OPTW benchmarks require.
        """
        xy = np.asarray(coords, dtype=np.float64)
        if xy.ndim != 2 or xy.shape[1] != 2 or not np.all(np.isfinite(xy)):
            raise InvalidInputError("coords", coords, "must be a finite (n, 2) array")
        if not 0 <= decimals <= 6:
            raise InvalidInputError("decimals", decimals, "must be in [0, 6]")
        if not (math.isfinite(speed) and speed > 0):
            raise InvalidInputError("speed", speed, "must be positive and finite")
        scale = 10**decimals
        travel = euclidean_ticks(xy, decimals, rounding, speed)
        return cls(
            travel=travel,
            service=to_ticks("service", service, scale, "ceil"),
            profit=np.asarray(profit, dtype=np.float64),
            open=to_ticks("open", open, scale, "ceil"),
            close=to_ticks("close", close, scale, "truncate"),
            start=start,
            end=end,
            tmax=None if tmax is None else int(to_ticks("tmax", [tmax], scale, "truncate")[0]),
            vehicles=vehicles,
            time_scale=scale,
            name=name,
            coords=xy,
            ids=tuple(ids),
        )

    @classmethod
    def from_travel_times(
        cls,
        travel: ArrayLike,
        profit: ArrayLike,
        *,
        service: ArrayLike | None = None,
        open: ArrayLike | None = None,
        close: ArrayLike | None = None,
        start: int = 0,
        end: int | None = 0,
        tmax: float | None = None,
        vehicles: int = 1,
        time_scale: int = 1000,
        name: str = "optw",
        coords: ArrayLike | None = None,
    ) -> OPTWInstance:
        """Build an instance from a travel-time matrix in time units (e.g. seconds).

        Times are converted to ticks conservatively: travel and service rounded up, windows
        inward, so every plan feasible in ticks is feasible in real time. Missing windows are
        ``[0, tmax]`` (``tmax`` is then required).
        """
        t = np.asarray(travel, dtype=np.float64)
        if t.ndim != 2 or t.shape[0] != t.shape[1]:
            raise InvalidInputError("travel", travel, "must be a square (n, n) matrix")
        n = t.shape[0]
        if (open is None or close is None) and tmax is None:
            raise InvalidInputError("tmax", tmax, "is required when windows are not given")
        horizon = float(tmax) if tmax is not None else 0.0
        return cls(
            travel=to_ticks("travel", t.reshape(-1), time_scale, "ceil").reshape(n, n),
            service=to_ticks("service", np.zeros(n) if service is None else service,
                             time_scale, "ceil"),
            profit=np.asarray(profit, dtype=np.float64),
            open=to_ticks("open", np.zeros(n) if open is None else open, time_scale, "ceil"),
            close=to_ticks("close", np.full(n, horizon) if close is None else close,
                           time_scale, "truncate"),
            start=start,
            end=end,
            tmax=None if tmax is None else int(to_ticks("tmax", [tmax], time_scale,
                                                         "truncate")[0]),
            vehicles=vehicles,
            time_scale=time_scale,
            name=name,
            coords=None if coords is None else np.asarray(coords, dtype=np.float64),
        )


def _replace(inst: OPTWInstance, **changes: int) -> OPTWInstance:
    from dataclasses import replace

    return replace(inst, **changes)  # type: ignore[arg-type]


def to_ticks(name: str, values: ArrayLike, scale: int, rounding: Rounding) -> NDArray[np.int64]:
    """Convert times in units to integer ticks, rounding as asked (tolerant of float noise)."""
    v = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(v)):
        raise InvalidInputError(name, values, "must be finite")
    if np.any(v < 0):
        raise InvalidInputError(name, values, "must be non-negative")
    x = v * scale
    if rounding == "round":
        out = np.round(x)
    elif rounding == "ceil":
        out = np.ceil(x - 1e-9)
    else:
        out = np.floor(x + 1e-9)
    return out.astype(np.int64)


def _isqrt(d2: NDArray[np.int64]) -> NDArray[np.int64]:
    """Exact elementwise integer square root (floor) of non-negative int64 values below 2**62."""
    r = np.floor(np.sqrt(d2.astype(np.float64))).astype(np.int64)
    r -= (r * r > d2).astype(np.int64)
    r += ((r + 1) * (r + 1) <= d2).astype(np.int64)
    return r


def euclidean_ticks(
    xy: NDArray[np.float64], decimals: int, rounding: Rounding, speed: float = 1.0
) -> NDArray[np.int64]:
    """Euclidean distance / speed in ticks of ``10**-decimals``, exact for decimal coordinates.

    Coordinates are scaled to integers (at the least number of decimals ≤ 6 that represents them),
    squared distances are computed in integers and the integer square root gives the truncated
    distance with no round-off. Other speeds or roundings fall back to floating point.
    """
    scale = 10**decimals
    cdec = next((c for c in range(7) if np.allclose(xy * 10**c, np.round(xy * 10**c),
                                                    rtol=0, atol=1e-6)), None)
    if speed == 1.0 and rounding == "truncate" and cdec is not None:
        q = np.round(xy * 10**cdec).astype(np.int64)
        d = q[:, None, :] - q[None, :, :]
        d2 = (d * d).sum(axis=2) * (scale * scale)
        if np.any(d2 >= 2**62):
            raise InvalidInputError("coords", "…", "too large for exact integer distances")
        return np.asarray(_isqrt(d2) // (10**cdec), dtype=np.int64)
    diff = xy[:, None, :] - xy[None, :, :]
    dist = np.sqrt((diff * diff).sum(axis=2)) / speed
    return to_ticks("travel", dist, scale, rounding)


def profit_step(profit: NDArray[np.float64]) -> int:
    """The greatest common divisor of integral profits (1 when all are 0), 0 when some profit
    is not integral: every plan collects a multiple of it, so a bound rounds down to one."""
    if not np.all(profit == np.round(profit)):
        return 0
    return max(1, math.gcd(*np.abs(profit).astype(np.int64).tolist()))
