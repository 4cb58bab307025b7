"""Recorded UAV detections of targets on roads, filtered offline by the Rao-Blackwellized road
filter of Moore et al. 2021 (:class:`~searchtrack.estimate.road_rbpf.RoadRBPF`): DETECTIONS.json
read and validated into a :class:`RoadTrackJob` (the map built), run step by step, the estimates
written to EST.json — the library side of ``searchtrack track-roads``.

DETECTIONS.json::

    {"map": {"grid": [3, 3], "spacing_m": 100} | {"osm": "West-Oakland", "spacing_m": 10},
     "dt": 0.1, "targets": 2, "target_speed_mps": 10, "speed_sigma_mps": 4,
     "sensor": {"fov_radius_m": 30, "sigma2_m2": 5, "p_fa": 0.01, "p_fn": 0.1},
     "filter": {"histories": 10, "particles": 500},
     "uav_xy": [[x, y], ...], "detections": [[[x, y], ...], ...]}

A grid has ``rows × cols`` junctions ``spacing_m`` apart (junction ``(r, c)`` at
``(c·spacing_m, r·spacing_m)``, every road one block); junction ``(r, c)`` is road node
``c·rows + r`` (:func:`~searchtrack.models.road_synthetic.grid_node`), the node numbering of every
file format that reads a ``map``; ``osm`` is a bundled map name or an OSM
file relative to the JSON file, resampled every ``spacing_m`` (default 10 m), in the frame of
:func:`~searchtrack.models.osm.read_osm`. Step ``k`` (time ``(k + 1)·dt``): the particles move
``dt`` (Eq. 9); on a scan step the UAV at ``uav_xy[k]`` reports ``detections[k]`` (empty: a scan
that saw nothing, the negative update of Eq. 11). Optional: ``seed`` (0), ``measure_every`` (1:
step ``k`` is a scan when ``(k + 1) % measure_every == 0``; the other steps' lists must be
empty), ``filter.association`` (``"sequential"`` or ``"joint"``), ``sensor.
negative_radius_factor`` (0.75), ``sensor.clutter`` (``"roads"`` or ``"view"``). UAV positions
and detections must lie in the roads' bounding box enlarged by the view radius.

EST.json: ``{"estimates", "entropy", "combined_entropy", "ms_per_step", "interrupted"}``, after
every step the best history's MAP point and entropy (nats, 5 m bins) of each target and of the
targets pooled. Target labels are the filter's: target 0 is the one detected first.
"""

from __future__ import annotations

import json
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.errors import SearchtrackError
from searchtrack.core.fields import TOP_LEVEL, JsonFields
from searchtrack.core.files import read_json, write_text_atomic
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import MAX_SEED
from searchtrack.core.types import FloatArray
from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import DirectedRoads, RoadMotion
from searchtrack.sim.particles.track_job import MAX_DISTANCE_M, MAX_DT_S
from searchtrack.sim.roads.scenario import BUNDLED_MAPS, MAX_ROAD_NODES, MapSpec, bundled_map

log = logging.getLogger("searchtrack.sim.road_particles.track_job")

#: Largest DETECTIONS.json read (bytes).
MAX_DETECTIONS_BYTES = 64 * 2**20

#: Limits: target speeds (m/s), targets, histories, particles per filter, particles in all
#: (``H·M·N``: about 90 bytes each at the peak of a step), steps between scans, detections in
#: one scan (a scan is filtered without a break), steps × targets (EST.json about 30 bytes each).
MAX_SPEED_MPS = 1e3
MAX_TARGETS = 1000
MAX_HISTORIES = 10_000
MAX_PARTICLES = 1_000_000
MAX_FILTER_PARTICLES = 5_000_000
MAX_MEASURE_EVERY = 1_000_000
MAX_SCAN_DETECTIONS = 10_000
MAX_ESTIMATES = 5_000_000

_TOP_KEYS = ("map", "dt", "targets", "target_speed_mps", "speed_sigma_mps", "sensor", "filter",
             "uav_xy", "detections", "seed", "measure_every")
_MAP_KEYS = ("grid", "osm", "spacing_m")
_SENSOR_KEYS = ("fov_radius_m", "sigma2_m2", "p_fa", "p_fn", "negative_radius_factor",
                "clutter")
_FILTER_KEYS = ("histories", "particles", "association")


