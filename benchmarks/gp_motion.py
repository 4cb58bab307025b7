"""GP velocity field (paper 003 §1.3) fitted to taxi-like traces on OSM roads, vs a random walk.

    python benchmarks/gp_motion.py [--vehicles 60] [--duration 3600] [--dt 5] [--seed 0]
                                   [--one-way 0 0.5]

For each bundled map and share of one-way streets: generate taxi traces
(``searchtrack.models.road_traces``), hold out 20 % of the vehicles (paper 003: 436 training /
100 test taxis), fit the GP to the training vehicles' velocity samples (all samples, then
occupied fares only, then all samples of 7 taxis, about 5000 points) and score one-step-ahead
velocity prediction on the held-out vehicles:

- RMSE of ``μ(x_k)`` against ``(x_{k+1} − x_k)/Δt`` for the GP, and of 0 for the random walk
  (zero-mean velocity, the GRW of paper 003);
- mean log predictive density per step (nats) of ``N(μ, σ² + σ_n²)`` for the GP and of
  ``N(0, s²)`` for the random walk (``s²`` the training mean square velocity per axis).

Also timed: the fit (hyper-parameters on a 500-point subsample, nearest-neighbour GP on all
points at every grid node) and ``GPMotion.propagate`` for 10 000 particles. One BLAS thread;
run serially.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from searchtrack.models import read_osm
from searchtrack.models.gp_motion import GPMotion, GPVelocityField
from searchtrack.models.road_traces import TaxiModel, Traces, taxi_traces

OSM = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "osm"
MAPS = ("West-Oakland", "aguascalientes")


def _log_density(v: np.ndarray, mean: np.ndarray, var: np.ndarray) -> float:
    """Mean over samples of log N(v; mean, var I) in 2-D."""
    d2 = np.sum((v - mean) ** 2, axis=1)
    return float(np.mean(-d2 / (2.0 * var) - np.log(2.0 * math.pi * var)))


def _propagate_ms(motion: GPMotion, box: np.ndarray, rng: np.random.Generator) -> float:
    x = rng.uniform(box[:, 0], box[:, 1], (10_000, 2))
    times = []
    for _ in range(30):
        start = time.perf_counter()
        motion.propagate(x, 5.0, rng)
        times.append(time.perf_counter() - start)
    return 1e3 * float(np.median(times))


def evaluate(name: str, one_way: float, train: Traces, test: Traces, occupied_only: bool,
             seed: int) -> list[str]:
    """One table row: fit on ``train`` and score on ``test``."""
    x, v = train.velocities(occupied_only)
    xt, vt = test.velocities(occupied_only)
    field = GPVelocityField.fit(x, v, np.random.default_rng(seed))
    h = field.hyper
    mean, var = field.predict(xt)
    rmse_gp = math.sqrt(float(np.mean(np.sum((mean - vt) ** 2, axis=1))))
    rmse_rw = math.sqrt(float(np.mean(np.sum(vt**2, axis=1))))
    lpd_gp = _log_density(vt, mean, var + h.sigma_n**2)
    lpd_rw = _log_density(vt, np.zeros_like(vt), np.full(vt.shape[0], np.mean(v**2)))
    ms = _propagate_ms(GPMotion(field), field.bounds, np.random.default_rng(seed))
    return [name, f"{one_way:g}", "fares" if occupied_only else "all",
            f"{train.vehicles.size}/{test.vehicles.size}", f"{x.shape[0]}", f"{field.fit_s:.2f}",
            f"{h.length_m:.0f}", f"{h.sigma_f:.2f}", f"{h.sigma_n:.2f}", f"{rmse_gp:.3f}",
            f"{rmse_rw:.3f}", f"{100 * (1 - rmse_gp / rmse_rw):+.1f}", f"{lpd_gp:.3f}",
            f"{lpd_rw:.3f}", f"{ms:.2f}"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicles", type=int, default=60)
    parser.add_argument("--duration", type=float, default=3600.0, help="seconds of traffic")
    parser.add_argument("--dt", type=float, default=5.0, help="sampling interval (s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--one-way", type=float, nargs="+", default=[0.0, 0.5],
                        help="shares of one-way streets")
    args = parser.parse_args()
    head = ["map", "1-way", "samples", "train/test", "points", "fit s", "ℓ m", "σ_f", "σ_n",
            "RMSE GP", "RMSE RW", "gain %", "LPD GP", "LPD RW", "prop ms/10k"]
    rows = [head]
    with threadpool_limits(1):
        for name in MAPS:
            net = read_osm(OSM / f"{name}.osm.bz2")
            for one_way in args.one_way:
                traces = taxi_traces(net, args.vehicles, args.duration, args.dt,
                                     np.random.default_rng(args.seed),
                                     TaxiModel(one_way_fraction=one_way))
                cut = round(0.8 * args.vehicles)
                train, test = traces.select(np.arange(cut)), traces.select(np.arange(cut, 10**9))
                for occupied in (False, True):
                    rows.append(evaluate(name, one_way, train, test, occupied, args.seed))
                small = train.select(np.arange(7))  # about 5000 velocity samples
                rows.append(evaluate(name + " (7 taxis)", one_way, small, test, False, args.seed))
    widths = [max(len(r[i]) for r in rows) for i in range(len(head))]
    for r in rows:
        print("  ".join(c.ljust(w) if i in (0, 2) else c.rjust(w)
                        for i, (c, w) in enumerate(zip(r, widths, strict=True))))
    print("\nRMSE in m/s (one-step velocity), LPD = mean log predictive density per step (nats),"
          " higher is better; gain = 1 − RMSE_GP / RMSE_RW.")


if __name__ == "__main__":
    main()
