"""Fleet sizing from Theorem 1 and Corollary 1 of paper 000 (§5.4): the fewest UAVs that meet an
entropy or positional-variance requirement.

``B_L`` falls as the fleet grows (the revisit time ``T/Q`` shrinks), so the answer is the smallest
``Q`` with ``B_L(Q) ≤ B_req``; a variance requirement ``σ²`` becomes ``B_req`` through Eq. 47
(16 m² gives 2.805 nats with 1 m bins, and the 3 × 3 map with 100 m blocks and 10 targets needs
3 UAVs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import StopRequested, stop_requested
from searchtrack.plan.fleet.entropy_bound import (
    BoundConfig,
    BoundMap,
    EntropyBound,
    entropy_bound,
    required_entropy,
    variance_bound,
)


@dataclass(frozen=True)
class FleetOption:
    """One fleet size: its bound and the variance bound that follows (Corollary 1).

    Parameters
    ----------
    bound
        Theorem 1's terms for this fleet size.
    variance_m2
        ``σ_p²`` whose single-mode entropy is ``B_L`` (``nan`` if out of the invertible range).
    meets
        Whether ``B_L ≤ B_req``.
    """

    bound: EntropyBound
    variance_m2: float
    meets: bool


@dataclass(frozen=True)
class FleetSizing:
    """Bounds for ``Q = 1…max_uavs`` and the smallest ``Q`` meeting the requirement.

    Parameters
    ----------
    required_entropy
        ``B_req`` (nats).
    required_variance_m2
        The variance requirement, if one was given.
    options
        One entry per fleet size, ``Q = 1, 2, …``.
    uavs
        Smallest fleet size with ``B_L ≤ B_req``, or ``None`` if none up to ``max_uavs``.
    """

    required_entropy: float
    required_variance_m2: float | None
    options: tuple[FleetOption, ...]
    uavs: int | None


def _variance(entropy: float, length_m: float, config: BoundConfig) -> float:
    """Corollary 1's variance for ``entropy``, ``nan`` outside its invertible range."""
    try:
        return variance_bound(entropy, length_m, config)
    except InvalidInputError:
        return math.nan


def fleet_size(bound_map: BoundMap, config: BoundConfig, *, max_variance_m2: float | None = None,
               max_entropy: float | None = None, max_uavs: int = 10) -> FleetSizing:
    """The smallest ``Q ≤ max_uavs`` with ``B_L(Q) ≤ B_req`` (Eq. 27 solved for ``Q``, §5.4).

    A stop request (:mod:`searchtrack.core.interrupt`) ends the loop over fleet sizes: the
    answer holds the sizes done so far.

    Parameters
    ----------
    bound_map
        The map's terms (:meth:`BoundMap.from_network`).
    config
        Targets, speeds, noise and variants.
    max_variance_m2
        Requirement on the single-mode positional variance (m²); ``B_req`` by Eq. 47.
    max_entropy
        Requirement on the average entropy ``B_req`` (nats) directly.
    max_uavs
        Largest fleet to consider, ≥ 1.

    Raises
    ------
    InvalidInputError
        Unless exactly one requirement is given, or on a bad value.
    StopRequested
        On a stop request inside :func:`~searchtrack.core.interrupt.stops_raise` before the
        first fleet size (while the split profile is computed).
    """
    if (max_variance_m2 is None) == (max_entropy is None):
        raise InvalidInputError("max_variance_m2", max_variance_m2,
                                "give exactly one of max_variance_m2 and max_entropy")
    top = checks.count("max_uavs", max_uavs, 1)
    if max_variance_m2 is not None:
        variance = checks.positive("max_variance_m2", max_variance_m2)
        if config.binning == "density" and variance < (config.bin_m / 2.0) ** 2:
            raise InvalidInputError("max_variance_m2", max_variance_m2, "must be at least "
                                    f"(bin_m/2)² = {(config.bin_m / 2) ** 2:g} m² with "
                                    "binning='density'")
        required = required_entropy(variance, bound_map.length_m, config)
    else:
        variance = None
        required = checks.real("max_entropy", max_entropy)
    profile = bound_map.profile(config, 1)
    options = []
    for q in range(1, top + 1):
        if stop_requested():
            break                                 # Ctrl-C: the fleet sizes done so far
        if math.floor(bound_map.round_trip_s(config) / (q * config.dt_s)) < 1:
            break                                 # revisits faster than a step: no bound
        try:
            bound = entropy_bound(bound_map, config, q, profile)
            var = _variance(bound.bound, bound_map.length_m, config)
        except StopRequested:
            break                                 # Ctrl-C inside this fleet size
        options.append(FleetOption(bound, var, bound.bound <= required))
    if not options and not stop_requested():
        raise InvalidInputError("dt_s", config.dt_s, "the round trip is shorter than one step; "
                                "no bound can be averaged")
    answer = next((o.bound.uavs for o in options if o.meets), None)
    return FleetSizing(required, variance, tuple(options), answer)
