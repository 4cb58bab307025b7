"""Ground targets that drive the road network like couriers (thesis 001 §1.2, §6), seeded.

The thesis says only that targets "are constrained to remain on the road network at all times
and stop and start randomly to mimic courier behavior", at up to ``V_max`` = 50 mph (Tables 6.2,
6.4). The rest is our design, kept simple and stated here:

* A target alternates *drives* and *stops*. A drive lasts an exponential time (mean
  ``mean_drive_s``), so stops come as a Poisson process while driving; a stop (dwell) lasts a
  time uniform in ``[dwell_min_s, dwell_max_s]``.
* Each drive has its own constant speed, uniform in ``[min_speed_fraction·V_max, V_max]``, so
  the distance covered in a step of ``Δt`` never exceeds ``V_max·Δt``.
* At a node a target takes one of the other edges there uniformly at random: it goes straight on
  along a road (degree 2), turns at random at an intersection (degree ≥ 3) and turns back only at
  a dead end (degree 1).

A position is ``(edge, offset_m)``: the distance along the edge from ``edges[edge, 0]``, with a
direction of travel. Within a step the phases (rest of a stop, drive, new stop, ...) are resolved
exactly in time, and the distance driven is walked along the graph across any number of nodes.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.dubins import MPS_PER_MPH
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.models.targets")



@dataclass(frozen=True)
class CourierModel:
    """How courier-like targets drive and stop; defaults: ``V_max`` of Tables 6.2 and 6.4.

    Parameters
    ----------
    max_speed_mps
        ``V_max`` (m/s), 50 mph by default.
    min_speed_fraction
        Drive speeds are uniform in ``[min_speed_fraction·V_max, V_max]``; in ``[0, 1]``.
    mean_drive_s
        Mean duration (s) of a drive between stops (exponential), > 0.
    dwell_min_s, dwell_max_s
        A stop lasts a time uniform in ``[dwell_min_s, dwell_max_s]`` (s), ``0 ≤ min ≤ max``.
    """

    max_speed_mps: float = 50.0 * MPS_PER_MPH
    min_speed_fraction: float = 0.5
    mean_drive_s: float = 60.0
    dwell_min_s: float = 5.0
    dwell_max_s: float = 30.0

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "max_speed_mps", checks.positive("max_speed_mps", self.max_speed_mps))
        set_(self, "min_speed_fraction",
             checks.real("min_speed_fraction", self.min_speed_fraction, low=0.0, high=1.0))
        set_(self, "mean_drive_s", checks.positive("mean_drive_s", self.mean_drive_s))
        lo = checks.non_negative("dwell_min_s", self.dwell_min_s)
        hi = checks.non_negative("dwell_max_s", self.dwell_max_s)
        if lo > hi:
            raise InvalidInputError("dwell_max_s", self.dwell_max_s,
                                    f"must be ≥ dwell_min_s={lo!r}")
        set_(self, "dwell_min_s", lo)
        set_(self, "dwell_max_s", hi)

    def draw_speed(self, rng: np.random.Generator, size: int) -> FloatArray:
        """``size`` drive speeds (m/s)."""
        return self.max_speed_mps * rng.uniform(self.min_speed_fraction, 1.0, size)

    def draw_drive(self, rng: np.random.Generator, size: int) -> FloatArray:
        """``size`` drive durations (s)."""
        return rng.exponential(self.mean_drive_s, size)

    def draw_dwell(self, rng: np.random.Generator, size: int) -> FloatArray:
        """``size`` stop durations (s)."""
        return rng.uniform(self.dwell_min_s, self.dwell_max_s, size)


@dataclass(frozen=True)
class TargetState:
    """``k`` targets on a road network (read-only arrays, shape ``(k,)``).

    Attributes
    ----------
    edge
        Edge each target is on.
    offset_m
        Distance (m) along that edge from its first node ``edges[edge, 0]``.
    forward
        Whether the target heads to ``edges[edge, 1]`` (else to ``edges[edge, 0]``).
    speed_mps
        Speed (m/s) of the current drive (or of the next, while stopped); ≥ 0.
    drive_left_s
        Time (s) left before the next stop, ≥ 0.
    dwell_left_s
        Time (s) left in the current stop; 0 while driving.
    odometer_m
        Road distance (m) driven since spawning.
    """

    edge: IntArray
    offset_m: FloatArray
    forward: NDArray[np.bool_]
    speed_mps: FloatArray
    drive_left_s: FloatArray
    dwell_left_s: FloatArray
    odometer_m: FloatArray

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        edge = np.atleast_1d(np.asarray(self.edge))
        if edge.ndim != 1 or (edge.size and edge.dtype.kind not in "iu") or np.any(edge < 0):
            raise InvalidInputError("edge", self.edge, "must be non-negative integer edge indices")
        edge = edge.astype(np.int64)
        edge.setflags(write=False)
        set_(self, "edge", edge)
        shape = (edge.size,)
        forward = np.atleast_1d(np.array(self.forward, dtype=bool, copy=True))
        if forward.shape != shape:
            raise InvalidInputError("forward", self.forward, f"must have shape {shape}")
        forward.setflags(write=False)
        set_(self, "forward", forward)
        for name in ("offset_m", "speed_mps", "drive_left_s", "dwell_left_s", "odometer_m"):
            value = checks.finite_array(name, np.atleast_1d(np.asarray(getattr(self, name),
                                                                        dtype=float)), shape)
            if np.any(value < 0):
                raise InvalidInputError(name, getattr(self, name), "must be ≥ 0")
            set_(self, name, value)

    @property
    def n(self) -> int:
        """Number of targets."""
        return int(self.edge.size)

    @property
    def stopped(self) -> NDArray[np.bool_]:
        """Whether each target is in a stop."""
        return np.asarray(self.dwell_left_s > 0)

    def xy_m(self, network: RoadNetwork) -> FloatArray:
        """``(k, 2)`` planar positions (m), interpolated along each edge's segment."""
        self.check_on(network)
        u, v = network.edges[self.edge, 0], network.edges[self.edge, 1]
        frac = (self.offset_m / network.lengths_m[self.edge])[:, None]
        return np.asarray(network.coords[u] + frac * (network.coords[v] - network.coords[u]))

    def nodes(self, network: RoadNetwork) -> IntArray:
        """The nearer end node (along the road) of each target's edge."""
        self.check_on(network)
        second = self.offset_m > 0.5 * network.lengths_m[self.edge]
        return np.asarray(network.edges[self.edge, second.astype(np.int64)], dtype=np.int64)

    def check_on(self, network: RoadNetwork) -> None:
        """Raise :class:`InvalidInputError` unless every target lies on an edge of ``network``."""
        if self.n and self.edge.max() >= network.n_edges:
            raise InvalidInputError("edge", self.edge, f"must be < n_edges={network.n_edges}")
        if np.any(self.offset_m > network.lengths_m[self.edge] * (1 + 1e-12)):
            raise InvalidInputError("offset_m", self.offset_m, "must not exceed the edge length")


