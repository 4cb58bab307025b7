"""A robust motion prior for the road particle filters: targets may leave their predicted cloud.

Beyond Moore et al. 2021. Paper 000's motion model (Eq. 9) moves every particle along the roads,
so a filter whose particles were all removed from a stretch of road by negative information
(Eq. 11), or that split at junctions and followed the wrong branches, has no particle left where
the target is: a detection there finds nothing to weigh and is lost, however sure the sensor.

The prior here mixes the motion model with a jump anywhere on the roads:

    p̃(x_k | x_{k−1}) = (1 − ε) p(x_k | x_{k−1}) + ε u(x_k),   ε = 1 − exp(−λ Δt),

with ``u`` uniform over the directed road length ``L`` and ``λ`` the jump rate (per second). The
filters stay particle filters of this model: at each update the jump component ``ε u`` is
represented by ``K`` draws from a proposal ``g`` weighed back to it, and joined to the cloud.
With the measurement likelihood ``ℓ(x)`` of the scan and the cloud's weights ``w`` (before the
update),

    cloud particle n:  (1 − ε) w_n ℓ(x_n),        jump draw j:  ε ℓ(x_j) u(x_j) / (K g(x_j)),

whose expected total is the predictive likelihood ``(1 − ε) Σ_n w_n ℓ(x_n) + ε ∫ ℓ u`` (the
draws are an unbiased importance-sampling estimate of the second term, for any ``g`` positive
where ``ℓ u`` is); the union is resampled back to ``N``, or to its KLD-sampling count
(low-variance). The proposal is where the measurement points:

- a detection ``y`` (Eq. 10): ``g = (1 − α)·uniform on the road within ρ of y + α·u``, with
  ``ρ`` a few sensor standard deviations (the disc carries all but ``exp(−ρ²/2σ²)`` of the
  Gaussian term; the ``α·u`` part covers the clutter floor everywhere);
- a miss (Eq. 11): ``g = u``.

The integrals the association and the history weights need are exact: ``∫ ℓ u`` of a detection
is ``(gain · ∫_roads exp(−‖G(x) − y‖²/2σ²) dx + P_FA c L) / L``, the road integral summed edge by
edge in closed form with ``erf``; of a miss, ``1 − (1 − P_FN) L_in / L`` with ``L_in`` the road
length inside the negative-information disc.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import erf

from searchtrack.core import checks
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate import road_filter_kernels as kern
from searchtrack.estimate.road_pf import RoadClouds
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import DirectedRoads


@dataclass(frozen=True)
class TargetJumps:
    """The jump component of the robust road prior and its proposals.

    Parameters
    ----------
    rate_per_s
        ``λ ≥ 0``: the rate (1/s) at which a target leaves its predicted cloud for anywhere on
        the roads; 0 gives paper 000's prior.
    detection_share, miss_share
        Jump draws per update, as a share of the cloud's ``N`` (at least one draw), for a
        detection and for a miss.
    radius_sigmas
        ``ρ`` of the detection proposal, in standard deviations of the sensor's position noise.
    global_share
        ``α``: the share of the detection proposal drawn uniformly over all roads.
    """

    rate_per_s: float = 0.02
    detection_share: float = 0.2
    miss_share: float = 0.02
    radius_sigmas: float = 5.0
    global_share: float = 0.1

    def __post_init__(self) -> None:
        object.__setattr__(self, "rate_per_s", checks.non_negative("rate_per_s",
                                                                   self.rate_per_s))
        for name in ("detection_share", "miss_share"):
            object.__setattr__(self, name, checks.real(name, getattr(self, name), low=0.0,
                                                       high=1.0, low_open=True))
        object.__setattr__(self, "radius_sigmas", checks.positive("radius_sigmas",
                                                                  self.radius_sigmas))
        object.__setattr__(self, "global_share", checks.real(
            "global_share", self.global_share, low=0.0, high=1.0, low_open=True))

    @classmethod
    def at_rate(cls, rate_per_s: float) -> TargetJumps | None:
        """The jumps of rate ``rate_per_s`` with the default proposals; ``None`` (paper 000's
        prior, nothing drawn) at rate 0."""
        return cls(rate_per_s=rate_per_s) if rate_per_s != 0.0 else None

    def probability(self, dt_s: float) -> float:
        """``ε = 1 − exp(−λ Δt)``: the chance of a jump in a step of ``dt_s`` seconds."""
        return float(-math.expm1(-self.rate_per_s * checks.non_negative("dt_s", dt_s)))

    def draws(self, n_particles: int, detection: bool) -> int:
        """``K``: jump draws joined to a cloud of ``n_particles``."""
        share = self.detection_share if detection else self.miss_share
        return max(1, math.ceil(share * n_particles))


def road_gaussian_integral(roads: DirectedRoads, y: FloatArray, sigma2_m2: float) -> float:
    """``∫ exp(−‖G(x) − y‖² / 2σ²) dx`` over the directed roads (m), in closed form per edge
    (the numba kernel :func:`~searchtrack.estimate.road_filter_kernels.gaussian_road_integral`;
    the NumPy form is :func:`gaussian_integral_reference`)."""
    return float(kern.gaussian_road_integral(roads.tail_xy, roads.step_xy, roads.length,
                                             float(y[0]), float(y[1]), float(sigma2_m2)))


def gaussian_integral_reference(roads: DirectedRoads, y: FloatArray, sigma2_m2: float) -> float:
    """:func:`road_gaussian_integral` in NumPy: with ``h`` the distance from ``y`` to an edge's
    line and ``t*`` the arc of its foot point, each edge gives
    ``exp(−h²/2σ²) σ √(π/2) [erf((ℓ − t*)/σ√2) + erf(t*/σ√2)]``."""
    rel = np.asarray(y, dtype=np.float64) - roads.tail_xy          # (2m, 2)
    t_star = np.einsum("ij,ij->i", rel, roads.step_xy)             # arc of the foot point
    h2 = np.maximum(np.einsum("ij,ij->i", rel, rel) - t_star * t_star, 0.0)
    sigma = math.sqrt(sigma2_m2)
    scale = sigma * math.sqrt(2.0)
    along = erf((roads.length - t_star) / scale) + erf(t_star / scale)
    return float(np.sum(np.exp(-0.5 * h2 / sigma2_m2) * along) * sigma * math.sqrt(0.5 * math.pi))


def disc_intervals(roads: DirectedRoads, centre_xy: FloatArray,
                   radius_m: float) -> tuple[FloatArray, FloatArray, float]:
    """:meth:`~searchtrack.models.road_particles.DirectedRoads.disc_intervals` by the numba
    kernel, with the road length in the disc: ``(s0, s1, Σ (s1 − s0))``."""
    s0 = np.empty(roads.n_edges)
    s1 = np.empty(roads.n_edges)
    inside = kern.disc_intervals(roads.tail_xy, roads.step_xy, roads.length,
                                 float(centre_xy[0]), float(centre_xy[1]), float(radius_m),
                                 s0, s1)
    return s0, s1, float(inside)


def detection_prior_likelihood(roads: DirectedRoads, sensor: DiscSensor, y: FloatArray,
                               clutter_density: float) -> float:
    """``∫ p(y | x) u(x) dx``: the likelihood of detection ``y`` (Eq. 10) for a target anywhere
    on the roads."""
    total = roads.total_length_m
    return (sensor.detection_gain * road_gaussian_integral(roads, y, sensor.sigma2_m2) / total
            + sensor.p_fa * clutter_density)


def miss_prior_likelihood(roads: DirectedRoads, sensor: DiscSensor, uav_xy: FloatArray) -> float:
    """``∫ p(z | x) u(x) dx``: the no-detection likelihood (Eq. 11) of a target anywhere on the
    roads, ``1 − (1 − P_FN) L_in / L``."""
    inside = disc_intervals(roads, uav_xy, sensor.negative_radius_m)[2]
    return 1.0 - (1.0 - sensor.p_fn) * inside / roads.total_length_m


def detection_proposal(roads: DirectedRoads, sensor: DiscSensor, jumps: TargetJumps,
                       y: FloatArray) -> tuple[FloatArray, FloatArray, float, float, float]:
    """The detection proposal ``g`` around ``y``: ``(s0, s1)`` the arc of every directed edge
    inside its disc, the road length ``L_disc`` in it, the share ``α`` of ``u`` (1 when the
    disc holds no road) and the disc's radius ``ρ`` (m)."""
    radius = jumps.radius_sigmas * math.sqrt(sensor.sigma2_m2)
    s0, s1, l_disc = disc_intervals(roads, y, radius)
    return s0, s1, l_disc, jumps.global_share if l_disc > 0.0 else 1.0, radius


