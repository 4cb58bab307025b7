"""The experiment registry: typed parameters and defaults read from the configs, claims, and the
discovery of every domain's experiment modules (a new experiment is one module and one TOML)."""

from __future__ import annotations

import importlib
import subprocess
import sys
import textwrap
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.campaigns import experiments
from searchtrack.sim.campaigns.experiments import (
    EXPERIMENTS,
    ClaimsBy,
    Experiment,
    ExperimentRegistry,
    Metric,
    Param,
    declared_default,
    discover,
    experiment_modules,
    get,
    is_experiment_module,
)
from searchtrack.sim.campaigns.report import build_report
from searchtrack.sim.campaigns.runner import run_campaign
from searchtrack.sim.campaigns.spec import read_spec

#: Every experiment's parameters (name, type, default, minimum) and metrics: the columns and
#: defaults of the campaign store's rows, which moving an experiment must not change.
COLUMNS = {
    "toy": ([("sleep_s", float, 0.0, None), ("fail", bool, False, None),
             ("value", float, 1.0, None)], {"result": float, "seed_echo": int}),
    "mission": ([("map", str, "grid-small", None), ("mode", str, "track", None),
                 ("uavs", int, 3, None), ("targets", int, 4, None),
                 ("strategy", str, "search_and_loiter", None), ("altitude_m", float, 457.2, None),
                 ("duration_s", float, 60.0, None), ("tracker_alpha", float, 0.0, 0.0),
                 ("handover", bool, True, None), ("coverage_weight", float, 0.0, 0.0),
                 ("steering", str, "turn_back", None)],
                {"detected": int, "time_to_detect_all_s": float,
                 "time_to_first_detection_s": float, "moc_mean": float,
                 "moc_after_detection": float, "pvt": float, "pva": float}),
    "phd_tracking_scenario": ([("n_targets", int, 10, None), ("n_scans", int, 100, None),
                               ("burn_in", int, 20, None),
                               ("particles_per_target", int, 400, None),
                               ("clutter_rate", float, 10.0, None)],
                              {"ospa_mean": float, "estimates_mean": float}),
    "optw_instance": ([("instance", str, "c101", None), ("backend", str, "ils", None),
                       ("time_limit_s", float, 1.0, None), ("vehicles", int, 1, None)],
                      {"objective": float, "bound": float, "solve_status": str,
                       "solve_s": float}),
    "phd_search_episode": ([("planner", str, "proposed", None), ("horizon", int, 1, None),
                            ("refinement", str, "centre", None), ("alpha", float, 1.0, None),
                            ("max_steps", int, 0, None), ("adaptive_birth", bool, False, None),
                            ("found_gate_sigmas", float, 4.0, 0.0), ("fov", str, "printed", None)],
                           {"steps_to_find_all": int, "steps_capped": int, "targets_found": int,
                            "found_by_step_250": int, "false_found": int, "rmse_m": float,
                            "planner_ms": float, "filter_ms": float}),
    "phd_tracking_episode": ([("planner", str, "end", None), ("motion", str, "gp", None),
                              ("robots", int, 2, None), ("horizon", int, 2, None),
                              ("steps", int, 60, None)],
                             {"count_ratio": float, "entropy": float, "in_view": float,
                              "ospa_m": float, "altitude_m": float, "planner_ms": float,
                              "filter_ms": float}),
    "road_tracking_episode": ([("planner", str, "exhaustive", None),
                               ("coordination", str, "joint", None),
                               ("map", str, "grid-3x3", None),
                               ("targets", int, 2, None), ("uavs", int, 1, None),
                               ("duration_s", float, 120.0, None), ("histories", int, 10, None),
                               ("particles", int, 500, None), ("lookahead", int, 3, None),
                               ("normalization", str, "sum", None),
                               ("jump_rate_per_s", float, 0.0, 0.0),
                               ("horizon_s", float, 0.0, 0.0)],
                              {"mean_entropy": float, "early_entropy": float,
                               "late_entropy": float, "error_m": float, "all_detected_s": float,
                               "planner_ms": float, "filter_ms": float, "entropy_series": str}),
    "radio_tracking_episode": ([("filter", str, "tbd", None), ("planner", str, "renyi", None),
                                ("noise_std_v", float, 0.025, None), ("particles", int, 1000, None),
                                ("plan_particles", int, 300, None), ("horizon", int, 3, None),
                                ("headings", int, 8, None), ("backend", str, "exhaustive", None),
                                ("measurement", str, "stft", None), ("keep_out", bool, False, None),
                                ("temper_correlated", bool, True, None),
                                ("roughening_m", float, 0.0, None),
                                ("replan_on_breach", bool, False, None),
                                ("p_void_min", float, 0.9, None),
                                ("spread_inflation", float, 0.0, None),
                                ("explore_existence", float, 0.5, None),
                                ("calibration_gain_db", float, 15.0, None),
                                ("front_to_back_db", float, 10.0, None),
                                ("duration_s", float, 400.0, None)],
                               {"mean_ospa_m": float, "mean_localisation_m": float,
                                "mean_cardinality_m": float, "unsafe_fraction": float,
                                "cardinality_hit_fraction": float, "objects_detected": int,
                                "filter_ms": float, "planner_ms": float, "ospa_series": str}),
}

