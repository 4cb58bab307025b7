"""The belief seam: every guidance backend gives the same answer on the library's beliefs (LRT
field, tracker bank, graph diffusion) and on small independent implementations of the protocols
fed the same numbers."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from scipy.linalg import expm

from searchtrack.core.types import FloatArray
from searchtrack.estimate.belief import (
    BeliefBank,
    NodePredictor,
    SearchField,
    SparseNodePredictor,
    TrackBelief,
)
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.models.road_synthetic import grid_network
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance import (
    BACKENDS,
    Guidance,
    GuidanceProblem,
    GuidanceView,
    StrategyConfig,
    pair_uavs,
    reacquire_time,
    solve,
)


@dataclass(frozen=True, eq=False)
class ArrayTrack:
    """One target's location as a bare array."""

    p: FloatArray
    track_id: int

    @property
    def n_nodes(self) -> int:
        return int(self.p.size)

    def node_probability(self) -> FloatArray:
        return np.array(self.p, copy=True)

    def mass(self) -> float:
        return 1.0

    def peak_node(self) -> int:
        return int(np.argmax(self.p))

    def entropy(self) -> float:
        q = self.p[self.p > 0]
        return float(-(q * np.log(q)).sum())


@dataclass(frozen=True, eq=False)
class ArrayBank:
    """Track beliefs in a tuple."""

    tracks: tuple[ArrayTrack, ...]
    n_nodes: int

    def __len__(self) -> int:
        return len(self.tracks)

    def __getitem__(self, index: int) -> ArrayTrack:
        return self.tracks[index]


@dataclass(frozen=True, eq=False)
class ArrayField:
    """A search score as a bare array."""

    score: FloatArray

    @property
    def n_nodes(self) -> int:
        return int(self.score.size)

    def node_score(self) -> FloatArray:
        return self.score


@dataclass(frozen=True, eq=False)
class DenseStep:
    """A prediction step by a dense matrix (no sparse operator: the fallback path)."""

    matrix: FloatArray
    dt_s: float

    @property
    def n_nodes(self) -> int:
        return int(self.matrix.shape[0])

    def propagate(self, values: FloatArray) -> FloatArray:
        return np.asarray(self.matrix @ values, dtype=np.float64)


ALPHA, DT_S = 0.05, 0.3


def _scene(seed: int) -> tuple[RoadNetwork, np.ndarray, FloatArray, tuple[NodeTracker, ...]]:
    """A 5 × 5 grid, three UAVs, a noisy LRT field and three trackers: one sharp (peak > ϱ),
    two fading (diffused point masses)."""
    rng = np.random.default_rng(seed)
    net = grid_network(5, 5, 100.0, 20.0)
    diff = GraphDiffusion.on_network(net, ALPHA, DT_S)
    trackers = []
    for k, (node, steps) in enumerate(zip(rng.choice(net.n_nodes, 3, replace=False),
                                          (0, 120, 200), strict=True)):
        p = np.zeros(net.n_nodes)
        p[node] = 1.0
        for _ in range(steps):
            p = np.maximum(diff.propagate(p), 0.0)
        trackers.append(NodeTracker(p / p.sum(), k))
    xy = rng.uniform(0.0, 400.0, (3, 2))
    return net, xy, rng.normal(size=net.n_nodes), tuple(trackers)


def _problems(seed: int) -> tuple[GuidanceProblem, GuidanceProblem]:
    """The same numbers behind the library's beliefs and behind the array ones."""
    net, xy, llr, trackers = _scene(seed)
    cfg = StrategyConfig(sensor_range_m=30.0, speed_mps=20.0)
    o = xy.shape[0]
    bank = TrackerBank(net.n_nodes, trackers, len(trackers))
    real = GuidanceView(net, xy, np.zeros(o), np.full(o, 20.0), LikelihoodField(llr), bank, 0.0)
    arrays = ArrayBank(tuple(ArrayTrack(t.probability, t.track_id) for t in trackers),
                       net.n_nodes)
    mine = GuidanceView(net, xy, np.zeros(o), np.full(o, 20.0), ArrayField(llr), arrays, 0.0)
    dense = DenseStep(expm(-ALPHA * DT_S * net.laplacian.toarray()), DT_S)
    return (GuidanceProblem(real, cfg, GraphDiffusion.on_network(net, ALPHA, DT_S)),
            GuidanceProblem(mine, cfg, dense))


def test_array_beliefs_satisfy_the_protocols() -> None:
    """The array implementations and the library's beliefs both pass the runtime checks."""
    real, mine = _problems(0)
    for problem in (real, mine):
        assert isinstance(problem.view.field, SearchField)
        assert isinstance(problem.view.bank, BeliefBank)
        assert isinstance(problem.view.bank[0], TrackBelief)
        assert isinstance(problem.predictor, NodePredictor)
    assert isinstance(real.predictor, SparseNodePredictor)
    assert not isinstance(mine.predictor, SparseNodePredictor)


def _same(a: Guidance, b: Guidance) -> None:
    np.testing.assert_allclose(a.force, b.force, rtol=1e-9, atol=1e-9)
    assert a.mode == b.mode and a.route == b.route
    assert a.pairing.tracker == b.pairing.tracker and a.pairing.track_id == b.pairing.track_id
    np.testing.assert_allclose(a.pairing.peak_probability, b.pairing.peak_probability)
    assert [(r.track_id, r.uav, r.nodes, r.served) for r in a.reacquisitions] == [
        (r.track_id, r.uav, r.nodes, r.served) for r in b.reacquisitions]


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("backend", BACKENDS.names())
def test_backends_agree_across_belief_implementations(backend: str, seed: int) -> None:
    """Two chained steps of every backend: same forces, modes, routes and objectives on the
    library's beliefs and on the array ones."""
    real, mine = _problems(seed)
    for step in range(2):
        a = solve(real, backend=backend, time_limit_s=5.0, seed=10 * seed + step)
        b = solve(mine, backend=backend, time_limit_s=5.0, seed=10 * seed + step)
        assert a.plan is not None and b.plan is not None
        _same(a.plan, b.plan)
        assert a.objective == pytest.approx(b.objective)
        real, mine = real.following(real.view, a.plan), mine.following(mine.view, b.plan)


def test_fading_trackers_make_routes() -> None:
    """The scenes exercise reacquisition: some seed plans a route."""
    planned = [solve(_problems(seed)[0], backend="search_and_reacquire", time_limit_s=5.0).plan
               for seed in range(3)]
    assert any(g is not None and "reacquire" in g.mode for g in planned)


def test_reacquire_time_and_pairing_read_the_protocols() -> None:
    """``reacquire_time`` (sparse and dense paths) and ``pair_uavs`` agree on both."""
    real, mine = _problems(1)
    for k in range(3):
        p = real.view.bank[k].node_probability()
        assert reacquire_time(real.predictor, p) == pytest.approx(
            reacquire_time(mine.predictor, p))
    a = pair_uavs(real.view.network, real.view.uav_xy_m, real.view.bank)
    b = pair_uavs(mine.view.network, mine.view.uav_xy_m, mine.view.bank)
    assert a == b
