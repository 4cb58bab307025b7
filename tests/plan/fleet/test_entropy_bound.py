"""Theorem 1 of paper 000 (Lemmas 2–4, Eqs. 27–29, 32, 37, 40) and Corollary 1 (Eq. 47): the
entropy bound on the paper's 3 × 3 map and the variance it stands for."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork
from searchtrack.plan.fleet import (
    BoundConfig,
    BoundMap,
    entropy_bound,
    expected_entropy,
    gaussian_entropy,
    required_entropy,
    split_profile,
    steady_variance,
    variance_at,
    variance_bound,
)
from searchtrack.plan.fleet.entropy_bound import Growth

from .conftest import grid_3x3

#: B_L (nats) on the 3 × 3 map, 100 m blocks, v 10, V_a 40, σ_v 4, R 5, δ_t 0.1, 1 m bins, for
#: (σ²_p0 by Eq. 37 | by the authors' code) × (S_node with | without the diagonal), Q applied as
#: T/Q to both T_Q and σ²_p0. The reference averages E[H_k] over k = 0…⌊T_Q⌋−1, one revisit
#: period (``average="period"``); Eq. 27 as printed (``"printed"``) is 0.005–0.04 higher.
B3 = {
    (2, 1): (2.80, 2.88, 2.68, 2.77),
    (10, 1): (3.54, 3.66, 3.49, 3.62),
    (10, 2): (2.97, 3.06, 2.88, 2.97),
    (10, 3): (2.74, 2.80, 2.61, 2.68),
    (10, 4): (2.59, 2.65, 2.44, 2.51),
}
VARIANTS: tuple[tuple[Growth, bool], ...] = (("paper", True), ("paper", False), ("code", True),
                                            ("code", False))


@pytest.fixture(scope="module")
def roads() -> RoadNetwork:
    """The paper's 3 × 3 map with 100 m blocks."""
    return grid_3x3()


@pytest.mark.parametrize(("case", "reference"), list(B3.items()), ids=[f"M{m}Q{q}" for m, q in B3])
def test_theorem_1_reproduces_the_bound_table(roads: RoadNetwork, case: tuple[int, int],
                                              reference: tuple[float, ...]) -> None:
    """Each cell of the B_L table within 0.01 in its variant (the table has 2 decimals)."""
    targets, uavs = case
    for (growth, diagonal), expected in zip(VARIANTS, reference, strict=True):
        config = BoundConfig(targets, growth=growth, include_diagonal=diagonal)
        bound = entropy_bound(BoundMap.from_network(roads, config), config, uavs)
        assert bound.bound == pytest.approx(expected, abs=0.01), (growth, diagonal)


def test_printed_average_adds_the_last_step(roads: RoadNetwork) -> None:
    """Eq. 27 as printed sums k = 0…⌊T_Q⌋ and divides by T_Q; the period mean stops a step
    earlier and divides by the number of terms."""
    period = BoundConfig(10)
    printed = dataclasses.replace(period, average="printed")
    bound_map = BoundMap.from_network(roads, period)
    a, b = entropy_bound(bound_map, period, 2), entropy_bound(bound_map, printed, 2)
    n = math.floor(a.steps)
    assert a.expected.size == n and b.expected.size == n + 1
    np.testing.assert_allclose(b.expected[:n], a.expected)
    assert b.bound * b.steps == pytest.approx(a.bound * n + b.expected[-1])
    assert b.bound > a.bound


def test_steady_variance_solves_lemma_3() -> None:
    """σ²_p0 = 3.92 m² for M = 2, Q = 1 (T_ave = 8.89 s) and is the fixed point of the
    information update 1/σ² = 1/(σ² + T δ_t σ_v²) + 1/R (Eq. 38); the code variant uses
    T δ_t² σ_v²."""
    revisit = 2 * 177.7778 / 40.0
    var = steady_variance(revisit, 4.0, 0.1, 5.0)
    assert var == pytest.approx(3.92, abs=5e-3)
    assert 1 / var == pytest.approx(1 / (var + revisit * 0.1 * 16.0) + 1 / 5.0)
    code = steady_variance(revisit, 4.0, 0.1, 5.0, growth="code")
    assert 1 / code == pytest.approx(1 / (code + revisit * 0.01 * 16.0) + 1 / 5.0)
    assert steady_variance(1e-9, 4.0, 0.1, 5.0) == pytest.approx(math.sqrt(5.0 * 1.6e-9), rel=1e-3)


def test_variance_grows_linearly() -> None:
    """σ²_{p,k} = σ²_{p0} + σ_v² δ_t² k (Eq. 32)."""
    np.testing.assert_allclose(variance_at(3.0, 4.0, 0.1, [0, 1, 10]), [3.0, 3.16, 4.6])


@pytest.mark.parametrize(("variance", "entropy"), [(16.0, 2.805), (19.0, 2.891)])
def test_gaussian_entropy_on_1_m_bins(variance: float, entropy: float) -> None:
    """½ ln(2πeσ²) on 1 m bins: 2.805 nats for 16 m², 2.891 for 19 m² (Eq. 40)."""
    h, mass = gaussian_entropy(variance, 1200.0)
    assert float(h) == pytest.approx(entropy, abs=1e-3)
    assert float(mass) == pytest.approx(1.0)
    h_mass, _ = gaussian_entropy(variance, 1200.0, binning="mass")
    assert float(h_mass) == pytest.approx(entropy, abs=4e-3)