#: The metrics of each experiment declared never negative (a report draws their bands from 0).
NON_NEGATIVE = {
    "toy": [],
    "optw_instance": ["solve_s"],
    "phd_tracking_scenario": ["estimates_mean"],
    "phd_search_episode": ["rmse_m", "planner_ms", "filter_ms"],
    "phd_tracking_episode": ["ospa_m", "altitude_m", "planner_ms", "filter_ms"],
    "road_tracking_episode": ["error_m", "all_detected_s", "planner_ms", "filter_ms"],
    "mission": ["detected", "time_to_detect_all_s", "time_to_first_detection_s", "moc_mean",
                "moc_after_detection", "pvt", "pva"],
    "radio_tracking_episode": ["mean_ospa_m", "mean_localisation_m", "mean_cardinality_m",
                               "unsafe_fraction", "cardinality_hit_fraction",
                               "objects_detected", "filter_ms", "planner_ms"],
}

#: Fixed choices (those not read from a backend registry).
CHOICES = {
    ("mission", "map"): ("aguascalientes", "West-Oakland", "grid-dense", "grid-small"),
    ("mission", "mode"): ("track", "detect"),
    ("mission", "steering"): ("turn_back", "thesis"),
    ("optw_instance", "instance"): ("c101", "r101", "rc101", "pr01"),
    ("phd_search_episode", "planner"): ("proposed", "refinement", "lawnmower"),
    ("phd_search_episode", "horizon"): (1, 2, 3, 4, 5),
    ("phd_search_episode", "refinement"): ("centre", "mi"),
    ("phd_search_episode", "fov"): ("printed", "squared"),
    ("phd_tracking_episode", "planner"): ("end", "mi", "lawnmower"),
    ("phd_tracking_episode", "motion"): ("gp", "random_walk"),
    ("road_tracking_episode", "map"): ("grid-3x3", "aguascalientes", "West-Oakland"),
    ("road_tracking_episode", "normalization"): ("sum", "max"),
    ("road_tracking_episode", "coordination"): ("joint", "alone"),
    ("radio_tracking_episode", "filter"): ("tbd", "dtt"),
    ("radio_tracking_episode", "planner"): ("renyi", "cs", "straight"),
    ("radio_tracking_episode", "measurement"): ("stft", "time"),
}


def test_get_lists_the_registered_names() -> None:
    """An unknown experiment's error lists every registered name."""
    with pytest.raises(InvalidInputError, match=r"experiment='nope'.*toy"):
        get("nope")
    assert {"toy", "mission", "phd_tracking_scenario", "optw_instance"} <= set(EXPERIMENTS)


