"""Closed-loop search episodes of paper 004 with the PHD filter in the loop."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.phd import PHDState
from searchtrack.plan.search import (
    EmptyHorizonMI,
    ExplorationBonus,
    NoRefinement,
    SearchProblem,
    lawnmower_3d,
    solve,
)
from searchtrack.sim.particles.search import SearchConfig, _filter_step, run_search_episode

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
    assert small("refinement").settings().alpha == 0.0
    assert small("proposed", alpha=2.0).settings().alpha == 2.0


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"planner": "random"}, "planner"),
    ({"n_targets": 0}, "n_targets"),
    ({"max_steps": 0}, "max_steps"),
    ({"horizon": 0}, "horizon"),
    ({"alpha": -1.0}, "alpha"),
    ({"refinement": NoRefinement()}, "refinement"),
    ({"refinement": "mi"}, "refinement"),
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


def test_mi_refinement_episode_runs_and_repeats() -> None:
    """The proposed planner with MI refinement repeats exactly for a seed."""
    a = run_search_episode(small("proposed", refinement=EmptyHorizonMI(), max_steps=25), 2)
    b = run_search_episode(small("proposed", refinement=EmptyHorizonMI(), max_steps=25), 2)
    np.testing.assert_array_equal(a.path, b.path)
    assert a.path.shape[1] == 3


def _two_groups(seed: int) -> tuple[PHDState, np.ndarray]:
    """A 004 PHD with two static particle groups 370 m apart (masses 0.8 and 0.6: λ = 1.4, so
    ``round(λ)`` gives one cluster) and a UAV half-way between them."""
    rng = np.random.default_rng(seed)
    a, b = np.array([242.0, 209.0, -19.0]), np.array([-16.0, 209.0, 234.0])
    pos = np.vstack([a + rng.standard_normal((400, 3)), b + rng.standard_normal((300, 3))])
    w = np.concatenate([np.full(400, 0.8 / 400), np.full(300, 0.6 / 300)])
    return PHDState.from_particles(pos, w, position_dim=3), np.array([108.0, 180.0, 108.0])


def test_refinement_centres_cover_every_particle_group() -> None:
    """Eq. (11) gets a centre for each of two far groups although round(λ) = 1 (the trimmed
    k-means alone left the lighter group out of the refinement term)."""
    state, q = _two_groups(0)
    cfg = SearchConfig(planner="refinement")
    _, _, centres = _filter_step(state, np.empty((0, 3)), np.empty((0, 3)), q, cfg,
                                 np.random.default_rng(0))
    assert centres.shape[0] == 2
    assert np.linalg.norm(centres[0] - centres[1]) > 300.0


def test_centre_refinement_does_not_oscillate_between_far_groups() -> None:
    """From half-way between two far groups, centre refinement flies toward one of them: no
    move undoes the previous one (it flipped between the groups every step before)."""
    state, q = _two_groups(1)
    cfg = SearchConfig(planner="refinement")
    rng = np.random.default_rng(1)
    bonus = ExplorationBonus(cfg.bounds, cfg.bonus_resolution_m)
    moves = []
    for _ in range(8):
        state, _, centres = _filter_step(state, np.empty((0, 3)), np.empty((0, 3)), q, cfg, rng)
        bonus = bonus.updated(cfg.sensor, q)
        plan = solve(SearchProblem(q, cfg.bounds, bonus, cfg.sensor, cfg.settings(),
                                   belief=state, centres=centres), backend="receding").plan
        assert plan is not None
        moves.append(plan.waypoint - q)
        q = plan.waypoint
    assert not any(np.allclose(m1, -m0) for m0, m1 in itertools.pairwise(moves))


@pytest.mark.parametrize("offset_m", [6.0, 9.0])
def test_far_detection_of_a_found_target_does_not_rebuild_it(offset_m: float) -> None:
    """A found target seen from 150 m, its measurement 6 or 9 m across the line of sight from
    the saved estimate (2–3 σ of the 3 m bearing noise there): the loop's gate drops it, so it
    updates nothing and seeds no birth. With 004's printed 5 m ball (``gate_sigmas = 0``) it
    passed and seeded a birth at the found target, the peak the gate is meant to prevent."""
    cfg = SearchConfig(planner="lawnmower")
    found = np.array([[150.0, 0.0, 0.0]])
    z = cfg.sensor.measurement(np.zeros(3), np.array([[150.0, offset_m, 0.0]]))
    printed = replace(cfg, found=replace(cfg.found, gate_sigmas=0.0))
    for config, births in ((cfg, 0), (printed, 1)):
        state, saved, _ = _filter_step(PHDState.empty(3, 3), found, z, np.zeros(3), config,
                                       np.random.default_rng(0))
        assert state.record.seed_positions.shape[0] == births
        np.testing.assert_array_equal(saved, found)
    assert cfg.found.gate_sigmas == 4.0
