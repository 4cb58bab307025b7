"""The ``associate`` plan family: trackers and detections on a road map → the gated EMD data
association of thesis 001 (§4.3, Algorithm 1) and its EMD costs, read from a JSON file and
paired by a backend of :data:`searchtrack.estimate.association.BACKENDS`.

PROBLEM.json::

    {"map": {"grid": [5, 5], "spacing_m": 50} | {"osm": "West-Oakland", "spacing_m": 10},
     "trackers": [{"nodes": {"12": 0.7, "13": 0.3}} | {"peak": [x, y], "sd_m": 20}, ...],
     "detections": [[x, y], ...],
     "noise_sd_m": 10, "gate_m": 300, "support_mass": 0.999}

``map`` is read as by ``searchtrack track-roads`` (:mod:`searchtrack.sim.road_particles.track_job`):
a grid of ``rows × cols`` junctions ``spacing_m`` apart (junction ``(r, c)`` at ``(c·spacing_m,
r·spacing_m)``, node index ``c·rows + r``: :func:`~searchtrack.models.road_synthetic.grid_node`), or
a bundled map name or an OSM file relative to the JSON file, resampled every ``spacing_m`` (default
10 m). Each of the ``k ≥ 1`` trackers is a location distribution over the road nodes: ``nodes`` maps
node indices to non-negative masses (rescaled to sum to 1), ``peak`` a Gaussian of s.d. ``sd_m``
(optional, default 20 m) in the Euclidean distance from ``[x, y]`` to each node. Each of the ``q ≥
1`` ``detections`` is a position fix ``[x, y]`` (m, within the roads' bounding box enlarged by
``gate_m``), turned into the measurement density ``Û`` of §4.3 with noise s.d. ``noise_sd_m``.
Optional: ``noise_sd_m`` (10 m), ``gate_m`` (the gate ``𝓔``, 300 m: only pairs with EMD below it
associate) and ``support_mass`` (signature truncation in ``(0, 1]``, 0.999).

The objective is the gated saving ``Σ (gate − EMD)`` over the pairs (maximised). The ``"plan"``
object of PLAN.json: ``{"gate_m", "assignment": [tracker index or null per detection], "pairs":
[{"tracker", "detection", "emd_m"}, ...], "new": [detection, ...], "costs": [[EMD (m) or null
per detection] per tracker], "total_emd_m"}`` — ``null`` in ``assignment`` (listed in ``new``):
the detection is left unassociated (a new target or clutter); ``null`` in ``costs``: proven ≥ the
gate; ``total_emd_m`` sums the EMD of the pairs.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.files import read_json
from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.estimate.association import BACKENDS as BACKENDS
from searchtrack.estimate.association import Association
from searchtrack.estimate.emd_association import EMDAssociator
from searchtrack.estimate.emd_matrix import EMD_MATRIX_BACKENDS
from searchtrack.estimate.node_tracker import (
    TrackerBank,
    measurement_density,
    position_log_likelihood,
)
from searchtrack.models.roads import RoadNetwork
from searchtrack.sim.export.plans import VehiclePaths
from searchtrack.sim.kernels import kernels_of
from searchtrack.sim.road_particles.track_job import FieldReader, read_map

DESCRIPTION = "pair trackers with detections on a road map by gated EMD (thesis 001)"

KERNELS = kernels_of(EMD_MATRIX_BACKENDS)
"""The numba kernel sets this family's backends compile on first use."""

#: Largest PROBLEM.json read (bytes).
MAX_PROBLEM_BYTES = 32 * 2**20
#: Most trackers and detections (the EMD matrix has ``k·q`` transport problems).
MAX_TRACKERS = 1000
MAX_DETECTIONS = 1000
#: Distances (m) must lie within this.
MAX_DISTANCE_M = 1e7

_TOP_KEYS = ("map", "trackers", "detections", "noise_sd_m", "gate_m", "support_mass")
_MAP_KEYS = ("grid", "osm", "spacing_m")
_TRACKER_KEYS = ("nodes", "peak", "sd_m")


@dataclass(frozen=True, eq=False)
class AssociateJob:
    """A validated PROBLEM.json: the roads, the trackers, the detections (``(q, 2)``, m) and
    their measurement densities ``(q, n)``, and the associator (gate, truncation)."""

    path: Path
    network: RoadNetwork
    map_label: str
    bank: TrackerBank
    detections: FloatArray
    densities: FloatArray
    gate_m: float
    support_mass: float

    @property
    def name(self) -> str:
        """The file's stem."""
        return self.path.stem


@dataclass(frozen=True)
class AssociationPlan:
    """The association and the ``(k, q)`` EMD matrix (m, ``+inf`` where proven ≥ the gate) it
    was chosen from."""

    association: Association
    costs: FloatArray


