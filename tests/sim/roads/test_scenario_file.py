"""Scenario files: the shipped demo loads, defaults and units are applied, every malformed field
is named in the error with its file and dotted key."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.sim.roads.scenario import FilterSpec, GuidanceSpec, MapSpec, Scenario, bundled_map
from searchtrack.sim.roads.scenario_file import load_scenario
from tests.sim.roads.scenario_text import GRID, write

DEMO = Path(__file__).parents[3] / "searchtrack" / "data" / "scenarios" / "demo.toml"


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
        (GRID + "[filter]\ntracker_alpha = -0.5\n", "filter.tracker_alpha"),
        (GRID + "[filter]\ntracker_alpha = 0.0\n", "filter.tracker_alpha"),
        (GRID + "[filter]\ntracker_alpha = 'fast'\n", "filter.tracker_alpha"),
        (GRID + "[filter]\nhandover = 'yes'\n", "filter.handover"),
        (GRID + "[guidance]\ncoverage_weight = -1.0\n", "guidance.coverage_weight"),
        (GRID + "[guidance]\ncoverage_weight = inf\n", "guidance.coverage_weight"),
        (GRID + "[guidance]\nsteering = 'spin'\n", "guidance.steering"),
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
    with pytest.raises(ParseError, match=r"missing\.toml: no such file"):
        load_scenario(tmp_path / "missing.toml")
    with pytest.raises(ParseError, match="not valid TOML"):
        load_scenario(write(tmp_path, "name = [unclosed"))


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


def test_units_and_defaults_of_the_uavs_and_targets(tmp_path: Path) -> None:
    """Speeds default to 80 mph (UAVs) and 50 mph (targets); turn rates are read in °/s; the
    minimum speed defaults to the speed (a Dubins car)."""
    sc = load_scenario(write(tmp_path, GRID))
    assert sc.limits.speed_max_mps == sc.limits.speed_min_mps == pytest.approx(35.7632)
    assert sc.limits.turn_rate_max_rps == pytest.approx(math.radians(70.0))
    assert sc.courier.max_speed_mps == pytest.approx(22.352)
    text = GRID + "speed_mps = 30.0\nmin_speed_mps = 20.0\nturn_rate_deg_s = 90.0\n"
    sc = load_scenario(write(tmp_path, text))
    assert (sc.limits.speed_max_mps, sc.limits.speed_min_mps) == (30.0, 20.0)
    assert sc.limits.turn_rate_max_rps == pytest.approx(math.pi / 2)


def test_sensor_from_parameters_or_altitude(tmp_path: Path) -> None:
    """Explicit sensor parameters are kept (no altitude recorded); an altitude goes through
    the altitude model (914.4 m: ρ = 187 m)."""
    text = GRID + ("[sensor]\npd = 0.9\npf = 0.05\nfootprint_radius_m = 120.0\n"
                   "position_noise_m = 4.0\ncell_radius_m = 0.0\n")
    sc = load_scenario(write(tmp_path, text))
    assert (sc.sensor.pd, sc.sensor.pf, sc.sensor.footprint_radius_m) == (0.9, 0.05, 120.0)
    assert (sc.sensor.position_noise_m, sc.sensor.cell_radius_m) == (4.0, 0.0)
    assert sc.altitude_m is None
    sc = load_scenario(write(tmp_path, GRID + "[sensor]\naltitude_m = 914.4\n"))
    assert sc.altitude_m == 914.4
    assert sc.sensor.footprint_radius_m == pytest.approx(187.0, abs=0.5)
    assert sc.sensor.cell_radius_m == 20.0


def test_osm_path_is_relative_to_the_scenario_file(tmp_path: Path) -> None:
    """``osm = "tiny.osm"`` names the file beside the scenario."""
    (tmp_path / "tiny.osm").write_bytes(
        (Path(__file__).parents[2] / "data" / "osm" / "tiny.osm").read_bytes())
    text = GRID.replace("grid = { rows = 4, cols = 4, block_m = 100.0 }",
                        "osm = 'tiny.osm'\nspacing_m = 20.0")
    sc = load_scenario(write(tmp_path, text))
    assert sc.map.kind == "osm" and sc.map.osm_path == tmp_path / "tiny.osm"
    assert sc.map.spacing_m == 20.0


def test_random_map_section(tmp_path: Path) -> None:
    """A ``random`` map reads its junctions, extent and seed."""
    text = GRID.replace("grid = { rows = 4, cols = 4, block_m = 100.0 }",
                        "random = { junctions = 30, extent_m = 500.0, seed = 4 }")
    spec = load_scenario(write(tmp_path, text)).map
    assert (spec.kind, spec.junctions, spec.extent_m, spec.map_seed) == ("random", 30, 500.0, 4)


@pytest.mark.parametrize(("text", "key"), [
    (GRID.replace("block_m = 100.0", "block_m = 100.0, size = 3"), "map.grid.size"),
    (GRID.replace("[map]\n", "[map]\nrandom = { junctions = 30 }\n"), "map.osm"),
    (GRID + "[uavs.extra]\n", "uavs.extra"),
    ("guidance = 'fast'\n" + GRID, "guidance"),
])
def test_nested_and_clashing_keys_are_named(tmp_path: Path, text: str, key: str) -> None:
    """Unknown keys inside map sub-tables, two map kinds at once, sub-tables where none belong and
    a value where a table belongs are named by their dotted key."""
    with pytest.raises(ParseError) as info:
        load_scenario(write(tmp_path, text))
    assert info.value.field == key, str(info.value)


def test_belief_keys_are_read(tmp_path: Path) -> None:
    """``[filter] belief``, ``histories`` and ``particles`` are read; absent, they take the
    thesis's belief and the paper's sizes."""
    sc = load_scenario(write(tmp_path, GRID))
    assert (sc.filter.belief, sc.filter.histories, sc.filter.particles) == ("lrt", 10, 500)
    text = GRID + "[filter]\nbelief = 'rbpf'\nhistories = 3\nparticles = 100\n"
    sc = load_scenario(write(tmp_path, text))
    assert (sc.filter.belief, sc.filter.histories, sc.filter.particles) == ("rbpf", 3, 100)


@pytest.mark.parametrize(("text", "key"), [
    (GRID + "[filter]\nbelief = 'kalman'\n", "filter.belief"),
    (GRID + "[filter]\nbelief = 1\n", "filter.belief"),
    (GRID + "[filter]\nhistories = 0\n", "filter.histories"),
    (GRID + "[filter]\nhistories = 2.5\n", "filter.histories"),
    (GRID + "[filter]\nparticles = -1\n", "filter.particles"),
    (GRID + "[filter]\nparticles = 'many'\n", "filter.particles"),
    (GRID + "[filter]\nbelief = 'rbpf'\nhistories = 1000\nparticles = 100000\n",
     "filter.particles"),
])
def test_bad_belief_keys_are_named(tmp_path: Path, text: str, key: str) -> None:
    """A bad belief, a non-integer or non-positive size and an RBPF too large to hold are named
    by their dotted key."""
    with pytest.raises(ParseError) as info:
        load_scenario(write(tmp_path, text))
    assert info.value.field == key, str(info.value)


def test_rbpf_demo_is_the_demo_on_the_rbpf() -> None:
    """The shipped ``demo_rbpf.toml`` is the demo with ``belief = "rbpf"`` at the paper's sizes
    and its own name; everything else is the same."""

    demo = load_scenario(DEMO)
    rbpf = load_scenario(DEMO.with_name("demo_rbpf.toml"))
    assert (rbpf.filter.belief, rbpf.filter.histories, rbpf.filter.particles) == ("rbpf", 10, 500)
    assert rbpf.name != demo.name
    same = dataclasses.replace(rbpf, name=demo.name,
                               filter=dataclasses.replace(rbpf.filter, belief="lrt"))
    assert same == demo


def test_options_of_this_library_read_from_toml(tmp_path: Path) -> None:
    """``tracker_alpha``, ``handover``, ``coverage_weight`` and ``steering`` are read when
    given."""
    text = GRID + ("[filter]\ntracker_alpha = 0.894\nhandover = true\n"
                   "[guidance]\ncoverage_weight = 2\nsteering = \"thesis\"\n")
    sc = load_scenario(write(tmp_path, text))
    assert (sc.filter.tracker_alpha, sc.filter.handover) == (0.894, True)
    assert (sc.guidance.coverage_weight, sc.guidance.steering) == (2.0, "thesis")


def test_an_empty_file_gives_the_dataclass_defaults(tmp_path: Path) -> None:
    """A file with only its map is the Scenario of that map with every default its own: the
    reader states no default of its own (UAVs, targets, sensor, filter, guidance, timing)."""
    s = load_scenario(write(tmp_path, 'name = "x"\n[map]\ngrid = { rows = 3, cols = 3 }\n'))
    assert s == Scenario("x", MapSpec("grid", None, rows=3, cols=3))


def test_the_rbpf_jump_rate_is_read_and_checked(tmp_path: Path) -> None:
    """``filter.jump_rate_per_s`` reaches the RBPF's robust prior; a negative rate is named."""
    from searchtrack.sim.roads.rbpf_belief import rbpf_config

    text = 'name = "x"\n[map]\ngrid = { rows = 3, cols = 3 }\n[filter]\nbelief = "rbpf"\n'
    s = load_scenario(write(tmp_path, text + "jump_rate_per_s = 0.05\n"))
    jumps = rbpf_config(s).jumps
    assert jumps is not None and jumps.rate_per_s == 0.05
    assert rbpf_config(load_scenario(write(tmp_path, text))).jumps is None
    with pytest.raises(ParseError, match=r"filter\.jump_rate_per_s"):
        load_scenario(write(tmp_path, text + "jump_rate_per_s = -1.0\n"))


