"""What a radio mission (paper 002) exports: the UAV's flown path as one autopilot mission (a
waypoint every ``spacing_s`` seconds; home where it started) and a GeoJSON of the UAV's path,
each tag's true path while alive and each label's estimated path
(:mod:`~searchtrack.sim.export.plans` for the file layout)."""

from __future__ import annotations

import numpy as np

from searchtrack.sim.export import geojson
from searchtrack.sim.export.autopilot import Mission
from searchtrack.sim.export.geo import GeoFrame
from searchtrack.sim.export.plans import flown_waypoints, mission_files
from searchtrack.sim.radio.mission import RadioMissionLog


def radio_mission_files(log: RadioMissionLog, frame: GeoFrame,
                        spacing_s: float = 10.0) -> dict[str, str]:
    """File name → text of a radio mission (module docstring); nothing flown: no files."""
    if log.steps == 0:
        return {}
    xy = log.poses[:, :2]
    home = frame.degrees(xy[0])[0]
    mission = Mission((float(home[0]), float(home[1])),
                      flown_waypoints(xy, [False] * len(xy), log.scenario.uav.step_s, frame,
                                      spacing_s),
                      log.scenario.uav.speed_mps)
    features = [geojson.path(frame.degrees(xy), {"kind": "uav", "uav": 0})]
    truth = log.truth
    for tag in range(truth.states.shape[1]):
        alive = truth.alive[:, tag]
        if alive.any():
            features.append(geojson.path(frame.degrees(truth.states[alive, tag][:, [0, 2]]),
                                  {"kind": "target", "label": tag}))
    tracks: dict[int, list[tuple[float, float]]] = {}
    for step in log.estimates:
        for label, point in step:
            tracks.setdefault(label, []).append(point)
    for label, points in sorted(tracks.items()):
        features.append(geojson.path(frame.degrees(np.array(points)),
                              {"kind": "estimate", "label": label}))
    return mission_files([mission], geojson.collection(features))
