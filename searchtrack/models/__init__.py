"""searchtrack.models: the world the UAVs search (thesis 001): road networks (Ch. 2), sensors
(§3.3, §4.3, §6.2), Dubins UAVs (§5.1) and courier-like targets on the roads (§1.2, §6)."""

from __future__ import annotations

from searchtrack.models.dubins import (
    DubinsLimits,
    UavState,
    force_to_controls,
    propagate,
    sat,
    step_force,
)
from searchtrack.models.measurements import (
    FALSE_ALARM,
    LrtScan,
    PositionScan,
    lrt_measurements,
    position_measurements,
)
from searchtrack.models.osm import CAR_HIGHWAYS, read_osm
from searchtrack.models.projection import LocalProjection
from searchtrack.models.road_builder import network_from_polylines
from searchtrack.models.road_synthetic import grid_network, random_network
from searchtrack.models.roads import RoadNetwork
from searchtrack.models.sensors import AltitudeModel, SensorModel, roc, sensitivity, z_score
from searchtrack.models.targets import CourierModel, CourierMotion, TargetState

__all__ = [
    "CAR_HIGHWAYS",
    "FALSE_ALARM",
    "AltitudeModel",
    "CourierModel",
    "CourierMotion",
    "DubinsLimits",
    "LocalProjection",
    "LrtScan",
    "PositionScan",
    "RoadNetwork",
    "SensorModel",
    "TargetState",
    "UavState",
    "force_to_controls",
    "grid_network",
    "lrt_measurements",
    "network_from_polylines",
    "position_measurements",
    "propagate",
    "random_network",
    "read_osm",
    "roc",
    "sat",
    "sensitivity",
    "step_force",
    "z_score",
]
