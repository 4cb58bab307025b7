"""The plan families: every module of searchtrack.sim.jobs is a PlanJob, found by name."""

from __future__ import annotations

import sys
import types
from pathlib import Path

import pytest

from searchtrack.sim import jobs
from searchtrack.sim.jobs import PlanJob, assign, associate, route, search, trajectory

# Assigning each module to the protocol type is the static check (mypy) of its interface.
ASSIGN: PlanJob = assign
ASSOCIATE: PlanJob = associate
ROUTE: PlanJob = route
SEARCH: PlanJob = search
TRAJECTORY: PlanJob = trajectory
MODULES = (ASSIGN, ASSOCIATE, ROUTE, SEARCH, TRAJECTORY)


def test_families_are_the_modules() -> None:
    """The family names are the package's modules; each loads as itself."""
    assert jobs.families() == ["assign", "associate", "route", "search", "trajectory"]
    for name, module in zip(jobs.families(), MODULES, strict=True):
        assert jobs.load(name) is module
        assert isinstance(module, PlanJob)
        assert module.backends()[0] == "auto"
        assert set(module.backends()) == set(module.BACKENDS.names()) | {"auto"}
        assert isinstance(module.KERNELS, tuple) and module.DESCRIPTION


def test_unknown_family_is_refused() -> None:
    with pytest.raises(KeyError):
        jobs.load("teleport")


def test_a_module_without_the_interface_is_refused(monkeypatch: pytest.MonkeyPatch,
                                                   tmp_path: Path) -> None:
    """A module in the package that lacks part of the interface is named with what it lacks."""
    half = types.ModuleType("searchtrack.sim.jobs.half")
    half.DESCRIPTION = "half a family"  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "searchtrack.sim.jobs.half", half)
    monkeypatch.setattr(jobs, "families", lambda: ["half"])
    with pytest.raises(TypeError, match=r"lacks.*BACKENDS"):
        jobs.load("half")


def test_geo_projection_is_optional() -> None:
    """Only a family whose problems can carry a map frame defines ``geo_projection``; the
    helper asks it, and gives ``None`` for a family without one."""
    from searchtrack.models.projection import LocalProjection

    assert [m for m in (assign, associate, route, search, trajectory)
            if hasattr(m, "geo_projection")] == [route]
    assert jobs.geo_projection(SEARCH, object()) is None
    frame = LocalProjection(0.5, 0.1)
    mapped = types.SimpleNamespace(geo_projection=lambda problem: problem)
    assert jobs.geo_projection(mapped, frame) is frame  # type: ignore[arg-type]
