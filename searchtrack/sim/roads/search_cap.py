"""How much of a search-and-track mission's MOC the search leaves reachable: an ideal sweep.

A target counts toward MOC (thesis 001 (6.8)) only from the step it is first validly tracked, so
the whole-run MOC is capped by how fast the fleet can cover the road. :func:`ideal_sweep_moc`
estimates that cap under idealisations that favour the search (all but the targets standing
still, which cuts both ways: a driving target can enter road already searched or drive into
view from road not yet searched):

- the targets stand still where they start (uniform over the road length, as
  :meth:`~searchtrack.models.targets.CourierMotion.spawn` places them), are found the instant a
  footprint covers their road and are held from then on;
- each searching UAV sweeps a lane ``2ρ`` wide at speed ``S``, the starting footprints
  (``π ρ²`` each) count as covered, and the lanes fill the squares of side ``2ρ`` holding the
  most road first, with no overlap, no turns and no travel between squares
  (:func:`densest_road_curve`, the pointwise best of several grid placements);
- every UAV searches to the end (the cap); or, with ``hold``, each found target takes one UAV out
  of the search, a strict reading of the loiter strategies (one UAV per tracker). That variant
  is not a cap: a holding UAV's footprint follows its target over new road and sees the
  targets that drive through it.

Under these assumptions the fleet covers the road in one fixed order and a target at coverage
area ``a`` is found when the swept area reaches ``a`` (:func:`find_times`); the expected MOC is
the mean over draws of the targets' positions of ``Σ_i (D − T_i)⁺ / (n D)``.
"""

from __future__ import annotations

import itertools

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models import RoadNetwork

__all__ = ["densest_road_curve", "find_times", "ideal_sweep_moc"]


def densest_road_curve(network: RoadNetwork, side_m: float, *,
                       offsets: int = 4) -> tuple[FloatArray, FloatArray]:
    """``(area_m2, covered)``: the fraction of the road length inside the densest squares of
    side ``side_m`` whose total area is ``area_m2`` (breakpoints of a piecewise-linear,
    non-decreasing curve from ``(0, 0)`` to 1), the pointwise best of ``offsets²`` placements of
    the square grid. Road is counted at edge midpoints."""
    if not isinstance(network, RoadNetwork):
        raise InvalidInputError("network", network, "must be a RoadNetwork")
    side = checks.positive("side_m", side_m)
    k = checks.count("offsets", offsets, least=1)
    ends = network.coords[network.edges]
    mid, mass = ends.mean(axis=1), network.lengths_m / network.lengths_m.sum()
    best = np.zeros(1)
    for i, j in itertools.product(range(k), repeat=2):
        shift = np.array([i, j], dtype=np.float64) * side / k
        cell = np.floor((mid - mid.min(axis=0) + shift) / side).astype(np.int64)
        _, inverse = np.unique(cell, axis=0, return_inverse=True)
        per_cell = np.sort(np.bincount(inverse.ravel(), weights=mass))[::-1]
        curve = np.concatenate([[0.0], np.cumsum(per_cell)])
        n = max(best.size, curve.size)
        best = np.maximum(np.pad(best, (0, n - best.size), mode="edge"),
                          np.pad(curve, (0, n - curve.size), mode="edge"))
    area = np.arange(best.size, dtype=np.float64) * side**2
    return area, np.asarray(np.minimum(best, 1.0), dtype=np.float64)


def find_times(area_m2: FloatArray, *, uavs: int, start_m2: float, rate_m2_s: float,
               hold: bool) -> FloatArray:
    """Find times (s) of targets the coverage order reaches at ``area_m2`` (``(..., n)``, sorted
    along the last axis): ``start_m2`` is covered at time 0 and each searching UAV adds
    ``rate_m2_s`` per second; with ``hold`` the ``k``-th found target leaves ``uavs − k``
    searching (``inf``: never found)."""
    times = np.empty_like(area_m2)
    t = np.zeros(area_m2.shape[:-1])
    covered = np.full(area_m2.shape[:-1], start_m2)
    for k in range(area_m2.shape[-1]):
        searching = uavs - k if hold else uavs
        need = np.maximum(area_m2[..., k] - covered, 0.0)
        rate = searching * rate_m2_s
        t = t + need / rate if rate > 0 else np.where(need > 0, np.inf, t)
        covered = np.maximum(covered, area_m2[..., k])
        times[..., k] = t
    return times


def ideal_sweep_moc(network: RoadNetwork, *, uavs: int, targets: int, footprint_radius_m: float,
                    speed_mps: float, duration_s: float, hold: bool = False, offsets: int = 4,
                    samples: int = 200_000, seed: int = 0) -> tuple[float, FloatArray]:
    """``(moc, covered_at)``: the expected whole-run MOC of the ideal sweep (module docstring)
    over ``samples`` seeded draws of the targets' positions, and ``covered_at(t)``, the road
    fraction the whole fleet covers by ``t = 0, 1, …, duration_s`` s when every UAV searches."""
    o = checks.count("uavs", uavs, least=1)
    n = checks.count("targets", targets, least=1)
    rho = checks.positive("footprint_radius_m", footprint_radius_m)
    speed = checks.positive("speed_mps", speed_mps)
    duration = checks.positive("duration_s", duration_s)
    draws = checks.count("samples", samples, least=1)
    held = checks.boolean("hold", hold)
    area, covered = densest_road_curve(network, 2.0 * rho, offsets=offsets)
    start, rate = o * np.pi * rho**2, 2.0 * rho * speed
    u = np.random.default_rng(checks.count("seed", seed)).random((draws, n))
    at = np.sort(np.interp(u, covered, area), axis=1)
    times = find_times(at, uavs=o, start_m2=start, rate_m2_s=rate, hold=held)
    moc = float(np.mean(np.clip(duration - times, 0.0, duration)) / duration)
    clock = np.arange(int(np.floor(duration)) + 1, dtype=np.float64)
    return moc, np.interp(start + o * rate * clock, area, covered)
