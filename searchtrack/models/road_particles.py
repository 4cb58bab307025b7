"""Targets as points on directed roads: the state ``(edge, arc length)`` of Moore et al. 2021
(Eq. 8) and its motion model (Eq. 9 with the intersection rule), vectorised over any number of
particles.

A :class:`DirectedRoads` is the directed view of a :class:`~searchtrack.models.roads.RoadNetwork`:
undirected edge ``k`` (``edges[k, 0] < edges[k, 1]``) gives directed edge ``2k`` from
``edges[k, 0]`` to ``edges[k, 1]`` and ``2k + 1`` back, so the reverse of ``d`` is ``d ^ 1``. A
position is ``(d, s)`` with ``0 ≤ s ≤ length[d]`` the distance travelled from the tail of ``d``;
:meth:`DirectedRoads.point` is the paper's ``G(x)``.

The motion model (:class:`RoadMotion`, Eq. 9): ``s ← s + max(v_e + ν, 0)·δt`` with
``ν ~ N(0, σ_ν²)`` drawn afresh every step (so the variance of the position grows by
``σ_ν² δt²`` per step, as Lemma 2 of the paper assumes). A particle that passes the head node
carries the leftover distance onto a successor drawn uniformly from the edges leaving that node,
the reverse edge excluded (no U-turns); at a dead end the reverse edge is the only successor. The
paper leaves leftover distance, dead ends and negative speeds open; these are our choices: the
leftover is carried over (so the distance covered does not depend on the map's node spacing),
U-turns only at dead ends, and a target never drives backwards.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.roads import RoadNetwork


@dataclass(frozen=True, eq=False)
class DirectedRoads:
    """The directed view of a road network (two directed edges per road).

    Parameters
    ----------
    network
        The undirected road network.

    Attributes
    ----------
    tail, head
        ``(2m,)`` node of each directed edge's start and end.
    length
        ``(2m,)`` length (m) of each directed edge.
    successors, successor_ptr
        The edges a particle may take at the head of edge ``d`` are
        ``successors[successor_ptr[d]:successor_ptr[d + 1]]`` (never ``d ^ 1`` unless the head is a
        dead end).
    out_edges, out_ptr
        Every directed edge leaving node ``v`` (U-turns included), in increasing order:
        ``out_edges[out_ptr[v]:out_ptr[v + 1]]`` (:meth:`leaving`).
    """

    network: RoadNetwork
    tail: IntArray = field(init=False, repr=False)
    head: IntArray = field(init=False, repr=False)
    length: FloatArray = field(init=False, repr=False)
    successors: IntArray = field(init=False, repr=False)
    successor_ptr: IntArray = field(init=False, repr=False)
    out_edges: IntArray = field(init=False, repr=False)
    out_ptr: IntArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        net = self.network
        m = net.n_edges
        tail = np.empty(2 * m, dtype=np.int64)
        head = np.empty(2 * m, dtype=np.int64)
        tail[0::2], head[0::2] = net.edges[:, 0], net.edges[:, 1]
        tail[1::2], head[1::2] = net.edges[:, 1], net.edges[:, 0]
        length = np.repeat(np.asarray(net.lengths_m, dtype=np.float64), 2)
        # Out-edges of every node, in CSR form (sorted by tail).
        order = np.argsort(tail, kind="stable").astype(np.int64)
        out_ptr = np.zeros(net.n_nodes + 1, dtype=np.int64)
        np.add.at(out_ptr, tail + 1, 1)
        out_ptr = np.cumsum(out_ptr)
        # Successors of d: out-edges of head[d] except d ^ 1, unless that is the only one.
        counts = out_ptr[head + 1] - out_ptr[head]
        n_succ = np.where(counts > 1, counts - 1, counts)
        ptr = np.zeros(2 * m + 1, dtype=np.int64)
        ptr[1:] = np.cumsum(n_succ)
        succ = np.empty(int(ptr[-1]), dtype=np.int64)
        for d in range(2 * m):
            outs = order[out_ptr[head[d]]:out_ptr[head[d] + 1]]
            if outs.size > 1:
                outs = outs[outs != (d ^ 1)]
            succ[ptr[d]:ptr[d + 1]] = outs
        for name, value in (("tail", tail), ("head", head), ("length", length),
                            ("successors", succ), ("successor_ptr", ptr),
                            ("out_edges", order), ("out_ptr", out_ptr)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    def leaving(self, node: int) -> IntArray:
        """The directed edges leaving ``node`` (U-turns included), in increasing order."""
        return self.out_edges[self.out_ptr[node]:self.out_ptr[node + 1]]

    @property
    def n_edges(self) -> int:
        """Number of directed edges (twice the roads)."""
        return int(self.tail.size)

    @cached_property
    def total_length_m(self) -> float:
        """Total directed road length (m): each two-way road counted twice."""
        return float(self.length.sum())

    @cached_property
    def cum_length(self) -> FloatArray:
        """``(2m,)`` cumulative directed edge lengths (m): the inverse CDF of a uniform position
        by length (Eq. 1), read-only."""
        out = np.cumsum(self.length)
        out.setflags(write=False)
        return out

    @cached_property
    def successor_count(self) -> IntArray:
        """``(2m,)`` number of successors of each directed edge (≥ 1)."""
        out = np.diff(self.successor_ptr)
        out.setflags(write=False)
        return out

    @cached_property
    def tail_xy(self) -> FloatArray:
        """``(2m, 2)`` planar point (m) of each directed edge's tail, C-contiguous, read-only."""
        out = np.ascontiguousarray(self.network.coords[self.tail], dtype=np.float64)
        out.setflags(write=False)
        return out

    @cached_property
    def step_xy(self) -> FloatArray:
        """``(2m, 2)`` planar displacement per metre of arc on each directed edge,
        ``(p_head − p_tail) / length``, so that ``G(d, s) = tail_xy[d] + s · step_xy[d]``."""
        coords = self.network.coords
        out = np.ascontiguousarray((coords[self.head] - coords[self.tail])
                                   / self.length[:, None], dtype=np.float64)
        out.setflags(write=False)
        return out

    def disc_intervals(self, centre_xy: FloatArray,
                       radius_m: float) -> tuple[FloatArray, FloatArray]:
        """The arc of every directed edge inside the disc of ``radius_m`` around ``centre_xy``.

        Returns ``(s0, s1)``, each ``(2m,)``: edge ``d`` is inside the disc for
        ``s0[d] ≤ s ≤ s1[d]``; ``s0 = s1`` where the edge misses the disc. ``(s1 − s0).sum()`` is
        the directed road length (m) in the disc.
        """
        c = checks.finite_array("centre_xy", centre_xy, (2,))
        r = checks.non_negative("radius_m", radius_m)
        rel = self.tail_xy - c
        ab = self.step_xy * self.length[:, None]
        a2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
        b = np.einsum("ij,ij->i", ab, rel) / a2
        disc = b * b - (np.einsum("ij,ij->i", rel, rel) - r * r) / a2
        root = np.sqrt(np.maximum(disc, 0.0))
        t0 = np.clip(-b - root, 0.0, 1.0)
        t1 = np.clip(-b + root, 0.0, 1.0)
        t1 = np.where(disc > 0.0, np.maximum(t1, t0), t0)
        return t0 * self.length, t1 * self.length

    def check_positions(self, edge: IntArray, s: FloatArray) -> None:
        """Raise :class:`InvalidInputError` unless ``(edge, s)`` are valid positions."""
        if edge.shape != s.shape:
            raise InvalidInputError("s", s.shape, f"must have the shape of edge {edge.shape}")
        if edge.size and (edge.min() < 0 or edge.max() >= self.n_edges):
            raise InvalidInputError("edge", int(edge.max()),
                                    f"directed edges are 0…{self.n_edges - 1}")
        if not np.all(np.isfinite(s)) or (s.size and (s.min() < 0.0 or
                                                     np.any(s > self.length[edge] + 1e-9))):
            raise InvalidInputError("s", "out of range", "must lie in [0, length of the edge]")

    def point(self, edge: IntArray, s: FloatArray) -> FloatArray:
        """``G(x)`` (paper §2.2): the planar points ``(..., 2)`` of positions ``(edge, s)``."""
        coords = self.network.coords
        a, b = coords[self.tail[edge]], coords[self.head[edge]]
        f = (s / self.length[edge])[..., None]
        return a + f * (b - a)

    def uniform(self, shape: int | tuple[int, ...],
                rng: np.random.Generator) -> tuple[IntArray, FloatArray]:
        """Positions drawn uniformly by length over the network (paper Eq. 1): the directed edge
        with probability proportional to its length, then ``s ~ U(0, length)``."""
        cdf = self.cum_length
        u = rng.random(shape) * cdf[-1]
        edge = np.minimum(np.searchsorted(cdf, u, side="right"), self.n_edges - 1)
        s = rng.random(shape) * self.length[edge]
        return edge.astype(np.int64), s

    def nearest(self, points: FloatArray) -> tuple[IntArray, FloatArray]:
        """The road positions closest to planar ``points`` ``(k, 2)``: the directed edge (of the
        two directions, the one from the lower node) and arc length of the closest point."""
        pts = checks.points("points", points)
        coords = self.network.coords
        a = coords[self.tail[0::2]]
        ab = coords[self.head[0::2]] - a
        denom = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12)
        t = np.clip(np.einsum("kij,ij->ki", pts[:, None, :] - a[None], ab) / denom, 0.0, 1.0)
        proj = a[None] + t[..., None] * ab[None]
        k = np.argmin(np.sum((proj - pts[:, None, :]) ** 2, axis=-1), axis=1)
        rows = np.arange(pts.shape[0])
        return 2 * k, t[rows, k] * self.length[2 * k]

    def advance(self, edge: IntArray, s: FloatArray, distance: FloatArray,
                rng: np.random.Generator) -> tuple[IntArray, FloatArray]:
        """Move positions ``distance ≥ 0`` metres forward, turning at random at nodes (no
        U-turns except at dead ends, leftover distance carried over). Returns new arrays."""
        shape = np.shape(s)
        e = np.array(edge, dtype=np.int64, copy=True).reshape(-1)
        pos = (np.asarray(s, dtype=np.float64) + distance).reshape(-1)
        over = np.flatnonzero(pos > self.length[e])
        while over.size:
            pos[over] -= self.length[e[over]]
            d = e[over]
            pick = (rng.random(over.size) * self.successor_count[d]).astype(np.int64)
            e[over] = self.successors[self.successor_ptr[d] + pick]
            over = over[pos[over] > self.length[e[over]]]
        return e.reshape(shape), pos.reshape(shape)


