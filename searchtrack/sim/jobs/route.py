"""The ``route`` plan family: one UAV's OPTW route over tracker beliefs on a road network, built
as search-and-reacquire builds it (thesis 001 §5.5, :func:`~searchtrack.plan.guidance.reacquire.
reacquisition_instance`), read from a JSON file and solved by a backend of
:data:`searchtrack.plan.optw.BACKENDS`.

PROBLEM.json::

    {"map": {"grid": [6, 6], "spacing_m": 100} | {"osm": "West-Oakland", "spacing_m": 10},
     "uav": {"start_node": 0, "speed_mps": 20},
     "horizon_s": 60,
     "trackers": [{"peak_node": 14, "spread_m": 80},
                  {"nodes": [3, 4, 9], "masses": [0.5, 0.3, 0.2], "weight": 0.5}],
     "max_nodes": 60, "support_mass": 0.95}

``map`` is read as ``searchtrack track-roads`` reads it
(:mod:`searchtrack.sim.road_particles.track_job`):
a ``rows × cols`` grid of junctions ``spacing_m`` apart (node ``c·rows + r`` at
``(c·spacing_m, r·spacing_m)``: :func:`~searchtrack.models.road_synthetic.grid_node`) or a
bundled / OSM map resampled every ``spacing_m``. The UAV
starts at road node ``uav.start_node`` and flies ``uav.speed_mps`` in straight lines for at most
``horizon_s`` seconds (the reacquisition time ``T_r``). Each tracker is a probability over road
nodes, given either as ``nodes`` with their ``masses`` (normalised to 1) or as a ``peak_node``
with a Gaussian ``spread_m`` (mass ``∝ exp(−d²/2σ²)`` of each node's distance to the peak,
normalised to 1); the optional ``weight`` (default 1) scales it. A node's score is the weighted
sum of the trackers' probabilities; the OPTW keeps the best ``max_nodes`` (default 60) up to
``support_mass`` (default 0.95) of the score, as :func:`~searchtrack.plan.guidance.reacquire.
candidate_nodes` does.

The ``"plan"`` object of PLAN.json: ``{"nodes": [start, n_1, ...], "xy": [[x, y], ...],
"times_s": [0, t_1, ...], "finish_s", "horizon_s", "candidates", "profit", "tracker_profit":
[p_0, ...]}`` — the route as road node ids from the start, their coordinates (m) and visit times
(s), the number of OPTW candidate nodes, and the score collected in all and per tracker.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.files import read_json
from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.models.projection import LocalProjection
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance.reacquire import reacquisition_instance
from searchtrack.plan.optw import BACKENDS as BACKENDS
from searchtrack.plan.optw import OPTWInstance, Routes
from searchtrack.plan.optw import solve as solve_optw
from searchtrack.plan.optw.routes import schedule
from searchtrack.sim.export.plans import VehiclePaths
from searchtrack.sim.kernels import kernels_of
from searchtrack.sim.particles.track_job import MAX_DISTANCE_M
from searchtrack.sim.road_particles.track_job import FieldReader, read_map

DESCRIPTION = "one UAV's OPTW route over tracker beliefs on roads, as reacquisition (thesis 001)"

KERNELS = kernels_of(BACKENDS)
"""The numba kernel sets this family's backends compile on first use."""

#: Largest PROBLEM.json read (bytes).
MAX_PROBLEM_BYTES = 8 * 2**20
#: Most trackers, and most OPTW candidate nodes (the exact backends' limit is far lower).
MAX_TRACKERS = 1000
MAX_CANDIDATES = 2000
#: Longest horizon (s) and fastest UAV (m/s).
MAX_HORIZON_S = 1e6
MAX_SPEED_MPS = 1e3

_TOP_KEYS = ("map", "uav", "horizon_s", "trackers", "max_nodes", "support_mass")
_MAP_KEYS = ("grid", "osm", "spacing_m")
_UAV_KEYS = ("start_node", "speed_mps")
_TRACKER_KEYS = ("nodes", "masses", "peak_node", "spread_m", "weight")


@dataclass(frozen=True)
class RouteJob:
    """A validated PROBLEM.json: the roads, the trackers' weighted probabilities ``(k, n)`` and
    the reacquisition OPTW with the road node of each vertex (``-1`` for the UAV)."""

    path: Path
    network: RoadNetwork
    map_label: str
    start_node: int
    trackers: FloatArray
    instance: OPTWInstance
    node_ids: np.ndarray[Any, np.dtype[np.int64]]

    @property
    def name(self) -> str:
        """The file's stem."""
        return self.path.stem


