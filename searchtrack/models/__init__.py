"""searchtrack.models: the world the UAVs search, starting with road networks (thesis 001 Ch. 2)."""

from __future__ import annotations

from searchtrack.models.osm import CAR_HIGHWAYS, read_osm
from searchtrack.models.projection import LocalProjection
from searchtrack.models.road_builder import network_from_polylines
from searchtrack.models.road_synthetic import grid_network, random_network
from searchtrack.models.roads import RoadNetwork

__all__ = [
    "CAR_HIGHWAYS",
    "LocalProjection",
    "RoadNetwork",
    "grid_network",
    "network_from_polylines",
    "random_network",
    "read_osm",
]