@dataclass(frozen=True)
class RoadTrackJob:
    """A validated DETECTIONS.json: the roads (``map_label`` describes them), seconds per step,
    the filter's configuration, the UAV position ``(K, 2)`` (m) and the detections ``(k_i, 2)``
    of each of the ``K`` steps, the steps per scan and the file's seed."""

    roads: DirectedRoads
    map_label: str
    dt_s: float
    config: RBPFConfig
    uav_xy: FloatArray
    detections: tuple[FloatArray, ...]
    measure_every: int = 1
    seed: int = 0

    @property
    def n_steps(self) -> int:
        """``K``."""
        return len(self.detections)

    @property
    def n_scans(self) -> int:
        """Number of scan steps."""
        return self.n_steps // self.measure_every

    @property
    def n_detections(self) -> int:
        """Detections in the whole recording."""
        return sum(int(d.shape[0]) for d in self.detections)

    def is_scan(self, k: int) -> bool:
        """Whether step ``k`` (0-based) is a scan."""
        return (k + 1) % self.measure_every == 0


@dataclass(frozen=True)
class RoadTrackResult:
    """The filter's output after each of the ``K'`` steps filtered (all, unless
    ``interrupted`` by a stop request): the MAP point ``(K', M, 2)`` (m) and entropy ``(K', M)``
    (nats) of each target, the entropy of the targets pooled ``(K',)``, and the filter's
    seconds (predict, update and outputs) over all steps."""

    estimates: FloatArray
    entropy: FloatArray
    combined_entropy: FloatArray
    seconds: float
    interrupted: bool

    @property
    def steps(self) -> int:
        """``K'``: the steps filtered."""
        return int(self.combined_entropy.shape[0])

    @property
    def ms_per_step(self) -> float:
        """Mean filter time per step (ms); 0 without steps."""
        return 1e3 * self.seconds / self.steps if self.steps else 0.0

    def to_json(self) -> dict[str, Any]:
        """The EST.json record."""
        return {"estimates": np.round(self.estimates, 3).tolist(),
                "entropy": np.round(self.entropy, 4).tolist(),
                "combined_entropy": np.round(self.combined_entropy, 4).tolist(),
                "ms_per_step": round(self.ms_per_step, 4), "interrupted": self.interrupted}


class FieldReader(JsonFields):
    """Field checks raising :class:`ParseError` naming the file and the JSON field: numbers are
    ``≥ 0`` unless a call says otherwise, bad values are shown shortened to 60 characters.

    Parameters
    ----------
    path
        The file read.
    """

    def __init__(self, path: Path) -> None:
        super().__init__(path, low=0.0, shown_chars=60)
        self.path = path

    def points(self, value: Any, field: str, box: FloatArray) -> FloatArray:
        """A list of points ``(k, 2)``, each inside ``box`` ``[[x0, x1], [y0, y1]]``."""
        if not isinstance(value, list):
            raise self.fail(field, f"must be a list of x, y points, got {self.shown(value)}")
        out = np.empty((len(value), 2))
        for j, p in enumerate(value):
            where = f"{field}[{j}]"
            if not isinstance(p, list) or len(p) != 2:
                raise self.fail(where, f"must be a list of 2 numbers (x, y), got {self.shown(p)}")
            for i, v in enumerate(p):
                x = self.number(v, f"{where}[{i}]", low=-math.inf)
                lo, hi = box[i]
                if not lo <= x <= hi:
                    raise self.fail(where, f"{'xy'[i]}={x:g} is off the map area: {'xy'[i]} "
                                    f"must lie between {lo:g} and {hi:g} (the roads' bounding "
                                    "box enlarged by the view radius)")
                out[j, i] = x
        out.setflags(write=False)
        return out