def near_detection(roads: DirectedRoads, sensor: DiscSensor, jumps: TargetJumps, y: FloatArray,
                   uniforms: FloatArray) -> tuple[IntArray, FloatArray, FloatArray]:
    """Draws ``(edge, s)`` from the detection proposal ``g`` around ``y`` and the ratio
    ``u(x) / g(x)`` of each (the importance weight before ``ℓ`` and ``ε / K``), from
    ``uniforms`` ``(3, ...)`` in ``[0, 1)``: the component (``u`` below ``α``, else the disc),
    the edge by length, the arc along it. The NumPy reference of
    :func:`~searchtrack.estimate.road_filter_kernels.detection_jumps`."""
    s0, s1, l_disc, alpha, radius = detection_proposal(roads, sensor, jumps, y)
    pick, u_edge, u_s = uniforms
    total = roads.total_length_m
    local = (pick >= alpha) & (l_disc > 0.0)
    cdf = roads.cum_length
    edge = np.minimum(np.searchsorted(cdf, u_edge * cdf[-1], side="right"), roads.n_edges - 1)
    s = u_s * roads.length[edge]
    if np.any(local):
        inside = s1 - s0
        cum = np.cumsum(inside)
        e = np.minimum(np.searchsorted(cum, u_edge[local] * cum[-1], side="right"),
                       inside.size - 1)
        edge[local] = e
        s[local] = s0[e] + u_s[local] * inside[e]
    pts = roads.point(edge, s)
    near = np.einsum("...i,...i->...", pts - y, pts - y) <= radius * radius
    g = alpha / total + np.where(near, (1.0 - alpha) / l_disc if l_disc > 0.0 else 0.0, 0.0)
    return edge.astype(np.int64), s, (1.0 / total) / g