def _grid_nodes(r: FieldReader, nodes: Any, field: str, n: int) -> FloatArray:
    if not isinstance(nodes, dict) or not nodes:
        raise r.fail(field, "must be a non-empty JSON object of node index → mass")
    p = np.zeros(n)
    for key, mass in nodes.items():
        if not key.isdigit() or int(key) >= n:
            raise r.fail(f"{field}.{key}", f"must be a node index in [0, {n - 1}]")
        p[int(key)] += r.number(mass, f"{field}.{key}", high=1e12)
    if not p.sum() > 0.0:
        raise r.fail(field, "needs a positive total mass")
    return np.asarray(p / p.sum(), dtype=np.float64)


def _peak(r: FieldReader, spec: dict[str, Any], field: str, network: RoadNetwork) -> FloatArray:
    xy = spec["peak"]
    if not isinstance(xy, list) or len(xy) != 2:
        raise r.fail(f"{field}.peak", "must be a list of 2 numbers (x, y)")
    x, y = (r.number(v, f"{field}.peak[{i}]", low=-MAX_DISTANCE_M, high=MAX_DISTANCE_M)
            for i, v in enumerate(xy))
    sd = r.number(spec.get("sd_m", 20.0), f"{field}.sd_m", low_open=True, high=MAX_DISTANCE_M)
    d2 = (network.coords[:, 0] - x) ** 2 + (network.coords[:, 1] - y) ** 2
    log_w = -d2 / (2.0 * sd * sd)
    w = np.exp(log_w - log_w.max())
    return np.asarray(w / w.sum(), dtype=np.float64)


def _trackers(r: FieldReader, raw: Any, network: RoadNetwork) -> TrackerBank:
    if not isinstance(raw, list) or not raw:
        raise r.fail("trackers", "must be a non-empty list of trackers")
    if len(raw) > MAX_TRACKERS:
        raise r.fail("trackers", f"{len(raw)} trackers, above the {MAX_TRACKERS} allowed")
    bank = TrackerBank(network.n_nodes)
    for i, item in enumerate(raw):
        field = f"trackers[{i}]"
        spec = r.obj(item, field, _TRACKER_KEYS)
        kinds = [k for k in ("nodes", "peak") if k in spec]
        if len(kinds) != 1:
            raise r.fail(field, "give exactly one of 'nodes' or 'peak'")
        if kinds[0] == "nodes":
            if "sd_m" in spec:
                raise r.fail(f"{field}.sd_m", "only a 'peak' tracker has sd_m")
            p = _grid_nodes(r, spec["nodes"], f"{field}.nodes", network.n_nodes)
        else:
            p = _peak(r, spec, field, network)
        bank = bank.with_birth(p)
    return bank


def read_problem(path: str | Path) -> AssociateJob:
    """Read and validate an association PROBLEM.json (format in the module docstring); the
    map is built here.

    Raises
    ------
    ParseError
        Naming the file and the JSON key at fault (``trackers[1].peak[0]``, ``map.grid``).
    """
    p = Path(path)
    r = FieldReader(p)
    raw = read_json(p, max_bytes=MAX_PROBLEM_BYTES)
    top = r.obj(raw, "(top level)", _TOP_KEYS)
    roads, label = read_map(r, r.obj(r.get(top, "map"), "map", _MAP_KEYS), p.parent)
    network = roads.network
    noise = r.number(top.get("noise_sd_m", 10.0), "noise_sd_m", low_open=True,
                     high=MAX_DISTANCE_M)
    gate = r.number(top.get("gate_m", 300.0), "gate_m", low_open=True, high=MAX_DISTANCE_M)
    support = r.number(top.get("support_mass", 0.999), "support_mass", low_open=True, high=1.0)
    bank = _trackers(r, r.get(top, "trackers"), network)
    raw_det = r.get(top, "detections")
    if not isinstance(raw_det, list) or not raw_det:
        raise r.fail("detections", "must be a non-empty list of x, y points")
    if len(raw_det) > MAX_DETECTIONS:
        raise r.fail("detections", f"{len(raw_det)} detections, above the {MAX_DETECTIONS} "
                     "allowed")
    c = network.coords
    box = np.array([[c[:, 0].min() - gate, c[:, 0].max() + gate],
                    [c[:, 1].min() - gate, c[:, 1].max() + gate]])
    detections = r.points(raw_det, "detections", box)
    densities = measurement_density(position_log_likelihood(network, detections, noise))
    return AssociateJob(p, network, label, bank, detections, densities, gate, support)


