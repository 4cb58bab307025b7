"""Scan assimilation: routing through an injected associator, and a deterministic closed loop."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate import (
    Association,
    GraphDiffusion,
    LikelihoodField,
    LRTInitiator,
    LRTPredictor,
    ScanUpdater,
    TrackerBank,
    TrackerDeleter,
    TrackerPredictor,
)
from searchtrack.models import RoadNetwork, grid_network

M = 2.9264


@dataclass(frozen=True)
class PeakGate:
    """Test associator: greedy, pairs a measurement with the tracker whose peak node holds the most
    of its density, if that is above ``gate``."""

    gate: float = 1e-3

    def associate(self, bank: TrackerBank, densities: NDArray[np.float64]) -> Association:
        score = np.array([[d[t.peak_node()] for d in densities] for t in bank])
        pairs = []
        while score.size and score.max() > self.gate:
            t, q = np.unravel_index(np.argmax(score), score.shape)
            pairs.append((int(t), int(q)))
            score[t, :] = score[:, q] = -1.0
        return Association(tuple(pairs))


@dataclass(frozen=True)
class Broken:
    """Test associator that returns an index out of range."""

    def associate(self, bank: TrackerBank, densities: NDArray[np.float64]) -> Association:
        return Association(((len(bank), 0),))


def _bank(net: RoadNetwork, node: int) -> TrackerBank:
    return TrackerBank(net.n_nodes).with_birth(np.eye(net.n_nodes)[node])


def test_associated_fix_updates_the_tracker_not_the_lrt(path5: RoadNetwork) -> None:
    """A fix on the tracked node goes to the tracker; the LRT is left alone."""
    bank = TrackerBank(5).with_birth([0.0, 0.25, 0.5, 0.25, 0.0])
    out = ScanUpdater(path5, PeakGate()).update(
        LikelihoodField.neutral(5), bank, zeta=3.0, footprint=[1, 2, 3], sensitivity=M,
        positions_m=[[20.0, 0.0]], noise_sd_m=5.0)
    assert out.association.pairs == ((0, 0),) and not out.lrt_updated
    np.testing.assert_array_equal(out.field.llr, 0.0)
    assert out.bank[0].probability[2] > 0.5


def test_unassociated_fix_updates_the_lrt(path5: RoadNetwork) -> None:
    """A fix far from every tracker raises the LRT footprint by m(ζ − m/2)."""
    out = ScanUpdater(path5, PeakGate()).update(
        LikelihoodField.neutral(5), _bank(path5, 0), zeta=3.0, footprint=[3, 4], sensitivity=M,
        positions_m=[[40.0, 0.0]], noise_sd_m=5.0)
    assert out.association.pairs == () and out.lrt_updated
    np.testing.assert_allclose(out.field.llr, [0, 0, 0, M * (3 - M / 2), M * (3 - M / 2)])
    np.testing.assert_array_equal(out.bank[0].probability, np.eye(5)[0])


def test_empty_scan_is_negative_information(path5: RoadNetwork) -> None:
    """No position fix (ζ ≤ c): the footprint is lowered and the associator is not asked."""
    out = ScanUpdater(path5, Broken()).update(
        LikelihoodField.neutral(5), _bank(path5, 0), zeta=0.0, footprint=[0, 1], sensitivity=M,
        positions_m=np.empty((0, 2)), noise_sd_m=5.0)
    np.testing.assert_allclose(out.field.llr, [-M * M / 2, -M * M / 2, 0, 0, 0])


def test_negative_information_moves_an_unseen_tracker_off_the_footprint(
        path5: RoadNetwork) -> None:
    """With detection_probability, a tracker the scan did not update keeps (1 − p_d) of its
    probability on the footprint, renormalised; an associated tracker and a tracker wholly
    inside the footprint are left to the usual rules."""
    bank = TrackerBank(5).with_birth([0.0, 0.25, 0.5, 0.25, 0.0])
    updater = ScanUpdater(path5, PeakGate(), detection_probability=0.8)
    out = updater.update(LikelihoodField.neutral(5), bank, zeta=0.0, footprint=[2, 3, 4],
                         sensitivity=M, positions_m=np.empty((0, 2)), noise_sd_m=5.0)
    want = np.array([0.0, 0.25, 0.5 * 0.2, 0.25 * 0.2, 0.0])
    np.testing.assert_allclose(out.bank[0].probability, want / want.sum())
    inside = updater.update(LikelihoodField.neutral(5), bank, zeta=0.0, footprint=[0, 1, 2, 3],
                            sensitivity=M, positions_m=np.empty((0, 2)), noise_sd_m=5.0)
    np.testing.assert_allclose(inside.bank[0].probability, bank[0].probability)
    seen = updater.update(LikelihoodField.neutral(5), bank, zeta=3.0, footprint=[1, 2, 3],
                          sensitivity=M, positions_m=[[20.0, 0.0]], noise_sd_m=5.0)
    assert seen.association.pairs == ((0, 0),) and seen.bank[0].probability[2] > 0.5
    with pytest.raises(InvalidInputError, match="detection_probability"):
        ScanUpdater(path5, PeakGate(), detection_probability=1.0)


def test_bad_scan_inputs_name_the_field(path5: RoadNetwork) -> None:
    """A bad associator answer, NaN ζ or NaN positions each name their field."""
    field, bank = LikelihoodField.neutral(5), _bank(path5, 0)
    base = {"zeta": 3.0, "footprint": [0], "sensitivity": M, "positions_m": [[0.0, 0.0]],
            "noise_sd_m": 5.0}
    cases: list[tuple[object, dict[str, object], str]] = [
        (Broken(), {}, "association"),
        (PeakGate(), {"zeta": float("nan")}, "zeta"),
        (PeakGate(), {"positions_m": [[float("nan"), 0.0]]}, "positions_m"),
        (PeakGate(), {"footprint": [7]}, "footprint"),
        (Broken(), {"noise_sd_m": -1.0, "positions_m": []}, "noise_sd_m"),
    ]
    for associator, change, name in cases:
        with pytest.raises(InvalidInputError) as err:
            ScanUpdater(path5, associator).update(field, bank, **{**base, **change})  # type: ignore[arg-type]
        assert err.value.field == name
    with pytest.raises(InvalidInputError) as err:
        Association(((0, 1), (1, 1)))
    assert err.value.field == "pairs"


Loop = tuple[NDArray[np.float64], NDArray[np.float64], int]


def _closed_loop(seed: int, steps: int = 40) -> Loop:
    net = grid_network(4, 4)
    rng = np.random.default_rng(seed)
    scan = ScanUpdater(net, PeakGate())
    lrt_pred = LRTPredictor(GraphDiffusion.on_network(net, 0.447, 0.3, decay_c=50.0))
    trk_pred = TrackerPredictor(GraphDiffusion.on_network(net, 0.447, 0.3))
    init, deleter = LRTInitiator(net), TrackerDeleter()
    field, bank = LikelihoodField.neutral(net.n_nodes), TrackerBank(net.n_nodes)
    target = 55
    for _ in range(steps):
        for centre in (target, int(rng.integers(net.n_nodes))):
            footprint = np.flatnonzero(np.hypot(*(net.coords - net.coords[centre]).T) < 30.0)
            present = target in footprint
            zeta = float(rng.normal(M if present else 0.0))
            fixes = net.coords[target] + rng.normal(0.0, 5.0, (1, 2)) if zeta > M / 2 else []
            out = scan.update(field, bank, zeta=zeta, footprint=footprint, sensitivity=M,
                              positions_m=fixes, noise_sd_m=5.0)
            field, bank = out.field, out.bank
        field, bank = init.initiate(field, bank)
        bank = deleter.delete(bank)
        field, bank = lrt_pred.predict(field), trk_pred.predict(bank)
    return field.llr, bank.node_probability(), bank.next_id


def test_closed_loop_is_deterministic_and_finds_the_target() -> None:
    """Same seed, same result bit for bit; the target's node carries a tracker."""
    a, b = _closed_loop(7), _closed_loop(7)
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)
    _, prob, born = a
    assert born >= 1 and prob[55] > 0.05