def _map_spec(r: FieldReader, spec: dict[str, Any], base: Path, field: str) -> MapSpec:
    if field == "map.grid":
        grid = spec["grid"]
        if not isinstance(grid, list) or len(grid) != 2:
            raise r.fail(field, f"must be a list of 2 integers (rows, cols), got {r.shown(grid)}")
        rows, cols = (r.integer(v, f"{field}[{i}]", 2, MAX_ROAD_NODES)
                      for i, v in enumerate(grid))
        block = r.number(r.get(spec, "spacing_m", "map."), "map.spacing_m", low_open=True,
                         high=MAX_DISTANCE_M)
        try:
            return MapSpec("grid", rows=rows, cols=cols, block_m=block, spacing_m=block)
        except SearchtrackError as exc:
            raise r.fail(field, str(exc)) from None
    name = spec["osm"]
    if not isinstance(name, str) or not name:
        raise r.fail(field, f"must be a bundled map name {list(BUNDLED_MAPS)} or a file path, "
                     f"got {r.shown(name)}")
    spacing = r.number(spec.get("spacing_m", 10.0), "map.spacing_m", low=1.0,
                       high=MAX_DISTANCE_M)
    return MapSpec("osm", bundled_map(name) if name in BUNDLED_MAPS else base / name, spacing)


def read_map(r: FieldReader, spec: dict[str, Any], base: Path) -> tuple[DirectedRoads, str]:
    """The roads of ``map``: a grid, a bundled map or an OSM file relative to ``base``."""
    kinds = [k for k in ("grid", "osm") if k in spec]
    if len(kinds) != 1:
        raise r.fail("map", "give exactly one of 'grid' or 'osm'")
    field = f"map.{kinds[0]}"
    ms = _map_spec(r, spec, base, field)
    try:
        network = ms.build()
    except SearchtrackError as exc:
        raise r.fail(field, f"cannot read the map: {exc}") from None
    if network.n_nodes > MAX_ROAD_NODES:
        raise r.fail(field, f"{network.n_nodes} road nodes, above the {MAX_ROAD_NODES} allowed; "
                     "give a larger map.spacing_m")
    return DirectedRoads(network), ms.describe()


def _sensor(r: FieldReader, spec: dict[str, Any]) -> DiscSensor:
    def get(key: str) -> Any:
        return r.get(spec, key, "sensor.")

    clutter = spec.get("clutter", "roads")
    if clutter not in ("roads", "view"):
        raise r.fail("sensor.clutter", f"must be 'roads' or 'view', got {r.shown(clutter)}")
    return DiscSensor(
        r.number(get("fov_radius_m"), "sensor.fov_radius_m", low_open=True, high=MAX_DISTANCE_M),
        r.number(get("sigma2_m2"), "sensor.sigma2_m2", low_open=True, high=MAX_DISTANCE_M**2),
        r.number(get("p_fa"), "sensor.p_fa", high=1.0, high_open=True),
        r.number(get("p_fn"), "sensor.p_fn", high=1.0, high_open=True),
        r.number(spec.get("negative_radius_factor", 0.75), "sensor.negative_radius_factor",
                 low_open=True, high=1.0),
        clutter)


def _config(r: FieldReader, top: dict[str, Any], sensor: DiscSensor) -> RBPFConfig:
    targets = r.integer(r.get(top, "targets"), "targets", 1, MAX_TARGETS)
    motion = RoadMotion(
        r.number(r.get(top, "target_speed_mps"), "target_speed_mps", high=MAX_SPEED_MPS),
        r.number(r.get(top, "speed_sigma_mps"), "speed_sigma_mps", high=MAX_SPEED_MPS))
    spec = r.obj(r.get(top, "filter"), "filter", _FILTER_KEYS)
    histories = r.integer(r.get(spec, "histories", "filter."), "filter.histories", 1,
                          MAX_HISTORIES)
    particles = r.integer(r.get(spec, "particles", "filter."), "filter.particles", 1,
                          MAX_PARTICLES)
    if histories * targets * particles > MAX_FILTER_PARTICLES:
        raise r.fail("filter.particles", f"histories × targets × particles = "
                     f"{histories * targets * particles}, above the {MAX_FILTER_PARTICLES} "
                     "allowed")
    association = spec.get("association", "sequential")
    if association not in ("sequential", "joint"):
        raise r.fail("filter.association", f"must be 'sequential' or 'joint', got "
                     f"{r.shown(association)}")
    return RBPFConfig(n_targets=targets, n_histories=histories, n_particles=particles,
                      motion=motion, sensor=sensor, association=association)


def _load(path: Path) -> Any:
    return read_json(path, max_bytes=MAX_DETECTIONS_BYTES)


