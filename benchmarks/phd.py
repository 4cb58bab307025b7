"""SMC-PHD on the standard scenario: searchtrack vs Stone Soup's SMC-PHD and GM-PHD.

    python benchmarks/phd.py [--seeds 3] [--skip-gm] [--particles-per-target 400]
    python benchmarks/phd.py --scaling-only [--scaling 10000,100000,1000000]

The standard scenario (:func:`searchtrack.sim.particles.scenario.standard_scenario`): 10 nearly-
constant-velocity targets (q = 0.5) in 1000 m × 1000 m, 100 scans 1 s apart, p_d = 0.9,
σ = 10 m, 10 clutter points per scan. Every filter runs on the same scans with one BLAS thread.
Columns: ms per scan for the filter (predict + update + resample) and for extracting estimates,
mean OSPA (p = 1, c = 100 m) over scans 20–99, and the mean number of estimates (truth: 10).

- searchtrack SMC-PHD: measurement-driven birth (total birth mass 0.25 per scan), 400 particles
  per target, extraction by measurement attribution with missed-target read-out (default), and
  the two alternatives (attribution without the read-out; weighted k-means).
- Stone Soup SMC-PHD: ``SMCPHDPredictor`` (expansion birth: 2000 particles per scan, uniform in
  position over the area, velocity N(0, 3²), birth rate 0.25, death probability 0.01 per s) +
  ``SMCPHDUpdater`` (systematic resampling to 10 000 particles, p_d 0.9, clutter density
  10 / 10⁶ m⁻²); estimates: the weighted mean of each measurement hypothesis whose intensity
  exceeds 0.5 (as ``SMCPHDInitiator`` does), timed separately.
- Stone Soup GM-PHD (its tutorial's set-up): Kalman predictor/updater, ``PHDUpdater``
  (p_s 0.99), Mahalanobis ``DistanceHypothesiser`` (missed distance 3), mixture reducer (prune
  1e-8, merge 5), a birth component of weight 0.25 at the centre with standard deviations
  500 m / 5 m/s; estimates: components of weight > 0.5.

The particle-scaling table runs searchtrack's filter (attribution + missed) on seed 0 with a fixed
particle count N after every resampling (``particles_per_target = min_particles = max_particles =
N``), once with the NumPy reference equations (``backend="numpy"``) and once with the compiled
passes (``backend="numba"``, warmed up first): median ms per scan of the filter (predict + update +
resample) and of each part, with the OSPA and count of that run.
Timings depend on the machine's load: run it on an idle machine.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from collections.abc import Callable
from datetime import datetime, timedelta
from typing import Any

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.phd import (
    PHDConfig,
    PHDState,
    SensorScan,
    extract,
    predict,
    resample,
    update,
)
from searchtrack.sim.particles.scenario import PHDScenario, standard_scenario

FloatArray = NDArray[np.float64]
C_M, FIRST = 100.0, 20


@dataclasses.dataclass
class Run:
    """Timings (s) and estimates of one filter on one scenario."""

    filter_s: float = 0.0
    extract_s: float = 0.0
    estimates: list[FloatArray] = dataclasses.field(default_factory=list)


    parts: list[tuple[float, float, float, float]] = dataclasses.field(default_factory=list)


def run_searchtrack(sc: PHDScenario, config: PHDConfig, seed: int) -> Run:
    """Our filter, timed step by step (``parts``: predict, update, extract, resample per scan)."""
    rng = np.random.default_rng(seed)
    state = PHDState.empty(4, 2)
    pose = np.zeros(3)
    out = Run()
    for z in sc.scans:
        t0 = time.perf_counter()
        state = predict(state, sc.motion, config, sc.dt_s, rng)
        tp = time.perf_counter()
        state = update(state, [SensorScan(sc.sensor, pose, z)], config)
        t1 = time.perf_counter()
        est = extract(state, config)
        t2 = time.perf_counter()
        state = resample(state, config, rng)
        t3 = time.perf_counter()
        out.filter_s += (t1 - t0) + (t3 - t2)
        out.extract_s += t2 - t1
        out.parts.append((tp - t0, t1 - tp, t2 - t1, t3 - t2))
        out.estimates.append(np.array(est.positions))
    return out


def scaling(sc: PHDScenario, counts: list[int], backends: list[str]) -> None:
    """The particle-scaling table: each backend at each particle count, back to back."""
    print(f"\nparticle scaling, seed 0, {len(sc.scans)} scans, median ms per scan")
    header = (f"{'backend':8s} {'N':>9s} {'filter':>8s} {'predict':>8s} {'update':>8s} "
              f"{'resample':>8s} {'extract':>8s} {'OSPA m':>7s} {'count':>6s}")
    print(header)
    print("-" * len(header))
    warm = standard_scenario(0, n_scans=3)
    for backend in backends:
        for n in counts:
            cfg = PHDConfig(particles_per_target=n, min_particles=n, max_particles=n,
                            region=sc.sensor.area, backend=backend)
            run_searchtrack(warm, cfg, 0)
            run = run_searchtrack(sc, cfg, 0)
            parts = 1e3 * np.asarray(run.parts)
            med = np.median(parts, axis=0)
            filt = float(np.median(parts[:, 0] + parts[:, 1] + parts[:, 3]))
            _, _, d, count = score(sc, run)
            print(f"{backend:8s} {n:9d} {filt:8.2f} {med[0]:8.2f} {med[1]:8.2f} {med[3]:8.2f} "
                  f"{med[2]:8.2f} {d:7.2f} {count:6.2f}", flush=True)


def _stonesoup_models(sc: PHDScenario) -> tuple[Any, Any]:
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import (
        CombinedLinearGaussianTransitionModel,
        ConstantVelocity,
    )

    transition = CombinedLinearGaussianTransitionModel(
        [ConstantVelocity(sc.motion.q), ConstantVelocity(sc.motion.q)])
    measurement = LinearGaussian(ndim_state=4, mapping=(0, 2),
                                 noise_covar=np.eye(2) * sc.sensor.sigma_m**2)
    return transition, measurement


def _detections(sc: PHDScenario, measurement: Any, start: datetime) -> list[tuple[datetime,
                                                                                  list[Any]]]:
    from stonesoup.types.detection import Detection

    out = []
    for k, z in enumerate(sc.scans):
        t = start + timedelta(seconds=k * sc.dt_s)
        out.append((t, [Detection(row.reshape(2, 1), timestamp=t, measurement_model=measurement)
                        for row in z]))
    return out


def run_stonesoup_smc(sc: PHDScenario, seed: int, n_particles: int = 10_000) -> Run:
    """Stone Soup's SMC-PHD predictor + updater; estimates from hypothesis intensities."""
    from scipy.special import logsumexp
    from stonesoup.predictor.particle import SMCPHDPredictor
    from stonesoup.resampler.particle import SystematicResampler
    from stonesoup.sampler.particle import ParticleSampler
    from stonesoup.types.array import StateVectors
    from stonesoup.types.detection import MissedDetection
    from stonesoup.types.hypothesis import SingleHypothesis
    from stonesoup.types.multihypothesis import MultipleHypothesis
    from stonesoup.types.state import ParticleState
    from stonesoup.updater.particle import SMCPHDUpdater

    transition, measurement = _stonesoup_models(sc)
    rng = np.random.default_rng(seed)
    lo, hi = sc.sensor.area[:, 0], sc.sensor.area[:, 1]

    def birth(num_samples: int) -> FloatArray:
        s = np.empty((4, num_samples))
        s[[0, 2]] = (lo + (hi - lo) * rng.random((num_samples, 2))).T
        s[[1, 3]] = 3.0 * rng.standard_normal((2, num_samples))
        return s

    sampler = ParticleSampler(distribution_func=birth, params={"num_samples": n_particles},
                              ndim_state=4)
    predictor = SMCPHDPredictor(transition_model=transition, death_probability=0.01,
                                birth_probability=0.2, birth_rate=0.25, birth_sampler=sampler)
    updater = SMCPHDUpdater(measurement_model=measurement, resampler=SystematicResampler(),
                            prob_detect=0.9, clutter_intensity=sc.sensor.clutter_rate /
                            sc.sensor.area_m2, num_samples=n_particles)
    start = datetime(2026, 1, 1)
    state = ParticleState(StateVectors(birth(n_particles)), log_weight=np.full(n_particles, np.log(
        0.25 / n_particles)), timestamp=start - timedelta(seconds=sc.dt_s))
    out = Run()
    for t, dets in _detections(sc, measurement, start):
        t0 = time.perf_counter()
        pred = predictor.predict(state, timestamp=t)
        hyps = MultipleHypothesis([SingleHypothesis(pred, MissedDetection(timestamp=t))] +
                                  [SingleHypothesis(pred, d) for d in dets])
        state = updater.update(hyps)
        t1 = time.perf_counter()
        logw = updater.get_log_weights_per_hypothesis(hyps)
        intensity = np.exp(logsumexp(logw, axis=0))
        sv = np.asarray(pred.state_vector, dtype=np.float64)
        est = []
        for j in np.flatnonzero(intensity[1:] > 0.5) + 1:
            w = np.exp(logw[:, j] - logsumexp(logw[:, j]))
            est.append([sv[0] @ w, sv[2] @ w])
        t2 = time.perf_counter()
        out.filter_s += t1 - t0
        out.extract_s += t2 - t1
        out.estimates.append(np.array(est).reshape(-1, 2))
    return out


