"""The campaign files shipped in ``searchtrack/data/campaigns``: each parses, names only
registered parameters and metrics, says what it reproduces, and runs the benchmark's seeds."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import pytest

from searchtrack.sim.campaigns.spec import CELLS, read_spec

FOLDER = Path(str(resources.files("searchtrack") / "data" / "campaigns"))
SHIPPED = sorted(p.name for p in FOLDER.glob("*.toml"))

#: File -> (experiment, number of runs): the benchmark scripts' grids and seeds.
EXPECTED = {
    "thesis_exp1.toml": ("mission", 3 * 4 * 25),
    "thesis_exp2.toml": ("mission", 2 * 4 * 3 * 10),
    "thesis_exp2_changes.toml": ("mission", 2 * 5 * 4 * 2 * 10),
    "thesis_exp2_search.toml": ("mission", 2 * 4 * 5 * 10),
    "phd_standard.toml": ("phd_tracking_scenario", 3),
    "p003_tracking.toml": ("phd_tracking_episode", 3 * 2 * 3 * 3),
    "p004_search.toml": ("phd_search_episode", 3 * 10),
    "p004_horizon.toml": ("phd_search_episode", 3 * 10),
    "p004_search_mi.toml": ("phd_search_episode", 2 * 10),
    "p004_search_fov.toml": ("phd_search_episode", 2 * 10),
    "p000_planners.toml": ("road_tracking_episode", 4 * 1000),
    "p000_osm.toml": ("road_tracking_episode", 6 * 100),
    "p000_osm_city.toml": ("road_tracking_episode", 4 * 20),
    "p002_exp2.toml": ("radio_tracking_episode", 9 * 2 * 3 * 20),
    "p002_safety.toml": ("radio_tracking_episode", 6 * 20),
    "p002_safety_paper.toml": ("radio_tracking_episode", 4 * 40),
    "p002_exp1.toml": ("radio_tracking_episode", 2 * 20),
    "p002_calibration.toml": ("radio_tracking_episode", 7 * 6),
    "p002_time_domain.toml": ("radio_tracking_episode", 2 * 10),
    "quick_start.toml": ("mission", 2 * 8),
}


def test_every_expected_file_is_shipped() -> None:
    """The folder holds exactly the expected campaign files."""
    assert set(SHIPPED) == set(EXPECTED)


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_file_parses(name: str) -> None:
    """Each file parses with ``read_spec`` (so it names only registered parameters, values of
    their types and registered metrics), expands to the expected runs and opens with a comment
    header saying what it reproduces and the claim."""
    path = FOLDER / name
    spec = read_spec(path)
    experiment, runs = EXPECTED[name]
    assert spec.experiment == experiment
    known = {p.name for p in spec.definition.params}
    varied = {k for k in spec.grid if k != CELLS}
    varied |= {k for cell in spec.grid.get(CELLS, ()) for k in cell}
    assert set(spec.settings) | varied <= known
    assert set(spec.metrics) <= set(spec.definition.metrics)
    assert len(spec.runs()) == runs
    first = spec.seeds[0]   # 0, or a later block kept apart from the evaluation's seeds
    assert list(spec.seeds) == list(range(first, first + len(spec.seeds)))
    assert first == 0 or "seeds" in path.read_text(encoding="utf-8").split("\nname = ")[0]
    header = path.read_text(encoding="utf-8").split("\nname = ")[0]
    assert header.startswith("# ") and "Reproduces" in header


def test_campaign_names_are_distinct() -> None:
    """Each shipped campaign has its own name (a results database holds one campaign)."""
    names = [read_spec(FOLDER / n).name for n in SHIPPED]
    assert len(set(names)) == len(names)
