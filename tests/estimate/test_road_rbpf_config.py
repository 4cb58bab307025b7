"""The RBPF's configuration: sizes, models and options checked, the robust prior optional."""

from __future__ import annotations

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.road_jumps import TargetJumps
from searchtrack.estimate.road_rbpf_config import RBPFConfig
from searchtrack.estimate.road_resampling import KLDSampling, SpeedRoughening
from searchtrack.models.road_particles import CourierRoadMotion


def test_paper_defaults() -> None:
    c = RBPFConfig(n_targets=2)
    assert (c.n_histories, c.n_particles, c.jumps) == (10, 500, None)
    assert RBPFConfig(n_targets=1, jumps=TargetJumps()).jumps == TargetJumps()


@pytest.mark.parametrize("bad", [{"n_targets": 0}, {"n_targets": 1, "n_particles": 0},
                                 {"n_targets": 1, "association": "greedy"},
                                 {"n_targets": 1, "history_weight": "max"},
                                 {"n_targets": 1, "bin_m": 0.0},
                                 {"n_targets": 1, "jumps": 0.1}])
def test_bad_settings_are_named(bad: dict[str, object]) -> None:
    with pytest.raises(InvalidInputError):
        RBPFConfig(**bad)  # type: ignore[arg-type]


def test_roughening_needs_the_drive_and_stop_motion() -> None:
    """Speed roughening is off by default (the paper), taken with the drive-and-stop motion, and
    refused by name with Eq. 9's motion (no speeds) or when not a SpeedRoughening."""
    assert RBPFConfig(n_targets=1).roughening is None
    rough = RBPFConfig(n_targets=1, motion=CourierRoadMotion(), roughening=SpeedRoughening())
    assert rough.roughening == SpeedRoughening()
    for bad in ({"roughening": SpeedRoughening()},
                {"motion": CourierRoadMotion(), "roughening": 1.0}):
        with pytest.raises(InvalidInputError) as info:
            RBPFConfig(n_targets=1, **bad)  # type: ignore[arg-type]
        assert info.value.field == "roughening"


def test_kld_counts_are_optional_and_checked() -> None:
    """Fixed counts by default (the paper); KLD-sampling taken, anything else refused by name."""
    assert RBPFConfig(n_targets=1).counts is None
    assert RBPFConfig(n_targets=1, counts=KLDSampling()).counts == KLDSampling()
    with pytest.raises(InvalidInputError) as info:
        RBPFConfig(n_targets=1, counts=0.05)  # type: ignore[arg-type]
    assert info.value.field == "counts"
