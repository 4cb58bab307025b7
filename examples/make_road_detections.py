"""Simulate a recording for ``searchtrack track-roads``: targets driving on the 3×3 grid of 100 m
roads (Moore et al. 2021's map), a UAV chasing them, and its disc sensor's detections.

    python examples/make_road_detections.py [--out examples/problems/road_detections.json]
                                            [--seed 0] [--steps 200] [--truth TRUTH.json]

The targets follow the road motion model (:class:`~searchtrack.models.road_particles.RoadMotion`,
10 m/s with σ 2 m/s, as the authors' truth); the UAV starts over the centre junction and flies at
25 m/s straight at the target it chases, switching to the next one each time it detects the one
it chases (the ideal planner of the paper's simulation), so its path follows the roads. Every
step is a scan (:meth:`~searchtrack.models.disc_sensor.DiscSensor.detect`: 30 m view, σ² 5 m²,
P_FA 0.01, P_FN 0.1). ``--truth`` also writes the true positions and the source of every
detection (target index, −1 for a false alarm).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import DirectedRoads, RoadMotion
from searchtrack.models.road_synthetic import grid_network

OUT = Path(__file__).resolve().parent / "problems" / "road_detections.json"

#: The sensor of the recording (also written into it).
SENSOR = DiscSensor(fov_radius_m=30.0, sigma2_m2=5.0, p_fa=0.01, p_fn=0.1)


def simulate(seed: int = 0, steps: int = 200, dt_s: float = 0.1, targets: int = 2,
             uav_speed_mps: float = 25.0) -> tuple[dict[str, Any], NDArray[np.float64],
                                                   list[NDArray[np.int64]]]:
    """A recording on the 3×3 grid: the document for ``track-roads``, the true positions
    ``(steps, targets, 2)`` and the source of each step's detections (−1: false alarm)."""
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    sensor, motion = SENSOR, RoadMotion(10.0, 2.0)
    rng = np.random.default_rng(seed)
    edge, s = roads.uniform(targets, rng)
    uav, chase = np.array([100.0, 100.0]), 0
    truth = np.empty((steps, targets, 2))
    path: list[list[float]] = []
    detections: list[list[list[float]]] = []
    sources: list[NDArray[np.int64]] = []
    for k in range(steps):
        edge, s = motion.step(roads, edge, s, dt_s, rng)
        truth[k] = roads.point(edge, s)
        gap = truth[k, chase] - uav
        uav = uav + gap * min(1.0, uav_speed_mps * dt_s / max(float(np.hypot(*gap)), 1e-9))
        ys, src = sensor.detect_labelled(uav, truth[k], rng, roads)
        if np.any(src == chase):
            chase = (chase + 1) % targets
        path.append(np.round(uav, 3).tolist())
        detections.append(np.round(ys, 3).tolist())
        sources.append(src)
    view = {"fov_radius_m": sensor.fov_radius_m, "sigma2_m2": sensor.sigma2_m2,
            "p_fa": sensor.p_fa, "p_fn": sensor.p_fn}
    doc = {"map": {"grid": [3, 3], "spacing_m": 100.0}, "dt": dt_s, "targets": targets,
           "target_speed_mps": 10.0, "speed_sigma_mps": 4.0, "sensor": view,
           "filter": {"histories": 10, "particles": 500}, "seed": seed,
           "uav_xy": path, "detections": detections}
    return doc, truth, sources


def main() -> None:
    """Write the recording (and optionally its truth)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--truth", type=Path, default=None, metavar="TRUTH.json")
    args = parser.parse_args()
    doc, truth, sources = simulate(args.seed, args.steps)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(doc) + "\n", encoding="utf-8")
    seen = sum(int(np.sum(src >= 0)) for src in sources)
    print(f"wrote {args.out}: {args.steps} steps, {seen} target detections, "
          f"{sum(int(np.sum(src < 0)) for src in sources)} false alarms")
    if args.truth is not None:
        args.truth.write_text(json.dumps({"truth": np.round(truth, 3).tolist(),
                                          "sources": [s.tolist() for s in sources]}) + "\n",
                              encoding="utf-8")
        print(f"wrote {args.truth}")


if __name__ == "__main__":
    main()
