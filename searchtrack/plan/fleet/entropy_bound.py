"""Theorem 1 of paper 000 (§5): a lower bound ``B_L`` on a tracker's time-averaged entropy.

``Q`` UAVs spaced evenly around the ideal round trip (Assumption 2, Lemma 1) see each target every
``T/Q`` seconds, ``T = T_ave(M)``. Between sightings a mode's positional variance grows linearly
(Lemma 2, Eq. 32) from the steady post-update variance of Lemma 3 (Eq. 37); its entropy is that of a
Gaussian discretised on bins over the map length (Lemma 4, Eq. 40, Eq. 44); the modes split at
intersections (Lemma 5). Eq. 29 combines them into the expected entropy ``E[H_k]`` and Eq. 27
averages it over the steps between sightings. Corollary 1 maps an entropy back to the variance of a
single mode (Eq. 47, read with ``−(μ − b_j)²`` in the exponent and ``d`` for ``D``).

Entropies are in nats with 1 m bins by default: the paper's example (``B_L = 2.89`` for
"19 m") holds only in nats, and "19 m" and "16 m" are variances in m².
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq
from scipy.special import ndtr

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import check_stop
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.fleet.chains import ChainGraph, chain_graph
from searchtrack.plan.fleet.mode_split import SplitProfile, split_profile
from searchtrack.plan.fleet.round_trip import round_trip_ratio, s_node

Growth = Literal["paper", "code"]
Revisit = Literal["fleet", "single"]
Average = Literal["period", "printed"]
Binning = Literal["density", "mass"]
GROWTHS: tuple[Growth, ...] = ("paper", "code")
REVISITS: tuple[Revisit, ...] = ("fleet", "single")
AVERAGES: tuple[Average, ...] = ("period", "printed")
BINNINGS: tuple[Binning, ...] = ("density", "mass")

#: Half-width of the bins evaluated around the mean, in standard deviations (the rest are < 1e-30).
WINDOW_SIGMAS = 12.0
#: Variances × bins :func:`gaussian_entropy` evaluates at once (bounds its memory).
ENTROPY_CELLS = 2**20
#: Most bins :func:`gaussian_entropy` evaluates per variance.
MAX_ENTROPY_BINS = 2**24
#: σ (in bins) above which :func:`required_entropy` takes ``½ ln(2πe σ²/bin²)`` (< 1e-8 off).
CLOSED_FORM_BINS = 1e4


@dataclass(frozen=True)
class BoundConfig:
    """Inputs of Theorem 1 other than the map and the fleet size (validated, frozen).

    Parameters
    ----------
    targets
        Number of targets ``M`` (≥ 2: the round trip of Lemma 1 needs two).
    uav_speed_mps
        UAV airspeed ``V_a`` (Eq. 31).
    target_speed_mps
        Target speed; a chain's traversal time is its length over it (Lemma 5).
    sigma_v_mps
        Target velocity noise standard deviation ``σ_v`` (Eq. 32).
    meas_var_m2
        Measurement variance along the road ``R`` (Eq. 37).
    dt_s
        Time step ``δ_t`` (Eqs. 28, 32).
    bin_m
        Map bin size for the discretised Gaussian (Eq. 40; 1 m in the paper).
    include_diagonal
        ``S_node`` over all node pairs including a node with itself (the mean distance between
        two independently drawn nodes, closest to ``S_point``) or over distinct pairs only.
    growth
        ``"paper"``: Eq. 37 with ``T δ_t σ_v²``, the variance Lemma 2 adds in ``T`` seconds;
        ``"code"``: the authors' code's ``T δ_t² σ_v²`` (not consistent with Lemma 2).
    revisit
        ``"fleet"``: Eq. 37 with the revisit time ``T/Q``, consistent with Theorem 1;
        ``"single"``: with ``T_ave(M)`` as printed, whatever ``Q``.
    average
        ``"period"``: the mean of ``E[H_k]`` over the ``⌊T_Q⌋`` steps ``k = 0…⌊T_Q⌋−1`` of one
        revisit period; ``"printed"``: Eq. 27 as printed, ``(1/T_Q) Σ_{k=0}^{⌊T_Q⌋} E[H_k]``.
    binning
        ``"density"``: ``φ[b] = N(b; μ, σ²)·bin`` at bin points, as in Eq. 47 (for variances of at
        least ``(bin/2)²``); ``"mass"``: the Gaussian probability of each bin (right for any
        variance; 0.003 nats above the density form at 16 m² with 1 m bins).
    """

    targets: int
    uav_speed_mps: float = 40.0
    target_speed_mps: float = 10.0
    sigma_v_mps: float = 4.0
    meas_var_m2: float = 5.0
    dt_s: float = 0.1
    bin_m: float = 1.0
    include_diagonal: bool = True
    growth: Growth = "paper"
    revisit: Revisit = "fleet"
    average: Average = "period"
    binning: Binning = "density"

    def __post_init__(self) -> None:
        checks.count("targets", self.targets, 2)
        for name in ("uav_speed_mps", "target_speed_mps", "sigma_v_mps", "meas_var_m2", "dt_s",
                     "bin_m"):
            checks.positive(name, getattr(self, name))
        if not isinstance(self.include_diagonal, bool):
            raise InvalidInputError("include_diagonal", self.include_diagonal, "must be a bool")
        checks.choice("growth", self.growth, GROWTHS)
        checks.choice("revisit", self.revisit, REVISITS)
        checks.choice("average", self.average, AVERAGES)
        checks.choice("binning", self.binning, BINNINGS)


def steady_variance(revisit_s: float, sigma_v_mps: float, dt_s: float, meas_var_m2: float,
                    growth: Growth = "paper") -> float:
    """Mean post-update ("minimum") positional variance ``σ²_{p0}`` (m²), Lemma 3, Eq. 37.

    The positive root of ``σ⁴ + σ² a − R a = 0`` with ``a = T δ_t σ_v²`` (``growth="paper"``,
    the growth of Eq. 32 over ``T`` seconds) or ``a = T δ_t² σ_v²`` (``"code"``).
    """
    checks.choice("growth", growth, GROWTHS)
    dt = checks.positive("dt_s", dt_s)
    a = (checks.positive("revisit_s", revisit_s) * checks.positive("sigma_v_mps", sigma_v_mps) ** 2
         * (dt if growth == "paper" else dt * dt))
    r = checks.positive("meas_var_m2", meas_var_m2)
    return 2.0 * r / (1.0 + math.sqrt(1.0 + 4.0 * r / a))   # = a/2 (√(1 + 4R/a) − 1), stably


def variance_at(variance0_m2: float, sigma_v_mps: float, dt_s: float,
                steps: ArrayLike) -> NDArray[np.float64]:
    """Positional variance ``σ²_{p,k} = σ²_{p,k0} + σ_v² δ_t² (k − k0)`` (m²), Lemma 2, Eq. 32;
    ``steps`` are ``k − k0``."""
    k = np.asarray(steps, dtype=np.float64)
    if not np.all(np.isfinite(k) & (k >= 0)):
        raise InvalidInputError("steps", steps, "must be finite and ≥ 0")
    var0 = checks.positive("variance0_m2", variance0_m2)
    return var0 + checks.positive("sigma_v_mps", sigma_v_mps) ** 2 * checks.positive(
        "dt_s", dt_s) ** 2 * k


def gaussian_entropy(variance_m2: ArrayLike, length_m: float, bin_m: float = 1.0,
                     binning: Binning = "density"
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Entropy ``−Σ_h φ[b^h] ln φ[b^h]`` (nats) of one mode, Lemma 4, Eq. 40, and ``Σ_h φ[b^h]``.

    ``φ`` is a Gaussian of the given variance centred on the middle of the map, on the bins
    ``b^h = 0, bin, 2·bin, …`` up to ``length_m``; only bins within ±12 σ of the mean are summed.
    For 1 m bins and ``σ² ≥ 2`` this is ``½ ln(2πe σ²)`` to within 0.01 (2.805 for 16 m²).

    Parameters
    ----------
    variance_m2
        One variance or an array of them (m², > 0).
    length_m
        Map length ``L_map`` (m).
    bin_m
        Bin size (m).
    binning
        ``"density"`` (Eq. 47: density at the bin times the bin size) or ``"mass"`` (bin
        probabilities).

    Returns
    -------
    The entropies and the total mass ``Σ_h φ`` (below 1 when the map cuts the tails), each of the
    shape of ``variance_m2``.
    """
    checks.choice("binning", binning, BINNINGS)
    var = np.asarray(variance_m2, dtype=np.float64)
    if var.size == 0 or not np.all(np.isfinite(var) & (var > 0)):
        raise InvalidInputError("variance_m2", variance_m2, "must be finite and > 0 (m²)")
    length = checks.positive("length_m", length_m)
    width = checks.positive("bin_m", bin_m)
    mean = length / 2.0
    reach = WINDOW_SIGMAS * math.sqrt(float(var.max()))
    lo = max(0, math.ceil((mean - reach) / width))
    hi = min(math.floor(length / width + 1e-9), math.floor((mean + reach) / width))
    if hi - lo + 1 > MAX_ENTROPY_BINS:
        raise InvalidInputError("variance_m2", float(var.max()),
                                f"spans over {MAX_ENTROPY_BINS} bins of {width:g} m")
    bins = np.arange(lo, hi + 1) * width
    sigma = np.sqrt(var.reshape(-1, 1))
    entropy, mass = np.empty(var.size), np.empty(var.size)
    rows = max(1, ENTROPY_CELLS // max(1, bins.size))
    for start in range(0, var.size, rows):
        check_stop()
        part = slice(start, start + rows)
        z = (bins[None, :] - mean) / sigma[part]
        if binning == "density":
            phi = np.exp(-0.5 * z * z) * (width / (math.sqrt(2 * math.pi) * sigma[part]))
        else:
            phi = ndtr(z + 0.5 * width / sigma[part]) - ndtr(z - 0.5 * width / sigma[part])
        with np.errstate(divide="ignore", invalid="ignore"):
            terms = np.where(phi > 0, -phi * np.log(phi), 0.0)
        entropy[part], mass[part] = terms.sum(axis=1), phi.sum(axis=1)
    return entropy.reshape(var.shape), mass.reshape(var.shape)


def expected_entropy(variance_m2: ArrayLike, profile: SplitProfile, length_m: float,
                     bin_m: float = 1.0, binning: Binning = "density") -> NDArray[np.float64]:
    """Expected entropy ``E[H_k] = −Σ_D Σ_h P_{D,k} φ_k[b^h] ln(D φ_k[b^h])`` (nats), Eq. 29.

    Expanded as ``(Σ_D P_{D,k}) H(φ_k) + (Σ_D P_{D,k} ln(1/D)) Σ_h φ_k[b^h]``: one mode's
    entropy plus the entropy of the split (Eqs. 44–46).

    Parameters
    ----------
    variance_m2
        ``(K + 1,)`` mode variances ``σ²_{p,k}``, ``k = 0…K``.
    profile
        The split sums for at least ``K + 1`` steps (:func:`split_profile`).
    length_m, bin_m, binning
        As in :func:`gaussian_entropy`.
    """
    var = np.atleast_1d(np.asarray(variance_m2, dtype=np.float64))
    if var.ndim != 1 or var.size > profile.mass.size:
        raise InvalidInputError("variance_m2", variance_m2,
                                f"must be a 1-D array of at most {profile.mass.size} variances")
    h, mass = gaussian_entropy(var, length_m, bin_m, binning)
    n = var.size
    return np.asarray(profile.mass[:n] * h + profile.split_entropy[:n] * mass)


@dataclass(frozen=True)
class BoundMap:
    """What Theorem 1 needs from a road map, computed once for any fleet size.

    Parameters
    ----------
    s_node_m
        Mean node-to-node road distance ``S_node`` standing in for ``S_point`` (Assumption 5).
    length_m
        Map length ``L_map``: the total (undirected) road length (m).
    chains
        The directed chains of the map (Lemma 5).
    """

    s_node_m: float
    length_m: float
    chains: ChainGraph

    @classmethod
    def from_network(cls, network: RoadNetwork, config: BoundConfig, *,
                     sources: int | None = None, seed: int = 0) -> BoundMap:
        """Measure ``network`` (``sources`` and ``seed`` as in :func:`s_node`)."""
        return cls(s_node(network, include_diagonal=config.include_diagonal, sources=sources,
                          seed=seed), network.total_length_m, chain_graph(network))

    def round_trip_s(self, config: BoundConfig) -> float:
        """``T = T_ave(M) = S_avg(M)/V_a`` (s), Eqs. 30–31."""
        return round_trip_ratio(config.targets) * self.s_node_m / config.uav_speed_mps

    def profile(self, config: BoundConfig, uavs: int = 1) -> SplitProfile:
        """The split sums for every step Theorem 1 averages over with ``uavs`` UAVs (or more)."""
        steps = math.floor(self.round_trip_s(config) / (uavs * config.dt_s))
        return split_profile(self.chains, config.target_speed_mps, config.dt_s, steps)


@dataclass(frozen=True)
class EntropyBound:
    """Theorem 1 for one fleet size.

    Parameters
    ----------
    uavs
        Fleet size ``Q``.
    revisit_s
        Time between sightings of a target, ``T/Q`` (s).
    steps
        ``T_Q = T/(Q δ_t)``, Eq. 28 (not rounded).
    variance0_m2
        Post-update variance ``σ²_{p0}``, Eq. 37.
    bound
        ``B_L`` (nats), Eq. 27.
    expected
        ``E[H_k]`` for the steps averaged (nats), Eq. 29.
    """

    uavs: int
    revisit_s: float
    steps: float
    variance0_m2: float
    bound: float
    expected: NDArray[np.float64]


def entropy_bound(bound_map: BoundMap, config: BoundConfig, uavs: int,
                  profile: SplitProfile | None = None) -> EntropyBound:
    """The lower bound ``B_L`` on the average entropy with ``Q`` UAVs: Theorem 1, Eqs. 27–28.

    ``T_Q = T/(Q δ_t)`` steps pass between sightings; ``σ²_{p,k}`` grows from ``σ²_{p0}``
    (Eq. 37 with the revisit time ``T/Q``, or ``T`` with ``revisit="single"``) by Eq. 32, and
    ``B_L`` averages ``E[H_k]`` (Eq. 29) over the period ``k = 0…⌊T_Q⌋−1``
    (``average="period"``), or is ``(1/T_Q) Σ_{k=0}^{⌊T_Q⌋} E[H_k]`` as Eq. 27 is printed,
    which counts the sighting step twice.

    Parameters
    ----------
    bound_map
        The map's terms.
    config
        Targets, speeds, noise and the variant flags.
    uavs
        Fleet size ``Q ≥ 1``.
    profile
        Split sums from :meth:`BoundMap.profile` for this fleet size or a smaller one (computed
        when ``None``).

    Raises
    ------
    InvalidInputError
        If ``uavs`` is not a positive integer, ``profile`` is too short or was made with another
        time step, or the revisit interval is shorter than one step.
    """
    q = checks.count("uavs", uavs, 1)
    revisit = bound_map.round_trip_s(config) / q
    t_q = revisit / config.dt_s
    last = math.floor(t_q)
    if last < 1:
        raise InvalidInputError("uavs", uavs, f"revisit time {revisit:.3g} s is shorter than "
                                f"one step dt_s={config.dt_s:g}")
    if profile is None:
        profile = bound_map.profile(config, q)
    if profile.mass.size <= last or not math.isclose(profile.dt_s, config.dt_s):
        raise InvalidInputError("profile", profile, f"must cover {last + 1} steps of "
                                f"dt_s={config.dt_s:g}")
    single = revisit * q if config.revisit == "single" else revisit
    var0 = steady_variance(single, config.sigma_v_mps, config.dt_s, config.meas_var_m2,
                           config.growth)
    if config.binning == "density" and var0 < (config.bin_m / 2.0) ** 2:
        raise InvalidInputError("binning", config.binning, f"σ²_p0 = {var0:.3g} m² is below "
                                f"(bin_m/2)² = {(config.bin_m / 2) ** 2:g} m², where sampled "
                                "densities are no bin probabilities; use binning='mass'")
    count = last if config.average == "period" else last + 1
    var = variance_at(var0, config.sigma_v_mps, config.dt_s, np.arange(count))
    expected = expected_entropy(var, profile, bound_map.length_m, config.bin_m, config.binning)
    total = float(expected.sum())
    bound = total / count if config.average == "period" else total / t_q
    return EntropyBound(q, revisit, t_q, var0, bound, checks.readonly(expected, copy=False))


def required_entropy(variance_m2: float, length_m: float, config: BoundConfig,
                     degree: float = 1.0) -> float:
    """Entropy (nats) of modes of ``degree`` each with ``variance_m2``: the right side of
    Eq. 47 with ``P_d = 1`` (Corollary 1), ``H(φ) + ln(1/d) Σ_h φ``.

    Above ``(L_map/8)²``, where the map would cut the tails (and a wider Gaussian have *less*
    entropy on it), the Gaussian is not cut, so the entropy keeps rising with any finite
    variance (in closed form beyond :data:`CLOSED_FORM_BINS` bins)."""
    d = checks.real("degree", degree, low=0.0, high=1.0, low_open=True)
    var, length = checks.positive("variance_m2", variance_m2), checks.positive("length_m", length_m)
    if var > (length / 8.0) ** 2:
        if (sigma_bins := math.sqrt(var) / config.bin_m) > CLOSED_FORM_BINS:
            return 0.5 * math.log(2.0 * math.pi * math.e) + math.log(sigma_bins / d)
        length = 2.0 * (WINDOW_SIGMAS * math.sqrt(var) + config.bin_m)  # a map cutting nothing
    h, mass = gaussian_entropy(var, length, config.bin_m, config.binning)
    return float(h + math.log(1.0 / d) * mass)


def variance_bound(entropy: float, length_m: float, config: BoundConfig,
                   degree: float = 1.0) -> float:
    """Corollary 1: the mode variance ``σ_p²`` (m²) whose entropy (Eq. 47) equals ``entropy``.

    Solved by Brent's method within ``[(bin/2)², (L_map/8)²]``, where the entropy rises with the
    variance, on a bracket grown from the continuous inverse ``bin² e^{2B}/(2πe d²)``.
    ``B_L = 2.89`` gives 18.96 m² ("19 m" in the paper) with 1 m bins.

    Raises
    ------
    InvalidInputError
        If ``entropy`` is not finite or lies outside the entropies of that range.
    """
    target = checks.real("entropy", entropy)
    d = checks.real("degree", degree, low=0.0, high=1.0, low_open=True)
    low = (config.bin_m / 2.0) ** 2
    high = (checks.positive("length_m", length_m) / 8.0) ** 2
    if high <= low:
        raise InvalidInputError("length_m", length_m, "the map must span at least 4 bins")

    def excess(v: float) -> float:
        return required_entropy(v, length_m, config, d) - target

    guess = config.bin_m**2 * math.exp(min(2.0 * (target - math.log(1.0 / d)), 700.0)) / (
        2.0 * math.pi * math.e)
    lo, hi = min(max(guess / 4.0, low), high), min(max(guess * 4.0, low), high)
    while lo > low and excess(lo) > 0:
        lo = max(lo / 16.0, low)
    while hi < high and excess(hi) < 0:
        hi = min(hi * 16.0, high)
    if not excess(lo) <= 0 <= excess(hi):
        raise InvalidInputError("entropy", entropy, "must be in "
                                f"[{required_entropy(low, length_m, config, d):.4g}, "
                                f"{required_entropy(high, length_m, config, d):.4g}] nats for "
                                "this map, bin size and degree")
    if excess(lo) == 0:
        return lo
    return float(brentq(excess, lo, hi, xtol=1e-10, rtol=1e-12))
