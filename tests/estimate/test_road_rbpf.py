"""The road RBPF: tracking, negative information, data association sampling, joint association,
history weights, determinism, the belief seams and bad input."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import BeliefBank, NodeBelief, RoadParticleBelief, TrackBelief
from searchtrack.estimate.particle_belief import ParticleBelief
from searchtrack.estimate.road_entropy import map_positions
from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
from searchtrack.estimate.road_resampling import KLDSampling
from searchtrack.models import RoadNetwork, grid_network
from searchtrack.models.road_particles import DirectedRoads, RoadMotion

CENTRE = np.array([100.0, 100.0])
STILL = RoadMotion(0.0, 0.0)


@pytest.fixture(scope="module")
def grid3() -> DirectedRoads:
    """The paper's 3×3 map of 100 m roads."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


@pytest.fixture(scope="module")
def line() -> DirectedRoads:
    """A straight 400 m road along x with nodes every 50 m."""
    coords = np.column_stack([np.arange(9) * 50.0, np.zeros(9)])
    edges = np.column_stack([np.arange(8), np.arange(1, 9)])
    return DirectedRoads(RoadNetwork(coords, edges, np.full(8, 50.0)))


def _clouds(line: DirectedRoads, spans: list[tuple[float, float]], n: int,
            seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Target clouds uniform on ``[a, b]`` of the line, one row per span."""
    rng = np.random.default_rng(seed)
    x = np.stack([rng.uniform(a, b, n) for a, b in spans])
    edge, s = line.nearest(np.column_stack([x.ravel(), np.zeros(x.size)]))
    return edge.reshape(x.shape), s.reshape(x.shape)


def _pt(x: float) -> np.ndarray:
    return np.array([x, 0.0])


@pytest.mark.parametrize("counts", [None, KLDSampling()])
def test_single_target_is_tracked(grid3: DirectedRoads, counts: KLDSampling | None) -> None:
    """M = 1, a UAV over the target scanning at 1 Hz: the MAP point ends within 10 m; with
    KLD-sampling the localised clouds hold far fewer particles than the cap."""
    rng = np.random.default_rng(0)
    f = RoadRBPF(grid3, RBPFConfig(n_targets=1, n_histories=5, n_particles=500,
                                   counts=counts), rng)
    te, ts = grid3.uniform(1, rng)
    for k in range(200):
        te, ts = RoadMotion(10.0, 2.0).step(grid3, te, ts, 0.1, rng)
        f.predict(0.1, rng)
        if k % 10 == 9:
            truth = grid3.point(te, ts)
            f.update(f.config.sensor.detect(truth[0], truth, rng, grid3), truth[0], rng)
    assert np.hypot(*(f.map_positions()[0] - grid3.point(te, ts)[0])) < 10.0
    assert np.all(f.clouds.count < 300) if counts else np.all(f.clouds.count == 500)


def test_a_miss_moves_mass_out_of_the_view_in_every_history(grid3: DirectedRoads) -> None:
    """No detection: every filter of every history loses the mass near the UAV (Eq. 11)."""
    rng = np.random.default_rng(1)
    f = RoadRBPF(grid3, RBPFConfig(n_targets=2, n_histories=4, n_particles=2000), rng)
    near = np.linalg.norm(f.clouds.points() - CENTRE, axis=-1) <= 22.5
    assert near.mean() > 0.05
    f.update(np.empty((0, 2)), CENTRE, rng)
    near = np.linalg.norm(f.clouds.points() - CENTRE, axis=-1) <= 22.5
    assert near.shape == (8, 2000) and near.mean(axis=1).max() < 0.01


def test_das_keeps_two_hypotheses_then_resolves_them(line: DirectedRoads) -> None:
    """A detection both targets could explain splits the histories; a later detection that only
    one hypothesis explains removes the other."""
    cfg = RBPFConfig(n_targets=2, n_histories=40, n_particles=400, motion=STILL,
                     break_symmetry=False)
    edge, s = _clouds(line, [(90.0, 130.0), (110.0, 170.0)], 400)
    f = RoadRBPF.from_particles(line, cfg, edge, s)
    rng = np.random.default_rng(2)
    f.update(_pt(120.0)[None], _pt(120.0), rng)      # target 0 at 120 m, seen
    p = f.association_probabilities()[0]
    assert 0.2 < p[0] < 0.85 and p.sum() == pytest.approx(1.0)
    assert set(f.last_association[:, 0].tolist()) == {0, 1}
    f.update(_pt(160.0)[None], _pt(160.0), rng)      # target 1 at 160 m, seen
    np.testing.assert_allclose(f.association_probabilities()[0], [0.0, 1.0], atol=1e-6)
    for h in range(cfg.n_histories):
        pos = map_positions(f.bins, *f.history_particles(h))
        np.testing.assert_allclose(pos[:, 0], [120.0, 160.0], atol=5.0)


def test_joint_association_gives_one_detection_per_target(line: DirectedRoads) -> None:
    """Two detections near target 0 both go to it sequentially, but to different targets when
    the scan is associated jointly; a third is clutter once both targets are used."""
    edge, s = _clouds(line, [(95.0, 105.0), (295.0, 305.0)], 200)
    ys = np.array([[100.0, 0.0], [102.0, 0.0], [101.0, 0.0]])
    out = {}
    for mode in ("sequential", "joint"):
        cfg = RBPFConfig(n_targets=2, n_histories=8, n_particles=200, motion=STILL,
                         association=mode, break_symmetry=False)  # type: ignore[arg-type]
        f = RoadRBPF.from_particles(line, cfg, edge, s)
        f.update(ys, _pt(100.0), np.random.default_rng(3))
        out[mode] = f.last_association
    assert np.all(out["sequential"] == 0)
    joint = out["joint"]
    assert np.all(np.sort(joint[:, :2], axis=1) == [0, 1]) and np.all(joint[:, 2] == -1)


def test_history_weights_use_negative_information(line: DirectedRoads) -> None:
    """A history whose target sits under the UAV loses weight on a miss (Eq. 11, Eq. 13)."""
    for weigh, x in ((True, 300.0), (False, 120.0)):
        cfg = RBPFConfig(n_targets=1, n_histories=2, n_particles=100, motion=STILL,
                         weigh_misses=weigh)
        edge, s = _clouds(line, [(115.0, 125.0)], 100)
        f = RoadRBPF.from_particles(line, cfg, edge, s)
        f.clouds.edge[1], f.clouds.s[1] = _clouds(line, [(295.0, 305.0)], 100)
        f.update(np.empty((0, 2)), _pt(120.0), np.random.default_rng(4))
        assert f.map_positions()[0, 0] == pytest.approx(x, abs=5.0)
        np.testing.assert_allclose(f.weights, 0.5)


@pytest.mark.parametrize(("weight", "counts"), [("marginal", None), ("sampled", None),
                                               ("marginal", KLDSampling())])
def test_association_is_accurate_on_a_simulated_run(grid3: DirectedRoads, weight: str,
                                                    counts: KLDSampling | None) -> None:
    """Two targets on the 3×3 map, a UAV chasing them in turn: ≥ 90 % of the scans with true
    detections get the right labels in the best history (labels up to one permutation), with
    fixed counts and with KLD-sampling."""
    rng = np.random.default_rng(5)
    f = RoadRBPF(grid3, RBPFConfig(n_targets=2, history_weight=weight,  # type: ignore[arg-type]
                                   counts=counts), rng)
    te, ts = grid3.uniform(2, rng)
    uav, chase, scans = CENTRE.copy(), 0, []
    for k in range(900):
        te, ts = RoadMotion(10.0, 2.0).step(grid3, te, ts, 0.1, rng)
        f.predict(0.1, rng)
        pts = grid3.point(te, ts)
        gap = pts[chase] - uav
        uav = uav + gap * min(1.0, 4.0 / max(float(np.hypot(*gap)), 1e-9))
        if k % 10 == 9:
            y, src = f.config.sensor.detect_labelled(uav, pts, rng, grid3)
            f.update(y, uav, rng)
            chase = 1 - chase if np.any(src == chase) else chase
            if np.any(src >= 0):
                scans.append((src[src >= 0], f.best_association()[src >= 0]))
    assert len(scans) >= 30
    best = max(sum(bool(np.all(np.array(p)[est] == truth)) for truth, est in scans)
               for p in itertools.permutations(range(2)))
    assert best / len(scans) >= 0.9


def test_deterministic_for_a_seed(grid3: DirectedRoads) -> None:
    """Same seed and scans, same state."""
    runs = []
    for _ in range(2):
        rng = np.random.default_rng(6)
        f = RoadRBPF(grid3, RBPFConfig(n_targets=2, n_histories=4, n_particles=100), rng)
        for k in range(5):
            f.step(0.5, [[100.0, 40.0 + 5 * k]] if k % 2 else np.empty((0, 2)),
                   [100.0, 40.0 + 5 * k], rng)
        runs.append((*f.target_particles(), f.weights.copy(), f.scores.copy()))
    for a, b in zip(*runs, strict=True):
        np.testing.assert_array_equal(a, b)


def test_belief_seams(grid3: DirectedRoads) -> None:
    """The filter is a RoadParticleBelief and adapts to node beliefs and a particle belief."""
    rng = np.random.default_rng(7)
    f = RoadRBPF(grid3, RBPFConfig(n_targets=3, n_histories=4, n_particles=100,
                                   keep_history=True), rng)
    f.update([[100.0, 30.0]], [100.0, 30.0], rng)
    f.update([[100.0, 33.0], [0.0, 150.0]], [50.0, 80.0], rng)
    assert isinstance(f, RoadParticleBelief) and f.n_targets == 3 and f.roads is grid3
    edge, _, w = f.target_particles()
    assert edge.shape == (3, 100) and edge.dtype == np.int64
    np.testing.assert_allclose(w.sum(axis=1), 1.0)
    assert f.target_entropy().shape == (3,) and f.history_entropy().shape == (4, 3)
    assert f.map_positions().shape == (3, 2)
    assert f.combined_entropy(1.0) > f.combined_entropy(5.0)
    beliefs = f.node_beliefs()
    assert len(beliefs) == 3
    assert all(isinstance(b, NodeBelief) and isinstance(b, TrackBelief) for b in beliefs)
    np.testing.assert_allclose([b.mass() for b in beliefs], 1.0)
    bank = f.belief_bank()
    assert isinstance(bank, BeliefBank) and len(bank) == 3 and bank.n_nodes == 9
    pb = f.particle_belief()
    assert isinstance(pb, ParticleBelief) and pb.positions.shape == (300, 2)
    assert pb.expected_count() == pytest.approx(3.0)
    assert f.association_history().shape == (4, 3)
    assert f.best_association().shape == (2,) and f.association_probabilities().shape == (2, 3)
    assert np.all(f.association_history()[:, 0] == 0)  # the first detection breaks symmetry


def test_bad_input_names_the_field(grid3: DirectedRoads) -> None:
    """Detections, UAV position, generator, config fields and initial clouds are checked."""
    rng = np.random.default_rng(8)
    f = RoadRBPF(grid3, RBPFConfig(n_targets=2, n_histories=2, n_particles=10), rng)
    with pytest.raises(InvalidInputError, match="detections"):
        f.update([[np.nan, 0.0]], CENTRE, rng)
    with pytest.raises(InvalidInputError, match="detections"):
        f.update([[0.0, 0.0, 0.0]], CENTRE, rng)
    with pytest.raises(InvalidInputError, match="uav_xy"):
        f.update(np.empty((0, 2)), [1.0], rng)
    with pytest.raises(InvalidInputError, match="rng"):
        f.update(np.empty((0, 2)), CENTRE, None)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="dt_s"):
        f.predict(-1.0, rng)
    with pytest.raises(InvalidInputError, match=r"^h="):
        f.history_particles(2)
    with pytest.raises(InvalidInputError, match="keep_history"):
        f.association_history()
    for field, value in (("n_targets", 0), ("n_histories", -1), ("n_particles", 2.5),
                         ("association", "greedy"), ("history_weight", "max"),
                         ("bin_m", 0.0), ("motion", "fast")):
        kwargs = {"n_targets": 2, field: value}
        with pytest.raises(InvalidInputError, match=field):
            RBPFConfig(**kwargs)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="config"):
        RoadRBPF(grid3, object(), rng)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match=r"^edge="):
        RoadRBPF.from_particles(grid3, RBPFConfig(n_targets=2, n_particles=10),
                                np.zeros((1, 10), dtype=np.int64), np.zeros((1, 10)))


def test_the_thesis_emd_association_runs_on_the_rbpf_bank() -> None:
    """The RBPF's node-tracker bank is what the thesis's EMD associator pairs measurements
    with: two targets localised at opposite corners each take the measurement next to them."""
    from searchtrack.estimate.emd_association import EMDAssociator
    from searchtrack.estimate.node_tracker import measurement_density, position_log_likelihood
    from searchtrack.models.road_synthetic import grid_network as grid

    network = grid(3, 3, 100.0, spacing_m=10.0)
    roads = DirectedRoads(network)
    near = [roads.nearest(np.array([[15.0, 0.0]])), roads.nearest(np.array([[185.0, 200.0]]))]
    n = 50
    edge = np.array([[int(e[0])] * n for e, _ in near])
    s = np.array([[float(x[0])] * n for _, x in near])
    rbpf = RoadRBPF.from_particles(roads, RBPFConfig(n_targets=2, n_histories=2, n_particles=n),
                                   edge, s)
    bank = rbpf.belief_bank()
    measured = np.array([[190.0, 200.0], [10.0, 0.0]])  # the second target first
    ll = position_log_likelihood(network, measured, 10.0)
    pairs = EMDAssociator(network, gate_m=100.0).associate(bank, measurement_density(ll)).pairs
    assert sorted(pairs) == [(0, 1), (1, 0)]


def test_summary_is_the_three_reports_at_once() -> None:
    from searchtrack.models.road_synthetic import grid_network as grid

    roads = DirectedRoads(grid(3, 3, 100.0, spacing_m=100.0))
    rng = np.random.default_rng(4)
    rbpf = RoadRBPF(roads, RBPFConfig(n_targets=2, n_histories=3, n_particles=80), rng)
    rbpf.predict(0.1, rng)
    rbpf.update(np.array([[50.0, 1.0]]), np.array([50.0, 0.0]), rng)
    per_target, pooled, estimates = rbpf.summary()
    assert np.array_equal(per_target, rbpf.target_entropy())
    assert pooled == rbpf.combined_entropy()
    assert np.array_equal(estimates, rbpf.map_positions())


def test_detections_with_no_road_in_view_are_clutter_and_the_scan_a_miss() -> None:
    """Clutter counted on the roads in view, and no road under the view: Eq. 10 is 0 for every
    history, so the filter takes the scan as a miss instead of zeroing every history's weight."""
    from searchtrack.models.disc_sensor import DiscSensor
    from searchtrack.models.road_synthetic import grid_network as grid

    roads = DirectedRoads(grid(3, 3, 100.0, spacing_m=100.0))
    config = RBPFConfig(n_targets=2, n_histories=3, n_particles=60,
                        sensor=DiscSensor(clutter="view"))
    a = RoadRBPF(roads, config, np.random.default_rng(2))
    b = RoadRBPF(roads, config, np.random.default_rng(2))
    away = np.array([50.0, 50.0])  # the middle of a block: > 30 m from every road
    a.update(np.array([[51.0, 49.0]]), away, np.random.default_rng(3))
    b.update(np.empty((0, 2)), away, np.random.default_rng(3))
    assert a.best_association().tolist() == [-1]
    assert np.all(np.isfinite(a.weights)) and np.allclose(a.weights, b.weights)
    assert np.array_equal(a.target_particles()[1], b.target_particles()[1])
