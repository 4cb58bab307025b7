"""The stepping protocols: what fits them, and the road scan and update records."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.node_tracker import TrackerBank
from searchtrack.estimate.stepping import (
    PointEstimates,
    RoadFilter,
    RoadScan,
    RoadUpdate,
    SteppedFilter,
    TrackBirth,
)
from searchtrack.models.dubins import UavState
from searchtrack.models.measurements import PositionScan


class Counter:
    """A filter of one number that predicts by adding time and updates by adding the scan."""

    def __init__(self) -> None:
        self.value = 0.0

    def predict(self, dt_s: float) -> None:
        self.value += dt_s

    def update(self, scan: float, pose: float) -> float:
        self.value += scan * pose
        return self.value

    def estimates_xy(self) -> FloatArray:
        return np.array([[self.value, 0.0]])


class StillRoads(Counter):
    """A road filter that never changes: a neutral field and no tracks."""

    @property
    def search_field(self) -> LikelihoodField:
        return LikelihoodField.neutral(4)

    @property
    def bank(self) -> TrackerBank:
        return TrackerBank(4)

    def update(self, scan: RoadScan, pose: UavState) -> RoadUpdate:  # type: ignore[override]
        return RoadUpdate()

    def estimates_xy(self) -> FloatArray:
        return np.empty((0, 2))


def test_protocols_are_structural() -> None:
    """Any object with the verbs is a stepped filter; a road filter also shows the field and
    the bank; an object without them is neither."""
    counter = Counter()
    assert isinstance(counter, SteppedFilter) and isinstance(counter, PointEstimates)
    assert not isinstance(counter, RoadFilter)
    assert isinstance(StillRoads(), RoadFilter)
    assert not isinstance(object(), SteppedFilter)
    counter.predict(0.5)
    assert counter.update(2.0, 3.0) == 6.5
    np.testing.assert_array_equal(counter.estimates_xy(), [[6.5, 0.0]])


def test_road_records_hold_what_an_update_found() -> None:
    """A scan keeps its time and measurements (no ζ unless sensed); a birth keeps a read-only
    copy of its position and refuses anything but one (x, y); an update defaults to nothing
    found."""
    pos = PositionScan(np.zeros(1, dtype=np.int64), np.array([[1.0, 2.0]]),
                       np.zeros(1, dtype=np.int64))
    scan = RoadScan(0.3, pos)
    assert scan.lrt is None and scan.positions is pos
    xy = np.array([5.0, 6.0])
    birth = TrackBirth(3, xy)
    xy[0] = 0.0
    np.testing.assert_array_equal(birth.xy_m, [5.0, 6.0])
    assert not birth.xy_m.flags.writeable and not birth.handover
    with pytest.raises(InvalidInputError) as info:
        TrackBirth(0, np.zeros(3))
    assert info.value.field == "xy_m"
    empty = RoadUpdate()
    assert (empty.pairs, empty.births, empty.associate_s, empty.initiate_s) == ((), (), 0.0, 0.0)
