"""Thesis 001's road missions flown on two beliefs: the thesis's likelihood-ratio field with node
trackers (``lrt``) and the Rao-Blackwellized particle filter of Moore et al. 2021 (``rbpf``).

    python benchmarks/road_beliefs.py [--seeds 3] [--scenarios demo grid-dense]
        [--strategies loiter search_and_loiter search_and_reacquire] [--duration S]
        [--histories 10] [--particles 500] [--jump-rates 0 0.02] [--kld-epsilon 0.05]
        [--search-field lrt]

Scenarios: ``demo`` is the shipped demo (``searchtrack/data/scenarios/demo.toml``: 3 UAVs,
4 targets, 914.4 m, Aguascalientes, 240 s); ``grid-dense`` is the thesis's experiment-2 cell on
the dense 16 × 16 grid with 3 UAVs / 2 targets at 914.4 m, 300 s
(:mod:`searchtrack.sim.roads.experiment`). Each cell is flown with both beliefs on the
same seeds (the world's randomness is the mission's; the RBPF draws from a stream of its own,
so the targets drive alike until the UAVs' paths part). Same guidance, same sensor, same scores:

- MOC and PVT (thesis (6.8)), mean ± 95 % half-width over seeds, and Δ: the RBPF's minus the
  LRT's on the same seed (paired, so the spread of the seeds' difficulty cancels);
- first detection: the time (s) of the first valid tracker on any target, mean over the runs
  that had one (``found`` counts them);
- detected: targets ever held by a valid tracker, mean per run;
- ms/step: median filter-and-plan time of a step (associate, update, initiate, guide, predict).

The RBPF is sized as in the paper (H = 10 histories, N = 500 particles per target) unless
``--histories`` / ``--particles`` say otherwise; it flies the couriers' drive-and-stop motion
and the draws near detections (:mod:`searchtrack.sim.roads.rbpf_belief`), or the robust prior
instead of those draws in the rows of a jump rate ``λ > 0``. With ``--kld-epsilon`` its filters
hold a count that follows their spread (KLD-sampling, at most ``--particles``; the scenario's
``filter.kld_epsilon``); ``--search-field`` picks the field its searching UAVs climb (the
scenario's ``filter.search_field``: by default the thesis's ``φ`` from an LRT flown beside it, or
its own particle mass). Timings depend on the machine's load.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from importlib import resources
from pathlib import Path

import numpy as np
from tables import table

from searchtrack.sim.campaigns.stats import estimate
from searchtrack.sim.roads.experiment import (
    TRACKING_STRATEGIES,
    tracking_base,
    tracking_scenario,
)
from searchtrack.sim.roads.filter_spec import SEARCH_FIELDS
from searchtrack.sim.roads.filters import FILTERS
from searchtrack.sim.roads.mission import World
from searchtrack.sim.roads.record import MissionLog
from searchtrack.sim.roads.scenario import GuidanceSpec, Scenario
from searchtrack.sim.roads.scenario_file import load_scenario
from searchtrack.sim.roads.seeds import fly_seeds

DEMO = Path(str(resources.files("searchtrack") / "data" / "scenarios" / "demo.toml"))
ALTITUDE_M = 914.4


def scenarios(names: list[str], duration_s: float | None) -> dict[str, Scenario]:
    """The benchmark's scenarios by name (``duration_s`` overrides their durations)."""
    out: dict[str, Scenario] = {}
    for name in names:
        if name == "demo":
            sc = load_scenario(DEMO)
        else:
            sc = tracking_scenario(tracking_base("grid-dense"), uavs=3, targets=2,
                                   altitude_m=ALTITUDE_M, strategy="search_and_loiter")
        out[name] = sc if duration_s is None else dataclasses.replace(sc, duration_s=duration_s)
    return out


def variant(base: Scenario, belief: str, strategy: str, histories: int,
            particles: int, jump_rate_per_s: float = 0.0,
            kld_epsilon: float | None = None, search_field: str | None = None) -> Scenario:
    """``base`` estimated with ``belief`` and guided by ``strategy`` (its other guidance
    settings kept)."""
    f = dataclasses.replace(base.filter, belief=belief, histories=histories,
                            particles=particles, jump_rate_per_s=jump_rate_per_s,
                            kld_epsilon=kld_epsilon,
                            search_field=search_field or base.filter.search_field)
    g: GuidanceSpec = dataclasses.replace(base.guidance, strategy=strategy)
    return dataclasses.replace(base, filter=f, guidance=g)


