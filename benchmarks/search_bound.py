"""How much of thesis 001's experiment-2 MOC a search can reach at all: an ideal-sweep estimate.

    python benchmarks/search_bound.py [--map aguascalientes] [--fleets 3/2 1/4]
        [--altitudes 457.2 914.4 1372 1828.8] [--duration 300] [--offsets 4] [--samples 1000000]

MOC over a run counts each target from the step it is first validly tracked. Before a target is
found it cannot be tracked, so the whole-run MOC is capped by how fast the fleet can cover the
road. This script estimates that cap under idealisations that favour the search (all but the
targets standing still, which cuts both ways)
(``searchtrack.sim.roads.search_cap``):

- targets stand still where they start (uniform over the road length, as the missions spawn
  them), are found the instant a footprint covers their road, and are held from then on;
- each searching UAV sweeps a lane ``2ρ`` wide at ``S_max`` (the footprint radius of the altitude
  model (6.7), the Dubins speed limit), the fleet's starting footprints count as covered, and the
  lanes fill the squares of side ``2ρ`` holding the most road first, with no overlap, no turns
  and no travel between squares (the best of ``offsets × offsets`` grid placements);
- "all search" (the cap): every UAV searches to the end. "one holds each": a found target takes
  one UAV out of the search, a strict reading of the loiter strategies (one UAV per tracker);
  not a cap, since a holding UAV's footprint follows its target over new road and sees the
  targets that drive through it.

The expected MOC under these idealisations is averaged over ``samples`` draws of the targets'
positions (seeded), which places each along the fleet's coverage order.
The script prints, per fleet and altitude, the road covered by 30/60/90/120 s with every UAV
searching and the two MOC estimates. The missions themselves are measured by
``benchmarks/road_missions.py exp2`` and the ``thesis_exp2*`` campaigns.
"""

from __future__ import annotations

import argparse

from tables import table

from searchtrack.models.dubins import DubinsLimits
from searchtrack.models.lrt_sensor import THESIS_ALTITUDES_M, AltitudeModel
from searchtrack.sim.roads.experiment import MAPS, TRACKING_FLEETS, tracking_base
from searchtrack.sim.roads.mission import World
from searchtrack.sim.roads.search_cap import ideal_sweep_moc

COVERAGE_TIMES_S = (30, 60, 90, 120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--map", default="aguascalientes", choices=list(MAPS))
    parser.add_argument("--fleets", nargs="+", default=[f"{o}/{t}" for o, t in TRACKING_FLEETS],
                        help="UAVs/targets")
    parser.add_argument("--altitudes", type=float, nargs="+", default=list(THESIS_ALTITUDES_M))
    parser.add_argument("--duration", type=float, default=300.0)
    parser.add_argument("--offsets", type=int, default=4,
                        help="grid placements per axis (the pointwise best is kept)")
    parser.add_argument("--samples", type=int, default=1_000_000,
                        help="draws of the targets' positions")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    network = World.build(tracking_base(args.map)).network
    speed = DubinsLimits().speed_max_mps
    altitude = AltitudeModel()
    header = ["UAVs/targets", "altitude m", "ρ m", "lane km²/min per UAV"] + [
        f"road by {t} s" for t in COVERAGE_TIMES_S] + ["MOC all search", "MOC one holds each"]
    rows = []
    for fleet in args.fleets:
        uavs, targets = (int(x) for x in fleet.split("/"))
        for h in args.altitudes:
            rho = float(altitude.sensor(h).footprint_radius_m)
            kw = {"uavs": uavs, "targets": targets, "footprint_radius_m": rho,
                  "speed_mps": speed, "duration_s": args.duration, "offsets": args.offsets,
                  "samples": args.samples, "seed": args.seed}
            free, covered = ideal_sweep_moc(network, hold=False, **kw)
            held, _ = ideal_sweep_moc(network, hold=True, **kw)
            rows.append([fleet, f"{h:g}", f"{rho:.0f}", f"{2 * rho * speed * 60 / 1e6:.2f}",
                         *(f"{covered[t]:.2f}" for t in COVERAGE_TIMES_S),
                         f"{free:.3f}", f"{held:.3f}"])
    print(f"\nIdeal-sweep estimate of the whole-run MOC on {args.map} ({args.duration:g} s, "
          f"S_max {speed:.1f} m/s, {network.total_length_m / 1e3:.0f} km of road; static "
          "targets found the instant covered; densest 2ρ squares first, no travel)")
    table(header, rows)


if __name__ == "__main__":
    main()