def test_the_rbpf_node_resolution_is_read_and_checked(tmp_path: Path) -> None:
    """``filter.node_resolution_m`` sets the σ the RBPF's bank is read at (unset: the sensor's
    position noise; 0: none); a negative or non-numeric value is named."""
    from searchtrack.sim.roads.rbpf_belief import node_resolution

    text = 'name = "x"\n[map]\ngrid = { rows = 3, cols = 3 }\n[filter]\nbelief = "rbpf"\n'
    unset = load_scenario(write(tmp_path, text))
    assert unset.filter.node_resolution_m is None
    assert node_resolution(unset) == unset.sensor.position_noise_m
    for value in (0.0, 7.5):
        s = load_scenario(write(tmp_path, text + f"node_resolution_m = {value}\n"))
        assert s.filter.node_resolution_m == value and node_resolution(s) == value
    for bad in ("-1.0", '"fine"'):
        with pytest.raises(ParseError, match=r"filter\.node_resolution_m"):
            load_scenario(write(tmp_path, text + f"node_resolution_m = {bad}\n"))


def test_the_rbpf_options_are_read_and_checked(tmp_path: Path) -> None:
    """``filter.kld_epsilon`` turns on the RBPF's KLD-sampling (bins of the sensor's position
    noise, the cap ``particles``; unset: fixed counts; outside (0, 1) it is named), and
    ``filter.search_field`` picks its search field (``lrt`` by default)."""
    from searchtrack.sim.roads.rbpf_belief import rbpf_config

    text = 'name = "x"\n[map]\ngrid = { rows = 3, cols = 3 }\n[filter]\nbelief = "rbpf"\n'
    assert rbpf_config(load_scenario(write(tmp_path, text))).counts is None
    s = load_scenario(write(tmp_path, text + "kld_epsilon = 0.1\n"))
    counts = rbpf_config(s).counts
    assert counts is not None and counts.epsilon == 0.1
    assert counts.bin_m == s.sensor.position_noise_m
    assert counts.speed_bin_mps is not None and counts.speed_bin_mps > 0.0
    for bad in ("0.0", "1.0", "-0.2", '"loose"'):
        with pytest.raises(ParseError, match=r"filter\.kld_epsilon"):
            load_scenario(write(tmp_path, text + f"kld_epsilon = {bad}\n"))
    assert load_scenario(write(tmp_path, text)).filter.search_field == "lrt"
    s = load_scenario(write(tmp_path, text + 'search_field = "particles"\n'))
    assert s.filter.search_field == "particles"
    with pytest.raises(ParseError, match=r"filter\.search_field"):
        load_scenario(write(tmp_path, text + 'search_field = "gradient"\n'))


