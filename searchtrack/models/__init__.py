"""searchtrack.models: the world the UAVs search and the agents in it.

* Roads (thesis 001 Ch. 2): :class:`RoadNetwork` from OpenStreetMap (:func:`read_osm`) or
  synthetic (:func:`grid_network`, :func:`random_network`), in a :class:`LocalProjection`.
* Targets on directed roads (paper 000): :class:`DirectedRoads` (positions ``(edge, arc
  length)``) and the along-road motion model :class:`RoadMotion` (Eq. 9), seen by the
  downward disc sensor :class:`DiscSensor` (Eq. 10–11).
* Targets: courier-like vehicles on the roads (001 §1.2, §6; :class:`CourierModel`); particle
  motion models (:class:`ConstantVelocity`, :class:`RandomWalk`, :class:`Static`, and the GP
  velocity field of paper 003 in :mod:`.gp_motion`, not imported here since it loads
  ``scipy.optimize``) behind the :class:`MotionModel` protocol.
* Sensors: the thesis's LRT sensor and its altitude model (001 §3.3, §4.3, §6.2;
  :class:`SensorModel`, :class:`AltitudeModel`), the downward camera of 003
  (:class:`DownwardCamera`), the range–bearing–elevation sensor of 004
  (:class:`RangeBearingElevationSensor`) and a planar position sensor (:class:`PositionSensor`),
  the last three behind the :class:`DetectionSensor` protocol.
* UAVs: the potential-field Dubins UAV (001 §5.1; :class:`UavState`, :func:`step_force`) and
  the controlled vehicle models of the trajectory controllers (:class:`VehicleModel`:
  :func:`unicycle`, :func:`fixed_wing`, :func:`uav7`).
"""

from __future__ import annotations

from searchtrack.models.camera import DownwardCamera
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.dubins import (
    DubinsLimits,
    UavState,
    force_to_controls,
    propagate,
    sat,
    step_force,
    unicycle_from_limits,
)
from searchtrack.models.lrt_sensor import AltitudeModel, SensorModel, roc, sensitivity, z_score
from searchtrack.models.measurements import (
    FALSE_ALARM,
    LrtScan,
    PositionScan,
    lrt_measurements,
    position_measurements,
)
from searchtrack.models.motion import ConstantVelocity, RandomWalk, Static
from searchtrack.models.osm import CAR_HIGHWAYS, read_osm
from searchtrack.models.particle_models import DetectionSensor, MotionModel
from searchtrack.models.position_sensor import PositionSensor
from searchtrack.models.projection import LocalProjection
from searchtrack.models.range_sensor import RangeBearingElevationSensor
from searchtrack.models.road_builder import network_from_polylines
from searchtrack.models.road_particles import DirectedRoads, RoadMotion
from searchtrack.models.road_synthetic import grid_network, random_network
from searchtrack.models.roads import RoadNetwork
from searchtrack.models.targets import CourierModel, CourierMotion, TargetState
from searchtrack.models.vehicles import VehicleModel, fixed_wing, uav7, unicycle

__all__ = [
    "CAR_HIGHWAYS",
    "FALSE_ALARM",
    "AltitudeModel",
    "ConstantVelocity",
    "CourierModel",
    "CourierMotion",
    "DetectionSensor",
    "DirectedRoads",
    "DiscSensor",
    "DownwardCamera",
    "DubinsLimits",
    "LocalProjection",
    "LrtScan",
    "MotionModel",
    "PositionScan",
    "PositionSensor",
    "RandomWalk",
    "RangeBearingElevationSensor",
    "RoadMotion",
    "RoadNetwork",
    "SensorModel",
    "Static",
    "TargetState",
    "UavState",
    "VehicleModel",
    "fixed_wing",
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
    "uav7",
    "unicycle",
    "unicycle_from_limits",
    "z_score",
]
