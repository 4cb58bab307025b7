"""The experiments a campaign can run, and the registry that finds them.

An experiment is a pure function ``(params, seed) -> metrics`` with declared, typed parameters
and metrics (a metric also says whether it can be negative), and what a report shows beside its
numbers: the paper's claim (one, or one per value of a parameter such as the thesis's mission
mode), reference lines for its time series (a lower bound) and the time axis of those series.

Each domain declares its experiments in a module of its own, as a module-level tuple
``EXPERIMENTS`` of :class:`Experiment` (e.g. :mod:`searchtrack.sim.roads.experiment`,
:mod:`searchtrack.sim.particles.experiments`). The registry finds those modules itself: every
module under :data:`ROOT` whose name is ``experiment``, ``experiments`` or starts with
``experiment_`` (this module aside) is an experiment module. It looks for them on first use
(:func:`get`, or reading :data:`EXPERIMENTS`), so importing the campaign runner does not import
every domain; a Dask worker finds them when it takes its first run. A new experiment is therefore
one module (and a campaign TOML file naming it).

A parameter that sets a field of a domain's configuration takes its default from there
(:meth:`Param.of`), so the default is stated once.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import math
import pkgutil
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from searchtrack.core.errors import InvalidInputError

ParamValue = bool | int | float | str
"""A parameter value: what TOML gives and a DuckDB column holds."""

MetricKind = type[float] | type[int] | type[str]
"""The type of a metric's column."""

MetricValue = float | int | str | None
"""A metric value (``None``: not defined for this run, e.g. no target to count)."""

Params = Mapping[str, ParamValue]
Metrics = dict[str, MetricValue]

Reference = Callable[[Mapping[str, Any]], dict[str, float]]
"""Given a group's parameters, the reference lines to draw over its series (label → value)."""

#: Column names every run row has; parameters and metrics may not take them.
RESERVED = ("key", "experiment", "seed", "status", "runtime_s", "error", "host", "version",
            "started_utc", "ended_utc")

ROOT = "searchtrack.sim"
"""The package searched for experiment modules."""

DECLARED = "EXPERIMENTS"
"""The module-level name an experiment module declares its experiments by."""


def declared_default(source: Callable[..., object], name: str) -> ParamValue:
    """The default of the argument ``name`` of ``source``: a configuration dataclass's field or
    a function's keyword.

    Raises
    ------
    InvalidInputError
        ``source`` has no such argument, or its default is not a bool, int, float or string.
    """
    arg = inspect.signature(source).parameters.get(name)
    default = inspect.Parameter.empty if arg is None else arg.default
    if not isinstance(default, (bool, int, float, str)):
        raise InvalidInputError(name, default, f"{getattr(source, '__qualname__', source)} "
                                "gives it no bool, int, float or str default")
    return default


@dataclass(frozen=True)
class Param:
    """A parameter of an experiment: its name, type (``bool``, ``int``, ``float``, ``str``),
    default and, optionally, the values it may take or the least value of a number."""

    name: str
    kind: type[bool] | type[int] | type[float] | type[str]
    default: ParamValue
    choices: tuple[ParamValue, ...] = ()
    minimum: float | None = None

    @classmethod
    def of(cls, source: Callable[..., object], argument: str, *, name: str | None = None,
           choices: Sequence[ParamValue] = (), minimum: float | None = None) -> Param:
        """The parameter that sets ``source``'s ``argument`` (a dataclass field or a function
        keyword), named ``name`` (default: ``argument``), with that argument's default and the
        default's type."""
        default = declared_default(source, argument)
        return cls(name or argument, type(default), default, tuple(choices), minimum)

    def check(self, value: object) -> ParamValue:
        """``value`` as this parameter's type (an integer is accepted for a float).

        Raises
        ------
        InvalidInputError
            Naming the parameter: wrong type, not one of the choices, or below the minimum.
        """
        ok = isinstance(value, self.kind) and (self.kind is bool or not isinstance(value, bool))
        if self.kind is float and isinstance(value, int) and not isinstance(value, bool):
            value, ok = float(value), True
        if not ok:
            raise InvalidInputError(self.name, value, f"must be {self.kind.__name__}")
        if self.kind is float and not math.isfinite(float(value)):  # type: ignore[arg-type]
            raise InvalidInputError(self.name, value, "must be finite")
        if self.choices and value not in self.choices:
            raise InvalidInputError(self.name, value, f"must be one of {list(self.choices)}")
        if self.minimum is not None and value < self.minimum:  # type: ignore[operator]
            raise InvalidInputError(self.name, value, f"must be ≥ {self.minimum:g}")
        return value  # type: ignore[return-value]


