"""One way to step a filter in a closed loop: predict, update with a scan taken from a pose, read.

Stone Soup composes a tracker from a predictor and an updater; a closed loop (a road mission of
thesis 001, a radio flight of paper 002, a particle search of papers 003–004) needs of any
filter only those two verbs and a few read-outs, so it is written against these protocols and
never against a filter's own calling convention (operator objects, a pure ``step`` function,
an update in place):

- :class:`SteppedFilter`: :meth:`~SteppedFilter.predict` moves the belief ``dt_s`` seconds on;
  :meth:`~SteppedFilter.update` assimilates one scan taken from a pose (one UAV's pose, or the
  states of a fleet) and returns what the update found (``ReportT``: the associations and
  births of a road filter, the point estimates of the SMC-PHD).
- :class:`PointEstimates`: the ground positions the filter reports as targets, what
  truth-based scores (OSPA, the MOC matching of thesis 001 §6.2) compare with the truth.
- :class:`RoadFilter`: a filter that flies a thesis 001 road mission. Besides the two verbs it
  shows the guidance the belief views of :mod:`searchtrack.estimate.belief` (a
  :class:`~searchtrack.estimate.belief.SearchField` to climb, the track beliefs as a
  :class:`~searchtrack.estimate.node_tracker.TrackerBank`, a
  :class:`~searchtrack.estimate.belief.BeliefBank`), and its update reports a
  :class:`RoadUpdate`: which measurement went to which track and which tracks were born, in
  the filter's own terms. What these mean against the truth (valid associations, the target a
  birth found) is the closed loop's business, not the filter's.

Randomness: a stepped filter owns its ``numpy.random.Generator``, given (or seeded) when it is
built. No call takes a generator, so a run's draws depend only on how the filter was built and
on the sequence of calls, and two filters never share a stream by accident.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, TypeVar, runtime_checkable

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.belief import SearchField
from searchtrack.estimate.node_tracker import TrackerBank
from searchtrack.models.dubins import UavState
from searchtrack.models.measurements import LrtScan, PositionScan

ScanT = TypeVar("ScanT", contravariant=True)
PoseT = TypeVar("PoseT", contravariant=True)
ReportT = TypeVar("ReportT", covariant=True)


@runtime_checkable
class SteppedFilter(Protocol[ScanT, PoseT, ReportT]):
    """A filter a closed loop steps: predict over a time, update with a scan from a pose.

    The filter owns its random generator (module docstring); neither verb takes one.
    """

    def predict(self, dt_s: float) -> None:
        """Move the belief ``dt_s`` seconds on, without measurements."""
        ...

    def update(self, scan: ScanT, pose: PoseT) -> ReportT:
        """Assimilate ``scan``, taken from ``pose``; what the update found."""
        ...


@runtime_checkable
class PointEstimates(Protocol):
    """A filter that reports its targets as points on the ground."""

    def estimates_xy(self) -> FloatArray:
        """``(k, 2)`` ground positions (m) of the ``k`` targets the filter reports now."""
        ...


@dataclass(frozen=True, eq=False)
class RoadScan:
    """What the UAVs of a road mission measured at one time (thesis 001 §3.3, §4.3).

    Parameters
    ----------
    time_s
        When the scan was taken (s).
    positions
        Every UAV's position measurements; measurement ``q`` is row ``q``.
    lrt
        The scalar measurements ``ζ`` on every UAV's footprint nodes, for a filter that reads
        them (``None``: not sensed).
    """

    time_s: float
    positions: PositionScan
    lrt: LrtScan | None = None


TrackPair = tuple[int, int, int]
"""One association of a road update: ``(uav, track_id, measurement row)``."""


@dataclass(frozen=True, eq=False)
class TrackBirth:
    """A track born in a road update: its identity and where its belief peaks.

    Parameters
    ----------
    track_id
        The new track's identity (for a hand-over, the live track's kept identity).
    xy_m
        ``(2,)`` position (m) of the new track's belief (its peak node, its MAP position).
    handover
        The new belief went to a live track that had lost its target
        (:mod:`searchtrack.estimate.handover`).
    """

    track_id: int
    xy_m: FloatArray
    handover: bool = False

    def __post_init__(self) -> None:
        xy = np.array(self.xy_m, dtype=np.float64)
        if xy.shape != (2,):
            raise InvalidInputError("xy_m", self.xy_m, "must be one (x, y) position")
        xy.setflags(write=False)
        object.__setattr__(self, "xy_m", xy)


@dataclass(frozen=True, eq=False)
class RoadUpdate:
    """What one road update found, in the filter's own terms.

    Parameters
    ----------
    pairs
        The associations, each ``(uav, track_id, measurement row)``, to tracks that were live
        when the update began, in the order they were made.
    births
        The tracks born, in the order the filter made them.
    associate_s, initiate_s
        Seconds of the update spent associating and initiating tracks (part of its total).
    """

    pairs: tuple[TrackPair, ...] = ()
    births: tuple[TrackBirth, ...] = ()
    associate_s: float = 0.0
    initiate_s: float = 0.0


@runtime_checkable
class RoadFilter(SteppedFilter[RoadScan, UavState, RoadUpdate], PointEstimates, Protocol):
    """A filter that flies a thesis 001 road mission.

    One step of the mission: :meth:`update` with the scan of every UAV (``pose``: the UAVs'
    states when they took it), the guidance reads :attr:`search_field` and :attr:`bank`, then
    :meth:`predict`. :meth:`estimates_xy` has one row per track, row ``i`` for ``bank[i]``.
    """

    @property
    def search_field(self) -> SearchField:
        """The per-node score the search laws climb (the LRT's ``φ`` or a stand-in for it)."""
        ...

    @property
    def bank(self) -> TrackerBank:
        """The live tracks' node beliefs, in a fixed order: a
        :class:`~searchtrack.estimate.belief.BeliefBank` for the guidance, held as node trackers
        so that the mission log can keep their peaks and summed probabilities."""
        ...
