"""Gated EMD association: Algorithm 1 (greedy), the optimal gated assignment and ``auto``, by
backend name."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate import LikelihoodField, ScanUpdater, TrackerBank
from searchtrack.estimate.association import (
    Associator,
    gated_objective,
    greedy_pairs,
    optimal_pairs,
)
from searchtrack.estimate.emd_association import EMDAssociator
from searchtrack.estimate.node_tracker import measurement_density, position_log_likelihood
from searchtrack.models import RoadNetwork, random_network

GATE = 300.0
BACKENDS = ["greedy", "optimal", "auto"]
INF = math.inf


def busy(net: RoadNetwork, backend: str, method: str = "transport") -> EMDAssociator:
    """The associator under test with a generous time limit: the suite runs on a busy machine,
    and these tests check the associations, not the time they take."""
    return EMDAssociator(net, backend, method=method, time_limit_s=30.0)


def road(length_m: float, spacing_m: float = 10.0) -> RoadNetwork:
    """A straight road along x with nodes every ``spacing_m``."""
    n = round(length_m / spacing_m) + 1
    coords = np.column_stack([np.arange(n) * spacing_m, np.zeros(n)])
    edges = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    return RoadNetwork(coords, edges, np.full(n - 1, spacing_m))


def bank_at(net: RoadNetwork, xs: list[float], sd_m: float = 10.0) -> TrackerBank:
    """Trackers shaped like Gaussians (s.d. ``sd_m``) around the road positions ``xs``."""
    bank = TrackerBank(net.n_nodes)
    for x in xs:
        w = np.exp(-((net.coords[:, 0] - x) ** 2) / (2 * sd_m**2))
        bank = bank.with_birth(w / w.sum())
    return bank


def fixes(net: RoadNetwork, xs: list[float], noise_sd_m: float = 5.0) -> NDArray[np.float64]:
    """Measurement densities Û for position fixes on the road at ``xs``."""
    xy = np.column_stack([xs, np.zeros(len(xs))])
    return measurement_density(position_log_likelihood(net, xy, noise_sd_m))


def brute_force(costs: NDArray[np.float64], gate: float) -> float:
    """min Σ(c − gate) over every one-to-one set of pairs with c < gate."""
    k, q = costs.shape
    best = 0.0
    for size in range(1, min(k, q) + 1):
        for rows in itertools.combinations(range(k), size):
            for cols in itertools.permutations(range(q), size):
                c = costs[list(rows), list(cols)]
                if (c < gate).all():
                    best = min(best, float((c - gate).sum()))
    return best


# ----- the matching rules on cost matrices ---------------------------------------------------

def test_greedy_takes_the_global_minimum_first() -> None:
    """Greedy picks pairs in increasing cost, removing rows and columns, under the gate."""
    costs = [[50.0, 10.0, 400.0], [20.0, 5.0, 250.0]]
    assert greedy_pairs(costs, GATE) == ((1, 1), (0, 0))
    assert greedy_pairs(costs, 30.0) == ((1, 1),)


def test_greedy_ties_and_strict_gate() -> None:
    """Ties go to the lowest tracker, then measurement; a cost equal to the gate never pairs."""
    assert greedy_pairs([[7.0, 7.0], [7.0, 7.0]], GATE) == ((0, 0), (1, 1))
    assert greedy_pairs([[GATE, INF]], GATE) == ()
    assert optimal_pairs([[GATE, INF]], GATE) == ()


def test_greedy_and_optimal_differ() -> None:
    """The cheapest pair blocks two cheaper-in-total pairs: optimal takes the two."""
    costs = np.array([[10.0, 20.0], [20.0, INF]])
    assert greedy_pairs(costs, GATE) == ((0, 0),)
    assert optimal_pairs(costs, GATE) == ((0, 1), (1, 0))
    assert gated_objective(costs, optimal_pairs(costs, GATE), GATE) == pytest.approx(-560.0)
    assert gated_objective(costs, greedy_pairs(costs, GATE), GATE) == pytest.approx(-290.0)


def test_empty_matrices_give_no_pairs() -> None:
    """No trackers or no measurements: no pairs from either rule."""
    for shape in ((0, 3), (2, 0), (0, 0)):
        assert greedy_pairs(np.zeros(shape), GATE) == ()
        assert optimal_pairs(np.zeros(shape), GATE) == ()


@pytest.mark.parametrize("seed", range(5))
def test_optimal_matches_brute_force_and_beats_greedy(seed: int) -> None:
    """On random gated matrices optimal = brute force ≤ greedy, and pairs are one-to-one."""
    rng = np.random.default_rng(seed)
    for _ in range(40):
        k, q = rng.integers(1, 5, size=2)
        costs = rng.uniform(0.0, 2 * GATE, size=(k, q))
        costs[rng.random((k, q)) < 0.2] = INF
        best = optimal_pairs(costs, GATE)
        value = gated_objective(costs, best, GATE)
        assert value == pytest.approx(brute_force(costs, GATE), abs=1e-9)
        assert value <= gated_objective(costs, greedy_pairs(costs, GATE), GATE) + 1e-9
        assert all(costs[i, j] < GATE for i, j in best)
        assert len({i for i, _ in best}) == len({j for _, j in best}) == len(best)


@pytest.mark.parametrize(("costs", "gate", "field"), [
    ([1.0, 2.0], GATE, "costs"),
    ([[np.nan]], GATE, "costs"),
    ([["x"]], GATE, "costs"),
    ([[1.0]], 0.0, "gate_m"),
    ([[1.0]], INF, "gate_m"),
])
def test_rules_bad_input(costs: object, gate: float, field: str) -> None:
    """Bad cost matrices or gates raise naming the field, for both rules."""
    for rule in (greedy_pairs, optimal_pairs):
        with pytest.raises(InvalidInputError) as err:
            rule(costs, gate)  # type: ignore[arg-type]
        assert err.value.field == field


# ----- associators on road scenes ------------------------------------------------------------

@pytest.mark.parametrize("backend", BACKENDS)
def test_trackers_at_the_two_ends(backend: str) -> None:
    """Fixes near each end of a road pair with the tracker at that end."""
    net = road(1000.0)
    associator: Associator = busy(net, backend)
    out = associator.associate(bank_at(net, [50.0, 950.0]), fixes(net, [940.0, 65.0]))
    assert sorted(out.pairs) == [(0, 1), (1, 0)]


@pytest.mark.parametrize("backend", BACKENDS)
def test_fix_beyond_the_gate_stays_unassociated(backend: str) -> None:
    """A fix 450 m from the only tracker is not associated; one 20 m away is."""
    net = road(1000.0)
    bank = bank_at(net, [100.0])
    out, costs = busy(net, backend).associate_with_costs(bank, fixes(net, [550.0, 120.0]))
    assert out.pairs == ((0, 1),)
    assert out.unassociated(2) == (0,)
    assert costs[0, 1] == pytest.approx(20.0, abs=1.0)
    assert costs[0, 0] >= GATE


def test_scene_where_greedy_and_optimal_differ() -> None:
    """T0 at 50 m, M0 at 150, T1 at 200, M1 at 400: greedy takes (T1, M0) and strands M1;
    optimal pairs (T0, M0) and (T1, M1), a lower Σ(EMD − gate)."""
    net = road(500.0)
    bank, dens = bank_at(net, [50.0, 200.0], sd_m=5.0), fixes(net, [150.0, 400.0])
    greedy, costs = busy(net, "greedy").associate_with_costs(bank, dens)
    optimal, costs2 = busy(net, "optimal").associate_with_costs(bank, dens)
    np.testing.assert_array_equal(costs, costs2)
    assert greedy.pairs == ((1, 0),)
    assert optimal.pairs == ((0, 0), (1, 1))
    assert gated_objective(costs, optimal.pairs, GATE) < gated_objective(costs, greedy.pairs, GATE)
    auto, costs3 = busy(net, "auto").solve_with_costs(bank, dens)
    np.testing.assert_array_equal(costs, costs3)
    assert auto.status is Status.OPTIMAL and auto.plan == optimal


@pytest.mark.parametrize("seed", range(3))
def test_random_scenes(seed: int) -> None:
    """Random trackers and fixes on random roads: optimal = brute force ≤ greedy on the costs."""
    net = random_network(12, 800.0, seed=seed)
    rng = np.random.default_rng(seed)
    greedy, optimal = busy(net, "greedy"), busy(net, "optimal")
    for _ in range(3):
        centres = net.coords[rng.choice(net.n_nodes, 3, replace=False)]
        bank = TrackerBank(net.n_nodes)
        for c in centres:
            w = np.exp(-np.sum((net.coords - c) ** 2, axis=1) / (2 * 40.0**2))
            bank = bank.with_birth(w / w.sum())
        xy = centres[rng.integers(0, 3, size=3)] + rng.normal(0.0, 60.0, size=(3, 2))
        dens = measurement_density(position_log_likelihood(net, xy, 10.0))
        g, costs = greedy.associate_with_costs(bank, dens)
        o, costs2 = optimal.associate_with_costs(bank, dens)
        np.testing.assert_array_equal(costs, costs2)
        value = gated_objective(costs, o.pairs, GATE)
        assert value == pytest.approx(brute_force(costs, GATE), abs=1e-9)
        assert value <= gated_objective(costs, g.pairs, GATE) + 1e-9


def test_graph_method_gives_the_same_association() -> None:
    """method='graph' (min-cost flow on the road) yields the same costs below the gate."""
    net = road(600.0)
    bank, dens = bank_at(net, [50.0, 300.0]), fixes(net, [325.0, 70.0, 580.0])
    a, ca = busy(net, "greedy").associate_with_costs(bank, dens)
    b, cb = busy(net, "greedy", method="graph").associate_with_costs(bank, dens)
    assert a.pairs == b.pairs == ((0, 1), (1, 0))
    below = ca < GATE
    np.testing.assert_allclose(cb[below], ca[below], rtol=1e-7)


@pytest.mark.parametrize("backend", BACKENDS)
def test_empty_bank_or_no_measurement(backend: str) -> None:
    """An empty bank or a (0, n) density array gives no pairs and an empty cost matrix."""
    net = road(100.0)
    associator = busy(net, backend)
    out, costs = associator.associate_with_costs(TrackerBank(net.n_nodes), fixes(net, [10.0]))
    assert out.pairs == () and costs.shape == (0, 1)
    out, costs = associator.associate_with_costs(bank_at(net, [10.0]), np.zeros((0, net.n_nodes)))
    assert out.pairs == () and costs.shape == (1, 0)


def test_scan_updater_updates_the_right_tracker() -> None:
    """Through ScanUpdater, a fix near tracker 1 updates tracker 1 only, not the LRT."""
    net = road(1000.0)
    bank = bank_at(net, [100.0, 800.0], sd_m=30.0)
    scan = ScanUpdater(net, busy(net, "greedy"))
    out = scan.update(LikelihoodField.neutral(net.n_nodes), bank, zeta=3.0,
                      footprint=np.arange(75, 86), sensitivity=2.9, positions_m=[[812.0, 0.0]],
                      noise_sd_m=5.0)
    assert out.association.pairs == ((1, 0),) and not out.lrt_updated
    np.testing.assert_array_equal(out.bank[0].probability, bank[0].probability)
    assert out.bank[1].peak_node() == 81
    assert out.bank[1].peak_probability > bank[1].peak_probability
    np.testing.assert_array_equal(out.field.llr, 0.0)


def test_associators_are_frozen() -> None:
    """Associators are immutable."""
    associator = EMDAssociator(road(100.0), "optimal")
    with pytest.raises(dataclasses.FrozenInstanceError):
        associator.gate_m = 10.0  # type: ignore[misc]


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"network": "roads"}, "network"),
    ({"gate_m": 0.0}, "gate_m"),
    ({"gate_m": -5.0}, "gate_m"),
    ({"gate_m": INF}, "gate_m"),
    ({"gate_m": math.nan}, "gate_m"),
    ({"gate_m": "300"}, "gate_m"),
    ({"support_mass": 0.0}, "support_mass"),
    ({"support_mass": 1.01}, "support_mass"),
    ({"method": "lp"}, "method"),
    ({"time_limit_s": -1.0}, "time_limit_s"),
    ({"backend": "hungarian"}, "backend"),
])
@pytest.mark.parametrize("backend", BACKENDS)
def test_bad_construction(backend: str, kwargs: dict[str, object], field: str) -> None:
    """A bad field raises InvalidInputError naming it."""
    args: dict[str, object] = {"network": road(100.0), "backend": backend, **kwargs}
    with pytest.raises(InvalidInputError) as err:
        EMDAssociator(**args)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize(("bank", "densities", "field"), [
    ("bank", np.eye(11)[[2]], "bank"),
    (TrackerBank(12).with_birth(np.eye(12)[0]), np.eye(11)[[2]], "bank"),
    (None, np.eye(12)[[2]], "densities"),
    (None, np.eye(11)[2], "densities"),
    (None, -np.eye(11)[[2]], "densities"),
    (None, np.full((1, 11), np.nan), "densities"),
    (None, np.zeros((1, 11)), "densities"),
])
def test_bad_associate_input(bank: object, densities: object, field: str) -> None:
    """A bank on the wrong nodes or bad densities raise naming the field."""
    net = road(100.0)
    given = bank_at(net, [20.0]) if bank is None else bank
    with pytest.raises(InvalidInputError) as err:
        EMDAssociator(net, "greedy").associate(given, densities)  # type: ignore[arg-type]
    assert err.value.field == field
