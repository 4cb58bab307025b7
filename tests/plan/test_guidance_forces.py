"""Tests of the Ch. 5 potential forces and the UAV-to-tracker pairing."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance import (
    GradientField,
    default_loiter_k,
    default_spring_k,
    pair_uavs,
    pauli_force,
    spring_force,
)


def _net(coords: list[tuple[float, float]], edges: list[tuple[int, int]]) -> RoadNetwork:
    xy = np.array(coords, dtype=float)
    e = np.array(edges, dtype=np.int64)
    lengths = np.hypot(*(xy[e[:, 0]] - xy[e[:, 1]]).T)
    return RoadNetwork(xy, e, lengths)


def _path(n: int, step: float = 10.0) -> RoadNetwork:
    return _net([(i * step, 0.0) for i in range(n)], [(i, i + 1) for i in range(n - 1)])


def test_gradient_picks_max_edge_and_points_to_higher_end() -> None:
    """∇R is |Δφ| of the max-|Δφ| candidate edge, toward its higher end (5.6)–(5.7)."""
    net = _net([(0, 0), (10, 0), (20, 0), (20, 10)], [(0, 1), (1, 2), (2, 3)])
    phi = np.array([0.0, 1.0, 4.0, 2.0])  # Δφ = [−1, −3, 2]
    force, n_max = GradientField(net).force([[10.0, 0.0]], phi, 15.0, np.random.default_rng(0))
    np.testing.assert_allclose(force, [[3.0, 0.0]])
    assert n_max.tolist() == [2]


def test_gradient_only_uses_edges_near_the_uav() -> None:
    """Edges not incident to a node within ρ are ignored."""
    net = _net([(0, 0), (10, 0), (20, 0), (30, 0)], [(0, 1), (1, 2), (2, 3)])
    phi = np.array([0.0, 0.5, 0.0, 9.0])  # the big jump is on edge (2, 3), out of reach
    force, n_max = GradientField(net).force([[0.0, 0.0]], phi, 5.0, np.random.default_rng(0))
    np.testing.assert_allclose(force, [[0.5, 0.0]])
    assert n_max.tolist() == [1]


def test_gradient_ties_are_random_seeded_and_cover_both_edges() -> None:
    """Tied edges are drawn uniformly from the generator: both occur, and a seed repeats."""
    field = GradientField(_path(3))
    phi = np.array([0.0, 1.0, 0.0])  # both edges |Δφ| = 1, pointing +x and −x toward node 1

    def draws(seed: int) -> list[float]:
        rng = np.random.default_rng(seed)
        return [float(field.force([[10.0, 0.0]], phi, 15.0, rng)[0][0, 0]) for _ in range(200)]

    first = draws(3)
    assert set(first) == {1.0, -1.0}
    assert 60 < first.count(1.0) < 140
    assert draws(3) == first


def test_gradient_without_nodes_in_range() -> None:
    """No node within ρ: zero force and n_max is the nearest node."""
    net = _path(3)
    force, n_max = GradientField(net).force([[100.0, 50.0], [0.0, 0.0]], np.array([0.0, 2.0, 0.0]),
                                            12.0, np.random.default_rng(0))
    np.testing.assert_allclose(force[0], [0.0, 0.0])
    assert n_max.tolist() == [2, 1]


def test_pauli_magnitude_and_direction() -> None:
    """Repulsion is 48εσ¹²r⁻¹³ along the line, away from the other UAV."""
    sigma, r = 240.0, 200.0
    f = pauli_force([[0.0, 0.0], [0.0, r]], sigma)
    mag = 48.0 * sigma**12 * r**-13
    np.testing.assert_allclose(f, [[0.0, -mag], [0.0, mag]], rtol=1e-12)


def test_pauli_respects_repeller_mask() -> None:
    """(5.14): a UAV only feels the UAVs the mask names."""
    xy = [[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]]
    mask = np.array([[False, True, False], [False, False, False], [True, True, False]])
    f = pauli_force(xy, 240.0, repellers=mask)
    full = pauli_force(xy, 240.0)
    mag = 48.0 * 240.0**12 * 100.0**-13
    np.testing.assert_allclose(f[0], [-mag, 0.0])
    np.testing.assert_allclose(f[1], [0.0, 0.0])
    np.testing.assert_allclose(f[2], full[2])


def test_pauli_coincident_uavs_are_capped_and_pushed_apart() -> None:
    """At r = 0 the force is finite, capped, and opposite for the two UAVs."""
    f = pauli_force([[5.0, 5.0], [5.0, 5.0]], 240.0, cap=1e3)
    np.testing.assert_allclose(f, [[-1e3, 0.0], [1e3, 0.0]])


def test_spring_with_rest_length() -> None:
    """∇Q (5.11) pushes out inside ρ and pulls back beyond it."""
    anchor = [[0.0, 0.0], [0.0, 0.0]]
    f = spring_force([[50.0, 0.0], [0.0, 200.0]], anchor, 0.1, 120.0)
    np.testing.assert_allclose(f, [[7.0, 0.0], [0.0, -8.0]])


def test_zero_rest_spring_points_to_anchor() -> None:
    """∇L / ∇W (5.13), (5.32) is −K(ξ − a)."""
    f = spring_force([[3.0, 4.0]], [[1.0, 1.0]], 0.5)
    np.testing.assert_allclose(f, [[-1.0, -1.5]])


def test_default_constants() -> None:
    """K = 4/ρ for ∇Q and (2S/ρ)² for ∇L, as documented."""
    assert default_spring_k(120.0) == pytest.approx(4.0 / 120.0)
    assert default_loiter_k(120.0, 30.0) == pytest.approx(0.25)


def _bank(net: RoadNetwork, peaks: list[int]) -> TrackerBank:
    trackers = []
    for i, node in enumerate(peaks):
        p = np.full(net.n_nodes, 0.5 / (net.n_nodes - 1))
        p[node] = 0.5
        trackers.append(NodeTracker(p, i))
    return TrackerBank(net.n_nodes, tuple(trackers), len(peaks))


@pytest.mark.parametrize("seed", range(12))
def test_pairing_matches_brute_force(seed: int) -> None:
    """The assignment's summed distance equals the best over every injective pairing."""
    rng = np.random.default_rng(seed)
    net = _net([tuple(xy) for xy in rng.uniform(0, 1000, (12, 2))], [(i, i + 1) for i in range(11)])
    n_uav, n_trk = int(rng.integers(1, 5)), int(rng.integers(1, 5))
    peaks = rng.choice(12, n_trk, replace=False).tolist()
    uav = rng.uniform(0, 1000, (n_uav, 2))
    pairing = pair_uavs(net, uav, _bank(net, peaks))
    dist = np.hypot(*(uav[:, None, :] - net.coords[peaks][None, :, :]).transpose(2, 0, 1))
    k = min(n_uav, n_trk)
    best = min(sum(dist[u, t] for u, t in zip(us, ts, strict=True))
               for us in itertools.permutations(range(n_uav), k)
               for ts in itertools.combinations(range(n_trk), k))
    assert pairing.cost_m == pytest.approx(best)
    assert len(pairing.assigned) == k
    got = sum(dist[j, t] for j, t in enumerate(pairing.tracker) if t >= 0)
    assert got == pytest.approx(best)
    for j, t in enumerate(pairing.tracker):
        if t >= 0:
            assert pairing.peak_node[j] == peaks[t] and pairing.track_id[j] == t


def test_pairing_empty_bank() -> None:
    """No trackers: every UAV is unpaired."""
    net = _path(3)
    pairing = pair_uavs(net, [[0.0, 0.0]], TrackerBank(3))
    assert pairing.tracker == (-1,) and pairing.unpaired == (0,)


def test_bad_force_inputs() -> None:
    """Bad shapes and constants are rejected, naming the field."""
    field = GradientField(_path(3))
    with pytest.raises(InvalidInputError, match="llr"):
        field.force([[0.0, 0.0]], np.zeros(4), 10.0, np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="sensor_range_m"):
        field.force([[0.0, 0.0]], np.zeros(3), -1.0, np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="repellers"):
        pauli_force([[0.0, 0.0], [1.0, 1.0]], 10.0, repellers=np.ones((3, 3), dtype=bool))
    with pytest.raises(InvalidInputError, match="k"):
        spring_force([[0.0, 0.0]], [[1.0, 1.0]], 0.0)
    with pytest.raises(InvalidInputError, match="uav_xy_m"):
        pauli_force([[np.nan, 0.0]], 10.0)