@dataclass(frozen=True)
class Metric:
    """A metric of an experiment: the type of its values (``float``, ``int`` or ``str``) and
    whether they are never negative (a time, a distance, a fraction, a count), which a report's
    figure shows by drawing the confidence band from 0 up. Off by default: the band is then the
    plain mean ± half-width."""

    kind: MetricKind
    non_negative: bool = False

    def __post_init__(self) -> None:
        if self.kind not in (float, int, str):
            raise InvalidInputError("kind", self.kind, "must be float, int or str")
        if self.non_negative and self.kind is str:
            raise InvalidInputError("non_negative", self.non_negative, "only for a number")


@dataclass(frozen=True)
class ClaimsBy:
    """Claims that depend on the value of one parameter (the thesis's claims per mission mode):
    a report shows the claim of the value all its runs share, none when they mix values."""

    param: str
    claims: Mapping[ParamValue, str]


@dataclass(frozen=True)
class TimeAxis:
    """The time axis of an experiment's series: sample ``i`` is at ``(i + 1)·step``."""

    step: float = 1.0
    label: str = "sample"


@dataclass(frozen=True)
class Experiment:
    """A registered experiment.

    Parameters
    ----------
    name
        Its name in campaign files.
    params
        Its parameters, in column order.
    metrics
        Metric name -> :class:`Metric` (type, never negative or not) of the row a run returns.
    run
        ``(params, seed) -> metrics``; ``params`` has every parameter, checked.
    description
        One line on what a run computes.
    claim
        What the paper claims, printed beside the measured table: one text, or one per value of
        a parameter (:class:`ClaimsBy`); empty when the experiment reproduces no claim.
    references
        Reference lines of its series (e.g. a lower bound), given a group's parameters.
    time_axis
        Sample spacing and axis label of its series.
    """

    name: str
    params: tuple[Param, ...]
    metrics: Mapping[str, Metric]
    run: Callable[[Params, int], Metrics]
    description: str = ""
    claim: str | ClaimsBy = ""
    references: Reference | None = None
    time_axis: TimeAxis = field(default_factory=TimeAxis)

    def __post_init__(self) -> None:
        names = [p.name for p in self.params] + list(self.metrics)
        clash = sorted({n for n in names if n in RESERVED or names.count(n) > 1})
        if clash:
            raise InvalidInputError("params", clash, "reserved or repeated column names")
        for p in self.params:
            p.check(p.default)
        for name, metric in self.metrics.items():
            if not isinstance(metric, Metric):
                raise InvalidInputError(name, metric, "declare a metric as a Metric")
        if isinstance(self.claim, ClaimsBy):
            by = self.param(self.claim.param)
            for value in self.claim.claims:
                by.check(value)

    def param(self, name: str) -> Param:
        """The parameter ``name``.

        Raises
        ------
        InvalidInputError
            Unknown name, listing the known ones.
        """
        for p in self.params:
            if p.name == name:
                return p
        raise InvalidInputError(name, name, f"not a parameter of {self.name!r} "
                                f"(parameters: {[p.name for p in self.params]})")

    def resolve(self, given: Mapping[str, object]) -> dict[str, ParamValue]:
        """Every parameter: ``given`` (checked) over the defaults."""
        for name in given:
            self.param(name)
        return {p.name: p.check(given[p.name]) if p.name in given else p.default
                for p in self.params}

    def claims(self) -> tuple[str, ...]:
        """Every claim text the experiment states."""
        if isinstance(self.claim, ClaimsBy):
            return tuple(self.claim.claims.values())
        return (self.claim,) if self.claim else ()

    def claim_for(self, rows: Sequence[Mapping[str, Any]]) -> str | None:
        """The claim to print beside ``rows``: the experiment's, or, when it depends on a
        parameter, that of the value every row shares (``None`` when there is none)."""
        if not isinstance(self.claim, ClaimsBy):
            return self.claim or None
        values = {row.get(self.claim.param) for row in rows}
        if len(values) != 1:
            return None
        value = values.pop()
        return next((text for key, text in self.claim.claims.items() if key == value), None)

    def non_negative(self, name: str) -> bool:
        """Whether the metric ``name`` is declared never negative (an undeclared name: no)."""
        metric = self.metrics.get(name)
        return metric is not None and metric.non_negative

    def reference_lines(self, params: Mapping[str, Any]) -> dict[str, float]:
        """The reference lines (label → value) of a group with ``params``."""
        return {} if self.references is None else self.references(params)


