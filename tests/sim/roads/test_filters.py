"""The registry of road mission filters, and the seam it is for: a filter written here, on a
few arrays, flies a road mission through one registration."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.estimate.stepping import RoadFilter, RoadScan, RoadUpdate, TrackBirth, TrackPair
from searchtrack.models import RoadNetwork, SensorModel, UavState
from searchtrack.sim.roads.filters import FILTER_STREAM, FILTERS, MissionFilter
from searchtrack.sim.roads.lrt_belief import LRTMissionBelief
from searchtrack.sim.roads.mission import Mission, log_field
from searchtrack.sim.roads.rbpf_belief import RBPFMissionBelief
from searchtrack.sim.roads.scenario import FilterSpec, GuidanceSpec, MapSpec, Scenario
from searchtrack.sim.roads.world import World

SENSOR = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)


def small(belief: str = "lrt", **changes: object) -> Scenario:
    """A 6 × 6 grid of 100 m blocks, 2 UAVs, 2 targets, 30 s (a small RBPF when asked)."""
    base = Scenario("small", MapSpec("grid", rows=6, cols=6, block_m=100.0), uav_count=2,
                    target_count=2, sensor=SENSOR, altitude_m=None, duration_s=30.0, seed=3,
                    guidance=GuidanceSpec(strategy="search_and_loiter"),
                    filter=FilterSpec(belief=belief, histories=3, particles=100))  # type: ignore[arg-type]
    return dataclasses.replace(base, **changes)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def world() -> World:
    """The grid and its operators, built once."""
    return World.build(small())


class NearestNode:
    """A tiny road filter on arrays: each position fix within ``gate_m`` of a track moves that
    track to the fix's nearest node (an association), any other fix starts a track there (a
    birth); the search field is −1 where a UAV looked recently, relaxing towards 0."""

    def __init__(self, network: RoadNetwork, radius_m: float, rng: np.random.Generator) -> None:
        self.network, self.radius_m, self.rng = network, radius_m, rng
        self.score = np.zeros(network.n_nodes)
        self.nodes = np.empty(0, dtype=np.int64)
        self.ids = np.empty(0, dtype=np.int64)
        self.next_id = 0
        self.lrt_seen: list[bool] = []

    @classmethod
    def for_mission(cls, scenario: Scenario, world: World,
                    rng: np.random.Generator) -> NearestNode:
        return cls(world.network, scenario.sensor.footprint_radius_m, rng)

    @property
    def search_field(self) -> LikelihoodField:
        return LikelihoodField(self.score)

    @property
    def bank(self) -> TrackerBank:
        n = self.network.n_nodes
        return TrackerBank(n, tuple(NodeTracker(np.eye(1, n, int(v)).ravel(), int(i))
                                    for v, i in zip(self.nodes, self.ids, strict=True)),
                           self.next_id)

    def estimates_xy(self) -> FloatArray:
        return np.asarray(self.network.coords[self.nodes], dtype=np.float64).reshape(-1, 2)

    def update(self, scan: RoadScan, pose: UavState) -> RoadUpdate:
        self.lrt_seen.append(scan.lrt is not None)
        self.score[self.network.nodes_within(pose.xy_m, self.radius_m)[1]] = -1.0
        live = set(self.ids.tolist())
        pairs: list[TrackPair] = []
        births: list[TrackBirth] = []
        fixes = scan.positions
        for q, (uav, xy) in enumerate(zip(fixes.uav.tolist(), fixes.xy_m, strict=True)):
            node = int(self.network.nearest_nodes(xy[None, :])[0])
            gap = np.linalg.norm(self.estimates_xy() - xy, axis=1)
            if gap.size and gap.min() < 100.0 and int(self.ids[np.argmin(gap)]) in live:
                self.nodes[np.argmin(gap)] = node
                pairs.append((uav, int(self.ids[np.argmin(gap)]), q))
            elif gap.size == 0 or gap.min() >= 100.0:
                self.nodes = np.append(self.nodes, node)
                self.ids = np.append(self.ids, self.next_id)
                births.append(TrackBirth(self.next_id, self.network.coords[node]))
                self.next_id += 1
        return RoadUpdate(tuple(pairs), tuple(births))

    def predict(self, dt_s: float) -> None:
        self.score *= 0.99


@pytest.fixture
def nearest(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[NearestNode]]:
    """``NearestNode`` registered as ``"nearest"`` (the one registration; scenarios are told
    the name), and the filters the missions built."""
    built: list[NearestNode] = []

    def build(scenario: Scenario, world: World, rng: np.random.Generator) -> NearestNode:
        built.append(NearestNode.for_mission(scenario, world, rng))
        return built[-1]

    FILTERS.register(MissionFilter("nearest", build, reads_lrt=False, description="test"))
    try:
        yield built
    finally:
        FILTERS.unregister("nearest")


def test_a_new_filter_flies_a_mission_through_one_registration(
        world: World, nearest: list[NearestNode]) -> None:
    """The array filter flies the whole mission: the log is whole (a step per step, tracks as
    counted, associations as scored, every birth credited), its associations are scored valid
    on the targets it follows, its field is the log's; it owns a generator of the filter
    stream, and the sensors draw no ζ for it."""
    log = Mission(small("nearest"), world).run()
    (tiny,) = nearest
    n = log.scenario.n_steps
    assert len(log.time_s) == n and log.uav_xy_m.shape == (n + 1, 2, 2)
    assert [len(t) for t in log.tracks] == [st.trackers for st in log.steps]
    assert sum(len(a) for a in log.associations) == log.score.nva + log.score.nfa > 0
    assert log.score.nva > 0 and log.score.detected >= 1
    assert [b.track_id for b in log.births] == list(range(tiny.next_id))
    np.testing.assert_array_equal(log.final_llr, tiny.score)
    assert isinstance(tiny, RoadFilter) and tiny.lrt_seen == [False] * n
    expected = np.random.default_rng([FILTER_STREAM, log.scenario.seed]).random(3)
    np.testing.assert_array_equal(tiny.rng.random(3), expected)


def test_a_filter_reading_lrt_gets_the_footprints_zeta(
        world: World, nearest: list[NearestNode]) -> None:
    """Registered as reading the LRT scan, the same filter gets the ζ of every step."""
    entry = FILTERS.unregister("nearest")
    FILTERS.register(dataclasses.replace(entry, reads_lrt=True))
    log = Mission(small("nearest", duration_s=3.0), world).run()
    assert nearest[0].lrt_seen == [True] * log.scenario.n_steps


def test_the_registry_holds_the_scenarios_filters(world: World) -> None:
    """Every registered filter is a ``filter.belief`` a scenario accepts (and nothing else is),
    builds a RoadFilter of its class, and declares what it reads; the stream of a mission's
    filter is fixed by its seed."""
    assert FILTERS.names() == ["lrt", "rbpf"]
    with pytest.raises(InvalidInputError, match="belief"):
        FilterSpec(belief="nearest")
    kinds = {"lrt": (LRTMissionBelief, True), "rbpf": (RBPFMissionBelief, True)}
    for name in FILTERS.names():
        entry = FILTERS.get(name)
        built = entry.filter_for(small(name), world)
        assert isinstance(built, RoadFilter)
        assert (type(built), entry.reads_lrt_of(small(name))) == kinds[name]
    a = FILTERS.get("rbpf").filter_for(small("rbpf"), world)
    b = Mission(small("rbpf"), world).new_filter()
    for x, y in zip(a.rbpf.target_particles(), b.rbpf.target_particles(),  # type: ignore[attr-defined]
                    strict=True):
        np.testing.assert_array_equal(x, y)


def test_unknown_and_duplicate_names_are_refused() -> None:
    """An unknown name is refused naming the field and the choices; a name registers once."""
    with pytest.raises(InvalidInputError) as info:
        FILTERS.get("kalman")
    assert info.value.field == "filter.belief" and "lrt" in str(info.value)
    with pytest.raises(ValueError, match="already registered"):
        FILTERS.register(FILTERS.get("lrt"))
    with pytest.raises(InvalidInputError):
        FILTERS.unregister("kalman")


def test_the_log_keeps_each_filters_search_field(world: World) -> None:
    """The LRT's field is logged as it is; the RBPF's scores become a field of equal values."""
    lrt = FILTERS.get("lrt").filter_for(small("lrt"), world)
    assert log_field(lrt) is lrt.search_field
    rbpf = FILTERS.get("rbpf").filter_for(small("rbpf"), world)
    logged = log_field(rbpf)
    assert isinstance(logged, LikelihoodField)
    np.testing.assert_array_equal(logged.llr, rbpf.search_field.node_score())


def test_the_rbpf_searches_on_the_lrt_field_when_asked(world: World) -> None:
    """With ``filter.search_field = "lrt"`` (the default) the RBPF mission draws the
    footprints' ζ and its search field is the φ of the thesis's LRT on the same scans (a
    standalone LRT mission filter stepped alike has the same φ), while its bank and tracks stay
    the RBPF's; with ``"particles"`` the sensors draw no ζ and the field is the particle
    field."""
    from searchtrack.sim.roads.particle_field import ParticleSearchField

    hybrid = small("rbpf")
    plain = dataclasses.replace(hybrid, filter=dataclasses.replace(hybrid.filter,
                                                                   search_field="particles"))
    entry = FILTERS.get("rbpf")
    assert not entry.reads_lrt_of(plain) and entry.reads_lrt_of(hybrid)
    assert isinstance(entry.filter_for(plain, world).search_field, ParticleSearchField)
    belief = entry.filter_for(hybrid, world)
    assert isinstance(belief, RBPFMissionBelief) and belief.search is not None
    twin = LRTMissionBelief.for_mission(hybrid, world, np.random.default_rng(0))
    seen = []

    class Tap:
        """Steps the twin LRT on every scan the mission's filter gets."""

        def __init__(self, inner: RBPFMissionBelief) -> None:
            self.inner = inner

        def __getattr__(self, name: str) -> object:
            return getattr(self.inner, name)

        def update(self, scan: object, pose: object) -> object:
            twin.update(scan, pose)  # type: ignore[arg-type]
            seen.append(scan.lrt is not None)  # type: ignore[attr-defined]
            return self.inner.update(scan, pose)  # type: ignore[arg-type]

        def predict(self, dt_s: float) -> None:
            twin.predict(dt_s)
            self.inner.predict(dt_s)

    mission = Mission(hybrid, world)
    mission.new_filter = lambda: Tap(belief)  # type: ignore[method-assign,assignment,return-value]
    mission.run()
    assert seen and all(seen)
    np.testing.assert_array_equal(belief.search_field.node_score(), twin.search_field.node_score())
    assert np.any(belief.search_field.node_score() != 0.0)
    assert all(0 <= t.track_id < 2 for t in belief.bank)   # target indices: the RBPF's