@dataclass(frozen=True, eq=False)
class CourierMotion:
    """Courier-like motion of targets on one road network: :meth:`spawn` then :meth:`step`."""

    network: RoadNetwork
    model: CourierModel = field(default_factory=CourierModel)

    def __post_init__(self) -> None:
        if not isinstance(self.network, RoadNetwork):
            raise InvalidInputError("network", self.network, "must be a RoadNetwork")
        if not isinstance(self.model, CourierModel):
            raise InvalidInputError("model", self.model, "must be a CourierModel")

    @cached_property
    def _incidence(self) -> tuple[IntArray, IntArray, IntArray]:
        """``(indptr, key, edge)``: the edges at each node, sorted by ``key = node·M + edge``."""
        m = self.network.n_edges
        node = self.network.edges.T.reshape(-1)
        edge = np.tile(np.arange(m, dtype=np.int64), 2)
        key = node * m + edge
        order = np.argsort(key)
        indptr = np.concatenate([[0], np.cumsum(np.bincount(node, minlength=self.network.n_nodes))])
        return indptr.astype(np.int64), key[order], edge[order]

    def spawn(self, count: int, rng: np.random.Generator) -> TargetState:
        """``count`` targets uniform over the road length, random directions, starting drives."""
        k = checks.count("count", count)
        rng = checks.generator("rng", rng)
        lengths = self.network.lengths_m
        edge = rng.choice(lengths.size, size=k, p=lengths / lengths.sum())
        return TargetState(
            edge=edge.astype(np.int64),
            offset_m=rng.random(k) * lengths[edge],
            forward=rng.random(k) < 0.5,
            speed_mps=self.model.draw_speed(rng, k),
            drive_left_s=self.model.draw_drive(rng, k),
            dwell_left_s=np.zeros(k),
            odometer_m=np.zeros(k),
        )

    def step(self, state: TargetState, dt_s: float, rng: np.random.Generator) -> TargetState:
        """The targets ``dt_s`` seconds later (drives, stops and turns drawn from ``rng``)."""
        dt = checks.positive("dt_s", dt_s)
        rng = checks.generator("rng", rng)
        state.check_on(self.network)
        speed, drive, dwell, dist = self._phases(state, dt, rng)
        edge, offset, forward = self._walk(state, dist, rng)
        return TargetState(edge=edge, offset_m=offset, forward=forward, speed_mps=speed,
                           drive_left_s=drive, dwell_left_s=dwell,
                           odometer_m=state.odometer_m + dist)

    def _phases(self, state: TargetState, dt: float, rng: np.random.Generator
                ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Run each target's stops and drives through ``dt``; return the new speed, drive and
        dwell times and the distance driven."""
        model = self.model
        speed, drive = state.speed_mps.copy(), state.drive_left_s.copy()
        dwell = state.dwell_left_s.copy()
        left, dist = np.full(state.n, dt), np.zeros(state.n)

        def new_drive(mask: NDArray[np.bool_]) -> None:
            if k := int(np.count_nonzero(mask)):
                speed[mask] = model.draw_speed(rng, k)
                drive[mask] = model.draw_drive(rng, k)

        while np.any(left > 0):
            waiting = (dwell > 0) & (left > 0)
            used = np.minimum(dwell[waiting], left[waiting])
            dwell[waiting] -= used
            left[waiting] -= used
            restart = waiting & (dwell <= 0)
            dwell[restart] = 0.0
            new_drive(restart)
            driving = (dwell <= 0) & (left > 0)
            used = np.minimum(drive[driving], left[driving])
            dist[driving] += speed[driving] * used
            drive[driving] -= used
            left[driving] -= used
            stop = driving & (drive <= 0)
            if k := int(np.count_nonzero(stop)):
                drive[stop] = 0.0
                dwell[stop] = model.draw_dwell(rng, k)
                new_drive(stop & (dwell <= 0))  # a zero-length stop: drive on at once
        return speed, drive, dwell, dist

    def _walk(self, state: TargetState, dist: FloatArray, rng: np.random.Generator
              ) -> tuple[IntArray, FloatArray, NDArray[np.bool_]]:
        """Move each target ``dist`` metres along the graph, choosing an edge at each node."""
        ends, lengths, m = self.network.edges, self.network.lengths_m, self.network.n_edges
        indptr, key, inc_edge = self._incidence
        edge, offset, forward = state.edge.copy(), state.offset_m.copy(), state.forward.copy()
        remaining = dist.copy()
        active = np.flatnonzero(remaining > 0)
        crossings = 0
        while active.size:
            e, fwd = edge[active], forward[active]
            to_end = np.where(fwd, lengths[e] - offset[active], offset[active])
            arrive = remaining[active] > to_end
            stay, go = active[~arrive], active[arrive]
            offset[stay] += np.where(forward[stay], remaining[stay], -remaining[stay])
            remaining[stay] = 0.0
            if not go.size:
                break
            crossings += go.size
            remaining[go] -= to_end[arrive]
            node = np.where(forward[go], ends[edge[go], 1], ends[edge[go], 0])
            degree = indptr[node + 1] - indptr[node]
            here = np.searchsorted(key, node * m + edge[go]) - indptr[node]
            pick = np.floor(rng.random(go.size) * np.maximum(degree - 1, 1)).astype(np.int64)
            pick = np.where(degree == 1, here, pick + (pick >= here))
            new = inc_edge[indptr[node] + pick]
            edge[go] = new
            forward[go] = ends[new, 0] == node
            offset[go] = np.where(forward[go], 0.0, lengths[new])
            active = go
        log.debug("moved %d targets across %d nodes", state.n, crossings)
        return edge, np.clip(offset, 0.0, lengths[edge]), forward
