"""Measurement-driven rejuvenation of the road particle filters: particles drawn near a
detection, weighed back to a smoothed motion prior (beyond Moore et al. 2021).

On a map of a hundred kilometres of road, ``N`` = 500 particles spread one per few hundred
metres: a cloud that has not yet found its target has no particle within a few ``σ`` of a
detection, though its prior puts some mass there. Weighing its particles by Eq. 10 then sees
nothing but the clutter floor, and consecutive detections of a target never accumulate: the
filter cannot localise a target it is not already near.

Here the prior of each cloud is regularised near the detection ``y``, in the disc ``D`` of road
within ``ρ`` (a few sensor standard deviations) of ``y``, as in the regularised particle filter
(Musso, Oudjane and Le Gland 2001): inside ``D`` it is ``(1 − β) p + β p̂``, with ``p`` the
cloud and ``p̂`` its kernel estimate ``p̂(x) = Σ_n w_n k_b(‖G(x) − G(x_n)‖)`` (a Gaussian kernel
per metre of road, planar distance standing for road distance; bandwidth ``b`` by Silverman's
rule on the cloud's planar spread, ``b = 1.06 s N^{-1/5}``, between ``min_bandwidth_m`` and
``max_bandwidth_sigmas`` sensor standard deviations); outside ``D`` it is ``p``. The ``β``
share is represented by ``K`` draws ``x_j`` uniform on the road of ``D`` (density
``g = 1/L_D``), each weighing ``β p̂(x_j) ℓ(x_j) L_D / K``; the cloud's particles weigh
``w_n ℓ(x_n)``, times ``1 − β`` inside ``D``. The union is an unbiased importance-sampling
estimate of the posterior of the regularised prior, and its total weight of the predictive
likelihood ``∫ p̃ ℓ``, which the association sampling (Eq. 15–16) and the history weights use.
``β = K / (K + n_D)`` with ``n_D`` the cloud's particles inside ``D``: the draws and the
particles already there share ``D`` by count, so a cloud with nothing near ``y`` hands ``D`` to
the kernel estimate; a cloud with at least ``full_share · N`` particles in ``D`` represents it
well already and gets ``β = 0`` (no draws; any ``β`` fixed by the cloud keeps the estimate
unbiased).

The cap on ``b`` keeps the negative information. Silverman's rule gives a cloud spread over
kilometres a bandwidth of many tens of metres; in a footprint the sensors have just swept (and
emptied of particles), a kernel that wide reads the mass of the unswept road around it, so a
single false alarm there would localise the cloud on nothing. Capped at a few ``σ``, the
estimate reads the cloud at the sensor's own resolution: a detection a few bandwidths from a
diffuse cloud's particles still finds their density (consecutive detections then localise it), a
detection in an emptied footprint finds none. The price is a slower take-up of a target farther
from every particle of its cloud than that.

``p̂`` in ``D`` is the sum over the particles within ``ρ + 4b`` of ``y`` (the others add below
``e^{-8}`` of a kernel's peak). When more than ``kernel_points`` are there (a cloud already on
the target), it is read from ``kernel_points`` of them chosen by systematic resampling on their
weights, each chosen one carrying ``1 / kernel_points`` of their mass: every particle's expected
weight is its own, so ``p̂`` and the draws' weights stay unbiased, and the kernel work per cloud
and detection is at most ``K · kernel_points``. A diffuse cloud's few particles near ``y`` are
all read.

A cloud that is localised far from ``y`` has ``p̂ ≈ 0`` in ``D``: its draws weigh nothing. A
diffuse cloud's ``p̂`` near ``y`` is its local density, so a few consecutive detections (each
multiplying the odds of a target at ``y`` by about ``gain / (P_FA c)``) localise it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from searchtrack.core import checks
from searchtrack.core.kernel_cache import follow_callees
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.road_filter_kernels import MAX_EXPONENT
from searchtrack.estimate.road_jumps import disc_intervals, join_draws
from searchtrack.estimate.road_pf import RoadClouds
from searchtrack.estimate.road_resampling import SILVERMAN

#: Particles farther than this many bandwidths beyond the disc add nothing to the kernel
#: estimate inside it (below ``exp(−8)`` of a kernel's peak each, 6e-5 of its mass beyond).
_REACH_BANDWIDTHS = 4.0


@dataclass(frozen=True)
class DetectionBirths:
    """The rejuvenation near detections (module docstring).

    Parameters
    ----------
    draw_share
        ``K`` as a share of the cloud's ``N`` (at least one draw), in ``(0, 1]``.
    radius_sigmas
        ``ρ`` in standard deviations of the sensor's position noise, > 0.
    bandwidth_scale
        The factor of Silverman's rule (:data:`~searchtrack.estimate.road_resampling.SILVERMAN`,
        1.06), > 0.
    min_bandwidth_m
        Smallest kernel bandwidth (m), > 0.
    max_bandwidth_sigmas
        Largest kernel bandwidth in standard deviations of the sensor's position noise, > 0
        (a bandwidth below ``min_bandwidth_m`` is raised to it).
    kernel_points
        Most particles the kernel estimate is read from (systematic resampling), ≥ 1.
    full_share
        A cloud with at least this share of its particles inside ``D`` gets no draws, in
        ``(0, 1]``. 1 (default): only a cloud entirely inside ``D``; a smaller share saves
        the kernel estimate of the clouds already on the target, but their draws also bring
        fresh speed states (:class:`~searchtrack.models.road_particles.CourierRoadMotion`),
        and in the thesis missions skipping them lost targets that stopped or sped up.
    """

    draw_share: float = 0.05
    radius_sigmas: float = 5.0
    bandwidth_scale: float = SILVERMAN
    min_bandwidth_m: float = 1.0
    full_share: float = 1.0
    max_bandwidth_sigmas: float = 2.5
    kernel_points: int = 64

    def __post_init__(self) -> None:
        for name in ("draw_share", "full_share"):
            checks.real(name, getattr(self, name), low=0.0, high=1.0, low_open=True)
        for name in ("radius_sigmas", "bandwidth_scale", "min_bandwidth_m",
                     "max_bandwidth_sigmas"):
            checks.positive(name, getattr(self, name))
        checks.count("kernel_points", self.kernel_points, least=1)

    def bandwidth_range(self, sigma_m: float) -> tuple[float, float]:
        """``(lowest, highest)`` kernel bandwidth (m) for a sensor of position noise
        ``sigma_m``."""
        return self.min_bandwidth_m, max(self.max_bandwidth_sigmas * sigma_m,
                                         self.min_bandwidth_m)

    def draws(self, n_particles: int) -> int:
        """``K``: draws per cloud and detection."""
        return max(1, math.ceil(self.draw_share * n_particles))


@dataclass(frozen=True)
class BirthDraws:
    """The draws of one detection for every cloud, and what the clouds' particles keep.

    Attributes
    ----------
    edge, s, w
        ``(F, K)`` draws and their weights ``β p̂ ℓ L_D / K``.
    keep
        ``(F, N)`` factor of each cloud particle's ``w ℓ``: ``1 − β`` inside ``D``, 1 outside.
    sums
        ``(F,)`` the predictive likelihood estimate of each cloud (the union's total weight).
    bandwidth
        ``(F,)`` each cloud's kernel bandwidth (m), :func:`bandwidths`.
    """

    edge: IntArray
    s: FloatArray
    w: FloatArray
    keep: FloatArray
    sums: FloatArray
    bandwidth: FloatArray


def bandwidths(clouds: RoadClouds, births: DetectionBirths) -> FloatArray:
    """``(F,)`` kernel bandwidth (m) of each cloud: Silverman's rule on its weighted planar
    spread (the root mean of the two coordinates' variances), clipped to
    :meth:`DetectionBirths.bandwidth_range`. The NumPy reference of the bandwidths
    :func:`birth_draws` computes in its kernel."""
    pts = clouds.points()
    w = clouds.w / clouds.w.sum(axis=1, keepdims=True)
    mean = np.einsum("fn,fnk->fk", w, pts)
    var = np.einsum("fn,fnk->f", w, (pts - mean[:, None, :]) ** 2) / 2.0
    n_eff = 1.0 / np.einsum("fn,fn->f", w, w)
    b = births.bandwidth_scale * np.sqrt(np.maximum(var, 0.0)) * n_eff ** -0.2
    low, high = births.bandwidth_range(math.sqrt(clouds.sensor.sigma2_m2))
    return np.asarray(np.clip(b, low, high), dtype=np.float64)


def birth_draws(clouds: RoadClouds, births: DetectionBirths, y: FloatArray,
                clutter_density: float, uniforms: FloatArray) -> BirthDraws:
    """The draws near detection ``y`` for every cloud of ``clouds`` from ``uniforms``
    ``(3, F, K)`` (the edge by length inside ``D``, the arc; the first of the third row
    offsets the systematic choice of the kernel's particles), after
    :meth:`~searchtrack.estimate.road_pf.RoadClouds.detection_sums` for ``y`` (whose
    per-particle likelihoods the cloud particles' weights use). The clouds' weights are
    normalized. A detection with no road in ``D`` gives no draw any weight (``β = 0``)."""
    roads, sensor = clouds.roads, clouds.sensor
    radius = births.radius_sigmas * math.sqrt(sensor.sigma2_m2)
    s0, s1, l_disc = disc_intervals(roads, y, radius)
    f, k = uniforms.shape[1], uniforms.shape[2]
    edge = np.zeros((f, k), dtype=np.int64)
    s = np.zeros((f, k))
    w = np.zeros((f, k))
    keep = np.empty(clouds.shape)
    sums = np.empty(f)
    band = np.empty(f)
    inside = s1 - s0
    low, high = births.bandwidth_range(math.sqrt(sensor.sigma2_m2))
    _births(clouds.edge, clouds.s, clouds.w, clouds.count, clouds.likelihoods, roads.tail_xy,
            roads.step_xy,
            s0, inside, np.cumsum(inside), l_disc, radius, float(y[0]), float(y[1]),
            sensor.detection_gain, 0.5 / sensor.sigma2_m2, sensor.p_fa * clutter_density,
            births.bandwidth_scale, low, high, births.kernel_points, births.full_share, uniforms,
            edge, s, w, keep, sums, band)
    return BirthDraws(edge, s, w, keep, sums, band)


def join_births(clouds: RoadClouds, rows: IntArray, draws: BirthDraws,
                rng: np.random.Generator) -> None:
    """Bayes' rule on ``rows`` with the regularised prior: each row's particles weighed by
    ``w ℓ`` (times ``1 − β`` inside ``D``) joined with its draws, and the union resampled back
    to ``N``, or to its KLD-sampling count (low-variance); a row whose union weighs nothing is
    left as it is."""
    if rows.size == 0:
        return
    post = clouds.w[rows] * clouds.likelihoods[rows] * draws.keep[rows]
    total = post.sum(axis=1)
    ok = total > 0.0
    clouds.w[rows[ok]] = post[ok] / total[ok, None]
    join_draws(clouds, rows, total, draws.edge[rows], draws.s[rows], draws.w[rows], rng)


@njit(cache=True)
def _births(edge: IntArray, s: FloatArray, w: FloatArray, count: IntArray, lik: FloatArray,
            tail_xy: FloatArray, step_xy: FloatArray, s0: FloatArray, inside: FloatArray,
            cum_inside: FloatArray, l_disc: float, radius: float, yx: float, yy: float,
            gain: float, inv_two_var: float, floor: float, scale: float, min_band: float,
            max_band: float, n_kernel: int, full_share: float, uniforms: FloatArray,
            out_edge: IntArray, out_s: FloatArray, out_w: FloatArray, keep: FloatArray,
            sums: FloatArray, band: FloatArray) -> None:
    """:func:`birth_draws` for every row (module docstring); rows of normalized weights, each
    of its ``count`` particles (``keep`` 1 beyond)."""
    f_count, cap = edge.shape
    k_count = out_edge.shape[1]
    n_edges = inside.size
    r2 = radius * radius
    px = np.empty(k_count)
    py = np.empty(k_count)
    lk = np.empty(k_count)
    dens = np.empty(k_count)
    qx = np.empty(cap)   # the row's particles' points and squared distances to y
    qy = np.empty(cap)
    qd2 = np.empty(cap)
    kw = np.empty(cap)   # the kernel's weight of each particle
    for f in range(f_count):
        n_count = count[f]
        full = math.ceil(full_share * n_count - 1e-9)
        for n in range(n_count, cap):
            keep[f, n] = 1.0
        for n in range(n_count):
            e = edge[f, n]
            qx[n] = tail_xy[e, 0] + s[f, n] * step_xy[e, 0]
            qy[n] = tail_xy[e, 1] + s[f, n] * step_xy[e, 1]
            dx = qx[n] - yx
            dy = qy[n] - yy
            qd2[n] = dx * dx + dy * dy
        # Silverman's bandwidth of the cloud (the reference is bandwidths()).
        mx = 0.0
        my = 0.0
        w2 = 0.0
        for n in range(n_count):
            mx += w[f, n] * qx[n]
            my += w[f, n] * qy[n]
            w2 += w[f, n] * w[f, n]
        var = 0.0
        n_in = 0
        for n in range(n_count):
            dx = qx[n] - mx
            dy = qy[n] - my
            var += w[f, n] * (dx * dx + dy * dy)
            if qd2[n] <= r2:   # the cloud's particles inside D
                n_in += 1
        band[f] = min(max(scale * math.sqrt(max(var / 2.0, 0.0)) * w2 ** 0.2, min_band),
                      max_band)
        beta = k_count / (k_count + n_in) if l_disc > 0.0 and n_in < full else 0.0
        acc = 0.0
        for n in range(n_count):
            keep[f, n] = 1.0 - beta if qd2[n] <= r2 else 1.0
            acc += w[f, n] * lik[f, n] * keep[f, n]
        if beta == 0.0:
            sums[f] = acc
            continue
        # Draws uniform on the road of D, their likelihood and the kernel estimate there.
        for j in range(k_count):
            d = min(np.searchsorted(cum_inside, uniforms[0, f, j] * cum_inside[n_edges - 1],
                                    side="right"), n_edges - 1)
            arc = s0[d] + uniforms[1, f, j] * inside[d]
            out_edge[f, j] = d
            out_s[f, j] = arc
            px[j] = tail_xy[d, 0] + arc * step_xy[d, 0]
            py[j] = tail_xy[d, 1] + arc * step_xy[d, 1]
            q = ((px[j] - yx) ** 2 + (py[j] - yy) ** 2) * inv_two_var
            lk[j] = floor + (gain * math.exp(-q) if q < MAX_EXPONENT else 0.0)
            dens[j] = 0.0
        b = band[f]
        inv_two_b2 = 0.5 / (b * b)
        reach = radius + _REACH_BANDWIDTHS * b
        reach2 = reach * reach
        # The particles within reach of D carry the kernel estimate there: all of them when
        # few, else a systematic choice of n_kernel by weight (each one's expected weight is
        # its own).
        n_reach = 0
        m_reach = 0.0
        for n in range(n_count):
            kw[n] = 0.0
            if qd2[n] <= reach2:
                n_reach += 1
                m_reach += w[f, n]
        if n_reach <= n_kernel:
            for n in range(n_count):
                if qd2[n] <= reach2:
                    kw[n] = w[f, n]
        elif m_reach > 0.0:
            step = m_reach / n_kernel
            u = uniforms[2, f, 0] * step
            cum = 0.0
            for n in range(n_count):
                if qd2[n] > reach2:
                    continue
                n_reach -= 1
                cum = cum + w[f, n] if n_reach > 0 else 2.0 * m_reach   # the last: the rest
                while u < cum and u < m_reach:
                    kw[n] += step
                    u += step
        for n in range(n_count):
            if kw[n] == 0.0:
                continue
            for j in range(k_count):
                z = ((px[j] - qx[n]) ** 2 + (py[j] - qy[n]) ** 2) * inv_two_b2
                if z < MAX_EXPONENT:
                    dens[j] += kw[n] * math.exp(-z)
        norm = beta * l_disc / (k_count * math.sqrt(2.0 * math.pi) * b)
        for j in range(k_count):
            out_w[f, j] = norm * dens[j] * lk[j]
            acc += out_w[f, j]
        sums[f] = acc


follow_callees(__name__, globals())
