"""Radio mission figures: the map and the OSPA plot are written as PNG files."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from searchtrack.models.radio import RadioScenario
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.sim.radio.figures import plot_radio_map, plot_radio_ospa
from searchtrack.sim.radio.mission import RadioMissionConfig, run_radio_mission


def test_figures_are_pngs(tmp_path: Path) -> None:
    scenario = dataclasses.replace(RadioScenario.paper(), duration_s=10.0)
    config = RadioMissionConfig(planner="straight", particles_per_label=60,
                                plan=RadioPlanSettings(plan_particles=10))
    log = run_radio_mission(scenario, config, 0)
    for plot, name in ((plot_radio_map, "map.png"), (plot_radio_ospa, "ospa.png")):
        path = plot(log, tmp_path / "figs" / name)
        data = path.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == ["map.png", "ospa.png"]