def first_detection_s(log: MissionLog) -> float:
    """Time (s) of the run's first detection, NaN when nothing was detected."""
    t = log.first_detection_s[np.isfinite(log.first_detection_s)]
    return float(t.min()) if t.size else math.nan


def paired(logs: list[MissionLog], reference: list[MissionLog] | None) -> tuple[str, str]:
    """MOC and PVT (%) minus the reference's, seed by seed (mean ± 95 % half-width; a seed
    without a PVT in either run is left out); blank without a reference."""
    if reference is None or reference is logs:
        return "", ""
    moc = [a.score.moc_mean - b.score.moc_mean for a, b in zip(logs, reference, strict=True)]
    pvt = [100.0 * (a.score.pvt - b.score.pvt) for a, b in zip(logs, reference, strict=True)
           if a.score.pvt is not None and b.score.pvt is not None]
    return str(estimate(moc)), str(estimate(pvt))


def row(name: str, belief: str, strategy: str, logs: list[MissionLog], wall_s: float,
        reference: list[MissionLog] | None = None) -> list[str]:
    """One table row (the paired differences against ``reference``, the LRT's runs)."""
    first = [first_detection_s(lg) for lg in logs]
    ms = np.concatenate([lg.step_ms for lg in logs])
    return [name, belief, strategy, str(len(logs)),
            str(estimate([lg.score.moc_mean for lg in logs])),
            str(estimate([100.0 * lg.score.pvt for lg in logs if lg.score.pvt is not None])),
            *paired(logs, reference),
            str(estimate(first)), f"{sum(math.isfinite(t) for t in first)}/{len(logs)}",
            f"{np.mean([lg.score.detected for lg in logs]):.2f}",
            f"{np.median(ms):.1f}", f"{wall_s:.0f}"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--scenarios", nargs="+", default=["demo", "grid-dense"],
                        choices=["demo", "grid-dense"])
    parser.add_argument("--strategies", nargs="+", default=list(TRACKING_STRATEGIES))
    parser.add_argument("--duration", type=float, default=None,
                        help="seconds per run (default: each scenario's own)")
    parser.add_argument("--histories", type=int, default=10)
    parser.add_argument("--particles", type=int, default=500)
    parser.add_argument("--jump-rates", type=float, nargs="+", default=[0.0],
                        help="RBPF rows for each jump rate λ (1/s) of its robust prior")
    parser.add_argument("--kld-epsilon", type=float, default=None,
                        help="the RBPF's KLD-sampling ε (default: fixed counts)")
    parser.add_argument("--search-field", default=None, choices=SEARCH_FIELDS,
                        help="the RBPF's search field (default: the scenario's)")
    args = parser.parse_args()
    header = ["scenario", "belief", "strategy", "runs", "MOC", "PVT %", "Δ MOC", "Δ PVT %",
              "first det. s", "found", "detected", "ms/step", "wall s"]
    rows = []
    for name, base in scenarios(args.scenarios, args.duration).items():
        world = World.build(base)
        seeds = range(base.seed, base.seed + args.seeds)
        for strategy in args.strategies:
            reference: list[MissionLog] | None = None
            for belief in FILTERS.names():
                for rate in (args.jump_rates if belief == "rbpf" else [0.0]):
                    started = time.perf_counter()
                    sc = variant(base, belief, strategy, args.histories, args.particles, rate,
                                 args.kld_epsilon, args.search_field)
                    logs = fly_seeds(sc, seeds, world)
                    label = f"rbpf λ={rate:g}" if belief == "rbpf" and rate > 0.0 else belief
                    reference = logs if belief == "lrt" else reference
                    rows.append(row(name, label, strategy, logs, time.perf_counter() - started,
                                    reference))
                    print(f"  done {name} {strategy} {label}", file=sys.stderr, flush=True)
    print(f"\nThesis 001 road missions on two beliefs: lrt (thesis) and rbpf (Moore et al. 2021, "
          f"H = {args.histories}, N = {args.particles}"
          + ("" if args.kld_epsilon is None else f" at most, KLD ε = {args.kld_epsilon:g}")
          + ("" if args.search_field is None else f", search field {args.search_field}")
          + "); mean ± 95 % half-width over "
          f"{args.seeds} seeds; Δ: minus the lrt row's, seed by seed")
    table(header, rows)


if __name__ == "__main__":
    main()