def join_draws(clouds: RoadClouds, rows: IntArray, cloud_mass: FloatArray, edge: IntArray,
               s: FloatArray, w: FloatArray, rng: np.random.Generator) -> None:
    """Join draws ``(R, K)`` (edges, arcs, importance weights: the jump draws here, the birth
    draws of :mod:`searchtrack.estimate.road_births`) to ``rows`` of ``clouds``, whose
    normalized weights count ``cloud_mass`` ``(R,)`` each, with speeds from the clouds'
    stationary law (:meth:`~searchtrack.estimate.road_pf.RoadClouds.new_speeds`), and resample
    each row (:meth:`~searchtrack.estimate.road_pf.RoadClouds.join`)."""
    clouds.join(rows, cloud_mass, edge, s, clouds.new_speeds(np.shape(s), rng), w, rng)


def jump_detection(clouds: RoadClouds, jumps: TargetJumps, eps: float, rows: IntArray,
                   sums: FloatArray, y: FloatArray, clutter_density: float,
                   rng: np.random.Generator) -> None:
    """After the detection ``y`` weighed ``rows`` (whose likelihood sums before the update were
    ``sums``): join each row's jump draws near ``y``."""
    k = jumps.draws(clouds.shape[1], detection=True)
    roads, sensor = clouds.roads, clouds.sensor
    s0, s1, l_disc, alpha, radius = detection_proposal(roads, sensor, jumps, y)
    edge = np.empty((rows.size, k), dtype=np.int64)
    s = np.empty((rows.size, k))
    w = np.empty((rows.size, k))
    inside = s1 - s0
    kern.detection_jumps(roads.cum_length, roads.length, roads.total_length_m,
                         roads.tail_xy, roads.step_xy, s0, inside, np.cumsum(inside), l_disc,
                         alpha, radius * radius,
                         float(y[0]), float(y[1]), sensor.detection_gain,
                         0.5 / sensor.sigma2_m2, sensor.p_fa * clutter_density, eps / k,
                         rng.random((3, rows.size, k)), edge, s, w)
    join_draws(clouds, rows, (1.0 - eps) * sums, edge, s, w, rng)


def jump_miss(clouds: RoadClouds, jumps: TargetJumps, eps: float, rows: IntArray,
              sums: FloatArray, uav_xy: FloatArray, rng: np.random.Generator) -> None:
    """After a miss of a UAV at ``uav_xy`` updated ``rows`` (no-detection likelihoods ``sums``
    before the update): join each row's jump draws from ``u``."""
    k = jumps.draws(clouds.shape[1], detection=False)
    roads, sensor = clouds.roads, clouds.sensor
    edge = np.empty((rows.size, k), dtype=np.int64)
    s = np.empty((rows.size, k))
    w = np.empty((rows.size, k))
    kern.miss_jumps(roads.cum_length, roads.length, roads.tail_xy, roads.step_xy,
                    float(uav_xy[0]), float(uav_xy[1]), sensor.negative_radius_m ** 2,
                    sensor.p_fn, eps / k, rng.random((2, rows.size, k)), edge, s, w)
    join_draws(clouds, rows, (1.0 - eps) * sums, edge, s, w, rng)
