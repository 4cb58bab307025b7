"""Artificial-potential forces that steer the UAVs (thesis 001, §5.2–§5.5).

All functions are pure and vectorised over the ``O`` UAVs; forces are ``(O, 2)`` arrays in the
thesis's "internally scaled" units (unit mass), fed to
:func:`searchtrack.models.dubins.step_force`, which turns them into controls by (5.3)–(5.4).

- :class:`GradientField` — the likelihood-gradient force ∇R (5.6)–(5.7) and its ``n_max``.
- :func:`pauli_force` — the Pauli (``r⁻¹²``) repulsion (5.8)–(5.9) and (5.14), **with the sign
  corrected** so that it repels (the printed (5.9) attracts).
- :func:`spring_force` — the drift-correcting spring ∇Q (5.10)–(5.11), rest length ``ρ``, and the
  zero-rest-length springs ∇L (5.13) and ∇W (5.32) with ``rest_m = 0``.
- :func:`default_spring_k`, :func:`default_loiter_k` — the constants the thesis never gives.
- :func:`coverage_force` — a push away from road covered recently, toward road that was not (a
  term of this library for searching UAVs; the thesis has none).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core.checks import positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.roads import RoadNetwork

#: Default cap on a single Pauli magnitude; (5.9) grows as r⁻¹³ and is infinite at r = 0.
PAULI_CAP = 1.0e6


def _points(name: str, value: ArrayLike) -> FloatArray:
    xy = np.asarray(value, dtype=np.float64)
    if xy.ndim != 2 or xy.shape[1] != 2 or not np.all(np.isfinite(xy)):
        raise InvalidInputError(name, value, "must be finite points of shape (O, 2) (m)")
    return xy


def default_spring_k(sensor_range_m: float, typical_gradient: float = 4.0) -> float:
    """``K`` of ∇Q (5.11): a spring stretched by ``ρ`` pulls as hard as a typical ``|Δφ|``.

    The thesis never gives ``K``. One negative look changes a node's LLR by
    ``m(ζ − m/2) ≈ −m²/2`` (≈ −4.3 for the §6.1 sensor, ``m`` = 2.93), so across an edge at the
    footprint rim ``|Δφ|`` is of order 4: ``K = typical_gradient / ρ`` makes a drift of one
    footprint radius beyond the rest length cost as much as following one fresh gradient.
    """
    return positive("typical_gradient", typical_gradient) / positive("sensor_range_m",
                                                                       sensor_range_m)


def default_loiter_k(sensor_range_m: float, speed_mps: float) -> float:
    """``K`` of the zero-rest springs ∇L (5.13) and ∇W (5.32): orbit radius ``ρ/2``.

    With unit mass, a UAV at speed ``S`` circling the anchor at radius ``d`` needs a centripetal
    force ``S²/d``; the spring gives ``K d``, so the natural orbit has ``d = S/√K``. Choosing
    ``K = (2S/ρ)²`` keeps the loitering UAV's footprint over the anchor node (the thesis never
    gives ``K``). At 35.76 m/s and ρ = 120 m, ``K`` ≈ 0.36 and the turn rate
    needed is 0.6 rad/s, inside the 70°/s limit.
    """
    rho = positive("sensor_range_m", sensor_range_m)
    s = positive("speed_mps", speed_mps)
    return (2.0 * s / rho) ** 2


@dataclass(frozen=True, eq=False)
class GradientField:
    """Per-network structures of the likelihood-gradient force ∇R (5.6)–(5.7), built once.

    Holds the node → incident-edge lists in CSR form, so one call costs a KD-tree ball query per
    UAV plus work linear in the edges around the footprints.
    """

    network: RoadNetwork
    _indptr: IntArray = field(init=False, repr=False)
    _edge_of: IntArray = field(init=False, repr=False)
    _unit: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.network, RoadNetwork):
            raise InvalidInputError("network", self.network, "must be a RoadNetwork")
        net = self.network
        m = net.n_edges
        ends = net.edges.T.reshape(-1)  # heads then tails
        edge_ids = np.tile(np.arange(m, dtype=np.int64), 2)
        order = np.argsort(ends, kind="stable")
        counts = np.bincount(ends, minlength=net.n_nodes)
        indptr = np.zeros(net.n_nodes + 1, dtype=np.int64)
        np.cumsum(counts, out=indptr[1:])
        d = net.coords[net.edges[:, 0]] - net.coords[net.edges[:, 1]]  # tail → head
        norm = np.hypot(d[:, 0], d[:, 1])
        unit = np.divide(d, norm[:, None], out=np.zeros_like(d), where=norm[:, None] > 0)
        set_ = object.__setattr__
        set_(self, "_indptr", indptr)
        set_(self, "_edge_of", edge_ids[order])
        set_(self, "_unit", unit)

    def edge_differences(self, llr: ArrayLike) -> FloatArray:
        """``Δφ = Bᵀφ`` (5.6): ``φ(head) − φ(tail)`` per edge."""
        phi = np.asarray(llr, dtype=np.float64)
        if phi.shape != (self.network.n_nodes,) or not np.all(np.isfinite(phi)):
            raise InvalidInputError("llr", llr,
                                    f"must be finite of shape ({self.network.n_nodes},)")
        e = self.network.edges
        return np.asarray(phi[e[:, 0]] - phi[e[:, 1]], dtype=np.float64)

    def force(
        self, uav_xy_m: ArrayLike, llr: ArrayLike, sensor_range_m: float,
        rng: np.random.Generator,
    ) -> tuple[FloatArray, IntArray]:
        """∇R (5.7) per UAV and ``n_max``, the higher end of the chosen edge ``μ``.

        Candidate edges are those incident to the nodes within ``ρ`` of the UAV; ``μ`` maximises
        ``|Δφ|``, ties drawn uniformly with ``rng``. The force is ``|Δφ(μ)|`` times the unit vector
        from the lower to the higher end (on a flat edge, ``Δφ = 0``: zero force, ``n_max`` = its
        head). With no node within ``ρ`` the force is zero and ``n_max`` is the nearest node.

        Returns
        -------
        force, n_max
            ``(O, 2)`` forces and ``(O,)`` node indices.
        """
        xy = _points("uav_xy_m", uav_xy_m)
        rho = positive("sensor_range_m", sensor_range_m)
        dphi = self.edge_differences(llr)
        n_uav = xy.shape[0]
        force = np.zeros((n_uav, 2))
        n_max = np.zeros(n_uav, dtype=np.int64)
        if n_uav == 0:
            return force, n_max
        point, node = self.network.nodes_within(xy, rho)
        starts, stops = self._indptr[node], self._indptr[node + 1]
        sizes = stops - starts
        pair_point = np.repeat(point, sizes)
        offsets = np.arange(int(sizes.sum())) - np.repeat(np.cumsum(sizes) - sizes, sizes)
        pair_edge = self._edge_of[np.repeat(starts, sizes) + offsets]
        key = np.unique(pair_point * self.network.n_edges + pair_edge)  # one entry per edge
        pair_point, pair_edge = key // self.network.n_edges, key % self.network.n_edges
        draws = rng.random(key.size)  # drawn every call: deterministic for a seed
        covered = np.zeros(n_uav, dtype=bool)
        covered[pair_point] = True
        if not covered.all():
            n_max[~covered] = self.network.nearest_nodes(xy[~covered])
        if key.size == 0:
            return force, n_max
        mag = np.abs(dphi[pair_edge])
        best = np.full(n_uav, -np.inf)
        np.maximum.at(best, pair_point, mag)
        draws[mag < best[pair_point]] = -1.0  # only tied maxima compete
        order = np.lexsort((draws, pair_point))
        last = np.flatnonzero(np.r_[pair_point[order][1:] != pair_point[order][:-1], True])
        chosen = order[last]
        uav, edge = pair_point[chosen], pair_edge[chosen]
        diff = dphi[edge]
        force[uav] = diff[:, None] * self._unit[edge]  # Δφ(μ) (ψ(n₁) − ψ(n₂))/‖·‖, (5.7)
        heads, tails = self.network.edges[edge, 0], self.network.edges[edge, 1]
        n_max[uav] = np.where(diff >= 0.0, heads, tails)
        return force, n_max


def pauli_force(
    uav_xy_m: ArrayLike, sigma_m: float, *, epsilon: float = 1.0,
    repellers: ArrayLike | None = None, cap: float = PAULI_CAP,
) -> FloatArray:
    """Repulsion ``Σᵢ 48 ε σ¹² r⁻¹³ r̂`` on each UAV, ``r̂`` pointing away from UAV ``i``.

    The gradient of the Pauli potential (5.8), with (5.9)'s sign corrected to repel.

    Parameters
    ----------
    uav_xy_m
        ``(O, 2)`` positions (m).
    sigma_m, epsilon
        ``σ`` (the thesis uses ``2ρ``) and ``ε`` (1).
    repellers
        ``(O, O)`` boolean, ``repellers[j, i]`` when UAV ``i`` pushes UAV ``j`` (the diagonal is
        ignored); ``None`` means every other UAV, as in (5.9). (5.14) restricts it for
        loitering UAVs.
    cap
        Largest magnitude of one pair's force: (5.9) diverges as ``r → 0``. Coincident UAVs are
        pushed apart along ±x (the higher index toward +x).
    """
    xy = _points("uav_xy_m", uav_xy_m)
    sigma = positive("sigma_m", sigma_m)
    eps = positive("epsilon", epsilon)
    cap_ = positive("cap", cap)
    n = xy.shape[0]
    if repellers is None:
        mask = ~np.eye(n, dtype=bool)
    else:
        mask = np.asarray(repellers)
        if mask.shape != (n, n) or mask.dtype != np.bool_:
            raise InvalidInputError("repellers", repellers, f"must be a boolean ({n}, {n}) array")
        mask = mask & ~np.eye(n, dtype=bool)
    d = xy[:, None, :] - xy[None, :, :]  # d[j, i] = ξʲ − ξⁱ
    r = np.hypot(d[..., 0], d[..., 1])
    idx = np.arange(n)
    coincident = (r == 0.0) & mask
    unit = np.divide(d, r[..., None], out=np.zeros_like(d), where=r[..., None] > 0)
    unit[..., 0] = np.where(coincident, np.sign(idx[:, None] - idx[None, :]), unit[..., 0])
    with np.errstate(divide="ignore", over="ignore"):
        mag = 48.0 * eps * np.exp(12.0 * np.log(sigma) - 13.0 * np.log(r))
    mag = np.where(mask, np.minimum(np.nan_to_num(mag, posinf=cap_), cap_), 0.0)
    return np.asarray((mag[..., None] * unit).sum(axis=1), dtype=np.float64)


def spring_force(
    uav_xy_m: ArrayLike, anchor_xy_m: ArrayLike, k: float, rest_m: float = 0.0
) -> FloatArray:
    """``−K(‖ξ − a‖ − rest) (ξ − a)/‖ξ − a‖`` toward (or away from) each UAV's anchor ``a``.

    ``rest_m = ρ`` is the drift-correcting spring ∇Q (5.11), anchored at ``n_max``: it pushes
    out inside ``ρ`` and pulls beyond. ``rest_m = 0`` is the loiter spring ∇L (5.13) and the
    route spring ∇W (5.32), ``−K(ξ − a)``. A UAV exactly on its anchor feels no force.
    """
    xy = _points("uav_xy_m", uav_xy_m)
    anchor = _points("anchor_xy_m", anchor_xy_m)
    if anchor.shape != xy.shape:
        raise InvalidInputError("anchor_xy_m", anchor_xy_m, f"must have shape {xy.shape}")
    kk = positive("k", k)
    if not (math.isfinite(rest_m) and rest_m >= 0.0):
        raise InvalidInputError("rest_m", rest_m, "must be finite and ≥ 0 (m)")
    d = xy - anchor
    if rest_m == 0.0:
        return np.asarray(-kk * d, dtype=np.float64)
    r = np.hypot(d[:, 0], d[:, 1])
    unit = np.divide(d, r[:, None], out=np.zeros_like(d), where=r[:, None] > 0)
    return np.asarray(-kk * (r - rest_m)[:, None] * unit, dtype=np.float64)


def coverage_force(network: RoadNetwork, uav_xy_m: ArrayLike, coverage: ArrayLike,
                   inner_m: float, outer_m: float) -> FloatArray:
    """Per UAV, the unit-bounded push away from recently covered road (a rule of this library).

    Over the road nodes ``v`` of the ring ``inner_m < ‖ψ(v) − ξ‖ ≤ outer_m`` around UAV ``ξ``
    (the UAV's own footprint, always just covered, left out), with ``c(v) ∈ [0, 1]`` the node's
    coverage and ``c̄`` its mean over the ring,

        ``F = Σ_v (c̄ − c(v)) (ψ(v) − ξ)/‖ψ(v) − ξ‖ / |ring|``:

    nodes covered more than the ring's average repel, less than average attract, so the force
    points toward the ring's least-covered road; it vanishes when the ring is evenly covered
    (e.g. never) or holds no node, and ``‖F‖ ≤ 1``. Vectorised over UAVs and ring nodes.

    Parameters
    ----------
    coverage
        ``(n,)`` coverage of each road node in ``[0, 1]`` (1: covered just now).
    inner_m, outer_m
        The ring's radii (m), ``0 ≤ inner_m < outer_m``.
    """
    xy = _points("uav_xy_m", uav_xy_m)
    c = np.asarray(coverage, dtype=np.float64)
    if c.shape != (network.n_nodes,) or not np.all((c >= 0.0) & (c <= 1.0)):
        raise InvalidInputError("coverage", coverage,
                                f"must be ({network.n_nodes},) values in [0, 1]")
    outer = positive("outer_m", outer_m)
    if not (math.isfinite(inner_m) and 0.0 <= inner_m < outer):
        raise InvalidInputError("inner_m", inner_m, f"must be in [0, outer_m={outer:g}) (m)")
    n_uav = xy.shape[0]
    force = np.zeros((n_uav, 2))
    point, node = network.nodes_within(xy, outer)
    d = network.coords[node] - xy[point]
    r = np.hypot(d[:, 0], d[:, 1])
    ring = r > inner_m
    point, node, d, r = point[ring], node[ring], d[ring], r[ring]
    if point.size == 0:
        return force
    size = np.bincount(point, minlength=n_uav).astype(np.float64)
    mean = np.bincount(point, weights=c[node], minlength=n_uav) / np.maximum(size, 1.0)
    w = (mean[point] - c[node]) / r / size[point]  # r > inner_m ≥ 0: no division by 0
    force[:, 0] = np.bincount(point, weights=w * d[:, 0], minlength=n_uav)
    force[:, 1] = np.bincount(point, weights=w * d[:, 1], minlength=n_uav)
    return force