def test_every_experiment_keeps_its_columns_and_defaults() -> None:
    """Each experiment, wherever its module lives, has the parameters (name, type, default,
    minimum, fixed choices) and metrics its campaign databases were written with."""
    assert set(EXPERIMENTS) == set(COLUMNS)
    for name, (params, metrics) in COLUMNS.items():
        exp = get(name)
        got = [(p.name, p.kind, p.default, p.minimum) for p in exp.params]
        assert got == params, name
        assert [type(p.default) for p in exp.params] == [kind for _, kind, _, _ in params], name
        assert [(m, d.kind) for m, d in exp.metrics.items()] == list(metrics.items()), name
        assert [m for m, d in exp.metrics.items() if d.non_negative] == NON_NEGATIVE[name], name
    for (name, param), choices in CHOICES.items():
        assert get(name).param(param).choices == choices, (name, param)


def test_resolve_checks_names_and_types() -> None:
    """Unknown names and wrong types are refused naming the parameter; ints widen to floats."""
    toy = get("toy")
    assert toy.resolve({"value": 2}) == {"sleep_s": 0.0, "fail": False, "value": 2.0}
    with pytest.raises(InvalidInputError, match="colour"):
        toy.resolve({"colour": 1})
    with pytest.raises(InvalidInputError, match="fail=1: must be bool"):
        toy.resolve({"fail": 1})
    with pytest.raises(InvalidInputError, match="value=True: must be float"):
        toy.resolve({"value": True})
    with pytest.raises(InvalidInputError, match="map='moon'"):
        get("mission").resolve({"map": "moon"})


def test_metrics_are_declared_with_a_type_and_a_sign() -> None:
    """A metric is a number or text; only a number may be declared never negative; an
    experiment takes its metrics as :class:`Metric` and tells which are never negative."""
    assert Metric(float) == Metric(float, non_negative=False)
    with pytest.raises(InvalidInputError, match="kind"):
        Metric(bool)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="non_negative"):
        Metric(str, non_negative=True)
    with pytest.raises(InvalidInputError, match="x="):
        Experiment("bare", (), {"x": float}, lambda p, s: {"x": 0.0})  # type: ignore[dict-item]
    exp = Experiment("signs", (), {"d_m": Metric(float, non_negative=True), "x": Metric(float)},
                     lambda p, s: {"d_m": 0.0, "x": 0.0})
    assert (exp.non_negative("d_m"), exp.non_negative("x"), exp.non_negative("t")) == (
        True, False, False)


def test_reserved_column_names_are_refused() -> None:
    """A parameter or metric may not take a column every row has (``seed``, ``status``...)."""
    with pytest.raises(InvalidInputError, match="seed"):
        Experiment("bad", (Param("seed", int, 0),), {"x": Metric(float)}, lambda p, s: {"x": 0.0})


@dataclass(frozen=True)
class _Config:
    count: int = 3
    rate: float = 0.5
    label: str = "a"
    on: bool = True
    nothing: float | None = None


def _step(x: int, *, scale: float = 2.0) -> float:
    return x * scale


def test_param_of_takes_the_default_and_its_type_from_the_source() -> None:
    """``Param.of`` reads a dataclass field's or a keyword's default and types the parameter by
    it; a source without a plain default is refused naming the argument."""
    assert Param.of(_Config, "count") == Param("count", int, 3)
    assert Param.of(_Config, "rate", name="r", minimum=0.0) == Param("r", float, 0.5,
                                                                       minimum=0.0)
    assert Param.of(_Config, "label", choices=("a", "b")) == Param("label", str, "a", ("a", "b"))
    assert Param.of(_Config, "on").kind is bool
    assert Param.of(_step, "scale") == Param("scale", float, 2.0)
    assert declared_default(_Config, "rate") == 0.5
    for source, name in ((_Config, "nothing"), (_Config, "missing"), (_step, "x")):
        with pytest.raises(InvalidInputError) as info:
            Param.of(source, name)
        assert info.value.field == name


