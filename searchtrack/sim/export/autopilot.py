"""Missions an autopilot flies: QGroundControl ``.plan`` files and MAVLink waypoint lists.

A mission is a home position and a list of :class:`Waypoint` (latitude, longitude, altitude
above home; a waypoint with ``loiter_s > 0`` is a loiter there). It is written as

- a QGroundControl plan (JSON, the ground station's documented *Plan File Format*, version 1:
  ``fileType`` ``"Plan"``, a ``mission`` of ``SimpleItem`` s, empty geofence and rally points):
  a take-off (``MAV_CMD_NAV_TAKEOFF``, 22) over home, then ``MAV_CMD_NAV_WAYPOINT`` (16) or
  ``MAV_CMD_NAV_LOITER_TIME`` (19: seconds, loiter radius) items, then
  ``MAV_CMD_NAV_RETURN_TO_LAUNCH`` (20); every position item in the frame
  ``MAV_FRAME_GLOBAL_RELATIVE_ALT`` (3), altitudes relative to home;
- the plain-text mission format ``QGC WPL 110`` that QGroundControl, Mission Planner and
  pymavlink read: a header line, then one tab-separated line per item (index, current, frame,
  command, four parameters, latitude, longitude, altitude, autocontinue), item 0 the home
  position.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from searchtrack.core.errors import InvalidInputError

#: Decimal places of the written degrees (about 1 cm).
DEGREE_DECIMALS = 7
#: MAV_CMD numbers of the items written.
NAV_WAYPOINT, NAV_LOITER_TIME, NAV_RETURN_TO_LAUNCH, NAV_TAKEOFF = 16, 19, 20, 22
#: MAV_FRAME numbers: absolute (home) and relative to home.
FRAME_GLOBAL, FRAME_GLOBAL_RELATIVE_ALT = 0, 3
#: MAV_TYPE numbers of the vehicle types a plan names.
VEHICLE_TYPES = {"fixed_wing": 1, "quadrotor": 2}
#: MAV_AUTOPILOT numbers of the firmware a plan names.
FIRMWARE_TYPES = {"px4": 12, "ardupilot": 3}


@dataclass(frozen=True)
class Waypoint:
    """A mission position: latitude and longitude (degrees), altitude above home (m) and, when
    ``loiter_s > 0``, a loiter of that many seconds there."""

    lat_deg: float
    lon_deg: float
    altitude_m: float
    loiter_s: float = 0.0

    def __post_init__(self) -> None:
        for name, most in (("lat_deg", 90.0), ("lon_deg", 180.0)):
            value = getattr(self, name)
            if not (math.isfinite(value) and abs(value) <= most):
                raise InvalidInputError(name, value, f"must be finite, within ±{most:g}°")
        if not (math.isfinite(self.altitude_m) and self.altitude_m > 0):
            raise InvalidInputError("altitude_m", self.altitude_m, "must be finite and > 0")
        if not (math.isfinite(self.loiter_s) and self.loiter_s >= 0):
            raise InvalidInputError("loiter_s", self.loiter_s, "must be finite and ≥ 0")


@dataclass(frozen=True)
class Mission:
    """One vehicle's mission.

    Parameters
    ----------
    home
        Latitude and longitude (degrees) of the home (launch) position, at altitude 0.
    waypoints
        The positions in order (at least one).
    speed_mps
        Cruise speed (m/s).
    loiter_radius_m
        Radius of every loiter (m).
    vehicle, firmware
        A key of :data:`VEHICLE_TYPES` and of :data:`FIRMWARE_TYPES`.
    """

    home: tuple[float, float]
    waypoints: tuple[Waypoint, ...]
    speed_mps: float
    loiter_radius_m: float = 80.0
    vehicle: str = "fixed_wing"
    firmware: str = "px4"

    def __post_init__(self) -> None:
        if not self.waypoints or not all(isinstance(w, Waypoint) for w in self.waypoints):
            raise InvalidInputError("waypoints", self.waypoints, "must be one or more Waypoint")
        Waypoint(*self.home, 1.0)   # checks the home's coordinates
        for name in ("speed_mps", "loiter_radius_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise InvalidInputError(name, value, "must be finite and > 0")
        if self.vehicle not in VEHICLE_TYPES:
            raise InvalidInputError("vehicle", self.vehicle,
                                    f"must be one of {list(VEHICLE_TYPES)}")
        if self.firmware not in FIRMWARE_TYPES:
            raise InvalidInputError("firmware", self.firmware,
                                    f"must be one of {list(FIRMWARE_TYPES)}")

    def items(self) -> list[tuple[int, list[float]]]:
        """``(command, [param1..param4, lat, lon, alt])`` of every item after home."""
        first = self.waypoints[0]
        out = [(NAV_TAKEOFF, [0.0, 0.0, 0.0, math.nan, *self.home, first.altitude_m])]
        for w in self.waypoints:
            if w.loiter_s > 0:
                out.append((NAV_LOITER_TIME, [w.loiter_s, 0.0, self.loiter_radius_m, 0.0,
                                              w.lat_deg, w.lon_deg, w.altitude_m]))
            else:
                out.append((NAV_WAYPOINT, [0.0, 0.0, 0.0, math.nan, w.lat_deg, w.lon_deg,
                                           w.altitude_m]))
        out.append((NAV_RETURN_TO_LAUNCH, [0.0] * 7))
        return out


def qgc_plan(mission: Mission) -> dict[str, Any]:
    """The QGroundControl plan of ``mission`` (a JSON-ready dict; NaN parameters as null)."""
    items = []
    for k, (command, params) in enumerate(mission.items(), start=1):
        rtl = command == NAV_RETURN_TO_LAUNCH
        items.append({
            "AMSLAltAboveTerrain": None, "Altitude": 0 if rtl else params[6],
            "AltitudeMode": 1, "autoContinue": True, "command": command, "doJumpId": k,
            "frame": 2 if rtl else FRAME_GLOBAL_RELATIVE_ALT,
            "params": [None if math.isnan(p) else round(p, DEGREE_DECIMALS) for p in params],
            "type": "SimpleItem"})
    return {
        "fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
        "geoFence": {"circles": [], "polygons": [], "version": 2},
        "rallyPoints": {"points": [], "version": 2},
        "mission": {
            "version": 2, "firmwareType": FIRMWARE_TYPES[mission.firmware],
            "vehicleType": VEHICLE_TYPES[mission.vehicle], "globalPlanAltitudeMode": 1,
            "cruiseSpeed": mission.speed_mps, "hoverSpeed": mission.speed_mps,
            "plannedHomePosition": [round(mission.home[0], DEGREE_DECIMALS),
                                    round(mission.home[1], DEGREE_DECIMALS), 0.0],
            "items": items},
    }


def wpl_text(mission: Mission) -> str:
    """The ``QGC WPL 110`` text of ``mission`` (item 0 the home position)."""
    lines = ["QGC WPL 110", _wpl_line(0, 1, FRAME_GLOBAL, NAV_WAYPOINT,
                                      [0.0, 0.0, 0.0, 0.0, *mission.home, 0.0])]
    for k, (command, params) in enumerate(mission.items(), start=1):
        frame = FRAME_GLOBAL_RELATIVE_ALT if command != NAV_RETURN_TO_LAUNCH else 2
        lines.append(_wpl_line(k, 0, frame, command,
                               [0.0 if math.isnan(p) else p for p in params]))
    return "\n".join(lines) + "\n"


def _wpl_line(index: int, current: int, frame: int, command: int, params: Sequence[float]) -> str:
    return "\t".join([str(index), str(current), str(frame), str(command),
                      *(f"{p:.8f}" for p in params), "1"])
