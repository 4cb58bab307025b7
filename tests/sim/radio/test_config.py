"""The closed loop's settings: names read from the planning registry and the simulators, and
every setting checked when the configuration is built."""

from __future__ import annotations

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.radio.problem import REWARDS
from searchtrack.plan.radio.solve import BACKENDS
from searchtrack.sim.radio.config import (
    FILTERS,
    PLAN_BACKENDS,
    PLANNERS,
    STRAIGHT,
    RadioMissionConfig,
)
from searchtrack.sim.radio.track_job import FILTERS as FILTER_CLASSES


def test_names_come_from_their_sources() -> None:
    assert (*REWARDS, STRAIGHT) == PLANNERS
    assert STRAIGHT in BACKENDS.names() and set(PLAN_BACKENDS) == set(BACKENDS.names()) - {STRAIGHT}
    assert tuple(FILTER_CLASSES) == FILTERS


def test_reward_follows_the_planner() -> None:
    assert RadioMissionConfig(planner="cs").plan.reward == "cs"


@pytest.mark.parametrize(("field", "value"), [
    ("filter", "kalman"), ("planner", "spiral"), ("measurement", "raw"),
    ("particles_per_label", 0), ("plan_time_limit_s", 0.0), ("keep_out", 1)])
def test_bad_settings_are_refused(field: str, value: object) -> None:
    with pytest.raises(InvalidInputError, match=field):
        RadioMissionConfig(**{field: value})  # type: ignore[arg-type]
