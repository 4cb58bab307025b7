"""What missions and OPTW plans export: one autopilot mission per vehicle and a GeoJSON of the
whole, read back with the real parsers."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from searchtrack.plan.optw import OPTWInstance
from searchtrack.sim.export.autopilot import NAV_LOITER_TIME, NAV_WAYPOINT
from searchtrack.sim.export.geo import GeoFrame
from searchtrack.sim.export.plans import (
    LOITER_CHUNK_S,
    flown_waypoints,
    optw_files,
    road_mission_files,
)
from tests.sim.roads.mission_logs import two_step_log

FRAME = GeoFrame.at(21.88, -102.29, 100.0)


def test_flown_path_becomes_waypoints_and_loiters() -> None:
    """30 s of flight sampled at 1 s, then 70 s of loitering, then 5 s of flight: waypoints
    every 10 s and the stretch's end, loiters of at most LOITER_CHUNK_S at the mean position."""
    xy = np.zeros((106, 2))
    xy[:31, 0] = np.arange(31) * 20.0
    xy[31:101] = [600.0, 0.0] + 50.0 * np.column_stack([np.cos(np.arange(70) / 5),
                                                        np.sin(np.arange(70) / 5)])
    xy[101:, 0] = 600.0 + np.arange(1, 6) * 20.0
    loitering = [False] * 31 + [True] * 70 + [False] * 5
    points = flown_waypoints(xy, loitering, 1.0, FRAME, spacing_s=10.0)
    loiters = [p for p in points if p.loiter_s > 0]
    assert [p.loiter_s for p in loiters] == [30.0, 30.0, 10.0]
    assert max(p.loiter_s for p in loiters) <= LOITER_CHUNK_S
    flown = [p for p in points if p.loiter_s == 0]
    assert len(flown) == 3 + 1 + 1 + 1        # k = 1, 11, 21 and 30; 101 and 105
    centre = FRAME.degrees([[600.0, 0.0]])[0]
    assert all(abs(p.lat_deg - centre[0]) < 1e-3 and abs(p.lon_deg - centre[1]) < 1e-3
               for p in loiters)
    assert all(p.altitude_m == 100.0 for p in points)


def test_road_mission_files_read_back(tmp_path: Path) -> None:
    """A mission exports one .plan and one .waypoints per UAV and a valid GeoJSON with the
    roads, the UAV and target paths and the trackers' peaks."""
    mavwp = pytest.importorskip("pymavlink.mavwp", reason="pymavlink (the test extra)")
    geojson = pytest.importorskip("geojson", reason="the geojson library (the test extra)")
    log = two_step_log()
    files = road_mission_files(log, FRAME, speed_mps=30.0)
    uavs = log.uav_xy_m.shape[1]
    assert set(files) == {"plan.geojson", "plan.html"} | {f"uav{j}.{s}" for j in range(uavs)
                                              for s in ("plan", "waypoints")}
    for name, text in files.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    loader = mavwp.MAVWPLoader()
    assert loader.load(str(tmp_path / "uav0.waypoints")) >= 4
    home = FRAME.degrees(log.uav_xy_m[0, 0])[0]
    assert (loader.wp(0).x, loader.wp(0).y) == pytest.approx(tuple(home))
    plan = json.loads(files["uav0.plan"])
    assert plan["mission"]["plannedHomePosition"][:2] == pytest.approx(list(home))
    collection = geojson.loads(files["plan.geojson"])
    assert collection.is_valid, collection.errors()
    kinds = [f["properties"]["kind"] for f in collection["features"]]
    assert kinds.count("road") == 1 and kinds.count("uav") == uavs
    assert kinds.count("target") == log.target_xy_m.shape[1] and "estimate" in kinds


def test_optw_files_visit_the_routes_customers(tmp_path: Path) -> None:
    """Each route's customers in order (a service time as a loiter of its flying time), the
    customers and routes in the GeoJSON; an empty route exports nothing."""
    mavwp = pytest.importorskip("pymavlink.mavwp", reason="pymavlink (the test extra)")
    geojson = pytest.importorskip("geojson", reason="the geojson library (the test extra)")
    coords = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]])
    inst = OPTWInstance.from_coordinates(coords, np.array([0.0, 5.0, 7.0, 3.0]),
                                         np.array([0.0, 10.0, 0.0, 0.0]), np.zeros(4),
                                         np.full(4, 1000.0), vehicles=3)
    routes = [[0, 1, 2, 0], [0, 3, 0], [0, 0]]
    files = optw_files(inst, routes, GeoFrame.at(21.88, -102.29, 80.0, unit_m=2.0),
                       speed_mps=10.0)
    assert set(files) == {"route0.plan", "route0.waypoints", "route1.plan",
                          "route1.waypoints", "plan.geojson", "plan.html"}
    (tmp_path / "r.waypoints").write_text(files["route0.waypoints"], encoding="utf-8")
    loader = mavwp.MAVWPLoader()
    loader.load(str(tmp_path / "r.waypoints"))
    visits = [loader.wp(k) for k in (2, 3)]
    assert [w.command for w in visits] == [NAV_LOITER_TIME, NAV_WAYPOINT]
    assert visits[0].param1 == pytest.approx(10.0 * 2.0 / 10.0)
    expected = GeoFrame.at(21.88, -102.29, 80.0, unit_m=2.0).degrees(coords[[1, 2]])
    assert [(w.x, w.y) for w in visits] == [pytest.approx(tuple(p)) for p in expected]
    collection = geojson.loads(files["plan.geojson"])
    assert collection.is_valid
    customers = [f for f in collection["features"] if f["properties"]["kind"] == "customer"]
    assert [f["properties"]["visited"] for f in customers] == [True, True, True]


def test_planned_paths_are_thinned_and_keep_their_altitudes() -> None:
    """A 500-point path exports at most MAX_PATH_WAYPOINTS waypoints, its last point kept;
    planned altitudes above 0 are kept, others fly at the frame's."""
    from searchtrack.sim.export.plans import MAX_PATH_WAYPOINTS, VehiclePaths, path_files

    long = np.column_stack([np.arange(500.0), np.zeros(500), np.full(500, 40.0)])
    flat = np.array([[0.0, 0.0, 0.0], [50.0, 0.0, 0.0]])
    files = path_files(VehiclePaths((long, flat, np.zeros((1, 2)))), FRAME, speed_mps=12.0)
    plans = [json.loads(files[f"uav{k}.plan"])["mission"] for k in range(3)]
    items = plans[0]["items"][1:-1]               # after take-off, before return
    assert len(items) == MAX_PATH_WAYPOINTS
    last = FRAME.degrees(long[-1, :2])[0]
    assert items[-1]["params"][4:6] == pytest.approx(list(last))
    assert all(i["Altitude"] == 40.0 for i in items)
    assert [i["Altitude"] for i in plans[1]["items"][1:-1]] == [100.0]
    assert len(plans[2]["items"]) == 3 and plans[0]["cruiseSpeed"] == 12.0
