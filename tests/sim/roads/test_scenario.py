"""Scenarios in Python: constructors refuse bad values, and every registered backend is a valid
choice."""

from __future__ import annotations

from pathlib import Path

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.roads.scenario import FilterSpec, GuidanceSpec, MapSpec, Scenario
from searchtrack.sim.roads.scenario_file import load_scenario
from tests.sim.roads.scenario_text import GRID, write


def test_constructor_validation() -> None:
    """Scenario and its parts refuse bad values in Python too."""
    grid = MapSpec("grid", rows=3, cols=3)
    with pytest.raises(InvalidInputError, match="dt_s"):
        Scenario("x", grid, duration_s=1.0, dt_s=2.0)
    with pytest.raises(InvalidInputError, match="osm_path"):
        MapSpec("osm")
    with pytest.raises(InvalidInputError, match="p_min"):
        FilterSpec(p_min=1.0)
    with pytest.raises(InvalidInputError, match="uav_start"):
        Scenario("x", grid, uav_start="north")
    with pytest.raises(InvalidInputError, match="strategy"):
        GuidanceSpec(strategy="chase")
    with pytest.raises(InvalidInputError, match="optw_backend"):
        GuidanceSpec(optw_backend="gurobi")
    with pytest.raises(InvalidInputError, match="steering"):
        GuidanceSpec(steering="spin")


def test_strategy_and_associator_names_come_from_the_registries(tmp_path: Path) -> None:
    """Every guidance and association backend is a valid scenario choice, in TOML too."""
    from searchtrack.estimate.association import BACKENDS as ASSOCIATION_BACKENDS
    from searchtrack.plan.guidance import BACKENDS as GUIDANCE_BACKENDS

    for name in GUIDANCE_BACKENDS.names():
        assert GuidanceSpec(strategy=name).strategy == name
        sc = load_scenario(write(tmp_path, GRID + f"[guidance]\nstrategy = '{name}'\n"))
        assert sc.guidance.strategy == name
    for name in ASSOCIATION_BACKENDS.names():
        assert FilterSpec(associator=name).associator == name
        sc = load_scenario(write(tmp_path, GRID + f"[filter]\nassociator = '{name}'\n"))
        assert sc.filter.associator == name


def test_belief_settings_default_to_the_thesis_and_are_validated() -> None:
    """The filter estimates with the LRT unless ``belief = "rbpf"``; the RBPF's histories and
    particles are integers ≥ 1 (10 and 500 by default), each refused by name."""
    spec = FilterSpec()
    assert (spec.belief, spec.histories, spec.particles) == ("lrt", 10, 500)
    assert FilterSpec(belief="rbpf", histories=3, particles=100).belief == "rbpf"
    for bad, name in [({"belief": "kalman"}, "belief"), ({"histories": 0}, "histories"),
                      ({"particles": -5}, "particles"), ({"particles": True}, "particles"),
                      ({"histories": 2.5}, "histories")]:
        with pytest.raises(InvalidInputError) as info:
            FilterSpec(**bad)  # type: ignore[arg-type]
        assert info.value.field == name


def test_rbpf_size_is_capped() -> None:
    """An RBPF of histories × targets × particles above the cap is refused, naming the
    particles; the same sizes are accepted for the LRT, which ignores them."""
    from searchtrack.sim.roads.scenario import MAX_RBPF_PARTICLES

    grid = MapSpec("grid", rows=3, cols=3)
    huge = MAX_RBPF_PARTICLES // 4 + 1
    with pytest.raises(InvalidInputError) as info:
        Scenario("x", grid, target_count=4,
                 filter=FilterSpec(belief="rbpf", histories=1, particles=huge))
    assert info.value.field == "filter.particles"
    assert Scenario("x", grid, target_count=4,
                    filter=FilterSpec(histories=1, particles=huge)).filter.belief == "lrt"


def test_options_of_this_library_defaults_and_validation() -> None:
    """``tracker_alpha`` (None: the LRT's α) and ``coverage_weight`` (0) default to the thesis,
    ``handover`` to on; bad values are refused naming the field."""
    f, g = FilterSpec(), GuidanceSpec()
    assert (f.tracker_alpha, f.handover, g.coverage_weight) == (None, True, 0.0)
    assert FilterSpec(tracker_alpha=0.894, handover=True).tracker_alpha == 0.894
    assert GuidanceSpec(coverage_weight=2.0).coverage_weight == 2.0
    bad: list[tuple[type, dict[str, object], str]] = [
        (FilterSpec, {"tracker_alpha": 0.0}, "tracker_alpha"),
        (FilterSpec, {"tracker_alpha": -1.0}, "tracker_alpha"),
        (FilterSpec, {"tracker_alpha": float("nan")}, "tracker_alpha"),
        (FilterSpec, {"tracker_alpha": float("inf")}, "tracker_alpha"),
        (FilterSpec, {"tracker_alpha": "fast"}, "tracker_alpha"),
        (FilterSpec, {"node_resolution_m": -1.0}, "node_resolution_m"),
        (FilterSpec, {"node_resolution_m": float("inf")}, "node_resolution_m"),
        (FilterSpec, {"node_resolution_m": "fine"}, "node_resolution_m"),
        (FilterSpec, {"handover": 1}, "handover"),
        (FilterSpec, {"handover": "yes"}, "handover"),
        (GuidanceSpec, {"coverage_weight": -0.5}, "coverage_weight"),
        (GuidanceSpec, {"coverage_weight": float("inf")}, "coverage_weight"),
        (GuidanceSpec, {"coverage_weight": float("nan")}, "coverage_weight"),
    ]
    for cls, kwargs, name in bad:
        with pytest.raises(InvalidInputError) as info:
            cls(**kwargs)
        assert info.value.field == name, kwargs
