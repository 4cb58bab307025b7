"""Thesis 001 experiments on real and synthetic road maps, and the closed-loop step budget.

    python benchmarks/road_missions.py exp1 [--seeds 25] [--uavs 3 4 5 6]
    python benchmarks/road_missions.py exp2 [--seeds 10] [--duration 300] [--strategies ...]
        [--fleets 3/2] [--altitudes 914.4 1828.8] [--belief rbpf] [--search-field lrt]
    python benchmarks/road_missions.py step [--duration 120]

exp1 (§6.1): likelihood-gradient search, detection only: time to detect all 8 targets against the
number of UAVs on the two bundled OSM maps and a dense synthetic grid (claim: it falls with more
UAVs; its spread too). exp2 (§6.2): loiter vs search-and-loiter vs search-and-reacquire, MOC,
PVT and PVA at the four altitudes for 1 UAV / 4 targets and 3 UAVs / 2 targets (claims: loiter ≥
search-and-loiter on MOC; PVT ≈ 97 %; MOC ≈ 25 % at ratio 0.25 and ≈ 100 % at 1.5), on the
thesis's LRT belief or (``--belief rbpf``) on paper 000's RBPF (``--search-field``: the field its
searching UAVs climb). step: the
filter-and-plan time of one step on Aguascalientes with 3 UAVs, by number of trackers (< 50 ms).
The scenarios and per-run scores are :mod:`searchtrack.sim.roads.experiment`; this script
loops over them, times and prints.
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import sys
import time

import numpy as np
from tables import table

from searchtrack.models.lrt_sensor import THESIS_ALTITUDES_M
from searchtrack.sim.campaigns.stats import estimate
from searchtrack.sim.roads.experiment import (
    MAPS,
    TRACKING_FLEETS,
    TRACKING_STRATEGIES,
    detection_scenario,
    detection_time_s,
    step_samples,
    step_scenario,
    tracking_base,
    tracking_run,
    tracking_scenario,
    with_fleet,
    with_strategy,
)
from searchtrack.sim.roads.filter_spec import SEARCH_FIELDS
from searchtrack.sim.roads.filters import FILTERS
from searchtrack.sim.roads.mission import World
from searchtrack.sim.roads.record import PHASES
from searchtrack.sim.roads.scenario import STRATEGIES
from searchtrack.sim.roads.seeds import fly_seeds


def exp1(args: argparse.Namespace) -> None:
    """Time to detect all targets vs number of UAVs (detection only, Table 6.2)."""
    header = ["map", "int/mi²", "hull km²", "UAVs", "runs", "all found", "time s (95 % CI)",
              "median s", "s.d. s", "wall s"]
    rows = []
    for name in args.maps:
        base = detection_scenario(name, max_duration_s=args.max_duration,
                                  llr_floor=args.llr_floor)
        world = World.build(base)
        net = world.network
        for o in args.uavs:
            started = time.perf_counter()
            logs = fly_seeds(with_fleet(base, o), range(args.seeds), world)
            found = [detection_time_s(lg) for lg in logs]
            ok = [t for t in found if t is not None]
            est = estimate(ok)
            rows.append([name, f"{net.intersection_density_per_mi2:.0f}",
                         f"{net.hull_area_m2 / 1e6:.2f}", str(o), str(len(logs)),
                         f"{len(ok)}/{len(logs)}", str(est),
                         f"{np.median(ok):.0f}" if ok else "-",
                         f"{est.std:.0f}" if est.n > 1 else "-",
                         f"{time.perf_counter() - started:.0f}"])
            print(f"  done {name} O={o}", file=sys.stderr, flush=True)
    print(f"\nExperiment 1: time to detect all 8 targets (cap {args.max_duration:g} s, LRT floor "
          f"{args.llr_floor:g}; runs that miss a target are excluded from the mean and counted in "
          "'all found')")
    table(header, rows)
    print("\nthesis claim (§6.1, Fig. 6.3): the time to detect all targets falls as UAVs are added")
    for name in args.maps:
        means = [(int(r[3]), float(r[6].split(" ")[0])) for r in rows
                 if r[0] == name and r[6] != "-"]
        falls = all(b[1] < a[1] for a, b in itertools.pairwise(means))
        trend = ", ".join(f"{o} UAVs {m:.0f} s" for o, m in means)
        verdict = "falls at every step" if falls else "does NOT fall at every step"
        print(f"  {name}: {trend}: {verdict}")


def exp2(args: argparse.Namespace) -> None:
    """MOC, PVT, PVA for the three tracking strategies at the four altitudes."""
    header = ["UAVs/targets", "altitude m", "strategy", "runs", "MOC mean", "MOC last third",
              "MOC after det.", "PVT %", "PVA %", "1st det. s", "no det.", "plan ms p95",
              "wall s"]
    rows = []
    base = tracking_base(args.map, duration_s=args.duration)
    base = dataclasses.replace(base, filter=dataclasses.replace(
        base.filter, belief=args.belief,
        search_field=args.search_field or base.filter.search_field))
    world = World.build(base)
    fleets = [f for f in TRACKING_FLEETS if f"{f[0]}/{f[1]}" in args.fleets]
    for uavs, targets in fleets:
        for h in args.altitudes:
            for strategy in args.strategies:
                started = time.perf_counter()
                sc = tracking_scenario(base, uavs=uavs, targets=targets, altitude_m=h,
                                       strategy=strategy)
                runs = [tracking_run(lg) for lg in fly_seeds(sc, range(args.seeds), world)]
                rows.append([
                    f"{uavs}/{targets}", f"{h:g}", strategy, str(len(runs)),
                    str(estimate([r.moc_mean for r in runs])),
                    str(estimate([r.moc_last_third for r in runs])),
                    str(estimate([r.moc_after_detection for r in runs
                                  if r.moc_after_detection is not None])),
                    str(estimate([r.pvt_pct for r in runs if r.pvt_pct is not None])),
                    str(estimate([r.pva_pct for r in runs if r.pva_pct is not None])),
                    str(estimate([r.first_detection_s for r in runs
                                  if r.first_detection_s is not None])),
                    str(sum(r.first_detection_s is None for r in runs)),
                    f"{max(r.plan_ms_p95 for r in runs):.1f}",
                    f"{time.perf_counter() - started:.0f}"])
                print(f"  done {uavs}/{targets} h={h} {strategy}", file=sys.stderr, flush=True)
    searched = (f" (search field {base.filter.search_field})" if args.belief == "rbpf"
                else "")
    print(f"\nExperiment 2 on {args.map}, belief {args.belief}{searched}: {args.duration:g} s "
          "per run, mean ± 95 % half-width over seeds")
    table(header, rows)
    print("\nthesis claims (§6.2, Figs. 6.6–6.13): loiter ≥ search-and-loiter on MOC; PVT ≈ 97 %;"
          " MOC ≈ 25 % at ratio 0.25 (1 UAV/4 targets) and ≈ 100 % at 1.5 (3 UAVs/2 targets);"
          " search-and-reacquire was never simulated")
    moc = {(r[0], r[1], r[2]): float(r[4].split(" ")[0]) for r in rows if r[4] != "-"}
    for uavs, targets in fleets:
        for h in args.altitudes:
            key = (f"{uavs}/{targets}", f"{h:g}")
            got = {st: moc.get((*key, st)) for st in args.strategies}
            known = {st: v for st, v in got.items() if v is not None}
            order = " > ".join(f"{st} {v:.2f}" for st, v in
                               sorted(known.items(), key=lambda kv: -kv[1]))
            verdict = ""
            if "loiter" in known and "search_and_loiter" in known:
                holds = known["loiter"] >= known["search_and_loiter"]
                verdict = "loiter ≥ search-and-loiter " + ("holds" if holds else "does NOT hold")
            print(f"  {key[0]} at {key[1]} m: MOC {order}; {verdict}")


def step(args: argparse.Namespace) -> None:
    """Filter-and-plan milliseconds per step by number of live trackers."""
    header = ["strategy", "trackers", "steps", "median ms", "p95 ms", "max ms"] + [
        f"{p} ms" for p in PHASES[2:]]
    rows = []
    base = step_scenario(duration_s=args.duration)
    world = World.build(base)
    for strategy in args.strategies:
        logs = fly_seeds(with_strategy(base, strategy), range(args.seeds), world)
        counts, ms, phases = step_samples(logs)
        for k in sorted(set(counts.tolist())):
            sel = counts == k
            rows.append([strategy, str(k), str(int(sel.sum())), f"{np.median(ms[sel]):.1f}",
                         f"{np.percentile(ms[sel], 95):.1f}", f"{ms[sel].max():.1f}"]
                        + [f"{phases[sel, i].mean():.2f}" for i in range(2, len(PHASES))])
    print(f"\nClosed-loop step on aguascalientes ({world.network.n_nodes} nodes, 10 m), 3 UAVs, "
          "4 targets, altitude 1828.8 m: filter-and-plan ms per step (update = associate + "
          "tracker and LRT updates; guide = assignment, forces, OPTW)")
    table(header, rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="section", required=True)
    p1 = sub.add_parser("exp1")
    p1.add_argument("--seeds", type=int, default=25)
    p1.add_argument("--uavs", type=int, nargs="+", default=[3, 4, 5, 6])
    p1.add_argument("--maps", nargs="+", default=list(MAPS), choices=list(MAPS))
    p1.add_argument("--max-duration", type=float, default=1800.0)
    p1.add_argument("--llr-floor", type=float, default=-20.0,
                    help="lowest LRT value where sensed (-inf: none, the thesis)")
    p1.set_defaults(run=exp1)
    strategies = list(TRACKING_STRATEGIES)
    p2 = sub.add_parser("exp2")
    p2.add_argument("--seeds", type=int, default=10)
    p2.add_argument("--duration", type=float, default=300.0)
    p2.add_argument("--map", default="aguascalientes", choices=list(MAPS))
    p2.add_argument("--strategies", nargs="+", default=strategies, choices=STRATEGIES)
    p2.add_argument("--fleets", nargs="+", default=[f"{o}/{t}" for o, t in TRACKING_FLEETS],
                    choices=[f"{o}/{t}" for o, t in TRACKING_FLEETS], help="UAVs/targets")
    p2.add_argument("--altitudes", type=float, nargs="+", default=list(THESIS_ALTITUDES_M))
    p2.add_argument("--belief", default="lrt", choices=FILTERS.names())
    p2.add_argument("--search-field", default=None, choices=SEARCH_FIELDS,
                    help="the RBPF's search field (default: the scenario's)")
    p2.set_defaults(run=exp2)
    p3 = sub.add_parser("step")
    p3.add_argument("--duration", type=float, default=120.0)
    p3.add_argument("--seeds", type=int, default=3)
    p3.add_argument("--strategies", nargs="+", default=strategies)
    p3.set_defaults(run=step)
    args = parser.parse_args()
    args.run(args)


if __name__ == "__main__":
    main()
