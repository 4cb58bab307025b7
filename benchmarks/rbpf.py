"""The road RBPF of Moore et al. 2021: time per step, and association accuracy on the 3×3 map.

    python benchmarks/rbpf.py [--repeats 200] [--seeds 5] [--duration 120]

Timing (ms per call, mean over ``--repeats`` calls after a warm-up that compiles the kernels):
``predict`` moves every particle by δt (Eq. 9); ``update (miss)`` is a scan without detections
(negative update of every filter, Eq. 11); ``update (det)`` a scan with one detection of a true
target under the UAV (DAS over every history, Eq. 15–16, the detection and negative updates,
top-level resampling). ``total`` = predict + update (det), the worst case. Rows per jump rate
of the robust prior (``--jump-rates``, 0: the paper's prior), one with the draws near
detections (``births``, :mod:`searchtrack.estimate.road_births`) and one with those draws and
KLD-sampling (``births, KLD``: each filter's count follows its spread, at most ``N``;
:class:`~searchtrack.estimate.road_resampling.KLDSampling`). ``particles`` is ``H·M·N``, or the
mean count held over the timed steps with KLD-sampling. Cases:

- the paper's simulation: 3×3 grid of 100 m roads, H = 10, M = 2, N = 500, δt = 0.1 s;
- the bundled Aguascalientes map (17 834 directed edges of ≤ 10 m), H = 20, M = 10, N = 500,
  δt = 0.1 s and δt = 1 s (at 10 m/s a particle then crosses about one node per step).

Association accuracy: on the 3×3 map two targets drive with the motion model (10 m/s, σ 2 m/s,
as the authors' truth); a UAV at 40 m/s flies straight at the true position of one target until
it detects it, then at the other (the paper's ideal planner); the filter predicts every 0.1 s and
scans at 1 Hz with the default sensor (30 m view, σ² = 5 m², P_FA 0.02, P_FN 0.05). A scan counts
as correct when every true detection in it gets the best history's label of its target; filter
labels are matched to the truth by the permutation that agrees best over the run (the labels are
arbitrary: the first detection is target 0). Clutter detections are left out of the score. The
accuracy is printed with fixed counts (the paper) and with KLD-sampling.
Timings depend on the machine's load.
"""

from __future__ import annotations

import argparse
import itertools
import time

import numpy as np
from numpy.typing import NDArray

from searchtrack.estimate.road_births import DetectionBirths
from searchtrack.estimate.road_jumps import TargetJumps
from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
from searchtrack.estimate.road_resampling import KLDSampling
from searchtrack.models.road_particles import DirectedRoads, RoadMotion
from searchtrack.models.road_synthetic import grid_network
from searchtrack.sim.roads.experiment import MAPS

FloatArray = NDArray[np.float64]


def _time(roads: DirectedRoads, h: int, m: int, n: int, dt_s: float,
          repeats: int, jump_rate: float = 0.0, births: DetectionBirths | None = None,
          counts: KLDSampling | None = None) -> tuple[float, float, float, float]:
    """Mean ms of predict, update without and with one detection (``jump_rate > 0``: with the
    robust prior's jump draws at every update; ``births``: with the draws near detections;
    ``counts``: with KLD-sampling), and the mean number of particles held."""
    rng = np.random.default_rng(0)
    f = RoadRBPF(roads, RBPFConfig(n_targets=m, n_histories=h, n_particles=n,
                                   jumps=TargetJumps.at_rate(jump_rate), births=births,
                                   counts=counts), rng)
    te, ts = roads.uniform(m, rng)
    truth = roads.point(te, ts)
    for _ in range(3):  # warm-up: compile and reach a tracked state
        f.predict(dt_s, rng)
        f.update(truth[:1], truth[0], rng)
    t_pred = t_miss = t_det = held = 0.0
    for i in range(repeats):
        t0 = time.perf_counter()
        f.predict(dt_s, rng)
        t1 = time.perf_counter()
        if i % 2:
            f.update(np.empty((0, 2)), truth[i % m], rng)
            t_miss += time.perf_counter() - t1
        else:
            y = truth[i % m] + rng.normal(0.0, 2.0, 2)
            f.update(y[None], truth[i % m], rng)
            t_det += time.perf_counter() - t1
        t_pred += t1 - t0
        held += float(f.clouds.count.sum())
    half = repeats / 2
    return 1e3 * t_pred / repeats, 1e3 * t_miss / half, 1e3 * t_det / half, held / repeats


