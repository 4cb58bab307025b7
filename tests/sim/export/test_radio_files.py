"""A radio mission exports the UAV's flown path as one autopilot mission and a GeoJSON of the
UAV, the tags and the estimates."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from searchtrack.models.radio.scenario import RadioScenario
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.sim.export.geo import GeoFrame
from searchtrack.sim.export.radio_files import radio_mission_files
from searchtrack.sim.radio.mission import RadioMissionConfig, run_radio_mission


def test_radio_mission_files_read_back(tmp_path: Path) -> None:
    mavwp = pytest.importorskip("pymavlink.mavwp", reason="pymavlink (the test extra)")
    geojson = pytest.importorskip("geojson", reason="the geojson library (the test extra)")
    scenario = dataclasses.replace(RadioScenario.paper(noise_var_v2=0.015**2), duration_s=25.0)
    config = RadioMissionConfig(particles_per_label=100,
                                plan=RadioPlanSettings(horizon=1, plan_particles=30))
    log = run_radio_mission(scenario, config, 3)
    frame = GeoFrame.at(-35.0, 149.0, 100.0)
    files = radio_mission_files(log, frame)
    assert set(files) == {"uav0.plan", "uav0.waypoints", "plan.geojson", "plan.html"}
    (tmp_path / "uav0.waypoints").write_text(files["uav0.waypoints"], encoding="utf-8")
    loader = mavwp.MAVWPLoader()
    n = loader.load(str(tmp_path / "uav0.waypoints"))
    assert n >= 1 + 1 + 3 + 1           # home, take-off, a waypoint per 10 s, RTL
    home = frame.degrees(log.poses[0, :2])[0]
    assert (loader.wp(0).x, loader.wp(0).y) == pytest.approx(tuple(home))
    last = frame.degrees(log.poses[-1, :2])[0]
    assert (loader.wp(n - 2).x, loader.wp(n - 2).y) == pytest.approx(tuple(last))
    collection = geojson.loads(files["plan.geojson"])
    assert collection.is_valid, collection.errors()
    kinds = {f["properties"]["kind"] for f in collection["features"]}
    assert {"uav", "target"} <= kinds
    assert json.loads(files["uav0.plan"])["mission"]["cruiseSpeed"] == scenario.uav.speed_mps
