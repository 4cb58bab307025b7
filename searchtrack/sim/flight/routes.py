"""Planner routes flown closed loop by the trajectory controllers.

* Road map (thesis 001): an OPTW route (a sequence of :class:`RoadNetwork` node indices, e.g.
  from :func:`plan_optw_route`) or a potential-field trajectory (the ``xy`` path a road mission
  recorded) becomes a constant-speed reference (:func:`waypoint_path`) flown by a Dubins unicycle
  (``v_min = v_max``, :func:`~searchtrack.models.dubins.unicycle_from_limits`) with
  :func:`~searchtrack.sim.flight.loop.fly`; :func:`road_obstacles` puts buildings beside the roads.
* 3-D waypoints (e.g. a lattice search planner's, paper 004): :func:`fixed_wing_path` turns them
  into a reference a fixed wing can fly; :func:`route_deviation_m` measures the cross-track
  error of a flight. Paper 004's experiment E7 is :mod:`searchtrack.sim.flight.e7`.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.dubins import DubinsLimits, unicycle_from_limits
from searchtrack.models.roads import RoadNetwork
from searchtrack.models.vehicles import VehicleModel
from searchtrack.plan.guidance.reacquire import plan_reacquisition, reacquisition_instance
from searchtrack.plan.trajectory import Obstacles, SampledPath, waypoint_path
from searchtrack.sim.flight.loop import FlightConfig, FlightLog, fly


def route_waypoints(network: RoadNetwork, route_nodes: ArrayLike, *,
                    along_roads: bool = False) -> FloatArray:
    """``(k, 2)`` positions (m) of the route's nodes; with ``along_roads`` the shortest road
    path joins consecutive nodes (else the straight legs the OPTW's Euclidean times assume).

    Raises
    ------
    InvalidInputError
        An empty route, non-integer entries (NaN included) or an index outside the network.
    """
    nodes = np.asarray(route_nodes)
    if nodes.ndim != 1 or nodes.size == 0:
        raise InvalidInputError("route_nodes", route_nodes,
                                "must be a non-empty 1-D sequence of node indices")
    if nodes.dtype.kind not in "iu":
        raise InvalidInputError("route_nodes", route_nodes, "node indices must be integers")
    if nodes.min() < 0 or nodes.max() >= network.n_nodes:
        raise InvalidInputError("route_nodes", route_nodes,
                                f"node indices must be in [0, {network.n_nodes})")
    idx = nodes.astype(np.int64)
    if along_roads and idx.size > 1:
        legs = [idx[:1]]
        for a, b in itertools.pairwise(idx):
            path, _ = network.shortest_path(int(a), int(b))
            if path.size == 0:
                raise InvalidInputError("route_nodes", route_nodes,
                                        f"nodes {a} and {b} are not connected by road")
            legs.append(path[1:])
        idx = np.concatenate(legs)
    return np.asarray(network.coords[idx], dtype=np.float64)


def path_waypoints(xy_m: ArrayLike, *, min_spacing_m: float = 5.0) -> FloatArray:
    """A recorded ``(n, 2)`` path thinned so consecutive waypoints are ``min_spacing_m`` apart
    (the last point always kept); :class:`InvalidInputError` unless a finite ``(n ≥ 2, 2)``
    array that moves.
    """
    pts = checks.finite_array("xy_m", xy_m, (None, 2))
    spacing = checks.positive("min_spacing_m", min_spacing_m)
    if pts.shape[0] < 2:
        raise InvalidInputError("xy_m", xy_m, "needs at least 2 points")
    keep = [0]
    for i in range(1, pts.shape[0]):
        if np.linalg.norm(pts[i] - pts[keep[-1]]) >= spacing:
            keep.append(i)
    if np.linalg.norm(pts[-1] - pts[keep[-1]]) > 1e-9:
        keep.append(pts.shape[0] - 1)
    if len(keep) < 2:
        raise InvalidInputError("xy_m", xy_m, f"moves less than min_spacing_m={spacing:g}")
    return np.asarray(pts[keep], dtype=np.float64)


def dubins_model(limits: DubinsLimits) -> VehicleModel:
    """The constant-speed Dubins unicycle (``v_min = v_max = S_max``) of ``limits``."""
    fixed = DubinsLimits(limits.speed_max_mps, limits.speed_max_mps, limits.turn_rate_max_rps)
    return unicycle_from_limits(fixed)


def fly_dubins(waypoints_m: ArrayLike, *, limits: DubinsLimits | None = None,
               obstacles: Obstacles | None = None, config: FlightConfig | None = None,
               rng: np.random.Generator) -> FlightLog:
    """Fly the polyline ``waypoints_m`` ``(k ≥ 2, 2)`` at ``S_max`` with the Dubins unicycle,
    starting on the first waypoint heading along the first leg, until the reference ends
    (unless ``config.duration_s`` says otherwise)."""
    lim = DubinsLimits() if limits is None else limits
    pts = checks.finite_array("waypoints_m", waypoints_m, (None, 2))
    reference = waypoint_path(pts, lim.speed_max_mps)
    if reference.positions_m.shape[0] < 2:
        raise InvalidInputError("waypoints_m", waypoints_m, "needs two distinct waypoints")
    lead = reference.positions_m[1] - reference.positions_m[0]
    start = np.array([*reference.positions_m[0], math.atan2(lead[1], lead[0])])
    return fly(dubins_model(lim), start, reference, obstacles,
               until_reference_end(config, reference), rng=rng)


def until_reference_end(config: FlightConfig | None, reference: SampledPath) -> FlightConfig:
    """``config`` flying until the reference ends, unless it sets ``duration_s`` (a vehicle with
    a minimum speed cannot hold the end point, so the 2 s hold of :func:`fly` would only measure
    its overshoot)."""
    cfg = FlightConfig() if config is None else config
    if cfg.duration_s is not None:
        return cfg
    return dataclasses.replace(cfg, duration_s=reference.duration_s)


def fly_optw_route(network: RoadNetwork, route_nodes: ArrayLike, *,
                   limits: DubinsLimits | None = None, obstacles: Obstacles | None = None,
                   config: FlightConfig | None = None, along_roads: bool = False,
                   rng: np.random.Generator) -> FlightLog:
    """Fly an OPTW route (road node indices, start node first) with the Dubins unicycle."""
    pts = route_waypoints(network, route_nodes, along_roads=along_roads)
    if pts.shape[0] < 2:
        raise InvalidInputError("route_nodes", route_nodes, "needs at least 2 nodes to fly")
    return fly_dubins(pts, limits=limits, obstacles=obstacles, config=config, rng=rng)


def fly_xy_path(xy_m: ArrayLike, *, limits: DubinsLimits | None = None,
                obstacles: Obstacles | None = None, config: FlightConfig | None = None,
                min_spacing_m: float = 5.0, rng: np.random.Generator) -> FlightLog:
    """Fly a recorded ``(n, 2)`` path (e.g. a potential-field UAV track of a road mission)."""
    pts = path_waypoints(xy_m, min_spacing_m=min_spacing_m)
    return fly_dubins(pts, limits=limits, obstacles=obstacles, config=config, rng=rng)


def plan_optw_route(network: RoadNetwork, scores: ArrayLike, start_node: int, *,
                    speed_mps: float, horizon_s: float, max_nodes: int = 30,
                    backend: str = "auto", time_limit_s: float = 0.5, seed: int = 0
                    ) -> tuple[int, ...]:
    """An OPTW route over the best-scored nodes, as thesis 001 §5.5 builds it for reacquisition
    (:func:`reacquisition_instance`): node ids, ``start_node`` first."""
    n = checks.count("start_node", start_node)
    if n >= network.n_nodes:
        raise InvalidInputError("start_node", start_node, f"must be < {network.n_nodes}")
    instance, ids = reacquisition_instance(network, scores, network.coords[n], speed_mps,
                                           horizon_s, max_nodes=max_nodes)
    route, _ = plan_reacquisition(instance, ids, backend=backend, time_limit_s=time_limit_s,
                                  seed=seed)
    return (n, *(v for v in route if v != n))


def road_obstacles(network: RoadNetwork, count: int, *, radius_m: float, clearance_m: float,
                   rng: np.random.Generator, keep_clear_xy_m: ArrayLike | None = None,
                   keep_clear_m: float = 0.0, max_tries: int = 10_000) -> Obstacles:
    """``count`` vertical cylinders (buildings) inside the map's bounding box, each at least
    ``clearance_m`` from every road node and from each other, and their surfaces at least
    ``keep_clear_m`` from the ``(p, 2)`` points ``keep_clear_xy_m`` (e.g. a UAV's start).

    Raises
    ------
    InvalidInputError
        Bad sizes, or fewer than ``count`` places found within ``max_tries`` draws.
    """
    k = checks.count("count", count)
    radius = checks.positive("radius_m", radius_m)
    clear = checks.non_negative("clearance_m", clearance_m)
    gen = checks.generator("rng", rng)
    keep = np.zeros((0, 2)) if keep_clear_xy_m is None else checks.finite_array(
        "keep_clear_xy_m", np.reshape(keep_clear_xy_m, (-1, 2)), (None, 2))
    far = checks.non_negative("keep_clear_m", keep_clear_m)
    lo, hi = network.coords.min(axis=0), network.coords.max(axis=0)
    centres: list[FloatArray] = []
    for _ in range(checks.count("max_tries", max_tries, least=1)):
        if len(centres) == k:
            break
        c = gen.uniform(lo, hi)
        road = float(np.min(np.linalg.norm(network.coords - c, axis=1)))
        apart = all(np.linalg.norm(c - o) >= 2.0 * radius + clear for o in centres)
        away = keep.shape[0] == 0 or np.min(np.linalg.norm(keep - c, axis=1)) >= radius + far
        if road >= radius + clear and apart and away:
            centres.append(c)
    if len(centres) < k:
        raise InvalidInputError("count", count, f"only {len(centres)} cylinders of radius "
                                f"{radius:g} m fit {clear:g} m clear of the roads")
    return Obstacles(centers_m=np.reshape(centres, (k, 2)), radii_m=np.full(k, radius))


# ----- 3-D waypoints -------------------------------------------------------------------------

def fixed_wing_path(waypoints_m: ArrayLike, speed_mps: float, max_slope: float,
                    *, sample_m: float = 2.0) -> SampledPath:
    """A reference a fixed wing can fly through ``(k, 3)`` waypoints: the horizontal polyline
    at ``speed_mps`` (consecutive waypoints with one ``xy`` merged), its height chasing each
    leg's height with ``|dz/ds| ≤ max_slope`` along the horizontal arc ``s``.

    A lattice planner's vertical moves (004: ±12 m in ``z``) cannot be flown on the spot by an
    aircraft with a minimum airspeed; here they become climbs spread over the following legs
    (a trailing vertical move is not reached). :class:`InvalidInputError` for bad sizes or
    waypoints that never move horizontally.
    """
    pts = checks.finite_array("waypoints_m", waypoints_m, (None, 3))
    speed = checks.positive("speed_mps", speed_mps)
    slope = checks.positive("max_slope", max_slope)
    step = checks.positive("sample_m", sample_m)
    xy, z = pts[:, :2], pts[:, 2]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    moves = np.flatnonzero(np.diff(arc) > 1e-9)
    if moves.size == 0:
        raise InvalidInputError("waypoints_m", waypoints_m, "never moves horizontally")
    s = np.concatenate([np.arange(0.0, arc[-1], step), [arc[-1]]])
    leg = np.clip(np.searchsorted(arc[moves + 1], s, side="left"), 0, moves.size - 1)
    i = moves[leg]
    frac = np.clip((s - arc[i]) / (arc[i + 1] - arc[i]), 0.0, 1.0)
    target = z[i] + frac * (z[i + 1] - z[i])
    height = np.empty_like(s)
    height[0] = z[0]
    for n in range(1, s.size):
        room = slope * (s[n] - s[n - 1])
        height[n] = height[n - 1] + np.clip(target[n] - height[n - 1], -room, room)
    knots = np.r_[moves, moves[-1] + 1]
    flat = np.column_stack([np.interp(s, arc[knots], xy[knots, 0]),
                            np.interp(s, arc[knots], xy[knots, 1]), height])
    return SampledPath(times_s=s / speed, positions_m=flat)


def polyline_distance_m(points: FloatArray, path: FloatArray) -> FloatArray:
    """``(n,)`` distance (m) from each of the ``(n, d)`` points to the polyline ``path``
    ``(k, d)``."""
    if path.shape[0] == 1:
        return np.asarray(np.linalg.norm(points - path[0], axis=1))
    a, b = path[:-1], path[1:]
    ab = b - a
    sq = np.maximum(np.sum(ab**2, axis=1), 1e-12)
    t = np.clip(np.einsum("nkd,kd->nk", points[:, None, :] - a[None], ab) / sq, 0.0, 1.0)
    near = a[None] + t[..., None] * ab[None]
    return np.asarray(np.linalg.norm(points[:, None, :] - near, axis=2).min(axis=1))


def route_deviation_m(flight: FlightLog, waypoints_m: ArrayLike) -> FloatArray:
    """``(T + 1,)`` distance from each flown position to the polyline ``waypoints_m`` (the
    cross-track error, blind to lagging behind the timed reference)."""
    pos = flight.states[:, list(flight.model.position_indices)]
    path = checks.finite_array("waypoints_m", waypoints_m, (None, pos.shape[1]))
    return polyline_distance_m(pos, path)
