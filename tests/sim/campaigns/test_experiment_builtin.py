"""The campaign package's own experiments: ``toy`` and ``optw_instance``."""

from __future__ import annotations

import math

import pytest

from searchtrack.plan.optw import BACKENDS as OPTW_BACKENDS
from searchtrack.sim.campaigns.experiment_builtin import (
    EXPERIMENTS,
    OPTW_INSTANCES,
    optw_run,
    toy_run,
)
from searchtrack.sim.campaigns.experiments import get


def _run(name: str, params: dict[str, object], seed: int = 1) -> dict[str, object]:
    exp = get(name)
    metrics = exp.run(exp.resolve(params), seed)
    assert set(metrics) == set(exp.metrics)
    return dict(metrics)


def test_declares_toy_and_optw_instance() -> None:
    """Both are registered as declared here, with their run functions."""
    assert [e.name for e in EXPERIMENTS] == ["toy", "optw_instance"]
    assert all(get(e.name) is e for e in EXPERIMENTS)
    assert (get("toy").run, get("optw_instance").run) == (toy_run, optw_run)
    optw = get("optw_instance")
    assert optw.param("instance").choices == OPTW_INSTANCES
    assert optw.param("backend").choices == tuple(OPTW_BACKENDS.names())


def test_toy_returns_its_value_or_raises() -> None:
    """The toy run returns its value, or raises when asked to fail."""
    assert _run("toy", {"value": 3.5}, seed=4) == {"result": 3.5, "seed_echo": 4}
    with pytest.raises(RuntimeError, match="on purpose"):
        get("toy").run(get("toy").resolve({"fail": True}), 0)


def test_optw_instance_reports_the_solve() -> None:
    """An OPTW run reports objective, status and solve time."""
    metrics = _run("optw_instance", {"instance": "c101", "backend": "ils",
                                     "time_limit_s": 0.1})
    assert float(metrics["objective"]) > 0  # type: ignore[arg-type]
    assert metrics["solve_status"] in ("FEASIBLE", "OPTIMAL")
    assert math.isfinite(float(metrics["solve_s"]))  # type: ignore[arg-type]