def test_the_search_route_settings_reach_the_guidance(tmp_path: Path) -> None:
    """The route strategies' ``search_*`` settings are read into the GuidanceSpec and reach the
    guidance's StrategyConfig; absent, they are StrategyConfig's own defaults (the cell side and
    the serve distance then derived from ρ)."""
    from searchtrack.plan.guidance.view import SEARCH_SETTINGS, StrategyConfig
    from searchtrack.sim.roads.guidance_setup import strategy_config

    given = {"search_iterations": 40, "search_horizon_s": 30.5, "search_replan_s": 4.0,
             "search_route_nodes": 12, "search_cell_m": 150.0, "search_serve_m": 0.0}
    assert set(given) == set(SEARCH_SETTINGS)
    text = GRID + "[guidance]\nstrategy = 'route_loiter'\n" + "".join(
        f"{k} = {v}\n" for k, v in given.items())
    sc = load_scenario(write(tmp_path, text))
    config = strategy_config(sc)
    for name, value in given.items():
        assert getattr(sc.guidance, name) == value
        assert getattr(config, name) == value
    plain = strategy_config(load_scenario(write(tmp_path, GRID)))
    rho = plain.sensor_range_m
    for name in SEARCH_SETTINGS[:4]:
        assert getattr(plain, name) == getattr(StrategyConfig, name)
    assert (plain.search_cell_m, plain.search_serve_m) == (math.sqrt(2.0) * rho, 0.5 * rho)


