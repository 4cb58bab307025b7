"""Truth-based scores of a road search-and-track mission (thesis 001 §6.2, after Gorji et al.).

Definitions (the thesis names the metrics but not what makes a track or association valid):

- Trackers are matched one-to-one to true targets by a gated minimum-distance assignment between
  tracker peak nodes and target positions: a pair counts only when the distance is below
  ``valid_distance_m``, and the matching minimises ``Σ (distance − valid_distance_m)`` over the
  pairs taken. A matched tracker is *valid* (NVT), an unmatched one *spurious* (NST).
- An association (tracker, measurement) is *valid* (NVA) when the measurement came from the target
  the tracker was matched to at the start of the step, otherwise *false* (NFA), false alarms
  included (:func:`count_associations`).
- A tracker birth is credited to the nearest true target within ``valid_distance_m``
  (:func:`credit_birth`); in ``detect`` mode that target counts as detected from then on.
- MOC = NVT / number of targets; PVT = NVT / (NVT + NST) (6.8); PVA = NVA / (NVA + NFA) (6.9).
- MOC after detection (this library's, to separate tracking from search latency, which the
  whole-run MOC mixes): a target counts as detected from the first step at which a tracker is
  validly matched to it (the step a track-mode mission records as its first detection); over
  the target-steps from then to the end, the fraction in which the target is validly tracked,
  ``Σ_t tracked_t / Σ_t steps since detection_t`` (targets weighted by the time they were
  known; ``None`` before any detection).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.measurements import FALSE_ALARM

UNMATCHED = -1


def match_trackers(peaks_xy: FloatArray, targets_xy: FloatArray,
                   valid_distance_m: float) -> IntArray:
    """For each tracker peak, the index of its matched target or ``UNMATCHED`` (−1)."""
    k = peaks_xy.shape[0]
    match = np.full(k, UNMATCHED, dtype=np.int64)
    if k == 0 or targets_xy.shape[0] == 0:
        return match
    dist = np.linalg.norm(peaks_xy[:, None, :] - targets_xy[None, :, :], axis=2)
    rows, cols = linear_sum_assignment(np.minimum(dist - valid_distance_m, 0.0))
    ok = dist[rows, cols] < valid_distance_m
    match[rows[ok]] = cols[ok]
    return match


def match_tracks(track_ids: Sequence[int], peaks_xy: FloatArray, targets_xy: FloatArray,
                 valid_distance_m: float) -> dict[int, int]:
    """:func:`match_trackers` keyed by the trackers' ``track_ids`` (row ``i`` of ``peaks_xy``
    is track ``track_ids[i]``): each track's matched target or ``UNMATCHED``."""
    match = match_trackers(peaks_xy, targets_xy, valid_distance_m)
    return dict(zip((int(t) for t in track_ids), match.tolist(), strict=True))


def count_associations(pairs: Sequence[tuple[int, int, int]],
                       matched: Mapping[int, int]) -> tuple[int, int]:
    """NVA and NFA of a step's associations ``(uav, track_id, true target)``: an association is
    valid when its measurement came from the target its track was matched to at the start of
    the step (``matched``, from :func:`match_tracks`); false alarms and unmatched or unknown
    tracks make it false."""
    valid = sum(1 for _, track, target in pairs
                if target != FALSE_ALARM and matched.get(track, UNMATCHED) == target)
    return valid, len(pairs) - valid


def credit_birth(xy_m: FloatArray, targets_xy: FloatArray, valid_distance_m: float,
                 found: NDArray[np.bool_] | None = None) -> tuple[int, float]:
    """The true target a track born at ``xy_m`` found: the nearest one (the lowest index on
    ties), or ``UNMATCHED`` when it is not closer than ``valid_distance_m``, and its distance
    (m). Targets marked in ``found`` (detect mode: already detected) are passed over."""
    dist = np.linalg.norm(targets_xy - xy_m, axis=1)
    if found is not None:
        dist[found] = np.inf
    target = int(np.argmin(dist))
    hit = bool(dist[target] < valid_distance_m)
    return (target if hit else UNMATCHED), float(dist[target])


@dataclass(frozen=True)
class StepScore:
    """Counts at one time step; ``tracked`` lists the targets validly tracked (the matched
    targets of the valid trackers, ascending), for :func:`moc_after_detection`."""

    trackers: int
    valid_trackers: int
    valid_associations: int
    false_associations: int
    tracked: tuple[int, ...] = ()

    @property
    def spurious_trackers(self) -> int:
        """NST."""
        return self.trackers - self.valid_trackers


def ratio(num: float, den: float) -> float | None:
    """``num / den``, ``None`` when ``den`` is 0."""
    return num / den if den > 0 else None


@dataclass(frozen=True)
class MissionScore:
    """Scores summed over a mission.

    Attributes
    ----------
    moc_mean, moc_final
        Measure of completeness averaged over steps and at the last step.
    pvt, pva
        (6.8) and (6.9) over all steps (``None`` when no tracker / association occurred).
    time_to_detect_all_s
        First time every target had been detected (``None`` if some never were).
    time_to_first_detection_s
        First time any target was detected (``None`` if none ever was): the search latency
        that the whole-run MOC pays for.
    detected
        Number of targets ever detected.
    moc_after_detection
        MOC after first detection (module docstring): of the steps from each target's first
        valid track on, the fraction in which it was validly tracked (``None`` if no target
        ever was).
    """

    steps: int
    targets: int
    nvt: int
    nst: int
    nva: int
    nfa: int
    moc_mean: float
    moc_final: float
    pvt: float | None
    pva: float | None
    time_to_detect_all_s: float | None
    detected: int
    moc_after_detection: float | None
    time_to_first_detection_s: float | None


def moc_after_detection(steps: list[StepScore], targets: int) -> float | None:
    """MOC after first detection (module docstring) from the steps' ``tracked`` targets."""
    flags = np.zeros((len(steps), targets), dtype=bool)
    for k, s in enumerate(steps):
        flags[k, list(s.tracked)] = True
    known = np.logical_or.accumulate(flags, axis=0)
    exposure = int(known.sum())
    return ratio(int(flags.sum()), exposure)


def score(steps: list[StepScore], targets: int, first_detection_s: FloatArray) -> MissionScore:
    """Sum per-step counts into a :class:`MissionScore` (``first_detection_s`` is NaN for a
    target never detected)."""
    nvt = sum(s.valid_trackers for s in steps)
    nst = sum(s.spurious_trackers for s in steps)
    nva = sum(s.valid_associations for s in steps)
    nfa = sum(s.false_associations for s in steps)
    moc = np.array([s.valid_trackers / targets for s in steps]) if steps else np.zeros(1)
    detected = int(np.count_nonzero(np.isfinite(first_detection_s)))
    all_time = float(np.max(first_detection_s)) if detected == targets else None
    first_time = float(np.nanmin(first_detection_s)) if detected else None
    return MissionScore(
        steps=len(steps), targets=targets, nvt=nvt, nst=nst, nva=nva, nfa=nfa,
        moc_mean=float(moc.mean()), moc_final=float(moc[-1]),
        pvt=ratio(nvt, nvt + nst), pva=ratio(nva, nva + nfa),
        time_to_detect_all_s=all_time, detected=detected,
        moc_after_detection=moc_after_detection(steps, targets),
        time_to_first_detection_s=first_time,
    )
