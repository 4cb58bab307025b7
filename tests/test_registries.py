"""Backend names, choices and defaults are stated once, by the solver registries and the config
dataclasses: every command-line choice list, planner list and kernel set is read from them."""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
from typing import Any

import pytest

from searchtrack.cli import build_parser, main
from searchtrack.cli import kernels as cli_kernels
from searchtrack.cli.plan import BACKEND_NAMES, available_families, family_module
from searchtrack.core.registry import Registry
from searchtrack.plan.fleet.entropy_bound import BINNINGS, BoundConfig
from searchtrack.plan.optw import BACKENDS as OPTW_BACKENDS
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.plan.radio.problem import REWARDS
from searchtrack.plan.radio.solve import BACKENDS as RADIO_BACKENDS
from searchtrack.plan.road_search import BACKENDS as ROAD_SEARCH_BACKENDS
from searchtrack.sim import kernels
from searchtrack.sim.campaigns.experiments import EXPERIMENTS
from searchtrack.sim.radio.config import STRAIGHT, RadioMissionConfig
from searchtrack.sim.radio.run import SIMULATORS
from searchtrack.sim.radio.track_job import FILTERS
from searchtrack.sim.road_particles.planners import OWN_PLANNERS, PLANNERS, SOLVER_PLANNERS
from searchtrack.sim.roads.scenario import FilterSpec
from searchtrack.sim.roads.scenario_file import load_scenario

DEMO = Path(__file__).parents[1] / "searchtrack" / "data" / "scenarios" / "demo.toml"


def _options(*path: str) -> dict[str, argparse.Action]:
    """The options of ``searchtrack PATH...`` by flag."""
    parser = build_parser()
    for name in path:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        parser = sub.choices[name]
    return {flag: a for a in parser._actions for flag in a.option_strings}


def test_optw_backend_choices_are_the_registry() -> None:
    for command in ("solve", "bench"):
        option = _options("optw", command)["--backend"]
        assert list(option.choices or ()) == OPTW_BACKENDS.names()


def test_plan_backends_are_each_familys_registry() -> None:
    """``plan FAMILY --backend`` lists the family's registry (and ``auto``, which the search
    family adds), with each registered backend's description."""
    for name in available_families():
        module = family_module(name)
        registry: Registry[Any, Any] = module.BACKENDS
        assert set(BACKEND_NAMES[name]) - {"auto"} == set(registry.names()) - {"auto"}, name
        help_text = _options("plan", name)["--backend"].help or ""
        for backend in registry.names():
            assert registry.get(backend).description.replace("%", "%%") in help_text


def test_radio_choices_and_defaults_are_the_missions() -> None:
    """Every radio choice list is read from the registry or table it names, every default from
    :class:`RadioMissionConfig` and :class:`RadioPlanSettings`."""
    mission, plan = RadioMissionConfig(), RadioPlanSettings()
    track = _options("radio", "track")
    flown = _options("radio", "mission")
    for options in (_options("radio", "simulate"), flown):
        assert tuple(options["--measurement"].choices or ()) == tuple(SIMULATORS)
        assert options["--measurement"].default == mission.measurement
    for options in (track, flown):
        assert tuple(options["--filter"].choices or ()) == tuple(FILTERS)
        assert options["--filter"].default == mission.filter
        assert options["--particles"].default == mission.particles_per_label
    assert tuple(flown["--planner"].choices or ()) == (*REWARDS, STRAIGHT)
    assert flown["--planner"].default == mission.planner
    assert list(flown["--backend"].choices or ()) == [
        n for n in RADIO_BACKENDS.names() if n != STRAIGHT]
    assert flown["--backend"].default == mission.backend
    assert (flown["--horizon"].default, flown["--plan-particles"].default,
            flown["--r-min"].default, flown["--p-void"].default) == (
        plan.horizon, plan.plan_particles, plan.r_min_m, plan.p_void_min)


def test_fleet_binning_is_the_bounds() -> None:
    option = _options("fleet-size")["--binning"]
    assert tuple(option.choices or ()) == BINNINGS and option.default == BoundConfig.binning


def test_fleet_defaults_are_the_bound_config() -> None:
    """Every ``fleet-size`` option that sets a :class:`BoundConfig` field defaults to it."""
    options = _options("fleet-size")
    fields = {"--uav-speed": "uav_speed_mps", "--target-speed": "target_speed_mps",
              "--sigma-v": "sigma_v_mps", "--R": "meas_var_m2", "--dt": "dt_s"}
    for flag, field in fields.items():
        assert options[flag].default == getattr(BoundConfig, field), flag


def test_road_planners_are_the_road_search_registry() -> None:
    assert set(SOLVER_PLANNERS) == set(ROAD_SEARCH_BACKENDS.names()) - set(OWN_PLANNERS)
    assert (*SOLVER_PLANNERS, *OWN_PLANNERS) == PLANNERS


def test_campaign_defaults_are_the_configs() -> None:
    """The campaign parameters that mirror a config field take its default and choices."""
    mission = {p.name: p for p in EXPERIMENTS["mission"].params}
    assert mission["handover"].default == FilterSpec.handover
    radio = {p.name: p for p in EXPERIMENTS["radio_tracking_episode"].params}
    config = RadioMissionConfig()
    for name in ("filter", "planner", "backend", "measurement", "keep_out"):
        assert radio[name].default == getattr(config, name), name
    assert radio["backend"].choices == tuple(n for n in RADIO_BACKENDS.names() if n != STRAIGHT)
    road = {p.name: p for p in EXPERIMENTS["road_tracking_episode"].params}
    assert road["planner"].choices == PLANNERS


def test_scenario_file_handover_default_is_the_filters(tmp_path: Path) -> None:
    """The demo scenario without its ``handover`` line gets :class:`FilterSpec`'s default."""
    default = next(f.default for f in dataclasses.fields(FilterSpec) if f.name == "handover")
    text = "\n".join(line for line in DEMO.read_text(encoding="utf-8").splitlines()
                     if not line.startswith("handover"))
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    assert load_scenario(path).filter.handover == default


def test_backend_kernels_name_kernel_sets() -> None:
    """Every kernel set a registered backend lists is defined."""
    for registry in kernels.solver_registries():
        for name in registry.names():
            unknown = set(registry.get(name).kernels) - kernels.KERNEL_SETS.keys()
            assert not unknown, (registry.problem, name, unknown)


def test_warm_up_compiles_the_registered_kernel_sets(monkeypatch: pytest.MonkeyPatch) -> None:
    """``searchtrack warm-up`` compiles exactly the union of the registered backends' kernel
    sets and the estimators' (which no solver registry lists), and no defined set is left
    out of it."""
    compiled: list[str] = []
    monkeypatch.setattr(cli_kernels, "cold_sets", lambda names: [])
    monkeypatch.setattr(cli_kernels, "warm", lambda sets, jobs=1: {
        ks.name: compiled.append(ks.name) or 0.0 for ks in sets})
    assert main(["warm-up"]) == 0
    registered = {k for registry in kernels.solver_registries() for name in registry.names()
                  for k in registry.get(name).kernels}
    assert set(compiled) == registered | set(kernels.FILTER_KERNELS)
    assert compiled == list(kernels.KERNEL_SETS)
    assert set(kernels.OPTW_KERNELS) == {k for name in OPTW_BACKENDS.names()
                                         for k in OPTW_BACKENDS.get(name).kernels}