def is_experiment_module(name: str) -> bool:
    """Whether the dotted module ``name`` is named like an experiment module."""
    last = name.rpartition(".")[2]
    return last in ("experiment", "experiments") or last.startswith("experiment_")


def experiment_modules(root: str) -> list[str]:
    """The dotted names of the experiment modules under the package ``root``, sorted; only the
    packages on the way are imported, not the other modules."""
    package = importlib.import_module(root)
    found: list[str] = []
    todo = [(root, list(getattr(package, "__path__", ())))]
    while todo:
        prefix, paths = todo.pop()
        for info in pkgutil.iter_modules(paths, prefix + "."):
            if is_experiment_module(info.name) and info.name != __name__:
                found.append(info.name)
            if info.ispkg:
                spec = importlib.util.find_spec(info.name)
                if spec is not None and spec.submodule_search_locations is not None:
                    todo.append((info.name, list(spec.submodule_search_locations)))
    return sorted(found)


def discover(roots: Sequence[str]) -> dict[str, Experiment]:
    """Every experiment the experiment modules under ``roots`` declare, by name: module by
    module (sorted), in each module's order.

    Raises
    ------
    InvalidInputError
        An experiment module without its tuple ``EXPERIMENTS`` of :class:`Experiment`, or two
        experiments of one name.
    """
    found: dict[str, Experiment] = {}
    home: dict[str, str] = {}
    for module_name in [m for root in roots for m in experiment_modules(root)]:
        declared = getattr(importlib.import_module(module_name), DECLARED, None)
        if not isinstance(declared, (tuple, list)) or not all(
                isinstance(e, Experiment) for e in declared):
            raise InvalidInputError(f"{module_name}.{DECLARED}", declared,
                                    "an experiment module declares a tuple of Experiment")
        for experiment in declared:
            if experiment.name in found:
                raise InvalidInputError("experiment", experiment.name, "declared twice: in "
                                        f"{home[experiment.name]} and {module_name}")
            found[experiment.name], home[experiment.name] = experiment, module_name
    return found


class ExperimentRegistry(Mapping[str, Experiment]):
    """Every experiment of the experiment modules under ``roots``, by name, found on first use.

    Parameters
    ----------
    roots
        Dotted names of the packages searched (default: :data:`ROOT`).
    """

    def __init__(self, roots: Sequence[str] = (ROOT,)) -> None:
        self.roots = tuple(roots)
        self._found: dict[str, Experiment] | None = None

    def _experiments(self) -> dict[str, Experiment]:
        if self._found is None:
            self._found = discover(self.roots)
        return self._found

    def __getitem__(self, name: str) -> Experiment:
        return self._experiments()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._experiments())

    def __len__(self) -> int:
        return len(self._experiments())


EXPERIMENTS: Mapping[str, Experiment] = ExperimentRegistry()
"""Every registered experiment by name (the experiment modules are imported on first use)."""


def get(name: str) -> Experiment:
    """The experiment ``name``.

    Raises
    ------
    InvalidInputError
        Unknown name, listing the registered ones.
    """
    if name not in EXPERIMENTS:
        raise InvalidInputError("experiment", name, f"must be one of {sorted(EXPERIMENTS)}")
    return EXPERIMENTS[name]
