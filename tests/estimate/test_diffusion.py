"""Graph diffusion: closed forms, mass conservation, decay toward neutral, both backends."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate import GraphDiffusion
from searchtrack.estimate.diffusion import Method, Weighting
from searchtrack.models import grid_network, random_network

from .conftest import path_network

ALPHA, DT, C = 0.447, 0.3, 50.0


@pytest.mark.parametrize("method", ["cached", "expm_multiply"])
def test_three_node_path_matches_eigen_decomposition(method: Method) -> None:
    """A delta on node 0 of a 3-node path is 1/3 + e^{−τ}/2 (1,0,−1) + e^{−3τ}/6 (1,−2,1)."""
    diff = GraphDiffusion.on_network(path_network(3), ALPHA, DT, decay_c=C, method=method)
    tau = ALPHA * DT
    expected = (np.full(3, 1 / 3) + math.exp(-tau) / 2 * np.array([1, 0, -1])
                + math.exp(-3 * tau) / 6 * np.array([1, -2, 1])) * math.exp(-tau / C)
    np.testing.assert_allclose(diff.propagate([1.0, 0.0, 0.0]), expected, rtol=0, atol=1e-14)


@pytest.mark.parametrize("method", ["cached", "expm_multiply"])
def test_diffusion_without_decay_conserves_mass(method: Method) -> None:
    """Without decay the total of every column is unchanged, step after step."""
    net = random_network(25, 800.0, seed=3)
    diff = GraphDiffusion.on_network(net, ALPHA, DT, method=method)
    x = np.random.default_rng(0).random((net.n_nodes, 3))
    total = x.sum(axis=0)
    for _ in range(20):
        x = diff.propagate(x)
    np.testing.assert_allclose(x.sum(axis=0), total, rtol=1e-12)


@pytest.mark.parametrize(
    ("alpha", "dt_s", "weighting"),
    [(ALPHA, DT, "unweighted"), (2.0, 1.0, "unweighted"), (ALPHA, DT, "length"),
     (50.0, 2.0, "length")],
)
def test_cached_operator_agrees_with_expm_multiply(
    alpha: float, dt_s: float, weighting: Weighting
) -> None:
    """The cached sparse operator and expm_multiply agree to 1e-10 on a grid."""
    net = grid_network(4, 5)
    diff = GraphDiffusion.on_network(net, alpha, dt_s, decay_c=C, weighting=weighting)
    assert diff.operator is not None
    x = np.random.default_rng(1).normal(scale=10.0, size=(net.n_nodes, 2))
    np.testing.assert_allclose(diff.propagate(x), diff.propagate_expm_multiply(x), rtol=0,
                               atol=1e-10)


def test_lrt_prediction_decays_toward_neutral() -> None:
    """With decay, a uniform field shrinks by e^{−αΔt/C} a step and any field relaxes to φ = 0."""
    net = grid_network(3, 3)
    diff = GraphDiffusion.on_network(net, ALPHA, DT, decay_c=C)
    uniform = diff.propagate(np.full(net.n_nodes, 8.0))
    np.testing.assert_allclose(uniform, 8.0 * math.exp(-ALPHA * DT / C), rtol=1e-13)
    phi = np.random.default_rng(2).normal(scale=5.0, size=net.n_nodes)
    peaks = [np.abs(phi).max()]
    means = [phi.mean()]
    for _ in range(3000):
        phi = diff.propagate(phi)
        peaks.append(np.abs(phi).max())
        means.append(phi.mean())
    assert np.all(np.diff(peaks) <= 1e-12)
    np.testing.assert_allclose(means[-1], means[0] * math.exp(-3000 * ALPHA * DT / C), rtol=1e-9)
    assert peaks[-1] < 0.01 * peaks[0]


def test_falls_back_to_expm_multiply_when_the_operator_is_too_dense() -> None:
    """A cap on entries per node abandons the cache and still gives the right answer."""
    net = grid_network(3, 3)
    diff = GraphDiffusion.on_network(net, 5.0, 1.0)
    capped = GraphDiffusion(net.laplacian, 5.0, 1.0, max_nnz_per_node=3)
    assert capped.operator is None
    x = np.random.default_rng(4).random(net.n_nodes)
    np.testing.assert_allclose(capped.propagate(x), diff.propagate(x), atol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [({"alpha": -0.1}, "alpha"), ({"alpha": math.nan}, "alpha"), ({"dt_s": 0.0}, "dt_s"),
     ({"decay_c": 0.0}, "decay_c"), ({"decay_c": -math.inf}, "decay_c"),
     ({"method": "dense"}, "method")],
)
def test_bad_parameters_name_the_field(kwargs: dict[str, object], name: str) -> None:
    """Invalid diffusivity, step, decay or method raise InvalidInputError naming the field."""
    args: dict[str, object] = {"alpha": ALPHA, "dt_s": DT, "decay_c": C, "method": "cached"}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        GraphDiffusion(path_network(3).laplacian, **args)  # type: ignore[arg-type]
    assert err.value.field == name


def test_bad_values_shape_names_the_field() -> None:
    """Propagating a vector of the wrong length names ``values``."""
    diff = GraphDiffusion.on_network(path_network(3), ALPHA, DT)
    with pytest.raises(InvalidInputError) as err:
        diff.propagate(np.zeros(4))
    assert err.value.field == "values"
