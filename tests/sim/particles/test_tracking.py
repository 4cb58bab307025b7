"""Closed-loop tracking episodes of paper 003 with the PHD filter in the loop."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.particles.tracking import TrackConfig, run_track_episode, taxi_world


def tiny_track(planner: str, motion: str = "random_walk") -> TrackConfig:
    return TrackConfig(planner=planner, motion=motion, robots=2, horizon=1,  # type: ignore[arg-type]
                       steps=6, n_targets=6, n_training=8, particles=500, max_particles=2000,
                       plan_particles=200)


@pytest.mark.parametrize("planner", ["end", "mi", "lawnmower"])
def test_track_episode_is_deterministic(planner: str) -> None:
    """Tracking episodes repeat exactly for a seed and log sane metrics."""
    cfg = tiny_track(planner)
    world = taxi_world(cfg, 1)
    a = run_track_episode(cfg, world, 4)
    b = run_track_episode(cfg, world, 4)
    for name in ("count_ratio", "entropy", "in_view", "ospa_m", "altitude_m"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.count_ratio.shape == (6,)
    assert np.all((a.in_view >= 0.0) & (a.in_view <= 1.0))
    assert np.all((a.ospa_m >= 0.0) & (a.ospa_m <= 50.0))
    assert np.all(a.altitude_m >= 20.0 - 1e-9)


def test_taxi_world_truth_stays_on_the_area() -> None:
    """Ground truth has one row per step and stays on the road grid."""
    cfg = tiny_track("end")
    world = taxi_world(cfg, 0)
    assert world.truth.shape == (7, 6, 2)
    assert world.field is None
    area = cfg.area
    assert np.all((world.truth >= area[:, 0] - 1e-6) & (world.truth <= area[:, 1] + 1e-6))


def test_gp_motion_needs_a_fitted_field() -> None:
    """A world built without the GP cannot run the GP model."""
    world = taxi_world(tiny_track("end"), 0)
    with pytest.raises(InvalidInputError, match="world"):
        run_track_episode(tiny_track("end", motion="gp"), world, 0)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"planner": "random"}, "planner"),
    ({"motion": "cv"}, "motion"),
    ({"robots": 0}, "robots"),
    ({"horizon": 0}, "horizon"),
    ({"dt_s": 0.0}, "dt_s"),
    ({"blocks": 1}, "blocks"),
    ({"one_way_fraction": 2.0}, "one_way_fraction"),
    ({"min_separation_m": -1.0}, "min_separation_m"),
    ({"camera": None}, "camera"),
])
def test_bad_track_config_names_the_field(kwargs: dict[str, object], field: str) -> None:
    """Every bad tracking setting raises InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        TrackConfig(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field
