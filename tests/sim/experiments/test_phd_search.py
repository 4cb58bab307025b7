"""Closed-loop search (paper 004) and tracking (paper 003) episodes with the PHD filter."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.search.lawnmower import lawnmower_3d
from searchtrack.sim.phd_search import (
    SearchConfig,
    TrackConfig,
    run_search_episode,
    run_track_episode,
    taxi_world,
)

BOX = np.array([[0.0, 96.0]] * 3)


def small(planner: str, **kwargs: object) -> SearchConfig:
    args: dict[str, object] = {"planner": planner, "bounds": BOX, "n_targets": 3,
                               "max_steps": 300, "start": np.zeros(3), **kwargs}
    return SearchConfig(**args)  # type: ignore[arg-type]


def test_search_is_deterministic_for_a_seed() -> None:
    """Two runs with one seed give the same path, counts and estimates."""
    a = run_search_episode(small("proposed"), 3)
    b = run_search_episode(small("proposed"), 3)
    assert a.steps_to_find_all == b.steps_to_find_all
    np.testing.assert_array_equal(a.path, b.path)
    np.testing.assert_array_equal(a.found_per_step, b.found_per_step)
    np.testing.assert_array_equal(a.estimates, b.estimates)


def test_same_seed_same_map_for_every_planner() -> None:
    """The target map depends on the seed only, so planners compare on equal maps."""
    a = run_search_episode(small("proposed"), 5)
    b = run_search_episode(small("lawnmower"), 5)
    np.testing.assert_array_equal(a.targets, b.targets)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_proposed_finds_all_targets_in_a_small_box(seed: int) -> None:
    """Exploration + refinement finds 3 targets in a 96 m cube well within the cap, accurately."""
    ep = run_search_episode(small("proposed"), seed)
    assert ep.finished
    assert ep.steps_to_find_all <= 100
    assert ep.false_found == 0
    assert ep.rmse_m < 3.0
    assert np.all(np.diff(ep.found_per_step) >= 0)


@pytest.mark.parametrize("seed", [0, 1])
def test_lawnmower_eventually_covers(seed: int) -> None:
    """Flying the whole lawnmower finds every target before the path runs out."""
    length = lawnmower_3d(BOX, 48.0, 48.0, 12.0).shape[0]
    ep = run_search_episode(small("lawnmower", max_steps=length), seed)
    assert ep.finished
    assert ep.steps_to_find_all <= length
    np.testing.assert_array_equal(ep.path[1:4], lawnmower_3d(BOX, 48.0, 48.0, 12.0)[1:4])


def test_unfinished_episode_reports_the_cap() -> None:
    """An episode that cannot find everything reports ``max_steps + 1``."""
    ep = run_search_episode(small("proposed", max_steps=2), 0)
    assert not ep.finished
    assert ep.steps_to_find_all == 3
    assert ep.found_per_step.shape == (2,)


def test_refinement_only_uses_no_exploration() -> None:
    """The refinement-only baseline is the planner with α = 0."""
    assert small("refinement").receding().alpha == 0.0
    assert small("proposed", alpha=2.0).receding().alpha == 2.0


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"planner": "random"}, "planner"),
    ({"n_targets": 0}, "n_targets"),
    ({"max_steps": 0}, "max_steps"),
    ({"horizon": 0}, "horizon"),
    ({"alpha": -1.0}, "alpha"),
    ({"refinement": "none"}, "refinement"),
    ({"step_m": 0.0}, "step_m"),
    ({"bounds": np.zeros((3, 2))}, "bounds"),
    ({"start": np.array([500.0, 0.0, 0.0])}, "start"),
    ({"min_distinct": 0}, "min_distinct"),
    ({"sensor": "camera"}, "sensor"),
])
def test_bad_search_config_names_the_field(kwargs: dict[str, object], field: str) -> None:
    """Every bad setting raises InvalidInputError naming the field."""
    args: dict[str, object] = {"bounds": BOX, "start": np.zeros(3), **kwargs}
    with pytest.raises(InvalidInputError) as err:
        SearchConfig(**args)  # type: ignore[arg-type]
    assert err.value.field == field


def test_bad_seed_is_rejected() -> None:
    """A negative seed names the field."""
    with pytest.raises(InvalidInputError, match="seed"):
        run_search_episode(small("proposed"), -1)


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
