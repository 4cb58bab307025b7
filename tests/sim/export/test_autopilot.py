"""Autopilot missions: a QGroundControl plan that follows the documented Plan File Format, and
a QGC WPL 110 list that pymavlink's waypoint loader reads back item by item."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.export.autopilot import (
    NAV_LOITER_TIME,
    NAV_RETURN_TO_LAUNCH,
    NAV_TAKEOFF,
    NAV_WAYPOINT,
    Mission,
    Waypoint,
    qgc_plan,
    wpl_text,
)

HOME = (21.88, -102.29)
MISSION = Mission(HOME, (Waypoint(21.881, -102.291, 100.0),
                         Waypoint(21.882, -102.289, 100.0, loiter_s=45.0),
                         Waypoint(21.8805, -102.2885, 110.0)), speed_mps=20.0,
                  loiter_radius_m=60.0)


def test_plan_follows_the_documented_format() -> None:
    """Top level, mission object and SimpleItem keys of QGroundControl's Plan File Format;
    take-off, waypoint, loiter and return-to-launch commands with their parameters."""
    plan = qgc_plan(MISSION)
    assert plan["fileType"] == "Plan" and plan["version"] == 1
    assert {"geoFence", "rallyPoints", "groundStation", "mission"} <= set(plan)
    mission = plan["mission"]
    assert mission["version"] == 2 and mission["plannedHomePosition"] == [*HOME, 0.0]
    assert {"cruiseSpeed", "hoverSpeed", "firmwareType", "vehicleType", "items"} <= set(mission)
    items = mission["items"]
    keys = {"AMSLAltAboveTerrain", "Altitude", "AltitudeMode", "autoContinue", "command",
            "doJumpId", "frame", "params", "type"}
    assert all(set(i) == keys and i["type"] == "SimpleItem" and len(i["params"]) == 7
               for i in items)
    assert [i["doJumpId"] for i in items] == list(range(1, len(items) + 1))
    assert [i["command"] for i in items] == [NAV_TAKEOFF, NAV_WAYPOINT, NAV_LOITER_TIME,
                                             NAV_WAYPOINT, NAV_RETURN_TO_LAUNCH]
    loiter = items[2]["params"]
    assert loiter[0] == 45.0 and loiter[2] == 60.0 and loiter[4:] == [21.882, -102.289, 100.0]
    assert all(i["frame"] == 3 for i in items[:-1])   # relative to home
    assert items[3]["params"][4:] == [21.8805, -102.2885, 110.0]


def test_waypoint_list_reads_back_with_pymavlink(tmp_path: Path) -> None:
    """pymavlink's loader reads every item: commands, frames, coordinates and loiter time."""
    mavwp = pytest.importorskip("pymavlink.mavwp", reason="pymavlink (the test extra)")
    path = tmp_path / "m.waypoints"
    path.write_text(wpl_text(MISSION), encoding="utf-8")
    loader = mavwp.MAVWPLoader()
    assert loader.load(str(path)) == 6
    items = [loader.wp(k) for k in range(loader.count())]
    assert [w.command for w in items] == [NAV_WAYPOINT, NAV_TAKEOFF, NAV_WAYPOINT,
                                          NAV_LOITER_TIME, NAV_WAYPOINT, NAV_RETURN_TO_LAUNCH]
    assert (items[0].x, items[0].y, items[0].z) == pytest.approx((*HOME, 0.0))
    assert (items[3].x, items[3].y, items[3].z) == pytest.approx((21.882, -102.289, 100.0))
    assert items[3].param1 == 45.0 and items[3].param3 == 60.0
    assert [w.frame for w in items[1:5]] == [3, 3, 3, 3]
    assert all(w.autocontinue == 1 for w in items) and items[0].current == 1


@pytest.mark.parametrize(("build", "field"), [
    (lambda: Waypoint(91.0, 0.0, 10.0), "lat_deg"),
    (lambda: Waypoint(0.0, math.nan, 10.0), "lon_deg"),
    (lambda: Waypoint(0.0, 0.0, 0.0), "altitude_m"),
    (lambda: Waypoint(0.0, 0.0, 10.0, -1.0), "loiter_s"),
    (lambda: Mission(HOME, (), 10.0), "waypoints"),
    (lambda: Mission(HOME, MISSION.waypoints, 0.0), "speed_mps"),
    (lambda: Mission(HOME, MISSION.waypoints, 10.0, vehicle="blimp"), "vehicle"),
    (lambda: Mission(HOME, MISSION.waypoints, 10.0, firmware="x"), "firmware"),
])
def test_bad_missions_are_refused_by_field(build: object, field: str) -> None:
    with pytest.raises(InvalidInputError, match=field):
        build()  # type: ignore[operator]