def _two_modes(claims: dict[str, str]) -> Experiment:
    return Experiment("modes", (Param("mode", str, "a", ("a", "b")), Param("n", int, 1)),
                      {"x": Metric(float)}, lambda p, s: {"x": 0.0}, claim=ClaimsBy("mode", claims))


def test_claims_by_a_parameter_are_the_shared_values() -> None:
    """A claim per mode is the claim of the mode every row shares; mixed modes, no rows or a
    mode without a claim give none; a claim keyed by an unknown parameter or value is refused."""
    exp = _two_modes({"a": "claim A", "b": "claim B"})
    assert exp.claims() == ("claim A", "claim B")
    assert exp.claim_for([{"mode": "b", "n": 1}, {"mode": "b", "n": 2}]) == "claim B"
    assert exp.claim_for([{"mode": "a"}, {"mode": "b"}]) is None
    assert exp.claim_for([]) is None
    assert _two_modes({"a": "claim A"}).claim_for([{"mode": "b"}]) is None
    with pytest.raises(InvalidInputError, match="colour"):
        Experiment("c", (Param("mode", str, "a"),), {"x": Metric(float)}, lambda p, s: {"x": 0.0},
                   claim=ClaimsBy("colour", {"red": "claim"}))
    with pytest.raises(InvalidInputError, match="mode='c'"):
        _two_modes({"c": "claim C"})
    plain = Experiment("p", (), {"x": Metric(float)}, lambda p, s: {"x": 0.0}, claim="one claim")
    assert plain.claims() == ("one claim",) and plain.claim_for([]) == "one claim"
    assert get("toy").claims() == () and get("toy").claim_for([{}]) is None


def test_modules_are_named_experiment_experiments_or_experiment_something() -> None:
    assert all(is_experiment_module(n) for n in ("a.experiment", "a.b.experiments",
                                                 "a.experiment_toy"))
    assert not any(is_experiment_module(n) for n in ("a.experimental", "a.my_experiment",
                                                     "experiment.a"))


def test_the_domains_experiment_modules_are_found() -> None:
    """Every domain's experiment module is found, this registry module is not."""
    assert experiment_modules("searchtrack.sim") == [
        "searchtrack.sim.campaigns.experiment_builtin",
        "searchtrack.sim.particles.experiments",
        "searchtrack.sim.radio.experiment",
        "searchtrack.sim.road_particles.experiment",
        "searchtrack.sim.roads.experiment",
    ]


_NEW_EXPERIMENT = '''
"""A domain's new experiment."""

from searchtrack.sim.campaigns.experiments import Experiment, Metric, Param


def doubled(params, seed):
    return {"twice": 2.0 * params["x"], "seed_plus": seed + params["shift"]}


EXPERIMENTS = (Experiment("doubling", (Param("x", float, 1.0), Param("shift", int, 0)),
                          {"twice": Metric(float), "seed_plus": Metric(int)}, doubled,
                          claim="the new paper: twice as much"),)
'''


@pytest.fixture
def new_domain(tmp_path: Path) -> Iterator[tuple[str, Path]]:
    """A package ``newdomain_<n>`` on ``sys.path`` with a subpackage holding an experiment
    module and a helper module; removed from ``sys.modules`` afterwards."""
    root = f"newdomain_{abs(hash(tmp_path)) % 10**8}"
    folder = tmp_path / root / "sub"
    folder.mkdir(parents=True)
    (tmp_path / root / "__init__.py").write_text("", encoding="utf-8")
    (folder / "__init__.py").write_text("", encoding="utf-8")
    (folder / "experiment.py").write_text(textwrap.dedent(_NEW_EXPERIMENT), encoding="utf-8")
    (folder / "helpers.py").write_text("raise RuntimeError('not an experiment module')\n",
                                       encoding="utf-8")
    sys.path.insert(0, str(tmp_path))
    try:
        yield root, folder
    finally:
        sys.path.remove(str(tmp_path))
        for name in [m for m in sys.modules if m == root or m.startswith(root + ".")]:
            del sys.modules[name]