def test_per_node_zeta_spares_only_the_associated_neighbourhood(path5: RoadNetwork) -> None:
    """With one ζ per node, nodes near an associated fix keep their LRT; the others update."""
    bank = TrackerBank(5).with_birth([0.0, 0.0, 0.0, 0.5, 0.5])
    zeta = np.array([0.0, 0.0, 3.0, 3.0])
    out = ScanUpdater(path5, PeakGate()).update(
        LikelihoodField.neutral(5), bank, zeta=zeta, footprint=[0, 1, 2, 3], sensitivity=M,
        positions_m=[[30.0, 0.0]], noise_sd_m=2.0)
    assert out.association.pairs == ((0, 0),)
    assert out.lrt_updated
    expected = M * (zeta - M / 2)
    np.testing.assert_allclose(out.field.llr[:3], expected[:3])
    assert out.field.llr[3] == 0.0 and out.field.llr[4] == 0.0
    # a 10 m resolution cell widens the spared neighbourhood by one node (20 m from the fix)
    cell = ScanUpdater(path5, PeakGate(), cell_radius_m=10.0).update(
        LikelihoodField.neutral(5), bank, zeta=zeta, footprint=[0, 1, 2, 3], sensitivity=M,
        positions_m=[[30.0, 0.0]], noise_sd_m=2.0)
    np.testing.assert_allclose(cell.field.llr[:2], expected[:2])
    assert cell.field.llr[2] == 0.0 and cell.field.llr[3] == 0.0
    with pytest.raises(InvalidInputError, match="cell_radius_m"):
        ScanUpdater(path5, PeakGate(), cell_radius_m=-1.0)


def test_per_node_zeta_shape_is_checked(path5: RoadNetwork) -> None:
    """A per-node ζ must have one value per footprint node."""
    with pytest.raises(InvalidInputError, match="zeta"):
        ScanUpdater(path5, PeakGate()).update(
            LikelihoodField.neutral(5), TrackerBank(5), zeta=[1.0, 2.0], footprint=[0, 1, 2],
            sensitivity=M, positions_m=np.empty((0, 2)), noise_sd_m=2.0)