def run_stonesoup_gm(sc: PHDScenario) -> Run:
    """Stone Soup's GM-PHD as in its tutorial; estimates: components of weight > 0.5."""
    from stonesoup.hypothesiser.distance import DistanceHypothesiser
    from stonesoup.hypothesiser.gaussianmixture import GaussianMixtureHypothesiser
    from stonesoup.measures import Mahalanobis
    from stonesoup.mixturereducer.gaussianmixture import GaussianMixtureReducer
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.types.state import TaggedWeightedGaussianState
    from stonesoup.updater.kalman import KalmanUpdater
    from stonesoup.updater.pointprocess import PHDUpdater

    transition, measurement = _stonesoup_models(sc)
    kalman_updater = KalmanUpdater(measurement)
    updater = PHDUpdater(kalman_updater, clutter_spatial_density=sc.sensor.clutter_rate /
                         sc.sensor.area_m2, prob_detection=0.9, prob_survival=0.99)
    base = DistanceHypothesiser(KalmanPredictor(transition), kalman_updater, Mahalanobis(),
                                missed_distance=3)
    hypothesiser = GaussianMixtureHypothesiser(base, order_by_detection=True)
    reducer = GaussianMixtureReducer(prune_threshold=1e-8, pruning=True, merge_threshold=5,
                                     merging=True)
    centre = sc.sensor.area.mean(axis=1)
    start = datetime(2026, 1, 1)
    birth = TaggedWeightedGaussianState([centre[0], 0.0, centre[1], 0.0],
                                        np.diag([500.0, 5.0, 500.0, 5.0]) ** 2, weight=0.25,
                                        tag="birth", timestamp=start)
    reduced: set[Any] = set()
    out = Run()
    for t, dets in _detections(sc, measurement, start):
        t0 = time.perf_counter()
        birth.timestamp = t
        current = set(reduced) | {birth}
        hyps = hypothesiser.hypothesise(current, set(dets), timestamp=t, order_by_detection=True)
        reduced = set(reducer.reduce(updater.update(hyps)))
        t1 = time.perf_counter()
        est = [[float(s.state_vector[0, 0]), float(s.state_vector[2, 0])] for s in reduced
               if s.weight > 0.5]
        t2 = time.perf_counter()
        out.filter_s += t1 - t0
        out.extract_s += t2 - t1
        out.estimates.append(np.array(est).reshape(-1, 2))
    return out