def test_a_new_experiment_module_is_found(new_domain: tuple[str, Path]) -> None:
    """A module named ``experiment`` in a new package is found and its experiments listed;
    the package's other modules are not imported."""
    root, _ = new_domain
    assert experiment_modules(root) == [f"{root}.sub.experiment"]
    registry = ExperimentRegistry((root,))
    assert list(registry) == ["doubling"] and len(registry) == 1
    assert registry["doubling"].run({"x": 2.0, "shift": 1}, 4) == {"twice": 4.0, "seed_plus": 5}
    assert f"{root}.sub.helpers" not in sys.modules


def test_a_new_experiment_is_one_module_and_one_toml(new_domain: tuple[str, Path],
                                                     tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """With the new package searched beside the library's, a campaign file naming its
    experiment runs into a results database and its report carries the module's claim."""
    root, _ = new_domain
    monkeypatch.setattr(experiments, "EXPERIMENTS", ExperimentRegistry((experiments.ROOT, root)))
    path = tmp_path / "doubling.toml"
    path.write_text('name = "d"\nexperiment = "doubling"\nseeds = [0, 1]\n[grid]\nx = [1, 3]\n',
                    encoding="utf-8")
    spec = read_spec(path)
    summary = run_campaign(spec, tmp_path / "d.duckdb", workers=0)
    assert (summary.ok, summary.failed) == (4, 0)
    from searchtrack.sim.campaigns.store import open_existing

    with open_existing(tmp_path / "d.duckdb") as store:
        rows = store.rows()
        report = build_report("d", store.experiment, list(store.metrics), rows)
    assert sorted(r["twice"] for r in rows) == [2.0, 2.0, 6.0, 6.0]
    assert report.group_keys == ("x",) and report.claim == "the new paper: twice as much"
    assert "toy" in experiments.EXPERIMENTS


def test_experiment_modules_must_declare_their_experiments(new_domain: tuple[str, Path]) -> None:
    """An experiment module without ``EXPERIMENTS`` and two experiments of one name are
    refused naming the module or the name."""
    root, folder = new_domain
    (folder / "experiment_other.py").write_text(textwrap.dedent(_NEW_EXPERIMENT),
                                                encoding="utf-8")
    with pytest.raises(InvalidInputError, match="'doubling': declared twice"):
        discover((root,))
    (folder / "experiment_other.py").write_text("EXPERIMENT = None\n", encoding="utf-8")
    del sys.modules[f"{root}.sub.experiment_other"]
    importlib.invalidate_caches()
    with pytest.raises(InvalidInputError, match=rf"{root}\.sub\.experiment_other\.EXPERIMENTS"):
        discover((root,))


def test_registry_is_found_on_first_use() -> None:
    """Importing the runner imports no domain; the first lookup imports the experiment modules
    (as a Dask worker does when it takes its first run)."""
    modules = ("searchtrack.sim.roads.experiment", "searchtrack.sim.particles.experiments",
               "searchtrack.sim.radio.experiment", "searchtrack.sim.road_particles.experiment")
    domains = tuple(m.rpartition(".")[0] for m in modules)
    code = ("import sys\nimport searchtrack.sim.campaigns.runner\n"
            f"print(any(m.startswith({domains!r}) for m in sys.modules))\n"
            "from searchtrack.sim.campaigns.experiments import get\nget('toy')\n"
            f"print(all(m in sys.modules for m in {modules!r}))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.split() == ["False", "True"]
