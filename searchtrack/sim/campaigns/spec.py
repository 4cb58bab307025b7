"""A campaign file: one experiment × a parameter grid × seeds, read from TOML and validated.

::

    name = "toy-demo"
    experiment = "toy"          # a name of searchtrack.sim.campaigns.experiments.EXPERIMENTS
    metrics = ["result"]        # the metrics to summarise (default: all of the experiment's)
    seeds = {count = 5, start = 0}   # or a list: seeds = [1, 2, 3]

    [settings]                  # fixed parameters (the rest keep their defaults)
    sleep_s = 0.01

    [grid]                      # the parameters varied: every combination is run per seed
    value = [1.0, 2.0, 3.0]

The key of a run is the SHA-256 of the canonical JSON of experiment, every parameter, seed and
``searchtrack.__version__``: the same run has the same key in every file and on every machine.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

import searchtrack
from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.files import read_text
from searchtrack.core.registry import MAX_SEED, check_seed
from searchtrack.sim.campaigns.experiments import Experiment, ParamValue, get

#: Largest number of runs one campaign may hold (grid size × seeds).
MAX_RUNS = 10_000_000

#: The grid key whose values are tables of parameters varying together.
CELLS = "cells"

_TOP_KEYS = ("name", "experiment", "settings", "grid", "seeds", "metrics")


@dataclass(frozen=True)
class RunSpec:
    """One run: the experiment, every parameter, the seed and the run's key (picklable: it is
    sent to Dask workers)."""

    key: str
    experiment: str
    params: dict[str, ParamValue]
    seed: int


def run_key(experiment: str, params: Mapping[str, ParamValue], seed: int) -> str:
    """SHA-256 (hex) of the canonical JSON of experiment, parameters, seed and package version."""
    text = json.dumps({"experiment": experiment, "params": dict(params), "seed": seed,
                       "version": searchtrack.__version__}, sort_keys=True,
                      separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _field(key: str, exc: InvalidInputError) -> InvalidInputError:
    return InvalidInputError(key, exc.value, exc.reason)


@dataclass(frozen=True)
class CampaignSpec:
    """A validated campaign.

    Parameters
    ----------
    name
        The campaign's name (a results database holds one campaign).
    experiment
        A registered experiment's name.
    settings
        Fixed parameter values (the others keep the experiment's defaults).
    grid
        Parameter name -> the values it takes (at least one parameter, each a non-empty list);
        the key ``cells`` instead lists tables of parameters that vary together (e.g.
        ``[{uavs = 1, targets = 4}, {uavs = 3, targets = 2}]``), one axis of the product.
    seeds
        The seeds every grid point is run with (distinct, in ``[0, MAX_SEED]``).
    metrics
        The metrics to summarise (default: all of the experiment's).

    Raises
    ------
    InvalidInputError
        Naming the dotted key at fault (``grid.value``, ``settings.sleep_s``, ``seeds``...).
    """

    name: str
    experiment: str
    settings: Mapping[str, ParamValue]
    grid: Mapping[str, tuple[Any, ...]]
    seeds: tuple[int, ...]
    metrics: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InvalidInputError("name", self.name, "must be a non-empty string")
        exp = get(self.experiment)
        settings = {}
        for k, v in self.settings.items():
            try:
                settings[k] = exp.param(k).check(v)
            except InvalidInputError as exc:
                raise _field(f"settings.{k}", exc) from None
        if not self.grid:
            raise InvalidInputError("grid", {}, "must vary at least one parameter "
                                    "(a one-value list is fine)")
        grid: dict[str, tuple[Any, ...]] = {}
        for k, values in self.grid.items():
            key = f"grid.{k}"
            if not values:
                raise InvalidInputError(key, [], "must list at least one value")
            if k == CELLS:
                grid[k] = _cells(exp, values, settings, [n for n in self.grid if n != CELLS])
                continue
            if k in settings:
                raise InvalidInputError(key, values, "is also in [settings]")
            try:
                param = exp.param(k)
                grid[k] = tuple(param.check(v) for v in values)
            except InvalidInputError as exc:
                raise _field(key, exc) from None
            if len(set(grid[k])) != len(grid[k]):
                raise InvalidInputError(key, list(values), "repeats a value")
        if not self.seeds:
            raise InvalidInputError("seeds", [], "must hold at least one seed")
        for s in self.seeds:
            try:
                check_seed(s)
            except InvalidInputError as exc:
                raise _field("seeds", exc) from None
        if len(set(self.seeds)) != len(self.seeds):
            raise InvalidInputError("seeds", list(self.seeds), "repeats a seed")
        for m in self.metrics:
            if m not in exp.metrics:
                raise InvalidInputError("metrics", m, f"not a metric of {exp.name!r} "
                                        f"(metrics: {list(exp.metrics)})")
        size = len(self.seeds)
        for values in grid.values():
            size *= len(values)
        if size > MAX_RUNS:
            raise InvalidInputError("grid", size, f"runs; at most {MAX_RUNS} per campaign")
        object.__setattr__(self, "settings", MappingProxyType(settings))
        object.__setattr__(self, "grid", MappingProxyType(grid))
        object.__setattr__(self, "metrics", tuple(self.metrics) or tuple(exp.metrics))

    @property
    def definition(self) -> Experiment:
        """The registered experiment."""
        return get(self.experiment)

    def runs(self) -> list[RunSpec]:
        """Every run, grid points (in file order, last key fastest) × seeds, with its key."""
        exp = self.definition
        names = list(self.grid)
        out = []
        for combo in itertools.product(*self.grid.values()):
            point: dict[str, Any] = {}
            for name, value in zip(names, combo, strict=True):
                point.update(value if name == CELLS else {name: value})
            params = exp.resolve({**self.settings, **point})
            for seed in self.seeds:
                out.append(RunSpec(run_key(exp.name, params, seed), exp.name, params, seed))
        return out


def _cells(exp: Experiment, values: Any, settings: Mapping[str, Any],
           others: Sequence[str]) -> tuple[Mapping[str, ParamValue], ...]:
    """``grid.cells``: tables of parameters that vary together, all with the same keys, none of
    them in ``[settings]`` or elsewhere in the grid, no table repeated."""
    if not isinstance(values, (list, tuple)) or not all(isinstance(v, Mapping) for v in values):
        raise InvalidInputError(f"grid.{CELLS}", values, "must be a list of tables of parameters")
    keys = set(values[0])
    cells = []
    for i, cell in enumerate(values):
        where = f"grid.{CELLS}[{i}]"
        if set(cell) != keys or not keys:
            raise InvalidInputError(where, dict(cell), f"must set the same parameters as the "
                                    f"first table ({sorted(keys)})")
        checked: dict[str, ParamValue] = {}
        for k, v in cell.items():
            if k in settings or k in others:
                raise InvalidInputError(f"{where}.{k}", v, "is also in [settings] or the grid")
            try:
                checked[k] = exp.param(k).check(v)
            except InvalidInputError as exc:
                raise _field(f"{where}.{k}", exc) from None
        cells.append(MappingProxyType(checked))
    if len({tuple(sorted(c.items())) for c in cells}) != len(cells):
        raise InvalidInputError(f"grid.{CELLS}", list(values), "repeats a table")
    return tuple(cells)


def _seeds(value: Any) -> tuple[int, ...]:
    if isinstance(value, list):
        return tuple(value)
    if isinstance(value, dict):
        extra = sorted(set(value) - {"count", "start"})
        if extra:
            raise InvalidInputError(f"seeds.{extra[0]}", value[extra[0]],
                                    "unknown key (seeds take count and start)")
        count, start = value.get("count"), value.get("start", 0)
        for name, v, low in (("count", count, 1), ("start", start, 0)):
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise InvalidInputError(f"seeds.{name}", v, f"must be an integer ≥ {low}")
        assert isinstance(count, int) and isinstance(start, int)
        if count > MAX_RUNS or start + count - 1 > MAX_SEED:
            raise InvalidInputError("seeds.count", count, f"seeds must stay in [0, {MAX_SEED}] "
                                    f"and number at most {MAX_RUNS}")
        return tuple(range(start, start + count))
    raise InvalidInputError("seeds", value, "must be a list of integers or {count, start}")


def _table(data: dict[str, Any], key: str) -> dict[str, Any]:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise InvalidInputError(key, value, "must be a table")
    return value


def from_toml(data: dict[str, Any]) -> CampaignSpec:
    """A campaign from a parsed TOML document.

    Raises
    ------
    InvalidInputError
        Naming the dotted key at fault.
    """
    for k in data:
        if k not in _TOP_KEYS:
            raise InvalidInputError(k, data[k], f"unknown key (keys: {list(_TOP_KEYS)})")
    for k in ("name", "experiment", "seeds"):
        if k not in data:
            raise InvalidInputError(k, None, "missing")
    if not isinstance(data["experiment"], str):
        raise InvalidInputError("experiment", data["experiment"], "must be a string")
    grid = _table(data, "grid")
    for k, v in grid.items():
        if not isinstance(v, list):
            raise InvalidInputError(f"grid.{k}", v, "must be a list of values")
    metrics = data.get("metrics", [])
    if not isinstance(metrics, list) or not all(isinstance(m, str) for m in metrics):
        raise InvalidInputError("metrics", metrics, "must be a list of metric names")
    return CampaignSpec(data["name"], data["experiment"], _table(data, "settings"),
                        {k: tuple(v) for k, v in grid.items()}, _seeds(data["seeds"]),
                        tuple(metrics))


def read_spec(path: str | Path) -> CampaignSpec:
    """Read and validate a campaign file.

    Raises
    ------
    ParseError
        Naming the file and the dotted key (or the line, for malformed TOML).
    """
    text = read_text(path, max_bytes=2**20)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParseError(path, getattr(exc, "lineno", None), None, f"not valid TOML: {exc}"
                         ) from None
    try:
        return from_toml(data)
    except InvalidInputError as exc:
        raise ParseError(path, None, exc.field, f"{exc.value!r}: {exc.reason}") from None
