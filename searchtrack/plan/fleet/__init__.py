"""Fleet sizing from paper 000's lower bound on tracking entropy (Moore et al. 2021, §5).

Theorem 1 bounds the time-averaged entropy ``B_L`` of a road-constrained tracker for ``M``
targets watched by ``Q`` UAVs on a given map; Corollary 1 turns it into a bound on a mode's
positional variance, and the smallest ``Q`` meeting a requirement sizes the fleet.

- :mod:`.round_trip`: ``S_node``, the point-to-point check of Assumption 5, ``S_avg`` and
  ``T_ave`` (Lemma 1, Eqs. 30–31).
- :mod:`.chains`: directed chains and subdivisions of a road map (§5.3, Fig. 6–7).
- :mod:`.mode_split`: ``P_D(t)``, the mass fraction in modes of each degree (Lemma 5,
  Algorithms 1–2), its step-grid form and a Monte Carlo check.
- :mod:`.entropy_bound`: Lemmas 2–4, ``E[H_k]`` and ``B_L`` (Eqs. 27–29, 32, 37, 40) and
  Corollary 1 (Eq. 47).
- :mod:`.sizing`: the fewest UAVs for an entropy or variance requirement.

Example::

    from searchtrack.models.road_synthetic import grid_network
    from searchtrack.plan.fleet import BoundConfig, BoundMap, fleet_size

    config = BoundConfig(targets=10)                    # V_a 40, v 10, σ_v 4, R 5, δ_t 0.1
    roads = grid_network(3, 3, block_m=100.0, spacing_m=100.0)
    sizing = fleet_size(BoundMap.from_network(roads, config), config, max_variance_m2=16.0)
    sizing.uavs                                          # 3
"""

from __future__ import annotations

from searchtrack.plan.fleet.chains import ChainGraph, Subdivision, chain_graph, subdivisions
from searchtrack.plan.fleet.entropy_bound import (
    BoundConfig,
    BoundMap,
    EntropyBound,
    entropy_bound,
    expected_entropy,
    gaussian_entropy,
    required_entropy,
    steady_variance,
    variance_at,
    variance_bound,
)
from searchtrack.plan.fleet.mode_split import (
    ModeProbabilities,
    SplitProfile,
    mode_probabilities,
    mode_split_mc,
    split_profile,
)
from searchtrack.plan.fleet.round_trip import (
    point_distance_mc,
    round_trip_ratio,
    s_avg,
    s_node,
    t_ave,
)
from searchtrack.plan.fleet.sizing import FleetOption, FleetSizing, fleet_size

__all__ = ["BoundConfig", "BoundMap", "ChainGraph", "EntropyBound", "FleetOption", "FleetSizing",
           "ModeProbabilities", "SplitProfile", "Subdivision", "chain_graph", "entropy_bound",
           "expected_entropy", "fleet_size", "gaussian_entropy", "mode_probabilities",
           "mode_split_mc", "point_distance_mc", "required_entropy", "round_trip_ratio", "s_avg",
           "s_node", "split_profile", "steady_variance", "subdivisions", "t_ave", "variance_at",
           "variance_bound"]