def _node(r: FieldReader, value: Any, field: str, n: int) -> int:
    return r.integer(value, field, 0, n - 1)


def _tracker(r: FieldReader, raw: Any, field: str, network: RoadNetwork) -> FloatArray:
    """One tracker's probability over the road nodes, scaled by its weight."""
    spec = r.obj(raw, field, _TRACKER_KEYS)
    n = network.n_nodes
    weight = r.number(spec.get("weight", 1.0), f"{field}.weight", low=0.0, low_open=True,
                      high=1e6)
    kinds = [k for k in ("nodes", "peak_node") if k in spec]
    if len(kinds) != 1:
        raise r.fail(field, "give exactly one of 'nodes' (with 'masses') or 'peak_node' "
                     "(with 'spread_m')")
    p = np.zeros(n)
    if kinds[0] == "nodes":
        if "spread_m" in spec:
            raise r.fail(f"{field}.spread_m", "goes with 'peak_node', not 'nodes'")
        nodes, masses = spec["nodes"], r.get(spec, "masses", f"{field}.")
        if not isinstance(nodes, list) or not nodes:
            raise r.fail(f"{field}.nodes", "must be a non-empty list of road node ids")
        if not isinstance(masses, list) or len(masses) != len(nodes):
            raise r.fail(f"{field}.masses", f"must be a list of {len(nodes)} masses, one per "
                         "node")
        for i, (v, m) in enumerate(zip(nodes, masses, strict=True)):
            p[_node(r, v, f"{field}.nodes[{i}]", n)] += r.number(m, f"{field}.masses[{i}]",
                                                                   high=1e6)
        if p.sum() <= 0.0:
            raise r.fail(f"{field}.masses", "must not all be 0")
    else:
        if "masses" in spec:
            raise r.fail(f"{field}.masses", "goes with 'nodes', not 'peak_node'")
        peak = _node(r, spec["peak_node"], f"{field}.peak_node", n)
        sigma = r.number(r.get(spec, "spread_m", f"{field}."), f"{field}.spread_m",
                         low_open=True, high=MAX_DISTANCE_M)
        d2 = np.sum((network.coords - network.coords[peak]) ** 2, axis=1)
        p = np.exp(-0.5 * (d2 - d2.min()) / sigma**2)
    return np.asarray(weight * p / p.sum(), dtype=np.float64)


def _load(path: Path) -> Any:
    return read_json(path, max_bytes=MAX_PROBLEM_BYTES)


def read_problem(path: str | Path) -> RouteJob:
    """Read and validate a route PROBLEM.json (format in the module docstring; the map is built
    and the OPTW instance assembled here).

    Raises
    ------
    ParseError
        Naming the file and the JSON key at fault (``uav.start_node``, ``trackers[1].spread_m``).
    """
    p = Path(path)
    r = FieldReader(p)
    top = r.obj(_load(p), "(top level)", _TOP_KEYS)
    roads, label = read_map(r, r.obj(r.get(top, "map"), "map", _MAP_KEYS), p.parent)
    network = roads.network
    uav = r.obj(r.get(top, "uav"), "uav", _UAV_KEYS)
    start = _node(r, r.get(uav, "start_node", "uav."), "uav.start_node", network.n_nodes)
    speed = r.number(r.get(uav, "speed_mps", "uav."), "uav.speed_mps", low_open=True,
                     high=MAX_SPEED_MPS)
    horizon = r.number(r.get(top, "horizon_s"), "horizon_s", low_open=True, high=MAX_HORIZON_S)
    raw = r.get(top, "trackers")
    if not isinstance(raw, list) or not raw or len(raw) > MAX_TRACKERS:
        raise r.fail("trackers", f"must be a list of 1 to {MAX_TRACKERS} tracker objects")
    trackers = np.vstack([_tracker(r, t, f"trackers[{i}]", network) for i, t in enumerate(raw)])
    max_nodes = r.integer(top.get("max_nodes", 60), "max_nodes", 1, MAX_CANDIDATES)
    support = r.number(top.get("support_mass", 0.95), "support_mass", low_open=True, high=1.0)
    try:
        instance, ids = reacquisition_instance(network, trackers.sum(axis=0),
                                               network.coords[start], speed, horizon,
                                               max_nodes=max_nodes, support_mass=support)
    except InvalidInputError as exc:
        raise r.fail(exc.field, exc.reason) from None
    trackers.setflags(write=False)
    return RouteJob(p, network, label, start, trackers, instance, ids)