@dataclass(frozen=True)
class RoadMotion:
    """Constant speed along the road with per-step velocity noise (paper Eq. 9).

    Parameters
    ----------
    speed_mps
        Nominal speed ``v_e`` (m/s), the same on every road, ≥ 0 (10 m/s in the paper's
        simulation).
    sigma_mps
        ``σ_ν`` (m/s), ≥ 0: standard deviation of the velocity noise drawn each step.
    """

    speed_mps: float = 10.0
    sigma_mps: float = 4.0

    def __post_init__(self) -> None:
        checks.non_negative("speed_mps", self.speed_mps)
        checks.non_negative("sigma_mps", self.sigma_mps)

    def step(self, roads: DirectedRoads, edge: IntArray, s: FloatArray, dt_s: float,
             rng: np.random.Generator) -> tuple[IntArray, FloatArray]:
        """Propagate positions by ``dt_s`` seconds; returns new ``(edge, s)`` arrays of the same
        shape."""
        dt = checks.non_negative("dt_s", dt_s)
        speed = self.speed_mps + self.sigma_mps * rng.standard_normal(np.shape(s))
        return roads.advance(edge, s, np.maximum(speed, 0.0) * dt, rng)


@dataclass(frozen=True)
class CourierRoadMotion:
    """Drives and stops along the roads, a particle carrying its speed (beyond paper 000).

    The jump-Markov form of a courier (:class:`~searchtrack.models.targets.CourierModel`): each
    particle has a speed ``v`` (0 while stopped). Every step of ``δt`` a driving particle stops
    with chance ``1 − exp(−δt/T_d)`` and a stopped one drives off with chance
    ``1 − exp(−δt/T_s)`` at a speed uniform in ``[v_lo, v_hi]``, kept until its next stop; then
    it moves ``v·δt`` along the roads, turning at nodes as :class:`RoadMotion` does. Drives and
    stops last exponential times of means ``T_d`` and ``T_s``; a share ``T_d / (T_d + T_s)`` of
    the time is spent driving. Unlike Eq. 9, whose noise is drawn afresh every step, a cloud
    keeps both its stopped particles and its fast and slow drivers, so it covers a target that
    stopped or drives at its own speed for a long time.

    Parameters
    ----------
    min_speed_mps, max_speed_mps
        ``v_lo ≤ v_hi`` (m/s), ``v_lo ≥ 0``, ``v_hi > 0``.
    mean_drive_s, mean_stop_s
        ``T_d`` and ``T_s`` (s), > 0.
    """

    min_speed_mps: float = 5.0
    max_speed_mps: float = 10.0
    mean_drive_s: float = 60.0
    mean_stop_s: float = 17.5

    def __post_init__(self) -> None:
        lo = checks.non_negative("min_speed_mps", self.min_speed_mps)
        if checks.positive("max_speed_mps", self.max_speed_mps) < lo:
            raise InvalidInputError("max_speed_mps", self.max_speed_mps,
                                    f"must be ≥ min_speed_mps={lo!r}")
        checks.positive("mean_drive_s", self.mean_drive_s)
        checks.positive("mean_stop_s", self.mean_stop_s)

    @property
    def driving_share(self) -> float:
        """``T_d / (T_d + T_s)``: the stationary chance that a particle is driving."""
        return self.mean_drive_s / (self.mean_drive_s + self.mean_stop_s)

    def switch_chances(self, dt_s: float) -> tuple[float, float]:
        """``(stop, drive off)`` chances in a step of ``dt_s`` seconds."""
        dt = checks.non_negative("dt_s", dt_s)
        return -math.expm1(-dt / self.mean_drive_s), -math.expm1(-dt / self.mean_stop_s)

    def initial_speeds(self, shape: int | tuple[int, ...],
                       rng: np.random.Generator) -> FloatArray:
        """Speeds from the stationary law: driving with chance :attr:`driving_share`, at a
        uniform speed (two uniforms per particle: the mode, then the speed)."""
        mode, u = rng.random(shape), rng.random(shape)
        return np.where(mode < self.driving_share,
                        self.min_speed_mps + u * (self.max_speed_mps - self.min_speed_mps), 0.0)

    def step(self, roads: DirectedRoads, edge: IntArray, s: FloatArray, v: FloatArray,
             dt_s: float, rng: np.random.Generator) -> tuple[IntArray, FloatArray, FloatArray]:
        """Switch modes, then move ``dt_s`` seconds on; returns new ``(edge, s, v)`` arrays of
        the same shape. Draws two uniforms per particle (the switch, the new speed), then one
        per node crossing."""
        stop, go = self.switch_chances(dt_s)
        shape = np.shape(s)
        mode, u = rng.random(shape), rng.random(shape)
        speed = np.asarray(v, dtype=np.float64)
        driving = speed > 0.0
        new_v = np.where(driving, np.where(mode < stop, 0.0, speed),
                         np.where(mode < go, self.min_speed_mps
                                  + u * (self.max_speed_mps - self.min_speed_mps), 0.0))
        edge2, s2 = roads.advance(edge, s, new_v * dt_s, rng)
        return edge2, s2, new_v