def test_an_optw_iteration_cap_reaches_the_guidance(tmp_path: Path) -> None:
    """``optw_iterations`` with the ILS reaches the StrategyConfig; absent, there is no cap;
    with another backend, or below 1, it is refused naming the key."""
    from searchtrack.sim.roads.guidance_setup import strategy_config

    text = GRID + "[guidance]\noptw_backend = 'ils'\noptw_iterations = 250\n"
    assert strategy_config(load_scenario(write(tmp_path, text))).optw_iterations == 250
    assert strategy_config(load_scenario(write(tmp_path, GRID))).optw_iterations is None
    for bad in ("[guidance]\noptw_iterations = 250\n",
                "[guidance]\noptw_backend = 'ils'\noptw_iterations = 0\n"):
        with pytest.raises(ParseError, match="optw_iterations"):
            load_scenario(write(tmp_path, GRID + bad))
    with pytest.raises(InvalidInputError, match="optw_iterations"):
        GuidanceSpec(optw_iterations=250)


@pytest.mark.parametrize("key,bad", [("search_iterations", "0"), ("search_iterations", "2.5"),
                                     ("search_horizon_s", "0.0"), ("search_replan_s", "-1.0"),
                                     ("search_route_nodes", "0"), ("search_cell_m", "0.0"),
                                     ("search_serve_m", "-3.0")])
def test_bad_search_route_settings_are_named(tmp_path: Path, key: str, bad: str) -> None:
    """A bad ``search_*`` value in a file is named with the file and its dotted key, and the
    spec refuses it from Python too."""
    with pytest.raises(ParseError) as info:
        load_scenario(write(tmp_path, GRID + f"[guidance]\n{key} = {bad}\n"))
    assert info.value.field == f"guidance.{key}", str(info.value)
    from searchtrack.core.errors import InvalidInputError

    with pytest.raises(InvalidInputError, match=key):
        options: dict[str, Any] = {key: float(bad) if "." in bad else int(bad)}
        GuidanceSpec(**options)