def backends() -> list[str]:
    """The OPTW backends, ``"auto"`` first."""
    return BACKENDS.names()


def solve(problem: RouteJob, *, backend: str, time_limit_s: float, seed: int) -> Result[Routes]:
    """Solve the reacquisition OPTW with the named backend (see :func:`searchtrack.plan.optw.
    solve`)."""
    return solve_optw(problem.instance, backend=backend, time_limit_s=time_limit_s, seed=seed)


def _visits(problem: RouteJob, result: Result[Routes]) -> tuple[list[int], list[float]]:
    """The OPTW vertices of the route (the UAV's vertex 0 first) and their visit times (s)."""
    if result.plan is None:
        raise ValueError("plan_json needs a result with a plan")
    inst = problem.instance
    route = [int(v) for v in result.plan[0]] if result.plan else [inst.start]
    ticks = schedule(inst, route)
    return route, [inst.to_time(t) for t in ticks]


def plan_json(problem: RouteJob, result: Result[Routes]) -> dict[str, Any]:
    """The ``"plan"`` object: the route's road nodes, coordinates and visit times, and the score
    collected in all and per tracker."""
    route, times = _visits(problem, result)
    visited = problem.node_ids[route[1:]]
    nodes, at = [problem.start_node], [0.0]
    for node, t in zip(visited.tolist(), times[1:-1], strict=True):
        if node != nodes[-1]:  # the start node may also be a candidate, reached at once
            nodes.append(int(node))
            at.append(round(t, 6))
    per_tracker = problem.trackers[:, visited].sum(axis=1) if visited.size else \
        np.zeros(problem.trackers.shape[0])
    return {"nodes": nodes,
            "xy": np.round(problem.network.coords[nodes], 6).tolist(),
            "times_s": at,
            "finish_s": round(times[-1], 6),
            "horizon_s": problem.instance.to_time(problem.instance.latest_finish),
            "candidates": problem.instance.n - 1,
            "profit": round(float(per_tracker.sum()), 9),
            "tracker_profit": [round(float(x), 9) for x in per_tracker]}


def figure(problem: RouteJob, result: Result[Routes], path: Path) -> Path | None:
    """PNG of the roads, the nodes' scores (area ∝ score), the OPTW candidates and the route."""
    from searchtrack.sim.figure_style import pyplot, save_png

    plt = pyplot()

    net = problem.network
    plan = plan_json(problem, result)
    fig, ax = plt.subplots(figsize=(6.0, 6.0))
    for a, b in net.edges:
        ax.plot(*net.coords[[a, b]].T, color="0.8", lw=1, zorder=1)
    score = problem.trackers.sum(axis=0)
    cand = problem.node_ids[1:]
    sizes = 4.0 + 200.0 * score[cand] / max(float(score.max()), 1e-12)
    ax.scatter(net.coords[cand, 0], net.coords[cand, 1], s=sizes, c="tab:orange", alpha=0.6,
               zorder=2, label="OPTW candidates (area ∝ score)")
    xy = np.asarray(plan["xy"])
    ax.plot(xy[:, 0], xy[:, 1], color="tab:blue", lw=2.5, marker="o", ms=4, zorder=3,
            label=f"route: {len(xy) - 1} nodes, {plan['finish_s']:g} s")
    ax.plot(*xy[0], marker="^", color="tab:blue", ms=10, zorder=4, label="UAV start")
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_title(f"{problem.name}: profit {plan['profit']:.3g}, {result.status.name}")
    ax.legend(loc="best", fontsize=7)
    return save_png(fig, Path(path))


def vehicle_paths(problem: RouteJob, result: Result[Routes]) -> VehiclePaths:
    """The UAV from its start node through the route's road nodes, in the map's frame."""
    nodes = plan_json(problem, result)["nodes"]
    return VehiclePaths((problem.network.coords[nodes],))


def geo_projection(problem: RouteJob) -> LocalProjection | None:
    """The road map's projection (``None`` for a synthetic grid)."""
    return problem.network.projection