def association_run(seed: int, duration_s: float,
                    counts: KLDSampling | None = None) -> tuple[int, int]:
    """``(correct scans, scans with a true detection)`` of one simulated 3×3 run."""
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    rng = np.random.default_rng(seed)
    f = RoadRBPF(roads, RBPFConfig(n_targets=2, counts=counts), rng)
    sensor, truth_motion = f.config.sensor, RoadMotion(10.0, 2.0)
    te, ts = roads.uniform(2, rng)
    uav, chase, dt = np.array([100.0, 100.0]), 0, 0.1
    labels: list[tuple[NDArray[np.int64], NDArray[np.int64]]] = []
    for k in range(round(duration_s / dt)):
        te, ts = truth_motion.step(roads, te, ts, dt, rng)
        f.predict(dt, rng)
        pts = roads.point(te, ts)
        gap = pts[chase] - uav
        uav = uav + gap * min(1.0, 40.0 * dt / max(float(np.hypot(*gap)), 1e-9))
        if k % 10 == 9:
            y, src = sensor.detect_labelled(uav, pts, rng, roads)
            f.update(y, uav, rng)
            if np.any(src == chase):
                chase = 1 - chase
            real = src >= 0
            if real.any():
                labels.append((src[real], f.best_association()[real]))
    best = 0
    for perm in itertools.permutations(range(2)):
        p = np.array(perm)
        best = max(best, sum(bool(np.all(p[est] == truth)) for truth, est in labels))
    return best, len(labels)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=200)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--jump-rates", type=float, nargs="+", default=[0.0, 0.1],
                        help="timing rows per jump rate λ (1/s) of the robust prior (0: paper)")
    args = parser.parse_args()
    grid = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    agu = DirectedRoads(MAPS["aguascalientes"].build())
    cases = [("3x3 grid, H=10 M=2 N=500, dt 0.1 s", grid, 10, 2, 500, 0.1, 1.0),
             ("Aguascalientes, H=20 M=10 N=500, dt 0.1 s", agu, 20, 10, 500, 0.1, 15.0),
             ("Aguascalientes, H=20 M=10 N=500, dt 1 s", agu, 20, 10, 500, 1.0, 15.0)]
    print(f"{'case':52s} {'particles':>9s} {'predict':>8s} {'upd miss':>8s} {'upd det':>8s} "
          f"{'total':>8s} {'target':>7s}   (ms per step)")
    for name, roads, h, m, n, dt, target in cases:
        variants: list[tuple[str, float, DetectionBirths | None, KLDSampling | None]] = [
            (f", λ {rate:g}/s" if rate > 0.0 else "", rate, None, None)
            for rate in args.jump_rates]
        variants += [(", births", 0.0, DetectionBirths(), None),
                     (", births, KLD", 0.0, DetectionBirths(), KLDSampling())]
        for suffix, rate, births, counts in variants:
            p, miss, det, held = _time(roads, h, m, n, dt, args.repeats, rate, births, counts)
            print(f"{name + suffix:52s} {held:9.0f} {p:8.3f} {miss:8.3f} {det:8.3f} "
                  f"{p + det:8.3f} {target:7.1f}")
    for label, counts in (("fixed counts", None), ("KLD-sampling", KLDSampling())):
        print()
        print(f"association on the 3x3 map, {label} ({args.duration:g} s per run, scans at "
              "1 Hz):")
        total_ok = total = 0
        for seed in range(args.seeds):
            ok, n_scans = association_run(seed, args.duration, counts)
            total_ok, total = total_ok + ok, total + n_scans
            print(f"  seed {seed}: {ok}/{n_scans} scans correct ({ok / max(n_scans, 1):.1%})")
        print(f"  all: {total_ok}/{total} ({total_ok / max(total, 1):.1%})")


if __name__ == "__main__":
    main()
