"""Recorded 2-D detections filtered offline: SCANS.json read and validated into a
:class:`TrackJob`, run through the SMC-PHD filter, the estimates written to EST.json (the library
side of ``searchtrack track``).

SCANS.json::

    {"area": [[x0, x1], [y0, y1]], "dt": 1.0,
     "sensor": {"pd": 0.9, "sigma": 10.0, "clutter_rate": 10.0},
     "motion": {"model": "cv", "q": 0.5},
     "birth_weight": 0.25,
     "scans": [[[x, y], ...], ...]}

``motion.model`` is ``"cv"`` (nearly constant velocity, needs ``q``), ``"rw"`` (random walk, needs
``sigma`` in m/s) or ``"static"``; ``birth_weight`` (expected births per scan, default 0.25) is
optional. Clutter is uniform over the area, which is also the surveillance region. EST.json is
``{"estimates": [[[x, y], ...], ...], "ms_per_scan": ..., "expected_count": [...]}``: one list of
estimated positions per scan, the mean filter time per scan (update and extraction) and the
PHD's expected number of targets after each scan.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from searchtrack.core.fields import TOP_LEVEL, JsonFields
from searchtrack.core.files import read_json, write_text_atomic
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.types import FloatArray
from searchtrack.estimate.phd import PHDConfig, PHDState, SensorScan, step
from searchtrack.models.motion import ConstantVelocity, RandomWalk, Static
from searchtrack.models.particle_models import MotionModel
from searchtrack.models.position_sensor import PositionSensor

MOTION_MODELS = ("cv", "rw", "static")

#: Largest SCANS.json read (bytes): about a million detections.
MAX_SCANS_BYTES = 64 * 2**20

#: Physical ranges a SCANS.json value must lie in: coordinates and lengths (m, a continent),
#: the scan interval (s, a day), rates (clutter per scan, birth mass, process noise).
MAX_DISTANCE_M = 1e7
MAX_DT_S = 86_400.0
MAX_RATE = 1e6


@dataclass(frozen=True)
class TrackJob:
    """A validated SCANS.json: the sensor, motion model, birth weight and scans."""

    sensor: PositionSensor
    motion: MotionModel
    dt_s: float
    birth_weight: float
    scans: tuple[FloatArray, ...]


@dataclass(frozen=True)
class TrackSummary:
    """What :func:`run_track_file` did."""

    scans: int
    ms_per_scan: float
    mean_estimates: float
    final_expected_count: float
    out_path: Path


class _Reader(JsonFields):
    """SCANS.json's field checks: the common ones and points."""

    def point(self, value: Any, field: str) -> list[float]:
        """A point ``(x, y)`` (m) within ±:data:`MAX_DISTANCE_M`."""
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(field, f"must be a list of 2 numbers (x, y), got {value!r}")
        return [self.number(v, f"{field}[{i}]", low=-MAX_DISTANCE_M, high=MAX_DISTANCE_M)
                for i, v in enumerate(value)]


def _motion(r: _Reader, spec: dict[str, Any]) -> MotionModel:
    name = r.get(spec, "model", "motion.")
    if name not in MOTION_MODELS:
        raise r.fail("motion.model", f"must be one of {MOTION_MODELS}, got {name!r}")
    known = {"cv": ("model", "q"), "rw": ("model", "sigma"), "static": ("model",)}[name]
    r.check_keys(spec, "motion", known, unknown=f"unknown key for model {name!r}")
    if name == "cv":
        return ConstantVelocity(r.number(r.get(spec, "q", "motion."), "motion.q", low=0.0,
                                         low_open=True, high=MAX_RATE))
    if name == "rw":
        return RandomWalk(r.number(r.get(spec, "sigma", "motion."), "motion.sigma", low=0.0,
                                   low_open=True, high=MAX_DISTANCE_M))
    return Static()


_TOP_KEYS = ("area", "dt", "sensor", "motion", "birth_weight", "scans")
_SENSOR_KEYS = ("pd", "sigma", "clutter_rate")


