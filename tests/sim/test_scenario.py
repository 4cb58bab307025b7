"""Scenario files: the shipped demo loads, every malformed field is named in the error."""

from __future__ import annotations

from pathlib import Path

import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.sim.scenario import FilterSpec, GuidanceSpec, MapSpec, Scenario, bundled_map
from searchtrack.sim.scenario_file import load_scenario

DEMO = Path(__file__).parents[2] / "searchtrack" / "data" / "scenarios" / "demo.toml"

GRID = """
name = "grid"
duration_s = 3.0
[map]
grid = { rows = 4, cols = 4, block_m = 100.0 }
[uavs]
count = 2
"""


def write(tmp_path: Path, text: str) -> Path:
    """Write ``text`` to a scenario file and return its path."""
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_demo_scenario_loads() -> None:
    """The shipped demo reads with its documented values."""
    sc = load_scenario(DEMO)
    assert sc.name == "demo-aguascalientes"
    assert sc.uav_count == 3 and sc.target_count == 4
    assert sc.guidance.strategy == "search_and_reacquire"
    assert sc.map.osm_path == bundled_map("aguascalientes")
    assert sc.sensor.footprint_radius_m == pytest.approx(187.0, abs=0.5)
    assert sc.n_steps == 800


def test_grid_scenario_defaults(tmp_path: Path) -> None:
    """Missing sections take the thesis defaults; a synthetic grid builds."""
    sc = load_scenario(write(tmp_path, GRID))
    assert sc.map.kind == "grid" and sc.map.rows == 4
    assert sc.filter == FilterSpec()
    assert sc.guidance == GuidanceSpec()
    assert sc.sensor.pd == pytest.approx(0.95, abs=1e-3)
    net = sc.map.build()
    assert net.n_nodes > 16


@pytest.mark.parametrize(
    ("text", "key"),
    [
        (GRID + "[filter]\nalpha = -1.0\n", "filter.alpha"),
        (GRID + "[filter]\nassociator = 'hungarian'\n", "filter.associator"),
        (GRID + "[uavs2]\ncount = 1\n", "uavs2"),
        (GRID.replace("count = 2", "count = 0"), "uavs.count"),
        (GRID.replace("count = 2", "count = 'two'"), "uavs.count"),
        (GRID.replace("duration_s = 3.0", "duration_s = nan"), "duration_s"),
        (GRID.replace("duration_s = 3.0", "duration_s = -3.0"), "duration_s"),
        (GRID + "[sensor]\naltitude_m = 457.2\npd = 0.9\n", "sensor.pd"),
        (GRID + "[sensor]\naltitude_m = 99999.0\n", "sensor.altitude_m"),
        (GRID + "[guidance]\nrevisit_threshold = 1.5\n", "guidance.revisit_threshold"),
        (GRID + "[targets]\ncount = 2\nspeed = 3\n", "targets.speed"),
        (GRID.replace("grid = { rows = 4, cols = 4, block_m = 100.0 }", "osm = 'nowhere.osm'"),
         "map.osm"),
        (GRID.replace("grid = { rows = 4, cols = 4, block_m = 100.0 }", ""), "map.osm"),
        ("mode = 'chase'\n" + GRID, "mode"),
        (GRID + "[guidance]\nstrategy = 'nonsense'\n", "guidance.strategy"),
        (GRID + "[guidance]\noptw_backend = 'gurobi'\n", "guidance.optw_backend"),
        (GRID + "[guidance]\nspring_k = -2.0\n", "guidance.spring_k"),
        (GRID + "[sensor]\ncell_radius_m = -1.0\n", "sensor.cell_radius_m"),
        (GRID + "[filter]\nmerge_radius_m = -5.0\n", "filter.merge_radius_m"),
        (GRID + "[filter]\nllr_floor = 3.0\n", "filter.llr_floor"),
        (GRID + "[filter]\nllr_floor = 'off'\n", "filter.llr_floor"),
        (GRID + "[filter]\nnegative_information = 1\n", "filter.negative_information"),
    ],
)
def test_bad_fields_are_named(tmp_path: Path, text: str, key: str) -> None:
    """Each malformed field raises a ParseError naming the file and the dotted key."""
    with pytest.raises(ParseError) as info:
        load_scenario(write(tmp_path, text))
    assert info.value.field == key, str(info.value)
    assert "s.toml" in str(info.value)


def test_unreadable_files(tmp_path: Path) -> None:
    """A missing file and broken TOML are reported with the file name."""
    with pytest.raises(ParseError, match="cannot read"):
        load_scenario(tmp_path / "missing.toml")
    with pytest.raises(ParseError, match="not valid TOML"):
        load_scenario(write(tmp_path, "name = [unclosed"))


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


def test_llr_floor_none_means_no_floor(tmp_path: Path) -> None:
    """``llr_floor = "none"`` reads as −inf (the thesis); the default is −20; a number is kept."""
    import math

    assert load_scenario(write(tmp_path, GRID)).filter.llr_floor == -20.0
    sc = load_scenario(write(tmp_path, GRID + "[filter]\nllr_floor = 'none'\n"))
    assert sc.filter.llr_floor == -math.inf
    sc = load_scenario(write(tmp_path, GRID + "[filter]\nllr_floor = -5.0\n"))
    assert sc.filter.llr_floor == -5.0
    sc = load_scenario(write(tmp_path, GRID + "[filter]\nnegative_information = false\n"))
    assert sc.filter.negative_information is False


def test_spring_constants_reach_the_strategy() -> None:
    """``spring_k`` and ``loiter_k`` from the scenario configure the strategy's force laws."""
    from searchtrack.sim.guidance_setup import strategy_config

    grid = MapSpec("grid", rows=3, cols=3)
    sc = Scenario("x", grid, guidance=GuidanceSpec(spring_k=5.0, loiter_k=7.0))
    config = strategy_config(sc)
    assert config.spring_k == 5.0
    assert config.loiter_k == 7.0


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