def read_road_job(path: str | Path) -> RoadTrackJob:
    """Read and validate a DETECTIONS.json file (the map is built here).

    Raises
    ------
    ParseError
        Naming the file and the JSON field at fault (``detections[3][0]``, ``sensor.p_fa``,
        ``map.osm``, ...).
    """
    p = Path(path)
    r = FieldReader(p)
    top = r.obj(_load(p), TOP_LEVEL, _TOP_KEYS)
    dt = r.number(r.get(top, "dt"), "dt", low_open=True, high=MAX_DT_S)
    sensor = _sensor(r, r.obj(r.get(top, "sensor"), "sensor", _SENSOR_KEYS))
    config = _config(r, top, sensor)
    seed = r.integer(top.get("seed", 0), "seed", 0, MAX_SEED)
    every = r.integer(top.get("measure_every", 1), "measure_every", 1, MAX_MEASURE_EVERY)
    uav_raw, det_raw = r.get(top, "uav_xy"), r.get(top, "detections")
    for key, value in (("uav_xy", uav_raw), ("detections", det_raw)):
        if not isinstance(value, list) or not value:
            raise r.fail(key, "must be a non-empty list with one entry per step")
    if len(det_raw) != len(uav_raw):
        raise r.fail("detections", f"has {len(det_raw)} steps but uav_xy has {len(uav_raw)}; "
                     "give one list of detections per UAV position")
    if len(uav_raw) * config.n_targets > MAX_ESTIMATES:
        raise r.fail("uav_xy", f"{len(uav_raw)} steps × {config.n_targets} targets: more than "
                     f"the {MAX_ESTIMATES} estimates EST.json may hold")
    roads, label = read_map(r, r.obj(r.get(top, "map"), "map", _MAP_KEYS), p.parent)
    coords = roads.network.coords
    margin = sensor.fov_radius_m
    box = np.column_stack([coords.min(axis=0) - margin, coords.max(axis=0) + margin])
    uav = r.points(uav_raw, "uav_xy", box)
    detections = []
    for k, scan in enumerate(det_raw):
        if isinstance(scan, list) and len(scan) > MAX_SCAN_DETECTIONS:
            raise r.fail(f"detections[{k}]", f"{len(scan)} detections in one scan, above the "
                         f"{MAX_SCAN_DETECTIONS} allowed")
        ys = r.points(scan, f"detections[{k}]", box)
        if ys.shape[0] and (k + 1) % every:
            raise r.fail(f"detections[{k}]", f"step {k} is not a scan (measure_every={every}: "
                         f"scans are steps {every - 1}, {2 * every - 1}, ...); its list must "
                         "be empty")
        detections.append(ys)
    log.info("%s: %d steps, %d detections on %s", p, len(detections),
             sum(len(d) for d in detections), label)
    return RoadTrackJob(roads, label, dt, config, uav, tuple(detections), every, seed)


def run_road_track_job(job: RoadTrackJob, seed: int,
                       progress: Callable[[int, int], None] | None = None) -> RoadTrackResult:
    """Filter every step of ``job``: predict, update on scan steps, then the best history's MAP
    points and entropies.

    A stop request (:func:`~searchtrack.core.interrupt.stop_requested`) ends the run before the
    next step; the result then covers the steps done. ``progress(done, total)`` is called after
    every step.
    """
    rng = np.random.default_rng(seed)
    n, m = job.n_steps, job.config.n_targets
    estimates, entropy = np.empty((n, m, 2)), np.empty((n, m))
    combined = np.empty(n)
    done = 0
    rbpf = RoadRBPF(job.roads, job.config, rng)
    start = time.perf_counter()
    for k in range(n):
        if stop_requested():
            log.info("stop requested: %d of %d steps filtered", k, n)
            break
        rbpf.predict(job.dt_s, rng)
        if job.is_scan(k):
            rbpf.update(job.detections[k], job.uav_xy[k], rng)
        entropy[k], combined[k], estimates[k] = rbpf.summary()
        done = k + 1
        if progress is not None:
            progress(done, n)
    seconds = time.perf_counter() - start
    log.info("%d steps in %.3f s", done, seconds)
    return RoadTrackResult(estimates[:done], entropy[:done], combined[:done], seconds, done < n)


def write_road_estimates(result: RoadTrackResult, path: str | Path) -> Path:
    """Write EST.json atomically; returns its path."""
    return write_text_atomic(path, json.dumps(result.to_json()) + "\n")
