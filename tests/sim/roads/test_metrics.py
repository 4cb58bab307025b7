"""Mission metrics: gated one-to-one tracker matching, association counts, birth credits and the
MOC/PVT/PVA sums."""

from __future__ import annotations

import numpy as np

from searchtrack.sim.roads.metrics import (
    UNMATCHED,
    StepScore,
    count_associations,
    credit_birth,
    match_trackers,
    match_tracks,
    moc_after_detection,
    score,
)


def test_matching_is_one_to_one_and_gated() -> None:
    """Two trackers near one target: only the closer is valid; a far tracker is unmatched."""
    peaks = np.array([[0.0, 0.0], [30.0, 0.0], [1000.0, 0.0]])
    targets = np.array([[10.0, 0.0], [500.0, 0.0]])
    match = match_trackers(peaks, targets, 100.0)
    assert match.tolist() == [0, UNMATCHED, UNMATCHED]


def test_matching_minimises_total_distance() -> None:
    """Crossed pairs are resolved by the minimum total distance."""
    peaks = np.array([[0.0, 0.0], [50.0, 0.0]])
    targets = np.array([[45.0, 0.0], [5.0, 0.0]])
    assert match_trackers(peaks, targets, 100.0).tolist() == [1, 0]


def test_matching_empty_inputs() -> None:
    """No trackers or no targets give no matches."""
    assert match_trackers(np.empty((0, 2)), np.zeros((2, 2)), 10.0).size == 0
    assert match_trackers(np.zeros((2, 2)), np.empty((0, 2)), 10.0).tolist() == [-1, -1]


def test_score_sums() -> None:
    """MOC, PVT and PVA follow (6.8)-(6.9) over the steps."""
    steps = [StepScore(0, 0, 0, 0), StepScore(2, 1, 3, 1), StepScore(2, 2, 1, 0)]
    first = np.array([0.6, 0.9])
    s = score(steps, 2, first)
    assert s.nvt == 3 and s.nst == 1 and s.nva == 4 and s.nfa == 1
    assert s.pvt == 0.75 and s.pva == 0.8
    assert np.isclose(s.moc_mean, (0 + 0.5 + 1.0) / 3) and s.moc_final == 1.0
    assert s.time_to_detect_all_s == 0.9 and s.detected == 2
    assert s.time_to_first_detection_s == 0.6


def test_score_without_trackers() -> None:
    """No tracker ever: PVT and PVA are undefined, not zero; the time to detect all is None,
    the time to the first detection that of the one target found."""
    s = score([StepScore(0, 0, 0, 0)], 3, np.array([np.nan, 1.0, np.nan]))
    assert s.pvt is None and s.pva is None
    assert s.time_to_detect_all_s is None and s.detected == 1
    assert s.time_to_first_detection_s == 1.0


def test_moc_after_detection_by_hand() -> None:
    """Three targets over five steps. Target 0 is tracked at steps 1, 2, 4 (known from step 1:
    4 steps, 3 tracked); target 1 at step 3 only (known from step 3: 2 steps, 1 tracked);
    target 2 never (no steps count). MOC after detection = (3 + 1) / (4 + 2); the whole-run
    MOC is (0 + 1 + 1 + 1 + 1) / 15."""
    tracked = [(), (0,), (0,), (1,), (0,)]
    steps = [StepScore(len(t), len(t), 0, 0, t) for t in tracked]
    s = score(steps, 3, np.array([0.6, 1.2, np.nan]))
    assert s.moc_after_detection == 4 / 6
    assert np.isclose(s.moc_mean, 4 / 15)
    assert moc_after_detection(steps, 3) == 4 / 6


def test_moc_after_detection_undefined_before_any_detection() -> None:
    """No target ever tracked (or no step): ``None``, not 0; a target tracked every step
    from its first detection on scores 1."""
    assert moc_after_detection([StepScore(1, 0, 0, 0)] * 3, 2) is None
    assert moc_after_detection([], 2) is None
    steps = [StepScore(0, 0, 0, 0), StepScore(1, 1, 0, 0, (1,)), StepScore(1, 1, 0, 0, (1,))]
    assert moc_after_detection(steps, 2) == 1.0


def test_matching_by_track_id() -> None:
    """The matching keyed by the trackers' identities, in the order of the peaks."""
    peaks = np.array([[0.0, 0.0], [30.0, 0.0], [1000.0, 0.0]])
    targets = np.array([[10.0, 0.0], [500.0, 0.0]])
    assert match_tracks([7, 2, 9], peaks, targets, 100.0) == {7: 0, 2: UNMATCHED, 9: UNMATCHED}
    assert match_tracks([], np.empty((0, 2)), targets, 100.0) == {}


def test_associations_are_valid_only_on_the_matched_target() -> None:
    """Valid: the measurement came from the target its track was matched to. False: a false
    alarm, another target, an unmatched track or a track unknown at the start of the step."""
    matched = {4: 0, 5: 1, 6: UNMATCHED}
    pairs = [(0, 4, 0), (0, 5, 1), (1, 4, -1), (1, 5, 0), (1, 6, 2), (0, 8, 0)]
    assert count_associations(pairs, matched) == (2, 4)
    assert count_associations([], matched) == (0, 0)


def test_a_birth_credits_the_nearest_target_within_reach() -> None:
    """The nearest target (lowest index on ties) when closer than the validity distance, else
    none; targets already found are passed over (a birth among them only credits another)."""
    targets = np.array([[0.0, 0.0], [60.0, 0.0], [-60.0, 0.0]])
    assert credit_birth(np.array([40.0, 0.0]), targets, 100.0) == (1, 20.0)
    assert credit_birth(np.array([0.0, 0.0]), targets[1:], 100.0) == (0, 60.0)
    assert credit_birth(np.array([500.0, 0.0]), targets, 100.0) == (UNMATCHED, 440.0)
    found = np.array([False, True, False])
    assert credit_birth(np.array([40.0, 0.0]), targets, 100.0, found) == (0, 40.0)
    assert credit_birth(np.array([40.0, 0.0]), targets, 30.0, found) == (UNMATCHED, 40.0)
