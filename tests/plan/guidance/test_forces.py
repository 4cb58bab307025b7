"""The Ch. 5 potential forces (thesis 001 §5.2–§5.5): the likelihood gradient ∇R, the Pauli
repulsion ∇P, the springs ∇Q, ∇L and ∇W, and their default constants."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.guidance import (
    GradientField,
    coverage_force,
    default_loiter_k,
    default_spring_k,
    pauli_force,
    spring_force,
)

from .helpers import path_road, road


def test_gradient_picks_max_edge_and_points_to_higher_end() -> None:
    """∇R is |Δφ| of the max-|Δφ| candidate edge, toward its higher end (5.6)–(5.7)."""
    net = road([(0, 0), (10, 0), (20, 0), (20, 10)], [(0, 1), (1, 2), (2, 3)])
    phi = np.array([0.0, 1.0, 4.0, 2.0])  # Δφ = [−1, −3, 2]
    force, n_max = GradientField(net).force([[10.0, 0.0]], phi, 15.0, np.random.default_rng(0))
    np.testing.assert_allclose(force, [[3.0, 0.0]])
    assert n_max.tolist() == [2]

def test_gradient_only_uses_edges_near_the_uav() -> None:
    """Edges not incident to a node within ρ are ignored."""
    net = road([(0, 0), (10, 0), (20, 0), (30, 0)], [(0, 1), (1, 2), (2, 3)])
    phi = np.array([0.0, 0.5, 0.0, 9.0])  # the big jump is on edge (2, 3), out of reach
    force, n_max = GradientField(net).force([[0.0, 0.0]], phi, 5.0, np.random.default_rng(0))
    np.testing.assert_allclose(force, [[0.5, 0.0]])
    assert n_max.tolist() == [1]

def test_gradient_ties_are_random_seeded_and_cover_both_edges() -> None:
    """Tied edges are drawn uniformly from the generator: both occur, and a seed repeats."""
    field = GradientField(path_road(3))
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
    net = path_road(3)
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

def test_bad_force_inputs() -> None:
    """Bad shapes and constants are rejected, naming the field."""
    field = GradientField(path_road(3))
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


def test_edge_differences_are_head_minus_tail() -> None:
    """Δφ = Bᵀφ (5.6): φ(head) − φ(tail) per stored edge, whose head is its lower node (the
    edge given as (3, 2) is stored as (2, 3))."""
    net = road([(0, 0), (10, 0), (20, 0), (20, 10)], [(0, 1), (1, 2), (3, 2)])
    assert net.edges.tolist() == [[0, 1], [1, 2], [2, 3]]
    dphi = GradientField(net).edge_differences(np.array([0.0, 1.0, 4.0, 2.0]))
    np.testing.assert_allclose(dphi, [-1.0, -3.0, 2.0])


def test_flat_field_gives_no_gradient() -> None:
    """Δφ = 0 on every edge: zero force and n_max the head of the chosen edge."""
    net = path_road(3)
    force, n_max = GradientField(net).force([[10.0, 0.0]], np.full(3, 2.5), 15.0,
                                            np.random.default_rng(0))
    np.testing.assert_array_equal(force, [[0.0, 0.0]])
    assert n_max[0] in (0, 1)  # head of edge (0, 1) or (1, 2)


def test_gradient_of_no_uav() -> None:
    """No UAVs: empty force and node arrays."""
    force, n_max = GradientField(path_road(3)).force(np.zeros((0, 2)), np.zeros(3), 10.0,
                                                     np.random.default_rng(0))
    assert force.shape == (0, 2) and n_max.shape == (0,)


def test_pauli_scales_with_epsilon_and_ignores_a_lone_uav() -> None:
    """The repulsion is linear in ε; a single UAV feels nothing."""
    xy = [[0.0, 0.0], [150.0, 80.0]]
    np.testing.assert_allclose(pauli_force(xy, 240.0, epsilon=3.0),
                               3.0 * pauli_force(xy, 240.0), rtol=1e-12)
    np.testing.assert_array_equal(pauli_force([[5.0, 5.0]], 240.0), [[0.0, 0.0]])


def test_spring_on_its_anchor_is_still() -> None:
    """A UAV exactly on its anchor feels no force, with or without rest length."""
    for rest in (0.0, 120.0):
        np.testing.assert_array_equal(spring_force([[3.0, 4.0]], [[3.0, 4.0]], 0.5, rest),
                                      [[0.0, 0.0]])


def test_more_bad_force_inputs() -> None:
    """Bad networks, anchors, rest lengths and constants raise naming the field."""
    with pytest.raises(InvalidInputError, match="network"):
        GradientField("roads")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="anchor_xy_m"):
        spring_force([[0.0, 0.0], [1.0, 1.0]], [[1.0, 1.0]], 1.0)
    with pytest.raises(InvalidInputError, match="rest_m"):
        spring_force([[0.0, 0.0]], [[1.0, 1.0]], 1.0, -5.0)
    with pytest.raises(InvalidInputError, match="sigma_m"):
        pauli_force([[0.0, 0.0]], 0.0)
    with pytest.raises(InvalidInputError, match="speed_mps"):
        default_loiter_k(120.0, 0.0)
    with pytest.raises(InvalidInputError, match="typical_gradient"):
        default_spring_k(120.0, -1.0)
    assert default_spring_k(100.0, typical_gradient=2.0) == pytest.approx(0.02)


def test_coverage_force_points_to_the_less_covered_road() -> None:
    """On a straight road through the UAV, the ring ρ < r ≤ 2ρ holds three nodes each side;
    with the west side covered the push is (c̄ − c) summed: exactly 0.5 toward the east. Even
    coverage, or no node in the ring, gives no force."""
    net = road([(x, 0.0) for x in range(-100, 101, 10)],
               [(i, i + 1) for i in range(20)])
    west = (net.coords[:, 0] < 0).astype(float)
    force = coverage_force(net, [[0.0, 0.0]], west, 30.0, 60.0)
    np.testing.assert_allclose(force, [[0.5, 0.0]], atol=1e-12)
    np.testing.assert_allclose(coverage_force(net, [[0.0, 0.0]], 1.0 - west, 30.0, 60.0),
                               [[-0.5, 0.0]], atol=1e-12)
    for even in (np.zeros(net.n_nodes), np.ones(net.n_nodes)):
        np.testing.assert_allclose(coverage_force(net, [[0.0, 0.0]], even, 30.0, 60.0),
                                   [[0.0, 0.0]], atol=1e-12)
    np.testing.assert_array_equal(coverage_force(net, [[0.0, 500.0]], west, 30.0, 60.0),
                                  [[0.0, 0.0]])


def test_coverage_force_refuses_bad_inputs() -> None:
    """Coverage outside [0, 1] or of the wrong length, and a ring with inner ≥ outer."""
    net = path_road(5)
    for bad in (np.full(5, 1.5), np.full(4, 0.5), np.full(5, np.nan)):
        with pytest.raises(InvalidInputError, match="coverage"):
            coverage_force(net, [[0.0, 0.0]], bad, 10.0, 20.0)
    with pytest.raises(InvalidInputError, match="inner_m"):
        coverage_force(net, [[0.0, 0.0]], np.zeros(5), 20.0, 20.0)
