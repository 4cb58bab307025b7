"""Identity hand-over on re-detection: a birth where a live tracker lost its target goes to that
tracker, which keeps its identity; elsewhere, or without the rule, the birth stands."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate import LikelihoodField, LRTInitiator, TrackerBank, TrackHandover
from searchtrack.models import RoadNetwork

from .conftest import path_network

N = 100  # a 990 m straight road, nodes 10 m apart


def _spread(centre: int, half_width: int) -> np.ndarray:
    """A flat distribution over ``centre ± half_width`` nodes (a tracker that lost its target)."""
    p = np.zeros(N)
    p[centre - half_width:centre + half_width + 1] = 1.0
    return p / p.sum()


def _delta(node: int) -> np.ndarray:
    p = np.zeros(N)
    p[node] = 1.0
    return p


def _bank_with_birth(old: np.ndarray, born_at: int) -> tuple[RoadNetwork, TrackerBank, int]:
    """A bank holding tracker 0 (``old``) and, born this step, tracker 1 at ``born_at``."""
    net = path_network(N)
    bank = TrackerBank(N).with_birth(old)
    first_new = bank.next_id
    return net, bank.with_birth(_delta(born_at)), first_new


def test_birth_near_a_lost_tracker_is_handed_over() -> None:
    """Tracker 0 is spread over nodes 20–40 (peak 0.048); a detection at node 55 (150–350 m
    from its mass, all of it within 600 m) replaces its distribution: one tracker, id 0."""
    net, bank, first_new = _bank_with_birth(_spread(30, 10), 55)
    assert len(bank) == 2
    out, done = TrackHandover(net).hand_over(bank, first_new)
    assert done == ((0, 1),)
    assert len(out) == 1 and out[0].track_id == 0
    np.testing.assert_array_equal(out[0].probability, _delta(55))
    assert out.next_id == bank.next_id == 2  # identities are never reused


def test_without_the_rule_the_birth_stands() -> None:
    """The same step through the initiator alone leaves two trackers, ids 0 and 1."""
    net = path_network(N)
    bank = TrackerBank(N).with_birth(_spread(30, 10))
    llr = np.zeros(N)
    llr[55] = 12.0  # above φ_max = 10, 250 m from tracker 0's peak (no merge)
    _, bank = LRTInitiator(net, 10.0, merge_radius_m=100.0).initiate(LikelihoodField(llr), bank)
    assert [t.track_id for t in bank] == [0, 1]
    assert bank[1].peak_node() == 55


def test_far_birth_and_confident_tracker_are_left_alone() -> None:
    """A birth beyond the reach of the old tracker's mass stands; so does one near a tracker
    whose peak is above ``lost_peak``."""
    net, bank, first_new = _bank_with_birth(_spread(10, 5), 90)  # 750–850 m away
    out, done = TrackHandover(net).hand_over(bank, first_new)
    assert done == () and out is bank and len(out) == 2
    sharp = np.full(N, 0.5 / (N - 1))
    sharp[30] = 0.5 + 0.5 / (N - 1)
    net, bank, first_new = _bank_with_birth(sharp / sharp.sum(), 45)
    out, done = TrackHandover(net, lost_peak=0.3).hand_over(bank, first_new)
    assert done == () and len(out) == 2


def test_the_tracker_with_most_mass_near_the_birth_takes_it_once() -> None:
    """Of two lost trackers the one holding more mass near the birth takes it; two births in
    one step go to two different trackers, never both to one."""
    net = path_network(N)
    bank = TrackerBank(N).with_birth(_spread(20, 10)).with_birth(_spread(60, 10))
    first_new = bank.next_id
    bank = bank.with_birth(_delta(70)).with_birth(_delta(75))
    out, done = TrackHandover(net, reach_m=200.0).hand_over(bank, first_new)
    assert done == ((1, 2),)  # tracker 0 (nodes 10–30) has no mass within 200 m of 75
    assert [t.track_id for t in out] == [0, 1, 3]
    assert out[1].peak_node() == 70


def test_nothing_to_hand_over() -> None:
    """No birth, or no older tracker: the bank comes back as it was."""
    net, bank, _ = _bank_with_birth(_spread(30, 10), 55)
    handover = TrackHandover(net)
    assert handover.hand_over(bank, bank.next_id) == (bank, ())
    assert handover.hand_over(bank, 0) == (bank, ())


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"reach_m": 0.0}, "reach_m"), ({"reach_m": float("inf")}, "reach_m"),
    ({"min_mass": 0.0}, "min_mass"), ({"min_mass": 1.5}, "min_mass"),
    ({"lost_peak": float("nan")}, "lost_peak"),
])
def test_bad_settings_are_named(kwargs: dict[str, float], field: str) -> None:
    """Each setting is refused by name."""
    with pytest.raises(InvalidInputError) as info:
        TrackHandover(path_network(3), **kwargs)  # type: ignore[arg-type]
    assert info.value.field == field


def test_only_lost_trackers_take_a_birth_over() -> None:
    """A tracker the caller does not name as lost (it still gets fixes) keeps its own target;
    naming it lost lets it take the birth."""
    net, bank, first_new = _bank_with_birth(_spread(30, 10), 55)
    handover = TrackHandover(net)
    assert handover.hand_over(bank, first_new, lost=set()) == (bank, ())
    assert handover.hand_over(bank, first_new, lost={7}) == (bank, ())
    out, done = handover.hand_over(bank, first_new, lost={0})
    assert done == ((0, 1),) and [t.track_id for t in out] == [0]