def score(sc: PHDScenario, run: Run) -> tuple[float, float, float, float]:
    """ms/scan (filter), ms/scan (extraction), mean OSPA and mean count over scans 20–99."""
    n = len(sc.scans)
    d = [ospa(run.estimates[k], sc.truth[k][:, :2], C_M, 1.0) for k in range(FIRST, n)]
    count = [run.estimates[k].shape[0] for k in range(FIRST, n)]
    return (1e3 * run.filter_s / n, 1e3 * run.extract_s / n, float(np.mean(d)),
            float(np.mean(count)))


def main() -> None:
    """Run every filter on every seed and print the table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--skip-gm", action="store_true", help="skip the (slow) GM-PHD")
    ap.add_argument("--skip-stonesoup", action="store_true", help="only searchtrack's filter")
    ap.add_argument("--particles-per-target", type=int, default=400)
    ap.add_argument("--scaling", default="10000,100000,1000000",
                    help="particle counts of the scaling table (empty: no table)")
    ap.add_argument("--scaling-backends", default="numpy,numba",
                    help="backends of the scaling table, in order")
    ap.add_argument("--scaling-only", action="store_true", help="only the scaling table")
    args = ap.parse_args()
    counts = [int(n) for n in args.scaling.split(",") if n]
    if args.scaling_only:
        with threadpool_limits(1):
            scaling(standard_scenario(0), counts, args.scaling_backends.split(","))
        return
    scenarios = [standard_scenario(s) for s in range(args.seeds)]
    region = scenarios[0].sensor.area
    base = PHDConfig(particles_per_target=args.particles_per_target, region=region)
    filters: list[tuple[str, Callable[[PHDScenario, int], Run]]] = [
        ("searchtrack SMC-PHD (attribution + missed)", lambda sc, s: run_searchtrack(
            sc, base, s)),
        ("  the same, NumPy reference equations", lambda sc, s: run_searchtrack(
            sc, dataclasses.replace(base, backend="numpy"), s)),
        ("searchtrack SMC-PHD (attribution only)", lambda sc, s: run_searchtrack(
            sc, dataclasses.replace(base, report_missed=False), s)),
        ("searchtrack SMC-PHD (weighted k-means)", lambda sc, s: run_searchtrack(
            sc, dataclasses.replace(base, extraction="kmeans"), s)),
    ]
    if not args.skip_stonesoup:
        filters.append(("Stone Soup SMC-PHD (10 000 particles)", run_stonesoup_smc))
        if not args.skip_gm:
            filters.append(("Stone Soup GM-PHD", lambda sc, s: run_stonesoup_gm(sc)))
    truth_count = float(np.mean([sc.truth.shape[1] for sc in scenarios]))
    print(f"standard scenario, {args.seeds} seeds, OSPA p=1 c={C_M:g} m over scans "
          f"{FIRST}-{len(scenarios[0].scans) - 1}, truth count {truth_count:g}")
    header = (f"{'filter':44s} {'ms/scan':>8s} {'extract':>8s} {'total':>7s} {'OSPA m':>7s} "
              f"{'count':>6s}  per-seed OSPA")
    print(header)
    print("-" * len(header))
    with threadpool_limits(1):
        for name, fn in filters:
            rows = [score(sc, fn(sc, s)) for s, sc in enumerate(scenarios)]
            m = np.mean(rows, axis=0)
            seeds = " ".join(f"{r[2]:.1f}" for r in rows)
            print(f"{name:44s} {m[0]:8.2f} {m[1]:8.2f} {m[0] + m[1]:7.2f} {m[2]:7.2f} "
                  f"{m[3]:6.2f}  {seeds}", flush=True)
        if counts:
            scaling(scenarios[0], counts, args.scaling_backends.split(","))


if __name__ == "__main__":
    main()
