"""Taxi-like traces on roads: on the roads, within the speed limit, occupied fares, seeded."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork, random_network
from searchtrack.models.road_traces import TaxiModel, Traces, taxi_traces

MODEL = TaxiModel(min_speed_mps=6.0, max_speed_mps=12.0, dwell_min_s=5.0, dwell_max_s=20.0)


@pytest.fixture(scope="module")
def roads() -> RoadNetwork:
    """Random planar roads, 25 junctions in 800 m square, nodes every 10 m."""
    return random_network(25, 800.0, 10.0, seed=4)


@pytest.fixture(scope="module")
def traces(roads: RoadNetwork) -> Traces:
    """Eight taxis for 20 minutes, sampled every 2 s."""
    return taxi_traces(roads, 8, 1200.0, 2.0, np.random.default_rng(7), MODEL)


def _distance_to_roads(net: RoadNetwork, xy: np.ndarray) -> np.ndarray:
    """Distance (m) from each point to the nearest edge segment."""
    a, b = net.coords[net.edges[:, 0]], net.coords[net.edges[:, 1]]
    ab = b - a
    t = np.einsum("pek,ek->pe", xy[:, None, :] - a[None], ab) / np.sum(ab * ab, axis=1)
    t = np.clip(t, 0.0, 1.0)
    nearest = a[None] + t[:, :, None] * ab[None]
    return np.asarray(np.min(np.linalg.norm(xy[:, None, :] - nearest, axis=2), axis=1))


def test_shape_and_sampling(traces: Traces) -> None:
    """Each vehicle has one sample every dt over the window, in vehicle-then-time order."""
    assert traces.n_points == 8 * 600
    assert traces.vehicles.tolist() == list(range(8))
    np.testing.assert_allclose(traces.time_s[:3], [0.0, 2.0, 4.0])
    assert np.count_nonzero(traces.consecutive) == 8 * 599


def test_traces_stay_on_roads(roads: RoadNetwork, traces: Traces) -> None:
    """Every sampled position lies on a road segment."""
    assert np.max(_distance_to_roads(roads, traces.xy_m)) < 1e-6


def test_traces_respect_the_speed_limit(traces: Traces) -> None:
    """No step is longer than max_speed·dt, the cruise speeds are reached and taxis stop."""
    _, v = traces.velocities()
    speed = np.linalg.norm(v, axis=1)
    assert speed.max() <= MODEL.max_speed_mps * (1 + 1e-9)
    assert speed.max() > MODEL.min_speed_mps
    assert np.mean(speed < 1e-9) > 0.05


def test_velocities_are_forward_differences(traces: Traces) -> None:
    """velocities() pairs x_k with (x_{k+1} − x_k)/dt of the same vehicle only."""
    x, v = traces.velocities()
    assert x.shape == v.shape == (8 * 599, 2)
    np.testing.assert_allclose(x[0] + traces.dt_s * v[0], traces.xy_m[1])
    np.testing.assert_allclose(x[599], traces.xy_m[600])  # vehicle 1 starts a new run


def test_occupied_fares(traces: Traces) -> None:
    """Taxis are occupied part of the time; occupied-only velocities are a proper subset."""
    assert 0.1 < traces.occupied.mean() < 0.9
    x_all, _ = traces.velocities()
    x_occ, _ = traces.velocities(occupied_only=True)
    assert 0 < x_occ.shape[0] < x_all.shape[0]


def test_deterministic_for_a_seed(roads: RoadNetwork, traces: Traces) -> None:
    """The same seed gives the same traces; another seed different ones."""
    again = taxi_traces(roads, 8, 1200.0, 2.0, np.random.default_rng(7), MODEL)
    np.testing.assert_array_equal(again.xy_m, traces.xy_m)
    np.testing.assert_array_equal(again.occupied, traces.occupied)
    other = taxi_traces(roads, 8, 1200.0, 2.0, np.random.default_rng(8), MODEL)
    assert not np.array_equal(other.xy_m, traces.xy_m)


def test_gps_noise_moves_points_off_the_roads(roads: RoadNetwork) -> None:
    """With GPS noise the samples scatter about the roads by about σ."""
    noisy = taxi_traces(roads, 2, 300.0, 5.0, np.random.default_rng(1),
                        TaxiModel(gps_sigma_m=3.0))
    d = _distance_to_roads(roads, noisy.xy_m)
    assert 0.5 < np.median(d) < 6.0


def test_select_keeps_whole_vehicles(traces: Traces) -> None:
    """select() keeps only the chosen vehicles' samples."""
    sub = traces.select([1, 3])
    assert sub.vehicles.tolist() == [1, 3]
    assert sub.n_points == 2 * 600


@pytest.mark.parametrize(("field", "value"), [
    ("min_speed_mps", 0.0), ("max_speed_mps", 1.0), ("stop_probability", 1.5),
    ("stop_min_s", -1.0), ("stop_max_s", 1.0), ("dwell_min_s", -2.0), ("dwell_max_s", 1.0),
    ("n_hotspots", -1), ("hotspot_radius_m", 0.0), ("hotspot_share", -0.1),
    ("gps_sigma_m", -1.0),
])
def test_bad_taxi_model(field: str, value: object) -> None:
    """Every bad TaxiModel field raises InvalidInputError naming it."""
    with pytest.raises(InvalidInputError) as err:
        TaxiModel(**{field: value})  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"n_vehicles": 0}, "n_vehicles"), ({"duration_s": 0.0}, "duration_s"),
    ({"dt_s": -1.0}, "dt_s"), ({"rng": 3}, "rng"), ({"model": "fast"}, "model"),
    ({"network": "roads"}, "network"),
])
def test_bad_taxi_traces_arguments(roads: RoadNetwork, kwargs: dict[str, object],
                                   field: str) -> None:
    """Bad arguments of taxi_traces raise InvalidInputError naming the argument."""
    args: dict[str, object] = {"network": roads, "n_vehicles": 2, "duration_s": 60.0,
                               "dt_s": 1.0, "rng": np.random.default_rng(0)}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        taxi_traces(**args)  # type: ignore[arg-type]
    assert err.value.field == field


def test_disconnected_network_is_refused() -> None:
    """A network of two separate roads is refused."""
    net = RoadNetwork(coords=np.array([[0.0, 0.0], [10.0, 0.0], [50.0, 0.0], [60.0, 0.0]]),
                      edges=np.array([[0, 1], [2, 3]]), lengths_m=np.array([10.0, 10.0]))
    with pytest.raises(InvalidInputError, match="connected"):
        taxi_traces(net, 1, 10.0, 1.0, np.random.default_rng(0))


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"vehicle": [1, 0]}, "vehicle"), ({"time_s": [1.0, 0.0]}, "time_s"),
    ({"xy_m": [[0.0, 0.0]]}, "xy_m"), ({"occupied": [1, 0]}, "occupied"),
    ({"dt_s": 0.0}, "dt_s"),
])
def test_bad_traces(kwargs: dict[str, object], field: str) -> None:
    """Unsorted vehicles, non-increasing times, bad shapes or types are refused."""
    args: dict[str, object] = {"vehicle": [0, 0], "time_s": [0.0, 1.0],
                               "xy_m": [[0.0, 0.0], [1.0, 0.0]], "occupied": [True, False],
                               "dt_s": 1.0}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        Traces(**args)  # type: ignore[arg-type]
    assert err.value.field == field
