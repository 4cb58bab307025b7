"""Taxi-like vehicle traces on a road network, the stand-in for paper 003's taxi data set.

Paper 003 learns its target model from the Cabspotting San Francisco taxi GPS traces (CRAWDAD
``epfl/mobility``). That data set cannot be downloaded here (no network beyond package registries,
and CRAWDAD needs registration), so these traces are generated on an OpenStreetMap road network
instead (``searchtrack.models.read_osm``). The design is ours:

* A vehicle makes back-to-back *fares*: an empty leg from where it is to a pick-up node, a wait
  there, an occupied leg to a drop-off node and a wait there, each leg along a shortest road path.
  A share ``hotspot_share`` of pick-ups is drawn near a few random *hotspots* (Gaussian weights of
  radius ``hotspot_radius_m`` around random nodes), the rest and all drop-offs uniformly over the
  nodes: like taxis leaving downtown at the evening rush, occupied traffic flows out of the
  hotspots and empty traffic back in. Each sample records whether the taxi is occupied, as the
  Cabspotting traces do. On two-way streets shortest-path traffic goes both ways about equally,
  so the mean velocity at a point is ≈ 0 (occupied samples keep a little direction); one-way
  streets (next item) are what gives the flow a direction a velocity field can learn.
* Each leg has its own cruise speed, uniform in ``[min_speed_mps, max_speed_mps]``; at every
  intersection passed (degree ≥ 3) the vehicle stops with probability ``stop_probability`` for a
  time uniform in ``[stop_min_s, stop_max_s]`` (traffic lights); the waits at pick-up and
  drop-off are uniform in ``[dwell_min_s, dwell_max_s]``.
* A share ``one_way_fraction`` of the streets is one-way (random direction; see
  :mod:`searchtrack.models.one_way`), since ``read_osm`` does not keep OSM's ``oneway`` tags.
  Routes follow the directions; trips start and end in the largest strongly connected part.
* Positions are sampled every ``dt_s`` seconds from ``t = 0`` to ``duration_s``, linearly
  between road nodes, so they lie on the roads; ``gps_sigma_m > 0`` adds Gaussian GPS noise.

Every draw comes from the ``numpy.random.Generator`` passed in, so traces repeat for a seed.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.one_way import one_way_roads
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.models.road_traces")



def _range(model: object, lo_name: str, hi_name: str, positive: bool) -> None:
    check = checks.positive if positive else checks.non_negative
    lo = check(lo_name, getattr(model, lo_name))
    hi = check(hi_name, getattr(model, hi_name))
    if hi < lo:
        raise InvalidInputError(hi_name, hi, f"must be ≥ {lo_name}={lo!r}")
    object.__setattr__(model, lo_name, lo)
    object.__setattr__(model, hi_name, hi)


@dataclass(frozen=True)
class TaxiModel:
    """How taxi-like vehicles drive (see the module docstring); speeds in m/s, times in s."""

    min_speed_mps: float = 7.0
    max_speed_mps: float = 14.0
    stop_probability: float = 0.3
    stop_min_s: float = 5.0
    stop_max_s: float = 30.0
    dwell_min_s: float = 10.0
    dwell_max_s: float = 60.0
    n_hotspots: int = 3
    hotspot_radius_m: float = 300.0
    hotspot_share: float = 0.5
    gps_sigma_m: float = 0.0
    one_way_fraction: float = 0.0

    def __post_init__(self) -> None:
        _range(self, "min_speed_mps", "max_speed_mps", positive=True)
        _range(self, "stop_min_s", "stop_max_s", positive=False)
        _range(self, "dwell_min_s", "dwell_max_s", positive=False)
        set_ = object.__setattr__
        set_(self, "stop_probability",
             checks.real("stop_probability", self.stop_probability, low=0.0, high=1.0))
        set_(self, "n_hotspots", checks.count("n_hotspots", self.n_hotspots))
        set_(self, "hotspot_radius_m", checks.positive("hotspot_radius_m", self.hotspot_radius_m))
        set_(self, "hotspot_share",
             checks.real("hotspot_share", self.hotspot_share, low=0.0, high=1.0))
        set_(self, "gps_sigma_m", checks.non_negative("gps_sigma_m", self.gps_sigma_m))
        set_(self, "one_way_fraction",
             checks.real("one_way_fraction", self.one_way_fraction, low=0.0, high=1.0))


@dataclass(frozen=True)
class Traces:
    """Sampled vehicle positions, sorted by vehicle then time (read-only arrays).

    Parameters
    ----------
    vehicle
        ``(n,)`` vehicle index of each sample, non-decreasing.
    time_s
        ``(n,)`` sample times (s), increasing within a vehicle.
    xy_m
        ``(n, 2)`` positions (m).
    occupied
        ``(n,)`` whether the vehicle carries a fare at each sample.
    dt_s
        Sampling interval (s), ``> 0``; consecutive samples of a vehicle are ``dt_s`` apart.
    """

    vehicle: IntArray
    time_s: FloatArray
    xy_m: FloatArray
    occupied: NDArray[np.bool_]
    dt_s: float

    def __post_init__(self) -> None:
        veh = np.array(self.vehicle, copy=True)
        if veh.ndim != 1 or (veh.size and veh.dtype.kind not in "iu") or np.any(veh < 0):
            raise InvalidInputError("vehicle", self.vehicle, "must be non-negative integers")
        veh = veh.astype(np.int64)
        if np.any(np.diff(veh) < 0):
            raise InvalidInputError("vehicle", self.vehicle, "must be sorted (non-decreasing)")
        veh.setflags(write=False)
        n = veh.size
        t = checks.finite_array("time_s", self.time_s, (n,))
        same = veh[1:] == veh[:-1]
        if np.any(np.diff(t)[same] <= 0):
            raise InvalidInputError("time_s", self.time_s, "must increase within a vehicle")
        object.__setattr__(self, "vehicle", veh)
        object.__setattr__(self, "time_s", t)
        object.__setattr__(self, "xy_m", checks.finite_array("xy_m", self.xy_m, (n, 2)))
        occ = np.array(self.occupied, copy=True)
        if occ.shape != (n,) or occ.dtype != np.bool_:
            raise InvalidInputError("occupied", self.occupied, f"must be {n} booleans")
        occ.setflags(write=False)
        object.__setattr__(self, "occupied", occ)
        object.__setattr__(self, "dt_s", checks.positive("dt_s", self.dt_s))

    @property
    def n_points(self) -> int:
        """Number of samples."""
        return int(self.vehicle.size)

    @property
    def vehicles(self) -> IntArray:
        """The distinct vehicle indices, sorted."""
        return np.unique(self.vehicle)

    @property
    def consecutive(self) -> NDArray[np.bool_]:
        """``(n,)`` whether sample ``i`` has a successor ``i + 1`` of the same vehicle one
        ``dt_s`` later."""
        nxt = np.zeros(self.n_points, dtype=bool)
        if self.n_points > 1:
            same = self.vehicle[1:] == self.vehicle[:-1]
            gap = np.abs(np.diff(self.time_s) - self.dt_s) <= 1e-6 * self.dt_s
            nxt[:-1] = same & gap
        return nxt

    def velocities(self, occupied_only: bool = False) -> tuple[FloatArray, FloatArray]:
        """``(positions, velocities)``, each ``(m, 2)``: forward differences
        ``(x_{k+1} − x_k) / dt`` attributed to ``x_k``, for every sample with a successor (both
        occupied if ``occupied_only``)."""
        ok = self.consecutive
        if occupied_only:
            ok = ok & self.occupied & np.roll(self.occupied, -1)
        i = np.flatnonzero(ok)
        v = (self.xy_m[i + 1] - self.xy_m[i]) / self.dt_s
        return self.xy_m[i].copy(), np.asarray(v)

    def select(self, vehicles: ArrayLike) -> Traces:
        """The traces of the given vehicles only."""
        keep = np.isin(self.vehicle, np.asarray(vehicles))
        return Traces(self.vehicle[keep], self.time_s[keep], self.xy_m[keep],
                      self.occupied[keep], self.dt_s)


def _hotspot_weights(xy: FloatArray, model: TaxiModel, rng: np.random.Generator) -> FloatArray:
    """Pick-up probabilities over the ``(n, 2)`` candidate nodes: uniform mixed with hotspot
    bumps."""
    n = xy.shape[0]
    w = np.full(n, (1.0 - model.hotspot_share) / n)
    if model.n_hotspots and model.hotspot_share > 0.0:
        centres = xy[rng.integers(0, n, model.n_hotspots)]
        d2 = np.sum((xy[:, None, :] - centres[None, :, :]) ** 2, axis=2)
        bump = np.exp(-0.5 * d2 / model.hotspot_radius_m**2).sum(axis=1)
        w += model.hotspot_share * bump / bump.sum()
    return np.asarray(w / w.sum())


def _leg(network: RoadNetwork, path: IntArray, t0: float, occupied: bool, model: TaxiModel,
         rng: np.random.Generator) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """Knot times ``(2p,)``, positions ``(2p, 2)`` and occupancy (arrive and depart at each path
    node), ending with the wait at the last node."""
    xy = network.coords[path]
    seg = np.sqrt(np.sum(np.diff(xy, axis=0) ** 2, axis=1))
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    speed = rng.uniform(model.min_speed_mps, model.max_speed_mps)
    p = path.size
    stop = np.zeros(p)
    inner = np.zeros(p, dtype=bool)
    inner[1:-1] = network.degree[path[1:-1]] >= 3
    halt = inner & (rng.random(p) < model.stop_probability)
    stop[halt] = rng.uniform(model.stop_min_s, model.stop_max_s, int(halt.sum()))
    stop[-1] = rng.uniform(model.dwell_min_s, model.dwell_max_s)
    arrive = t0 + cum / speed + np.concatenate([[0.0], np.cumsum(stop[:-1])])
    depart = arrive + stop
    times = np.column_stack([arrive, depart]).reshape(-1)
    flags = np.full(2 * p, occupied)
    flags[-2:] = False  # the wait at the end of the leg
    return times, np.repeat(xy, 2, axis=0), flags


def _draw(cdf: FloatArray, rng: np.random.Generator) -> int:
    return int(min(np.searchsorted(cdf, rng.random() * cdf[-1], side="right"), cdf.size - 1))


def taxi_traces(network: RoadNetwork, n_vehicles: int, duration_s: float, dt_s: float,
                rng: np.random.Generator, model: TaxiModel | None = None) -> Traces:
    """Traces of ``n_vehicles`` taxi-like vehicles on ``network`` over ``[0, duration_s)``.

    Parameters
    ----------
    network
        A connected road network (``read_osm`` keeps the largest component).
    n_vehicles
        Number of vehicles, ``≥ 1``; each starts at a uniformly random node at ``t = 0``.
    duration_s
        Length of the observation window (s), ``> 0``.
    dt_s
        Sampling interval (s), ``> 0``.
    rng
        Source of every random draw (hotspots included).
    model
        Driving behaviour (``TaxiModel()`` by default).

    Raises
    ------
    InvalidInputError
        For a bad argument or a disconnected network.
    """
    if not isinstance(network, RoadNetwork):
        raise InvalidInputError("network", network, "must be a RoadNetwork")
    if not network.is_connected:
        raise InvalidInputError("network", network, "must be connected (use largest_component)")
    k = checks.count("n_vehicles", n_vehicles, 1)
    duration = checks.positive("duration_s", duration_s)
    dt = checks.positive("dt_s", dt_s)
    rng = checks.generator("rng", rng)
    model = TaxiModel() if model is None else model
    if not isinstance(model, TaxiModel):
        raise InvalidInputError("model", model, "must be a TaxiModel")
    roads = one_way_roads(network, model.one_way_fraction, rng)
    ends = roads.reachable
    pick_cdf = np.cumsum(_hotspot_weights(network.coords[ends], model, rng))
    drop_cdf = np.arange(1.0, ends.size + 1.0)
    sample_t = np.arange(0.0, duration, dt)
    vehicles, xys, occs = [], [], []
    fares = 0
    for v in range(k):
        node = int(ends[rng.integers(ends.size)])
        t = 0.0
        knots = [(np.zeros(1), network.coords[node][None, :], np.zeros(1, dtype=bool))]
        while t < duration:
            pick, drop = int(ends[_draw(pick_cdf, rng)]), int(ends[_draw(drop_cdf, rng)])
            if drop == pick:
                continue
            for dest, occupied in ((pick, False), (drop, True)):
                if dest != node:
                    knots.append(_leg(network, roads.path(node, dest), t, occupied, model,
                                      rng))
                    t, node = float(knots[-1][0][-1]), dest
            fares += 1
        kt = np.concatenate([kn[0] for kn in knots])
        kxy = np.vstack([kn[1] for kn in knots])
        kocc = np.concatenate([kn[2] for kn in knots])
        xys.append(np.column_stack([np.interp(sample_t, kt, kxy[:, 0]),
                                    np.interp(sample_t, kt, kxy[:, 1])]))
        occs.append(kocc[np.searchsorted(kt, sample_t, side="right") - 1])
        vehicles.append(np.full(sample_t.size, v, dtype=np.int64))
    xy_all = np.vstack(xys)
    if model.gps_sigma_m > 0.0:
        xy_all = xy_all + model.gps_sigma_m * rng.standard_normal(xy_all.shape)
    log.info("%d taxi traces, %d fares, %d samples every %g s", k, fares, xy_all.shape[0], dt)
    return Traces(np.concatenate(vehicles), np.tile(sample_t, k), xy_all, np.concatenate(occs),
                  dt)
