"""What a road mission and an OPTW plan export: one autopilot mission per vehicle (a
QGroundControl ``.plan`` and a ``QGC WPL 110`` list, :mod:`~searchtrack.sim.export.autopilot`)
and one GeoJSON of the whole (:mod:`~searchtrack.sim.export.geojson`).

- A road mission (:class:`~searchtrack.sim.roads.record.MissionLog`) exports each UAV's flown
  path: a waypoint every ``spacing_s`` seconds of flight, and its loitering (mode ``loiter``)
  as loiter items of at most :data:`LOITER_CHUNK_S` each at the mean position of that stretch;
  home is where the UAV started. The GeoJSON holds the roads, each UAV's and target's path and
  each tracker's peak path.
- An OPTW plan exports each route: its customers as waypoints, a customer with a service time
  as a loiter of that long (a time unit is the time to fly one coordinate unit, ``unit_m``
  metres, at ``speed_mps``); home is the start depot. The GeoJSON holds the customers (with
  their scores and windows, visited or not) and the routes.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.plan.optw.instance import OPTWInstance
from searchtrack.sim.export import geojson
from searchtrack.sim.export.autopilot import Mission, Waypoint, qgc_plan, wpl_text
from searchtrack.sim.export.geo import GeoFrame
from searchtrack.sim.export.map_page import map_page
from searchtrack.sim.roads.record import MissionLog

#: Longest loiter item (s): a loiter over a moving target is re-centred this often.
LOITER_CHUNK_S = 30.0
#: Most waypoints a planned path exports (a longer one is thinned evenly, its ends kept).
MAX_PATH_WAYPOINTS = 100


@dataclass(frozen=True)
class VehiclePaths:
    """What a ``plan`` family's answer flies, for export.

    Parameters
    ----------
    paths
        Per vehicle, ``(n, 2)`` planar positions (m) from its start, or ``(n, 3)`` with each
        position's altitude (m) as the third column.
    """

    paths: tuple[FloatArray, ...] = ()


def path_files(plan: VehiclePaths, frame: GeoFrame, speed_mps: float) -> dict[str, str]:
    """The files of planned paths: one mission per vehicle from its first position (home) through
    the others (at most :data:`MAX_PATH_WAYPOINTS`; each at its planned altitude when the path
    has one above 0, else the frame's), and a GeoJSON of the paths."""
    missions, features = [], []
    for k, path in enumerate(plan.paths):
        points = np.asarray(path, dtype=np.float64)
        where = frame.degrees(points[:, :2])
        if len(points) > 1:   # after home, evenly thinned, the last position kept
            count = min(MAX_PATH_WAYPOINTS, len(points) - 1)
            keep = np.unique(np.round(np.linspace(1, len(points) - 1, count)).astype(np.int64))
        else:                 # a vehicle that stays: one waypoint over home
            keep = np.zeros(1, dtype=np.int64)
        height = np.full(len(points), frame.altitude_m)
        if points.shape[1] > 2:   # a planned altitude; at or below the ground: the frame's
            height = np.where(points[:, 2] > 0, points[:, 2], frame.altitude_m)
        missions.append(Mission((float(where[0, 0]), float(where[0, 1])), tuple(
            Waypoint(float(where[i, 0]), float(where[i, 1]), float(height[i]))
            for i in keep), speed_mps))
        features.append(geojson.path(where, {"kind": "route", "vehicle": k}))
    return mission_files(missions, geojson.collection(features))


def mission_files(missions: Sequence[Mission], collection: dict[str, object],
                  stem: str = "uav") -> dict[str, str]:
    """File name → text: ``{stem}{k}.plan`` and ``{stem}{k}.waypoints`` per mission,
    ``plan.geojson`` and ``plan.html``, its offline map page
    (:mod:`~searchtrack.sim.export.map_page`)."""
    files: dict[str, str] = {}
    for k, mission in enumerate(missions):
        files[f"{stem}{k}.plan"] = json.dumps(qgc_plan(mission), indent=1) + "\n"
        files[f"{stem}{k}.waypoints"] = wpl_text(mission)
    files["plan.geojson"] = json.dumps(collection) + "\n"
    files["plan.html"] = map_page(collection, f"{len(missions)} vehicle(s): plan.geojson")
    return files


def flown_waypoints(xy: FloatArray, loitering: Sequence[bool], dt_s: float, frame: GeoFrame,
                    spacing_s: float = 10.0) -> tuple[Waypoint, ...]:
    """The waypoints of one flown path ``(T, 2)`` sampled every ``dt_s``: every ``spacing_s``
    of flight and each stretch's end; loitering stretches as loiters (module docstring)."""
    if not spacing_s > 0:
        raise InvalidInputError("spacing_s", spacing_s, "must be > 0")
    every = max(1, round(spacing_s / dt_s))
    chunk = max(1, round(LOITER_CHUNK_S / dt_s))
    points: list[tuple[FloatArray, float]] = []
    k, n = 1, len(xy)
    while k < n:
        end = k
        while end < n and loitering[end] == loitering[k]:
            end += 1
        if loitering[k]:
            for a in range(k, end, chunk):
                b = min(end, a + chunk)
                points.append((xy[a:b].mean(axis=0), (b - a) * dt_s))
        else:
            points += [(xy[i], 0.0) for i in range(k, end, every)]
            if (end - 1 - k) % every:
                points.append((xy[end - 1], 0.0))
        k = end
    if not points:
        points = [(xy[-1], 0.0)]
    latlon = frame.degrees(np.array([p for p, _ in points]))
    return tuple(Waypoint(float(a), float(b), frame.altitude_m, float(s))
                 for (a, b), (_, s) in zip(latlon, points, strict=True))


def road_mission_files(log: MissionLog, frame: GeoFrame, speed_mps: float,
                       spacing_s: float = 10.0) -> dict[str, str]:
    """The files of a road mission (module docstring)."""
    missions = []
    for j in range(log.uav_xy_m.shape[1]):
        path = log.uav_xy_m[:, j]   # the start, then one position per step (and mode)
        loitering = [False, *(modes[j] == "loiter" for modes in log.modes)]
        home = frame.degrees(path[0])[0]
        missions.append(Mission((float(home[0]), float(home[1])), flown_waypoints(
            path, loitering, log.scenario.dt_s, frame, spacing_s), speed_mps))
    net = log.network
    features = [geojson.lines([frame.degrees(net.coords[e]) for e in net.edges],
                              {"kind": "road", "source": net.source})]
    for j in range(log.uav_xy_m.shape[1]):
        features.append(geojson.line(frame.degrees(log.uav_xy_m[:, j]), {"kind": "uav", "uav": j}))
    for i in range(log.target_xy_m.shape[1]):
        features.append(geojson.line(frame.degrees(log.target_xy_m[:, i]),
                                     {"kind": "target", "target": i}))
    peaks: dict[int, list[int]] = {}
    for step in log.tracks:
        for track_id, node, _ in step:
            peaks.setdefault(track_id, []).append(node)
    for track_id, nodes in sorted(peaks.items()):
        where = frame.degrees(net.coords[nodes])
        features.append(geojson.path(where, {"kind": "estimate", "track": track_id}))
    return mission_files(missions, geojson.collection(features))


def optw_files(instance: OPTWInstance, routes: Sequence[Sequence[int]], frame: GeoFrame,
               speed_mps: float) -> dict[str, str]:
    """The files of an OPTW plan (module docstring); ``routes`` hold vertex indices."""
    xy = instance.coords
    if xy is None:
        raise InvalidInputError("instance", instance.name, "has no coordinates to export")
    home = frame.degrees(xy[instance.start])[0]
    missions = []
    for route in routes:
        visits = [v for v in route if v not in (instance.start, instance.end)]
        if not visits:
            continue
        latlon = frame.degrees(xy[visits])
        missions.append(Mission(
            (float(home[0]), float(home[1])),
            tuple(Waypoint(float(a), float(b), frame.altitude_m,
                           instance.to_time(int(instance.service[v])) * frame.unit_m / speed_mps)
                  for (a, b), v in zip(latlon, visits, strict=True)),
            speed_mps))
    visited = {v for r in routes for v in r}
    where = frame.degrees(xy)
    features = [geojson.point(where[v], {
        "kind": "depot" if v == instance.start else "customer", "vertex": int(v),
        "score": float(instance.profit[v]), "open": instance.to_time(int(instance.open[v])),
        "close": instance.to_time(int(instance.close[v])), "visited": v in visited})
        for v in range(instance.n)]
    for k, route in enumerate(routes):
        if len(route) > 1:
            features.append(geojson.line(where[list(route)], {"kind": "route", "route": k}))
    return mission_files(missions, geojson.collection(features), stem="route")