def test_gaussian_entropy_matches_the_continuous_form_and_is_vectorised() -> None:
    """For σ² ≥ 2 the 1 m-bin entropy is within 0.02 of ½ ln(2πeσ²); 2 m bins lose ln 2."""
    var = np.array([2.0, 5.0, 50.0, 400.0])
    h, _ = gaussian_entropy(var, 1200.0)
    np.testing.assert_allclose(h, 0.5 * np.log(2 * np.pi * np.e * var), atol=0.02)
    h2, _ = gaussian_entropy(var[1:], 1200.0, bin_m=2.0)
    np.testing.assert_allclose(h2, h[1:] - math.log(2.0), atol=1e-3)


def test_map_cuts_the_tails() -> None:
    """A Gaussian wider than the map loses mass outside it."""
    _, mass = gaussian_entropy(100.0**2, 200.0)
    assert 0.6 < float(mass) < 0.7


def test_expected_entropy_adds_the_split(roads: RoadNetwork) -> None:
    """E[H_k] is the single-mode entropy plus Σ_D P_D ln(1/D) (Eq. 29); at k = 0 only one
    mode exists."""
    bound_map = BoundMap.from_network(roads, BoundConfig(2))
    profile = split_profile(bound_map.chains, 10.0, 0.1, 150)
    var = np.full(151, 16.0)
    e = expected_entropy(var, profile, 1200.0)
    assert e[0] == pytest.approx(2.805, abs=1e-3)
    np.testing.assert_allclose(e - e[0], profile.split_entropy, atol=1e-12)
    with pytest.raises(InvalidInputError, match="variance_m2"):
        expected_entropy(np.full(152, 16.0), profile, 1200.0)


def test_corollary_1_inverts_the_entropy() -> None:
    """B_L = 2.89 nats is "19 m", i.e. σ_p² = 18.96 m²; 2.805 is 16 m²; five modes of degree
    1/5 add ln 5."""
    config = BoundConfig(10)
    assert variance_bound(2.89, 1200.0, config) == pytest.approx(18.96, abs=0.01)
    assert variance_bound(2.805, 1200.0, config) == pytest.approx(16.0, abs=0.01)
    five = required_entropy(3.0, 1200.0, config, degree=0.2)
    assert five == pytest.approx(required_entropy(3.0, 1200.0, config) + math.log(5.0))
    assert variance_bound(five, 1200.0, config, degree=0.2) == pytest.approx(3.0, rel=1e-6)


@pytest.mark.parametrize(("entropy", "degree", "name"), [
    (math.nan, 1.0, "entropy"), (-3.0, 1.0, "entropy"), (40.0, 1.0, "entropy"),
    (2.0, 0.0, "degree"), (2.0, 1.5, "degree"),
])
def test_corollary_1_refuses_what_it_cannot_invert(entropy: float, degree: float,
                                                  name: str) -> None:
    """Entropies outside the invertible range and degrees outside (0, 1] name the field."""
    with pytest.raises(InvalidInputError, match=name):
        variance_bound(entropy, 1200.0, BoundConfig(10), degree=degree)


def test_variance_revisit_variants(roads: RoadNetwork) -> None:
    """``revisit="single"`` keeps σ²_p0 of one UAV whatever Q; ``"fleet"`` shrinks it with T/Q."""
    fleet = BoundConfig(10)
    single = dataclasses.replace(fleet, revisit="single")
    bound_map = BoundMap.from_network(roads, fleet)
    one = entropy_bound(bound_map, fleet, 1)
    assert entropy_bound(bound_map, single, 3).variance0_m2 == pytest.approx(one.variance0_m2)
    assert entropy_bound(bound_map, fleet, 3).variance0_m2 < one.variance0_m2


@pytest.mark.parametrize(("field", "value"), [
    ("targets", 0), ("targets", 1), ("targets", -2), ("targets", 2.0), ("targets", True),
    ("uav_speed_mps", math.nan), ("uav_speed_mps", 0.0), ("target_speed_mps", -10.0),
    ("sigma_v_mps", math.inf), ("meas_var_m2", 0.0), ("dt_s", -0.1), ("bin_m", math.nan),
    ("uav_speed_mps", "40"), ("include_diagonal", 1), ("growth", "kalman"),
    ("revisit", "double"), ("average", "mean"), ("binning", "pdf"),
])
def test_config_names_the_bad_field(field: str, value: object) -> None:
    """Every field of BoundConfig is checked; the error names it."""
    kwargs: dict[str, object] = {"targets": 10, field: value}
    with pytest.raises(InvalidInputError, match=field):
        BoundConfig(**kwargs)  # type: ignore[arg-type]


def test_bound_refuses_bad_fleets_and_profiles(roads: RoadNetwork) -> None:
    """Zero UAVs, a revisit shorter than a step, a short profile or one of another step size,
    and a σ²_p0 below what 1 m density bins resolve are refused, naming the field."""
    config = BoundConfig(10)
    bound_map = BoundMap.from_network(roads, config)
    for uavs in (0, -1, 1.5, 10_000):
        with pytest.raises(InvalidInputError, match="uavs"):
            entropy_bound(bound_map, config, uavs)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="profile"):
        entropy_bound(bound_map, config, 1, bound_map.profile(config, 4))
    with pytest.raises(InvalidInputError, match="profile"):
        entropy_bound(bound_map, config, 1, split_profile(bound_map.chains, 10.0, 0.05, 1000))
    tiny = dataclasses.replace(config, meas_var_m2=0.01)
    with pytest.raises(InvalidInputError, match="binning"):
        entropy_bound(bound_map, tiny, 1)
    assert entropy_bound(bound_map, dataclasses.replace(tiny, binning="mass"), 1).bound > 0