def backends() -> list[str]:
    """The association backends, ``"auto"`` first."""
    names = BACKENDS.names()
    return ["auto", *(n for n in names if n != "auto")] if "auto" in names else names


def solve(problem: AssociateJob, *, backend: str, time_limit_s: float,
          seed: int) -> Result[AssociationPlan]:
    """The EMD matrix between the trackers and the detections' densities, then the pairing by
    the named backend (see :class:`~searchtrack.estimate.emd_association.EMDAssociator`);
    both share ``time_limit_s`` and ``runtime_s`` counts both. The pairing backends are
    deterministic (``seed`` unused).

    Raises
    ------
    InvalidInputError
        Unknown backend or a bad time limit.
    """
    associator = EMDAssociator(problem.network, backend=backend, gate_m=problem.gate_m,
                               support_mass=problem.support_mass, time_limit_s=time_limit_s)
    start = time.perf_counter()
    result, costs = associator.solve_with_costs(problem.bank, problem.densities)
    elapsed = time.perf_counter() - start
    plan = None if result.plan is None else AssociationPlan(result.plan, costs)
    return Result(result.status, result.objective, result.bound, max(elapsed, result.runtime_s),
                  result.backend, plan, sense=result.sense, message=result.message,
                  stats=dict(result.stats))


def _metres(x: float) -> float | None:
    return round(float(x), 4) if math.isfinite(x) else None


def plan_json(problem: AssociateJob, result: Result[AssociationPlan]) -> dict[str, Any]:
    """The ``"plan"`` object: the tracker of each detection (``null``: new or clutter), the
    pairs with their EMD, the EMD matrix (``null`` where proven ≥ the gate) and the total."""
    plan = result.plan
    if plan is None:
        raise ValueError("plan_json needs a result with a plan")
    q = problem.detections.shape[0]
    assignment: list[int | None] = [None] * q
    for i, j in plan.association.pairs:
        assignment[j] = i
    pairs = sorted(plan.association.pairs, key=lambda ij: ij[1])
    return {"gate_m": problem.gate_m,
            "assignment": assignment,
            "pairs": [{"tracker": i, "detection": j, "emd_m": _metres(plan.costs[i, j])}
                      for i, j in pairs],
            "new": list(plan.association.unassociated(q)),
            "costs": [[_metres(x) for x in row] for row in plan.costs],
            "total_emd_m": round(float(sum(plan.costs[i, j] for i, j in pairs)), 4)}


def figure(problem: AssociateJob, result: Result[AssociationPlan], path: Path) -> Path | None:
    """PNG of the roads, each tracker's node masses (area ∝ probability), the detections and a
    line from each paired tracker's peak node to its detection, labelled with the EMD."""
    from searchtrack.sim.figure_style import pyplot, save_png

    plt = pyplot()

    if result.plan is None:
        return None
    net = problem.network
    fig, ax = plt.subplots(figsize=(6.0, 6.0))
    for a, b in net.edges:
        ax.plot(net.coords[[a, b], 0], net.coords[[a, b], 1], color="0.8", lw=1, zorder=0)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    probabilities = problem.bank.probabilities()
    for i, p in enumerate(probabilities):
        colour = colours[i % len(colours)]
        shown = p > 1e-3 * p.max()
        ax.scatter(net.coords[shown, 0], net.coords[shown, 1], s=200.0 * p[shown] / p.max(),
                   color=colour, alpha=0.5, label=f"tracker {i}")
    det = problem.detections
    ax.scatter(det[:, 0], det[:, 1], marker="x", color="k", s=50, label="detections")
    boxed = {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85}
    for j, (x, y) in enumerate(det):   # the detection's index above it, its EMD below
        ax.annotate(f"det {j}", (x, y), textcoords="offset points", xytext=(0, 9),
                    ha="center", fontsize=8, bbox=boxed, zorder=5)
    for i, j in result.plan.association.pairs:
        peak = net.coords[int(np.argmax(probabilities[i]))]
        ax.plot([peak[0], det[j, 0]], [peak[1], det[j, 1]], color=colours[i % len(colours)],
                lw=2)
        ax.annotate(f"{result.plan.costs[i, j]:.0f} m", det[j], textcoords="offset points",
                    xytext=(0, -16), ha="center", fontsize=7, bbox=boxed, zorder=5,
                    color=colours[i % len(colours)])
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_title(f"{problem.name}: gate {problem.gate_m:g} m, {result.status.name}")
    ax.legend(loc="best", fontsize=7)
    return save_png(fig, Path(path))


def vehicle_paths(problem: AssociateJob, result: Result[AssociationPlan]) -> VehiclePaths:
    """None: an association moves no vehicle."""
    return VehiclePaths()
