"""Birth intensity and survival probability on a grid, counted from traces (paper 003, §1.3).

Paper 003 lays a uniform grid over the area and, for every data sample where a target appears in
a cell, adds one to that cell's

- *birth* count if the target was previously outside the area,
- *survival* count if it was previously in another cell, and one to its
- *death* count if at the next sample the target leaves the area,

on top of pseudo-counts of 10 births, 9 survivals and 1 death per cell (so ``p_s = 0.9`` and
births are uniform where there are no data). Then ``p_s(cell) = S / (S + D)`` and the birth PHD
is the normalised birth counts times the total birth rate.

Our choices (the paper leaves them open):

- ``count_same_cell=True`` (default) also counts a sample whose predecessor was in the *same*
  cell as a survival, so that ``p_s`` is a per-sample probability whatever the cell size (with
  ``False``, the paper's literal rule, it is per cell crossing). :meth:`BirthSurvivalGrid.survival`
  rescales it to a filter step: ``p_s^(Δt / Δt_data)``.
- The first sample of a trace counts as a birth and the last as a death only if asked
  (``trace_start_is_birth``, ``trace_end_is_death``): synthetic traces start and end with the
  observation window, not with a taxi switching on or off.
- The birth rate is the number of (data) births over the time spanned by the traces; the
  pseudo-counts shape the birth *density* only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray


def _bounds(name: str, value: ArrayLike) -> FloatArray:
    arr = checks.finite_array(name, value, (2, 2))
    if not np.all(arr[:, 1] > arr[:, 0]):
        raise InvalidInputError(name, value, "must be [[x0, x1], [y0, y1]] with x0 < x1, y0 < y1")
    return arr


@dataclass(frozen=True)
class BirthSurvivalGrid:
    """Birth, survival and death counts on a regular grid (use :meth:`from_tracks`).

    Parameters
    ----------
    bounds
        ``[[x0, x1], [y0, y1]]`` (m): the area; its size must be a multiple of ``cell_m``.
    cell_m
        Cell side (m), ``> 0``.
    birth_counts, survival_counts, death_counts
        ``(n_x, n_y)`` counts including the priors, indexed ``[ix, iy]`` (the layout of
        ``searchtrack.estimate.phd.config.BirthGrid.cell_weights``), all ``≥ 0``, with
        ``S + D > 0`` in every cell.
    birth_rate_per_s
        Expected number of births per second over the whole area, ``≥ 0``.
    data_dt_s
        Sampling interval of the traces the counts came from (s), ``> 0``.
    """

    bounds: FloatArray
    cell_m: float
    birth_counts: FloatArray
    survival_counts: FloatArray
    death_counts: FloatArray
    birth_rate_per_s: float
    data_dt_s: float

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        b = _bounds("bounds", self.bounds)
        cell = checks.positive("cell_m", self.cell_m)
        shape_f = (b[:, 1] - b[:, 0]) / cell
        shape = np.rint(shape_f).astype(np.int64)
        if np.any(np.abs(shape_f - shape) > 1e-6) or np.any(shape < 1):
            raise InvalidInputError("cell_m", cell, "must divide the area's width and height")
        cells = (int(shape[0]), int(shape[1]))
        for name in ("birth_counts", "survival_counts", "death_counts"):
            arr = checks.finite_array(name, getattr(self, name), cells)
            if np.any(arr < 0):
                raise InvalidInputError(name, getattr(self, name), "must be ≥ 0")
            set_(self, name, arr)
        if np.any(self.survival_counts + self.death_counts <= 0):
            raise InvalidInputError("death_counts", self.death_counts,
                                    "survival + death counts must be > 0 in every cell")
        set_(self, "bounds", b)
        set_(self, "cell_m", cell)
        set_(self, "birth_rate_per_s", checks.non_negative("birth_rate_per_s",
                                                            self.birth_rate_per_s))
        set_(self, "data_dt_s", checks.positive("data_dt_s", self.data_dt_s))

    @classmethod
    def from_tracks(cls, xy_m: ArrayLike, track: ArrayLike, time_s: ArrayLike, bounds: ArrayLike,
                    cell_m: float, data_dt_s: float, *, birth_prior: float = 10.0,
                    survival_prior: float = 9.0, death_prior: float = 1.0,
                    count_same_cell: bool = True, trace_start_is_birth: bool = False,
                    trace_end_is_death: bool = False) -> BirthSurvivalGrid:
        """Count births, survivals and deaths of ``(n, 2)`` samples grouped by ``track`` and
        ordered by time within a track (e.g. the arrays of a
        :class:`~searchtrack.models.road_traces.Traces`).

        The area is ``bounds`` extended up and right to a whole number of cells. Samples of the
        same track more than 1.5 ``data_dt_s`` apart are not linked (a gap in the trace).
        """
        xy = checks.finite_array("xy_m", xy_m, (None, 2))
        n = xy.shape[0]
        trk = np.asarray(track)
        if trk.shape != (n,) or (n and trk.dtype.kind not in "iu"):
            raise InvalidInputError("track", track, f"must be {n} integer track ids")
        t = checks.finite_array("time_s", time_s, (n,))
        b = _bounds("bounds", bounds)
        cell = checks.positive("cell_m", cell_m)
        dt = checks.positive("data_dt_s", data_dt_s)
        priors = [checks.non_negative(name, v) for name, v in (
            ("birth_prior", birth_prior), ("survival_prior", survival_prior),
            ("death_prior", death_prior))]
        for name, flag in (("count_same_cell", count_same_cell),
                           ("trace_start_is_birth", trace_start_is_birth),
                           ("trace_end_is_death", trace_end_is_death)):
            checks.boolean(name, flag)
        order = np.lexsort((t, trk))
        xy, trk, t = xy[order], trk[order], t[order]
        shape = np.maximum(np.ceil((b[:, 1] - b[:, 0]) / cell - 1e-9).astype(np.int64), 1)
        box = np.column_stack([b[:, 0], b[:, 0] + shape * cell])
        ij = np.floor((xy - b[:, 0]) / cell).astype(np.int64)
        inside = np.all((xy >= box[:, 0]) & (xy <= box[:, 1]), axis=1)
        ij = np.clip(ij, 0, shape - 1)
        flat = ij[:, 0] * shape[1] + ij[:, 1]
        linked = np.zeros(n, dtype=bool)  # sample i − 1 is the same track, one step earlier
        if n > 1:
            linked[1:] = (trk[1:] == trk[:-1]) & (np.diff(t) <= 1.5 * dt)
        prev_in = np.zeros(n, dtype=bool)
        prev_in[1:] = inside[:-1]
        next_linked = np.append(linked[1:], False)
        next_in = np.append(inside[1:], False)
        prev_cell = np.append(-1, flat[:-1])
        birth = inside & (linked & ~prev_in | (~linked & trace_start_is_birth))
        surv = inside & linked & prev_in & (count_same_cell | (prev_cell != flat))
        death = inside & (next_linked & ~next_in | (~next_linked & trace_end_is_death))
        cells = int(shape[0] * shape[1])

        def grid(mask: NDArray[np.bool_], prior: float) -> FloatArray:
            counts = np.bincount(flat[mask], minlength=cells).astype(np.float64)
            return np.asarray((counts + prior).reshape(int(shape[0]), int(shape[1])))

        span = 0.0
        if n:
            starts = np.flatnonzero(np.append(True, trk[1:] != trk[:-1]))
            ends = np.append(starts[1:], n) - 1
            span = float(np.max(t[ends] + dt) - np.min(t[starts]))
        rate = float(np.count_nonzero(birth)) / span if span > 0 else 0.0
        return cls(box, cell, grid(birth, priors[0]), grid(surv, priors[1]),
                   grid(death, priors[2]), rate, dt)

    # ----- lookups ---------------------------------------------------------------------------

    @property
    def shape(self) -> tuple[int, int]:
        """``(n_x, n_y)`` cells."""
        return (int(self.birth_counts.shape[0]), int(self.birth_counts.shape[1]))

    @property
    def birth_pdf(self) -> FloatArray:
        """``(n_x, n_y)`` probability of each cell for a newborn (sums to 1; all 0 when there
        are no birth counts at all)."""
        total = self.birth_counts.sum()
        return np.asarray(self.birth_counts / total if total > 0 else self.birth_counts * 0.0)

    @property
    def survival_grid(self) -> FloatArray:
        """``(n_x, n_y)`` per-sample survival ``S / (S + D)``."""
        return np.asarray(self.survival_counts / (self.survival_counts + self.death_counts))

    def birth_mass(self, dt_s: float | None = None) -> float:
        """Expected births in a step of ``dt_s`` seconds (one data step if ``None``):
        ``rate · Δt``."""
        dt = self.data_dt_s if dt_s is None else checks.non_negative("dt_s", dt_s)
        return self.birth_rate_per_s * dt

    def _cells(self, positions: FloatArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
        xy = np.asarray(positions, dtype=np.float64)
        if xy.ndim != 2 or xy.shape[1] < 2:
            raise InvalidInputError("positions", xy.shape, "must have shape (N, 2)")
        xy = xy[:, :2]
        inside = np.all((xy >= self.bounds[:, 0]) & (xy <= self.bounds[:, 1]), axis=1)
        ij = np.floor((xy - self.bounds[:, 0]) / self.cell_m).astype(np.int64)
        ij = np.clip(ij, 0, np.asarray(self.shape) - 1)
        return ij[:, 0], ij[:, 1], np.asarray(inside)

    def birth_intensity(self, positions: FloatArray, dt_s: float | None = None) -> FloatArray:
        """``(N,)`` birth PHD ``b(x)`` (targets per m² per step of ``dt_s``, one data step if
        ``None``); 0 outside."""
        ix, iy, inside = self._cells(positions)
        density = self.birth_pdf[ix, iy] / self.cell_m**2
        return np.where(inside, self.birth_mass(dt_s) * density, 0.0)

    def survival(self, positions: FloatArray, dt_s: float | None = None) -> FloatArray:
        """``(N,)`` survival probability over ``dt_s`` (one data step if ``None``):
        ``p_s^(Δt/Δt_data)`` of the cell, 0 outside the area (the target has left)."""
        ix, iy, inside = self._cells(positions)
        ps = self.survival_grid[ix, iy]
        if dt_s is not None:
            ps = ps ** (checks.non_negative("dt_s", dt_s) / self.data_dt_s)
        return np.where(inside, ps, 0.0)

    def sample_births(self, count: int, rng: np.random.Generator) -> FloatArray:
        """``(count, 2)`` birth positions: a cell drawn by its birth count, then a uniform point
        in it (paper 003, *PHD Filter*)."""
        k = checks.count("count", count)
        rng = checks.generator("rng", rng)
        cdf = np.cumsum(self.birth_counts.ravel())
        if cdf[-1] <= 0:
            raise InvalidInputError("birth_counts", self.birth_counts, "all 0: nothing to sample")
        cells = np.minimum(np.searchsorted(cdf, rng.random(k) * cdf[-1], side="right"),
                           cdf.size - 1)
        ix, iy = np.unravel_index(cells, self.shape)
        corner = self.bounds[:, 0] + self.cell_m * np.column_stack([ix, iy])
        return np.asarray(corner + self.cell_m * rng.random((k, 2)))