def read_scans(path: str | Path) -> TrackJob:
    """Read and validate a SCANS.json file.

    Raises
    ------
    ParseError
        Naming the file and the JSON field (``scans[3][1]``, ``sensor.pd``, ...) at fault.
    """
    p = Path(path)
    r = _Reader(p)
    raw = read_json(p, max_bytes=MAX_SCANS_BYTES)
    top = r.obj(raw, TOP_LEVEL)
    area_raw = r.get(top, "area")
    if not isinstance(area_raw, list) or len(area_raw) != 2:
        raise r.fail("area", f"must be a list of 2 pairs (x0, x1), (y0, y1), got {area_raw!r}")
    area = np.array([r.point(v, f"area[{i}]") for i, v in enumerate(area_raw)])
    if not np.all(area[:, 1] > area[:, 0]):
        raise r.fail("area", f"must have x0 < x1 and y0 < y1 (non-empty), got {area_raw!r}")
    dt = r.number(r.get(top, "dt"), "dt", low=0.0, low_open=True, high=MAX_DT_S)
    sensor = r.obj(r.get(top, "sensor"), "sensor")
    pd = r.number(r.get(sensor, "pd", "sensor."), "sensor.pd", low=0.0, high=1.0)
    sigma = r.number(r.get(sensor, "sigma", "sensor."), "sensor.sigma", low=0.0, low_open=True,
                     high=MAX_DISTANCE_M)
    clutter = r.number(r.get(sensor, "clutter_rate", "sensor."), "sensor.clutter_rate", low=0.0,
                       high=MAX_RATE)
    motion = _motion(r, r.obj(r.get(top, "motion"), "motion"))
    birth = r.number(top.get("birth_weight", 0.25), "birth_weight", low=0.0, high=MAX_RATE)
    r.check_keys(top, TOP_LEVEL, _TOP_KEYS)
    r.check_keys(sensor, "sensor", _SENSOR_KEYS)
    scans_raw = r.items(r.get(top, "scans"), "scans", "scans (lists of x, y detections)",
                        allow_empty=True)
    scans = []
    for k, scan in enumerate(scans_raw):
        if not isinstance(scan, list):
            raise r.fail(f"scans[{k}]", f"must be a list of x, y detections, got {scan!r}")
        pts = [r.point(z, f"scans[{k}][{j}]") for j, z in enumerate(scan)]
        arr = np.array(pts, dtype=np.float64).reshape(-1, 2)
        arr.setflags(write=False)
        scans.append(arr)
    return TrackJob(PositionSensor(pd, sigma, clutter, area), motion, dt, birth, tuple(scans))


def run_track_job(job: TrackJob, config: PHDConfig, seed: int,
                  progress: Callable[[int, int], None] | None = None,
                  ) -> tuple[list[FloatArray], list[float], float]:
    """Filter every scan: the estimated positions and expected count per scan, and seconds.

    ``progress(done, total)`` is called after each scan. A stop request ends the run after the
    current scan: the lists then cover the scans done."""
    rng = np.random.default_rng(seed)
    state = PHDState.empty(job.motion.state_dim, job.motion.position_dim)
    pose = np.zeros(3)
    estimates: list[FloatArray] = []
    counts: list[float] = []
    start = time.perf_counter()
    with threadpool_limits(1):
        for z in job.scans:
            if stop_requested():
                break
            state, est = step(state, [SensorScan(job.sensor, pose, z)], job.motion, config,
                              job.dt_s, rng)
            estimates.append(est.positions)
            counts.append(state.expected_count())
            if progress is not None:
                progress(len(estimates), len(job.scans))
    return estimates, counts, time.perf_counter() - start


def run_track_file(scans_path: str | Path, out_path: str | Path, particles: int | None = None,
                   seed: int = 0,
                   progress: Callable[[int, int], None] | None = None) -> TrackSummary:
    """Read SCANS.json, run the SMC-PHD filter, write EST.json.

    Parameters
    ----------
    scans_path, out_path
        Input and output files.
    particles
        Cap on the number of particles (``PHDConfig.max_particles``); ``None``: the default.
    seed
        Seed of the filter's random generator.
    progress
        ``progress(done, total)`` after each scan.
    """
    job = read_scans(scans_path)
    config = PHDConfig(birth_mass=job.birth_weight, region=job.sensor.area)
    if particles is not None:
        config = dataclasses.replace(config, max_particles=particles,
                                     min_particles=min(config.min_particles, particles))
    estimates, counts, seconds = run_track_job(job, config, seed, progress)
    n = len(estimates)
    ms = 1e3 * seconds / max(n, 1)
    record = {"estimates": [np.round(e, 3).tolist() for e in estimates],
              "ms_per_scan": round(ms, 3),
              "expected_count": [round(c, 4) for c in counts]}
    out = write_text_atomic(out_path, json.dumps(record) + "\n")
    mean_est = float(np.mean([e.shape[0] for e in estimates])) if estimates else 0.0
    return TrackSummary(n, ms, mean_est, counts[-1] if counts else 0.0, out)
